//! Model: the checked problem, structural matrices, DOF splits and Craig-Bampton reduction of a
//! problem.

pub mod matrix;
pub mod problem;
pub mod reduce;

pub use problem::{
    Analysis, Coupling, DofSplit, Effects, FeOrigin, Formulation, HarmonicLoad, JacobianStrategy,
    LinearModel, Problem, CHORD_MIN_UNKNOWNS,
};
