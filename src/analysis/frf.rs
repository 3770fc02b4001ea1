//! Frequency-response runs: continuation of the harmonic balance over the scene's range, with
//! per-point outputs (amplitudes, peaks, contact states) handed to an observer as they come.

use std::f64::consts::PI;
use std::time::Instant;

use crate::analysis::linear;
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::ContactState;
use crate::hbm::operator::HbmOperator;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::Problem;
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::{
    Continuation, ContinuationError, NewtonFailure, Observer, ParametricResidual, PathEnd,
    PathPoint,
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
    /// Why the run ended.
    pub end: PathEnd,
    /// Wall time of the run (s).
    pub elapsed_s: f64,
}

impl FrfRun {
    /// Whether the path reached the end frequency: only then does the run cover the range.
    pub fn is_complete(&self) -> bool {
        self.end == PathEnd::EndFrequency
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
            PathEnd::EndFrequency => None,
            PathEnd::LeftRangeBelow => Some(format!(
                "the path turned back and left the range below the start frequency at \
                 {last:.4} Hz; frequencies above {highest:.4} Hz were never reached"
            )),
            PathEnd::MaxPoints => Some(format!(
                "the point budget (analysis.max_points = {}) was used up at {last:.4} Hz; \
                 frequencies above {highest:.4} Hz were never reached",
                self.points.len()
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
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = ((best as f64 - 1.0) * dt, (best as f64 + 1.0) * dt);
    let mut c = hi - ratio * (hi - lo);
    let mut d = lo + ratio * (hi - lo);
    let (mut vc, mut vd) = (value(c), value(d));
    let mut peak = value(best as f64 * dt).max(vc).max(vd);
    while hi - lo > 1e-12 {
        if vc >= vd {
            hi = d;
            d = c;
            vd = vc;
            c = hi - ratio * (hi - lo);
            vc = value(c);
            peak = peak.max(vc);
        } else {
            lo = c;
            c = d;
            vc = vd;
            d = lo + ratio * (hi - lo);
            vd = value(d);
            peak = peak.max(vd);
        }
    }
    peak
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

struct Adapter<'o, O: FrfObserver> {
    observer: &'o mut O,
    points: Vec<FrfPoint>,
    /// A converged point whose full coefficients could not be recovered.
    failure: Option<HbmError>,
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
    Ok(FrfPoint {
        freq_hz,
        amplitudes,
        peaks,
        states: system.states().to_vec(),
        newton_iterations: p.iterations,
        residual: p.residual,
        coefficients,
    })
}

impl<O: FrfObserver> Observer<HbmOperator<'_>> for Adapter<'_, O> {
    fn accepted(&mut self, system: &mut HbmOperator<'_>, p: &PathPoint) {
        let point = match full_point(system, p) {
            Ok(point) => point,
            Err(e) => {
                self.failure.get_or_insert(e);
                return;
            }
        };
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

/// Solves the nonlinear frequency response of a problem over its analysis range.
pub fn solve<O: FrfObserver>(problem: &Problem, observer: &mut O) -> Result<FrfRun, FrfError> {
    let started = Instant::now();
    let mut system = HbmOperator::new(problem)?;
    let set = system.unknowns().clone();
    let omega0 = 2.0 * PI * problem.analysis.continuation.freq_start_hz;
    let guess = system.restrict(&linear::stuck_guess(problem, &set, omega0)?);
    let continuation = Continuation::new(
        problem.analysis.continuation,
        arc_length_x_scale(problem, &set, &system)?,
    );
    let mut adapter = Adapter {
        observer,
        points: Vec::new(),
        failure: None,
    };
    let summary = continuation.run(&mut system, &guess, &mut adapter)?;
    if let Some(e) = adapter.failure {
        return Err(FrfError::Setup(e));
    }
    Ok(FrfRun {
        points: adapter.points,
        turning_points: summary.turning_points,
        rejected_steps: summary.rejected_steps,
        leaps: summary.leaps,
        end: summary.end,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
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

/// The first path segment bracketing `freq_hz` and the linearly interpolated coefficients on it.
pub fn interpolate_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<Vec<f64>> {
    points.windows(2).find_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        let (lo, hi) = if a.freq_hz <= b.freq_hz {
            (a, b)
        } else {
            (b, a)
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
        Some(
            lo.coefficients
                .iter()
                .zip(&hi.coefficients)
                .map(|(p, q)| p + t * (q - p))
                .collect(),
        )
    })
}
