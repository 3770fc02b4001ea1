//! Time integration of the equations of motion, as an independent check of a harmonic-balance
//! point (validation ladder step 4 of the design notes).
//!
//! The same equations the harmonic balance solves,
//!
//! ```text
//! M q̈ + C q̇ + K q + F_c(q, w) = F_static + F_h(t),     F_h(t) = Σ (cos·cos hωt + sin·sin hωt)
//! ```
//!
//! are integrated in time with the Newmark average-acceleration scheme (trapezoidal rule,
//! β = 1/4, γ = 1/2: unconditionally stable and non-dissipative for the linear part, second-order
//! accurate), with a fixed number of steps per excitation period. The contact forces are implicit:
//! each step solves the Newmark residual
//!
//! ```text
//! R(q₁) = M a₁ + C v₁ + K q₁ + F_c(q₁, w₀) − F(t₁),
//! a₁ = 4/dt² (q₁ − q₀ − dt v₀) − a₀,   v₁ = 2/dt (q₁ − q₀) − v₀,
//! ```
//!
//! by Newton with the consistent tangent 4/dt² M + 2/dt C + K + K_c. F_c is the contact law of
//! [`crate::contact`] (paper Eqs. 4-6) as a return mapping per contact point: N = max(kₙ v, 0)
//! (v = aₙ·q − g; bilateral without lift-off), trial T = kₜ (u − w₀); |T| ≤ μN stick, otherwise
//! T = ±μN (slip) and the slider moves to w₁ = u − T/kₜ; an open contact (N ≤ 0) carries no
//! tangential force and its slider follows u. This is exactly the sample-by-sample march of the
//! AFT ([`crate::contact::aft`]), here driven by the integrated motion instead of a prescribed
//! periodic one. Only variable normal load is supported (a constant normal load is defined from
//! the 0th harmonic of a periodic motion, which a time integration does not have).
//!
//! A point with the 2D law (`jenkins-2d`) has u, w, T ∈ ℝ² in its tangent plane (components
//! along t₁, t₂) and the same mapping with the radial return of [`crate::contact::aft2d`]:
//! trial T* = kₜ (u − w₀); |T*| ≤ μN stick, otherwise T = μN T*/|T*| and w₁ = u − T/kₜ; its
//! consistent tangent is ∂T/∂u = (μN/|T*|) kₜ (I − d dᵀ), ∂T/∂v = μ kₙ d with d = T*/|T*|. A 1D
//! point is the same mapping with the second components 0 (d = ±1, I − d dᵀ = 0: the 1D slip
//! tangent 0), so one function serves both laws and gives the 1D results unchanged. The slider
//! state of a problem ([`TimeState::sliders`]) holds one coordinate per 1D point and two per 2D
//! point, in contact order ([`slider_offsets`]).
//!
//! Integration goes period by period (τ = ωt; period starts at τ = 2πp) until the state at the
//! period start (q, q̇/ω) changes by less than a tolerance relative to the largest first-harmonic
//! amplitude, or a budget of periods runs out. The last period's samples are then projected on
//! harmonics 0..H (rectangle rule on the uniform grid, exact for trigonometric polynomials of
//! degree < steps/2); the energy of the dynamic part outside harmonics 1..H, relative to the
//! dynamic part's total, tells whether the motion is periodic at the excitation's period.
//!
//! [`verify_point`] starts on a harmonic-balance solution (positions and velocities at τ = 0
//! from its coefficients; slider positions by marching the contact law on its periodic motion
//! from T(0) = m μ N(0), as the AFT does: for a 2D point by the AFT's own 2D march,
//! [`crate::contact::aft2d::Aft2dWorkspace`], whose slider at the start of its periodic period
//! is the slider at τ = 0) and integrates twice, with `steps_per_period` and twice as many
//! steps: the change of the first-harmonic amplitudes is the reported dt error.
//!
//! The files: [`settings`] (what a verification takes and its errors), [`contact`] (the contact
//! forces in time, by return mapping), [`newmark`] (the integrator), [`start`] (the starting
//! state from a harmonic-balance point or the statics) and [`integrate`](mod@integrate) (to the steady state).

mod contact;
mod integrate;
mod newmark;
mod settings;
mod start;

pub use contact::{slider_offsets, TimeState};
pub use integrate::{
    fourier, integrate, verify_from, verify_point, ContactLoop, PointVerification, TimeResponse,
};
pub(crate) use newmark::Newmark;
pub use newmark::{MAX_MONODROMY_STEPS, MIN_MONODROMY_STEPS};
pub use settings::{VerifyError, VerifySettings, MAX_VERIFY_DOFS};
pub use start::{hbm_state, static_state};

/// How a verified case is named in a status: `<freq> Hz`, or `<freq> Hz (m = <m>)` for a case
/// started with every contact's initial tangential state set to m.
pub fn case_name(freq_hz: f64, initial_state: Option<f64>) -> String {
    match initial_state {
        Some(m) => format!("{freq_hz} Hz (m = {m})"),
        None => format!("{freq_hz} Hz"),
    }
}

/// Why a set of verified cases is incomplete, as `fricbound verify` reports it (exit code 3):
/// each case (named by [`case_name`]) that failed (no verification) or whose time integration
/// did not settle within its period budget, in order, joined by `, `; None when every case
/// settled. A case that settled away from the HBM point (`hbm_difference` above the stay
/// tolerance) is a result, not an incomplete run.
pub fn incomplete_reason<'a>(
    cases: impl IntoIterator<Item = (String, Option<&'a PointVerification>)>,
) -> Option<String> {
    let problems: Vec<String> = cases
        .into_iter()
        .filter_map(|(name, v)| match v {
            None => Some(format!("{name} failed")),
            Some(v) if !v.fine.settled => Some(format!("{name} did not settle")),
            Some(_) => None,
        })
        .collect();
    (!problems.is_empty()).then(|| problems.join(", "))
}
