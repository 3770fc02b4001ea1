//! Frequency-response runs: continuation of the harmonic balance over the scene's range, with
//! per-point outputs (amplitudes, peaks, contact states) handed to an observer as they come.

use std::f64::consts::PI;
use std::time::Instant;

use crate::analysis::error_estimate::{ErrorEstimator, EstimateProblems, PathPlace, PointAccuracy};
use crate::analysis::linear;
use crate::analysis::monodromy::point_monodromy;
use crate::analysis::stability::{PointStability, StabilityError};
use crate::analysis::stability_sparse::{hill_solver_for, point_stability_with};
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::ContactState;
use crate::hbm::operator::HbmOperator;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::{Problem, StabilityMethod};
use crate::numerics::continuation::AdaptiveScale;
use crate::numerics::golden;
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::path::NoObserver;
use crate::numerics::{
    Continuation, ContinuationError, ContinuationSettings, NewtonFailure, Observer,
    ParametricResidual, PathEnd, PathPoint,
};

/// One converged point of a nonlinear frequency response.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrfPoint {
    /// Excitation frequency (Hz).
    pub freq_hz: f64,
    /// First-harmonic amplitude √(c₁² + s₁²) of each output DOF (m).
    pub amplitudes: Vec<f64>,
    /// Peak |q(τ)| over the period of each output DOF, static part included (m).
    pub peaks: Vec<f64>,
    /// Contact state of each contact over the period.
    pub states: Vec<ContactState>,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Final residual relative to the load norm.
    pub residual: f64,
    /// All Fourier coefficients, harmonic-major (m).
    pub coefficients: Vec<f64>,
    /// A-posteriori error estimate of the amplitudes (continuation points of a run whose
    /// scene asks for it; None for points solved on their own, such as refined peaks).
    pub accuracy: Option<PointAccuracy>,
    /// Hill stability of the point, when the scene asks for it (`analysis.stability`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<PointStability>,
}

/// The frequency (Hz) and error estimate of every point of `points` that has one, in order
/// (for [`crate::analysis::error_estimate::run_warnings`]).
pub fn accuracy_of(points: &[FrfPoint]) -> Vec<(f64, &PointAccuracy)> {
    points
        .iter()
        .filter_map(|p| p.accuracy.as_ref().map(|a| (p.freq_hz, a)))
        .collect()
}

/// A jump of an FRF run from one branch to another: where the path turned back at a fold and
/// did not come back, the run goes on on a branch found past the highest frequency reached, and
/// solves further branches inside any stretch that neither branch reached.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Jump {
    /// Highest frequency of the branch before the jump (Hz).
    pub from_hz: f64,
    /// Lowest frequency of the branch after the jump (Hz): a branch found past a fold is
    /// followed back down toward `from_hz` as far as it goes. Frequencies between the two were
    /// not computed on any branch (none when `to_hz` ≤ `from_hz`).
    pub to_hz: f64,
    /// Index of the next branch's first point in the run's points.
    pub first_point: usize,
    /// Why the run changed branch.
    pub kind: JumpKind,
}

/// Why an FRF run changed branch (see [`Jump`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum JumpKind {
    /// The path turned back at a fold and did not come back; the run went on on a branch
    /// solved just past the highest frequency reached.
    PastFold,
    /// A branch solved inside a stretch that the branches on either side of it did not reach
    /// (Newton from blends of the two ends' coefficients, then followed both ways).
    Bridge,
}

impl Jump {
    /// Width of the stretch not computed on any branch (Hz); stretches narrower than 10⁻⁹ of
    /// the frequency (round-off of a branch followed onto an end frequency) count as none.
    pub fn uncovered_hz(&self) -> f64 {
        let gap = self.to_hz - self.from_hz;
        if gap > 1e-9 * self.to_hz.abs() {
            gap
        } else {
            0.0
        }
    }
}

/// Receives the events of an FRF run.
pub trait FrfObserver {
    /// A point converged.
    fn point(&mut self, _point: &FrfPoint) {}
    /// A step was cut (frequency of the last converged point, Hz).
    fn step_cut(&mut self, _freq_hz: f64, _step: f64, _new_step: f64, _reason: &NewtonFailure) {}
    /// A turning point was passed (Hz).
    fn turning_point(&mut self, _freq_hz: f64) {}
    /// The path could not be followed from `from_hz` and was resumed at `to_hz` (Hz).
    fn leap(&mut self, _from_hz: f64, _to_hz: f64) {}
    /// The path turned back at a fold and did not return; it goes on on another branch, whose
    /// points come next (see [`Jump`]).
    fn jump(&mut self, _jump: &Jump) {}
}

/// Observer that ignores everything.
pub struct Silent;
impl FrfObserver for Silent {}

/// Result of an FRF run.
#[derive(Debug, Clone, PartialEq)]
pub struct FrfRun {
    /// Converged points in path order.
    pub points: Vec<FrfPoint>,
    /// Turning-point frequencies (Hz).
    pub turning_points: Vec<f64>,
    /// Number of cut steps.
    pub rejected_steps: usize,
    /// Stretches leapt over: (last point before, first point after), Hz.
    pub leaps: Vec<(f64, f64)>,
    /// Jumps to another branch after a fold the path did not come back from.
    pub jumps: Vec<Jump>,
    /// Why the run ended.
    pub end: PathEnd,
    /// Wall time of the run (s).
    pub elapsed_s: f64,
}

/// One crossing of a frequency by a path ([`FrfRun::crossings`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathCrossing {
    /// Amplitude of the output there, interpolated along the segment (m).
    pub amplitude: f64,
    /// Index of the segment's first point.
    pub segment: usize,
    /// Index of the segment's point nearer in frequency.
    pub nearest_point: usize,
}

impl FrfRun {
    /// Indices of the points where a branch reached by a jump starts.
    pub fn branch_starts(&self) -> Vec<usize> {
        self.jumps.iter().map(|j| j.first_point).collect()
    }

    /// Every place where the path crosses `freq_hz` (Hz) within a branch (a segment between
    /// consecutive points bracketing it, not across a jump), in path order: the linearly
    /// interpolated amplitude of output `output` there (m), the segment's first point index,
    /// and the index of its point nearer in frequency. A folded path crosses a frequency more
    /// than once, which is why a comparison between paths picks among these.
    pub fn crossings(&self, freq_hz: f64, output: usize) -> Vec<PathCrossing> {
        let starts = self.branch_starts();
        let mut out = Vec::new();
        for k in 0..self.points.len().saturating_sub(1) {
            if starts.contains(&(k + 1)) {
                continue;
            }
            let (p, q) = (&self.points[k], &self.points[k + 1]);
            if (p.freq_hz - freq_hz) * (q.freq_hz - freq_hz) > 0.0 || p.freq_hz == q.freq_hz {
                continue;
            }
            let t = (freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
            out.push(PathCrossing {
                amplitude: p.amplitudes[output] + t * (q.amplitudes[output] - p.amplitudes[output]),
                segment: k,
                nearest_point: if t < 0.5 { k } else { k + 1 },
            });
        }
        out
    }

    /// Whether the run covers the range: the path reached the end frequency, and every
    /// stretch it jumped over at a fold was computed on some branch.
    pub fn is_complete(&self) -> bool {
        self.incomplete_reason().is_none()
    }

    /// Why the run did not cover the range (None when it did), for the run's status line
    /// (`incomplete: <reason>`).
    pub fn incomplete_reason(&self) -> Option<String> {
        let last = self.points.last().map_or(f64::NAN, |p| p.freq_hz);
        let highest = self
            .points
            .iter()
            .map(|p| p.freq_hz)
            .fold(f64::NEG_INFINITY, f64::max);
        match self.end {
            PathEnd::EndFrequency => {
                let gaps: Vec<String> = self
                    .jumps
                    .iter()
                    .filter(|j| j.uncovered_hz() > 0.0)
                    .map(|j| format!("{:.4}-{:.4} Hz", j.from_hz, j.to_hz))
                    .collect();
                (!gaps.is_empty()).then(|| {
                    format!(
                        "no solution was found at {}: the path turned back at a fold there and \
                         neither the branch found past it nor a branch solved inside reached \
                         those frequencies",
                        gaps.join(", ")
                    )
                })
            }
            PathEnd::LeftRangeBelow => Some(format!(
                "the path turned back and left the range below the start frequency at \
                 {last:.4} Hz; frequencies above {highest:.4} Hz were never reached"
            )),
            PathEnd::MaxPoints => Some(format!(
                "the point budget (analysis.max_points = {}) was used up at {last:.4} Hz; \
                 frequencies above {highest:.4} Hz were never reached",
                self.points.len()
            )),
            PathEnd::NoProgress => Some(format!(
                "the path wandered back and forth below {highest:.4} Hz without getting \
                 higher (last point at {last:.4} Hz); frequencies above were never reached"
            )),
        }
    }
}

/// Errors of an FRF run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrfError {
    /// Building the operator failed.
    #[error("{0}")]
    Setup(#[from] HbmError),
    /// The linear starting guess failed.
    #[error("linear starting guess: {0}")]
    Guess(#[from] LinearSolveError),
    /// Continuation failed.
    #[error("{0}")]
    Continuation(#[from] ContinuationError),
}

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

/// Scale of each unknown in the arc length (m), in the operator's layout: per coefficient
/// block, the largest stuck-linear response norm of that kind of block over the range (the
/// static block's norm for the 0th harmonic, the dynamic blocks' for the others), divided so
/// that climbing to it costs a quarter of the range in arc length.
///
/// One scale for all unknowns would let a large static part (a high pre-load) dominate the
/// arc length: the dynamic response would then hardly count, steps would grow to the largest
/// one and cross resonance peaks. Each kind of block gets its own scale, with a floor of 10⁻³
/// of the other so that a block without load (no static load) does not get a zero scale.
fn arc_length_x_scale(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> Result<Vec<f64>, LinearSolveError> {
    let a = &problem.analysis.continuation;
    // The 0th harmonic of the guess does not depend on ω: solved once, the dynamic harmonics
    // on the grid.
    let dynamic = HarmonicSet::new(
        set.harmonics()
            .iter()
            .copied()
            .filter(|&h| h != 0)
            .collect(),
    );
    let static_norm = if set.has_constant() {
        crate::numerics::linalg::norm(&linear::stuck_guess(
            problem,
            &HarmonicSet::new(vec![0]),
            0.0,
        )?)
    } else {
        0.0
    };
    let mut dynamic_norm = 0.0_f64;
    for i in 0..=40 {
        let f = a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / 40.0;
        let x = linear::stuck_guess(problem, &dynamic, 2.0 * PI * f)?;
        dynamic_norm = dynamic_norm.max(crate::numerics::linalg::norm(&x));
    }
    let x_ref = static_norm.hypot(dynamic_norm);
    let range = a.freq_end_hz - a.freq_start_hz;
    let to_scale =
        |block_norm: f64| (block_norm.max(1e-3 * x_ref) / (0.25 * range)).max(f64::MIN_POSITIVE);
    let (static_scale, dynamic_scale) = (to_scale(static_norm), to_scale(dynamic_norm));
    let n = problem.model.n_dofs();
    let full: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let s = match b {
                Block::Constant => static_scale,
                _ => dynamic_scale,
            };
            std::iter::repeat_n(s, n)
        })
        .collect();
    Ok(system.restrict(&full))
}

/// The groups of [`arc_length_x_scale`] (static block, dynamic blocks) as an adaptive scale:
/// each grows with its block's norm along the path, at the same climb (a quarter of the range).
fn adaptive_scale(problem: &Problem, set: &HarmonicSet, system: &HbmOperator<'_>) -> AdaptiveScale {
    let a = &problem.analysis.continuation;
    let n = problem.model.n_dofs();
    let full: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let g = if *b == Block::Constant { 0.0 } else { 1.0 };
            std::iter::repeat_n(g, n)
        })
        .collect();
    AdaptiveScale {
        group_of: system.restrict(&full).iter().map(|&g| g as usize).collect(),
        climb: 0.25 * (a.freq_end_hz - a.freq_start_hz),
    }
}

/// For each output DOF, the indices of its first-harmonic cosine and sine among the operator's
/// unknowns (outputs the operator does not carry are left out), for the step length to follow
/// the output amplitudes ([`Continuation::with_amplitude_steps`]).
fn output_amplitude_groups(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> Vec<Vec<usize>> {
    let n = problem.model.n_dofs();
    let blocks: Vec<usize> = [set.cos_block(1), set.sin_block(1)]
        .into_iter()
        .flatten()
        .collect();
    problem
        .outputs
        .iter()
        .filter_map(|&d| {
            let mut marker = vec![0.0; n * set.n_blocks()];
            for &j in &blocks {
                marker[j * n + d] = 1.0;
            }
            let group: Vec<usize> = system
                .restrict(&marker)
                .iter()
                .enumerate()
                .filter(|(_, &v)| v == 1.0)
                .map(|(i, _)| i)
                .collect();
            (!group.is_empty()).then_some(group)
        })
        .collect()
}

struct Adapter<'o, 'e, O: FrfObserver> {
    observer: &'o mut O,
    points: Vec<FrfPoint>,
    /// A converged point whose full coefficients could not be recovered.
    failure: Option<HbmError>,
    /// The error estimate of every accepted point, when the scene asks for it.
    estimator: Option<ErrorEstimator<'e>>,
}

/// The outputs of a converged path point, on full coefficients.
fn full_point(system: &mut HbmOperator<'_>, p: &PathPoint) -> Result<FrfPoint, HbmError> {
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
fn with_stability(
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

impl<O: FrfObserver> Observer<HbmOperator<'_>> for Adapter<'_, '_, O> {
    fn accepted(&mut self, system: &mut HbmOperator<'_>, p: &PathPoint, normal: Option<&[f64]>) {
        let mut point =
            match full_point(system, p).and_then(|point| with_stability(system, point, p.omega)) {
                Ok(point) => point,
                Err(e) => {
                    self.failure.get_or_insert(e);
                    return;
                }
            };
        if let Some(estimator) = &mut self.estimator {
            let place = normal.map(|normal| PathPlace {
                normal,
                step: p.step,
            });
            point.accuracy =
                Some(estimator.estimate(&point.coefficients, p.omega, place, &point.states));
        }
        self.observer.point(&point);
        self.points.push(point);
    }
    fn rejected(&mut self, freq_hz: f64, step: f64, new_step: f64, reason: &NewtonFailure) {
        self.observer.step_cut(freq_hz, step, new_step, reason);
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.observer.turning_point(freq_hz);
    }
    fn leap(&mut self, from_hz: f64, to_hz: f64) {
        self.observer.leap(from_hz, to_hz);
    }
}

/// Point budget of the fill of a branch back toward the fold (see [`solve`]).
const FILL_POINTS: usize = 500;
/// Most jumps to another branch in one run (see [`solve`]).
const MAX_JUMPS: usize = 8;
/// How far past the highest frequency a path reached a jump lands, as fractions of the range,
/// tried in turn until a point converges there.
const JUMP_FRACTIONS: &[f64] = &[0.0005, 0.002, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2];

/// Solves the nonlinear frequency response of a problem over its analysis range.
///
/// The path is followed from the start frequency. A path that turns back at a fold and does not
/// come back toward the end (it leaves the range below the start, or wanders without reaching
/// a higher frequency) is not the whole answer: as in a stepped-sine test sweeping
/// up, the response then jumps to another branch. The run solves a point just past the highest
/// frequency reached (see [`jump_target`]) and
/// follows the path on from it, up to [`MAX_JUMPS`] times. The new branch is first followed
/// back down toward the highest frequency reached, to fill the gap (those points come first,
/// in rising frequency). Each jump is reported ([`FrfRun::jumps`], [`FrfObserver::jump`]) with
/// the frequencies its ends reached: the stretch between them was not computed on any branch
/// (empty when the fill got back to the highest frequency).
pub fn solve<O: FrfObserver>(problem: &Problem, observer: &mut O) -> Result<FrfRun, FrfError> {
    let started = Instant::now();
    let mut system = HbmOperator::new(problem)?;
    let set = system.unknowns().clone();
    let settings = problem.analysis.continuation;
    let omega0 = 2.0 * PI * settings.freq_start_hz;
    let mut x_scale = arc_length_x_scale(problem, &set, &system)?;
    let mut guess = start_guess(problem, &set, &mut system, &x_scale, omega0)?;
    // How the scale grows and which amplitudes the steps follow: the same on every branch.
    let adaptive = adaptive_scale(problem, &set, &system);
    let amplitude_groups = output_amplitude_groups(problem, &set, &system);
    let refined = EstimateProblems::new(problem);
    let estimator = refined
        .as_ref()
        .map(|r| ErrorEstimator::new(problem, r))
        .transpose()?;
    let mut adapter = Adapter {
        observer,
        points: Vec::new(),
        failure: None,
        estimator,
    };
    let mut run = FrfRun {
        points: Vec::new(),
        turning_points: Vec::new(),
        rejected_steps: 0,
        leaps: Vec::new(),
        jumps: Vec::new(),
        end: PathEnd::MaxPoints,
        elapsed_s: 0.0,
    };
    let mut start_hz = settings.freq_start_hz;
    loop {
        let segment = ContinuationSettings {
            freq_start_hz: start_hz,
            max_points: settings.max_points.saturating_sub(adapter.points.len()),
            ..settings
        };
        let mut continuation = Continuation::new(segment, x_scale.clone())
            .with_adaptive_scale(adaptive.clone())
            .with_amplitude_steps(amplitude_groups.clone());
        let outcome = continuation.run(&mut system, &guess, &mut adapter);
        // The next branch starts with the scale this one grew to.
        x_scale.clone_from(&continuation.x_scale);
        if let Some(e) = adapter.failure.take() {
            return Err(FrfError::Setup(e));
        }
        match outcome {
            Ok(summary) => {
                run.turning_points.extend(summary.turning_points);
                run.rejected_steps += summary.rejected_steps;
                run.leaps.extend(summary.leaps);
                run.end = summary.end;
            }
            // A stall is not a fold: the path goes on past it, but could not be followed.
            Err(e) => return Err(e.into()),
        }
        let turned_back = matches!(run.end, PathEnd::LeftRangeBelow | PathEnd::NoProgress);
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        let past_folds = run
            .jumps
            .iter()
            .filter(|j| j.kind == JumpKind::PastFold)
            .count();
        if !turned_back || past_folds >= MAX_JUMPS || budget < 2 {
            break;
        }
        let highest = adapter
            .points
            .iter()
            .map(|p| p.freq_hz)
            .fold(f64::NEG_INFINITY, f64::max);
        let Some((freq_hz, x)) = jump_target(
            problem,
            &set,
            &mut system,
            &continuation,
            &adapter.points,
            highest,
        )?
        else {
            break;
        };
        let branching = Branching {
            settings,
            x_scale: &x_scale,
            adaptive: &adaptive,
            amplitude_groups: &amplitude_groups,
        };
        // Fill the gap on the new branch, back down toward the highest frequency reached, and
        // report those points first (in rising frequency) so that the path reads on from the
        // jump. The fill's first point (at the jump target) is solved again by the branch's
        // own run.
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        let (mut fill, summary) = branching.follow(
            &mut system,
            &x,
            freq_hz,
            highest,
            (budget / 2).min(FILL_POINTS),
            &mut adapter.estimator,
        );
        if let Some(summary) = &summary {
            run.turning_points.extend(&summary.turning_points);
            run.rejected_steps += summary.rejected_steps;
        }
        // A stretch neither branch reached: solve branches inside it, between the highest
        // point before the jump and the lowest point of the new branch.
        let top = adapter
            .points
            .iter()
            .rev()
            .find(|p| p.freq_hz == highest)
            .cloned();
        let bottom = fill
            .iter()
            .min_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz))
            .cloned();
        fill.reverse();
        fill.pop();
        let bridges = match (top, bottom) {
            (Some(top), Some(bottom)) if bottom.freq_hz > highest => {
                let budget = settings
                    .max_points
                    .saturating_sub(adapter.points.len() + fill.len())
                    / 2;
                branching.bridge(&mut system, &top, &bottom, budget, &mut adapter.estimator)
            }
            _ => Vec::new(),
        };
        let mut reached = highest;
        let mut kind = JumpKind::PastFold;
        for branch in bridges.into_iter().chain([fill]) {
            let lowest = branch
                .iter()
                .map(|p| p.freq_hz)
                .fold(f64::INFINITY, f64::min);
            let jump = Jump {
                from_hz: reached,
                // A fill that solved nothing below the jump target starts there.
                to_hz: if lowest.is_finite() { lowest } else { freq_hz },
                first_point: adapter.points.len(),
                kind,
            };
            adapter.observer.jump(&jump);
            run.jumps.push(jump);
            for mut p in branch {
                reached = reached.max(p.freq_hz);
                // Points followed on a branch have their estimate (across the path) already;
                // the others (solved at a fixed frequency) take it at their frequency.
                if let (Some(estimator), None) = (&mut adapter.estimator, &p.accuracy) {
                    let omega = 2.0 * PI * p.freq_hz;
                    p.accuracy = Some(estimator.estimate(&p.coefficients, omega, None, &p.states));
                }
                adapter.observer.point(&p);
                adapter.points.push(p);
            }
            kind = JumpKind::Bridge;
        }
        start_hz = freq_hz;
        guess = x;
    }
    run.points = adapter.points;
    run.elapsed_s = started.elapsed().as_secs_f64();
    Ok(run)
}

/// Point budget of each direction of a bridge branch (see [`Branching::bridge`]).
const BRIDGE_POINTS: usize = 300;
/// Most branches solved inside the stretches left uncovered by one jump.
const MAX_BRIDGES: usize = 8;
/// Where in an uncovered stretch a bridge branch is sought, as fractions of the stretch, in
/// the order tried.
const BRIDGE_FRACTIONS: &[f64] = &[0.5, 0.25, 0.75, 0.1, 0.9];
/// Weights w of the blends (1 − w)·lower end + w·upper end of the stretch's end points'
/// coefficients tried as Newton guesses, in the order tried.
const BRIDGE_BLENDS: &[f64] = &[0.5, 0.25, 0.75, 0.0, 1.0];

/// What the branches of one run share: the settings, the arc-length scale, how it grows and
/// which amplitudes the steps follow.
struct Branching<'a> {
    settings: ContinuationSettings,
    x_scale: &'a [f64],
    adaptive: &'a AdaptiveScale,
    amplitude_groups: &'a [Vec<usize>],
}

impl Branching<'_> {
    /// Follows the path silently from `x` (the operator's unknowns, converged at `from_hz`)
    /// toward `to_hz` (below or above) with at most `max_points` points. Returns the points in
    /// path order (the first is the start point) and the summary, None when the continuation
    /// failed (its points up to the failure are kept). With an `estimator`, each point gets
    /// its error estimate across the path as it is accepted (the estimator is lent to the
    /// branch's observer and given back).
    fn follow<'e>(
        &self,
        system: &mut HbmOperator<'_>,
        x: &[f64],
        from_hz: f64,
        to_hz: f64,
        max_points: usize,
        estimator: &mut Option<ErrorEstimator<'e>>,
    ) -> (Vec<FrfPoint>, Option<crate::numerics::PathSummary>) {
        let settings = ContinuationSettings {
            freq_start_hz: from_hz,
            freq_end_hz: to_hz,
            max_points,
            ..self.settings
        };
        let mut collect = Adapter {
            observer: &mut Silent,
            points: Vec::new(),
            failure: None,
            estimator: estimator.take(),
        };
        let mut continuation = Continuation::new(settings, self.x_scale.to_vec())
            .with_adaptive_scale(self.adaptive.clone())
            .with_amplitude_steps(self.amplitude_groups.to_vec());
        let summary = continuation.run(system, x, &mut collect).ok();
        *estimator = collect.estimator.take();
        (collect.points, summary)
    }

    /// Branches inside the stretch between `below` (the highest point of the branch before a
    /// jump) and `above` (the lowest point of the branch after it), which neither reached.
    ///
    /// At a fold of the sampled contact law's solution curve, two branches can fold away from
    /// each other with solutions between them on neither (a damper bouncing at a low
    /// pre-load). Newton from blends of the two ends' coefficients ([`BRIDGE_BLENDS`]) at
    /// points inside the stretch ([`BRIDGE_FRACTIONS`]) finds such solutions; each is followed
    /// down toward `below` and up toward `above`, and what is still uncovered on either side
    /// is bridged in turn, up to [`MAX_BRIDGES`] branches and `budget` points. Returns the
    /// branches found, each in path order from its lowest point up, sorted by their lowest
    /// frequency.
    fn bridge<'e>(
        &self,
        system: &mut HbmOperator<'_>,
        below: &FrfPoint,
        above: &FrfPoint,
        budget: usize,
        estimator: &mut Option<ErrorEstimator<'e>>,
    ) -> Vec<Vec<FrfPoint>> {
        let mut branches: Vec<Vec<FrfPoint>> = Vec::new();
        let mut gaps = vec![(below.clone(), above.clone())];
        let mut used = 0;
        let solver = Continuation::new(self.settings, self.x_scale.to_vec());
        while let Some((lo, hi)) = gaps.pop() {
            if branches.len() >= MAX_BRIDGES || used + 2 > budget {
                break;
            }
            let Some((freq_hz, x)) = solve_between(system, &solver, &lo, &hi) else {
                continue;
            };
            let per_side = BRIDGE_POINTS.min((budget - used) / 2);
            let (mut down, _) = self.follow(system, &x, freq_hz, lo.freq_hz, per_side, estimator);
            let (up, _) = self.follow(system, &x, freq_hz, hi.freq_hz, per_side, estimator);
            down.reverse();
            // Both directions start with the point at `freq_hz`: keep one.
            let branch: Vec<FrfPoint> = down.into_iter().chain(up.into_iter().skip(1)).collect();
            used += branch.len();
            let by_freq = |a: &&FrfPoint, b: &&FrfPoint| a.freq_hz.total_cmp(&b.freq_hz);
            let (Some(low), Some(high)) =
                (branch.iter().min_by(by_freq), branch.iter().max_by(by_freq))
            else {
                continue;
            };
            let gap_below = Jump {
                from_hz: lo.freq_hz,
                to_hz: low.freq_hz,
                first_point: 0,
                kind: JumpKind::Bridge,
            };
            if gap_below.uncovered_hz() > 0.0 {
                gaps.push((lo.clone(), low.clone()));
            }
            let gap_above = Jump {
                from_hz: high.freq_hz,
                to_hz: hi.freq_hz,
                ..gap_below
            };
            if gap_above.uncovered_hz() > 0.0 {
                gaps.push((high.clone(), hi.clone()));
            }
            branches.push(branch);
        }
        branches.sort_by(|a, b| a[0].freq_hz.total_cmp(&b[0].freq_hz));
        branches
    }
}

/// A converged point strictly between `lo` and `hi` (Hz and operator unknowns), by Newton at
/// fixed frequency from blends of their coefficients (see [`Branching::bridge`]).
fn solve_between(
    system: &mut HbmOperator<'_>,
    solver: &Continuation,
    lo: &FrfPoint,
    hi: &FrfPoint,
) -> Option<(f64, Vec<f64>)> {
    for fraction in BRIDGE_FRACTIONS {
        let freq_hz = lo.freq_hz + fraction * (hi.freq_hz - lo.freq_hz);
        let omega = 2.0 * PI * freq_hz;
        for w in BRIDGE_BLENDS {
            let blend: Vec<f64> = lo
                .coefficients
                .iter()
                .zip(&hi.coefficients)
                .map(|(a, b)| (1.0 - w) * a + w * b)
                .collect();
            let guess = system.restrict(&blend);
            if let Ok(p) = solver.solve_fixed(system, &guess, omega) {
                return Some((freq_hz, p.x));
            }
        }
    }
    None
}

/// The starting guess at ω0 (rad/s): the stuck linear solution, or where Newton does not
/// converge from it (a low pre-load: the contacts open for most of the period) the solution
/// converged from the open-contact guess ([`linear::open_guess`]), else from either on the
/// static state with the contacts ([`contact_statics`]), else the end of a short
/// continuation onto ω0 from a point solved a little off it ([`START_OFFSETS`]). When none converges the
/// stuck guess is returned and the run reports its failure at the start.
fn start_guess(
    problem: &Problem,
    set: &HarmonicSet,
    system: &mut HbmOperator<'_>,
    x_scale: &[f64],
    omega0: f64,
) -> Result<Vec<f64>, FrfError> {
    let stuck = system.restrict(&linear::stuck_guess(problem, set, omega0)?);
    let newton = Continuation::new(problem.analysis.continuation, x_scale.to_vec());
    if newton.solve_fixed(system, &stuck, omega0).is_ok() {
        return Ok(stuck);
    }
    let open = system.restrict(&linear::open_guess(problem, set, omega0)?);
    if let Ok(p) = newton.solve_fixed(system, &open, omega0) {
        return Ok(p.x);
    }
    // Contacts open at rest (gaps the pre-load must close): the linear guesses leave the
    // damper where it hangs free. Solve the statics with the contacts first, then the linear
    // harmonics on that static state.
    if let Some(statics) = contact_statics(problem, set)? {
        for dynamic in [
            linear::stuck_guess(problem, set, omega0)?,
            linear::open_guess(problem, set, omega0)?,
        ] {
            let n = problem.model.n_dofs();
            let mut guess = dynamic;
            if let Some(j) = set.constant_block() {
                guess[j * n..(j + 1) * n].copy_from_slice(&statics);
            }
            let guess = system.restrict(&guess);
            if let Ok(p) = newton.solve_fixed(system, &guess, omega0) {
                return Ok(p.x);
            }
        }
    }
    // On (or next to) a resonance of the stuck structure the stuck guess is near-singular:
    // start a little off it, where the guess is sound, and follow the path onto ω0 (from
    // below, then from above).
    for offset in START_OFFSETS {
        for sign in [-1.0, 1.0] {
            let f0 = omega0 / (2.0 * PI);
            let from_hz = f0 * (1.0 + sign * offset);
            let near = system.restrict(&linear::stuck_guess(problem, set, 2.0 * PI * from_hz)?);
            let settings = ContinuationSettings {
                freq_start_hz: from_hz,
                freq_end_hz: f0,
                max_points: START_APPROACH_POINTS,
                ..problem.analysis.continuation
            };
            let mut approach = Continuation::new(settings, x_scale.to_vec());
            if let Ok(summary) = approach.run(system, &near, &mut NoObserver) {
                if summary.end == PathEnd::EndFrequency {
                    if let Some(p) = summary.points.last() {
                        return Ok(p.x.clone());
                    }
                }
            }
        }
    }
    Ok(stuck)
}

/// The static state with the contacts (m), when the unknowns include the 0th harmonic: the
/// harmonic balance of the 0th harmonic alone (normal springs with lift-off, and the
/// tangential force m μ N of each contact's initial state, since nothing moves), solved by
/// Newton from the sliding static state ([`linear::sliding_static`]), else from the stuck
/// static guess. None when neither converges.
fn contact_statics(problem: &Problem, set: &HarmonicSet) -> Result<Option<Vec<f64>>, FrfError> {
    if !set.has_constant() {
        return Ok(None);
    }
    let mut statics = problem.clone();
    statics.harmonics = Vec::new();
    let static_set = HarmonicSet::new(vec![0]);
    let mut system = HbmOperator::new(&statics)?;
    let mut guesses = Vec::new();
    if let Ok(q) = linear::sliding_static(&statics) {
        guesses.push(system.restrict(&q));
    }
    guesses.push(system.restrict(&linear::stuck_guess(&statics, &static_set, 0.0)?));
    let scale = vec![1.0; guesses[0].len()];
    let newton = Continuation::new(statics.analysis.continuation, scale);
    let omega = 2.0 * PI * statics.analysis.continuation.freq_start_hz;
    for guess in guesses {
        if let Ok(p) = newton.solve_fixed(&mut system, &guess, omega) {
            return Ok(Some(system.expand(&p.x, omega)?));
        }
    }
    Ok(None)
}

/// Relative frequency offsets at which a start on a resonance of the stuck structure is first
/// solved (see [`start_guess`]).
const START_OFFSETS: &[f64] = &[1e-2, 5e-2];
/// Point budget of the approach onto the start frequency (see [`start_guess`]).
const START_APPROACH_POINTS: usize = 200;

/// A converged point just past `highest` (Hz) on whatever branch Newton finds there, for the
/// path to go on from after a fold it did not come back from: at each of [`JUMP_FRACTIONS`] of
/// the range past `highest` (capped at the end frequency), from the stuck linear guess there,
/// the open-contact one (harmonics of the open structure on the stuck static state), then from
/// the highest point solved so far. Returns the frequency and the operator's
/// unknowns, or None when no guess converges.
fn jump_target(
    problem: &Problem,
    set: &HarmonicSet,
    system: &mut HbmOperator<'_>,
    continuation: &Continuation,
    points: &[FrfPoint],
    highest: f64,
) -> Result<Option<(f64, Vec<f64>)>, FrfError> {
    let settings = &problem.analysis.continuation;
    let range = settings.freq_end_hz - settings.freq_start_hz;
    let top = points.iter().find(|p| p.freq_hz == highest);
    for fraction in JUMP_FRACTIONS {
        let freq_hz = (highest + fraction * range).min(settings.freq_end_hz);
        if freq_hz <= highest {
            return Ok(None);
        }
        let omega = 2.0 * PI * freq_hz;
        let mut guesses = vec![
            system.restrict(&linear::stuck_guess(problem, set, omega)?),
            system.restrict(&linear::open_guess(problem, set, omega)?),
        ];
        if let Some(p) = top {
            guesses.push(system.restrict(&p.coefficients));
        }
        for g in guesses {
            if let Ok(p) = continuation.solve_fixed(system, &g, omega) {
                return Ok(Some((freq_hz, p.x)));
            }
        }
    }
    Ok(None)
}

/// Solves single points of a problem at fixed frequencies (Newton from a given guess), reusing
/// one harmonic-balance operator. Used to put curves on a common grid and to refine peaks.
pub struct PointSolver<'p> {
    system: HbmOperator<'p>,
    continuation: Continuation,
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
        let (y, iterations, residual) =
            self.continuation
                .correct(&mut self.system, &predicted, &chord)?;
        let n = y.len() - 1;
        let x: Vec<f64> = y[..n].iter().zip(&scale).map(|(v, s)| v * s).collect();
        let omega = 2.0 * PI * y[n];
        // Leave the operator (and its contact states) evaluated at the returned point.
        let mut r = vec![0.0; n];
        self.system
            .residual(&x, omega, &mut r)
            .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
        let path_point = PathPoint {
            omega,
            x,
            iterations,
            residual,
            step: 0.0,
        };
        let mut point = full_point(&mut self.system, &path_point)
            .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
        point.freq_hz = y[n];
        Ok(point)
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
/// [`PointAccuracy::path_normal`] holds it (a covector on `point`'s full coefficients on
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

    fn run_with_jumps(jumps: Vec<Jump>) -> FrfRun {
        FrfRun {
            points: Vec::new(),
            turning_points: Vec::new(),
            rejected_steps: 0,
            leaps: Vec::new(),
            jumps,
            end: PathEnd::EndFrequency,
            elapsed_s: 0.0,
        }
    }

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
        let mut reference = run_with_jumps(vec![Jump {
            from_hz: 101.0,
            to_hz: 97.0,
            first_point: 11,
            kind: JumpKind::PastFold,
        }]);
        reference.points = points;
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

    /// A path that reached the end frequency but jumped over a stretch at a fold that no branch
    /// reached does not cover the range; one whose jumps left nothing uncovered (or only the
    /// round-off of a branch followed onto an end frequency) does.
    #[test]
    fn an_uncovered_stretch_makes_the_run_incomplete() {
        let jump = |from_hz: f64, to_hz: f64| Jump {
            from_hz,
            to_hz,
            first_point: 0,
            kind: JumpKind::PastFold,
        };
        assert!(run_with_jumps(vec![jump(66.0, 66.0)]).is_complete());
        assert!(run_with_jumps(vec![jump(66.0, 66.0 + 1e-12)]).is_complete());
        let gap = run_with_jumps(vec![jump(66.0, 66.0), jump(151.84, 152.14)]);
        assert!(!gap.is_complete());
        let reason = gap.incomplete_reason().unwrap();
        assert!(reason.contains("151.8400-152.1400 Hz"), "{reason}");
    }
}
