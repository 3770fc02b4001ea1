//! Alternating frequency/time (AFT) contact forces and their analytic Jacobian.
//!
//! For one contact point, the Fourier coefficients of the relative displacements û, v̂ are
//! turned into N time samples by an inverse real FFT, the Jenkins element with variable normal
//! load and lift-off (paper Eqs. 4-6) is marched over the samples, and a forward real FFT gives
//! the force coefficients T̂, N̂.
//!
//! # The march
//!
//! The march starts at τ = 0 with the slider placed so that T(0) = m μ N(0) (paper Eqs. 14-15;
//! m is the contact's initial tangential state). It is repeated period after period until the
//! slider position at the end of a period equals the one at its start (the state repeats);
//! the forces of that last period are the steady-state forces. A march that has not repeated
//! after [`MarchSettings::max_periods`] periods is reported as [`AftError::NotSettled`].
//!
//! # Analytic Jacobian
//!
//! Every sample records how its slider position was last set (its *anchor*): the initial
//! condition, a slip, or a separation at sample a, where w_a = u_a − s_a μ N_a / kₜ. Then
//!
//! * stick at k anchored at a: dT_k = kₜ (du_k − du_a) + s_a μ dN_a,
//! * slip at k with sign s:     dT_k = s μ dN_k,
//! * open:                      dT_k = 0,
//! * closed:                    dN_k = kₙ dv_k (or kₙ dv̂₀ with a constant normal load),
//!
//! and du_k, dv_k are rows of the synthesis matrix E, so dT̂/dû = P · (sample sensitivities).
//! This costs one pass over the samples per contact instead of one march per unknown.
//!
//! Everything here is allocation-free after [`AftWorkspace::new`]: plans, scratch and all
//! buffers live in the workspace.

mod resolved;

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

use crate::contact::events::EventSolver;
use crate::contact::harmonic::{product_integral, Block, HarmonicSet, SampleBasis};
use crate::contact::{ContactEffects, ContactState, JenkinsLaw, NormalLoad};

/// Limits of the periodic march.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarchSettings {
    /// Most periods marched before giving up (≥ 2).
    pub max_periods: usize,
    /// Relative tolerance on the slider position repeating, scaled by
    /// [`MarchSettings::length_scale`].
    pub periodicity_tolerance: f64,
    /// Force scale of the whole problem (N), e.g. the norm of its loads; 0 for none. The
    /// periodicity tolerance is never scaled by less than `force_scale / kₜ`: a slider drift
    /// whose spring force kₜ·drift is round-off against the loads on the structure is periodic,
    /// even on a point whose own motion is tiny (a barely loaded, barely slipping point of a
    /// 3D damper, whose 2D march otherwise creeps for thousands of periods).
    pub force_scale: f64,
}

impl MarchSettings {
    /// The length (m) the periodicity tolerance is relative to, for a point whose own motion
    /// scale is `own_scale` (m: its tangential path's extent plus μ N_max / kₜ): the larger of
    /// that and the problem's, `force_scale / kₜ`. The 1D and the 2D march both use it; the
    /// test of a slip by mere rounding keeps the point's own scale.
    pub fn length_scale(&self, own_scale: f64, kt: f64) -> f64 {
        let problem = if kt > 0.0 { self.force_scale / kt } else { 0.0 };
        own_scale.max(problem)
    }
}

impl Default for MarchSettings {
    fn default() -> Self {
        Self {
            max_periods: 64,
            periodicity_tolerance: 1e-12,
            force_scale: 0.0,
        }
    }
}

/// Errors of one AFT evaluation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AftError {
    /// The slider state did not repeat within the allowed number of periods.
    #[error("contact march did not reach a periodic state in {periods} periods (slider drift {drift:.3e} m)")]
    NotSettled {
        /// Periods marched.
        periods: usize,
        /// Last change of the slider position over one period (m).
        drift: f64,
    },
    /// A displacement sample was NaN or infinite.
    #[error("non-finite relative displacement in the contact march")]
    NonFinite,
    /// The event-resolved law met more transitions in one period than its bracketing grid
    /// can separate.
    #[error(
        "contact transitions too dense to locate on the bracketing grid (raise harmonics.samples)"
    )]
    TooManyEvents,
}

/// What happened at one sample of the final period (kept for the Jacobian and for outputs).
#[derive(Debug, Clone, Copy, PartialEq)]
enum SampleKind {
    /// Stuck; slider last set at `anchor` with friction sign `sign` (0 for a separation).
    Stick { anchor: usize, sign: f64 },
    /// Slipping with sign ±1.
    Slip { sign: f64 },
    /// Separated (no tangential force).
    Open,
}

/// Result summary of one contact evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarchReport {
    /// Contact state over the final period.
    pub state: ContactState,
    /// Periods marched, including the final one.
    pub periods: usize,
}

/// Workspace for the AFT of contacts sharing one harmonic set and sample count.
pub struct AftWorkspace {
    set: HarmonicSet,
    basis: SampleBasis,
    n_samples: usize,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
    spectrum: Vec<Complex<f64>>,
    scratch_fwd: Vec<Complex<f64>>,
    scratch_inv: Vec<Complex<f64>>,
    fft_buffer: Vec<f64>,
    kinds: Vec<SampleKind>,
    normal_active: Vec<bool>,
    gram_weights: [Vec<f64>; 3],
    gram_spectra: [Vec<Complex<f64>>; 3],
    anchor_sum: Vec<f64>,
    /// Whether the slider of the last march was never moved from its initial position by a
    /// slip (beyond rounding) or a separation: the forces then depend on m.
    initial_anchor: bool,
    /// Tangential relative displacement samples u(τ_k) (m).
    pub u: Vec<f64>,
    /// Normal relative displacement samples v(τ_k) (m).
    pub v: Vec<f64>,
    /// Tangential force samples T(τ_k) of the final period (N).
    pub t: Vec<f64>,
    /// Normal force samples N(τ_k) (N).
    pub n: Vec<f64>,
    /// Fourier coefficients of T, one per block (N).
    pub t_hat: Vec<f64>,
    /// Fourier coefficients of N, one per block (N).
    pub n_hat: Vec<f64>,
    /// ∂T̂/∂û, row-major n_blocks × n_blocks (N/m).
    pub dt_du: Vec<f64>,
    /// ∂T̂/∂v̂, row-major (N/m).
    pub dt_dv: Vec<f64>,
    /// ∂N̂/∂v̂, row-major (N/m).
    pub dn_dv: Vec<f64>,
    /// March limits.
    pub settings: MarchSettings,
    /// Buffers of the event-resolved law ([`Self::evaluate_events`]).
    events: EventSolver,
}

impl AftWorkspace {
    /// Creates plans and buffers for `set` sampled at `n_samples` points per period.
    ///
    /// # Panics
    /// If `n_samples ≤ 2·max_harmonic` (validated scenes never do this).
    #[track_caller]
    pub fn new(set: &HarmonicSet, n_samples: usize) -> Self {
        assert!(
            n_samples > 2 * set.max_harmonic(),
            "AFT needs more than 2·H samples per period"
        );
        let mut planner = RealFftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(n_samples);
        let inverse = planner.plan_fft_inverse(n_samples);
        let nb = set.n_blocks();
        let gram_spectra = std::array::from_fn(|_| forward.make_output_vec());
        Self {
            set: set.clone(),
            basis: SampleBasis::new(set, n_samples),
            n_samples,
            spectrum: forward.make_output_vec(),
            scratch_fwd: forward.make_scratch_vec(),
            scratch_inv: inverse.make_scratch_vec(),
            fft_buffer: vec![0.0; n_samples],
            forward,
            inverse,
            kinds: vec![SampleKind::Open; n_samples],
            normal_active: vec![false; n_samples],
            gram_weights: [
                vec![0.0; n_samples],
                vec![0.0; n_samples],
                vec![0.0; n_samples],
            ],
            gram_spectra,
            anchor_sum: vec![0.0; nb],
            initial_anchor: false,
            u: vec![0.0; n_samples],
            v: vec![0.0; n_samples],
            t: vec![0.0; n_samples],
            n: vec![0.0; n_samples],
            t_hat: vec![0.0; nb],
            n_hat: vec![0.0; nb],
            dt_du: vec![0.0; nb * nb],
            dt_dv: vec![0.0; nb * nb],
            dn_dv: vec![0.0; nb * nb],
            settings: MarchSettings::default(),
            events: EventSolver::new(set, n_samples),
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

    /// Coefficients → samples (inverse real FFT), into [`Self::u`] or [`Self::v`].
    fn synthesize(&mut self, coefficients: &[f64], which: Signal) {
        let out = match which {
            Signal::U => &mut self.u,
            Signal::V => &mut self.v,
        };
        synthesize_into(
            &self.set,
            self.inverse.as_ref(),
            (&mut self.spectrum, &mut self.scratch_inv),
            coefficients,
            out,
        );
    }

    /// Samples → coefficients (forward real FFT).
    fn analyze(&mut self, which: Force) {
        let src = match which {
            Force::T => &self.t,
            Force::N => &self.n,
        };
        self.fft_buffer.copy_from_slice(src);
        self.forward
            .process_with_scratch(
                &mut self.fft_buffer,
                &mut self.spectrum,
                &mut self.scratch_fwd,
            )
            .expect("forward real FFT of a buffer of the planned length");
        let scale = 1.0 / self.n_samples as f64;
        let out = match which {
            Force::T => &mut self.t_hat,
            Force::N => &mut self.n_hat,
        };
        for (b, o) in self.set.blocks().iter().zip(out.iter_mut()) {
            *o = match *b {
                Block::Constant => self.spectrum[0].re * scale,
                Block::Cos(h) => 2.0 * self.spectrum[h].re * scale,
                Block::Sin(h) => -2.0 * self.spectrum[h].im * scale,
            };
        }
    }

    /// Evaluates the contact forces (and, if asked, their Jacobian) for coefficients û, v̂.
    ///
    /// `v_coefficients` already include the gap in the constant block. Results are left in
    /// [`Self::t_hat`], [`Self::n_hat`], the sample buffers and, with `jacobian`, in
    /// [`Self::dt_du`], [`Self::dt_dv`], [`Self::dn_dv`].
    pub fn evaluate(
        &mut self,
        law: &JenkinsLaw,
        effects: ContactEffects,
        u_coefficients: &[f64],
        v_coefficients: &[f64],
        jacobian: bool,
    ) -> Result<MarchReport, AftError> {
        self.synthesize(u_coefficients, Signal::U);
        self.synthesize(v_coefficients, Signal::V);
        let constant_v = self
            .set
            .constant_block()
            .map(|j| v_coefficients[j])
            .unwrap_or(0.0);
        let report = self.march(law, effects, constant_v)?;
        self.analyze(Force::T);
        self.analyze(Force::N);
        if jacobian {
            self.accumulate_jacobian(law, effects);
        }
        Ok(report)
    }

    /// Normal force samples and which samples are closed.
    fn normal_forces(&mut self, law: &JenkinsLaw, effects: ContactEffects, constant_v: f64) {
        for k in 0..self.n_samples {
            let v = match effects.normal_load {
                NormalLoad::Variable => self.v[k],
                NormalLoad::Constant => constant_v,
            };
            let nk = law.kn * v;
            let (force, active) = if effects.liftoff {
                if nk > 0.0 {
                    (nk, true)
                } else {
                    (0.0, false)
                }
            } else {
                (nk, true)
            };
            self.n[k] = force;
            self.normal_active[k] = active;
        }
    }

    fn march(
        &mut self,
        law: &JenkinsLaw,
        effects: ContactEffects,
        constant_v: f64,
    ) -> Result<MarchReport, AftError> {
        let ns = self.n_samples;
        if self.u.iter().chain(self.v.iter()).any(|x| !x.is_finite()) {
            return Err(AftError::NonFinite);
        }
        self.normal_forces(law, effects, constant_v);
        let (umin, umax) = self
            .u
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        let nmax = self.n.iter().fold(0.0_f64, |a, &x| a.max(x.abs()));
        let scale = (umax - umin) + law.mu * nmax / law.kt + f64::MIN_POSITIVE;
        let tol = self.settings.periodicity_tolerance * self.settings.length_scale(scale, law.kt);

        // Initial condition: T(0) = m μ N(0), i.e. w = u₀ − m μ N₀ / kₜ.
        let limit0 = law.mu * self.n[0].max(0.0);
        let mut w = if limit0 > 0.0 {
            self.u[0] - law.initial_state * limit0 / law.kt
        } else {
            self.u[0]
        };
        let mut anchor = 0usize;
        let mut anchor_sign = if limit0 > 0.0 { law.initial_state } else { 0.0 };
        self.initial_anchor = limit0 > 0.0;
        let mut w_start = w;
        let mut drift = f64::INFINITY;
        let mut open_samples;
        let mut stick_margin_slips;
        let mut any_slip;
        for period in 1..=self.settings.max_periods.max(2) {
            open_samples = 0usize;
            stick_margin_slips = 0usize;
            any_slip = false;
            // The first sample of the first period is the initial condition itself.
            let first = if period == 1 { 1 } else { 0 };
            if period == 1 {
                self.t[0] = self.u[0] * law.kt - w * law.kt;
                self.kinds[0] = if limit0 > 0.0 {
                    SampleKind::Stick {
                        anchor,
                        sign: anchor_sign,
                    }
                } else {
                    open_samples += 1;
                    SampleKind::Open
                };
                if limit0 == 0.0 {
                    self.t[0] = 0.0;
                }
            }
            for k in first..ns {
                let limit = law.mu * self.n[k].max(0.0);
                let closed = self.n[k] > 0.0;
                if !closed {
                    w = self.u[k];
                    self.t[k] = 0.0;
                    self.kinds[k] = SampleKind::Open;
                    anchor = k;
                    anchor_sign = 0.0;
                    open_samples += 1;
                    self.initial_anchor = false;
                    continue;
                }
                let predictor = law.kt * (self.u[k] - w);
                if predictor.abs() <= limit {
                    self.t[k] = predictor;
                    self.kinds[k] = SampleKind::Stick {
                        anchor,
                        sign: anchor_sign,
                    };
                } else {
                    let sign = predictor.signum();
                    self.t[k] = sign * limit;
                    w = self.u[k] - self.t[k] / law.kt;
                    self.kinds[k] = SampleKind::Slip { sign };
                    anchor = k;
                    anchor_sign = sign;
                    any_slip = true;
                    // A slip by rounding only (the limit-case stuck side touches μN) is
                    // not a state change.
                    if predictor.abs() - limit > 1e-9 * (limit + law.kt * scale) {
                        stick_margin_slips += 1;
                        self.initial_anchor = false;
                    }
                }
            }
            drift = (w - w_start).abs();
            // A first period without slip or separation is already periodic (the slider never
            // moved); otherwise the sample kinds must come from a repeated period, whose
            // anchors are the steady-state ones.
            let settled = drift <= tol && (period >= 2 || (!any_slip && open_samples == 0));
            if settled {
                let state = if open_samples == ns {
                    ContactState::Open
                } else if open_samples > 0 {
                    ContactState::StickSlipLiftoff
                } else if stick_margin_slips > 0 {
                    ContactState::StickSlip
                } else {
                    ContactState::Stuck
                };
                return Ok(MarchReport {
                    state,
                    periods: period,
                });
            }
            w_start = w;
        }
        Err(AftError::NotSettled {
            periods: self.settings.max_periods.max(2),
            drift,
        })
    }

    /// ∂T̂₀/∂m of the last evaluation (N per unit m): the derivative of the constant block of
    /// the tangential force with respect to the initial tangential state m (T(0) = m μ N(0),
    /// paper Eqs. 14-15). The other blocks of ∂T̂/∂m are zero.
    ///
    /// m enters the march only through the initial slider position w₀ = u₀ − m μ N₀ / kₜ. A
    /// slip or a separation anywhere in the march (in the final period or in the transient
    /// periods before it) resets the slider to a position that does not depend on m, and the
    /// derivative is 0. When neither happened, the contact is stuck over the whole period with
    /// every sample anchored at the initial condition: T_k = kₜ (u_k − u₀) + m μ N₀, so
    /// ∂T_k/∂m = μ N₀ at every sample and only the mean T̂₀ moves. A contact that slipped in
    /// the transient and then stuck (reported `Stuck`, touching μN once per period) forgets
    /// m. Slips by rounding only (m = ±1, where the contact touches μN at τ = 0) do not count:
    /// the value is then the one-sided derivative into [−1, 1].
    pub fn initial_state_derivative(&self, law: &JenkinsLaw) -> f64 {
        if self.initial_anchor {
            law.mu * self.n[0].max(0.0)
        } else {
            0.0
        }
    }

    /// The initial state m at which a march would start directly in the steady state of the
    /// last evaluation, T(0) / (μ N(0)) ∈ [−1, 1], when that state is stuck over the whole
    /// period (`state` as reported); `None` otherwise (slipping or open somewhere, or open at
    /// τ = 0). A contact that slipped in the transient and then stuck has the same forces as
    /// the march started at this m, which stays stuck from its start: the response depends on
    /// m only through it (m is clamped to the range of initial states that stay stuck).
    pub fn effective_initial_state(&self, law: &JenkinsLaw, state: ContactState) -> Option<f64> {
        let limit0 = law.mu * self.n[0];
        (state == ContactState::Stuck && limit0 > 0.0)
            .then(|| (self.t[0] / limit0).clamp(-1.0, 1.0))
    }

    /// Assembles ∂T̂/∂û, ∂T̂/∂v̂, ∂N̂/∂v̂ from the recorded sample kinds.
    ///
    /// Sums over samples of P_k ⊗ E_k weighted by an indicator g (stick, slip sign, closed) are
    /// weighted Gram matrices of the trigonometric basis; products of cosines and sines reduce
    /// to single harmonics |a ± b| of g, so one real FFT of g gives each matrix in
    /// O(N log N + n_blocks²) instead of O(N · n_blocks²). The anchor terms are rank-1
    /// updates, one per stick segment.
    fn accumulate_jacobian(&mut self, law: &JenkinsLaw, effects: ContactEffects) {
        let nb = self.set.n_blocks();
        let ns = self.n_samples;
        let constant_block = self.set.constant_block();
        self.dt_du.iter_mut().for_each(|x| *x = 0.0);
        self.dt_dv.iter_mut().for_each(|x| *x = 0.0);
        self.dn_dv.iter_mut().for_each(|x| *x = 0.0);

        // Indicator weights: stick → kₜ on dT/du; slip → s μ kₙ on dT/dv; closed → kₙ on dN/dv.
        for k in 0..ns {
            let (stick, slip) = match self.kinds[k] {
                SampleKind::Stick { .. } => (law.kt, 0.0),
                SampleKind::Slip { sign } => (0.0, sign * law.mu * law.kn),
                SampleKind::Open => (0.0, 0.0),
            };
            self.gram_weights[0][k] = stick;
            self.gram_weights[1][k] = slip;
            self.gram_weights[2][k] = if self.normal_active[k] { law.kn } else { 0.0 };
        }
        for w in 0..3 {
            self.fft_buffer.copy_from_slice(&self.gram_weights[w]);
            self.forward
                .process_with_scratch(
                    &mut self.fft_buffer,
                    &mut self.gram_spectra[w],
                    &mut self.scratch_fwd,
                )
                .expect("forward real FFT of a buffer of the planned length");
        }
        let blocks = self.set.blocks();
        let normal_columns = |i: usize| match effects.normal_load {
            NormalLoad::Variable => true,
            NormalLoad::Constant => Some(i) == constant_block,
        };
        for j in 0..nb {
            let wj = if blocks[j] == Block::Constant {
                1.0
            } else {
                2.0
            } / ns as f64;
            for i in 0..nb {
                let stick = gram_entry(&self.gram_spectra[0], ns, blocks[j], blocks[i]);
                self.dt_du[j * nb + i] = wj * stick;
                if normal_columns(i) {
                    // With a constant normal load the sensitivity is the constant block only,
                    // whose basis function is 1: the same Gram entry with b_i = 1.
                    let bi = match effects.normal_load {
                        NormalLoad::Variable => blocks[i],
                        NormalLoad::Constant => Block::Constant,
                    };
                    self.dt_dv[j * nb + i] =
                        wj * gram_entry(&self.gram_spectra[1], ns, blocks[j], bi);
                    self.dn_dv[j * nb + i] =
                        wj * gram_entry(&self.gram_spectra[2], ns, blocks[j], bi);
                }
            }
        }

        // Anchor terms: every stick sample k anchored at a adds −kₜ P_k ⊗ E_a to dT/du and
        // s_a μ kₙ P_k ⊗ NS_a to dT/dv; sum P_k per stick segment, then one rank-1 update.
        let mut acc = std::mem::take(&mut self.anchor_sum);
        acc.iter_mut().for_each(|x| *x = 0.0);
        let mut current: Option<(usize, f64)> = None;
        for k in 0..=ns {
            let kind = if k < ns { Some(self.kinds[k]) } else { None };
            let anchor = match kind {
                Some(SampleKind::Stick { anchor, sign }) => Some((anchor, sign)),
                _ => None,
            };
            if anchor != current {
                if let Some((a, sign)) = current {
                    self.flush_anchor(law, effects, constant_block, &acc, a, sign);
                    acc.iter_mut().for_each(|x| *x = 0.0);
                }
                current = anchor;
            }
            if anchor.is_some() {
                for (j, x) in acc.iter_mut().enumerate() {
                    *x += self.basis.projection[j * ns + k];
                }
            }
        }
        self.anchor_sum = acc;
    }

    /// Rank-1 anchor update for a stick segment whose projections sum to `acc`.
    fn flush_anchor(
        &mut self,
        law: &JenkinsLaw,
        effects: ContactEffects,
        constant_block: Option<usize>,
        acc: &[f64],
        anchor: usize,
        sign: f64,
    ) {
        let nb = acc.len();
        let ea = self.basis.row(anchor);
        for j in 0..nb {
            let pj = acc[j];
            if pj == 0.0 {
                continue;
            }
            let row = &mut self.dt_du[j * nb..(j + 1) * nb];
            for i in 0..nb {
                row[i] -= law.kt * pj * ea[i];
            }
        }
        if sign != 0.0 && self.normal_active[anchor] {
            let scale = sign * law.mu * law.kn;
            for j in 0..nb {
                let pj = acc[j];
                let row = &mut self.dt_dv[j * nb..(j + 1) * nb];
                match effects.normal_load {
                    NormalLoad::Variable => {
                        for i in 0..nb {
                            row[i] += scale * pj * ea[i];
                        }
                    }
                    NormalLoad::Constant => {
                        if let Some(c) = constant_block {
                            row[c] += scale * pj;
                        }
                    }
                }
            }
        }
    }

    /// The contact state samples of the last evaluation as labels per sample (for outputs).
    pub fn sample_is_slipping(&self, k: usize) -> bool {
        matches!(self.kinds[k], SampleKind::Slip { .. })
    }
}

/// Σ_k g_k b_j(τ_k) b_i(τ_k) from the real FFT X of g (X_m = Σ_k g_k e^{−imτ_k}):
/// Σ g cos(mτ) = Re X_m and Σ g sin(mτ) = −Im X_m in [`product_integral`].
fn gram_entry(spectrum: &[Complex<f64>], n: usize, bj: Block, bi: Block) -> f64 {
    product_integral(
        |m| spectrum_at(spectrum, n, m).re,
        |m| -spectrum_at(spectrum, n, m).im,
        bj,
        bi,
    )
}

/// X_m of a real signal of length n for any integer m, from the half spectrum 0..=n/2.
fn spectrum_at(spectrum: &[Complex<f64>], n: usize, m: i64) -> Complex<f64> {
    let r = m.rem_euclid(n as i64) as usize;
    if r <= n / 2 {
        spectrum[r]
    } else {
        spectrum[n - r].conj()
    }
}

/// Coefficients on the blocks of `set` → N samples of the signal (inverse real FFT), with the
/// plan's spectrum and scratch buffers.
fn synthesize_into(
    set: &HarmonicSet,
    inverse: &dyn ComplexToReal<f64>,
    (spectrum, scratch): (&mut [Complex<f64>], &mut [Complex<f64>]),
    coefficients: &[f64],
    out: &mut [f64],
) {
    for c in spectrum.iter_mut() {
        *c = Complex::new(0.0, 0.0);
    }
    for (b, &c) in set.blocks().iter().zip(coefficients) {
        match *b {
            Block::Constant => spectrum[0].re += c,
            Block::Cos(h) => spectrum[h].re += 0.5 * c,
            Block::Sin(h) => spectrum[h].im -= 0.5 * c,
        }
    }
    // Validated sample counts keep every harmonic below Nyquist, so the DC and Nyquist bins
    // are real and the transform cannot fail.
    inverse
        .process_with_scratch(spectrum, out, scratch)
        .expect("inverse real FFT with real DC/Nyquist bins");
}

#[derive(Clone, Copy)]
enum Signal {
    U,
    V,
}

#[derive(Clone, Copy)]
enum Force {
    T,
    N,
}
