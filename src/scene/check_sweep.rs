//! Validation of the `[sweep]` table: its parameter (and the optional series parameter) with
//! values and target fields, the number of runs, the `[limits]` table a sweep needs, and the
//! scene at every sweep point, so that `check` refuses what a sweep's `run` would refuse at
//! one of its points.

use std::collections::BTreeSet;
use std::sync::Mutex;

use rayon::prelude::*;
use sha2::{Digest, Sha256};

use crate::scene::checker::Checker;
use crate::scene::error::SceneError;
use crate::scene::limits_schema::{SweepSpec, SweepTarget};
use crate::scene::overrides::{apply_override, one_line};
use crate::scene::schema::Scene;

/// Checks the scene's `[sweep]` table, if any: names, values and targets. The targets are
/// only checked to be scene fields outside `[sweep]` here; [`check_sweep_points`] applies
/// them.
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
        // The parameter names CSV columns and the folders of the sweep points.
        ck.name(&format!("{table}.parameter"), parameter)?;
        if values.is_empty() {
            return Err(ck.err(format!("{table}.values"), "must hold at least one value"));
        }
        for (i, v) in values.iter().enumerate() {
            ck.finite(&format!("{table}.values[{i}]"), *v)?;
            // The same value twice would solve the same scene twice and write both into one
            // folder and one row of the tables.
            if let Some(j) = values[..i].iter().position(|w| w == v) {
                return Err(ck.err(
                    format!("{table}.values[{i}]"),
                    format!(
                        "duplicate value {v} (also {table}.values[{j}]): each value is solved once"
                    ),
                ));
            }
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

/// One sweep point: the series value (its index and value) if the sweep has a series, and
/// the parameter value's index and value.
type SweepPoint = (Option<(usize, f64)>, usize, f64);

/// Validates the scene at every sweep point (in parallel), as a sweep's `run` builds it: the
/// series targets, then the parameter targets, applied to the scene as `--set` overrides, each
/// checked against the schema, and the result checked by `validate` (the scene's validation
/// without this check). The first failing point in sweep order is reported: a target that
/// cannot be set names `sweep.targets[i].field` (or `sweep.series.targets[i].field`), an
/// invalid scene names `sweep.values[k]` with the point and the inner field and reason. A
/// sweep family already found valid in this process is not checked again (see
/// [`family_key`]), so that a sweep's run, which validates the scene at each point, does not
/// validate every point at every point.
pub(super) fn check_sweep_points(
    scene: &Scene,
    ck: &Checker,
    validate: &(dyn Fn(&Scene) -> Result<(), SceneError> + Sync),
) -> Result<(), SceneError> {
    let Some(spec) = &scene.sweep else {
        return Ok(());
    };
    let base = match toml::Value::try_from(scene) {
        Ok(toml::Value::Table(t)) => t,
        Ok(_) => return Err(ck.err("sweep", "the scene is not a table")),
        Err(e) => {
            return Err(ck.err(
                "sweep",
                format!("the scene cannot be written back to TOML to apply the sweep: {e}"),
            ))
        }
    };
    // The points of a sweep are the same scenes whether they are derived from the scene as
    // written or from one of its points (each target overwrites its field), so a family
    // validated once in this process is not validated again when a sweep's run validates
    // each of its points.
    let family = family_key(ck.file, &base, spec);
    if family.as_ref().is_some_and(|key| {
        VALIDATED_FAMILIES
            .lock()
            .map(|done| done.contains(key))
            .unwrap_or(false)
    }) {
        return Ok(());
    }
    let series: Vec<Option<(usize, f64)>> = match &spec.series {
        Some(s) => s.values.iter().copied().enumerate().map(Some).collect(),
        None => vec![None],
    };
    let points: Vec<SweepPoint> = series
        .iter()
        .flat_map(|&s| spec.values.iter().enumerate().map(move |(k, &v)| (s, k, v)))
        .collect();
    let results: Vec<Result<(), SceneError>> = points
        .par_iter()
        .map(|&(series_point, k, value)| {
            let mut table = base.clone();
            if let (Some(s), Some((_, sv))) = (&spec.series, series_point) {
                set_targets(ck, &mut table, "sweep.series", &s.targets, &s.overrides(sv))?;
            }
            set_targets(
                ck,
                &mut table,
                "sweep",
                &spec.targets,
                &spec.overrides(value),
            )?;
            let point_scene: Scene = toml::Value::Table(table)
                .try_into()
                .map_err(|e: toml::de::Error| ck.err("sweep", one_line(&e.to_string())))?;
            validate(&point_scene).map_err(|e| {
                let mut at = String::new();
                if let (Some(s), Some((j, sv))) = (&spec.series, series_point) {
                    at = format!(
                        "{} (sweep.series.values[{j}]), ",
                        label(&s.parameter, &s.unit, sv)
                    );
                }
                at.push_str(&label(&spec.parameter, &spec.unit, value));
                ck.err(
                    format!("sweep.values[{k}]"),
                    format!("at the sweep point {at}: {}", inner(&e)),
                )
            })
        })
        .collect();
    results.into_iter().collect::<Result<(), SceneError>>()?;
    if let (Some(key), Ok(mut done)) = (family, VALIDATED_FAMILIES.lock()) {
        done.insert(key);
    }
    Ok(())
}

/// The sweep families (see [`family_key`]) whose every point was found valid in this process.
static VALIDATED_FAMILIES: Mutex<BTreeSet<[u8; 32]>> = Mutex::new(BTreeSet::new());

/// SHA-256 of the scene file's name and of the scene (as a TOML table) with every sweep and
/// series target set to 0: the same for the scene and for each of its sweep points. `None`
/// when a target cannot be set (the points are then checked, and refused).
fn family_key(file: &str, base: &toml::Table, spec: &SweepSpec) -> Option<[u8; 32]> {
    let mut table = base.clone();
    let targets = spec
        .targets
        .iter()
        .chain(spec.series.iter().flat_map(|s| &s.targets));
    for t in targets {
        apply_override(&mut table, &format!("{}=0", t.field)).ok()?;
    }
    let mut hash = Sha256::new();
    hash.update(file.as_bytes());
    hash.update([0]);
    hash.update(toml::to_string(&table).ok()?.as_bytes());
    Some(hash.finalize().into())
}

/// Applies the `assignments` of the `targets` of `table_name` (`sweep` or `sweep.series`) to
/// the scene `table`, each checked against the schema; an error names the target's field.
fn set_targets(
    ck: &Checker,
    table: &mut toml::Table,
    table_name: &str,
    targets: &[SweepTarget],
    assignments: &[String],
) -> Result<(), SceneError> {
    for (i, (t, assignment)) in targets.iter().zip(assignments).enumerate() {
        let field = format!("{table_name}.targets[{i}].field");
        apply_override(table, assignment).map_err(|reason| {
            ck.err(
                field.clone(),
                format!("`{}` cannot be set: {reason}", t.field),
            )
        })?;
        toml::Value::Table(table.clone())
            .try_into::<Scene>()
            .map_err(|e| {
                ck.err(
                    field.clone(),
                    format!(
                        "setting `{assignment}` breaks the scene schema: {}",
                        one_line(&e.to_string())
                    ),
                )
            })?;
    }
    Ok(())
}

/// "F0 = 60 N", "m = 0": a parameter at a value, with its unit if it has one.
fn label(parameter: &str, unit: &str, value: f64) -> String {
    if unit.is_empty() {
        format!("{parameter} = {value}")
    } else {
        format!("{parameter} = {value} {unit}")
    }
}

/// A scene error without its file name (the sweep error names the file once).
fn inner(e: &SceneError) -> String {
    match e {
        SceneError::Invalid { field, reason, .. } => format!("field `{field}`: {reason}"),
        SceneError::Parse { message, .. } => message.clone(),
        SceneError::Override {
            assignment, reason, ..
        } => format!("--set `{assignment}`: {reason}"),
        SceneError::Io { source, .. } => format!("cannot read: {source}"),
    }
}
