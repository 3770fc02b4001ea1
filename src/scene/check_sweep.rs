//! Validation of the `[sweep]` table: its parameter (and the optional series parameter) with
//! values and target fields, the number of runs, and the `[limits]` table a sweep needs.

use crate::scene::checker::Checker;
use crate::scene::error::SceneError;
use crate::scene::schema::Scene;

/// Checks the scene's `[sweep]` table, if any. The targets are only checked to be scene
/// fields outside `[sweep]`; each run applies them as `--set` overrides.
pub(super) fn check_sweep(scene: &Scene, ck: &Checker) -> Result<(), SceneError> {
    let Some(s) = &scene.sweep else {
        return Ok(());
    };
    let mut parameters = vec![("sweep", &s.parameter, &s.values, &s.targets)];
    if let Some(series) = &s.series {
        parameters.push((
            "sweep.series",
            &series.parameter,
            &series.values,
            &series.targets,
        ));
    }
    for (table, parameter, values, targets) in parameters {
        if parameter.trim().is_empty() {
            return Err(ck.err(format!("{table}.parameter"), "must name the parameter"));
        }
        if values.is_empty() {
            return Err(ck.err(format!("{table}.values"), "must hold at least one value"));
        }
        for (i, v) in values.iter().enumerate() {
            ck.finite(&format!("{table}.values[{i}]"), *v)?;
        }
        if targets.is_empty() {
            return Err(ck.err(format!("{table}.targets"), "must name at least one field"));
        }
        for (i, t) in targets.iter().enumerate() {
            if t.field.trim().is_empty() || t.field.starts_with("sweep") {
                return Err(ck.err(
                    format!("{table}.targets[{i}].field"),
                    "must be a scene field outside [sweep]",
                ));
            }
            ck.finite(&format!("{table}.targets[{i}].scale"), t.scale)?;
            ck.finite(&format!("{table}.targets[{i}].offset"), t.offset)?;
        }
    }
    let runs = s.values.len() * s.series.as_ref().map_or(1, |x| x.values.len());
    if runs > 100_000 {
        return Err(ck.err(
            "sweep.values",
            format!("{runs} sweep points; at most 100000"),
        ));
    }
    if scene.limits.is_none() {
        return Err(ck.err(
            "sweep",
            "a sweep runs the limit analysis: add a [limits] table",
        ));
    }
    Ok(())
}
