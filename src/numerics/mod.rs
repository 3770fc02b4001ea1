//! Numerics: linear solves and factorisations (dense, sparse, bordered), Newton and
//! pseudo-arc-length continuation.
//!
//! Lowest layer: uses no other layer of the crate. It knows operators R(x, λ) with a Jacobian
//! ([`ParametricResidual`]), never friction or harmonics.

pub mod continuation;
pub mod jacobian;
pub mod linalg;
