//! Frequency-response runs: continuation of the harmonic balance over the scene's range, with
//! per-point outputs (amplitudes, peaks, contact states) handed to an observer as they come.
//!
//! The files, lowest first (each uses only those before it): [`checks`] (the judgements of
//! cuts, dead ends and leaps), [`status`] (what a run reports), [`observer`] (the run's
//! observer), [`scale`] (the arc length's scales), [`point`] (one point: its outputs, solving
//! it, path interpolation), [`cuts`] (how a branch ended and where it left the path),
//! [`branches`] (fills and bridges past jumps), [`landing`] (Newton past a point, compared
//! with the run), [`judge`] (the judgements once a run is over) and [`run`] (the driver).

mod branches;
mod checks;
mod cuts;
#[cfg(test)]
mod fixtures;
mod judge;
mod landing;
mod observer;
mod point;
mod run;
mod scale;
mod status;

/// Relative distance ‖c − c'‖ / ‖c‖ over all Fourier coefficients within which two solutions
/// converged by Newton at one frequency are the same solution ([`Landing::resolved_distance`]):
/// the continuation's own, which tells a sharp fold's other side from the path already
/// followed with it (measurements there).
pub use crate::numerics::continuation::SAME_SOLUTION_TOLERANCE;
pub use checks::{CutCheck, CutVerdict, FoldCheck, Landing, LeapCheck, RETRACE_TOLERANCE};
pub use judge::{DEAD_END_CHECK_STEP, LEAP_CHECK_POINTS};
pub use landing::{CUT_CHECK_FALLBACKS, CUT_CHECK_OFFSETS};
pub use observer::{FrfObserver, Silent};
pub use point::{
    amplitude_across_path, amplitude_on_path, bracket_on_path, interpolate_on_path, point_outputs,
    time_peak, PointSolver, ROUND_FOLD_CHORD, ROUND_FOLD_STEPS,
};
pub use run::solve;
pub use status::{
    accuracy_of, BranchEnd, FrfError, FrfPoint, FrfRun, GiveUpCause, GivenUp, Jump, JumpKind,
    PathCrossing,
};
