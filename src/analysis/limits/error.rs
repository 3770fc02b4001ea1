//! Errors of a limit analysis: an operator that cannot be built, a curve that cannot be
//! solved, contact forces that cannot be evaluated, a curve with no converged point in the peak
//! window.

use crate::analysis::frf::FrfError;
use crate::hbm::HbmError;

/// Errors of a limit analysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitError {
    /// The harmonic-balance operator of the problem cannot be built (no case can be solved).
    #[error("the harmonic-balance system cannot be set up: {0}")]
    Setup(HbmError),
    /// A curve could not be solved.
    #[error("curve `{case}`: {source}")]
    Curve {
        /// Case name.
        case: String,
        /// Cause.
        source: FrfError,
    },
    /// Evaluating contact forces failed.
    #[error("curve `{case}`: {source}")]
    Contacts {
        /// Case name.
        case: String,
        /// Cause.
        source: HbmError,
    },
    /// A curve's continuation ended before the end of the range with every step setting
    /// tried (see `FrfRun::incomplete_reason`).
    #[error("curve `{case}` is incomplete: {reason}")]
    Incomplete {
        /// Case name.
        case: String,
        /// Why the range was not covered.
        reason: String,
    },
    /// No converged point of a curve lies in the peak window.
    #[error("curve `{case}`: no converged point in the peak window {lo_hz} .. {hi_hz} Hz")]
    NoPeak {
        /// Case name.
        case: String,
        /// Window start (Hz).
        lo_hz: f64,
        /// Window end (Hz).
        hi_hz: f64,
    },
}

impl LimitError {
    /// The case the error belongs to (`None` for [`LimitError::Setup`]).
    pub fn case(&self) -> Option<&str> {
        match self {
            LimitError::Setup(_) => None,
            LimitError::Curve { case, .. }
            | LimitError::Contacts { case, .. }
            | LimitError::Incomplete { case, .. }
            | LimitError::NoPeak { case, .. } => Some(case),
        }
    }

    /// The message without the case's name (for texts that name the case already).
    pub fn cause(&self) -> String {
        match self {
            LimitError::Setup(e) => e.to_string(),
            LimitError::Curve { source, .. } => source.to_string(),
            LimitError::Contacts { source, .. } => source.to_string(),
            LimitError::Incomplete { reason, .. } => reason.clone(),
            LimitError::NoPeak { lo_hz, hi_hz, .. } => {
                format!("no converged point in the peak window {lo_hz} .. {hi_hz} Hz")
            }
        }
    }
}
