//! What continuation produces and reports: converged path points, the events an observer
//! receives, how a run ended, and why a corrector or a run failed.

use std::f64::consts::PI;

use crate::numerics::linalg::LinearSolveError;
use crate::numerics::residual::ParametricResidual;

/// Why a Newton corrector failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NewtonFailure {
    /// Iteration limit reached.
    #[error("no convergence in {iterations} iterations (relative residual {residual:.3e})")]
    MaxIterations {
        /// Iterations made.
        iterations: usize,
        /// Last relative residual.
        residual: f64,
    },
    /// The residual grew far beyond its starting value.
    #[error("diverged (relative residual {residual:.3e})")]
    Diverged {
        /// Relative residual when stopped.
        residual: f64,
    },
    /// A linear solve failed.
    #[error("{0}")]
    Linear(#[from] LinearSolveError),
    /// The operator failed to evaluate.
    #[error("{0}")]
    Evaluation(String),
    /// The tangent turned too sharply between two points (possible branch jump).
    #[error("tangent turned by {degrees:.1}° in one step")]
    SharpTurn {
        /// Angle between successive tangents.
        degrees: f64,
    },
    /// The corrector converged far from the predicted point (possible branch jump).
    #[error("corrector moved {distance:.3e} from the prediction, more than the step {step:.3e}")]
    FarCorrection {
        /// Scaled distance between predicted and corrected points.
        distance: f64,
        /// Step length.
        step: f64,
    },
}

/// Fatal continuation errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContinuationError {
    /// The first point could not be solved.
    #[error("no solution at the start frequency {freq_hz:.4} Hz: {reason}")]
    Start {
        /// Start frequency (Hz).
        freq_hz: f64,
        /// Cause.
        reason: NewtonFailure,
    },
    /// The step fell below the minimum: every step down to the minimum failed at the last
    /// converged point.
    #[error("continuation stalled at {freq_hz:.4} Hz (step {step:.3e} below minimum): {reason}")]
    Stalled {
        /// Frequency of the last converged point (Hz).
        freq_hz: f64,
        /// Step that failed.
        step: f64,
        /// Last failure.
        reason: NewtonFailure,
    },
    /// The run was stopped on request ([`crate::numerics::interrupt`]) before it reached its
    /// end.
    #[error("interrupted after {freq_hz:.4} Hz")]
    Interrupted {
        /// Frequency of the last converged point (Hz).
        freq_hz: f64,
    },
}

/// A converged point of the path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathPoint {
    /// Angular frequency ω (rad/s).
    pub omega: f64,
    /// Unknowns x.
    pub x: Vec<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// Final residual relative to the residual scale.
    pub residual: f64,
    /// Arc-length step that reached this point (0 for the first).
    pub step: f64,
}

impl PathPoint {
    /// Frequency in Hz.
    pub fn freq_hz(&self) -> f64 {
        self.omega / (2.0 * PI)
    }
}

/// Receives continuation events; writing results as they come is an observer's job.
pub trait Observer<S: ParametricResidual> {
    /// A point converged. The operator was last evaluated at this point.
    ///
    /// `normal` (length dim + 1), when the path's tangent at the point is known, is the
    /// hyperplane normal to the path there, as a covector on (x, ω): the points y = (x, ω) with
    /// Σᵢ normalᵢ (xᵢ − x_pᵢ) + normalₙ (ω − ω_p) = 0, ω in rad/s. It is the unit tangent t of
    /// the continuation's scaled space (x / x_scale, ω / 2π) divided by the scales, so that the
    /// hyperplane is the one orthogonal to the path in the arc length's own metric (the
    /// corrector's hyperplane of Eq. 9). None at points solved at a fixed frequency (the end
    /// frequency of a path).
    fn accepted(&mut self, _system: &mut S, _point: &PathPoint, _normal: Option<&[f64]>) {}
    /// A step was rejected and will be retried with `new_step`.
    fn rejected(&mut self, _freq_hz: f64, _step: f64, _new_step: f64, _reason: &NewtonFailure) {}
    /// dω/ds changed sign between the previous and this point.
    fn turning_point(&mut self, _freq_hz: f64) {}
    /// Whether the path has reached the observer's own end, asked after each accepted point:
    /// the run then stops there as at the end frequency ([`PathEnd::EndFrequency`]). A path
    /// whose range ends in a quantity other than λ (e.g. a nonlinear mode's amplitude at a DOF,
    /// whose continuation runs in the modal amplitude) ends where that quantity passes its end.
    fn reached_end(&self) -> bool {
        false
    }
}

/// An observer that does nothing.
pub struct NoObserver;
impl<S: ParametricResidual> Observer<S> for NoObserver {}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSummary {
    /// Converged points, in path order.
    pub points: Vec<PathPoint>,
    /// Frequencies (Hz) of turning points.
    pub turning_points: Vec<f64>,
    /// Rejected steps.
    pub rejected_steps: usize,
    /// Why the run stopped.
    pub end: PathEnd,
}

/// Reason a run stopped normally.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathEnd {
    /// Reached the end frequency.
    EndFrequency,
    /// The path turned back below the start frequency and ran on far below it (see
    /// `Continuation::left_range`): the range above was not covered.
    LeftRangeBelow,
    /// The point budget was used up.
    MaxPoints,
}
