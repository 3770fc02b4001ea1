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
//! [`AftWorkspace::initial_state_derivative`]: crate::contact::aft::AftWorkspace::initial_state_derivative

use faer::Mat;

use crate::contact::ContactState;
use crate::hbm::{HbmError, HbmSystem};
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
/// (see [`AmplitudeSensitivity::effective`]).
pub fn residual_derivative(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    groups: &[Vec<usize>],
) -> Result<ResidualDerivative, HbmError> {
    let problem = system.problem();
    if let Some(c) = problem.contacts.iter().find(|c| c.second_tangent.is_some()) {
        return Err(HbmError::TwoDimensionalFriction {
            contact: c.name.clone(),
            evaluation: "the initial-state sensitivity (response envelope)",
        });
    }
    let n = problem.model.n_dofs();
    let dim = system.dim();
    let constant = system.unknowns().constant_block();
    let mut per_contact = vec![0.0; problem.contacts.len()];
    let mut states = Vec::with_capacity(problem.contacts.len());
    let mut effective_per_contact = Vec::with_capacity(problem.contacts.len());
    for c in 0..problem.contacts.len() {
        let state = system.contact_forces(c, x, false)?;
        // The law the system evaluates (its initial state may be set apart from the problem's).
        let law = system.law(c);
        per_contact[c] = system.aft().initial_state_derivative(&law);
        effective_per_contact.push(system.aft().effective_initial_state(&law, state));
        states.push(state);
    }
    let effective = groups
        .iter()
        .map(|group| {
            let first = effective_per_contact[*group.first()?]?;
            group
                .iter()
                .all(|&c| effective_per_contact[c].is_some_and(|m| (m - first).abs() <= 1e-9))
                .then_some(first)
        })
        .collect();
    let derivative = groups
        .iter()
        .map(|group| {
            let mut d = vec![0.0; dim];
            if let Some(j0) = constant {
                for &c in group {
                    for &(p, a) in &problem.contacts[c].tangential {
                        d[j0 * n + p] += a * per_contact[c];
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
    } = residual_derivative(system, x, groups)?;
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
