//! Errors of the harmonic-balance layer: evaluating the residual (the AFT), forming the
//! formulation, solving the statics.

use crate::contact::aft::AftError;
use crate::hbm::formulation::RelativeCoordinatesError;
use crate::numerics::linalg::LinearSolveError;

/// Errors while evaluating or solving the harmonic balance.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HbmError {
    /// The AFT of a contact failed.
    #[error("contact `{contact}`: {source}")]
    Aft {
        /// Contact name.
        contact: String,
        /// Cause.
        source: AftError,
    },
    /// A linear solve failed.
    #[error("linear solve: {0}")]
    Linear(#[from] LinearSolveError),
    /// The problem does not admit the formulation asked for.
    #[error("formulation: {0}")]
    Formulation(#[from] RelativeCoordinatesError),
    /// The Hill stability of a converged point could not be computed (the eigen solve).
    #[error("Hill stability: {0}")]
    Stability(String),
    /// The static pre-solve of the uncoupled mode did not converge.
    #[error("static pre-solve did not converge in {iterations} iterations (relative residual {residual:.3e})")]
    StaticNotConverged {
        /// Iterations made.
        iterations: usize,
        /// Final residual norm relative to the static load.
        residual: f64,
    },
}
