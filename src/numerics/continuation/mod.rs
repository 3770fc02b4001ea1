//! Newton's method with pseudo-arc-length continuation in the frequency (paper Eqs. 8-9).
//!
//! The path y(s) = (x(s), ω(s)) is followed in a scaled space where one unit of ω is 1 Hz
//! (ω/2π) and one unit of xᵢ is `x_scale[i]` (m), so step sizes read as "Hz-equivalent" arc
//! length. The scale is per unknown so that no block of unknowns (e.g. a large static part)
//! dominates the arc length and hides the change of the others.
//! Each step predicts along the unit tangent t, y_p = y + Δs·t, and corrects with Newton on
//!
//! R(x, ω) = 0,   tᵀ (y − y_p) = 0.
//!
//! A point converges when ‖R‖ ≤ tol_R·‖F_ex‖ and the scaled Newton step ≤ tol_y, or when
//! ‖R‖ ≤ tol_R·‖F_ex‖ and the full Newton step no longer lowers it (the step is then round-off
//! amplified by an ill-conditioned Jacobian near a lightly damped resonance). A failed
//! corrector (iteration limit, divergence, singular Jacobian, failed AFT) is not a result: the
//! step is cut and the reason reported to the observer; below the minimum step the run ends
//! with [`ContinuationError::Stalled`]. Turning points (sign changes of dω/ds) are reported and
//! traversed. Where the corrector fails at every step down to the minimum (a contact sample
//! changing state: the residual is only piecewise smooth), the path is resumed past the spot
//! by [`Continuation::corner`] (along the outgoing piece) or [`Continuation::leap`] (further
//! ahead), never on the path already followed: a point found behind the incoming direction
//! is kept only when a look-ahead step from it leaves that path (a sharp fold), since at a
//! contact transition such a point can lead straight back onto the incoming branch, which the
//! path would then retrace (and loop: back along the followed path and on again through the
//! same corners). "On the path" means near the polyline through all the points followed so far
//! and the same solution as the path's own at that frequency, by Newton: the other side of a
//! sharp fold may run within a fraction of a per cent of the side followed, and a branch may
//! come back onto a stretch followed long before. When neither is found, the path is taken on from its last point over a
//! narrow window around the spot, with the arc-length scales of a range that narrow, and past
//! the window with the range's again ([`Continuation::run`]). The spot is instead a *dead
//! end*, where the run ends with [`PathEnd::DeadEnd`] for the caller to go on past the highest
//! frequency reached (as after a path that wandered without progress), when it lies below that
//! frequency (behind a fold), or when a way back along the followed path was refused and either
//! no window is left to try or the frequency turned back and forth over the last points (the
//! path bouncing between corners of the sampled law, see `frequency_reversals`). A window
//! taken where a way back was refused holds its points back from the observer until the path
//! leaves it; a point of it that lands back on the path already followed, or the window
//! failing, drops them and ends the path at that dead end. A stall with no window left ends
//! the run with [`ContinuationError::Stalled`]. The last point is solved at exactly the end
//! frequency. A path runs down in
//! frequency when the end frequency is below the start (e.g. to fill in, back toward a fold, a
//! branch found past it).
//!
//! On large problems (at least [`ContinuationSettings::chord_min_unknowns`] unknowns) the corrector takes
//! chord iterations: the bordered Newton matrix factorised at one iterate is reused for the
//! next steps, with Broyden's secant updates (`BroydenUpdates`), as long as each cuts the
//! relative residual by at least a factor of 2; otherwise the Jacobian is evaluated and
//! factorised afresh at the current iterate. A chord step costs one residual and one solve
//! against an O(n³) factorisation of a Newton matrix that is dense in the contact DOFs of a
//! reduced model (single-precision factors where the storage keeps them, see
//! [`crate::hbm::schur`]). Where the border is eliminated by blocks (sparse and schur storage) the
//! last factorisation is carried over to the next continuation points (up to `CARRY_POINTS`)
//! with the new tangent as border; a carried factorisation whose full step does not lower the
//! residual is dropped at once. Fixed-frequency Newton takes chord steps the same way. The
//! convergence tests are the same, on the true residual, so the points are those of full
//! Newton; the iteration count reported (and used for step adaptation) counts three chord steps
//! as one iteration. The tangent at the corrected point is then solved with the corrector's
//! last factorisation (the same bordered system) instead of a new Jacobian.
//!
//! The files: [`settings`] (what a continuation is set up with), [`corrector`] (Newton on the
//! hyperplane and at a fixed frequency), [`predictor`] (the tangent and the step length),
//! [`events`] (range ends, turning back, no progress), [`recovery`] (corners, leaps and narrow
//! windows past a spot the corrector cannot pass), [`step`] (accepting a point, and the
//! observer's events, held back in a window) and [`run`] (the path, step by step).

mod corrector;
mod events;
#[cfg(test)]
mod fixtures;
mod predictor;
mod recovery;
mod run;
mod settings;
mod step;

pub use events::SAME_SOLUTION_TOLERANCE;
pub use settings::{AdaptiveScale, Continuation, ContinuationSettings, StagnationExit};
