//! The two-dimensional Jenkins element: friction in the tangent plane of a 3D contact, sampled
//! (this module's march, `jenkins-2d-sampled`) or event-resolved ([`resolved`], `jenkins-2d`).
//!
//! A contact point of a 3D model moves in its tangent plane along a path u(τ) ∈ ℝ² (two
//! tangential relative displacements u₁, u₂ along an orthonormal tangent basis t₁, t₂) and along
//! its normal by v(τ). The element is the isotropic generalisation of the paper's Jenkins element
//! (Eqs. 4-6): a tangential spring kₜ in series with a Coulomb slider w ∈ ℝ² whose force is
//! bounded by the friction circle |T| ≤ μN, and the same normal law N = max(kₙ v, 0).
//!
//! # The march
//!
//! At each sample the elastic predictor is T* = kₜ (u_k − w). If |T*| ≤ μN_k the contact sticks
//! (T = T*, the slider stays). Otherwise it slips, and the force returns radially onto the
//! friction circle, T = μN_k · T*/|T*|, with the slider moved so that T = kₜ (u_k − w). An open
//! sample (N_k = 0) has T = 0 and the slider follows u (the spring is unloaded). Radial return
//! is the exact closest-point projection for an isotropic kₜ; the predictor is measured from the
//! slider, as in the 1D march of [`crate::contact::aft`], so a drop of N between samples is
//! returned onto the smaller circle at once.
//!
//! The march starts at τ = 0 with the slider placed so that T(0) = μN(0)·m, with m a vector in
//! the unit disc (the 2D initial tangential state; m = ±e along a tangent direction e are the
//! paper's limit cases, Eqs. 14-15). Unlike the 1D law, a slip does not erase the slider's past
//! in 2D: it resets the slider along the slip direction only, and contracts its offset across
//! it by μN/|T*| < 1. The state therefore approaches its periodic value geometrically (slowly
//! when the slip is slight), so the march does not only repeat the period: with the derivative
//! A = ∂w_end/∂w_start of the period map (propagated along the march, 2×2), each period restarts
//! (where det(I − A) > 10⁻⁶ at once, elsewhere after 200 plain periods: a nearly singular
//! I − A most often means a transient slip followed by a state the map barely moves, which
//! plain periods settle with the derivative of their own history, and restarting such points
//! by Newton early was measured to break the harmonic-balance Newton on
//! `tests/it/friction_2d.rs`'s out-of-plane case at 160.1 Hz)
//! from a safeguarded Newton update of the fixed-point equation Φ(w) = w: the step
//! (I − A)⁻¹(Φ(w) − w) is tried whole, then halved, until the period started there ends with a
//! smaller mismatch |Φ(w) − w| (a backtracking line search); when no fraction down to 1/32
//! does, the plain update w ← Φ(w) is taken and Newton rests for 1, 2, 4 … 64 periods. The
//! march ends when a period started at w ends within the periodicity tolerance of w, as the 1D
//! one does; Newton steps then polish the fixed point to round-off, and its forces are the
//! steady-state forces. The tolerance is relative to the point's own motion scale or, when
//! larger, to the problem's force scale over kₜ ([`MarchSettings::length_scale`](crate::contact::aft::MarchSettings::length_scale)), so that a
//! barely loaded point is not held to a drift below round-off of the problem.
//!
//! Degenerate fixed points. A point whose slip runs (nearly) along one direction contracts
//! the slider's offset o across it by μN/|T*| = 1 − O(o²) per slip (exactly so where the path
//! only grazes the friction circle, nearly where it barely slips), so the plain period map
//! converges like n^(−1/2) (drift per period n^(−3/2)) and I − A is singular, or nearly, at the
//! fixed point. The mismatch across the slip direction then behaves like −c·o³ − ε·o + b; the
//! line-searched Newton step takes o to 2/3 o per period while the cubic term dominates and
//! converges quadratically once ε·o or b does. Measured on single points (unit tests): a point
//! that barely slips (by 10⁻⁴ of its stick amplitude; det(I − A) above 10⁻⁶) settles in 43
//! periods against its own scale, where the plain march does not settle in 2000 (and needs
//! 16 742 to a finer tolerance measured against a problem's scale, landing on the same
//! forces); a straight
//! path just off t₁ that slips by 10⁻³ or 10⁻⁶ of its stick amplitude, started across the path,
//! settles in 11 or 18 periods on the 1D law's forces (to 8e-13 of μN).
//!
//! # Analytic Jacobian
//!
//! Along the final period the derivative of the slider D = ∂w/∂(û₁, û₂, v̂, w_start) (a 2 × (3
//! n_blocks + 2) matrix) is propagated sample by sample with the consistent tangent of the
//! return mapping:
//!
//! * stick:  dT = kₜ (du − dw), dw unchanged;
//! * slip:   dT = μ dN d + (μN/|T*|)(I − d dᵀ) kₜ (du − dw), d = T*/|T*|, then dw = du − dT/kₜ;
//! * open:   dT = 0, dw = du;
//! * closed: dN = kₙ dv (or kₙ dv̂₀ with a constant normal load),
//!
//! with du, dv rows of the synthesis matrix E. The steady state's own start is a function of the
//! coefficients: at the fixed point, dw_start = A dw_start + B dx, so dw_start = (I − A)⁻¹ B dx,
//! with A and B the last two and the first 3 n_blocks columns of D at the period's end. This
//! holds however small det(I − A) is, as long as the start is the fixed point to round-off
//! (a Newton polish cut the mismatch at least tenfold: quadratic convergence); the forces'
//! derivative is then right even where the slider's own is ill-conditioned (checked against
//! central differences on a barely slipping, nearly one-directional point). Where the polish
//! does not converge quadratically (an exactly degenerate fixed point: o shrinks only to 2/3
//! per step) and det(I − A) ≤ 10⁻⁶, the singular direction is left out, dw_start =
//! (I − A)⁺ B dx: the offset across the slip direction is held, as the 1D law holds it. A contact
//! that stuck over the whole first period (A = I: the slider never moved) keeps the initial
//! condition instead, dw_start = du₀ − (μ/kₜ) m dN₀. The force coefficients' Jacobian is then
//! dT̂ = Σ_k P_k dT_k with the w_start columns folded in.
//!
//! Which derivative where. The fixed-point derivative needs a final period that *slips* (by
//! more than rounding, at one sample or many) or lifts off: then the period map attracts and
//! its fixed point, not the history, sets the start. A final period stuck throughout (at most
//! touching the friction circle by rounding) rests on one of a continuum of periodic states,
//! the one its transient chose: its derivative is the history's, carried through the plain
//! periods (dw_start = du₀ − (μ/kₜ) m dN₀ propagated through every transient slip), and a march
//! that used Newton restarts is marched again with plain periods, since a Newton step can land
//! elsewhere on the stuck set's boundary (measured: two corners 60 samples apart for
//! coefficients 10⁻¹¹ m apart, relative error 0.57 against differences). A final period that
//! touches in two directions apart (a corner of the stuck set, det(I − A) > 10⁻⁶) keeps the
//! fixed-point derivative of its polished corner, which is where the plain march converges.
//! Where the plain re-march of a stuck state does not settle in the budget (it creeps) but the
//! Newton restarts did, their stuck state is kept, with the slider held in the directions
//! where I − A is singular: a valid periodic state, though not necessarily the plain
//! transient's (measured needed at `tests/it/friction_2d.rs`'s out-of-plane case at 160.1 Hz and
//! at the 3D blade pair's `left-17` at 852.78 Hz, whose plain marches creep). In
//! between: a slight slip at a few samples per turning point is a genuine slip and takes the
//! fixed-point derivative, resolved by Newton where I − A is ill-conditioned, and the
//! property tests check it down to an excess of 1.2e-4 of the stick amplitude (1 slipping
//! sample of 128 per turning point); below that the forces' noise at the periodicity
//! tolerance and the slip's kinks leave no difference step that can check it (measured at an
//! excess of 1.5e-5 with other harmonics on top: 1.0e-5 to 1.1e-5 relative error for steps of
//! 10⁻⁶ and 3·10⁻⁶, 4.5e-6 at 10⁻⁵).
//!
//! Why by hand: no crate marches a 2D Jenkins element or differentiates through its periodic
//! steady state. The Jacobian costs O(N · n_blocks²) per contact (the 1D element's anchor
//! structure, which makes its Jacobian O(N log N + n_blocks²), does not exist in 2D because the
//! slip direction rotates); synthesis and analysis use the dense sample basis E, P, which for
//! the harmonic counts of harmonic balance costs no more than that.
//!
//! The files: [`workspace`] (the workspace and its evaluation), [`march`] (one period of the
//! march), [`settle`] (the march to the periodic steady state, with Newton restarts) and
//! [`jacobian`] (the analytic Jacobian through it) for the sampled law (`jenkins-2d-sampled`);
//! [`resolved`] for the event-resolved law (`jenkins-2d`, [`crate::contact::events2d`]),
//! whose periodic state is found by Newton on the continuous period map, and [`grazing`] for
//! the corner of the stuck set its march creeps into at the onset of slip, found directly.

#[cfg(test)]
mod fixtures;
mod grazing;
mod jacobian;
mod march;
mod resolved;
mod settle;
mod workspace;

pub use crate::contact::point::Jenkins2dLaw;
pub use workspace::{Aft2dWorkspace, DEFAULT_MAX_PERIODS};
