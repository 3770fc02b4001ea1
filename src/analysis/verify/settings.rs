//! What a time-domain verification is set up with, which problems it supports and how it
//! fails: the settings, their limits and the typed errors.

use crate::contact::NormalLoad;
use crate::model::Problem;

/// Most DOFs of a model the dense time integration (and the monodromy) accepts: lumped or
/// reduced models.
pub const MAX_VERIFY_DOFS: usize = 2000;

/// Settings of a time integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifySettings {
    /// Newmark steps per excitation period (≥ 8·H is sensible; the default 256·H).
    pub steps_per_period: usize,
    /// Most periods integrated.
    pub max_periods: usize,
    /// Fewest periods integrated, even if the start already repeats.
    pub min_periods: usize,
    /// Tolerance on the period-to-period change of the state at the period start, relative to
    /// the largest first-harmonic amplitude of the last period.
    pub periodicity_tolerance: f64,
    /// Newton tolerance on the step residual, relative to the load scale.
    pub newton_tolerance: f64,
    /// Newton iterations per step before the step is reported failed.
    pub max_newton: usize,
}

impl VerifySettings {
    /// Defaults for a harmonic set with highest harmonic `h_max`: 256·H steps per period,
    /// 300 periods at most, at least 4, periodicity tolerance 10⁻⁵.
    pub fn for_harmonics(h_max: usize) -> Self {
        Self {
            steps_per_period: 256 * h_max.max(1),
            max_periods: 300,
            min_periods: 4,
            periodicity_tolerance: 1e-5,
            newton_tolerance: 1e-9,
            max_newton: 50,
        }
    }
}

/// Errors of a time integration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VerifyError {
    /// The model is not supported by the time integration.
    #[error("time integration not supported: {reason}")]
    Unsupported {
        /// Why.
        reason: String,
    },
    /// The step Newton did not converge.
    #[error("Newton did not converge at t = {time_s:.6e} s (residual {residual:.3e})")]
    StepFailed {
        /// Time of the failed step (s).
        time_s: f64,
        /// Last relative residual.
        residual: f64,
    },
    /// The static deflection could not be solved.
    #[error("static deflection: {0}")]
    Static(String),
    /// The monodromy matrix of the periodic orbit could not be computed.
    #[error("monodromy: {0}")]
    Monodromy(String),
    /// The initial coefficients do not match the problem's layout.
    #[error("initial coefficients have length {found}, expected {expected}")]
    WrongLength {
        /// Expected length.
        expected: usize,
        /// Found length.
        found: usize,
    },
}

pub(super) fn check_supported(problem: &Problem) -> Result<(), VerifyError> {
    if problem.effects.contact.normal_load == NormalLoad::Constant && !problem.contacts.is_empty() {
        return Err(VerifyError::Unsupported {
            reason:
                "effects.normal_load = \"constant\" has no time-domain meaning; use \"variable\""
                    .into(),
        });
    }
    let n = problem.model.n_dofs();
    if n > MAX_VERIFY_DOFS {
        return Err(VerifyError::Unsupported {
            reason: format!("{n} DOFs: the dense time integration is for lumped or reduced models (≤ {MAX_VERIFY_DOFS} DOFs)"),
        });
    }
    Ok(())
}
