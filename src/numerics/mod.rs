//! Numerics: linear solves and factorisations (dense, sparse, bordered), Newton and
//! pseudo-arc-length continuation.
//!
//! Lowest layer: uses no other layer of the crate. It knows operators R(x, λ) with a Jacobian
//! ([`ParametricResidual`]), never friction or harmonics.

pub mod broyden;
pub mod continuation;
pub mod jacobian;
pub mod linalg;
pub mod path;
pub mod residual;

pub use continuation::{Continuation, ContinuationSettings};
pub use jacobian::{AssembledJacobian, BorderedFactor, ImplicitFactor, ImplicitJacobian, Storage};
pub use path::{
    ContinuationError, NewtonFailure, NoObserver, Observer, PathEnd, PathPoint, PathSummary,
};
pub use residual::ParametricResidual;
