//! Frequency-response runs: continuation of the harmonic balance over the scene's range, with
//! per-point outputs (amplitudes, peaks, contact states) handed to an observer as they come.
//!
//! The files, lowest first (each uses only those before it): [`status`] (what a run reports),
//! [`observer`] (the run's observer), [`scale`] (the arc length's scales), [`point`] (one
//! point: its outputs, solving it, path interpolation), [`branches`] (the branch found past a
//! fold the path did not come back from) and [`run`] (the driver).

mod branches;
mod observer;
mod point;
mod run;
mod scale;
mod status;

pub use observer::{FrfObserver, Silent};
pub use point::{
    amplitude_across_path, amplitude_on_path, bracket_on_path, interpolate_on_path, point_outputs,
    time_peak, PointSolver,
};
pub use run::solve;
pub use status::{accuracy_of, FrfError, FrfPoint, FrfRun, Jump, PathCrossing};
