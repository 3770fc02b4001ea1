//! Where a nonlinear mode starts: the linear modes of the structure as the harmonic balance
//! sees it at rest (contacts stuck, or open where the static state leaves them open), the mode
//! asked for, and the starting guess of the continuation.

use faer::Mat;

use super::error::NonlinearModeError;
use crate::contact::harmonic::HarmonicSet;
use crate::hbm::HbmSystem;
use crate::model::ModeChoice;
use crate::model::Problem;
use crate::numerics::jacobian::Storage;
use crate::numerics::Continuation;

/// One linear mode of the structure at rest with its contacts linearised.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearStart {
    /// Mode number among the elastic modes (1-based, ascending frequency).
    pub number: usize,
    /// Natural frequency ω₀ (rad/s).
    pub omega: f64,
    /// Mass-normalised shape φ (φᵀ M φ = 1, kg^-½), signed so that φ at the phase DOF is
    /// positive.
    pub shape: Vec<f64>,
    /// Modal damping φᵀ C φ (1/s): the artificial damping ξ of the linear mode when C is
    /// proportional (exact then, a first guess otherwise).
    pub xi: f64,
    /// Static state at rest (m, [`rest_statics`]).
    pub statics: Vec<f64>,
}

/// The static state at rest (m) and the elastic modes there: (ω² (rad²/s²), mass-normalised
/// shape), ascending.
pub type RestModes = (Vec<f64>, Vec<(f64, Vec<f64>)>);

/// Relative size of the shape at the phase DOF (to its largest entry) below which the DOF is
/// a node of the mode and cannot fix its phase.
pub const NODE_TOLERANCE: f64 = 1e-6;

/// The linear modes at rest: K_eff = ∂R_c1/∂q_c1 of the harmonic balance at ω = 0 on the static
/// state with no motion (the structure's K with each contact's stuck tangential stiffness, and
/// its normal stiffness where it is closed), against M. Returns the static state and the
/// elastic modes (ω² (rad²/s²), mass-normalised shape), ascending.
pub fn linearised_modes(problem: &Problem) -> Result<RestModes, NonlinearModeError> {
    let mut system = HbmSystem::new(problem)?;
    system.set_storage(Storage::Dense)?;
    let set = system.unknowns().clone();
    let n = problem.model.n_dofs();
    let mut x = vec![0.0; system.dim()];
    let statics = rest_statics(problem)?;
    if let Some(j) = set.constant_block() {
        x[j * n..(j + 1) * n].copy_from_slice(&statics);
    }
    let (cos1, _) = super::operator::first_harmonic_blocks(&set);
    let mut jac = system.new_jacobian();
    let (mut r, mut dr) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    system.residual_and_jacobian(&x, 0.0, &mut r, &mut jac, &mut dr)?;
    let k = Mat::from_fn(n, n, |i, j| {
        0.5 * (jac.get(cos1 * n + i, cos1 * n + j) + jac.get(cos1 * n + j, cos1 * n + i))
    });
    let m = problem.model.mass.to_dense();
    let (values, vectors) =
        fricbound_reduction::dense_generalized_eigenvalues(k.as_ref(), m.as_ref())
            .map_err(|e| NonlinearModeError::Eigen(e.to_string()))?;
    let scale = (0..n)
        .filter(|&i| m[(i, i)] > 0.0)
        .map(|i| k[(i, i)].abs() / m[(i, i)])
        .fold(0.0, f64::max);
    let modes = values
        .iter()
        .enumerate()
        .filter(|(_, &v)| v > crate::analysis::modes::RIGID_TOLERANCE * scale)
        .map(|(c, &v)| (v, (0..n).map(|i| vectors[(i, c)]).collect()))
        .collect();
    Ok((statics, modes))
}

/// The static state at rest (m): the harmonic balance of the 0th harmonic alone (no motion:
/// each contact's normal spring with lift-off and its tangential force m μN from its initial
/// state), solved by Newton from the state with the contacts sliding freely
/// ([`crate::analysis::linear::sliding_static`]), else from the stuck static guess. Zeros when
/// the statics are uncoupled (the harmonic balance then holds the pre-solve's state itself).
pub fn rest_statics(problem: &Problem) -> Result<Vec<f64>, NonlinearModeError> {
    let n = problem.model.n_dofs();
    if !problem.unknown_harmonics().has_constant() {
        return Ok(vec![0.0; n]);
    }
    let mut statics = problem.clone();
    statics.harmonics = Vec::new();
    statics.harmonic_loads.clear();
    let mut system = HbmSystem::new(&statics)?;
    let mut guesses = Vec::new();
    if let Ok(q) = crate::analysis::linear::sliding_static(&statics) {
        guesses.push(q);
    }
    guesses.push(
        crate::analysis::linear::stuck_guess(&statics, &HarmonicSet::new(vec![0]), 0.0)
            .map_err(crate::hbm::HbmError::from)?,
    );
    let newton = Continuation::new(statics.analysis.continuation, vec![1.0; n]);
    let mut last = None;
    for guess in guesses {
        match newton.solve_fixed(&mut system, &guess, std::f64::consts::TAU) {
            Ok(p) => return Ok(p.x),
            Err(e) => last = Some(e),
        }
    }
    Err(NonlinearModeError::Statics(
        last.map_or_else(String::new, |e| e.to_string()),
    ))
}

/// The linear mode asked for (by number or nearest frequency), signed at the phase DOF, with
/// its modal damping; an error when there is no such mode or the phase DOF is a node of it.
pub fn linear_start(
    problem: &Problem,
    choice: ModeChoice,
    phase_dof: usize,
) -> Result<LinearStart, NonlinearModeError> {
    let (statics, modes) = linearised_modes(problem)?;
    let index = match choice {
        ModeChoice::Number(k) => {
            if k == 0 || k > modes.len() {
                return Err(NonlinearModeError::NoSuchMode {
                    asked: k,
                    available: modes.len(),
                });
            }
            k - 1
        }
        ModeChoice::NearestHz(f) => {
            let target = (std::f64::consts::TAU * f).powi(2);
            (0..modes.len())
                .min_by(|&a, &b| {
                    let da = (modes[a].0.sqrt() - target.sqrt()).abs();
                    let db = (modes[b].0.sqrt() - target.sqrt()).abs();
                    da.total_cmp(&db)
                })
                .ok_or(NonlinearModeError::NoSuchMode {
                    asked: 1,
                    available: 0,
                })?
        }
    };
    let (value, mut shape) = modes[index].clone();
    let largest = shape.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let at_dof = shape[phase_dof];
    if at_dof.abs() <= NODE_TOLERANCE * largest {
        return Err(NonlinearModeError::NodeAtDof {
            dof: problem.model.dof_names[phase_dof].clone(),
            mode: index + 1,
        });
    }
    if at_dof < 0.0 {
        shape.iter_mut().for_each(|v| *v = -*v);
    }
    let mut c_phi = vec![0.0; shape.len()];
    problem.model.damping.mul_add(1.0, &shape, &mut c_phi);
    let xi = shape.iter().zip(&c_phi).map(|(a, b)| a * b).sum();
    Ok(LinearStart {
        number: index + 1,
        omega: value.sqrt(),
        shape,
        xi,
        statics,
    })
}

/// The continuation's first guess y = (ψ, ω, ξ): the linear shape in the cosine of the first
/// harmonic, zero elsewhere (the static state does not change in the linear mode).
pub fn start_guess(problem: &Problem, set: &HarmonicSet, start: &LinearStart) -> Vec<f64> {
    let n = problem.model.n_dofs();
    let mut y = vec![0.0; n * set.n_blocks() + 2];
    let (cos1, _) = super::operator::first_harmonic_blocks(set);
    y[cos1 * n..(cos1 + 1) * n].copy_from_slice(&start.shape);
    let dim_h = n * set.n_blocks();
    y[dim_h] = start.omega;
    y[dim_h + 1] = start.xi;
    y
}
