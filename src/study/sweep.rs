//! Parameter sweeps of the limit analysis: optimal curves (peak amplitude of each limit case
//! vs the pre-load), resonance-frequency limits, geometry variability (paper Figs. 15-19).
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
    /// Case names: the two limit cases, then the intermediate ones.
    pub cases: Vec<String>,
    /// Resonance peak of each case (first output DOF); `None` where the case failed or did not
    /// cover the range (an unfinished path's highest point need not be the peak).
    pub peaks: Vec<Option<Peak>>,
    /// Continuation retries of each case (see [`limits::attempt_case`]).
    pub retries: Vec<usize>,
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
    /// Larger and smaller resonance-peak amplitude of the two limit cases (m); `None` if one
    /// of them failed.
    pub fn limit_amplitudes(&self) -> Option<(f64, f64)> {
        let (a, b) = (self.peaks[0].as_ref()?, self.peaks[1].as_ref()?);
        Some((a.amplitude.max(b.amplitude), a.amplitude.min(b.amplitude)))
    }

    /// Higher and lower resonance frequency of the two limit cases (Hz); `None` if one of them
    /// failed.
    pub fn limit_frequencies(&self) -> Option<(f64, f64)> {
        let (a, b) = (self.peaks[0].as_ref()?, self.peaks[1].as_ref()?);
        Some((a.freq_hz.max(b.freq_hz), a.freq_hz.min(b.freq_hz)))
    }

    /// Whether both limit peaks are refined interior maxima (true resonance peaks).
    pub fn limits_refined(&self) -> bool {
        self.peaks[..2]
            .iter()
            .all(|p| p.as_ref().is_some_and(|p| p.refined))
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
    let mut cases = limits::two_point_cases(problem);
    cases.extend(settings.intermediate_cases(problem));
    let names: Vec<String> = cases.iter().map(|c| c.name.clone()).collect();
    let mut point = SweepPoint {
        value,
        series,
        cases: names,
        peaks: vec![None; cases.len()],
        retries: vec![0; cases.len()],
        failures: Vec::new(),
        analysis: None,
    };
    match output {
        SweepOutput::Peaks => {
            for (k, case) in cases.iter().enumerate() {
                let curve = limits::attempt_case(problem, case, settings.peak_window_hz);
                point.retries[k] = curve.retries;
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
                    point.retries[k] = c.retries;
                }
                point.failures.extend(analysis.unfinished());
                point.analysis = Some(Box::new(analysis));
            }
            Err(e) => point.failures.push(e.to_string()),
        },
    }
    point
}
