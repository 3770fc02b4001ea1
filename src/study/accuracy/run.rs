//! Running the study: each setting's curves solved and timed, compared with the reference, and
//! reported to an observer as they come.

use std::time::Instant;

use rayon::prelude::*;

use super::compare::{errors, pareto_front, SettingErrors, SettingResult};
use super::settings::{load_with_curves, settings, Setting, StudyCurve};
use crate::analysis::frf::{self, Silent};
use crate::analysis::peaks;
use crate::model::Problem;
use crate::scene::{self, Scene, SceneError};

/// Solves one setting of `scene_text` (named `label`, with the base overrides `base`) on one
/// curve (the scene's initial states replaced by the curve's case, if any) and refines its
/// peaks; a setting that does not validate or solve is reported `failed: …`.
pub fn run_setting(
    scene_text: &str,
    label: &str,
    base: &[String],
    curve: &StudyCurve,
    setting: &Setting,
) -> SettingResult {
    let mut overrides = base.to_vec();
    overrides.extend(setting.overrides.iter().cloned());
    overrides.push("accuracy.estimate=false".into());
    let failed = |status: String| SettingResult {
        curve: curve.name.clone(),
        setting: setting.clone(),
        status,
        unknowns: 0,
        points: 0,
        newton_iterations: 0,
        time_s: f64::NAN,
        path: Vec::new(),
        peaks: Vec::new(),
    };
    let problem = match scene::parse(scene_text, label, &overrides).and_then(|s| s.validate(label))
    {
        Ok(p) => p,
        Err(e) => return failed(format!("failed: {e}")),
    };
    let problem = match &curve.case {
        None => problem,
        Some(case) if case.contact_states.len() == problem.contacts.len() => case.apply(&problem),
        Some(case) => {
            return failed(format!(
                "failed: the case `{}` gives {} contact states, the setting's problem has {} contact points",
                case.name,
                case.contact_states.len(),
                problem.contacts.len()
            ))
        }
    };
    let unknowns = problem.model.n_dofs() * problem.unknown_harmonics().n_blocks();
    let started = Instant::now();
    let run = frf::solve(&problem, &mut Silent);
    let time_s = started.elapsed().as_secs_f64();
    let run = match run {
        Ok(r) => r,
        Err(e) => {
            let mut r = failed(format!("failed: {e}"));
            r.unknowns = unknowns;
            r.time_s = time_s;
            return r;
        }
    };
    let status = match run.incomplete_reason() {
        None => "complete".to_string(),
        Some(reason) => format!("incomplete: {reason}"),
    };
    let peaks = peaks::path_peaks(&problem, &run.points)
        .ok()
        .and_then(|mut p| (!p.is_empty()).then(|| p.swap_remove(0)))
        .unwrap_or_default()
        .iter()
        .map(|p| (p.freq_hz, p.amplitude))
        .collect();
    SettingResult {
        curve: curve.name.clone(),
        setting: setting.clone(),
        status,
        unknowns,
        points: run.points.len(),
        newton_iterations: run.points.iter().map(|p| p.newton_iterations).sum(),
        time_s,
        path: run.points,
        peaks,
    }
}

/// Runs the (curve, setting) `jobs` in parallel (rayon), calling `done` with each job's index
/// and result as it finishes (from the worker threads). The results come back in job order.
pub fn run_settings<F>(
    scene_text: &str,
    label: &str,
    base: &[String],
    jobs: &[(&StudyCurve, &Setting)],
    done: F,
) -> Vec<SettingResult>
where
    F: Fn(usize, &SettingResult) + Sync,
{
    jobs.par_iter()
        .enumerate()
        .map(|(i, (curve, setting))| {
            let r = run_setting(scene_text, label, base, curve, setting);
            done(i, &r);
            r
        })
        .collect()
}

/// Why a study could not be carried out.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The scene (with the user's overrides) does not parse or validate.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A curve's reference did not solve, so no error can be measured on that curve.
    #[error("the accuracy study's reference ({setting}) did not solve{curve}: {status}")]
    ReferenceFailed {
        /// The reference setting's label.
        setting: String,
        /// ` on the curve `…`` for a limit scene, empty for a plain FRF.
        curve: String,
        /// The reference's status.
        status: String,
    },
}

/// One curve's results: its reference, the reference's convergence check, and the settings
/// with their errors against the reference (in setting order).
#[derive(Debug, Clone)]
pub struct CurveStudy {
    /// The curve.
    pub curve: StudyCurve,
    /// The most refined setting's result.
    pub reference: SettingResult,
    /// The next refinement down, whose difference from the reference says how converged the
    /// reference is.
    pub check: SettingResult,
    /// The check's errors against the reference.
    pub check_errors: SettingErrors,
    /// Every setting's result.
    pub results: Vec<SettingResult>,
    /// Every setting's errors against the reference.
    pub errors: Vec<SettingErrors>,
}

impl CurveStudy {
    /// (wall time s, largest relative peak amplitude error) of every setting, and the indices
    /// of the Pareto front (no other setting is both faster and more accurate), by time.
    ///
    /// Only settings whose run is `complete` can be on the front: a run that gave a branch up
    /// or left one unfollowed measures its peak error on the curve as followed, which can miss
    /// the peak and land near the reference's amplitude by chance (measured on the reduced
    /// blade pair at H = 1: a run abandoned at 871.45 Hz, 0.5 % from the reference peak, while
    /// the complete runs at H = 1 are 37 % off), and it did less work than a complete run.
    pub fn pareto(&self) -> (Vec<(f64, f64)>, Vec<usize>) {
        let pairs: Vec<(f64, f64)> = self
            .results
            .iter()
            .zip(&self.errors)
            .map(|(r, e)| (r.time_s, e.max_peak_amplitude()))
            .collect();
        let eligible: Vec<(f64, f64)> = pairs
            .iter()
            .zip(&self.results)
            .map(|(&p, r)| {
                if r.is_complete() {
                    p
                } else {
                    (f64::NAN, f64::NAN)
                }
            })
            .collect();
        let front = pareto_front(&eligible);
        (pairs, front)
    }

    /// The Pareto front's setting labels, comma separated.
    pub fn front_labels(&self) -> String {
        self.pareto()
            .1
            .iter()
            .map(|&i| self.results[i].setting.label.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// What a study reports while it runs (from the worker threads).
pub trait StudyObserver: Sync {
    /// Every curve's reference and check are solved (before any other setting): the pairs
    /// (reference, check) in curve order and the largest number of reference peaks.
    fn references(&self, _pairs: &[(SettingResult, SettingResult)], _peaks: usize) {}
    /// A setting finished, with its errors against its curve's reference.
    fn setting(&self, _result: &SettingResult, _errors: &SettingErrors) {}
    /// A job (reference, check or setting) finished.
    fn job_done(&self) {}
}

/// A study before it runs: the scene, its curves and settings.
#[derive(Debug, Clone)]
pub struct StudyPlan {
    /// Scene label (file path) used in messages.
    pub label: String,
    /// Scene text.
    pub text: String,
    /// The scene with the user's overrides, `[limits]` and `[sweep]` removed.
    pub scene: Scene,
    /// Its checked problem.
    pub problem: Problem,
    /// The overrides every setting starts from ([`base_overrides`](super::base_overrides)).
    pub base: Vec<String>,
    /// The curves studied ([`study_curves`](super::study_curves)).
    pub curves: Vec<StudyCurve>,
    /// The reference setting.
    pub reference: Setting,
    /// The reference's convergence check.
    pub check: Setting,
    /// The settings varied one at a time.
    pub settings: Vec<Setting>,
}

impl StudyPlan {
    /// Plans the study of a scene (`text`, named `label`, with the user's `--set` overrides):
    /// `quick` uses the short setting lists.
    pub fn new(text: &str, label: &str, user: &[String], quick: bool) -> Result<Self, SceneError> {
        let (scene, problem, base, curves) = load_with_curves(text, label, user)?;
        let (reference, check, settings) = settings(&scene, &problem, quick);
        Ok(Self {
            label: label.to_string(),
            text: text.to_string(),
            scene,
            problem,
            base,
            curves,
            reference,
            check,
            settings,
        })
    }

    /// Number of solves: per curve the reference, its check and every setting.
    pub fn jobs(&self) -> usize {
        self.curves.len() * (2 + self.settings.len())
    }

    /// Runs the study: every curve's reference and check first (side by side, in parallel),
    /// then every (curve, setting) in parallel, reporting to `observer` as jobs finish.
    pub fn run(&self, observer: &dyn StudyObserver) -> Result<Vec<CurveStudy>, StudyError> {
        let reference_jobs: Vec<(&StudyCurve, &Setting)> = self
            .curves
            .iter()
            .flat_map(|c| [(c, &self.reference), (c, &self.check)])
            .collect();
        let mut references = run_settings(
            &self.text,
            &self.label,
            &self.base,
            &reference_jobs,
            |_, _| observer.job_done(),
        )
        .into_iter();
        let mut pairs: Vec<(SettingResult, SettingResult)> = Vec::with_capacity(self.curves.len());
        while let (Some(r), Some(c)) = (references.next(), references.next()) {
            pairs.push((r, c));
        }
        let several = self.curves.len() > 1;
        if let Some((curve, (r, _))) = self
            .curves
            .iter()
            .zip(&pairs)
            .find(|(_, (r, _))| r.status != "complete")
        {
            return Err(StudyError::ReferenceFailed {
                setting: self.reference.label.clone(),
                curve: if several || curve.case.is_some() {
                    format!(" on the curve `{}`", curve.name)
                } else {
                    String::new()
                },
                status: r.status.clone(),
            });
        }
        let peaks = pairs.iter().map(|(r, _)| r.peaks.len()).max().unwrap_or(0);
        observer.references(&pairs, peaks);
        let per_curve = self.settings.len().max(1);
        let jobs: Vec<(&StudyCurve, &Setting)> = self
            .curves
            .iter()
            .flat_map(|c| self.settings.iter().map(move |s| (c, s)))
            .collect();
        let results = run_settings(&self.text, &self.label, &self.base, &jobs, |i, r| {
            observer.setting(r, &errors(r, &pairs[i / per_curve].0));
            observer.job_done();
        });
        let mut results = results.into_iter();
        Ok(self
            .curves
            .iter()
            .zip(pairs)
            .map(|(curve, (reference, check))| {
                let results: Vec<SettingResult> =
                    results.by_ref().take(self.settings.len()).collect();
                let setting_errors = results.iter().map(|r| errors(r, &reference)).collect();
                CurveStudy {
                    curve: curve.clone(),
                    check_errors: errors(&check, &reference),
                    reference,
                    check,
                    results,
                    errors: setting_errors,
                }
            })
            .collect())
    }
}
