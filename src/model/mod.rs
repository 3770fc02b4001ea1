//! Model: the checked problem a scene becomes, ready to solve.
//!
//! May use `crate::fe`, `crate::contact` and `crate::numerics`. It holds no analysis settings
//! beyond the frequency-response range and the formulation choice ([`Analysis`]); the limit
//! analysis and sweeps keep theirs in `crate::analysis` and `crate::study`.
//!
//! | module | main types | job |
//! |---|---|---|
//! | [`problem`] | [`Problem`], [`LinearModel`], [`Effects`], [`Analysis`], [`DofSplit`], [`FeOrigin`] | linear structure, contacts, loads, switched effects, DOF splits |
//! | [`matrix`] | `StructuralMatrix` | M, C, K in dense or sparse storage |
//! | [`reduce`] | `reduce`, `ReductionSettings` | Craig-Bampton reduction of a problem (crate `fricbound-reduction`) |

pub mod matrix;
pub mod problem;
pub mod reduce;

pub use problem::{
    Analysis, BeyondLinearRange, Coupling, DofSplit, Effects, ErrorEstimateSettings, FeOrigin,
    Formulation, HarmonicLoad, HillSolve, JacobianStrategy, LinearModel, ModeAnalysis, ModeChoice,
    Problem, StabilityMethod, CHORD_MIN_UNKNOWNS,
};
