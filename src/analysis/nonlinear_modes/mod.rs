//! Nonlinear modes of friction-damped structures by the extended periodic motion concept
//! (EPMC, Krack, Computers & Structures 154, 2015): backbone frequency and modal damping ratio
//! against the vibration level, one continuation per mode.
//!
//! The damped structure has no periodic free motion; EPMC adds the artificial damping −ξ M q̇,
//! which feeds in per cycle exactly the energy the structure dissipates, so that
//!
//! ```text
//! M q̈ + (C − ξ M) q̇ + K q + f_c(q, q̇) = F_static          (Krack 2015, Eq. 5)
//! ```
//!
//! has a periodic solution at each vibration level. It is solved on the same harmonic balance
//! as the forced response (same contact laws, formulation switches, effects), without the
//! harmonic loads, for the harmonics ψ, the frequency ω and ξ, with the first-harmonic part of
//! the motion a ψ₁ normalised by ψ₁ᵀ M ψ₁ = 1 (a the modal amplitude, kg^½·m) and its phase
//! fixed by a zero sine at one DOF ([`operator`] gives the equations). The modal damping ratio
//! is D = ξ / (2ω); for a linear structure with proportional damping these are its natural
//! frequencies and modal damping ratios exactly.
//!
//! Continuation runs in log₁₀ a from the linear mode at rest (contacts stuck, [`start`]), from
//! the point whose first-harmonic amplitude at the DOF is the low end asked to the one where it
//! is the high end ([`ends`], [`run::solve`]).
//!
//! | module | main items | job |
//! |---|---|---|
//! | [`operator`] | [`EpmcOperator`], [`LogAmplitude`] | the extended residual and its analytic Jacobian |
//! | [`start`] | [`linear_start`], [`linearised_modes`] | the linear modes at rest and the mode asked |
//! | [`run`] | [`solve`], [`NonlinearModeRun`], [`NonlinearModePoint`] | the continuation and its points |
//! | [`ends`] | `solve_at_dof_amplitude` | the path's ends at the amplitudes asked at the DOF |
//! | [`predict`] | [`predicted_peak`], [`predicted_frf`] | the forced response near the resonance from the mode (single-nonlinear-mode theory) |
//! | [`accuracy`] | [`ModeAccuracy`] | each point's error estimate: the change when the harmonics are raised to 2H + 1 |
//! | [`warnings`](mod@warnings) | [`warnings::largest`], [`warnings::warnings`] | the estimates of a run in words |
//! | [`verify`] | [`verify_mode_point`] | a point checked by time integration with the artificial damping applied |
//! | [`limits`] | [`mode_limits`], [`ModeBand`] | the mode per initial tangential state (m = ±1 per side) and the band they span |

pub mod accuracy;
mod ends;
pub mod error;
pub mod limits;
pub mod operator;
pub mod predict;
pub mod run;
pub mod start;
pub mod verify;
pub mod warnings;

pub use accuracy::{EstimateCounts, ModeAccuracy};
pub use limits::{band, mode_cases, mode_limits, scene_modes, ModeBand, ModeCase, ModeLimits};
pub use operator::{EpmcOperator, LogAmplitude};
pub use predict::{modal_force, predicted_frf, predicted_peak, PredictedPeak};
pub use run::{
    autonomous, point_at, solve, ModeChoice, NonlinearModeEnd, NonlinearModeError,
    NonlinearModePoint, NonlinearModeRun, NonlinearModeSettings,
};
pub use start::{linear_start, linearised_modes, rest_statics, start_guess, LinearStart};
pub use verify::{negatively_damped, verify_mode_point};

use crate::numerics::derivatives::JacobianCheck;
use crate::numerics::ParametricResidual;

/// Checks the analytic Jacobian of the EPMC operator at (y, λ) against central differences:
/// the step on each unknown is `rel_step` times its own size (ψ entries: the RMS of their
/// block kind's entries), so that ψ, ω and ξ are each stepped at their scale; columns are
/// compared after multiplying by that size.
pub fn check_jacobian(
    op: &mut EpmcOperator<'_>,
    y: &[f64],
    lambda: f64,
    rel_step: f64,
) -> Result<JacobianCheck, crate::hbm::HbmError> {
    let dim = op.dim();
    let dim_h = op.harmonic_dim();
    let mut r = vec![0.0; dim];
    let mut dr = vec![0.0; dim];
    let mut jac = op.new_jacobian();
    op.residual_and_jacobian(y, lambda, &mut r, &mut jac, &mut dr)?;
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let typical_psi = rms(&y[..dim_h]).max(1e-300);
    let (mut rp, mut rm) = (vec![0.0; dim], vec![0.0; dim]);
    let (mut max_error, mut max_entry) = (0.0_f64, 0.0_f64);
    let mut yp = y.to_vec();
    for i in 0..=dim {
        let size = if i < dim_h {
            typical_psi
        } else if i < dim {
            y[i].abs().max(1e-3 * y[dim_h].abs())
        } else {
            1.0
        };
        let step = rel_step * size;
        if i < dim {
            yp[i] = y[i] + step;
            op.residual(&yp, lambda, &mut rp)?;
            yp[i] = y[i] - step;
            op.residual(&yp, lambda, &mut rm)?;
            yp[i] = y[i];
        } else {
            op.residual(y, lambda + step, &mut rp)?;
            op.residual(y, lambda - step, &mut rm)?;
        }
        for k in 0..dim {
            let fd = (rp[k] - rm[k]) / (2.0 * step);
            let an = if i < dim { jac.get(k, i) } else { dr[k] };
            max_error = max_error.max((fd - an).abs() * size);
            max_entry = max_entry.max(an.abs() * size);
        }
    }
    Ok(JacobianCheck {
        max_error,
        max_entry,
    })
}
