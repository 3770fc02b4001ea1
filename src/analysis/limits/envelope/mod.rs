//! The response envelope: at each frequency, the largest and smallest first-harmonic amplitude
//! of every output DOF over all admissible initial tangential states m ∈ [−1, 1]^k, with k one
//! m per damper side (`sides`) or per contact point (`points`).
//!
//! # 2D friction: the disc
//!
//! A group (side or point) with a 2D-friction point (`jenkins-2d`) has a vector m = (m₁, m₂) in
//! the unit disc (T(0) = μN(0)·m along t₁, t₂): two variables. The box search runs on
//! s ∈ [−1, 1]² mapped onto the disc by the elliptical grid map
//! m₁ = s₁ √(1 − s₂²/2), m₂ = s₂ √(1 − s₁²/2) ([`square_to_disc`]: smooth, one-to-one, the
//! square's edges onto the circle, s = (±1, 0) onto the limit states m = (±1, 0)), with the
//! gradient by the chain rule through it, and the moves to effective initial states mapped
//! back ([`disc_to_square`]). The starts of a 2D group are those of a 1D one placed on t₁
//! (m = (±1, 0) for the corners, the limit curves' states), plus, per 2D group, the two points
//! m = (0, ±1) on t₂ with every other group at 0. The 1D points of a group with 2D points share
//! its m₁ only. Cost: a 2D group adds one variable (one more sensitivity solve per evaluation
//! where it acts) and two starts per bound.
//!
//! The two-point method (paper §3.3, Eqs. 14-15) solves only the corners m = ±1 on every
//! side; the paper leaves the general search open (§3.3, §5). Here each bound is a box-
//! constrained optimisation ([`minimise_in_box`](crate::numerics::box_minimize::minimise_in_box): projected quasi-Newton) of A(m), where every
//! evaluation is a Newton solve of the harmonic balance at the frequency with that m, and the
//! gradient dA/dm comes from the implicit-function theorem ([`amplitude_sensitivity`](crate::analysis::limits::sensitivity::amplitude_sensitivity): one
//! extra solve with the Jacobian per acting group). Contacts that slip or separate somewhere in
//! the period forget their m (their gradient is exactly 0), so their m is not moved: the
//! search runs, in effect, over the sides or points that stick at the current iterate.
//!
//! A contact's m acts only within the range where the contact, started at T(0) = mμN(0), stays
//! stuck: beyond it the contact slips in the first periods of the march and then sticks with
//! its slider set by that slip, the same state as the march started at the range's edge
//! (T(0)/μN(0) of the steady state, [`AmplitudeSensitivity::effective`](crate::analysis::limits::sensitivity::AmplitudeSensitivity::effective)). Such a state is
//! re-solved at that edge m, where the gradient is the one-sided derivative into the range, and
//! the optimiser takes the edge as the bound of that m ([`minimise_in_box`](crate::numerics::box_minimize::minimise_in_box) moves to the point
//! an evaluation stands for). The limit curves m = ±1 are such states: the two-point method
//! takes the two ends of the stuck side's range.
//!
//! A(m) is only piecewise smooth (flat in the m of a contact once it slips) and can have several
//! local extrema, so each bound is sought from several starts: the corners of the box (all 2^k
//! of them up to k = 4, the two uniform corners beyond; with one m per point also the corners of
//! the sides' box, each side uniformly at ±1), the two limit curves' solutions, the
//! best and worst scanned cases of the bound scan at that frequency, and the optimum of the
//! previous grid frequency, and the centre m = 0 (warm start along the grid; the grid is cut into [`CHUNKS`]
//! stretches solved in parallel, so results do not depend on the thread count). Every state
//! solved on the way is a steady state of the structure, so the reported bound is the best
//! amplitude among all of them. Newton for a new m starts from the solved state with the
//! nearest m, and walks there in [`HOMOTOPY_STEPS`] steps of m when the direct solve fails.
//!
//! Cost: one point solver is built per stretch of the grid and per peak, and reused for every
//! evaluation there: only the contacts' initial states change between Newton solves
//! ([`HbmSystem::set_initial_states`](crate::hbm::HbmSystem::set_initial_states)), so the
//! operator, its Jacobian pattern and symbolic factorisation, the AFT plans and the arc-length
//! scaling (42 linear solves over the range) are built once, not once per evaluation. Each
//! evaluation costs one Newton solve and one extra solve per acting group.
//!
//! The files: [`report`] (what the envelope reports), [`search`] (the search over the square or
//! disc of initial states at one frequency) and [`run`] (the envelope over the range).

mod report;
mod run;
mod search;

pub use report::{
    Envelope, EnvelopeAtPeak, EnvelopeBound, EnvelopeCheck, EnvelopeMode, EnvelopePoint,
};
pub use run::{
    envelope, envelope_at, envelope_at_with, group_states, EnvelopeInputs, EnvelopeSeeds, CHUNKS,
};
pub use search::{
    disc_to_square, search_settings, square_to_disc, SearchLayout, EDGE_INSET, HOMOTOPY_STEPS,
};
