//! The 2D AFT workspace: its sample basis and buffers, built once per harmonic set, and the
//! evaluation of a contact point's force harmonics and Jacobian from its motion.

use crate::contact::aft::{AftError, MarchReport, MarchSettings};
use crate::contact::harmonic::{HarmonicSet, SampleBasis};
use crate::contact::point::Jenkins2dLaw;
use crate::contact::{ContactEffects, ContactState, NormalLoad};

/// Default budget of periods of the 2D march. Plain periods creep where the path barely
/// leaves the stuck region (grazing: measured 422 periods for a circle of 0.996 times the
/// stick radius, sampled 128 times, before the Newton restarts were line-searched) or slips
/// along one direction; the safeguarded Newton restarts settle such points in tens of periods
/// (module doc), and the budget bounds the cost of a point where they do not help.
pub const DEFAULT_MAX_PERIODS: usize = 2000;

/// What happened at one sample of the final period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum SampleKind {
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
pub(super) struct PeriodOutcome {
    /// Slider position at the period's end (m).
    pub(super) slider_end: [f64; 2],
    /// ∂w_end/∂w_start, row-major 2×2.
    pub(super) period_map_derivative: [f64; 4],
    /// Whether any sample slipped (rounding slips included).
    pub(super) any_slip: bool,
    /// Samples that slipped by more than rounding.
    pub(super) margin_slips: usize,
    /// Samples with the contact open.
    pub(super) open_samples: usize,
}

/// Workspace for the AFT of 2D-friction contacts sharing one harmonic set and sample count.
pub struct Aft2dWorkspace {
    pub(super) set: HarmonicSet,
    pub(super) basis: SampleBasis,
    pub(super) n_samples: usize,
    pub(super) kinds: Vec<SampleKind>,
    pub(super) normal_active: Vec<bool>,
    /// Derivative of the slider, 2 × (3 n_blocks + 2), row-major (scratch of the Jacobian).
    pub(super) slider_derivative: Vec<f64>,
    /// Σ P_k dT_k over 3 n_blocks + 2 columns, row-major (2 n_blocks) × (3 n_blocks + 2).
    pub(super) force_derivative: Vec<f64>,
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
    pub(super) initial_slider: [f64; 2],
    /// The point's own motion scale (m): the path's extent plus μ N_max / kₜ (the scale of the
    /// test of a slip by mere rounding).
    pub(super) march_scale: f64,
    /// Length scale of the periodicity tolerance (m): the own scale, or the problem's force
    /// scale over kₜ when larger ([`MarchSettings::length_scale`]).
    pub(super) tolerance_scale: f64,
    /// March limits (the same meaning as for the 1D march).
    pub settings: MarchSettings,
    /// Whether periods restart from Newton updates of the fixed point (always, except in the
    /// tests that compare with the plain march).
    pub(super) newton_restarts: bool,
    /// Buffers of the event-resolved law ([`Self::evaluate_events`]).
    pub(super) events: crate::contact::events2d::march::EventScratch,
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
            events: Default::default(),
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
        self.sample_motion(law, effects, u_coefficients, v_coefficients)?;
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

    /// Samples u₁, u₂, v and N on the grid from their coefficients (the normal force with
    /// its law and effects, and whether the normal spring is active at each sample).
    pub(super) fn sample_motion(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        u_coefficients: [&[f64]; 2],
        v_coefficients: &[f64],
    ) -> Result<(), AftError> {
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
        Ok(())
    }

    /// The march's report for a final period `outcome` reached at period `period`.
    pub(super) fn report(&self, outcome: &PeriodOutcome, period: usize) -> MarchReport {
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

    use crate::contact::aft2d::fixtures::{coefficients, law, KN, KT, MU};

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
