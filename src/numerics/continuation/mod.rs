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
//! corrector (iteration limit, divergence, singular Jacobian, failed AFT), a correction
//! further from the prediction than the step, or a tangent turned by more than 45° in one
//! step (a jump to another branch; not where the half step lands on the same straight
//! piece, a corner of the path) cuts the step in half and is reported to the observer;
//! below the minimum step the run ends with [`ContinuationError::Stalled`](crate::numerics::path::ContinuationError::Stalled). An accepted step
//! sets the next from Newton's iterations, the turn of the tangent and the change of the
//! watched output amplitudes. Turning points (sign changes of dω/ds) are reported and
//! followed. The tangent keeps the sign of det [J; tᵀ] along the path where the
//! factorisation gives it (dense LU, the schur formulation's reduced LU and its low-rank
//! factorisation; see
//! `Continuation::orient`), else it is oriented along the previous tangent. The last point
//! is solved at exactly the end frequency. A path runs down in
//! frequency when the end frequency is below the start (e.g. to fill in, back toward a fold,
//! a branch found past it), and a path that turns back at a fold and runs half the range
//! behind its start ends there ([`PathEnd::LeftRangeBelow`](crate::numerics::path::PathEnd::LeftRangeBelow)).
//!
//! The event-resolved contact laws make the residual continuously differentiable wherever a
//! contact slips or lifts off, so Newton converges to the tolerance and plain step control
//! follows the folds. One seam is left: where a contact's slider changes what anchors it
//! ([`crate::contact::events`]), mostly where a contact goes from stuck all period to slipping
//! and its periodic state changes from the one its initial state sets to the one its slip
//! sets, the path has a corner. Where the steps are cut to the minimum at such a
//! corner, the path is taken on past it on a sphere about the last point
//! ([`Continuation::turn_corner`]); only where that fails too does the run stall. A sampled
//! contact law (`jenkins-1d-sampled`, `jenkins-2d-sampled`) has a kink wherever a transition
//! crosses a time sample, and may stall there.
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
//! [`events`] (range ends and Newton's stagnation exit), [`corner`] (past a corner of the
//! path), [`step`] (accepting a point) and [`run`] (the path, step by step).

mod corner;
mod corrector;
mod events;
#[cfg(test)]
mod fixtures;
mod predictor;
mod run;
mod settings;
mod step;

pub use settings::{AdaptiveScale, Continuation, ContinuationSettings, StagnationExit};
