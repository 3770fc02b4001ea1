//! The accuracy study: what each solver setting costs in time and gives in accuracy.
//!
//! One setting at a time is changed from the scene as given: the harmonic set (H = 1 … H, and
//! the odd harmonics 1, 3, … H alone), the AFT
//! samples per period, the Newton residual tolerance, the Craig-Bampton interior modes (scenes
//! with `[reduction]`), and each effect switch (constant normal load, no lift-off, uncoupled
//! statics). Every setting's FRF is compared with a reference: the most refined setting (the
//! largest H with the most samples and the tightest tolerance, and on a reduced scene the most
//! interior modes of the study), whose convergence is checked
//! against the next refinement down (H one step lower): the difference is reported.
//!
//! Per setting: the error of each resonance peak of the first output (refined amplitude and
//! frequency, relative, against the nearest reference peak), the relative L2 error of the
//! first output's amplitude over the range both paths cover ([`curve_l2_error`]), the wall time
//! of the continuation (peak refinement excluded), Newton iterations and unknowns.
//!
//! Limit scenes are studied per limit curve ([`study_curves`]): the two-point method's m = +1
//! and m = −1 on every contact point (paper Eqs. 14-15) and each case the scene gives per damper
//! side or per contact point (`[[limits.cases]]`), each against its own reference (the same
//! case at the most refined setting). The `[limits]` and `[sweep]` tables are removed: a curve
//! is the FRF of the scene with every contact's initial state set from the case.

use std::time::Instant;

use rayon::prelude::*;

use crate::analysis::frf::{self, FrfPoint, Silent};
use crate::analysis::limits::{two_point_cases, LimitCase};
use crate::analysis::peaks;
use crate::model::Problem;
use crate::scene::{self, Scene, SceneError};

/// One setting of the study: a group (`reference`, `harmonics`, `samples`, `tolerance`,
/// `modes`, `effect`), a label and the scene overrides that make it.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// What is varied.
    pub group: &'static str,
    /// Short label (`H = 3`, `samples = 64`, `no lift-off`, …).
    pub label: String,
    /// Scene overrides (`FIELD=VALUE`) on top of the scene as given.
    pub overrides: Vec<String>,
}

/// The settings of a study of `scene`: the reference, the convergence check of the reference,
/// then the settings varied one at a time. `quick` uses short lists (seconds on the paper case).
pub fn settings(scene: &Scene, problem: &Problem, quick: bool) -> (Setting, Setting, Vec<Setting>) {
    let h0 = problem.harmonics.iter().copied().max().unwrap_or(1);
    let s0 = problem.samples;
    let (h_list, s_list, tol_list): (Vec<usize>, Vec<usize>, Vec<f64>) = if quick {
        (vec![1, 3, 5], vec![64, 128, 256], vec![1e-4, 1e-8])
    } else {
        (
            vec![1, 2, 3, 5, 7, 9, 11, 15],
            vec![32, 64, 128, 256, 512, 1024, 2048],
            vec![1e-4, 1e-6, 1e-8, 1e-10],
        )
    };
    let h_ref = if quick { 7 } else { 21 };
    let h_check = if quick { 5 } else { 15 };
    let s_ref = if quick { 512 } else { 4096 };
    let tol_ref = 1e-12;
    let h_of = |h: usize| format!("harmonics.max={h}");
    let s_of = |s: usize| format!("harmonics.samples={s}");
    // A scene with an explicit harmonic list gets H = 1..h instead (the list removed).
    let drop_list: Vec<String> = if scene.harmonics.list.is_some() {
        vec!["harmonics.list=".to_string()]
    } else {
        Vec::new()
    };
    let set_h = |h: usize, s: usize| {
        let mut o = drop_list.clone();
        o.extend([h_of(h), s_of(s.max(4 * h + 2))]);
        o
    };
    // Craig-Bampton interior modes (scenes with `[reduction]`): a quarter, half, once and twice
    // the scene's (`quick`: half and once); the reference takes the most.
    let modes: Vec<usize> = scene.reduction.as_ref().map_or(Vec::new(), |r| {
        let list = if quick {
            vec![r.modes / 2, r.modes]
        } else {
            vec![r.modes / 4, r.modes / 2, r.modes, 2 * r.modes]
        };
        list.into_iter().filter(|&m| m >= 1).collect()
    });
    let modes_ref = modes.iter().copied().max();
    let fixed = |h: usize, s: usize, tol: f64| {
        let mut o = set_h(h, s);
        o.push(format!("analysis.residual_tolerance={tol:e}"));
        if let Some(m) = modes_ref {
            o.push(format!("reduction.modes={m}"));
        }
        o
    };
    let modes_label = modes_ref.map_or(String::new(), |m| format!("; modes = {m}"));
    let reference = Setting {
        group: "reference",
        label: format!("H = {h_ref}; samples = {s_ref}; tol = {tol_ref:e}{modes_label}"),
        overrides: fixed(h_ref, s_ref, tol_ref),
    };
    let check = Setting {
        group: "reference",
        label: format!("H = {h_check}; samples = {s_ref}; tol = {tol_ref:e}{modes_label}"),
        overrides: fixed(h_check, s_ref, tol_ref),
    };
    let mut list = Vec::new();
    for &h in &h_list {
        list.push(Setting {
            group: "harmonics",
            label: format!("H = {h}"),
            overrides: set_h(h, s0),
        });
    }
    // Odd harmonics only (with the 0th where the statics are coupled): exact where the
    // steady state has half-wave symmetry, q(τ + π) = −q(τ) about the static state (no
    // static pre-load on the contacts, symmetric contact laws); elsewhere the even harmonics
    // the contacts generate are lost, and the study measures what that costs.
    let odd_list: &[usize] = if quick { &[3] } else { &[3, 5, 7, 9] };
    for &h in odd_list {
        let odd: Vec<String> = (1..=h).step_by(2).map(|k| k.to_string()).collect();
        list.push(Setting {
            group: "harmonics",
            label: format!("H = {h} odd"),
            overrides: vec![
                "harmonics.max=".to_string(),
                format!("harmonics.list=[{}]", odd.join(", ")),
                s_of(s0.max(4 * h + 2)),
            ],
        });
    }
    for &s in s_list.iter().filter(|&&s| s > 2 * h0) {
        list.push(Setting {
            group: "samples",
            label: format!("samples = {s}"),
            overrides: vec![s_of(s)],
        });
    }
    for &t in &tol_list {
        list.push(Setting {
            group: "tolerance",
            label: format!("tol = {t:e}"),
            overrides: vec![format!("analysis.residual_tolerance={t:e}")],
        });
    }
    for m in modes {
        list.push(Setting {
            group: "modes",
            label: format!("modes = {m}"),
            overrides: vec![format!("reduction.modes={m}")],
        });
    }
    for (label, o) in [
        ("constant normal load", "effects.normal_load=\"constant\""),
        ("no lift-off", "effects.liftoff=false"),
        ("uncoupled statics", "effects.coupling=\"uncoupled\""),
    ] {
        list.push(Setting {
            group: "effect",
            label: label.to_string(),
            overrides: vec![o.to_string()],
        });
    }
    (reference, check, list)
}

/// A response curve the study is made on: the scene's FRF, or one limit curve of a limit
/// scene (its initial tangential states).
#[derive(Debug, Clone, PartialEq)]
pub struct StudyCurve {
    /// `frf` for the scene's FRF, otherwise the limit case's name (`m+1`, `m-1`, or the name of
    /// a `[[limits.cases]]` entry).
    pub name: String,
    /// The initial state m of every contact point; `None`: the scene's own.
    pub case: Option<LimitCase>,
}

impl StudyCurve {
    /// The scene's FRF with its own initial states.
    pub fn frf() -> Self {
        Self {
            name: "frf".to_string(),
            case: None,
        }
    }
}

/// The curves a study of the scene covers: the FRF for a scene without `[limits]`; for a limit
/// scene, the two limit curves (m = +1, m = −1 on every point) and each case the scene gives per
/// side or per point (`[[limits.cases]]`). The uniform intermediate curves
/// (`limits.intermediate`) and the bound scan are not studied. `scene`: parsed with the user's
/// overrides.
pub fn study_curves(scene: &Scene, label: &str) -> Result<Vec<StudyCurve>, SceneError> {
    if scene.limits.is_none() {
        return Ok(vec![StudyCurve::frf()]);
    }
    let (problem, limits) = scene.validate_with_limits(label)?;
    let specs = limits.map(|l| l.cases).unwrap_or_default();
    Ok(two_point_cases(&problem)
        .into_iter()
        .chain(specs.iter().map(|c| LimitCase::from_spec(&problem, c)))
        .map(|case| StudyCurve {
            name: case.name.clone(),
            case: Some(case),
        })
        .collect())
}

/// What one setting gave.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingResult {
    /// The curve (`frf` or the limit case's name).
    pub curve: String,
    /// The setting.
    pub setting: Setting,
    /// `complete`, `incomplete: …` or `failed: …`.
    pub status: String,
    /// Newton unknowns (DOFs × coefficient blocks of the problem).
    pub unknowns: usize,
    /// Converged path points.
    pub points: usize,
    /// Newton iterations over the path.
    pub newton_iterations: usize,
    /// Wall time of the continuation (s).
    pub time_s: f64,
    /// The path (empty when the setting failed).
    pub path: Vec<FrfPoint>,
    /// Refined resonance peaks of the first output: (frequency Hz, amplitude m).
    pub peaks: Vec<(f64, f64)>,
}

impl SettingResult {
    /// Whether the setting's run covered its range (status `complete`): not failed, no branch
    /// given up or left unfollowed.
    pub fn is_complete(&self) -> bool {
        self.status == "complete"
    }
}

/// Errors of a setting against the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingErrors {
    /// Relative L2 error of the first output's amplitude over the common range.
    pub curve_l2: f64,
    /// Per reference peak: relative amplitude and frequency errors of the nearest peak (NaN
    /// when the setting has no peak).
    pub peaks: Vec<(f64, f64)>,
}

impl SettingErrors {
    /// The largest peak amplitude error (NaN when some peak is missing).
    pub fn max_peak_amplitude(&self) -> f64 {
        self.peaks
            .iter()
            .map(|p| p.0)
            .fold(0.0, |a: f64, b| if b.is_nan() { b } else { a.max(b) })
    }
    /// The largest peak frequency error (NaN when some peak is missing).
    pub fn max_peak_frequency(&self) -> f64 {
        self.peaks
            .iter()
            .map(|p| p.1)
            .fold(0.0, |a: f64, b| if b.is_nan() { b } else { a.max(b) })
    }
}

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

/// Relative L2 error ‖a − r‖ / ‖r‖ of the first output's amplitude of `path` against
/// `reference`, on 400 uniform frequencies of the range both cover (NaN when they share none).
pub fn curve_l2_error(path: &[FrfPoint], reference: &[FrfPoint]) -> f64 {
    let range = |p: &[FrfPoint]| {
        p.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
                (a.min(q.freq_hz), b.max(q.freq_hz))
            })
    };
    let (a0, a1) = range(path);
    let (r0, r1) = range(reference);
    let (lo, hi) = (a0.max(r0), a1.min(r1));
    if hi <= lo || !hi.is_finite() {
        return f64::NAN;
    }
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..=400 {
        let f = lo + (hi - lo) * k as f64 / 400.0;
        if let (Some(a), Some(r)) = (
            frf::amplitude_on_path(path, f),
            frf::amplitude_on_path(reference, f),
        ) {
            num += (a - r) * (a - r);
            den += r * r;
        }
    }
    if den > 0.0 {
        (num / den).sqrt()
    } else {
        f64::NAN
    }
}

/// The errors of `result` against `reference`.
///
/// Each reference peak is compared with the highest peak of `result` in its basin: the
/// frequencies nearer to it than to any other reference peak (between the midpoints to its
/// neighbours; the whole range for a single peak). A resonance whose top is folded into many
/// small folds, as the blade pair's at H = 1, has many local maxima there; the one nearest in
/// frequency to the reference peak is one of those bumps, not the resonance's top (on the 2D
/// blade pair at H = 1 a bump at 867.4 Hz, 5.49 × 10⁻⁵ m, 37 % above the reference, where the
/// top is 6.46 × 10⁻⁵ m at 865.3 Hz, 61 % above). Without a peak of `result` in the basin the
/// nearest one in frequency is compared.
pub fn errors(result: &SettingResult, reference: &SettingResult) -> SettingErrors {
    let mut reference_hz: Vec<f64> = reference.peaks.iter().map(|p| p.0).collect();
    reference_hz.sort_by(f64::total_cmp);
    SettingErrors {
        curve_l2: curve_l2_error(&result.path, &reference.path),
        peaks: reference
            .peaks
            .iter()
            .map(|&(fr, ar)| {
                let basin = peak_basin(&reference_hz, fr);
                let highest_in_basin = result
                    .peaks
                    .iter()
                    .filter(|p| basin.contains(&p.0))
                    .max_by(|a, b| a.1.total_cmp(&b.1));
                let nearest = || {
                    result
                        .peaks
                        .iter()
                        .min_by(|a, b| (a.0 - fr).abs().total_cmp(&(b.0 - fr).abs()))
                };
                highest_in_basin
                    .or_else(nearest)
                    .map_or((f64::NAN, f64::NAN), |&(f, a)| {
                        ((a - ar).abs() / ar, (f - fr).abs() / fr)
                    })
            })
            .collect(),
    }
}

/// The basin of the reference peak at `freq_hz` among the reference peaks at `sorted_hz`
/// (ascending): the frequencies (Hz) between the midpoints to its neighbours, unbounded on a
/// side without one.
fn peak_basin(sorted_hz: &[f64], freq_hz: f64) -> std::ops::Range<f64> {
    let below = sorted_hz.iter().rev().find(|&&f| f < freq_hz);
    let above = sorted_hz.iter().find(|&&f| f > freq_hz);
    below.map_or(f64::NEG_INFINITY, |f| 0.5 * (f + freq_hz))
        ..above.map_or(f64::INFINITY, |f| 0.5 * (f + freq_hz))
}

/// Indices of the Pareto-optimal points of (time, error): no other point is at most as slow and
/// at most as wrong while better in one. Points with a NaN are never on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let (ti, ei) = points[i];
            ti.is_finite()
                && ei.is_finite()
                && !points
                    .iter()
                    .enumerate()
                    .any(|(j, &(tj, ej))| j != i && tj <= ti && ej <= ei && (tj < ti || ej < ei))
        })
        .collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    front
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

/// The base overrides of a study: the user's, plus the removal of `[limits]` and `[sweep]`
/// when the scene has them (the study runs the plain FRF).
pub fn base_overrides(scene: &Scene, user: &[String]) -> Vec<String> {
    let mut o = user.to_vec();
    if scene.limits.is_some() {
        o.push("limits=".into());
    }
    if scene.sweep.is_some() {
        o.push("sweep=".into());
    }
    o
}

/// Parses the scene for [`settings`]: the scene and its checked problem with the base
/// overrides.
pub fn load(
    scene_text: &str,
    label: &str,
    user: &[String],
) -> Result<(Scene, Problem, Vec<String>), SceneError> {
    let (scene, problem, base, _) = load_with_curves(scene_text, label, user)?;
    Ok((scene, problem, base))
}

/// [`load`] and the curves the study covers ([`study_curves`]), from the same parse with the
/// user's overrides.
fn load_with_curves(
    scene_text: &str,
    label: &str,
    user: &[String],
) -> Result<(Scene, Problem, Vec<String>, Vec<StudyCurve>), SceneError> {
    let user_scene = scene::parse(scene_text, label, user)?;
    let curves = study_curves(&user_scene, label)?;
    let base = base_overrides(&user_scene, user);
    let scene = scene::parse(scene_text, label, &base)?;
    let problem = scene.validate(label)?;
    Ok((scene, problem, base, curves))
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
    /// The overrides every setting starts from ([`base_overrides`]).
    pub base: Vec<String>,
    /// The curves studied ([`study_curves`]).
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_keeps_the_undominated() {
        let p = [
            (1.0, 0.1),
            (2.0, 0.01),
            (3.0, 0.05),
            (0.5, 0.5),
            (4.0, 0.001),
            (5.0, f64::NAN),
        ];
        assert_eq!(pareto_front(&p), vec![3, 0, 1, 4]);
    }

    /// A harmonics setting's result without a path: its label, status, time (s) and peaks
    /// (Hz, m).
    fn setting_result(
        label: &str,
        status: &str,
        time_s: f64,
        peaks: &[(f64, f64)],
    ) -> SettingResult {
        SettingResult {
            curve: "frf".into(),
            setting: Setting {
                group: "harmonics",
                label: label.into(),
                overrides: Vec::new(),
            },
            status: status.into(),
            unknowns: 1,
            points: 1,
            newton_iterations: 1,
            time_s,
            path: Vec::new(),
            peaks: peaks.to_vec(),
        }
    }

    #[test]
    fn incomplete_settings_are_never_on_the_pareto_front() {
        let result =
            |label: &str, status: &str, time_s: f64| setting_result(label, status, time_s, &[]);
        let errors = |peak: f64| SettingErrors {
            curve_l2: peak,
            peaks: vec![(peak, 0.0)],
        };
        let reference = result("reference", "complete", 10.0);
        // The incomplete run is both the fastest and the most accurate: it would dominate.
        let results = vec![
            result("H = 1", "complete", 1.0),
            result(
                "H = 1, fewer samples",
                "incomplete: a branch was abandoned",
                0.5,
            ),
            result("H = 3", "complete", 3.0),
        ];
        let study = CurveStudy {
            curve: StudyCurve::frf(),
            reference: reference.clone(),
            check: reference,
            check_errors: errors(0.0),
            results,
            errors: vec![errors(0.3), errors(1e-3), errors(0.05)],
        };
        let (pairs, front) = study.pareto();
        assert_eq!(pairs.len(), 3);
        assert_eq!(front, vec![0, 2]);
        assert_eq!(study.front_labels(), "H = 1, H = 3");
    }

    /// Two reference resonances at 100 and 200 Hz: each is compared with the highest peak of
    /// the setting in its basin (below and above 150 Hz), not with the bump nearest to it in
    /// frequency; a basin without a peak of the setting falls back on the nearest one.
    #[test]
    fn each_reference_peak_is_compared_with_the_highest_peak_of_its_basin() {
        let result = |peaks: Vec<(f64, f64)>| setting_result("H = 1", "complete", 1.0, &peaks);
        let reference = result(vec![(100.0, 1.0), (200.0, 2.0)]);
        // A folded top near 100 Hz: a bump at 101 Hz (1.1) beside the top at 98 Hz (1.5).
        let folded = result(vec![(98.0, 1.5), (101.0, 1.1), (149.0, 0.5), (204.0, 2.2)]);
        let e = errors(&folded, &reference).peaks;
        assert!(
            (e[0].0 - 0.5).abs() < 1e-12 && (e[0].1 - 0.02).abs() < 1e-12,
            "{e:?}"
        );
        assert!(
            (e[1].0 - 0.1).abs() < 1e-12 && (e[1].1 - 0.02).abs() < 1e-12,
            "{e:?}"
        );
        // Nothing above 150 Hz: the second reference peak takes the nearest, at 149 Hz.
        let low = result(vec![(98.0, 1.5), (149.0, 0.5)]);
        let e = errors(&low, &reference).peaks;
        assert!(
            (e[1].0 - 0.75).abs() < 1e-12 && (e[1].1 - 0.255).abs() < 1e-12,
            "{e:?}"
        );
        assert_eq!(peak_basin(&[100.0, 200.0], 100.0), f64::NEG_INFINITY..150.0);
        assert_eq!(peak_basin(&[100.0, 200.0], 200.0), 150.0..f64::INFINITY);
    }

    #[test]
    fn l2_error_of_a_scaled_curve() {
        let point = |f: f64, a: f64| FrfPoint {
            freq_hz: f,
            amplitudes: vec![a],
            peaks: vec![a],
            states: Vec::new(),
            newton_iterations: 1,
            residual: 0.0,
            coefficients: Vec::new(),
            accuracy: None,
            stability: None,
            pending_estimate: None,
        };
        let r: Vec<FrfPoint> = (0..=10).map(|k| point(k as f64, 1.0 + k as f64)).collect();
        let a: Vec<FrfPoint> = (0..=10)
            .map(|k| point(k as f64, 1.01 * (1.0 + k as f64)))
            .collect();
        assert!((curve_l2_error(&a, &r) - 0.01).abs() < 1e-12);
    }
}
