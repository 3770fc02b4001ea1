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

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

use crate::contact::{ContactEffects, ContactState, JenkinsLaw, NormalLoad};
use crate::harmonic::{Block, HarmonicSet, SampleBasis};

/// Limits of the periodic march.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarchSettings {
    /// Most periods marched before giving up (≥ 2).
    pub max_periods: usize,
    /// Relative tolerance on the slider position repeating, scaled by the range of u plus
    /// the largest μN/kₜ.
    pub periodicity_tolerance: f64,
}

impl Default for MarchSettings {
    fn default() -> Self {
        Self {
            max_periods: 64,
            periodicity_tolerance: 1e-12,
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

    /// Coefficients → samples (inverse real FFT), into `out`.
    fn synthesize(&mut self, coefficients: &[f64], which: Signal) {
        for c in self.spectrum.iter_mut() {
            *c = Complex::new(0.0, 0.0);
        }
        for (b, &c) in self.set.blocks().iter().zip(coefficients) {
            match *b {
                Block::Constant => self.spectrum[0].re += c,
                Block::Cos(h) => self.spectrum[h].re += 0.5 * c,
                Block::Sin(h) => self.spectrum[h].im -= 0.5 * c,
            }
        }
        let out = match which {
            Signal::U => &mut self.u,
            Signal::V => &mut self.v,
        };
        // Validated sample counts keep every harmonic below Nyquist, so the DC and Nyquist
        // bins are real and the transform cannot fail.
        self.inverse
            .process_with_scratch(&mut self.spectrum, out, &mut self.scratch_inv)
            .expect("inverse real FFT with real DC/Nyquist bins");
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
        let tol = self.settings.periodicity_tolerance * scale;

        // Initial condition: T(0) = m μ N(0), i.e. w = u₀ − m μ N₀ / kₜ.
        let limit0 = law.mu * self.n[0].max(0.0);
        let mut w = if limit0 > 0.0 {
            self.u[0] - law.initial_state * limit0 / law.kt
        } else {
            self.u[0]
        };
        let mut anchor = 0usize;
        let mut anchor_sign = if limit0 > 0.0 { law.initial_state } else { 0.0 };
        let mut w_start = w;
        let mut drift = f64::INFINITY;
        let mut open_samples;
        let mut stick_margin_slips;
        for period in 1..=self.settings.max_periods.max(2) {
            open_samples = 0usize;
            stick_margin_slips = 0usize;
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
                    // A slip by rounding only (the limit-case stuck side touches μN) is
                    // not a state change.
                    if predictor.abs() - limit > 1e-9 * (limit + law.kt * scale) {
                        stick_margin_slips += 1;
                    }
                }
            }
            drift = (w - w_start).abs();
            if period >= 2 && drift <= tol {
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

    fn accumulate_jacobian(&mut self, law: &JenkinsLaw, effects: ContactEffects) {
        let nb = self.set.n_blocks();
        let ns = self.n_samples;
        self.dt_du.iter_mut().for_each(|x| *x = 0.0);
        self.dt_dv.iter_mut().for_each(|x| *x = 0.0);
        self.dn_dv.iter_mut().for_each(|x| *x = 0.0);
        let constant_block = self.set.constant_block();
        for k in 0..ns {
            let ek = self.basis.row(k);
            let closed_k = self.normal_active[k];
            match self.kinds[k] {
                SampleKind::Open => {}
                SampleKind::Slip { sign } => {
                    if closed_k {
                        add_normal_outer(
                            &mut self.dt_dv,
                            &self.basis,
                            effects.normal_load,
                            constant_block,
                            k,
                            k,
                            sign * law.mu * law.kn,
                        );
                    }
                }
                SampleKind::Stick { anchor, sign } => {
                    let ea = self.basis.row(anchor);
                    for j in 0..nb {
                        let pj = self.basis.projection[j * ns + k];
                        if pj == 0.0 {
                            continue;
                        }
                        let row = &mut self.dt_du[j * nb..(j + 1) * nb];
                        for i in 0..nb {
                            row[i] += pj * law.kt * (ek[i] - ea[i]);
                        }
                    }
                    if sign != 0.0 && self.normal_active[anchor] {
                        add_normal_outer(
                            &mut self.dt_dv,
                            &self.basis,
                            effects.normal_load,
                            constant_block,
                            k,
                            anchor,
                            sign * law.mu * law.kn,
                        );
                    }
                }
            }
            if closed_k {
                add_normal_outer(
                    &mut self.dn_dv,
                    &self.basis,
                    effects.normal_load,
                    constant_block,
                    k,
                    k,
                    law.kn,
                );
            }
        }
    }

    /// The contact state samples of the last evaluation as labels per sample (for outputs).
    pub fn sample_is_slipping(&self, k: usize) -> bool {
        matches!(self.kinds[k], SampleKind::Slip { .. })
    }
}

/// J[j][i] += scale · P[j][k] · (∂v_at_sample_a/∂v̂_i), with the normal sensitivity of the
/// normal-load model (variable: E row a; constant: the constant block only).
fn add_normal_outer(
    jac: &mut [f64],
    basis: &SampleBasis,
    normal_load: NormalLoad,
    constant_block: Option<usize>,
    k: usize,
    a: usize,
    scale: f64,
) {
    let nb = basis.n_blocks;
    for j in 0..nb {
        let pj = basis.projection[j * basis.n_samples + k];
        if pj == 0.0 {
            continue;
        }
        let row = &mut jac[j * nb..(j + 1) * nb];
        match normal_load {
            NormalLoad::Variable => {
                let ea = basis.row(a);
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
