//! Parameter sweeps of the limit analysis: optimal curves (peak amplitude of each limit case
//! vs the pre-load), resonance-frequency limits, geometry variability (paper Figs. 15-19).
//! On a nonlinear-mode scene each value computes the mode of every case and the resonance peak
//! it predicts (single-nonlinear-mode theory): the optimal curve from one mode per case and
//! value instead of one forced response.
//!
//! A sweep parameter p drives one or more scene fields linearly (field = offset + scale·p),
//! so any numeric field can be swept, and a geometric parameter such as the apical angle β can
//! move both contact frames at once. An optional second parameter (the series) repeats the
//! sweep at each of its values, e.g. one optimal curve per apical angle. Each sweep point
//! computes either the resonance peaks of the limit and intermediate cases (`peaks`) or the
//! whole limit analysis (`limits`: FRF bands, classification, bound scan, loops).
//!
//! Every sweep point is independent: points run in parallel with rayon, each on its own scene,
//! and results do not depend on the thread count. A case that cannot be solved at one point
//! (e.g. a continuation that stalls at a low pre-load) or that does not cover the range is
//! recorded with its reason ([`SweepPoint::failures`]), the other cases of the point are still
//! solved, and the sweep goes on; an override that makes the scene invalid stops it (`check`
//! refuses such sweeps up front).

use rayon::prelude::*;

use crate::analysis::limits::{self, LimitAnalysis, LimitSettings, Peak};
use crate::analysis::nonlinear_modes::{self, NonlinearModeRun, NonlinearModeSettings};
use crate::model::Problem;
use crate::scene::{self, Scene, SceneError, SweepOutput, SweepSpec};

/// Errors of a sweep.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The scene at a sweep value is invalid.
    #[error("sweep {parameter} = {value}: {source}")]
    Scene {
        /// Parameter name (with the series parameter, if any).
        parameter: String,
        /// Parameter value.
        value: f64,
        /// Cause.
        source: SceneError,
    },
}

/// Result of one sweep value.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SweepPoint {
    /// Parameter value.
    pub value: f64,
    /// Series parameter value, when the sweep has a series.
    pub series: Option<f64>,
    /// Case names: the limit cases, then the intermediate ones.
    pub cases: Vec<String>,
    /// How many of the leading cases bound the response: the two limit cases m = ±1 of a
    /// forced response; every combination of m = ±1 per damper side of a nonlinear mode
    /// ([`nonlinear_modes::mode_cases`]).
    pub limit_cases: usize,
    /// Resonance peak of each case (first output DOF); `None` where the case failed or did not
    /// cover the range (an unfinished path's highest point need not be the peak).
    pub peaks: Vec<Option<Peak>>,
    /// Every case (limit, intermediate and, with `output = "limits"`, scanned) that failed or
    /// did not cover the range, one line each ("curve `<name>` failed: …", "curve `<name>`
    /// incomplete: …"); empty when everything was solved.
    pub failures: Vec<String>,
    /// The whole limit analysis (output `limits` only, with the finished points of unfinished
    /// curves; not serialised).
    #[serde(skip)]
    pub analysis: Option<Box<LimitAnalysis>>,
}

impl SweepPoint {
    /// Larger and smaller resonance-peak amplitude over the limit cases (m); `None` if one
    /// of them failed.
    pub fn limit_amplitudes(&self) -> Option<(f64, f64)> {
        self.limit_range(|p| p.amplitude)
    }

    /// Higher and lower resonance frequency over the limit cases (Hz); `None` if one of them
    /// failed.
    pub fn limit_frequencies(&self) -> Option<(f64, f64)> {
        self.limit_range(|p| p.freq_hz)
    }

    /// Largest and smallest of `value` over the limit cases' peaks; `None` if one is missing.
    fn limit_range(&self, value: impl Fn(&Peak) -> f64) -> Option<(f64, f64)> {
        let peaks = &self.peaks[..self.limit_cases.min(self.peaks.len())];
        peaks
            .iter()
            .try_fold((f64::NEG_INFINITY, f64::INFINITY), |(hi, lo), p| {
                let v = value(p.as_ref()?);
                Some((hi.max(v), lo.min(v)))
            })
    }

    /// Whether the limit cases' peaks are all refined interior maxima (true resonance peaks).
    pub fn limits_refined(&self) -> bool {
        self.peaks[..self.limit_cases.min(self.peaks.len())]
            .iter()
            .all(|p| p.as_ref().is_some_and(|p| p.refined))
    }
}

/// Where a sweep's resonance peaks come from: the forced response of each case of the limit
/// analysis, or on a nonlinear-mode scene the prediction of each case's mode.
pub fn peaks_from(problem: &Problem) -> &'static str {
    if problem.analysis.nonlinear_modes.is_some() {
        "predicted from the nonlinear mode of each case"
    } else {
        "of the forced response of each case"
    }
}

/// The (series value, parameter value) pairs of a sweep, series-major, in scene order.
pub fn sweep_points(spec: &SweepSpec) -> Vec<(Option<f64>, f64)> {
    let series: Vec<Option<f64>> = match &spec.series {
        Some(s) => s.values.iter().map(|&v| Some(v)).collect(),
        None => vec![None],
    };
    series
        .iter()
        .flat_map(|&s| spec.values.iter().map(move |&v| (s, v)))
        .collect()
}

/// Runs the sweep of `spec` over the scene text (with `overrides` applied first). `on_point`
/// is called as each value finishes (from worker threads, in completion order). Returns the
/// points in the order of [`sweep_points`].
pub fn run<F>(
    scene_text: &str,
    file: &str,
    overrides: &[String],
    spec: &SweepSpec,
    on_point: F,
) -> Result<Vec<SweepPoint>, SweepError>
where
    F: Fn(&SweepPoint) + Sync,
{
    run_with_problems(scene_text, file, overrides, spec, |point, _, _, _| {
        on_point(point)
    })
}

/// As [`run`], handing `on_point` the scene, checked problem and limit settings of each value
/// too (for writing its results).
pub fn run_with_problems<F>(
    scene_text: &str,
    file: &str,
    overrides: &[String],
    spec: &SweepSpec,
    on_point: F,
) -> Result<Vec<SweepPoint>, SweepError>
where
    F: Fn(&SweepPoint, &Scene, &Problem, &LimitSettings) + Sync,
{
    sweep_points(spec)
        .par_iter()
        .map(|&(series, value)| {
            let (scene, problem, limits) =
                problem_at(scene_text, file, overrides, spec, series, value)?;
            let point = solve_value(&problem, &limits, spec.output, series, value);
            on_point(&point, &scene, &problem, &limits);
            Ok(point)
        })
        .collect()
}

/// The scene, checked problem and limit settings (the defaults when the scene has no
/// `[limits]` table) at one sweep point.
pub fn problem_at(
    scene_text: &str,
    file: &str,
    overrides: &[String],
    spec: &SweepSpec,
    series: Option<f64>,
    value: f64,
) -> Result<(Scene, Problem, LimitSettings), SweepError> {
    let mut all = overrides.to_vec();
    if let (Some(s), Some(v)) = (&spec.series, series) {
        all.extend(s.overrides(v));
    }
    all.extend(spec.overrides(value));
    scene::parse(scene_text, file, &all)
        .and_then(|s| {
            let (p, limits) = s.validate_with_limits(file)?;
            Ok((s, p, limits.unwrap_or_default()))
        })
        .map_err(|source| SweepError::Scene {
            parameter: match (&spec.series, series) {
                (Some(s), Some(v)) => format!("{} ({} = {v})", spec.parameter, s.parameter),
                _ => spec.parameter.clone(),
            },
            value,
            source,
        })
}

/// Solves one sweep point of a checked problem with its limit settings.
pub fn solve_value(
    problem: &Problem,
    settings: &LimitSettings,
    output: SweepOutput,
    series: Option<f64>,
    value: f64,
) -> SweepPoint {
    if let Some(modes) = NonlinearModeSettings::of_problem(problem) {
        return solve_modes_value(problem, &modes, settings, series, value);
    }
    let mut cases = limits::two_point_cases(problem);
    cases.extend(settings.intermediate_cases(problem));
    let names: Vec<String> = cases.iter().map(|c| c.name.clone()).collect();
    let mut point = SweepPoint {
        value,
        series,
        cases: names,
        limit_cases: 2,
        peaks: vec![None; cases.len()],
        failures: Vec::new(),
        analysis: None,
    };
    match output {
        SweepOutput::Peaks => {
            for (k, case) in cases.iter().enumerate() {
                let curve = limits::attempt_case(problem, case, settings.peak_window_hz);
                point.failures.extend(curve.unfinished_reason());
                // The peak of an unfinished curve is not the case's: its path may stop short.
                if curve.status.is_complete() {
                    point.peaks[k] = curve.peak;
                }
            }
        }
        SweepOutput::Limits => match limits::analyse(problem, settings, |_| {}) {
            Ok(analysis) => {
                for (k, c) in analysis
                    .limits
                    .iter()
                    .chain(&analysis.intermediate)
                    .enumerate()
                {
                    if c.status.is_complete() {
                        point.peaks[k] = c.peak.clone();
                    }
                }
                point.failures.extend(analysis.unfinished());
                point.analysis = Some(Box::new(analysis));
            }
            Err(e) => point.failures.push(e.to_string()),
        },
    }
    point
}

/// One sweep point of a nonlinear-mode scene: the mode of every case of
/// [`nonlinear_modes::mode_cases`] (m = ±1 per damper side, then the intermediate and listed
/// cases) and the resonance peak each predicts for the scene's first-harmonic loads
/// ([`nonlinear_modes::predict`]). A peak's amplitude at the first output DOF, and its
/// coefficients, are interpolated between the two mode points around the crossing as the
/// prediction's amplitude is (log-linearly; the coefficients linearly), its contact states are
/// the nearer point's. A case whose mode failed, or ended below the amplitude of its peak, has
/// none and is recorded in [`SweepPoint::failures`]; a mode that ended short after its peak
/// still predicts it.
fn solve_modes_value(
    problem: &Problem,
    modes: &NonlinearModeSettings,
    settings: &LimitSettings,
    series: Option<f64>,
    value: f64,
) -> SweepPoint {
    let solved = nonlinear_modes::mode_limits(problem, modes, settings);
    let mut point = SweepPoint {
        value,
        series,
        cases: solved.cases.iter().map(|c| c.case.name.clone()).collect(),
        limit_cases: solved.cases.len() - settings.intermediate_cases(problem).len(),
        peaks: vec![None; solved.cases.len()],
        failures: Vec::new(),
        analysis: None,
    };
    for (k, case) in solved.cases.iter().enumerate() {
        let name = &case.case.name;
        match &case.run {
            Err(e) => point.failures.push(format!("mode `{name}` failed: {e}")),
            Ok(run) => match mode_peak(problem, run) {
                Some(peak) => point.peaks[k] = Some(peak),
                None => point.failures.push(format!(
                    "mode `{name}` predicts no peak: {}",
                    run.incomplete_reason().unwrap_or_else(|| {
                        "the excitation drives it beyond the amplitudes computed".to_string()
                    })
                )),
            },
        }
    }
    point
}

/// The resonance peak a mode predicts at the first output DOF (see [`solve_modes_value`]).
fn mode_peak(problem: &Problem, run: &NonlinearModeRun) -> Option<Peak> {
    let (i, t) = nonlinear_modes::predict::peak_crossing(problem, run)?;
    let predicted = nonlinear_modes::predict::peak_at(run, (i, t));
    let (p0, p1) = (&run.points[i - 1], &run.points[i]);
    let set = problem.unknown_harmonics();
    let n = problem.model.n_dofs();
    let (c1, s1) = (set.cos_block(1)?, set.sin_block(1)?);
    let dof = *problem.outputs.first()?;
    let amplitude = |c: &[f64]| c[c1 * n + dof].hypot(c[s1 * n + dof]);
    let (a0, a1) = (amplitude(&p0.coefficients), amplitude(&p1.coefficients));
    Some(Peak {
        freq_hz: predicted.freq_hz,
        amplitude: (a0.ln() + t * (a1.ln() - a0.ln())).exp(),
        refined: true,
        coefficients: p0
            .coefficients
            .iter()
            .zip(&p1.coefficients)
            .map(|(u, v)| u + t * (v - u))
            .collect(),
        states: if t < 0.5 { &p0.states } else { &p1.states }.clone(),
    })
}
