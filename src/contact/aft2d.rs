//! AFT of the two-dimensional Jenkins element: friction in the tangent plane of a 3D contact.
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
//! `tests/friction_2d.rs`'s out-of-plane case at 160.1 Hz)
//! from a safeguarded Newton update of the fixed-point equation Φ(w) = w: the step
//! (I − A)⁻¹(Φ(w) − w) is tried whole, then halved, until the period started there ends with a
//! smaller mismatch |Φ(w) − w| (a backtracking line search); when no fraction down to 1/32
//! does, the plain update w ← Φ(w) is taken and Newton rests for 1, 2, 4 … 64 periods. The
//! march ends when a period started at w ends within the periodicity tolerance of w, as the 1D
//! one does; Newton steps then polish the fixed point to round-off, and its forces are the
//! steady-state forces. The tolerance is relative to the point's own motion scale or, when
//! larger, to the problem's force scale over kₜ ([`MarchSettings::length_scale`]), so that a
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
//! transient's (measured needed at `tests/friction_2d.rs`'s out-of-plane case at 160.1 Hz and
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

use crate::contact::aft::{AftError, MarchReport, MarchSettings};
use crate::contact::harmonic::{HarmonicSet, SampleBasis};
use crate::contact::{ContactEffects, ContactState, NormalLoad};

pub use crate::contact::point::Jenkins2dLaw;

/// Default budget of periods of the 2D march. Plain periods creep where the path barely
/// leaves the stuck region (grazing: measured 422 periods for a circle of 0.996 times the
/// stick radius, sampled 128 times, before the Newton restarts were line-searched) or slips
/// along one direction; the safeguarded Newton restarts settle such points in tens of periods
/// (module doc), and the budget bounds the cost of a point where they do not help.
pub const DEFAULT_MAX_PERIODS: usize = 2000;

/// What happened at one sample of the final period.
#[derive(Debug, Clone, Copy, PartialEq)]
enum SampleKind {
    /// Stuck: the slider did not move.
    Stick,
    /// Slipping along the unit direction `direction` of the predictor, with `ratio` = μN/|T*|
    /// (< 1), the contraction of the slider offset across the slip direction.
    Slip { direction: [f64; 2], ratio: f64 },
    /// Separated (no tangential force, slider follows u).
    Open,
}

/// One period of the march: where it left the slider and what it saw.
#[derive(Debug, Clone, Copy)]
struct PeriodOutcome {
    /// Slider position at the period's end (m).
    slider_end: [f64; 2],
    /// ∂w_end/∂w_start, row-major 2×2.
    period_map_derivative: [f64; 4],
    /// Whether any sample slipped (rounding slips included).
    any_slip: bool,
    /// Samples that slipped by more than rounding.
    margin_slips: usize,
    /// Samples with the contact open.
    open_samples: usize,
}

/// Workspace for the AFT of 2D-friction contacts sharing one harmonic set and sample count.
pub struct Aft2dWorkspace {
    set: HarmonicSet,
    basis: SampleBasis,
    n_samples: usize,
    kinds: Vec<SampleKind>,
    normal_active: Vec<bool>,
    /// Derivative of the slider, 2 × (3 n_blocks + 2), row-major (scratch of the Jacobian).
    slider_derivative: Vec<f64>,
    /// Σ P_k dT_k over 3 n_blocks + 2 columns, row-major (2 n_blocks) × (3 n_blocks + 2).
    force_derivative: Vec<f64>,
    /// Tangential relative displacement samples u₁(τ_k), u₂(τ_k) (m).
    pub u: [Vec<f64>; 2],
    /// Normal relative displacement samples v(τ_k) (m).
    pub v: Vec<f64>,
    /// Tangential force samples T₁, T₂ of the final period (N).
    pub t: [Vec<f64>; 2],
    /// Normal force samples N(τ_k) (N).
    pub n: Vec<f64>,
    /// Fourier coefficients of T₁ and T₂, one per block (N).
    pub t_hat: [Vec<f64>; 2],
    /// Fourier coefficients of N, one per block (N).
    pub n_hat: Vec<f64>,
    /// ∂(T̂₁, T̂₂)/∂(û₁, û₂, v̂), row-major (2 n_blocks) × (3 n_blocks) (N/m): rows T̂₁ then
    /// T̂₂, columns û₁, û₂, v̂.
    pub dt_dx: Vec<f64>,
    /// ∂N̂/∂v̂, row-major n_blocks × n_blocks (N/m).
    pub dn_dv: Vec<f64>,
    /// Slider position at the start of the final (periodic) period (m).
    pub slider_start: [f64; 2],
    /// Slider position of the initial condition T(0) = μN(0)·m (m).
    initial_slider: [f64; 2],
    /// The point's own motion scale (m): the path's extent plus μ N_max / kₜ (the scale of the
    /// test of a slip by mere rounding).
    march_scale: f64,
    /// Length scale of the periodicity tolerance (m): the own scale, or the problem's force
    /// scale over kₜ when larger ([`MarchSettings::length_scale`]).
    tolerance_scale: f64,
    /// March limits (the same meaning as for the 1D march).
    pub settings: MarchSettings,
    /// Whether periods restart from Newton updates of the fixed point (always, except in the
    /// tests that compare with the plain march).
    newton_restarts: bool,
}

impl Aft2dWorkspace {
    /// Creates the sample basis and buffers for `set` sampled at `n_samples` points per period.
    ///
    /// # Panics
    /// If `n_samples ≤ 2·max_harmonic` (validated scenes never do this).
    #[track_caller]
    pub fn new(set: &HarmonicSet, n_samples: usize) -> Self {
        assert!(
            n_samples > 2 * set.max_harmonic(),
            "AFT needs more than 2·H samples per period"
        );
        let nb = set.n_blocks();
        let columns = 3 * nb + 2;
        Self {
            set: set.clone(),
            basis: SampleBasis::new(set, n_samples),
            n_samples,
            kinds: vec![SampleKind::Open; n_samples],
            normal_active: vec![false; n_samples],
            slider_derivative: vec![0.0; 2 * columns],
            force_derivative: vec![0.0; 2 * nb * columns],
            u: [vec![0.0; n_samples], vec![0.0; n_samples]],
            v: vec![0.0; n_samples],
            t: [vec![0.0; n_samples], vec![0.0; n_samples]],
            n: vec![0.0; n_samples],
            t_hat: [vec![0.0; nb], vec![0.0; nb]],
            n_hat: vec![0.0; nb],
            dt_dx: vec![0.0; 2 * nb * 3 * nb],
            dn_dv: vec![0.0; nb * nb],
            slider_start: [0.0; 2],
            initial_slider: [0.0; 2],
            march_scale: 0.0,
            tolerance_scale: 0.0,
            settings: MarchSettings {
                max_periods: DEFAULT_MAX_PERIODS,
                ..MarchSettings::default()
            },
            newton_restarts: true,
        }
    }

    /// The harmonic set of the coefficients.
    pub fn harmonic_set(&self) -> &HarmonicSet {
        &self.set
    }

    /// Samples per period.
    pub fn n_samples(&self) -> usize {
        self.n_samples
    }

    /// Whether sample `k` of the last evaluation slipped.
    pub fn sample_is_slipping(&self, k: usize) -> bool {
        matches!(self.kinds[k], SampleKind::Slip { .. })
    }

    /// Evaluates the contact forces (and, if asked, their Jacobian) for the coefficients of the
    /// two tangential relative displacements and the normal one.
    ///
    /// `v_coefficients` already include the gap in the constant block. Results are left in
    /// [`Self::t_hat`], [`Self::n_hat`], the sample buffers and, with `jacobian`, in
    /// [`Self::dt_dx`] and [`Self::dn_dv`].
    pub fn evaluate(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        u_coefficients: [&[f64]; 2],
        v_coefficients: &[f64],
        jacobian: bool,
    ) -> Result<MarchReport, AftError> {
        let nb = self.set.n_blocks();
        for (signal, coefficients) in self.u.iter_mut().zip(u_coefficients) {
            synthesize(&self.basis, coefficients, signal);
        }
        synthesize(&self.basis, v_coefficients, &mut self.v);
        if self
            .u
            .iter()
            .flatten()
            .chain(self.v.iter())
            .any(|x| !x.is_finite())
        {
            return Err(AftError::NonFinite);
        }
        let constant_v = self
            .set
            .constant_block()
            .map(|j| v_coefficients[j])
            .unwrap_or(0.0);
        for k in 0..self.n_samples {
            let v = match effects.normal_load {
                NormalLoad::Variable => self.v[k],
                NormalLoad::Constant => constant_v,
            };
            let (force, active) = effects.normal_force(law.kn, v);
            self.n[k] = force;
            self.normal_active[k] = active;
        }
        let (report, origin) = self.march(law)?;
        for a in 0..2 {
            analyze(&self.basis, &self.t[a], &mut self.t_hat[a]);
        }
        analyze(&self.basis, &self.n, &mut self.n_hat);
        if jacobian {
            self.accumulate_jacobian(law, effects, origin);
        }
        debug_assert_eq!(self.t_hat[0].len(), nb);
        Ok(report)
    }

    /// Marches periods until the slider state repeats, first with Newton-accelerated restarts
    /// and, when that lands in a state whose derivative needs the plain history (a final period
    /// without slip, or a fixed point that barely attracts), again with plain periods only.
    fn march(&mut self, law: &Jenkins2dLaw) -> Result<(MarchReport, StartOrigin), AftError> {
        let range = |x: &[f64]| {
            let (lo, hi) = x
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                    (a.min(y), b.max(y))
                });
            hi - lo
        };
        let nmax = self.n.iter().fold(0.0_f64, |a, &x| a.max(x.abs()));
        self.march_scale =
            range(&self.u[0]).hypot(range(&self.u[1])) + law.mu * nmax / law.kt + f64::MIN_POSITIVE;
        self.tolerance_scale = self.settings.length_scale(self.march_scale, law.kt);

        // Initial condition: T(0) = μ N(0) m, i.e. w = u₀ − μ N₀ m / kₜ.
        let limit0 = law.mu * self.n[0].max(0.0);
        let u0 = [self.u[0][0], self.u[1][0]];
        self.initial_slider = if limit0 > 0.0 {
            [
                u0[0] - law.initial_state[0] * limit0 / law.kt,
                u0[1] - law.initial_state[1] * limit0 / law.kt,
            ]
        } else {
            u0
        };
        match self.march_from_initial(law, self.newton_restarts, false)? {
            Some(result) => Ok(result),
            None => match self.march_from_initial(law, false, false) {
                Ok(Some(result)) => Ok(result),
                // The plain march creeps towards its stuck state without settling: keep the
                // stuck state the Newton restarts reached (a periodic state as valid as any of
                // the stuck set, though not the one the plain transient would choose), with
                // the slider held where I − A is singular (`DegenerateFixedPoint`).
                Ok(None) | Err(AftError::NotSettled { .. }) => self
                    .march_from_initial(law, true, true)?
                    .ok_or(AftError::NotSettled {
                        periods: self.settings.max_periods.max(2),
                        drift: f64::NAN,
                    }),
                Err(error) => Err(error),
            },
        }
    }

    /// One attempt of [`Self::march`]. Returns None when Newton restarts were used and the
    /// settled state is a function of the march's history (its final period does not slip
    /// beyond rounding nor lift off: a transient slip, then stuck), which only plain periods
    /// make continuous in the coefficients and differentiable.
    ///
    /// With `allow_newton`, each period's start is a safeguarded Newton update of the
    /// fixed-point equation Φ(w) = w: the full step (I − A)⁻¹(Φ(w) − w), shortened to the
    /// point's motion scale, is tried first and halved until a period started there ends with
    /// a smaller mismatch (a backtracking line search on |Φ(w) − w|); when no fraction down to
    /// [`MIN_STEP_FRACTION`] does, the plain update Φ(w) is taken and Newton rests for a
    /// number of periods that doubles at each such failure. A *degenerate* fixed point (slip
    /// along one direction, I − A singular there, the mismatch across the slip direction
    /// ≈ −c·o³ + b in the offset o) is then reached by Newton steps that shrink o to 2/3 per
    /// period (and quadratically once b dominates), where plain periods shrink it like n^(−1/2).
    fn march_from_initial(
        &mut self,
        law: &Jenkins2dLaw,
        allow_newton: bool,
        keep_newton_stuck_state: bool,
    ) -> Result<Option<(MarchReport, StartOrigin)>, AftError> {
        let scale = self.march_scale;
        let tol = self.settings.periodicity_tolerance * self.tolerance_scale;
        let first = self.march_period(law, self.initial_slider, true, scale);
        if !first.any_slip && first.open_samples == 0 {
            self.slider_start = self.initial_slider;
            let report = MarchReport {
                state: ContactState::Stuck,
                periods: 1,
            };
            return Ok(Some((report, StartOrigin::InitialCondition)));
        }
        let max_periods = self.settings.max_periods.max(2);
        let mut start = first.slider_end;
        let mut drift = f64::INFINITY;
        let mut used_newton = false;
        let mut trial: Option<NewtonTrial> = None;
        // Plain periods left before Newton is tried again, and the rest after the next failure.
        let mut newton_rest = 0_usize;
        let mut next_rest = 1_usize;
        for period in 2..=max_periods {
            let outcome = self.march_period(law, start, false, scale);
            let mismatch = [
                outcome.slider_end[0] - start[0],
                outcome.slider_end[1] - start[1],
            ];
            drift = mismatch[0].hypot(mismatch[1]);
            if drift <= tol {
                // A Newton step that cut the mismatch tenfold: converging quadratically.
                let quadratic = trial.is_some_and(|t| drift <= 0.1 * t.base_drift);
                return self.settle(
                    law,
                    start,
                    outcome,
                    mismatch,
                    used_newton,
                    quadratic,
                    period,
                    keep_newton_stuck_state,
                );
            }
            if let Some(t) = trial.take() {
                // Sufficient decrease of the mismatch (false for NaN, which is rejected).
                let decreased = drift < (1.0 - 1e-4 * t.fraction) * t.base_drift;
                if !decreased {
                    let fraction = 0.5 * t.fraction;
                    if fraction >= MIN_STEP_FRACTION {
                        start = [
                            t.base[0] + fraction * t.step[0],
                            t.base[1] + fraction * t.step[1],
                        ];
                        trial = Some(NewtonTrial { fraction, ..t });
                    } else {
                        // Newton does not help from here: a plain update, then a rest.
                        start = t.base_end;
                        newton_rest = next_rest;
                        next_rest = (2 * next_rest).min(MAX_NEWTON_REST);
                    }
                    continue;
                }
            }
            // Where I − A is nearly singular, plain periods first: they settle most such
            // points (a transient slip, then a state the period map barely moves) with the
            // derivative of their own history; Newton only for a point that keeps creeping.
            let newton_worth_it = well_conditioned(outcome.period_map_derivative)
                || period > PLAIN_PERIODS_BEFORE_DEGENERATE_NEWTON;
            let newton = if allow_newton && newton_rest == 0 && newton_worth_it {
                newton_step(mismatch, outcome.period_map_derivative, scale)
            } else {
                if newton_worth_it {
                    newton_rest = newton_rest.saturating_sub(1);
                }
                None
            };
            match newton {
                Some(step) => {
                    used_newton = true;
                    trial = Some(NewtonTrial {
                        base: start,
                        base_end: outcome.slider_end,
                        base_drift: drift,
                        step,
                        fraction: 1.0,
                    });
                    start = [start[0] + step[0], start[1] + step[1]];
                }
                None => start = outcome.slider_end,
            }
        }
        Err(AftError::NotSettled {
            periods: max_periods,
            drift,
        })
    }

    /// Ends a march whose period started at `start` repeated within the tolerance (its
    /// `outcome` is the last period marched): polishes a fixed point reached with slip by
    /// Newton steps and decides where the start's derivative comes from.
    ///
    /// Where det(I − A) > [`FIXED_POINT_CONDITION`] the fixed-point derivative is used, as is
    /// the plain history's where the march got there by plain periods. Below it, after Newton
    /// restarts, the fixed point counts as *resolved* when a Newton step cut the mismatch at
    /// least tenfold (`quadratic`, or in the polish): Newton converges quadratically there,
    /// the start is exact to round-off and the fixed-point derivative (I − A)⁻¹ B is the
    /// derivative of the forces however small det(I − A) is. At a degenerate fixed point a
    /// step only cuts it to about (2/3)³; the derivative then leaves out the direction in
    /// which I − A is singular ([`StartOrigin::DegenerateFixedPoint`]).
    #[allow(clippy::too_many_arguments)]
    fn settle(
        &mut self,
        law: &Jenkins2dLaw,
        mut start: [f64; 2],
        mut outcome: PeriodOutcome,
        mut mismatch: [f64; 2],
        used_newton: bool,
        quadratic: bool,
        period: usize,
        keep_newton_stuck_state: bool,
    ) -> Result<Option<(MarchReport, StartOrigin)>, AftError> {
        let scale = self.march_scale;
        let slipped = outcome.any_slip || outcome.open_samples > 0;
        let well = well_conditioned(outcome.period_map_derivative);
        if !slips_beyond_rounding(&outcome) {
            // Stuck throughout the final period (at most touching the friction circle by
            // rounding): the slider rests where the transient left it, one of a continuum of
            // periodic states (every point of the stuck set is one), so the state is a function
            // of the march's history. A history with Newton restarts is not a continuous
            // function of the coefficients (a step can land on another part of the stuck
            // set's boundary: measured on a grazing circle, two corners 60 samples apart for
            // coefficients 10⁻¹¹ m apart), so such a state is marched again with plain periods.
            if used_newton && keep_newton_stuck_state {
                let origin = if well {
                    StartOrigin::FixedPoint
                } else {
                    StartOrigin::DegenerateFixedPoint
                };
                self.slider_start = start;
                return Ok(Some((self.report(&outcome, period), origin)));
            }
            if used_newton {
                return Ok(None);
            }
        }
        if !well && !slips_beyond_rounding(&outcome) {
            // Touching along (nearly) one direction only: the position along the stuck set's
            // boundary is the transient's, whose derivative only the history gives. (Touching
            // in two directions apart, a corner of the stuck set, I − A is well conditioned and
            // the corner is the fixed point the plain march converges to.)
            let report = self.report(&outcome, period);
            self.slider_start = start;
            return Ok(Some((report, StartOrigin::History { periods: period })));
        }
        let mut drift = mismatch[0].hypot(mismatch[1]);
        let mut resolved = quadratic;
        if slipped && (well || used_newton) {
            // The forces' derivative assumes an exact fixed point: polish it to round-off.
            let round_off = 64.0 * f64::EPSILON * (start[0].hypot(start[1]) + scale);
            let mut marched_last = true;
            for _ in 0..POLISH_STEPS {
                if drift <= round_off {
                    break;
                }
                let Some(step) = newton_step(mismatch, outcome.period_map_derivative, scale) else {
                    break;
                };
                let polished = [start[0] + step[0], start[1] + step[1]];
                let again = self.march_period(law, polished, false, scale);
                let change = [
                    again.slider_end[0] - polished[0],
                    again.slider_end[1] - polished[1],
                ];
                let new_drift = change[0].hypot(change[1]);
                // A polished period must still be one whose start solves Φ(w) = w: slipping
                // (beyond rounding, unless I − A is well conditioned) or lifting off.
                let still_slipping = if well {
                    again.any_slip || again.open_samples > 0
                } else {
                    slips_beyond_rounding(&again)
                };
                let keeps_condition = !well || well_conditioned(again.period_map_derivative);
                let not_worse = new_drift <= drift;
                if !not_worse || !still_slipping || !keeps_condition {
                    marched_last = false;
                    break;
                }
                let cut = new_drift <= 0.1 * drift;
                resolved |= cut;
                (start, outcome, mismatch, drift) = (polished, again, change, new_drift);
                if !cut {
                    // Linear convergence: a degenerate fixed point; further steps gain little.
                    break;
                }
            }
            if !marched_last {
                // The sample buffers hold a rejected polish: march the accepted start again.
                outcome = self.march_period(law, start, false, scale);
            }
        }
        let origin = if well_conditioned(outcome.period_map_derivative) {
            StartOrigin::FixedPoint
        } else if !slips_beyond_rounding(&outcome) {
            // The polish keeps only periods that slip beyond rounding here, but should the
            // accepted period be stuck after all, the same rule as above holds.
            if used_newton {
                return Ok(None);
            }
            StartOrigin::History { periods: period }
        } else if !used_newton {
            StartOrigin::History { periods: period }
        } else if resolved {
            StartOrigin::FixedPoint
        } else {
            StartOrigin::DegenerateFixedPoint
        };
        self.slider_start = start;
        Ok(Some((self.report(&outcome, period), origin)))
    }

    /// The march's report for a final period `outcome` reached at period `period`.
    fn report(&self, outcome: &PeriodOutcome, period: usize) -> MarchReport {
        let state = if outcome.open_samples == self.n_samples {
            ContactState::Open
        } else if outcome.open_samples > 0 {
            ContactState::StickSlipLiftoff
        } else if outcome.margin_slips > 0 {
            ContactState::StickSlip
        } else {
            ContactState::Stuck
        };
        MarchReport {
            state,
            periods: period,
        }
    }

    /// Marches one period from the slider position `start`, filling the force samples and
    /// sample kinds. `initial` marks the first period, whose sample 0 is the initial condition.
    fn march_period(
        &mut self,
        law: &Jenkins2dLaw,
        start: [f64; 2],
        initial: bool,
        scale: f64,
    ) -> PeriodOutcome {
        let mut w = start;
        // ∂w/∂w_start, row-major 2×2.
        let mut a = [1.0, 0.0, 0.0, 1.0];
        let mut outcome = PeriodOutcome {
            slider_end: start,
            period_map_derivative: a,
            any_slip: false,
            margin_slips: 0,
            open_samples: 0,
        };
        for k in 0..self.n_samples {
            let limit = law.mu * self.n[k].max(0.0);
            let u = [self.u[0][k], self.u[1][k]];
            if self.n[k] <= 0.0 {
                w = u;
                a = [0.0; 4];
                self.t[0][k] = 0.0;
                self.t[1][k] = 0.0;
                self.kinds[k] = SampleKind::Open;
                outcome.open_samples += 1;
                continue;
            }
            let predictor = [law.kt * (u[0] - w[0]), law.kt * (u[1] - w[1])];
            let magnitude = predictor[0].hypot(predictor[1]);
            // Sample 0 of the first period is the initial condition T = μN m, |m| ≤ 1.
            if magnitude <= limit || (initial && k == 0) {
                self.t[0][k] = predictor[0];
                self.t[1][k] = predictor[1];
                self.kinds[k] = SampleKind::Stick;
                continue;
            }
            let direction = [predictor[0] / magnitude, predictor[1] / magnitude];
            let ratio = limit / magnitude;
            self.t[0][k] = limit * direction[0];
            self.t[1][k] = limit * direction[1];
            w = [u[0] - self.t[0][k] / law.kt, u[1] - self.t[1][k] / law.kt];
            // dw' = (I − ratio (I − d dᵀ)) applied to … : with du = 0 and dN = 0,
            // dw' = −dT/kₜ = ratio (I − d dᵀ) dw.
            let p = [
                ratio * (1.0 - direction[0] * direction[0]),
                -ratio * direction[0] * direction[1],
                -ratio * direction[1] * direction[0],
                ratio * (1.0 - direction[1] * direction[1]),
            ];
            a = mat2_mul(p, a);
            self.kinds[k] = SampleKind::Slip { direction, ratio };
            outcome.any_slip = true;
            // A slip by rounding only (a limit case touching μN) is not a state change.
            if magnitude - limit > 1e-9 * (limit + law.kt * scale) {
                outcome.margin_slips += 1;
            }
        }
        outcome.slider_end = w;
        outcome.period_map_derivative = a;
        outcome
    }

    /// Assembles ∂T̂/∂x and ∂N̂/∂v̂ along the final period (see the module doc).
    fn accumulate_jacobian(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        origin: StartOrigin,
    ) {
        let nb = self.set.n_blocks();
        let ns = self.n_samples;
        let w_columns = 3 * nb;
        let columns = w_columns + 2;
        // The start's own derivative when it does not come from the fixed-point equation.
        let history_start = match origin {
            StartOrigin::InitialCondition => Some(self.initial_condition_derivative(law, effects)),
            StartOrigin::History { periods } => {
                Some(self.history_derivative(law, effects, periods))
            }
            StartOrigin::FixedPoint | StartOrigin::DegenerateFixedPoint => None,
        };
        let mut d = std::mem::take(&mut self.slider_derivative);
        let mut g = std::mem::take(&mut self.force_derivative);
        d.iter_mut().for_each(|x| *x = 0.0);
        g.iter_mut().for_each(|x| *x = 0.0);
        d[w_columns] = 1.0;
        d[columns + w_columns + 1] = 1.0;
        self.dn_dv.iter_mut().for_each(|x| *x = 0.0);
        let mut dn = vec![0.0; nb];
        let mut dt = vec![0.0; 2 * columns];
        for k in 0..ns {
            self.normal_row(law, effects, k, &mut dn);
            // ∂N̂/∂v̂ += P_k ⊗ dN_k.
            for j in 0..nb {
                let pj = self.basis.projection[j * ns + k];
                if pj != 0.0 {
                    for (o, x) in self.dn_dv[j * nb..(j + 1) * nb].iter_mut().zip(&dn) {
                        *o += pj * x;
                    }
                }
            }
            step_derivative(
                self.kinds[k],
                self.basis.row(k),
                &dn,
                law,
                nb,
                &mut d,
                &mut dt,
            );
            // Σ P_k ⊗ dT_k.
            for a in 0..2 {
                for j in 0..nb {
                    let pj = self.basis.projection[j * ns + k];
                    if pj == 0.0 {
                        continue;
                    }
                    let out = &mut g[(a * nb + j) * columns..(a * nb + j + 1) * columns];
                    for (o, x) in out.iter_mut().zip(&dt[a * columns..(a + 1) * columns]) {
                        *o += pj * x;
                    }
                }
            }
        }

        // dw_start as a 2 × 3nb matrix.
        let start = history_start.unwrap_or_else(|| {
            // The periodic start solves (I − A) dw_start = B (in the least-squares sense,
            // without the singular direction, at a degenerate fixed point).
            let a = [
                d[w_columns],
                d[w_columns + 1],
                d[columns + w_columns],
                d[columns + w_columns + 1],
            ];
            let m = [1.0 - a[0], -a[1], -a[2], 1.0 - a[3]];
            let inv = if origin == StartOrigin::DegenerateFixedPoint {
                pseudo_inverse(m, FIXED_POINT_CONDITION)
            } else {
                let det = m[0] * m[3] - m[1] * m[2];
                [m[3] / det, -m[1] / det, -m[2] / det, m[0] / det]
            };
            let mut start = vec![0.0; 2 * w_columns];
            for c in 0..w_columns {
                let b0 = d[c];
                let b1 = d[columns + c];
                start[c] = inv[0] * b0 + inv[1] * b1;
                start[w_columns + c] = inv[2] * b0 + inv[3] * b1;
            }
            start
        });
        // dT̂/dx = G_x + G_w · dw_start.
        for r in 0..2 * nb {
            let grow = &g[r * columns..(r + 1) * columns];
            let out = &mut self.dt_dx[r * w_columns..(r + 1) * w_columns];
            for c in 0..w_columns {
                out[c] = grow[c]
                    + grow[w_columns] * start[c]
                    + grow[w_columns + 1] * start[w_columns + c];
            }
        }
        self.slider_derivative = d;
        self.force_derivative = g;
    }

    /// dN_k as a row over the v̂ coefficients (zero where the normal spring is inactive).
    fn normal_row(&self, law: &Jenkins2dLaw, effects: ContactEffects, k: usize, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        if !self.normal_active[k] {
            return;
        }
        match effects.normal_load {
            NormalLoad::Variable => {
                for (o, e) in out.iter_mut().zip(self.basis.row(k)) {
                    *o = law.kn * e;
                }
            }
            NormalLoad::Constant => {
                if let Some(c) = self.set.constant_block() {
                    out[c] = law.kn;
                }
            }
        }
    }

    /// Derivative (2 × 3 n_blocks) of the initial slider w = u₀ − μ N₀ m / kₜ.
    fn initial_condition_derivative(
        &self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
    ) -> Vec<f64> {
        let nb = self.set.n_blocks();
        let w_columns = 3 * nb;
        let mut dn = vec![0.0; nb];
        self.normal_row(law, effects, 0, &mut dn);
        let mut start = vec![0.0; 2 * w_columns];
        for a in 0..2 {
            for (i, ei) in self.basis.row(0).iter().enumerate() {
                start[a * w_columns + a * nb + i] = *ei;
            }
            for (i, x) in dn.iter().enumerate() {
                start[a * w_columns + 2 * nb + i] -= law.mu * law.initial_state[a] * x / law.kt;
            }
        }
        start
    }

    /// Derivative (2 × 3 n_blocks) of the start of period `periods`, reached by plain periods
    /// from the initial condition: the march is repeated with the derivative carried along,
    /// then the final period is marched again so that the sample kinds are its own.
    fn history_derivative(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        periods: usize,
    ) -> Vec<f64> {
        let nb = self.set.n_blocks();
        let mut d = self.initial_condition_derivative(law, effects);
        let mut dt = vec![0.0; d.len()];
        let mut dn = vec![0.0; nb];
        let mut start = self.initial_slider;
        for period in 1..periods {
            let outcome = self.march_period(law, start, period == 1, self.march_scale);
            for k in 0..self.n_samples {
                self.normal_row(law, effects, k, &mut dn);
                step_derivative(
                    self.kinds[k],
                    self.basis.row(k),
                    &dn,
                    law,
                    nb,
                    &mut d,
                    &mut dt,
                );
            }
            start = outcome.slider_end;
        }
        self.march_period(law, start, periods == 1, self.march_scale);
        d
    }
}

/// Where the final period's slider start comes from, which fixes its derivative.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StartOrigin {
    /// Stuck over the whole first period: the initial condition T(0) = μN(0)·m.
    InitialCondition,
    /// The fixed point of the period map, reached with slip: dw = (I − A)⁻¹ B dx.
    FixedPoint,
    /// A degenerate fixed point (slip along one direction: I − A singular there, the start
    /// converged only to the tolerance, not to round-off): dw = (I − A)⁺ B dx with the
    /// pseudo-inverse leaving out the direction whose singular value is below
    /// [`FIXED_POINT_CONDITION`] (the slider's offset across the slip direction is held).
    DegenerateFixedPoint,
    /// The end of plain periods from the initial condition (a transient slip, then stuck; or a
    /// fixed point too weakly attracting for the fixed-point derivative).
    History {
        /// The final period's number (1-based).
        periods: usize,
    },
}

/// One sample of the derivative march. `d` is ∂w (2 rows × c columns, the first 3 n_blocks
/// over û₁, û₂, v̂); on return it is the derivative after the sample and `dt` (same shape) that
/// of the force T_k. `e` is the synthesis row E_k and `dn` the row of dN_k over v̂.
fn step_derivative(
    kind: SampleKind,
    e: &[f64],
    dn: &[f64],
    law: &Jenkins2dLaw,
    nb: usize,
    d: &mut [f64],
    dt: &mut [f64],
) {
    let columns = d.len() / 2;
    if let SampleKind::Open = kind {
        // dT = 0; the slider follows u: dw_a = E_k in the û_a columns.
        dt.iter_mut().for_each(|x| *x = 0.0);
        d.iter_mut().for_each(|x| *x = 0.0);
        for a in 0..2 {
            d[a * columns + a * nb..a * columns + (a + 1) * nb].copy_from_slice(e);
        }
        return;
    }
    // Elastic increment kₜ (du − dw) per row a: du_a is E_k in the û_a columns.
    for a in 0..2 {
        let row = &mut dt[a * columns..(a + 1) * columns];
        for (r, x) in row.iter_mut().zip(&d[a * columns..(a + 1) * columns]) {
            *r = -law.kt * x;
        }
        for (r, ei) in row[a * nb..(a + 1) * nb].iter_mut().zip(e) {
            *r += law.kt * ei;
        }
    }
    if let SampleKind::Slip { direction, ratio } = kind {
        // dT = ratio (I − d dᵀ) dp + μ d dN.
        for c in 0..columns {
            let p0 = dt[c];
            let p1 = dt[columns + c];
            let along = direction[0] * p0 + direction[1] * p1;
            dt[c] = ratio * (p0 - direction[0] * along);
            dt[columns + c] = ratio * (p1 - direction[1] * along);
        }
        for (i, x) in dn.iter().enumerate() {
            dt[2 * nb + i] += law.mu * direction[0] * x;
            dt[columns + 2 * nb + i] += law.mu * direction[1] * x;
        }
        // dw = du − dT/kₜ.
        for a in 0..2 {
            for c in 0..columns {
                d[a * columns + c] = -dt[a * columns + c] / law.kt;
            }
            for (r, ei) in d[a * columns + a * nb..a * columns + (a + 1) * nb]
                .iter_mut()
                .zip(e)
            {
                *r += ei;
            }
        }
    }
}

/// Whether a period slips by more than rounding at some sample or lifts off: where it does
/// not, the slider stays put over the period (it at most touches the friction circle) and its
/// position is whatever the transient left, not the solution of a fixed-point equation.
fn slips_beyond_rounding(outcome: &PeriodOutcome) -> bool {
    outcome.margin_slips > 0 || outcome.open_samples > 0
}

/// Whether I − A is safely invertible: the period map attracts in every direction (a
/// slider that barely moved over the period has A ≈ I).
fn well_conditioned(a: [f64; 4]) -> bool {
    let m = [1.0 - a[0], -a[1], -a[2], 1.0 - a[3]];
    let det = m[0] * m[3] - m[1] * m[2];
    det.abs() > FIXED_POINT_CONDITION
}

/// Smallest |det(I − A)| for which the fixed-point derivative is used at a fixed point that
/// is not resolved to round-off (below it: the plain history when no Newton step was taken,
/// else the degenerate fixed point's pseudo-inverse, which also uses it as its relative
/// singular-value floor). The product of the contraction factors 1 − μN/|T*| of one period
/// is then below 1e-6.
const FIXED_POINT_CONDITION: f64 = 1e-6;

/// Smallest fraction of a Newton step tried by the march's line search before it falls back
/// to a plain period.
const MIN_STEP_FRACTION: f64 = 1.0 / 32.0;

/// Longest rest (plain periods) of the march's Newton updates after repeated failures.
const MAX_NEWTON_REST: usize = 64;

/// Newton steps at most spent polishing a fixed point once the period repeats.
const POLISH_STEPS: usize = 4;

/// Plain periods marched before Newton restarts are tried where det(I − A) is below
/// [`FIXED_POINT_CONDITION`] (a point still creeping after them is taken as degenerate).
const PLAIN_PERIODS_BEFORE_DEGENERATE_NEWTON: usize = 200;

/// A Newton update of the slider start under test: the period started at
/// `base + fraction·step` is accepted when its mismatch is below `base_drift`.
#[derive(Debug, Clone, Copy)]
struct NewtonTrial {
    /// The last accepted start (m).
    base: [f64; 2],
    /// Φ(base), the plain update from it (m).
    base_end: [f64; 2],
    /// |Φ(base) − base| (m).
    base_drift: f64,
    /// The full Newton step (m).
    step: [f64; 2],
    /// Fraction of the step tried.
    fraction: f64,
}

/// Newton step (I − A)⁻¹ (Φ(w) − w) of the fixed-point equation, shortened to `max_length`
/// (the point's motion scale, beyond which no slider start is reachable); None when I − A
/// is exactly singular (no slip over the period) or the step is not finite.
fn newton_step(mismatch: [f64; 2], a: [f64; 4], max_length: f64) -> Option<[f64; 2]> {
    let m = [1.0 - a[0], -a[1], -a[2], 1.0 - a[3]];
    let det = m[0] * m[3] - m[1] * m[2];
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let step = [
        (m[3] * mismatch[0] - m[1] * mismatch[1]) / det,
        (-m[2] * mismatch[0] + m[0] * mismatch[1]) / det,
    ];
    let length = step[0].hypot(step[1]);
    if !length.is_finite() {
        return None;
    }
    let shrink = if length > max_length {
        max_length / length
    } else {
        1.0
    };
    Some([shrink * step[0], shrink * step[1]])
}

/// Pseudo-inverse of the row-major 2×2 matrix `m`, leaving out singular values below
/// `floor` times the largest: (MᵀM)⁺ Mᵀ from the eigenpairs of MᵀM.
fn pseudo_inverse(m: [f64; 4], floor: f64) -> [f64; 4] {
    // S = MᵀM, symmetric [[p, q], [q, r]].
    let p = m[0] * m[0] + m[2] * m[2];
    let q = m[0] * m[1] + m[2] * m[3];
    let r = m[1] * m[1] + m[3] * m[3];
    let mean = 0.5 * (p + r);
    let radius = (0.25 * (p - r) * (p - r) + q * q).sqrt();
    let largest = mean + radius;
    if largest <= 0.0 {
        return [0.0; 4];
    }
    // Eigenvector of the largest eigenvalue (and its normal for the other).
    let (x, y) = if q.abs() > 0.0 {
        (largest - r, q)
    } else if p >= r {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    let norm = x.hypot(y);
    let v1 = [x / norm, y / norm];
    let v2 = [-v1[1], v1[0]];
    let smallest = (mean - radius).max(0.0);
    let mut s_plus = [0.0; 4];
    for (value, v) in [(largest, v1), (smallest, v2)] {
        // Singular value σ = √value, kept when σ ≥ floor·σ_max.
        if value > 0.0 && value >= floor * floor * largest {
            s_plus[0] += v[0] * v[0] / value;
            s_plus[1] += v[0] * v[1] / value;
            s_plus[2] += v[1] * v[0] / value;
            s_plus[3] += v[1] * v[1] / value;
        }
    }
    // (MᵀM)⁺ Mᵀ.
    let mt = [m[0], m[2], m[1], m[3]];
    mat2_mul(s_plus, mt)
}

/// Product of two row-major 2×2 matrices.
fn mat2_mul(x: [f64; 4], y: [f64; 4]) -> [f64; 4] {
    [
        x[0] * y[0] + x[1] * y[2],
        x[0] * y[1] + x[1] * y[3],
        x[2] * y[0] + x[3] * y[2],
        x[2] * y[1] + x[3] * y[3],
    ]
}

/// Samples of a signal from its coefficients: out_k = E_k · c.
fn synthesize(basis: &SampleBasis, coefficients: &[f64], out: &mut [f64]) {
    for (k, o) in out.iter_mut().enumerate() {
        *o = basis
            .row(k)
            .iter()
            .zip(coefficients)
            .map(|(e, c)| e * c)
            .sum();
    }
}

/// Coefficients of a signal from its samples: out_j = Σ_k P_jk f_k.
fn analyze(basis: &SampleBasis, samples: &[f64], out: &mut [f64]) {
    let ns = basis.n_samples;
    for (j, o) in out.iter_mut().enumerate() {
        *o = basis.projection[j * ns..(j + 1) * ns]
            .iter()
            .zip(samples)
            .map(|(p, f)| p * f)
            .sum();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::aft::AftWorkspace;
    use crate::contact::JenkinsLaw;
    use std::f64::consts::PI;

    const KT: f64 = 1.0e5;
    const KN: f64 = 2.0e5;
    const MU: f64 = 0.3;

    fn law(m: [f64; 2]) -> Jenkins2dLaw {
        Jenkins2dLaw {
            kt: KT,
            kn: KN,
            mu: MU,
            initial_state: m,
        }
    }

    /// Coefficients over `set` from (block index, value) pairs.
    fn coefficients(set: &HarmonicSet, entries: &[(usize, f64)]) -> Vec<f64> {
        let mut c = vec![0.0; set.n_blocks()];
        for &(j, x) in entries {
            c[j] = x;
        }
        c
    }

    #[test]
    fn straight_motion_equals_the_1d_law() {
        let set = HarmonicSet::up_to(3);
        let ns = 64;
        let mut plane = Aft2dWorkspace::new(&set, ns);
        let mut line = AftWorkspace::new(&set, ns);
        let zero = vec![0.0; set.n_blocks()];
        // Stick-slip with variable N, lift-off, full stick, each from several initial states.
        let cases = [
            (
                vec![(0, 1e-6), (1, 8e-5), (2, 2e-5), (3, 1e-5)],
                vec![(0, 1e-4), (1, 3e-5), (4, 1e-5)],
            ),
            (
                vec![(1, 5e-5), (2, -3e-5)],
                vec![(0, 2e-5), (1, 4e-5), (2, 1e-5)],
            ),
            (vec![(1, 1e-6), (5, 2e-7)], vec![(0, 1e-4)]),
        ];
        for effects in [
            ContactEffects::default(),
            ContactEffects {
                normal_load: NormalLoad::Constant,
                liftoff: true,
            },
        ] {
            for (u_entries, v_entries) in &cases {
                let u = coefficients(&set, u_entries);
                let v = coefficients(&set, v_entries);
                for m in [-1.0, -0.4, 0.0, 0.7, 1.0] {
                    let law1 = JenkinsLaw {
                        kt: KT,
                        kn: KN,
                        mu: MU,
                        initial_state: m,
                    };
                    let r1 = line.evaluate(&law1, effects, &u, &v, true).unwrap();
                    let r2 = plane
                        .evaluate(&law([m, 0.0]), effects, [&u, &zero], &v, true)
                        .unwrap();
                    assert_eq!(r1.state, r2.state, "state at m = {m}");
                    let nb = set.n_blocks();
                    let scale = line.t_hat.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
                    for j in 0..nb {
                        assert!((plane.t_hat[0][j] - line.t_hat[j]).abs() < 1e-10 * scale);
                        assert!(plane.t_hat[1][j].abs() < 1e-10 * scale);
                        assert!((plane.n_hat[j] - line.n_hat[j]).abs() < 1e-10 * scale);
                        for i in 0..nb {
                            let d_u = plane.dt_dx[j * 3 * nb + i];
                            let d_v = plane.dt_dx[j * 3 * nb + 2 * nb + i];
                            let tol = 1e-9 * KN;
                            assert!(
                                (d_u - line.dt_du[j * nb + i]).abs() < tol,
                                "dT/du[{j}][{i}] at m = {m}: {d_u} vs {}",
                                line.dt_du[j * nb + i]
                            );
                            assert!((d_v - line.dt_dv[j * nb + i]).abs() < tol);
                            assert!((plane.dn_dv[j * nb + i] - line.dn_dv[j * nb + i]).abs() < tol);
                            // No coupling into the perpendicular direction.
                            assert!(plane.dt_dx[(nb + j) * 3 * nb + i].abs() < tol);
                            assert!(plane.dt_dx[(nb + j) * 3 * nb + 2 * nb + i].abs() < tol);
                        }
                    }
                }
            }
        }
    }

    /// Circular motion of radius q̂ under a constant N with kₜ q̂ > μN: the slider runs on a
    /// circle of radius ρ = √(q̂² − (μN/kₜ)²), T has magnitude μN and is perpendicular to the
    /// slider's radius, and the energy dissipated per cycle is 2π μN ρ.
    #[test]
    fn circular_motion_matches_the_closed_form() {
        let set = HarmonicSet::up_to(3);
        let v0 = 1e-4;
        let normal = KN * v0;
        let q = 2.0 * MU * normal / KT;
        let rho = (q * q - (MU * normal / KT).powi(2)).sqrt();
        let (cos_phi, sin_phi) = (rho / q, MU * normal / (KT * q));
        let u1 = coefficients(&set, &[(1, q)]);
        let u2 = coefficients(&set, &[(2, q)]);
        let v = coefficients(&set, &[(0, v0)]);
        let mut errors = Vec::new();
        for ns in [128, 512, 2048] {
            let mut aft = Aft2dWorkspace::new(&set, ns);
            for m in [[0.0, 0.0], [1.0, 0.0], [-0.6, 0.8]] {
                let report = aft
                    .evaluate(&law(m), ContactEffects::default(), [&u1, &u2], &v, false)
                    .unwrap();
                assert_eq!(report.state, ContactState::StickSlip);
                for k in 0..ns {
                    let t = aft.t[0][k].hypot(aft.t[1][k]);
                    assert!((t - MU * normal).abs() < 1e-9 * MU * normal, "|T| = {t}");
                }
                let limit = MU * normal;
                let expected = [
                    (aft.t_hat[0][1], limit * sin_phi),
                    (aft.t_hat[0][2], -limit * cos_phi),
                    (aft.t_hat[1][1], limit * cos_phi),
                    (aft.t_hat[1][2], limit * sin_phi),
                ];
                let error = expected
                    .iter()
                    .fold(0.0_f64, |e, (x, y)| e.max((x - y).abs() / limit));
                let dissipated = PI * q * (aft.t_hat[1][1] - aft.t_hat[0][2]);
                let energy_error = (dissipated / (2.0 * PI * limit * rho) - 1.0).abs();
                println!("N = {ns}, m = {m:?}: coefficient error {error:.3e}, energy error {energy_error:.3e}");
                errors.push((ns, error, energy_error));
            }
        }
        // The march sets the slider at the samples only, which lags the continuous slider by
        // about half a sample: the error is first order in 1/N (measured: the largest
        // coefficient error is 2.7/N of μN, the energy error 1.8/N).
        for &(ns, error, energy_error) in &errors {
            let bound = 4.0 / ns as f64;
            assert!(error < bound, "N = {ns}: coefficient error {error:.2e}");
            assert!(
                energy_error < bound,
                "N = {ns}: energy error {energy_error:.2e}"
            );
        }
        let at = |ns: usize| {
            errors
                .iter()
                .filter(|e| e.0 == ns)
                .fold(0.0_f64, |a, e| a.max(e.1))
        };
        assert!(at(2048) < at(128) / 10.0, "no convergence in N: {errors:?}");
    }

    /// Central differences of the steady-state force coefficients in every regime.
    fn check_jacobian(effects: ContactEffects, m: [f64; 2], x: [&[f64]; 3], what: &str) {
        let worst = jacobian_mismatch(effects, m, x, what, 1e-6);
        assert!(
            worst < 1e-5,
            "{what}: largest central-difference mismatch {worst:.2e}"
        );
    }

    /// Largest difference between the analytic force Jacobian and central differences with
    /// the step `relative_step` times the largest coefficient, relative to the largest entry
    /// (128 samples; the harmonic set follows from the coefficients' length, 2H + 1).
    fn jacobian_mismatch(
        effects: ContactEffects,
        m: [f64; 2],
        x: [&[f64]; 3],
        what: &str,
        relative_step: f64,
    ) -> f64 {
        let set = HarmonicSet::up_to((x[0].len() - 1) / 2);
        let nb = set.n_blocks();
        let ns = 128;
        let mut aft = Aft2dWorkspace::new(&set, ns);
        let mut point = [x[0].to_vec(), x[1].to_vec(), x[2].to_vec()];
        let report = aft
            .evaluate(&law(m), effects, [&point[0], &point[1]], &point[2], true)
            .unwrap();
        let analytic = aft.dt_dx.clone();
        let analytic_n = aft.dn_dv.clone();
        let size = analytic.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        let length = x
            .iter()
            .flat_map(|c| c.iter())
            .fold(0.0_f64, |a, v| a.max(v.abs()));
        let h = relative_step * length;
        let mut worst = 0.0_f64;
        for c in 0..3 * nb {
            let (which, i) = (c / nb, c % nb);
            let mut forces = [vec![0.0; 3 * nb], vec![0.0; 3 * nb]];
            for (s, sign) in [1.0, -1.0].into_iter().enumerate() {
                point[which][i] = x[which][i] + sign * h;
                aft.evaluate(&law(m), effects, [&point[0], &point[1]], &point[2], false)
                    .unwrap();
                forces[s][..nb].copy_from_slice(&aft.t_hat[0]);
                forces[s][nb..2 * nb].copy_from_slice(&aft.t_hat[1]);
                forces[s][2 * nb..].copy_from_slice(&aft.n_hat);
            }
            point[which][i] = x[which][i];
            for r in 0..2 * nb {
                let fd = (forces[0][r] - forces[1][r]) / (2.0 * h);
                worst = worst.max((fd - analytic[r * 3 * nb + c]).abs() / size);
            }
            if which == 2 {
                for r in 0..nb {
                    let fd = (forces[0][2 * nb + r] - forces[1][2 * nb + r]) / (2.0 * h);
                    worst = worst.max((fd - analytic_n[r * nb + i]).abs() / size);
                }
            }
        }
        println!(
            "{what} ({:?}, {} periods): central-difference mismatch {worst:.2e} of {size:.2e} N/m",
            report.state, report.periods
        );
        worst
    }

    #[test]
    fn jacobian_matches_central_differences_in_every_regime() {
        let set = HarmonicSet::up_to(3);
        let c = |e: &[(usize, f64)]| coefficients(&set, e);
        let variable = ContactEffects::default();
        let constant = ContactEffects {
            normal_load: NormalLoad::Constant,
            liftoff: true,
        };
        let stick_limit = MU * KN * 1e-4 / KT; // μN/kₜ at v₀ = 1e-4 m: 6e-5 m
                                               // Stuck: a small ellipse.
        check_jacobian(
            variable,
            [0.3, -0.2],
            [
                &c(&[(1, 0.2 * stick_limit)]),
                &c(&[(2, 0.1 * stick_limit), (3, 0.05 * stick_limit)]),
                &c(&[(0, 1e-4), (1, 1e-5)]),
            ],
            "stuck",
        );
        // Full slip with a rotating direction: a large circle, constant N.
        check_jacobian(
            constant,
            [0.0, 0.0],
            [
                &c(&[(1, 3.0 * stick_limit)]),
                &c(&[(2, 3.0 * stick_limit)]),
                &c(&[(0, 1e-4)]),
            ],
            "rotating slip",
        );
        // Stick-slip on an ellipse with a variable normal load and higher harmonics.
        check_jacobian(
            variable,
            [0.5, 0.5],
            [
                &c(&[(1, 1.5 * stick_limit), (4, 0.2 * stick_limit)]),
                &c(&[(2, 0.7 * stick_limit), (1, 0.3 * stick_limit)]),
                &c(&[(0, 1e-4), (1, 3e-5), (2, -2e-5)]),
            ],
            "stick-slip",
        );
        // Lift-off over part of the period.
        check_jacobian(
            variable,
            [-1.0, 0.0],
            [
                &c(&[(1, 1.2 * stick_limit)]),
                &c(&[(1, 0.5 * stick_limit), (2, 0.8 * stick_limit)]),
                &c(&[(0, 3e-5), (1, 6e-5), (3, 1e-5)]),
            ],
            "lift-off",
        );
        // Grazing: the ellipse just reaches the friction circle.
        check_jacobian(
            constant,
            [0.0, 0.0],
            [
                &c(&[(1, 1.05 * stick_limit)]),
                &c(&[(2, 0.3 * stick_limit)]),
                &c(&[(0, 1e-4)]),
            ],
            "grazing",
        );
    }

    /// Coefficients (H = 1) of a barely loaded point that barely slips: gross slip along t₁
    /// by 10⁻⁴ of the stick amplitude, a smaller motion along t₂, variable N. Its slip runs
    /// nearly along one direction and the slider's offset across it contracts by only
    /// 1 − O(10⁻⁴) per period: I − A is nearly singular at the fixed point.
    fn barely_slipping_point() -> ([Vec<f64>; 3], f64) {
        // N₀ = kₙ v₀ = 2e-5 N: μN₀/kₜ = 6e-11 m, against 50 N / kₜ = 5e-4 m for a problem.
        let v0 = 1e-10;
        let stick = MU * KN * v0 / KT;
        let a = (1.0 + 1e-4) * stick;
        (
            [
                vec![0.0, a, 0.0],
                vec![0.0, 0.0, 0.3 * a],
                vec![v0, 0.5 * v0, 0.0],
            ],
            MU * KN * v0,
        )
    }

    /// The nearly one-directional, barely slipping point settles by Newton restarts against
    /// its own scale (the plain march creeps: it does not settle in 2000 periods), and its
    /// forces are those of a plain march 20 times longer to a 10⁴ times finer tolerance.
    #[test]
    fn a_nearly_one_directional_slip_settles_by_newton_restarts() {
        let set = HarmonicSet::up_to(1);
        let ([u1, u2, v], friction) = barely_slipping_point();
        let point = law([0.0, 1.0]);
        let effects = ContactEffects::default();
        let mut plain = Aft2dWorkspace::new(&set, 128);
        plain.newton_restarts = false;
        let error = plain
            .evaluate(&point, effects, [&u1, &u2], &v, false)
            .unwrap_err();
        assert!(matches!(error, AftError::NotSettled { .. }), "{error:?}");
        let mut newton = Aft2dWorkspace::new(&set, 128);
        let report = newton
            .evaluate(&point, effects, [&u1, &u2], &v, true)
            .unwrap();
        assert_eq!(report.state, ContactState::StickSlip);
        assert!(report.periods <= 100, "{report:?}");
        // Reference: the plain march, 20 times the budget, the tolerance 10⁴ times finer but
        // relative to a problem's force scale (50 N), which it reaches.
        let mut reference = Aft2dWorkspace::new(&set, 128);
        reference.newton_restarts = false;
        reference.settings.force_scale = 50.0;
        reference.settings.periodicity_tolerance = 1e-16;
        reference.settings.max_periods = 20 * DEFAULT_MAX_PERIODS;
        let long = reference
            .evaluate(&point, effects, [&u1, &u2], &v, false)
            .unwrap();
        let difference = (0..2)
            .flat_map(|c| (0..set.n_blocks()).map(move |j| (c, j)))
            .fold(0.0_f64, |m, (c, j)| {
                m.max((newton.t_hat[c][j] - reference.t_hat[c][j]).abs())
            });
        println!(
            "Newton: {} periods; plain reference: {} periods; force difference {difference:.3e} N \
             = {:.3e} of μN₀",
            report.periods,
            long.periods,
            difference / friction
        );
        // Measured: 43 periods against 16 742, forces equal to the last bit.
        assert!(long.periods > 10 * report.periods, "{long:?}");
        assert!(difference < 1e-10 * friction, "{difference:.3e} N");
        assert!(newton.dt_dx.iter().all(|x| x.is_finite()));
    }

    /// At the nearly one-directional, barely slipping point the forces' Jacobian, through the
    /// ill-conditioned fixed-point derivative (I − A)⁻¹ B, matches central differences.
    #[test]
    fn the_jacobian_of_a_nearly_one_directional_slip_matches_central_differences() {
        let ([u1, u2, v], _) = barely_slipping_point();
        // Steps of 10⁻⁸ of the largest coefficient: the fixed point moves far (relative to the
        // step) for a small change of the path, so larger steps see its curvature.
        let worst = jacobian_mismatch(
            ContactEffects::default(),
            [0.0, 1.0],
            [&u1, &u2, &v],
            "barely slipping",
            1e-8,
        );
        assert!(worst < 1e-5, "{worst:.2e}");
    }

    /// A straight path along a direction just off t₁ (a tiny component along t₂) that barely
    /// slips, started with T(0) along t₂, across the path: the slip is exactly along one
    /// direction, the slider's offset across it starts at μN/kₜ and the period map is
    /// degenerate there (contraction 1 − O(offset²) per slip). Newton restarts settle it, and
    /// the forces are those of the 1D law along the path (the fixed point has no offset).
    #[test]
    fn an_exactly_one_directional_slip_settles_to_the_1d_forces() {
        let set = HarmonicSet::up_to(1);
        let nb = set.n_blocks();
        let stick = MU * KN * 1e-4 / KT;
        let angle: f64 = 1e-3;
        let (c, s) = (angle.cos(), angle.sin());
        let v = vec![1e-4, 0.0, 0.0];
        for excess in [1e-3, 1e-6] {
            let a = (1.0 + excess) * stick;
            let along = vec![0.0, a, 0.0];
            let (u1, u2) = (vec![0.0, c * a, 0.0], vec![0.0, s * a, 0.0]);
            let mut plane = Aft2dWorkspace::new(&set, 128);
            let report = plane
                .evaluate(
                    &law([0.0, 1.0]),
                    ContactEffects::default(),
                    [&u1, &u2],
                    &v,
                    true,
                )
                .unwrap();
            let mut line = AftWorkspace::new(&set, 128);
            let law1 = JenkinsLaw {
                kt: KT,
                kn: KN,
                mu: MU,
                initial_state: 0.0,
            };
            line.evaluate(&law1, ContactEffects::default(), &along, &v, true)
                .unwrap();
            let friction = MU * KN * 1e-4;
            let mut worst = 0.0_f64;
            for j in 0..nb {
                let (t1, t2) = (plane.t_hat[0][j], plane.t_hat[1][j]);
                let (t_along, t_across) = (c * t1 + s * t2, -s * t1 + c * t2);
                worst = worst.max((t_along - line.t_hat[j]).abs());
                worst = worst.max(t_across.abs());
            }
            println!(
                "excess {excess:e}: {:?} in {} periods, largest difference from the 1D forces \
                 {:.3e} of μN",
                report.state,
                report.periods,
                worst / friction
            );
            // Measured: 11 and 18 periods, 7.6e-13 and 2.2e-14 of μN from the 1D forces.
            assert_eq!(report.state, ContactState::StickSlip);
            assert!(report.periods <= 100, "{report:?}");
            assert!(worst < 1e-10 * friction, "excess {excess:e}: {worst:.3e} N");
            assert!(plane.dt_dx.iter().all(|x| x.is_finite()));
        }
    }

    /// The problem's force scale only coarsens the tolerance of points whose own scale is
    /// smaller: on ordinary points (stuck, full slip, stick-slip with lift-off) a force scale
    /// of the order of their own forces leaves the forces and the Jacobian as they were.
    #[test]
    fn the_problem_scale_leaves_ordinary_points_unchanged() {
        let set = HarmonicSet::up_to(3);
        let c = |e: &[(usize, f64)]| coefficients(&set, e);
        let stick_limit = MU * KN * 1e-4 / KT;
        let cases = [
            (
                [0.3, -0.2],
                [
                    c(&[(1, 0.2 * stick_limit)]),
                    c(&[(2, 0.1 * stick_limit)]),
                    c(&[(0, 1e-4), (1, 1e-5)]),
                ],
            ),
            (
                [0.0, 0.0],
                [
                    c(&[(1, 3.0 * stick_limit)]),
                    c(&[(2, 3.0 * stick_limit)]),
                    c(&[(0, 1e-4)]),
                ],
            ),
            (
                [0.5, 0.5],
                [
                    c(&[(1, 1.5 * stick_limit), (4, 0.2 * stick_limit)]),
                    c(&[(2, 0.8 * stick_limit)]),
                    c(&[(0, 5e-5), (1, 8e-5)]),
                ],
            ),
        ];
        for (m, x) in &cases {
            let mut plain = Aft2dWorkspace::new(&set, 128);
            let mut scaled = Aft2dWorkspace::new(&set, 128);
            // 20 N: three times μN₀ of these points.
            scaled.settings.force_scale = 20.0;
            let effects = ContactEffects::default();
            let a = plain
                .evaluate(&law(*m), effects, [&x[0], &x[1]], &x[2], true)
                .unwrap();
            let b = scaled
                .evaluate(&law(*m), effects, [&x[0], &x[1]], &x[2], true)
                .unwrap();
            assert_eq!(a.state, b.state);
            let size = plain.dt_dx.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            let forces = plain.t_hat[0].iter().chain(&plain.t_hat[1]);
            let force_size = forces.fold(0.0_f64, |s, v| s.max(v.abs()));
            for k in 0..2 {
                for (p, q) in plain.t_hat[k].iter().zip(&scaled.t_hat[k]) {
                    assert!((p - q).abs() <= 1e-10 * force_size, "{m:?}: {p} vs {q}");
                }
            }
            for (p, q) in plain.dt_dx.iter().zip(&scaled.dt_dx) {
                assert!((p - q).abs() <= 1e-8 * size, "{m:?}: {p} vs {q}");
            }
        }
    }
}
