//! What the accuracy study changes and looks at: one setting at a time from the scene as given,
//! and the curves (FRF, limits) whose error each setting is measured on.

use crate::analysis::limits::{two_point_cases, LimitCase};
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
pub(super) fn load_with_curves(
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
