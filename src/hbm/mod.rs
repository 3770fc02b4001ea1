//! Harmonic balance: the residual R(x, ω) = D(ω) x + F̂_c(x) − F̂_ex (paper Eq. 7), its
//! Jacobian, and the formulations that store and solve it.
//!
//! May use `crate::model`, `crate::fe`, `crate::contact` and `crate::numerics`; implements
//! `crate::numerics::ParametricResidual`, so continuation follows it without knowing it.
//!
//! | module | main types | job |
//! |---|---|---|
//! | [`system`] | [`HbmSystem`], [`check_jacobian`] | residual and Jacobian on all DOFs (dense or sparse storage) |
//! | [`pattern`] | `JacobianLayout`, `ContactSlots` | the fixed Jacobian pattern and the slots every Newton iteration fills |
//! | [`formulation`] | `Problem::formulation`, `check_relative_coordinates` | which formulation `auto` picks, and whether schur applies |
//! | [`condensed`] | `CondensedHbm` | unknowns on the contact DOFs only, the rest eliminated per harmonic |
//! | [`schur`] | `RelativeCoordinates`, `SchurJacobian`, `ReducedSolver` | all DOFs, each linear solve reduced to the relative contact coordinates (dense, or by structure for many contacts) |
//! | [`operator`] | `HbmOperator` | the operator a run solves, dispatching to the formulation |
//! | [`cost`] | `CostEstimate`, `estimate` | size of the unknowns, memory of one Newton iteration and time per point, estimated before anything is allocated |
//! | [`statics`] | [`static_solve`], [`statics::StaticSystem`], [`statics::static_point_2d`] | the static pre-solve of the uncoupled mode (1D and 2D friction points from rest) |
//! | [`error`] | [`HbmError`] | evaluation and solve errors |

pub mod condensed;
pub mod cost;
pub mod error;
pub mod formulation;
pub mod operator;
pub mod pattern;
pub mod schur;
pub mod statics;
pub mod system;

pub use error::HbmError;
pub use statics::static_solve;
pub use system::{check_jacobian, HbmSystem};
