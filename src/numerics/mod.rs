//! Numerics: linear solves and factorisations, Newton and pseudo-arc-length continuation.
//!
//! The lowest layer: it uses no other layer of the crate. It knows operators R(x, λ) with a
//! Jacobian ([`ParametricResidual`]), never friction or harmonics; the harmonic balance
//! (`crate::hbm`) is one such operator.
//!
//! | module | main types | job |
//! |---|---|---|
//! | [`residual`] | [`ParametricResidual`] | the operator continuation works on |
//! | [`linalg`] | `checked_lu`, `PackedLu`, `LinearSolveError` | dense and sparse LU with singularity reported, norms |
//! | [`jacobian`] | [`AssembledJacobian`], [`BorderedFactor`], [`ImplicitJacobian`] | Jacobian storage (dense, sparse, implicit) and bordered solves |
//! | [`derivatives`] | `finite_difference_jacobian`, `check_operator_jacobian` | finite-difference Jacobians and derivative checks |
//! | [`continuation`] | [`Continuation`], [`ContinuationSettings`] | Newton at fixed λ, predictor-corrector continuation in λ |
//! | [`golden`] | [`golden::maximise`] | golden-section search for a maximum where evaluations may fail |
//! | [`box_minimize`] | [`box_minimize::minimise_in_box`] | projected quasi-Newton minimisation over a box, evaluations may fail |
//! | [`broyden`] | `BroydenUpdates` | secant updates of a factorised Newton matrix (chord steps) |
//! | [`path`] | [`PathPoint`], [`PathSummary`], [`Observer`], [`NewtonFailure`] | what continuation produces and reports |
//! | [`interrupt`] | `request`, `clear`, `requested` | a process-wide request to stop the runs in progress (Ctrl-C of an embedding caller) |
//! | [`work`] | `Work`, `WorkReading`, `reading` | process-wide counters of factorisations, solves and evaluations, for benchmarks |

pub mod box_minimize;
pub mod broyden;
pub mod continuation;
pub mod derivatives;
pub mod golden;
pub mod interrupt;
pub mod jacobian;
pub mod linalg;
pub mod path;
pub mod residual;
pub mod work;

pub use continuation::{Continuation, ContinuationSettings};
pub use jacobian::{AssembledJacobian, BorderedFactor, ImplicitFactor, ImplicitJacobian, Storage};
pub use path::{
    ContinuationError, NewtonFailure, NoObserver, Observer, PathEnd, PathPoint, PathSummary,
};
pub use residual::ParametricResidual;
