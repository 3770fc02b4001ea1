//! Harmonic balance: residual, Jacobian patterns and assembly, the formulations and the operator.

pub mod condensed;
pub mod formulation;
pub mod operator;
pub mod pattern;
pub mod schur;
pub mod system;

pub use system::{
    check_jacobian, check_operator_jacobian, finite_difference_jacobian, static_solve, HbmError,
    HbmSystem, JacobianCheck,
};
