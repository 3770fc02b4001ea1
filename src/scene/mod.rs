//! Scene files: the TOML schema, `--set` overrides, and validation into a [`Problem`].
//!
//! Every table rejects unknown fields, and [`Scene::validate`] checks every value at the door,
//! naming the file, the field (dotted path, e.g. `contacts[1].mu`) and the reason. The full
//! field reference with units is `docs/scene.md`.

pub mod fe_input;

use std::path::{Path, PathBuf};

use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::analysis::limits::LimitSettings;
use crate::contact::aft::MarchSettings;
use crate::contact::{ContactEffects, ContactPoint, DamperSide, JenkinsLaw, NormalLoad};
use crate::model::matrix::StructuralMatrix;
use crate::model::{
    Analysis, Coupling, Effects, Formulation, HarmonicLoad, JacobianStrategy, LinearModel, Problem,
};
use crate::numerics::ContinuationSettings;
use crate::scene::fe_input::{
    ContactPatchSpec, FeStructure, MaterialSpec, MatrixMarketSpec, PlaneSpec, ReductionSpec,
};

/// A scene could not be read or is invalid.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read scene: {source}")]
    Io {
        /// Scene file.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the schema (unknown or missing field,
    /// wrong type).
    #[error("{file}: {message}")]
    Parse {
        /// Scene file.
        file: String,
        /// Parser message with location and field.
        message: String,
    },
    /// A value is out of range or inconsistent.
    #[error("{file}: field `{field}`: {reason}")]
    Invalid {
        /// Scene file.
        file: String,
        /// Dotted path of the field.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// A `--set FIELD=VALUE` override could not be applied.
    #[error("{file}: --set `{assignment}`: {reason}")]
    Override {
        /// Scene file.
        file: String,
        /// The override as given.
        assignment: String,
        /// What is wrong.
        reason: String,
    },
}

/// Top-level scene.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Free text shown in plots and summaries.
    #[serde(default)]
    pub title: String,
    /// Linear structure.
    pub model: ModelSpec,
    /// Craig-Bampton reduction of an FE model; absent: the full model is solved.
    #[serde(default)]
    pub reduction: Option<ReductionSpec>,
    /// Contact points.
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    /// Contact patches of FE meshes (node-to-node pairs between facing groups).
    #[serde(default)]
    pub contact_patches: Vec<ContactPatchSpec>,
    /// Static loads (N).
    #[serde(default)]
    pub static_loads: Vec<StaticLoadSpec>,
    /// Harmonic loads (N).
    #[serde(default)]
    pub harmonic_loads: Vec<HarmonicLoadSpec>,
    /// Harmonics and time sampling.
    pub harmonics: HarmonicsSpec,
    /// Switched effects.
    #[serde(default)]
    pub effects: EffectsSpec,
    /// Frequency range, continuation and tolerances.
    pub analysis: AnalysisSpec,
    /// Outputs.
    pub output: OutputSpec,
    /// Limit analysis among multiple solutions (two-point method); absent: one FRF.
    #[serde(default)]
    pub limits: Option<LimitsSpec>,
    /// Parameter sweep of the limit analysis (optimal curves); absent: no sweep.
    #[serde(default)]
    pub sweep: Option<SweepSpec>,
}

/// The `[limits]` table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// m values of intermediate curves (the same m on every damper side), each in [−1, 1].
    #[serde(default)]
    pub intermediate: Vec<f64>,
    /// Points of the common frequency grid used for classification and the band.
    #[serde(default = "default_grid_points")]
    pub grid_points: usize,
    /// m values scanned on every side (all combinations) to test whether the limits bound the
    /// other solutions; empty: no scan.
    #[serde(default)]
    pub bound_scan: Vec<f64>,
    /// Intermediate cases with m given per damper side and/or per contact point.
    #[serde(default)]
    pub cases: Vec<LimitCaseSpec>,
    /// Frequency window [start, end] (Hz) in which each curve's resonance peak is sought;
    /// absent: the whole range.
    #[serde(default)]
    pub peak_window_hz: Option<[f64; 2]>,
    /// Hysteresis loops to write; absent: at every curve's peak.
    #[serde(default)]
    pub hysteresis: Option<HysteresisSpec>,
}

fn default_grid_points() -> usize {
    201
}

/// One `[[limits.cases]]` entry: an intermediate case with m per side and/or per point.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitCaseSpec {
    /// Name in files and legends; default built from the entries (e.g. `left+0.5`).
    #[serde(default)]
    pub name: Option<String>,
    /// m ∈ [−1, 1] per damper side name.
    #[serde(default)]
    pub sides: std::collections::BTreeMap<String, f64>,
    /// m ∈ [−1, 1] per contact name (wins over its side's value).
    #[serde(default)]
    pub contacts: std::collections::BTreeMap<String, f64>,
}

/// The `[limits.hysteresis]` table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HysteresisSpec {
    /// Loops at each limit and intermediate curve's resonance peak (default true).
    #[serde(default = "yes")]
    pub at_peaks: bool,
    /// Loops at these frequencies (Hz) on each limit and intermediate curve.
    #[serde(default)]
    pub freqs_hz: Vec<f64>,
}

/// The `[sweep]` table: one parameter mapped linearly onto scene fields.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Parameter name for tables and plots (e.g. "F0", "beta").
    pub parameter: String,
    /// Parameter unit (e.g. "N", "deg").
    #[serde(default)]
    pub unit: String,
    /// Parameter values.
    pub values: Vec<f64>,
    /// Fields set from the parameter p: field = offset + scale · p.
    pub targets: Vec<SweepTarget>,
    /// What each value computes: `peaks` (default; resonance peaks of the limit and
    /// intermediate cases: optimal curves) or `limits` (the whole limit analysis: FRF bands).
    #[serde(default)]
    pub output: SweepOutput,
    /// A second parameter: the sweep is repeated at each of its values (one curve family per
    /// value, e.g. one optimal curve per apical angle).
    #[serde(default)]
    pub series: Option<SeriesSpec>,
}

/// What each sweep value computes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SweepOutput {
    /// Resonance peaks of the limit and intermediate cases.
    #[default]
    Peaks,
    /// The whole limit analysis (bands, classification, bound scan, loops).
    Limits,
}

/// The `[sweep.series]` table: the second parameter of a sweep.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeriesSpec {
    /// Parameter name (e.g. "beta").
    pub parameter: String,
    /// Parameter unit (e.g. "deg").
    #[serde(default)]
    pub unit: String,
    /// Parameter values.
    pub values: Vec<f64>,
    /// Fields set from the parameter: field = offset + scale · p.
    pub targets: Vec<SweepTarget>,
}

impl SeriesSpec {
    /// The `--set` overrides that put the series parameter at `value`.
    pub fn overrides(&self, value: f64) -> Vec<String> {
        target_overrides(&self.targets, value)
    }
}

/// One scene field driven by the sweep parameter.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepTarget {
    /// Dotted path of the field, as for `--set` (e.g. `static_loads.0.value`).
    pub field: String,
    /// Factor on the parameter.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Offset added.
    #[serde(default)]
    pub offset: f64,
}

fn unit_scale() -> f64 {
    1.0
}

impl SweepSpec {
    /// The `--set` overrides that put the parameter at `value`.
    pub fn overrides(&self, value: f64) -> Vec<String> {
        target_overrides(&self.targets, value)
    }
}

fn target_overrides(targets: &[SweepTarget], value: f64) -> Vec<String> {
    targets
        .iter()
        .map(|t| format!("{}={:e}", t.field, t.offset + t.scale * value))
        .collect()
}

/// Inline dense matrices with DOF names.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// DOF names, in matrix order (inline models).
    #[serde(default)]
    pub dofs: Vec<String>,
    /// Mass matrix (kg), rows (inline models).
    #[serde(default)]
    pub mass: Vec<Vec<f64>>,
    /// Stiffness matrix (N/m), rows (inline models).
    #[serde(default)]
    pub stiffness: Vec<Vec<f64>>,
    /// Viscous damping matrix (N·s/m), rows; zero when absent (inline models).
    #[serde(default)]
    pub damping: Option<Vec<Vec<f64>>>,
    /// Gmsh `.msh` 4.1 mesh (FE models), relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// Materials per physical group of the mesh.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<MaterialSpec>,
    /// Plane assumption of 2D meshes.
    #[serde(default)]
    pub plane: PlaneSpec,
    /// Physical groups clamped (all their DOFs removed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clamp: Vec<String>,
    /// K and M from Matrix Market files with a DOF map (FE models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix_market: Option<MatrixMarketSpec>,
    /// Rayleigh damping C = αM + βK of an FE model: [α (1/s), β (s)].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rayleigh: Option<[f64; 2]>,
}

impl ModelSpec {
    /// Whether the model comes from a mesh or Matrix Market files.
    pub fn is_fe(&self) -> bool {
        self.mesh.is_some() || self.matrix_market.is_some()
    }
}

/// One contact point.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Unique name.
    pub name: String,
    /// Damper side the point belongs to (defaults to the contact name).
    #[serde(default)]
    pub side: Option<String>,
    /// DOFs of the damper point (one per direction: x or x, y).
    pub damper: Vec<String>,
    /// DOFs of the body point, same directions; empty for a grounded body.
    #[serde(default)]
    pub body: Vec<String>,
    /// Frame by angle (degrees, 2D): t = (cos a, sin a), n = (−sin a, cos a) (paper Eq. 16).
    #[serde(default)]
    pub angle_deg: Option<f64>,
    /// Frame by vectors: tangent direction (normalised here).
    #[serde(default)]
    pub tangent: Option<Vec<f64>>,
    /// Frame by vectors: normal direction, pointing from the damper into the body.
    #[serde(default)]
    pub normal: Option<Vec<f64>>,
    /// Tangential stiffness (N/m).
    pub kt: f64,
    /// Normal stiffness (N/m).
    pub kn: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Initial normal gap (m); negative for an interference.
    #[serde(default)]
    pub gap: f64,
    /// Initial tangential state m ∈ [−1, 1].
    #[serde(default)]
    pub initial_state: f64,
}

/// A static force on one DOF.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StaticLoadSpec {
    /// DOF name; or give `group` and `direction`.
    #[serde(default)]
    pub dof: Option<String>,
    /// Physical group of an FE mesh whose nodes share the force (by mass).
    #[serde(default)]
    pub group: Option<String>,
    /// Direction of a group force: `x`, `y` or `z`.
    #[serde(default)]
    pub direction: Option<String>,
    /// Force (N); the total over the group for group loads.
    pub value: f64,
}

/// A harmonic force on one DOF: cos·cos(hωt) + sin·sin(hωt).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarmonicLoadSpec {
    /// DOF name; or give `group` and `direction`.
    #[serde(default)]
    pub dof: Option<String>,
    /// Physical group of an FE mesh whose nodes share the force (by mass).
    #[serde(default)]
    pub group: Option<String>,
    /// Direction of a group force: `x`, `y` or `z`.
    #[serde(default)]
    pub direction: Option<String>,
    /// Harmonic h ≥ 1.
    #[serde(default = "one")]
    pub harmonic: usize,
    /// Cosine amplitude (N).
    #[serde(default)]
    pub cos: f64,
    /// Sine amplitude (N).
    #[serde(default)]
    pub sin: f64,
}

fn one() -> usize {
    1
}

/// Harmonic set and AFT sampling.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarmonicsSpec {
    /// Highest harmonic H: balance 1..H (and 0 when coupled).
    #[serde(default)]
    pub max: Option<usize>,
    /// Explicit dynamic harmonics, e.g. [1, 3, 5] (0 may be listed; coupling decides).
    #[serde(default)]
    pub list: Option<Vec<usize>>,
    /// Time samples per period of the AFT (> 2·H).
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Most periods in the contact march before it is reported as not settling.
    #[serde(default = "default_max_periods")]
    pub max_periods: usize,
}

fn default_samples() -> usize {
    256
}
fn default_max_periods() -> usize {
    64
}

/// Switched effects.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectsSpec {
    /// `variable` (default) or `constant` normal load.
    #[serde(default)]
    pub normal_load: NormalLoad,
    /// Whether contacts may separate (default true).
    #[serde(default = "yes")]
    pub liftoff: bool,
    /// `coupled` (default) or `uncoupled` statics.
    #[serde(default)]
    pub coupling: Coupling,
}

impl Default for EffectsSpec {
    fn default() -> Self {
        Self {
            normal_load: NormalLoad::Variable,
            liftoff: true,
            coupling: Coupling::Coupled,
        }
    }
}

fn yes() -> bool {
    true
}

/// Frequency range and continuation settings.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysisSpec {
    /// Start frequency (Hz).
    pub freq_start_hz: f64,
    /// End frequency (Hz).
    pub freq_end_hz: f64,
    /// First arc-length step (Hz-equivalent); default range/200.
    #[serde(default)]
    pub initial_step: Option<f64>,
    /// Smallest step; default range·1e-7.
    #[serde(default)]
    pub min_step: Option<f64>,
    /// Largest step; default range/50.
    #[serde(default)]
    pub max_step: Option<f64>,
    /// Most continuation points.
    #[serde(default = "default_max_points")]
    pub max_points: usize,
    /// Newton iterations aimed at per step.
    #[serde(default = "default_target_iterations")]
    pub target_iterations: usize,
    /// Newton iterations before a step is cut.
    #[serde(default = "default_max_iterations")]
    pub max_iterations: usize,
    /// Relative residual tolerance (to the load norm).
    #[serde(default = "default_residual_tolerance")]
    pub residual_tolerance: f64,
    /// Scaled step tolerance.
    #[serde(default = "default_step_tolerance")]
    pub step_tolerance: f64,
    /// `analytic` (default), `forward-difference` or `central-difference`.
    #[serde(default)]
    pub jacobian: JacobianStrategy,
    /// `auto` (default), `dense`, `sparse`, `condensed` or `schur`.
    #[serde(default)]
    pub formulation: Formulation,
    /// Points of the uniform grid for the linear references.
    #[serde(default = "default_linear_points")]
    pub linear_points: usize,
}

fn default_max_points() -> usize {
    5000
}
fn default_target_iterations() -> usize {
    4
}
fn default_max_iterations() -> usize {
    12
}
fn default_residual_tolerance() -> f64 {
    1e-10
}
fn default_step_tolerance() -> f64 {
    1e-8
}
fn default_linear_points() -> usize {
    501
}

/// Outputs.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Response DOFs reported in `frf.csv` and plotted.
    #[serde(default)]
    pub dofs: Vec<String>,
    /// Response DOFs by physical group of an FE mesh: every node of the group in one
    /// direction.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupDirectionSpec>,
}

/// A physical group and a direction.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupDirectionSpec {
    /// Physical group name.
    pub group: String,
    /// `x`, `y` or `z`.
    pub direction: String,
}

/// Reads a scene file, applying `--set` overrides (`path=value`).
pub fn load(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        file: file.clone(),
        source,
    })?;
    parse(&text, &file, overrides)
}

/// Parses scene text (`file` names it in errors), applying overrides.
///
/// The text must match the schema on its own; then each override is applied in turn and the
/// result checked against the schema again, so that an unknown field or a wrong type is
/// reported against the `--set` that introduced it.
pub fn parse(text: &str, file: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    let parse_err = |e: toml::de::Error| SceneError::Parse {
        file: file.to_string(),
        message: parse_message(&e, text),
    };
    let scene: Scene = toml::from_str(text).map_err(parse_err)?;
    if overrides.is_empty() {
        return Ok(scene);
    }
    let mut table: toml::Table = text.parse().map_err(parse_err)?;
    for assignment in overrides {
        let override_err = |reason: String| SceneError::Override {
            file: file.to_string(),
            assignment: assignment.clone(),
            reason,
        };
        apply_override(&mut table, assignment).map_err(override_err)?;
        toml::Value::Table(table.clone())
            .try_into::<Scene>()
            .map_err(|e| override_err(one_line(&e.to_string())))?;
    }
    toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| SceneError::Parse {
            file: file.to_string(),
            message: format!("after --set overrides: {}", one_line(&e.to_string())),
        })
}

/// A parser error as `line L, column C: message` (one line, so that the first line of the
/// report names the field), followed by the offending source line.
fn parse_message(e: &toml::de::Error, text: &str) -> String {
    let located = e.span().and_then(|span| {
        let before = text.get(..span.start)?;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let line_no = before.matches('\n').count() + 1;
        let column = before[line_start..].chars().count() + 1;
        let source = text[line_start..].lines().next().unwrap_or("");
        Some(format!(
            "line {line_no}, column {column}: {}\n  | {source}",
            one_line(e.message())
        ))
    });
    located.unwrap_or_else(|| one_line(&e.to_string()))
}

fn one_line(message: &str) -> String {
    message
        .trim()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Applies one `a.b.0.c=value` override to a TOML table. The value is read as TOML (number,
/// boolean, array, quoted string) and otherwise taken as a bare string; an empty value removes
/// the field or array entry. Missing tables on the path are created; array entries must exist.
/// The result is not checked against the schema.
pub fn apply_override(table: &mut toml::Table, assignment: &str) -> Result<(), String> {
    let (path, raw) = assignment
        .split_once('=')
        .ok_or_else(|| "expected FIELD=VALUE".to_string())?;
    let path = path.trim();
    if path.is_empty() {
        return Err("empty field path".into());
    }
    // An empty value removes the field (e.g. `harmonics.max=` before giving `harmonics.list`).
    let value: Option<toml::Value> = if raw.trim().is_empty() {
        None
    } else {
        Some(match format!("v = {}", raw.trim()).parse::<toml::Table>() {
            Ok(mut t) => t.remove("v").expect("parsed key v"),
            Err(_) => toml::Value::String(raw.trim().to_string()),
        })
    };
    let segments: Vec<&str> = path.split('.').collect();
    let mut current = toml::Value::Table(std::mem::take(table));
    let result = set_path(&mut current, &segments, value, path);
    if let toml::Value::Table(t) = current {
        *table = t;
    }
    result
}

fn set_path(
    node: &mut toml::Value,
    segments: &[&str],
    value: Option<toml::Value>,
    full: &str,
) -> Result<(), String> {
    let (head, rest) = segments.split_first().expect("non-empty path");
    let child: &mut toml::Value = match node {
        toml::Value::Table(t) => {
            if rest.is_empty() {
                match value {
                    Some(v) => {
                        t.insert(head.to_string(), v);
                    }
                    None => {
                        t.remove(*head)
                            .ok_or_else(|| format!("no field `{head}` to remove in `{full}`"))?;
                    }
                }
                return Ok(());
            }
            if value.is_none() && !t.contains_key(*head) {
                return Err(format!("no field `{head}` to remove in `{full}`"));
            }
            // A table the file omits (e.g. `[effects]`) is created; whether the key belongs to
            // the schema is checked by the caller.
            t.entry(head.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        }
        toml::Value::Array(a) => {
            let i: usize = head
                .parse()
                .map_err(|_| format!("`{head}` is not an array index in `{full}`"))?;
            let len = a.len();
            let slot = a
                .get_mut(i)
                .ok_or_else(|| format!("index {i} out of range (length {len}) in `{full}`"))?;
            if rest.is_empty() {
                match value {
                    Some(v) => *slot = v,
                    None => {
                        a.remove(i);
                    }
                }
                return Ok(());
            }
            slot
        }
        _ => {
            return Err(format!(
                "`{head}` is below a value that is not a table or array in `{full}`"
            ))
        }
    };
    set_path(child, rest, value, full)
}

/// Most AFT samples per period a scene may ask for (2²⁰).
pub const MAX_SAMPLES: usize = 1 << 20;
/// Most continuation points or linear-reference points a scene may ask for.
pub const MAX_POINTS: usize = 10_000_000;

/// Validation context: file name for messages.
struct Checker<'a> {
    file: &'a str,
}

impl Checker<'_> {
    fn err(&self, field: impl Into<String>, reason: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            file: self.file.to_string(),
            field: field.into(),
            reason: reason.into(),
        }
    }

    fn finite(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(field, format!("must be a finite number, got {v}")))
        }
    }

    fn positive(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(field, format!("must be > 0, got {v}")))
        }
    }

    fn matrix(&self, field: &str, rows: &[Vec<f64>], n: usize) -> Result<Mat<f64>, SceneError> {
        if rows.len() != n {
            return Err(self.err(
                field,
                format!("has {} rows but the model has {n} DOFs", rows.len()),
            ));
        }
        for (i, r) in rows.iter().enumerate() {
            if r.len() != n {
                return Err(self.err(
                    format!("{field}[{i}]"),
                    format!("has {} entries but the model has {n} DOFs", r.len()),
                ));
            }
            for (j, v) in r.iter().enumerate() {
                self.finite(&format!("{field}[{i}][{j}]"), *v)?;
            }
        }
        let m = Mat::from_fn(n, n, |i, j| rows[i][j]);
        let scale = rows
            .iter()
            .flatten()
            .fold(0.0_f64, |a, v| a.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for i in 0..n {
            for j in 0..i {
                if (m[(i, j)] - m[(j, i)]).abs() > 1e-12 * scale {
                    return Err(self.err(
                        field,
                        format!(
                            "is not symmetric: [{i}][{j}] = {} but [{j}][{i}] = {}",
                            m[(i, j)],
                            m[(j, i)]
                        ),
                    ));
                }
            }
        }
        Ok(m)
    }

    fn semidefinite(&self, field: &str, m: &Mat<f64>) -> Result<(), SceneError> {
        if m.nrows() == 0 {
            return Ok(());
        }
        let eig = m
            .self_adjoint_eigenvalues(faer::Side::Lower)
            .map_err(|_| self.err(field, "eigenvalues could not be computed"))?;
        let max = eig.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let min = eig.iter().cloned().fold(f64::INFINITY, f64::min);
        if min < -1e-10 * max {
            return Err(self.err(
                field,
                format!(
                    "is indefinite (smallest eigenvalue {min:.4e}, largest magnitude {max:.4e})"
                ),
            ));
        }
        Ok(())
    }

    /// DOF and contact names become CSV column names and parts of file names.
    fn name(&self, field: &str, name: &str) -> Result<(), SceneError> {
        if name.trim().is_empty() {
            return Err(self.err(field, "must not be empty"));
        }
        if let Some(bad) = name
            .chars()
            .find(|c| matches!(c, ',' | '"' | '/' | '\\') || c.is_control())
        {
            return Err(self.err(
                field,
                format!(
                    "`{}` contains {bad:?}, which cannot appear in CSV column or file names",
                    name.escape_debug()
                ),
            ));
        }
        Ok(())
    }

    fn dof(&self, field: &str, name: &str, dofs: &DofNames) -> Result<usize, SceneError> {
        dofs.index.get(name).copied().ok_or_else(|| {
            let listed = if dofs.names.len() <= 24 {
                dofs.names.join(", ")
            } else {
                format!(
                    "{} DOFs named <node>.<direction>, e.g. {}, ...",
                    dofs.names.len(),
                    dofs.names[..3].join(", ")
                )
            };
            self.err(
                field,
                format!("unknown DOF `{name}` (the model has {listed})"),
            )
        })
    }

    /// The DOFs and weights of a load given by `dof` or by `group` and `direction`.
    fn load_targets(
        &self,
        field: &str,
        dof: Option<&str>,
        group: Option<&str>,
        direction: Option<&str>,
        dofs: &DofNames,
        fe: Option<&FeStructure>,
    ) -> Result<Vec<(usize, f64)>, SceneError> {
        match (dof, group, direction) {
            (Some(d), None, None) => Ok(vec![(self.dof(&format!("{field}.dof"), d, dofs)?, 1.0)]),
            (None, Some(g), Some(dir)) => match fe {
                Some(fe) => fe_input::group_load(self.file, field, fe, g, dir),
                None => Err(self.err(
                    format!("{field}.group"),
                    "loads on groups need an FE mesh (`model.mesh`)",
                )),
            },
            _ => Err(self.err(field, "give either `dof`, or `group` and `direction`")),
        }
    }
}

/// DOF names with a look-up index.
struct DofNames<'a> {
    names: &'a [String],
    index: std::collections::HashMap<&'a str, usize>,
}

impl<'a> DofNames<'a> {
    fn new(names: &'a [String]) -> Self {
        Self {
            names,
            index: names
                .iter()
                .enumerate()
                .map(|(i, s)| (s.as_str(), i))
                .collect(),
        }
    }
}

impl std::ops::Index<usize> for DofNames<'_> {
    type Output = String;
    fn index(&self, i: usize) -> &String {
        &self.names[i]
    }
}

impl Scene {
    /// The linear structure: inline dense matrices, or an FE model (mesh or Matrix Market).
    fn build_model(&self, ck: &Checker) -> Result<(LinearModel, Option<FeStructure>), SceneError> {
        let m = &self.model;
        if m.is_fe() {
            if !m.dofs.is_empty()
                || !m.mass.is_empty()
                || !m.stiffness.is_empty()
                || m.damping.is_some()
            {
                return Err(ck.err(
                    "model",
                    "give inline matrices (`dofs`, `mass`, `stiffness`, `damping`) or an FE model \
                     (`mesh` or `matrix_market`), not both",
                ));
            }
            let [alpha, beta] = m.rayleigh.unwrap_or([0.0, 0.0]);
            for (i, v) in [alpha, beta].iter().enumerate() {
                let f = format!("model.rayleigh[{i}]");
                ck.finite(&f, *v)?;
                if *v < 0.0 {
                    return Err(ck.err(f, format!("must be ≥ 0, got {v}")));
                }
            }
            let fe = fe_input::build_structure(
                ck.file,
                m.mesh.as_deref(),
                &m.materials,
                m.plane,
                &m.clamp,
                m.matrix_market.as_ref(),
                (alpha, beta),
            )?;
            return Ok((fe.model.clone(), Some(fe)));
        }
        for (field, set) in [
            ("model.materials", !m.materials.is_empty()),
            ("model.clamp", !m.clamp.is_empty()),
            ("model.rayleigh", m.rayleigh.is_some()),
        ] {
            if set {
                return Err(ck.err(
                    field,
                    "applies to FE models only (`mesh` or `matrix_market`)",
                ));
            }
        }
        let dofs = &m.dofs;
        let n = dofs.len();
        if n == 0 {
            return Err(ck.err("model.dofs", "must name at least one DOF"));
        }
        for (i, d) in dofs.iter().enumerate() {
            ck.name(&format!("model.dofs[{i}]"), d)?;
            if dofs[..i].contains(d) {
                return Err(ck.err(format!("model.dofs[{i}]"), format!("duplicate DOF `{d}`")));
            }
        }
        let mass = ck.matrix("model.mass", &m.mass, n)?;
        let stiffness = ck.matrix("model.stiffness", &m.stiffness, n)?;
        let damping = match &m.damping {
            Some(c) => ck.matrix("model.damping", c, n)?,
            None => Mat::zeros(n, n),
        };
        ck.semidefinite("model.mass", &mass)?;
        ck.semidefinite("model.stiffness", &stiffness)?;
        ck.semidefinite("model.damping", &damping)?;
        Ok((
            LinearModel {
                dof_names: dofs.clone(),
                mass: StructuralMatrix::Dense(mass),
                damping: StructuralMatrix::Dense(damping),
                stiffness: StructuralMatrix::Dense(stiffness),
            },
            None,
        ))
    }

    /// Checks every value and builds the problem. `file` names the scene in errors.
    pub fn validate(&self, file: &str) -> Result<Problem, SceneError> {
        self.validate_with_limits(file).map(|(problem, _)| problem)
    }

    /// Checks every value and builds the problem and, when the scene has a `[limits]` table,
    /// the settings of its limit analysis. `file` names the scene in errors.
    pub fn validate_with_limits(
        &self,
        file: &str,
    ) -> Result<(Problem, Option<LimitSettings>), SceneError> {
        let ck = Checker { file };
        let (model, fe) = self.build_model(&ck)?;
        let dofs = DofNames::new(&model.dof_names);
        let dofs = &dofs;
        let n = model.n_dofs();

        if self.contacts.is_empty() && self.contact_patches.is_empty() {
            return Err(ck.err(
                "contacts",
                "the contact set is empty: a friction analysis needs at least one [[contacts]] \
                 entry or [[contact_patches]] entry",
            ));
        }
        let mut contacts = Vec::new();
        let mut sides: Vec<DamperSide> = Vec::new();
        for (ci, c) in self.contacts.iter().enumerate() {
            let f = |name: &str| format!("contacts[{ci}].{name}");
            ck.name(&f("name"), &c.name)?;
            if self.contacts[..ci].iter().any(|o| o.name == c.name) {
                return Err(ck.err(f("name"), format!("duplicate contact name `{}`", c.name)));
            }
            if c.side.as_deref().is_some_and(|s| s.trim().is_empty()) {
                return Err(ck.err(
                    f("side"),
                    "must not be empty (omit it to use the contact name)",
                ));
            }
            let dim = c.damper.len();
            if dim == 0 {
                return Err(ck.err(f("damper"), "must list the damper point's DOFs"));
            }
            if !c.body.is_empty() && c.body.len() != dim {
                return Err(ck.err(
                    f("body"),
                    format!("has {} DOFs but `damper` has {dim}", c.body.len()),
                ));
            }
            let damper_idx: Vec<usize> = c
                .damper
                .iter()
                .enumerate()
                .map(|(i, d)| ck.dof(&format!("contacts[{ci}].damper[{i}]"), d, dofs))
                .collect::<Result<_, _>>()?;
            let body_idx: Vec<usize> = c
                .body
                .iter()
                .enumerate()
                .map(|(i, d)| ck.dof(&format!("contacts[{ci}].body[{i}]"), d, dofs))
                .collect::<Result<_, _>>()?;
            for (list, idx) in [("damper", &damper_idx), ("body", &body_idx)] {
                for (i, d) in idx.iter().enumerate() {
                    if idx[..i].contains(d) {
                        return Err(ck.err(
                            format!("contacts[{ci}].{list}[{i}]"),
                            format!("DOF `{}` is listed twice in the same point", dofs[*d]),
                        ));
                    }
                }
            }
            if let Some(i) = body_idx.iter().position(|b| damper_idx.contains(b)) {
                return Err(ck.err(
                    format!("contacts[{ci}].body[{i}]"),
                    format!(
                        "DOF `{}` is also a DOF of the damper point; the damper and the body \
                         must use distinct DOFs",
                        dofs[body_idx[i]]
                    ),
                ));
            }
            let (t, nv) = match (c.angle_deg, &c.tangent, &c.normal) {
                (Some(a), None, None) => {
                    ck.finite(&f("angle_deg"), a)?;
                    if dim != 2 {
                        return Err(ck.err(
                            f("angle_deg"),
                            format!(
                                "a frame by angle needs 2 DOFs per point, this point has {dim}"
                            ),
                        ));
                    }
                    let r = a.to_radians();
                    (vec![r.cos(), r.sin()], vec![-r.sin(), r.cos()])
                }
                (None, Some(t), Some(nn)) => {
                    for (name, v) in [("tangent", t), ("normal", nn)] {
                        if v.len() != dim {
                            return Err(ck.err(
                                f(name),
                                format!("has {} components but the point has {dim} DOFs", v.len()),
                            ));
                        }
                        for (i, x) in v.iter().enumerate() {
                            ck.finite(&format!("contacts[{ci}].{name}[{i}]"), *x)?;
                        }
                    }
                    let tn = t.iter().map(|x| x * x).sum::<f64>().sqrt();
                    if tn == 0.0 {
                        return Err(ck.err(f("tangent"), "must not be the zero vector"));
                    }
                    let nn_norm = nn.iter().map(|x| x * x).sum::<f64>().sqrt();
                    let t: Vec<f64> = t.iter().map(|x| x / tn).collect();
                    let nn: Vec<f64> = if nn_norm > 0.0 {
                        nn.iter().map(|x| x / nn_norm).collect()
                    } else {
                        nn.clone()
                    };
                    let dot: f64 = t.iter().zip(&nn).map(|(a, b)| a * b).sum();
                    if dot.abs() > 1e-9 {
                        return Err(ck.err(
                            f("normal"),
                            format!("must be perpendicular to `tangent` (t·n = {dot:.3e})"),
                        ));
                    }
                    (t, nn)
                }
                _ => {
                    return Err(ck.err(
                        f("angle_deg"),
                        "give the frame either by `angle_deg` or by both `tangent` and `normal`",
                    ))
                }
            };
            let kt = ck.positive(&f("kt"), c.kt)?;
            let kn = ck.positive(&f("kn"), c.kn)?;
            let mu = ck.finite(&f("mu"), c.mu)?;
            if mu < 0.0 {
                return Err(ck.err(
                    f("mu"),
                    format!("friction coefficient must be ≥ 0, got {mu}"),
                ));
            }
            let gap = ck.finite(&f("gap"), c.gap)?;
            let m = ck.finite(&f("initial_state"), c.initial_state)?;
            if !(-1.0..=1.0).contains(&m) {
                return Err(ck.err(
                    f("initial_state"),
                    format!("must lie in [-1, 1] (T(0) = m·μN(0)), got {m}"),
                ));
            }
            let mut tangential = Vec::new();
            let mut normal = Vec::new();
            for d in 0..dim {
                push_coefficient(&mut tangential, damper_idx[d], t[d]);
                push_coefficient(&mut normal, damper_idx[d], nv[d]);
                if let Some(&b) = body_idx.get(d) {
                    push_coefficient(&mut tangential, b, -t[d]);
                    push_coefficient(&mut normal, b, -nv[d]);
                }
            }
            let side_name = c.side.clone().unwrap_or_else(|| c.name.clone());
            let side = match sides.iter().position(|s| s.name == side_name) {
                Some(s) => s,
                None => {
                    sides.push(DamperSide {
                        name: side_name,
                        contacts: Vec::new(),
                    });
                    sides.len() - 1
                }
            };
            sides[side].contacts.push(ci);
            contacts.push(ContactPoint {
                name: c.name.clone(),
                side,
                tangential,
                normal,
                gap,
                law: JenkinsLaw {
                    kt,
                    kn,
                    mu,
                    initial_state: m,
                },
            });
        }

        for (pi, p) in self.contact_patches.iter().enumerate() {
            let f = |name: &str| format!("contact_patches[{pi}].{name}");
            ck.name(&f("side"), &p.side)?;
            ck.positive(&f("kt"), p.kt)?;
            ck.positive(&f("kn"), p.kn)?;
            let mu = ck.finite(&f("mu"), p.mu)?;
            if mu < 0.0 {
                return Err(ck.err(
                    f("mu"),
                    format!("friction coefficient must be ≥ 0, got {mu}"),
                ));
            }
            ck.finite(&f("gap"), p.gap)?;
            ck.positive(&f("tolerance"), p.tolerance)?;
            let m = ck.finite(&f("initial_state"), p.initial_state)?;
            if !(-1.0..=1.0).contains(&m) {
                return Err(ck.err(
                    f("initial_state"),
                    format!("must lie in [-1, 1] (T(0) = m·μN(0)), got {m}"),
                ));
            }
            let Some(structure) = fe.as_ref() else {
                return Err(ck.err(
                    format!("contact_patches[{pi}]"),
                    "contact patches need an FE mesh (`model.mesh`)",
                ));
            };
            let side = match sides.iter().position(|s| s.name == p.side) {
                Some(s) => s,
                None => {
                    sides.push(DamperSide {
                        name: p.side.clone(),
                        contacts: Vec::new(),
                    });
                    sides.len() - 1
                }
            };
            let points = fe_input::patch_contacts(
                file,
                &format!("contact_patches[{pi}]"),
                structure,
                p,
                side,
            )?;
            for point in points {
                if contacts.iter().any(|c: &ContactPoint| c.name == point.name) {
                    return Err(ck.err(
                        f("side"),
                        format!("contact point name `{}` is already used", point.name),
                    ));
                }
                sides[side].contacts.push(contacts.len());
                contacts.push(point);
            }
        }

        let mut static_load = vec![0.0; n];
        for (i, l) in self.static_loads.iter().enumerate() {
            let value = ck.finite(&format!("static_loads[{i}].value"), l.value)?;
            for (d, w) in ck.load_targets(
                &format!("static_loads[{i}]"),
                l.dof.as_deref(),
                l.group.as_deref(),
                l.direction.as_deref(),
                dofs,
                fe.as_ref(),
            )? {
                static_load[d] += w * value;
            }
        }

        let h_max = match (&self.harmonics.max, &self.harmonics.list) {
            (Some(h), None) => {
                if *h == 0 {
                    return Err(ck.err(
                        "harmonics.max",
                        "must be ≥ 1 (the 0th harmonic alone has no dynamics)",
                    ));
                }
                *h
            }
            (None, Some(list)) => match list.iter().copied().max() {
                Some(h) if h > 0 => h,
                _ => return Err(ck.err("harmonics.list", "must hold at least one harmonic ≥ 1")),
            },
            _ => {
                return Err(ck.err(
                    "harmonics",
                    "give exactly one of `max` (harmonics 1..H) or `list`",
                ))
            }
        };
        // The sampling check comes before the set is built, so that an absurd H is an error
        // rather than an allocation of H entries.
        if self.harmonics.samples <= h_max.saturating_mul(2) || self.harmonics.samples < 8 {
            return Err(ck.err(
                "harmonics.samples",
                format!(
                    "must be ≥ 8 and > 2·H = {} to resolve harmonic {h_max}, got {}",
                    h_max.saturating_mul(2),
                    self.harmonics.samples
                ),
            ));
        }
        if self.harmonics.samples > MAX_SAMPLES {
            return Err(ck.err(
                "harmonics.samples",
                format!("must be ≤ {MAX_SAMPLES}, got {}", self.harmonics.samples),
            ));
        }
        if self.harmonics.max_periods < 2 {
            return Err(ck.err("harmonics.max_periods", "must be ≥ 2"));
        }
        let harmonics: Vec<usize> = match &self.harmonics.list {
            Some(list) => {
                let mut l: Vec<usize> = list.iter().copied().filter(|&h| h > 0).collect();
                l.sort_unstable();
                l.dedup();
                l
            }
            None => (1..=h_max).collect(),
        };

        let mut harmonic_loads = Vec::new();
        for (i, l) in self.harmonic_loads.iter().enumerate() {
            let targets = ck.load_targets(
                &format!("harmonic_loads[{i}]"),
                l.dof.as_deref(),
                l.group.as_deref(),
                l.direction.as_deref(),
                dofs,
                fe.as_ref(),
            )?;
            if l.harmonic == 0 {
                return Err(ck.err(
                    format!("harmonic_loads[{i}].harmonic"),
                    "must be ≥ 1 (static forces go in [[static_loads]])",
                ));
            }
            if !harmonics.contains(&l.harmonic) {
                return Err(ck.err(
                    format!("harmonic_loads[{i}].harmonic"),
                    format!(
                        "harmonic {} is not in the harmonic set {harmonics:?}",
                        l.harmonic
                    ),
                ));
            }
            let cos = ck.finite(&format!("harmonic_loads[{i}].cos"), l.cos)?;
            let sin = ck.finite(&format!("harmonic_loads[{i}].sin"), l.sin)?;
            for (dof, w) in targets {
                harmonic_loads.push(HarmonicLoad {
                    dof,
                    harmonic: l.harmonic,
                    cos: w * cos,
                    sin: w * sin,
                });
            }
        }
        if harmonic_loads.iter().all(|l| l.cos == 0.0 && l.sin == 0.0) {
            return Err(ck.err(
                "harmonic_loads",
                "no non-zero harmonic load: a forced response needs an excitation",
            ));
        }

        let a = &self.analysis;
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
        let residual_tolerance =
            ck.positive("analysis.residual_tolerance", a.residual_tolerance)?;
        let step_tolerance = ck.positive("analysis.step_tolerance", a.step_tolerance)?;

        if self.output.dofs.is_empty() && self.output.groups.is_empty() {
            return Err(ck.err("output.dofs", "name at least one response DOF"));
        }
        let mut outputs = self
            .output
            .dofs
            .iter()
            .enumerate()
            .map(|(i, d)| ck.dof(&format!("output.dofs[{i}]"), d, dofs))
            .collect::<Result<Vec<_>, _>>()?;
        for (i, g) in self.output.groups.iter().enumerate() {
            let field = format!("output.groups[{i}]");
            let targets = ck.load_targets(
                &field,
                None,
                Some(&g.group),
                Some(&g.direction),
                dofs,
                fe.as_ref(),
            )?;
            outputs.extend(targets.into_iter().map(|(d, _)| d));
        }

        let limits = self.validate_limits(&ck)?;
        let problem = Problem {
            model,
            contacts,
            sides,
            static_load,
            harmonic_loads,
            harmonics,
            samples: self.harmonics.samples,
            effects: Effects {
                contact: ContactEffects {
                    normal_load: self.effects.normal_load,
                    liftoff: self.effects.liftoff,
                },
                coupling: self.effects.coupling,
            },
            march: MarchSettings {
                max_periods: self.harmonics.max_periods,
                ..MarchSettings::default()
            },
            analysis: Analysis {
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
                    chord_min_unknowns: crate::model::CHORD_MIN_UNKNOWNS,
                },
                jacobian: a.jacobian,
                formulation: a.formulation,
                linear_points: a.linear_points,
            },
            outputs,
            fe: fe.as_ref().and_then(|f| {
                f.mesh.as_ref().map(|mesh| {
                    std::sync::Arc::new(crate::model::FeOrigin {
                        mesh: mesh.clone(),
                        dofs: f.dofs.clone(),
                        recovery: None,
                        reduced: false,
                    })
                })
            }),
        };
        self.validate_sweep(&ck)?;
        let problem = match &self.reduction {
            None => problem,
            Some(r) => {
                if r.modes == 0 {
                    return Err(ck.err("reduction.modes", "must be ≥ 1"));
                }
                let zeta = ck.finite("reduction.modal_damping", r.modal_damping)?;
                if zeta < 0.0 {
                    return Err(ck.err(
                        "reduction.modal_damping",
                        format!("must be ≥ 0, got {zeta}"),
                    ));
                }
                let [alpha, beta] = self.model.rayleigh.unwrap_or([0.0, 0.0]);
                let settings = crate::model::reduce::ReductionSettings {
                    modes: r.modes,
                    modal_damping: zeta,
                    rayleigh: (alpha, beta),
                    ordering: r.ordering.ordering(),
                    recover: Vec::new(),
                };
                crate::model::reduce::reduce(&problem, &settings)
                    .map_err(|e| ck.err("reduction", e.to_string()))?
                    .problem
            }
        };
        check_stuck_structure(&ck, &problem)?;
        if problem.analysis.formulation == Formulation::Schur {
            crate::hbm::formulation::check_relative_coordinates(&problem)
                .map_err(|e| ck.err("analysis.formulation", e.to_string()))?;
        }
        Ok((problem, limits))
    }

    fn validate_limits(&self, ck: &Checker) -> Result<Option<LimitSettings>, SceneError> {
        let Some(l) = &self.limits else {
            return Ok(None);
        };
        let check_m = |field: String, m: f64| -> Result<f64, SceneError> {
            ck.finite(&field, m)?;
            if !(-1.0..=1.0).contains(&m) {
                return Err(ck.err(
                    field,
                    format!("an initial state m must lie in [-1, 1], got {m}"),
                ));
            }
            Ok(m)
        };
        for (name, list) in [
            ("intermediate", &l.intermediate),
            ("bound_scan", &l.bound_scan),
        ] {
            for (i, m) in list.iter().enumerate() {
                check_m(format!("limits.{name}[{i}]"), *m)?;
            }
        }
        if !(2..=100_000).contains(&l.grid_points) {
            return Err(ck.err(
                "limits.grid_points",
                format!("must be in 2..=100000, got {}", l.grid_points),
            ));
        }
        let side_names = {
            let mut names: Vec<String> = Vec::new();
            for c in &self.contacts {
                let s = c.side.clone().unwrap_or_else(|| c.name.clone());
                if !names.contains(&s) {
                    names.push(s);
                }
            }
            names
        };
        let sides = side_names.len();
        let combinations = (l.bound_scan.len() as f64).powi(sides as i32);
        if combinations > 4096.0 {
            return Err(ck.err(
                "limits.bound_scan",
                format!(
                    "{} values on {sides} sides make {combinations} curves; at most 4096",
                    l.bound_scan.len()
                ),
            ));
        }

        // Intermediate cases per side or point; names must not clash with the uniform ones.
        let signed = crate::analysis::limits::signed;
        let mut names: Vec<String> = [1.0, -1.0]
            .iter()
            .chain(&l.intermediate)
            .map(|&m| format!("m{}", signed(m)))
            .collect();
        let mut cases = Vec::new();
        for (i, c) in l.cases.iter().enumerate() {
            let f = |name: &str| format!("limits.cases[{i}].{name}");
            if c.sides.is_empty() && c.contacts.is_empty() {
                return Err(ck.err(
                    format!("limits.cases[{i}]"),
                    "give m for at least one damper side (`sides`) or contact (`contacts`)",
                ));
            }
            let mut side_states = Vec::new();
            for (name, &m) in &c.sides {
                let field = format!("{}.{name}", f("sides"));
                let side = side_names.iter().position(|s| s == name).ok_or_else(|| {
                    ck.err(
                        field.clone(),
                        format!(
                            "unknown damper side `{name}` (the scene has {})",
                            side_names.join(", ")
                        ),
                    )
                })?;
                side_states.push((side, check_m(field, m)?));
            }
            let mut contact_states = Vec::new();
            for (name, &m) in &c.contacts {
                let field = format!("{}.{name}", f("contacts"));
                let contact = self
                    .contacts
                    .iter()
                    .position(|k| &k.name == name)
                    .ok_or_else(|| {
                        ck.err(
                            field.clone(),
                            format!(
                                "unknown contact `{name}` (the scene has {})",
                                self.contacts
                                    .iter()
                                    .map(|k| k.name.as_str())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        )
                    })?;
                contact_states.push((contact, check_m(field, m)?));
            }
            let name = match &c.name {
                Some(n) => {
                    ck.name(&f("name"), n)?;
                    n.clone()
                }
                None => c
                    .sides
                    .iter()
                    .chain(&c.contacts)
                    .map(|(k, m)| format!("{k}{}", signed(*m)))
                    .collect::<Vec<_>>()
                    .join("_"),
            };
            if names.contains(&name) {
                return Err(ck.err(
                    f("name"),
                    format!("case name `{name}` is already used by another curve"),
                ));
            }
            names.push(name.clone());
            cases.push(crate::analysis::limits::CaseSpec {
                name,
                sides: side_states,
                contacts: contact_states,
            });
        }

        let (f_lo, f_hi) = (self.analysis.freq_start_hz, self.analysis.freq_end_hz);
        let peak_window_hz = match l.peak_window_hz {
            None => None,
            Some([lo, hi]) => {
                ck.finite("limits.peak_window_hz[0]", lo)?;
                ck.finite("limits.peak_window_hz[1]", hi)?;
                if lo >= hi {
                    return Err(ck.err(
                        "limits.peak_window_hz",
                        format!("the window is reversed or empty: {lo} .. {hi} Hz"),
                    ));
                }
                if hi <= f_lo || lo >= f_hi {
                    return Err(ck.err(
                        "limits.peak_window_hz",
                        format!(
                            "the window {lo} .. {hi} Hz lies outside the analysis range \
                             {f_lo} .. {f_hi} Hz"
                        ),
                    ));
                }
                Some((lo, hi))
            }
        };
        let hysteresis = match &l.hysteresis {
            None => crate::analysis::limits::HysteresisRequest::default(),
            Some(h) => {
                for (i, &f) in h.freqs_hz.iter().enumerate() {
                    let field = format!("limits.hysteresis.freqs_hz[{i}]");
                    ck.finite(&field, f)?;
                    if f < f_lo || f > f_hi {
                        return Err(ck.err(
                            field,
                            format!("{f} Hz lies outside the analysis range {f_lo} .. {f_hi} Hz"),
                        ));
                    }
                }
                crate::analysis::limits::HysteresisRequest {
                    at_peaks: h.at_peaks,
                    freqs_hz: h.freqs_hz.clone(),
                }
            }
        };
        Ok(Some(crate::analysis::limits::LimitSettings {
            intermediate: l.intermediate.clone(),
            cases,
            grid_points: l.grid_points,
            bound_scan: l.bound_scan.clone(),
            peak_window_hz,
            hysteresis,
        }))
    }

    fn validate_sweep(&self, ck: &Checker) -> Result<(), SceneError> {
        let Some(s) = &self.sweep else {
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
        if self.limits.is_none() {
            return Err(ck.err(
                "sweep",
                "a sweep runs the limit analysis: add a [limits] table",
            ));
        }
        Ok(())
    }
}

/// The structure with all contacts stuck must carry static loads: K + contact springs must be
/// positive definite (a free body, or an indefinite K, is refused). Dense models: eigenvalues;
/// sparse ones: a sparse Cholesky factorisation.
fn check_stuck_structure(ck: &Checker, problem: &Problem) -> Result<(), SceneError> {
    let singular = || {
        ck.err(
            "model.stiffness",
            "the structure is singular or indefinite even with all contacts stuck (a body is \
             free, or K has a negative eigenvalue: ground the body or connect it through a \
             contact, and check K)",
        )
    };
    match &problem.model.stiffness {
        StructuralMatrix::Dense(k) => {
            let mut k = k.clone();
            for (i, j, v) in crate::analysis::linear::contact_stiffness(problem) {
                k[(i, j)] += v;
            }
            let eig = k
                .self_adjoint_eigenvalues(faer::Side::Lower)
                .map_err(|_| ck.err("model.stiffness", "eigenvalues could not be computed"))?;
            let max = eig.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
            let min = eig.iter().cloned().fold(f64::INFINITY, f64::min);
            if min <= 1e-12 * max {
                return Err(singular());
            }
        }
        StructuralMatrix::Sparse(_) => {
            let mut t = problem.model.stiffness.triplets();
            t.extend(crate::analysis::linear::contact_stiffness(problem));
            let StructuralMatrix::Sparse(k) =
                StructuralMatrix::sparse_from_triplets(problem.model.n_dofs(), &t)
            else {
                unreachable!("sparse_from_triplets builds sparse storage")
            };
            k.sp_cholesky(faer::Side::Lower).map_err(|_| singular())?;
        }
    }
    Ok(())
}

fn push_coefficient(row: &mut Vec<(usize, f64)>, dof: usize, value: f64) {
    if value == 0.0 {
        return;
    }
    match row.iter_mut().find(|(d, _)| *d == dof) {
        Some((_, v)) => *v += value,
        None => row.push((dof, value)),
    }
}

/// Loads and validates a scene in one go; returns the scene (for echoing) and the problem.
pub fn load_problem(path: &Path, overrides: &[String]) -> Result<(Scene, Problem), SceneError> {
    let scene = load(path, overrides)?;
    let problem = scene.validate(&path.display().to_string())?;
    Ok((scene, problem))
}

/// The paper's default scene (β = 120°, F0 = 120 N, full range), shipped in the binary.
pub const PAPER_DEFAULT_SCENE: &str = include_str!("../../meshes/paper-wedge/full-range.toml");

/// The paper's wedge-damper scene (β = 120°, F₀ = 120 N, full range) as TOML text: the
/// reference problem shared by tests, benchmarks and docs.
pub fn paper_wedge_scene() -> &'static str {
    PAPER_DEFAULT_SCENE
}

/// Path label used for the built-in default scene in messages.
pub fn default_scene_label() -> PathBuf {
    PathBuf::from("meshes/paper-wedge/full-range.toml")
}
