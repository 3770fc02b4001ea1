//! Response limits among multiple solutions: the two-point method per damper side (paper §3).
//!
//! A fully stuck contact's static tangential force T⁰ is not unique (paper §3.1); with a wedge
//! damper, the static balance couples it to the normal load N⁰ of the other side (Eqs. 11-13),
//! so when one side is fully stuck and the other slips (§3.2, case 3) the response is not
//! unique either. The limits come from the two extreme initial tangential states of the stuck
//! side, T(τ=0) = ±μN(τ=0) (Eqs. 14-15), which put the slipping side at its maximum N⁰
//! (closest to stuck) and minimum N⁰ (closest to free).
//!
//! A [`LimitCase`] assigns one initial state m ∈ [−1, 1] to every contact point (the march of
//! that point starts at T = mμN). The two-point method solves the cases "m = +1 on every side"
//! and "m = −1 on every side": wherever one side is stuck, the pair holds both of its limit
//! states. Intermediate cases may be uniform (the same m everywhere) or given per damper side
//! or per contact point (e.g. m = +0.5 on the side that sticks, the scene's m elsewhere).
//! The curves are put on a common frequency grid (each grid point solved exactly by Newton),
//! every grid point is classified (unique or multiple-solution regime, which sides stick or
//! slip), and in the multiple-solution regime each limit curve is labelled by the static normal
//! load it gives the slipping side. Which label has the larger amplitude is not assumed: near
//! the optimum pre-load the two cross (paper Fig. 15b).
//!
//! Whether the limits really bound the other solutions is checked, not assumed: a scan over
//! intermediate states per side reports the largest excursion outside the band, and the
//! response envelope (`[limits] envelope`) finds the largest and smallest amplitude over all
//! initial states per side or per point by bounded optimisation.
//!
//! Every case is attempted whatever the others do: a curve that fails or stops before the end
//! frequency keeps its finished points and says how it ended ([`CurveStatus`]); the band and
//! the classification exist where both limit curves were solved.
//!
//! The files, in the order they build on each other:
//!
//! | file | job |
//! | --- | --- |
//! | `error` | [`LimitError`] |
//! | `case` | the cases: [`LimitCase`], [`CaseSpec`], [`two_point_cases`], [`scan_cases`] |
//! | `peak` | resonance peaks: [`Peak`], [`refine_peak`], [`linear_resonance`] |
//! | `curve` | one attempted case: [`CaseCurve`], [`CurveStatus`], [`attempt_case`], [`solve_case`] |
//! | `side` | damper sides: [`SideStatics`], [`SideState`], [`LimitLabel`], [`Regime`] |
//! | `grid` | the common grid: [`GridPoint`], [`on_grid`], [`classify`] |
//! | `bounds` | the bound check: [`BoundCheck`], [`check_bounds`] |
//! | `sensitivity` | dA/dm by the implicit-function theorem: [`AmplitudeSensitivity`], [`amplitude_sensitivity`] |
//! | `envelope` | the response envelope over m ∈ [−1, 1]^k (the unit disc per group with 2D points): [`Envelope`], [`envelope()`], [`envelope_at`], [`SearchLayout`] |
//! | `loops` | contact loops: [`HysteresisLoop`], [`hysteresis`], [`LoopSet`] |
//! | `run` | the analysis: [`LimitSettings`], [`analyse`], [`LimitAnalysis`], [`ScannedCase`], [`Variability`] |
//!
//! Every item is re-exported here, so callers name it `limits::Item` whatever file holds it.

pub mod bounds;
pub mod case;
pub mod curve;
pub mod envelope;
pub mod error;
pub mod grid;
pub mod loops;
pub mod peak;
pub mod run;
pub mod sensitivity;
pub mod side;

pub use bounds::{check_bounds, BoundCheck, ExcessStates};
pub use case::{scan_cases, signed, two_point_cases, CaseSpec, LimitCase};
pub use curve::{attempt_case, solve_case, CaseCurve, CurveStatus};
pub use envelope::{
    envelope, envelope_at, envelope_at_with, group_states, Envelope, EnvelopeAtPeak, EnvelopeBound,
    EnvelopeCheck, EnvelopeInputs, EnvelopeMode, EnvelopePoint, EnvelopeSeeds, SearchLayout,
};
pub use error::LimitError;
pub use grid::{classify, on_grid, GridPoint, GridSolution};
pub use loops::{hysteresis, HysteresisLoop, HysteresisRequest, LoopSet};
pub use peak::{linear_resonance, refine_peak, Peak};
pub use run::{analyse, LimitAnalysis, LimitSettings, ScannedCase, Variability};
pub use sensitivity::{
    amplitude_sensitivity, amplitude_sensitivity_of, residual_derivative, residual_derivative_of,
    AmplitudeSensitivity, ResidualDerivative, SensitivityError, StateVariable,
};
pub use side::{side_states, side_statics, LimitLabel, Regime, SideState, SideStatics};
