//! The march to the periodic steady state: from the initial tangential state, plain periods or
//! Newton restarts on the period map where it is well conditioned, until the slider repeats.

use super::march::{mat2_mul, slips_beyond_rounding, StartOrigin};
use super::workspace::{Aft2dWorkspace, PeriodOutcome};
use crate::contact::aft::{AftError, MarchReport};
use crate::contact::point::Jenkins2dLaw;
use crate::contact::ContactState;

impl Aft2dWorkspace {
    /// Marches periods until the slider state repeats, first with Newton-accelerated restarts
    /// and, when that lands in a state whose derivative needs the plain history (a final period
    /// without slip, or a fixed point that barely attracts), again with plain periods only.
    pub(super) fn march(
        &mut self,
        law: &Jenkins2dLaw,
    ) -> Result<(MarchReport, StartOrigin), AftError> {
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
pub(super) const FIXED_POINT_CONDITION: f64 = 1e-6;

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
pub(super) fn newton_step(mismatch: [f64; 2], a: [f64; 4], max_length: f64) -> Option<[f64; 2]> {
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
pub(super) fn pseudo_inverse(m: [f64; 4], floor: f64) -> [f64; 4] {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::aft::AftWorkspace;
    use crate::contact::aft2d::fixtures::{barely_slipping_point, law, KN, KT, MU};
    use crate::contact::aft2d::workspace::DEFAULT_MAX_PERIODS;
    use crate::contact::harmonic::HarmonicSet;
    use crate::contact::ContactEffects;
    use crate::contact::JenkinsLaw;

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
}
