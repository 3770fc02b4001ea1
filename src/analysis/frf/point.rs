//! One point of a response: its outputs (amplitudes, time-domain peaks, stability), solving it at
//! a fixed frequency or on a hyperplane, and reading a path between its points.

use std::f64::consts::PI;

use super::scale::arc_length_x_scale;
use super::status::{FrfError, FrfPoint, FrfRun};
use crate::analysis::monodromy::point_monodromy;
use crate::analysis::stability::{PointStability, StabilityError};
use crate::analysis::stability_sparse::{hill_solver_for, point_stability_with};
use crate::contact::harmonic::HarmonicSet;
use crate::hbm::operator::HbmOperator;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::{Problem, StabilityMethod};
use crate::numerics::golden;
use crate::numerics::{Continuation, NewtonFailure, ParametricResidual, PathPoint};

/// The largest |offset + q(τ)| over a period of the trigonometric polynomial q with
/// coefficients `coef` on `set` (m): the time-domain peak of a DOF. The maximum is located on a
/// fine grid (16 points per period of the highest harmonic, at least 64), then refined by a
/// golden-section search between the neighbours of the best grid point, down to 10⁻¹² rad:
/// the value is exact to round-off, so at one harmonic it equals the first-harmonic
/// amplitude, and it does not depend on the AFT sampling.
pub fn time_peak(set: &HarmonicSet, coef: &[f64], offset: f64) -> f64 {
    let h_max = set.harmonics().iter().copied().max().unwrap_or(0);
    let grid = (16 * h_max).max(64);
    let value = |tau: f64| (offset + set.evaluate(coef, tau)).abs();
    let dt = 2.0 * PI / grid as f64;
    let (best, _) =
        (0..grid)
            .map(|k| (k, value(k as f64 * dt)))
            .fold(
                (0, f64::NEG_INFINITY),
                |acc, (k, v)| if v > acc.1 { (k, v) } else { acc },
            );
    let search = golden::maximise(
        (best as f64 - 1.0) * dt,
        (best as f64 + 1.0) * dt,
        1e-12,
        |tau| Some((value(tau), ())),
    );
    search
        .best
        .map_or(f64::NEG_INFINITY, |(_, v, _)| v)
        .max(value(best as f64 * dt))
}

/// Output quantities of a converged point.
pub fn point_outputs(
    problem: &Problem,
    set: &HarmonicSet,
    static_offset: &[f64],
    x: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let n = problem.model.n_dofs();
    let c1 = set.cos_block(1);
    let s1 = set.sin_block(1);
    let mut amplitudes = Vec::with_capacity(problem.outputs.len());
    let mut peaks = Vec::with_capacity(problem.outputs.len());
    let mut coef = vec![0.0; set.n_blocks()];
    for &d in &problem.outputs {
        let c = c1.map(|j| x[j * n + d]).unwrap_or(0.0);
        let s = s1.map(|j| x[j * n + d]).unwrap_or(0.0);
        amplitudes.push(c.hypot(s));
        for (j, v) in coef.iter_mut().enumerate() {
            *v = x[j * n + d];
        }
        let offset = if set.has_constant() {
            0.0
        } else {
            static_offset[d]
        };
        peaks.push(time_peak(set, &coef, offset));
    }
    (amplitudes, peaks)
}

/// The outputs of a converged path point, on full coefficients.
pub(super) fn full_point(
    system: &mut HbmOperator<'_>,
    p: &PathPoint,
) -> Result<FrfPoint, HbmError> {
    let coefficients = system.expand(&p.x, p.omega)?;
    let full = system.full_ref();
    let (amplitudes, peaks) = point_outputs(
        full.problem(),
        full.unknowns(),
        full.static_offset(),
        &coefficients,
    );
    // A point solved at the start or end frequency (ω = 2π f) is reported at exactly f, not at
    // ω / 2π rounded an ulp away (the last row of a range must be its end).
    let range = &full.problem().analysis.continuation;
    let freq_hz = [range.freq_start_hz, range.freq_end_hz]
        .into_iter()
        .find(|f| (p.freq_hz() - f).abs() <= 8.0 * f64::EPSILON * f)
        .unwrap_or_else(|| p.freq_hz());
    let states = system.states().to_vec();
    Ok(FrfPoint {
        freq_hz,
        amplitudes,
        peaks,
        states,
        newton_iterations: p.iterations,
        residual: p.residual,
        coefficients,
        accuracy: None,
        pending_estimate: None,
        stability: None,
    })
}

/// The point with its stability at ω (rad/s) when the problem asks for it
/// (`analysis.stability`): computed for the points of a continuation path (FRF runs and every
/// limit, intermediate and scanned curve), not for the extra solves of peak refinements and
/// common grids. The method is `analysis.stability_method`: Hill's verdict (marked unreliable
/// on stick-slip points, [`crate::analysis::stability::hill_reliable`]), the monodromy's
/// ([`point_monodromy`]), or Hill's replaced by the monodromy's where Hill is unreliable. A
/// monodromy that fails (a time step whose Newton does not converge) leaves Hill's verdict
/// (marked unreliable) or, with the monodromy alone, no verdict: empty cells.
pub(super) fn with_stability(
    system: &mut HbmOperator<'_>,
    mut point: FrfPoint,
    omega: f64,
) -> Result<FrfPoint, HbmError> {
    let analysis = system.full_ref().problem().analysis;
    if !analysis.stability {
        return Ok(point);
    }
    let method = analysis.stability_method;
    let mut verdict = None;
    if method.uses_hill() {
        verdict = Some(
            {
                let full = system.full();
                let unknowns = full.problem().model.n_dofs() * full.unknowns().n_blocks();
                let solver =
                    hill_solver_for(analysis.hill_solver, unknowns, analysis.hill_max_freq_hz);
                point_stability_with(full, &point.coefficients, omega, &solver)
            }
            .map_err(|e| match e {
                StabilityError::Hbm(e) => e,
                other => HbmError::Stability(other.to_string()),
            })?,
        );
    }
    let monodromy_needed = match method {
        StabilityMethod::Hill => false,
        StabilityMethod::Monodromy => true,
        StabilityMethod::HillMonodromy => verdict.is_some_and(|v| !v.reliable),
    };
    if monodromy_needed {
        let full = system.full_ref();
        match point_monodromy(
            full.problem(),
            full.unknowns(),
            &point.coefficients,
            point.freq_hz,
            analysis.monodromy_steps_per_period,
        ) {
            Ok(m) => verdict = Some(m.point_stability()),
            Err(_) => match &mut verdict {
                Some(v) => v.reliable = false,
                None => verdict = Some(PointStability::failed()),
            },
        }
    }
    point.stability = verdict;
    Ok(point)
}

/// The point on the hyperplane through `predicted` normal to `normal` (both in the scaled
/// space of `newton`: unknowns over its `x_scale`, then the frequency in Hz), by its corrector
/// from `predicted`, with the operator left evaluated at it (its contact states those of the
/// point).
fn correct_on_hyperplane(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    predicted: &[f64],
    normal: &[f64],
) -> Result<FrfPoint, NewtonFailure> {
    let (y, iterations, residual) = newton.correct(system, predicted, normal)?;
    let path_point = PathPoint {
        iterations,
        residual,
        ..newton.unscaled(&y)
    };
    let mut r = vec![0.0; path_point.x.len()];
    system
        .residual(&path_point.x, path_point.omega, &mut r)
        .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
    let mut point =
        full_point(system, &path_point).map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
    point.freq_hz = y[y.len() - 1];
    Ok(point)
}

/// Solves single points of a problem at fixed frequencies (Newton from a given guess), reusing
/// one harmonic-balance operator. Used to put curves on a common grid and to refine peaks.
pub struct PointSolver<'p> {
    pub(super) system: HbmOperator<'p>,
    pub(super) continuation: Continuation,
}

impl<'p> PointSolver<'p> {
    /// A solver for `problem`.
    pub fn new(problem: &'p Problem) -> Result<Self, FrfError> {
        let system = HbmOperator::new(problem)?;
        let set = system.unknowns().clone();
        let continuation = Continuation::new(
            problem.analysis.continuation,
            arc_length_x_scale(problem, &set, &system)?,
        );
        Ok(Self {
            system,
            continuation,
        })
    }

    /// The full operator (for contact time histories after a solve).
    pub fn system(&mut self) -> &mut HbmSystem<'p> {
        self.system.full()
    }

    /// Solves at `freq_hz` from the full-coefficient guess `x0`.
    pub fn solve(&mut self, x0: &[f64], freq_hz: f64) -> Result<FrfPoint, NewtonFailure> {
        let guess = self.system.restrict(x0);
        let p = self
            .continuation
            .solve_fixed(&mut self.system, &guess, 2.0 * PI * freq_hz)?;
        let mut point = full_point(&mut self.system, &p)
            .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
        point.freq_hz = freq_hz;
        Ok(point)
    }

    /// Solves the path point on the hyperplane through `a + t (b − a)` normal to the chord
    /// from `a` to `b` (two nearby points of a path; t ∈ [0, 1] moves along the chord), in the
    /// continuation's scaled space. Unlike [`Self::solve`] it does not fix the frequency, so it
    /// stays on the branch of the chord at folds (turning points) of the path.
    pub fn solve_on_chord(
        &mut self,
        a: &FrfPoint,
        b: &FrfPoint,
        t: f64,
    ) -> Result<FrfPoint, NewtonFailure> {
        let scale = self.continuation.x_scale.clone();
        let system = &self.system;
        let scaled = |p: &FrfPoint| -> Vec<f64> {
            system
                .restrict(&p.coefficients)
                .iter()
                .zip(&scale)
                .map(|(v, s)| v / s)
                .chain(std::iter::once(p.freq_hz))
                .collect()
        };
        let (ya, yb) = (scaled(a), scaled(b));
        let mut chord: Vec<f64> = ya.iter().zip(&yb).map(|(p, q)| q - p).collect();
        let length = crate::numerics::linalg::norm(&chord);
        if length == 0.0 {
            return self.solve(&a.coefficients, a.freq_hz);
        }
        chord.iter_mut().for_each(|v| *v /= length);
        let predicted: Vec<f64> = ya.iter().zip(&yb).map(|(p, q)| p + t * (q - p)).collect();
        correct_on_hyperplane(&mut self.system, &self.continuation, &predicted, &chord)
    }
}

/// The first path segment bracketing `freq_hz`: its lower and upper end (by frequency) and
/// the fraction t ∈ [0, 1] of the way from the lower one (0 on a segment of zero width).
pub fn bracket_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<(&FrfPoint, &FrfPoint, f64)> {
    points.windows(2).find_map(|w| {
        let (lo, hi) = if w[0].freq_hz <= w[1].freq_hz {
            (&w[0], &w[1])
        } else {
            (&w[1], &w[0])
        };
        if freq_hz < lo.freq_hz || freq_hz > hi.freq_hz {
            return None;
        }
        let span = hi.freq_hz - lo.freq_hz;
        let t = if span > 0.0 {
            (freq_hz - lo.freq_hz) / span
        } else {
            0.0
        };
        Some((lo, hi, t))
    })
}

/// The linearly interpolated coefficients on the first path segment bracketing `freq_hz`.
pub fn interpolate_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<Vec<f64>> {
    let (lo, hi, t) = bracket_on_path(points, freq_hz)?;
    Some(
        lo.coefficients
            .iter()
            .zip(&hi.coefficients)
            .map(|(p, q)| p + t * (q - p))
            .collect(),
    )
}

/// The first output's first-harmonic amplitude (m), linear on the first path segment
/// bracketing `freq_hz`.
pub fn amplitude_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<f64> {
    let (lo, hi, t) = bracket_on_path(points, freq_hz)?;
    Some(lo.amplitudes[0] + t * (hi.amplitudes[0] - lo.amplitudes[0]))
}

/// The first-harmonic amplitude of output `output` (index into the problem's outputs) on a
/// reference path where it crosses the hyperplane through `point` normal to `point`'s own path,
/// and the frequency there (Hz): the reference's counterpart of the point at the same place
/// along the path, against which a bordered error estimate (see
/// [`crate::analysis::error_estimate`]) is compared. `normal` is the hyperplane as
/// [`PointAccuracy::path_normal`](crate::analysis::error_estimate::PointAccuracy::path_normal) holds it (a covector on `point`'s full coefficients on
/// `set`, then on ω in rad/s); the reference's coefficients on `reference_set` enter on the
/// blocks of `set` (the hyperplane does not see the others). Each segment of the reference
/// within a branch (not across a jump) whose ends lie on either side is a crossing,
/// interpolated linearly; the one nearest the point in relative frequency and amplitude is
/// returned. None when the reference does not cross the hyperplane.
pub fn amplitude_across_path(
    reference: &FrfRun,
    reference_set: &HarmonicSet,
    point: &FrfPoint,
    set: &HarmonicSet,
    normal: &[f64],
    output: usize,
) -> Option<(f64, f64)> {
    let blocks = set.n_blocks();
    let n = point.coefficients.len() / blocks.max(1);
    if normal.len() != n * blocks + 1 {
        return None;
    }
    let block_in_reference: Vec<Option<usize>> = set
        .blocks()
        .iter()
        .map(|b| reference_set.blocks().iter().position(|c| c == b))
        .collect();
    let side = |q: &FrfPoint| -> f64 {
        let mut g = normal[n * blocks] * 2.0 * PI * (q.freq_hz - point.freq_hz);
        for (j, jr) in block_in_reference.iter().enumerate() {
            for i in 0..n {
                let on_reference = jr.map_or(0.0, |jr| q.coefficients[jr * n + i]);
                g += normal[j * n + i] * (on_reference - point.coefficients[j * n + i]);
            }
        }
        g
    };
    let sides: Vec<f64> = reference.points.iter().map(side).collect();
    let starts = reference.branch_starts();
    let a0 = point.amplitudes[output];
    let mut best: Option<(f64, (f64, f64))> = None;
    for k in 0..reference.points.len().saturating_sub(1) {
        let (ga, gb) = (sides[k], sides[k + 1]);
        if starts.contains(&(k + 1)) || ga * gb > 0.0 || (ga == 0.0 && gb == 0.0) {
            continue;
        }
        let t = ga / (ga - gb);
        let (p, q) = (&reference.points[k], &reference.points[k + 1]);
        let freq_hz = p.freq_hz + t * (q.freq_hz - p.freq_hz);
        let amplitude = p.amplitudes[output] + t * (q.amplitudes[output] - p.amplitudes[output]);
        let distance =
            ((freq_hz - point.freq_hz) / point.freq_hz).powi(2) + ((amplitude - a0) / a0).powi(2);
        if best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, (amplitude, freq_hz)));
        }
    }
    best.map(|(_, found)| found)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::frf::status::Jump;
    use crate::numerics::PathEnd;

    /// A one-DOF point at `freq_hz` (Hz) with first- and third-harmonic cosines `c1`, `c3` (m).
    fn line_point(freq_hz: f64, c1: f64, c3: f64) -> FrfPoint {
        FrfPoint {
            freq_hz,
            amplitudes: vec![c1.abs()],
            peaks: vec![0.0],
            states: Vec::new(),
            newton_iterations: 1,
            residual: 0.0,
            coefficients: vec![c1, 0.0, c3, 0.0],
            accuracy: None,
            pending_estimate: None,
            stability: None,
        }
    }

    /// The reference path c₁ = 1 + (f − 100) (one DOF, harmonics 1 and 3) crosses the
    /// hyperplane through (100.5 Hz, c₁ = 1.3) normal to the direction (1 Hz, 1) at 100.4 Hz,
    /// c₁ = 1.4 (the 3rd harmonic, which the point's set lacks, does not enter); the segment
    /// across a jump to another branch, which crosses it too, is not a crossing.
    #[test]
    fn the_reference_is_read_where_it_crosses_the_hyperplane_normal_to_the_path() {
        let mut points: Vec<FrfPoint> = (0..=10)
            .map(|k| {
                let f = 100.0 + 0.1 * k as f64;
                line_point(f, 1.0 + (f - 100.0), 7.0)
            })
            .collect();
        // The far branch: c1 = −5 at 99 Hz and 97 Hz, on one side of the hyperplane; the
        // jump's segment from (101 Hz, 2) to (99 Hz, −5) crosses it.
        points.push(line_point(99.0, -5.0, 0.0));
        points.push(line_point(97.0, -5.0, 0.0));
        let mut reference = FrfRun {
            points,
            turning_points: Vec::new(),
            rejected_steps: 0,
            jumps: vec![Jump {
                from_hz: 101.0,
                to_hz: 97.0,
                first_point: 11,
            }],
            end: PathEnd::EndFrequency,
            elapsed_s: 0.0,
        };
        let point = FrfPoint {
            coefficients: vec![1.3, 0.0],
            ..line_point(100.5, 1.3, 0.0)
        };
        let set = HarmonicSet::new(vec![1]);
        let reference_set = HarmonicSet::new(vec![1, 3]);
        // Unit weight per Hz of frequency (ω in rad/s) and per unit of c1.
        let normal = [1.0, 0.0, 1.0 / (2.0 * PI)];
        let (amplitude, freq_hz) =
            amplitude_across_path(&reference, &reference_set, &point, &set, &normal, 0).unwrap();
        assert!((amplitude - 1.4).abs() < 1e-12, "{amplitude}");
        assert!((freq_hz - 100.4).abs() < 1e-12, "{freq_hz}");
        // Without the line but its last point, only the jump's segment crosses: none.
        reference.points.drain(..10);
        reference.jumps[0].first_point = 1;
        assert_eq!(
            amplitude_across_path(&reference, &reference_set, &point, &set, &normal, 0),
            None
        );
    }
}
