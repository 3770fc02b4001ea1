//! Validation of what is solved and reported: the `[analysis]` table (frequency range,
//! continuation steps and limits, tolerances, Jacobian and formulation) built into the
//! problem's [`Analysis`] settings, and the `[output]` table into the response DOFs.

use crate::model::{Analysis, CHORD_MIN_UNKNOWNS};
use crate::numerics::ContinuationSettings;
use crate::scene::checker::{Checker, DofNames};
use crate::scene::error::SceneError;
use crate::scene::fe_input::FeStructure;
use crate::scene::schema::{AnalysisSpec, OutputSpec};

/// Most continuation points or linear-reference points a scene may ask for.
pub const MAX_POINTS: usize = 10_000_000;

/// The analysis settings of the `[analysis]` table: the frequency range (Hz), the arc-length
/// steps (defaults from the range), iteration counts and tolerances.
pub(super) fn analysis(a: &AnalysisSpec, ck: &Checker) -> Result<Analysis, SceneError> {
    let f0 = ck.positive("analysis.freq_start_hz", a.freq_start_hz)?;
    let f1 = ck.finite("analysis.freq_end_hz", a.freq_end_hz)?;
    if f1 <= f0 {
        return Err(ck.err(
            "analysis.freq_end_hz",
            format!("the range is reversed or empty: end {f1} Hz ≤ start {f0} Hz"),
        ));
    }
    let range = f1 - f0;
    let initial_step = ck.positive(
        "analysis.initial_step",
        a.initial_step.unwrap_or(range / 200.0),
    )?;
    let min_step = ck.positive("analysis.min_step", a.min_step.unwrap_or(range * 1e-7))?;
    let max_step = ck.positive("analysis.max_step", a.max_step.unwrap_or(range / 50.0))?;
    if min_step > max_step {
        return Err(ck.err(
            "analysis.min_step",
            format!("{min_step} exceeds max_step {max_step}"),
        ));
    }
    for (field, v) in [
        ("analysis.max_points", a.max_points),
        ("analysis.target_iterations", a.target_iterations),
        ("analysis.max_iterations", a.max_iterations),
        ("analysis.linear_points", a.linear_points),
    ] {
        if v == 0 {
            return Err(ck.err(field, "must be ≥ 1"));
        }
    }
    if a.linear_points < 2 {
        return Err(ck.err("analysis.linear_points", "must be ≥ 2"));
    }
    for (field, v) in [
        ("analysis.max_points", a.max_points),
        ("analysis.linear_points", a.linear_points),
    ] {
        if v > MAX_POINTS {
            return Err(ck.err(field, format!("must be ≤ {MAX_POINTS}, got {v}")));
        }
    }
    let residual_tolerance = ck.positive("analysis.residual_tolerance", a.residual_tolerance)?;
    let step_tolerance = ck.positive("analysis.step_tolerance", a.step_tolerance)?;
    Ok(Analysis {
        continuation: ContinuationSettings {
            freq_start_hz: f0,
            freq_end_hz: f1,
            initial_step,
            min_step,
            max_step,
            max_points: a.max_points,
            target_iterations: a.target_iterations,
            max_iterations: a.max_iterations,
            residual_tolerance,
            step_tolerance,
            chord_min_unknowns: CHORD_MIN_UNKNOWNS,
        },
        jacobian: a.jacobian,
        formulation: a.formulation,
        linear_points: a.linear_points,
    })
}

/// The response DOFs of the `[output]` table: the named DOFs, then every node of each group
/// in its direction.
pub(super) fn outputs(
    output: &OutputSpec,
    ck: &Checker,
    dofs: &DofNames,
    fe: Option<&FeStructure>,
) -> Result<Vec<usize>, SceneError> {
    if output.dofs.is_empty() && output.groups.is_empty() {
        return Err(ck.err("output.dofs", "name at least one response DOF"));
    }
    let mut outputs = output
        .dofs
        .iter()
        .enumerate()
        .map(|(i, d)| ck.dof(&format!("output.dofs[{i}]"), d, dofs))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, g) in output.groups.iter().enumerate() {
        let field = format!("output.groups[{i}]");
        let targets =
            ck.load_targets(&field, None, Some(&g.group), Some(&g.direction), dofs, fe)?;
        outputs.extend(targets.into_iter().map(|(d, _)| d));
    }
    Ok(outputs)
}
