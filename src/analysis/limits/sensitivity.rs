//! Sensitivity of the response amplitudes to the initial tangential states m, by the
//! implicit-function theorem on the harmonic-balance residual.
//!
//! At a converged point R(x; m) = 0 (paper Eq. 7, m entering through the AFT march), so
//! J dx/dm = −∂R/∂m with J = ∂R/∂x the Jacobian Newton already uses: one extra solve with J per
//! group of contacts sharing one m (a damper side or a contact point). ∂R/∂m is analytic
//! ([`AftWorkspace::initial_state_derivative`]): a contact stuck over the whole period moves
//! only the mean of its tangential force, ∂T̂₀/∂m = μ N(τ=0); a contact that slips or separates
//! anywhere forgets m (derivative 0). The first-harmonic amplitude A = √(c₁² + s₁²) of an
//! output DOF then has dA/dm = (c₁ dc₁/dm + s₁ ds₁/dm) / A.
//!
//! A 2D-friction point (`jenkins-2d`) has two initial-state components m = (m₁, m₂) (T(0) =
//! μN(0)·m along t₁, t₂), each a variable of its own ([`StateVariable`]): stuck over the whole
//! period from its start, the point moves the means of both tangential forces,
//! ∂T̂ₐ₀/∂mₐ = μ N(τ=0); one that slipped or separated anywhere has derivative 0 in both. Its
//! "stuck from the start" is read off the 2D march's periodic state: stuck, with T(0)/(μN(0))
//! equal to the m it started from (to 10⁻⁹); a state stuck with another T(0) slipped in the
//! transient, and its effective initial state is that T(0)/(μN(0)), component by component.
//!
//! [`AftWorkspace::initial_state_derivative`]: crate::contact::aft::AftWorkspace::initial_state_derivative

use faer::Mat;

use crate::contact::ContactState;
use crate::hbm::{HbmError, HbmSystem};

/// One initial-state variable of the sensitivity: the contacts sharing it and the component of
/// m it sets (0: m₁ along the first tangent, every point has it; 1: m₂ along the second tangent,
/// 2D points only: a 1D point ignores it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StateVariable {
    /// Contact indices.
    pub contacts: Vec<usize>,
    /// Component of m: 0 or 1.
    pub component: usize,
}

impl StateVariable {
    /// The variables of groups of contacts each sharing one m₁ (the 1D meaning of m).
    pub fn first_components(groups: &[Vec<usize>]) -> Vec<StateVariable> {
        groups
            .iter()
            .map(|g| StateVariable {
                contacts: g.clone(),
                component: 0,
            })
            .collect()
    }
}

/// Tolerance on T(0)/(μN(0)) − m below which a stuck 2D point counts as stuck from its start.
const STUCK_FROM_START_TOLERANCE: f64 = 1e-9;
use crate::numerics::linalg::{packed_lu, LinearSolveError};
use crate::numerics::Storage;

/// Errors of a sensitivity evaluation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SensitivityError {
    /// The residual, Jacobian or contact forces could not be evaluated.
    #[error("{0}")]
    Evaluation(#[from] HbmError),
    /// The Jacobian could not be factorised (singular at the point: a fold).
    #[error("{0}")]
    Solve(#[from] LinearSolveError),
}

/// Amplitudes of the output DOFs at a converged point and their derivatives with respect to the
/// m of each group of contacts.
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudeSensitivity {
    /// First-harmonic amplitude of each output DOF (m).
    pub amplitudes: Vec<f64>,
    /// dA/dm: one row per output DOF, one entry per group (m per unit m).
    pub gradient: Vec<Vec<f64>>,
    /// Whether each group's m acts on the response there: some contact of the group stays
    /// stuck from its initial state over the whole march (never slipped or separated). Groups that do not act have a zero
    /// gradient and are left out of the solves.
    pub active: Vec<bool>,
    /// Contact states at the point, one per contact.
    pub states: Vec<ContactState>,
    /// Per group, the m at which the same state is reached by a march that stays stuck from its
    /// start ([`AftWorkspace::effective_initial_state`](crate::contact::aft::AftWorkspace::effective_initial_state)),
    /// when every contact of the group is stuck over the period and they agree on it; `None`
    /// otherwise (the group's m does not act, or its points differ).
    pub effective: Vec<Option<f64>>,
}

/// ∂R/∂m per group at a point, with what the contacts say about m there.
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualDerivative {
    /// ∂R/∂m_g, one vector per group in the full unknown layout (zero for groups that do not act).
    pub per_group: Vec<Vec<f64>>,
    /// Contact states, one per contact.
    pub states: Vec<ContactState>,
    /// Each group's effective initial state (see [`AmplitudeSensitivity::effective`]).
    pub effective: Vec<Option<f64>>,
}

/// ∂R/∂m_g for every group at (x) (one vector per group, in the full unknown layout; zero for
/// groups that do not act), with the contact states and each group's effective initial state
/// (see [`AmplitudeSensitivity::effective`]). Each group is the m₁ of its points
/// ([`residual_derivative_of`] with [`StateVariable::first_components`]).
pub fn residual_derivative(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    groups: &[Vec<usize>],
) -> Result<ResidualDerivative, HbmError> {
    residual_derivative_of(system, x, &StateVariable::first_components(groups))
}

/// ∂R/∂m for every initial-state variable at (x) (see [`residual_derivative`]; a variable's
/// entry in `per_group`, `effective` is its own).
pub fn residual_derivative_of(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    variables: &[StateVariable],
) -> Result<ResidualDerivative, HbmError> {
    let problem = system.problem();
    let n = problem.model.n_dofs();
    let dim = system.dim();
    let constant = system.unknowns().constant_block();
    let nc = problem.contacts.len();
    // Per contact and component: ∂T̂ₐ₀/∂mₐ and the effective initial state.
    let mut per_contact = vec![[0.0; 2]; nc];
    let mut states = Vec::with_capacity(nc);
    let mut effective_per_contact: Vec<[Option<f64>; 2]> = Vec::with_capacity(nc);
    for c in 0..nc {
        let state = system.contact_forces(c, x, false)?;
        // The law the system evaluates (its initial state may be set apart from the problem's).
        if let Some(law) = system.law_2d(c) {
            let aft = system
                .aft2d()
                .expect("a system with a 2D point has a 2D workspace");
            let limit0 = law.mu * aft.n[0];
            let stuck = state == ContactState::Stuck && limit0 > 0.0;
            let t0 = [aft.t[0][0], aft.t[1][0]];
            let effective = stuck.then(|| [t0[0] / limit0, t0[1] / limit0]);
            let from_start = effective.is_some_and(|e| {
                (0..2).all(|a| (e[a] - law.initial_state[a]).abs() <= STUCK_FROM_START_TOLERANCE)
            });
            if from_start {
                per_contact[c] = [limit0, limit0];
            }
            effective_per_contact.push([effective.map(|e| e[0]), effective.map(|e| e[1])]);
        } else {
            let law = system.law(c);
            per_contact[c][0] = system.aft().initial_state_derivative(&law);
            effective_per_contact.push([system.aft().effective_initial_state(&law, state), None]);
        }
        states.push(state);
    }
    let problem = system.problem();
    let effective = variables
        .iter()
        .map(|v| {
            let a = v.component;
            // A 1D point has no second component: it does not constrain m₂.
            let members: Vec<usize> = v
                .contacts
                .iter()
                .copied()
                .filter(|&c| a == 0 || problem.contacts[c].second_tangent.is_some())
                .collect();
            let first = effective_per_contact[*members.first()?][a]?;
            members
                .iter()
                .all(|&c| effective_per_contact[c][a].is_some_and(|m| (m - first).abs() <= 1e-9))
                .then_some(first)
        })
        .collect();
    let derivative = variables
        .iter()
        .map(|v| {
            let mut d = vec![0.0; dim];
            if let Some(j0) = constant {
                for &c in &v.contacts {
                    let point = &problem.contacts[c];
                    let row = match v.component {
                        0 => Some(point.tangential.as_slice()),
                        _ => point.second_tangent.as_ref().map(|s| s.row.as_slice()),
                    };
                    for &(p, a) in row.into_iter().flatten() {
                        d[j0 * n + p] += a * per_contact[c][v.component.min(1)];
                    }
                }
            }
            d
        })
        .collect();
    Ok(ResidualDerivative {
        per_group: derivative,
        states,
        effective,
    })
}

/// Amplitudes of the output DOFs at the converged full coefficients `x` (ω in rad/s) and their
/// derivatives with respect to the m of each group of contacts (`groups`: contact indices per
/// group), by one solve with the Jacobian per acting group.
pub fn amplitude_sensitivity(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    omega: f64,
    groups: &[Vec<usize>],
) -> Result<AmplitudeSensitivity, SensitivityError> {
    amplitude_sensitivity_of(system, x, omega, &StateVariable::first_components(groups))
}

/// [`amplitude_sensitivity`] with respect to initial-state variables (a group's m₁ or, for 2D
/// points, m₂): one entry per variable in `gradient`, `active` and `effective`.
pub fn amplitude_sensitivity_of(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    omega: f64,
    variables: &[StateVariable],
) -> Result<AmplitudeSensitivity, SensitivityError> {
    let groups = variables;
    let problem = system.problem();
    let n = problem.model.n_dofs();
    let dim = system.dim();
    let (c1, s1) = (
        system.unknowns().cos_block(1),
        system.unknowns().sin_block(1),
    );
    let ResidualDerivative {
        per_group: derivative,
        states,
        effective,
    } = residual_derivative_of(system, x, variables)?;
    let active: Vec<bool> = derivative
        .iter()
        .map(|d| d.iter().any(|v| *v != 0.0))
        .collect();
    let amplitudes: Vec<f64> = problem
        .outputs
        .iter()
        .map(|&d| {
            let c = c1.map_or(0.0, |j| x[j * n + d]);
            let s = s1.map_or(0.0, |j| x[j * n + d]);
            c.hypot(s)
        })
        .collect();
    let mut gradient = vec![vec![0.0; groups.len()]; problem.outputs.len()];
    let acting: Vec<usize> = (0..groups.len()).filter(|&g| active[g]).collect();
    if !acting.is_empty() {
        let mut r = vec![0.0; dim];
        let mut dr = vec![0.0; dim];
        let mut jac = system.new_jacobian();
        system.residual_and_jacobian(x, omega, &mut r, &mut jac, &mut dr)?;
        // dx/dm_g = −J⁻¹ ∂R/∂m_g, one column per acting group.
        let columns: Vec<Vec<f64>> = if jac.storage() == Storage::Dense {
            let lu = packed_lu(jac.to_dense())?;
            let rhs = Mat::from_fn(dim, acting.len(), |i, k| -derivative[acting[k]][i]);
            let sol = lu.solve(&rhs);
            (0..acting.len())
                .map(|k| (0..dim).map(|i| sol[(i, k)]).collect())
                .collect()
        } else {
            acting
                .iter()
                .map(|&g| {
                    let rhs: Vec<f64> = derivative[g].iter().map(|v| -v).collect();
                    jac.solve(&rhs)
                })
                .collect::<Result<_, _>>()?
        };
        for (o, &d) in problem.outputs.iter().enumerate() {
            let a = amplitudes[o];
            if a == 0.0 {
                continue;
            }
            let c = c1.map_or(0.0, |j| x[j * n + d]);
            let s = s1.map_or(0.0, |j| x[j * n + d]);
            for (k, &g) in acting.iter().enumerate() {
                let dc = c1.map_or(0.0, |j| columns[k][j * n + d]);
                let ds = s1.map_or(0.0, |j| columns[k][j * n + d]);
                gradient[o][g] = (c * dc + s * ds) / a;
            }
        }
    }
    Ok(AmplitudeSensitivity {
        amplitudes,
        gradient,
        active,
        states,
        effective,
    })
}
