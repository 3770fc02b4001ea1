//! Parameter sweeps of the limit analysis: optimal curves (peak amplitude of each limit case
//! vs the pre-load), resonance-frequency limits, geometry variability (paper Figs. 16-19).
//!
//! A sweep parameter p drives one or more scene fields linearly (field = offset + scale·p),
//! so any numeric field can be swept, and a geometric parameter such as the apical angle β can
//! move both contact frames at once. Every sweep point is independent: points run in parallel
//! with rayon, each on its own scene, and results do not depend on the thread count.

use rayon::prelude::*;

use crate::limits::{self, LimitCase, Peak};
use crate::scene::{self, SceneError, SweepSpec};

/// Errors of a sweep.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The scene at a sweep value is invalid.
    #[error("sweep {parameter} = {value}: {source}")]
    Scene {
        /// Parameter name.
        parameter: String,
        /// Parameter value.
        value: f64,
        /// Cause.
        source: SceneError,
    },
    /// A curve failed at a sweep value.
    #[error("sweep {parameter} = {value}: {source}")]
    Solve {
        /// Parameter name.
        parameter: String,
        /// Parameter value.
        value: f64,
        /// Cause.
        source: limits::LimitError,
    },
}

/// Result of one sweep value.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SweepPoint {
    /// Parameter value.
    pub value: f64,
    /// Case names: the two limit cases, then the intermediate ones.
    pub cases: Vec<String>,
    /// Refined peak of each case (first output DOF).
    pub peaks: Vec<Peak>,
}

impl SweepPoint {
    /// Largest and smallest peak amplitude of the two limit cases (m).
    pub fn limit_amplitudes(&self) -> (f64, f64) {
        let a = self.peaks[0].amplitude;
        let b = self.peaks[1].amplitude;
        (a.max(b), a.min(b))
    }

    /// Highest and lowest peak frequency of the two limit cases (Hz).
    pub fn limit_frequencies(&self) -> (f64, f64) {
        let a = self.peaks[0].freq_hz;
        let b = self.peaks[1].freq_hz;
        (a.max(b), a.min(b))
    }
}

/// Runs the sweep of `spec` over the scene text (with `overrides` applied first). Each value is
/// solved with the two-point limit cases plus the scene's intermediate cases; `on_point` is
/// called as each value finishes (from worker threads, in completion order). Returns the
/// points in the order of `spec.values`.
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
    spec.values
        .par_iter()
        .map(|&value| {
            let point = solve_value(scene_text, file, overrides, spec, value)?;
            on_point(&point);
            Ok(point)
        })
        .collect()
}

/// Solves one sweep value.
pub fn solve_value(
    scene_text: &str,
    file: &str,
    overrides: &[String],
    spec: &SweepSpec,
    value: f64,
) -> Result<SweepPoint, SweepError> {
    let scene_err = |source| SweepError::Scene {
        parameter: spec.parameter.clone(),
        value,
        source,
    };
    let mut all = overrides.to_vec();
    all.extend(spec.overrides(value));
    let problem = scene::parse(scene_text, file, &all)
        .and_then(|s| s.validate(file))
        .map_err(scene_err)?;
    let mut cases = limits::two_point_cases(&problem);
    if let Some(l) = &problem.limits {
        cases.extend(
            l.intermediate
                .iter()
                .map(|&m| LimitCase::uniform(&problem, m)),
        );
    }
    let mut peaks = Vec::with_capacity(cases.len());
    for case in &cases {
        let curve = limits::solve_case(&problem, case).map_err(|source| SweepError::Solve {
            parameter: spec.parameter.clone(),
            value,
            source,
        })?;
        peaks.push(curve.peak);
    }
    Ok(SweepPoint {
        value,
        cases: cases.into_iter().map(|c| c.name).collect(),
        peaks,
    })
}
