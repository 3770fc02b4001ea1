//! Validation of a nonlinear-mode analysis (`analysis.kind = "nonlinear-modes"`): the mode by
//! number or nearest frequency, the phase DOF, the amplitude range, and what such a scene cannot
//! combine with. The DOF is looked up in the problem as solved (after any reduction).

use crate::analysis::limits::LimitSettings;
use crate::analysis::nonlinear_modes::linear_start;
use crate::model::{ModeAnalysis, ModeChoice, Problem};
use crate::scene::check_analysis::{set_range, MODE_RANGE_END, MODE_RANGE_START};
use crate::scene::checker::Checker;
use crate::scene::error::SceneError;
use crate::scene::schema::{AnalysisKind, Scene};
use crate::scene::SweepOutput;

/// For a nonlinear-mode scene without `analysis.freq_start_hz` / `freq_end_hz`: sets the range
/// of the linear references to [`MODE_RANGE_START`] .. [`MODE_RANGE_END`] times the chosen
/// mode's linear frequency (Hz, contacts stuck, as the continuation starts), with the step
/// defaults of that range. Nothing for an FRF scene or a scene that gives the range.
pub(super) fn mode_range(
    scene: &Scene,
    ck: &Checker,
    problem: &mut Problem,
) -> Result<(), SceneError> {
    let a = &scene.analysis;
    let Some(m) = problem.analysis.nonlinear_modes else {
        return Ok(());
    };
    if a.freq_start_hz.is_some() || a.freq_end_hz.is_some() {
        return Ok(());
    }
    let field = match m.mode {
        ModeChoice::Number(_) => "analysis.mode",
        ModeChoice::NearestHz(_) => "analysis.mode_freq_hz",
    };
    let start = linear_start(problem, m.mode, m.dof).map_err(|e| ck.err(field, e.to_string()))?;
    let f = start.omega / (2.0 * std::f64::consts::PI);
    set_range(
        &mut problem.analysis.continuation,
        a,
        ck,
        (MODE_RANGE_START * f, MODE_RANGE_END * f),
    )
}

/// The nonlinear-mode settings of the scene's `[analysis]` table, None for an FRF scene; an
/// error naming the field for a missing or bad value, or a mode field in an FRF scene.
pub(super) fn mode_analysis(
    scene: &Scene,
    ck: &Checker,
    problem: &Problem,
    limits: Option<&LimitSettings>,
) -> Result<Option<ModeAnalysis>, SceneError> {
    let a = &scene.analysis;
    if a.kind == AnalysisKind::Frf {
        let set = [
            ("analysis.mode", a.mode.is_some()),
            ("analysis.mode_freq_hz", a.mode_freq_hz.is_some()),
            ("analysis.dof", a.dof.is_some()),
            ("analysis.amplitude", a.amplitude.is_some()),
        ];
        if let Some((field, _)) = set.iter().find(|(_, on)| *on) {
            return Err(ck.err(
                *field,
                "belongs to a nonlinear-mode analysis: set analysis.kind = \"nonlinear-modes\" (or remove it)",
            ));
        }
        return Ok(None);
    }
    if scene
        .sweep
        .as_ref()
        .is_some_and(|s| s.output == SweepOutput::Limits)
    {
        return Err(ck.err(
            "sweep.output",
            "a sweep of nonlinear modes predicts the resonance peaks of every case (output = \"peaks\"); the whole analysis per value (\"limits\") is for forced responses",
        ));
    }
    if problem.analysis.stability {
        return Err(ck.err(
            "analysis.stability",
            "is computed on forced-response points, not on nonlinear modes: remove it",
        ));
    }
    if let Some(l) = limits {
        if !l.bound_scan.is_empty() {
            return Err(ck.err(
                "limits.bound_scan",
                "is for forced responses: a nonlinear-mode analysis takes the cases m = ±1 per side and limits.intermediate / limits.cases",
            ));
        }
        if l.envelope.is_some() {
            return Err(ck.err(
                "limits.envelope",
                "is for forced responses: a nonlinear-mode analysis takes the cases m = ±1 per side and limits.intermediate / limits.cases",
            ));
        }
    }
    if problem.unknown_harmonics().cos_block(1).is_none() {
        return Err(ck.err(
            "harmonics",
            "a nonlinear mode needs the first harmonic in the harmonic set",
        ));
    }
    let mode = match (a.mode, a.mode_freq_hz) {
        (Some(_), Some(_)) => {
            return Err(ck.err(
                "analysis.mode_freq_hz",
                "give the mode by its number (analysis.mode) or its nearest frequency (analysis.mode_freq_hz), not both",
            ))
        }
        (None, None) => {
            return Err(ck.err(
                "analysis.mode",
                "name the mode to continue: its number among the elastic modes at rest (analysis.mode = k, see `fricbound modes`) or its nearest frequency (analysis.mode_freq_hz)",
            ))
        }
        (Some(0), None) => return Err(ck.err("analysis.mode", "modes are numbered from 1")),
        (Some(k), None) => ModeChoice::Number(k),
        (None, Some(f)) => ModeChoice::NearestHz(ck.positive("analysis.mode_freq_hz", f)?),
    };
    let Some([low, high]) = a.amplitude else {
        return Err(ck.err(
            "analysis.amplitude",
            "give the first-harmonic amplitude range [low, high] (m) at analysis.dof",
        ));
    };
    let low = ck.positive("analysis.amplitude", low)?;
    let high = ck.positive("analysis.amplitude", high)?;
    if high <= low {
        return Err(ck.err(
            "analysis.amplitude",
            format!("the range is reversed or empty: [{low:e}, {high:e}] m"),
        ));
    }
    let dof = match &a.dof {
        Some(name) => problem.model.dof_index(name).ok_or_else(|| {
            ck.err(
                "analysis.dof",
                format!("unknown DOF `{name}` (of the model as solved, after any reduction)"),
            )
        })?,
        None => *problem
            .outputs
            .first()
            .ok_or_else(|| ck.err("analysis.dof", "name the DOF (no output DOF to default to)"))?,
    };
    Ok(Some(ModeAnalysis {
        mode,
        dof,
        amplitude: [low, high],
    }))
}
