//! Why a nonlinear mode could not be computed.

use crate::hbm::HbmError;
use crate::numerics::NewtonFailure;

/// Why a nonlinear-mode run could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NonlinearModeError {
    /// The harmonic balance could not be built or evaluated.
    #[error("{0}")]
    Hbm(#[from] HbmError),
    /// The harmonic set has no first harmonic.
    #[error("nonlinear modes need the first harmonic in the harmonic set ([harmonics])")]
    NoFirstHarmonic,
    /// No mode of that number.
    #[error("mode {asked} asked, the structure at rest has {available} elastic modes")]
    NoSuchMode {
        /// Mode asked (1-based).
        asked: usize,
        /// Elastic modes.
        available: usize,
    },
    /// The phase DOF does not move in the linear mode.
    #[error("DOF `{dof}` is a node of mode {mode}: it cannot fix the phase (choose another analysis.dof)")]
    NodeAtDof {
        /// DOF name.
        dof: String,
        /// Mode number.
        mode: usize,
    },
    /// The static state at rest did not converge.
    #[error("static state at rest: {0}")]
    Statics(String),
    /// The linear eigenvalue problem failed.
    #[error("linear modes at rest: {0}")]
    Eigen(String),
    /// Bad amplitude range.
    #[error("analysis.amplitude: need 0 < low < high (m), got [{low:e}, {high:e}]")]
    BadRange {
        /// Low end (m).
        low: f64,
        /// High end (m).
        high: f64,
    },
    /// The first point (the linear mode at the lowest amplitude) did not converge.
    #[error("no nonlinear mode at the lowest amplitude: {0}")]
    Start(NewtonFailure),
}
