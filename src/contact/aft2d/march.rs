//! One period of the march: radial return onto the friction circle at each sample, and the
//! derivative of the period map it carries (the slider's end state by its start).

use super::workspace::{Aft2dWorkspace, PeriodOutcome, SampleKind};
use crate::contact::point::Jenkins2dLaw;

impl Aft2dWorkspace {
    /// Marches one period from the slider position `start`, filling the force samples and
    /// sample kinds. `initial` marks the first period, whose sample 0 is the initial condition.
    pub(super) fn march_period(
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
}

/// Where the final period's slider start comes from, which fixes its derivative.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum StartOrigin {
    /// Stuck over the whole first period: the initial condition T(0) = μN(0)·m.
    InitialCondition,
    /// The fixed point of the period map, reached with slip: dw = (I − A)⁻¹ B dx.
    FixedPoint,
    /// A degenerate fixed point (slip along one direction: I − A singular there, the start
    /// converged only to the tolerance, not to round-off): dw = (I − A)⁺ B dx with the
    /// pseudo-inverse leaving out the direction whose singular value is below
    /// [`FIXED_POINT_CONDITION`](super::settle::FIXED_POINT_CONDITION) (the slider's offset across
    /// the slip direction is held).
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
pub(super) fn step_derivative(
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
pub(super) fn slips_beyond_rounding(outcome: &PeriodOutcome) -> bool {
    outcome.margin_slips > 0 || outcome.open_samples > 0
}

/// Product of two row-major 2×2 matrices.
pub(super) fn mat2_mul(x: [f64; 4], y: [f64; 4]) -> [f64; 4] {
    [
        x[0] * y[0] + x[1] * y[2],
        x[0] * y[1] + x[1] * y[3],
        x[2] * y[0] + x[3] * y[2],
        x[2] * y[1] + x[3] * y[3],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::aft::AftWorkspace;
    use crate::contact::aft2d::fixtures::{coefficients, law, KN, KT, MU};
    use crate::contact::harmonic::HarmonicSet;
    use crate::contact::ContactEffects;
    use crate::contact::ContactState;
    use crate::contact::JenkinsLaw;
    use crate::contact::NormalLoad;
    use std::f64::consts::PI;

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
}
