//! The `[limits]` and `[sweep]` tables of the scene schema: which extra curves the limit
//! analysis computes, where it seeks peaks and writes loops, and which scene fields a sweep
//! moves. Plain serde structs: the values are checked by
//! [`Scene::validate_with_limits`](crate::scene::Scene::validate_with_limits).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

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
    /// The response envelope over all initial tangential states: `"sides"` (one m per damper
    /// side) or `"points"` (one m per contact point); absent: not computed.
    #[serde(default)]
    pub envelope: Option<crate::analysis::limits::EnvelopeMode>,
}

/// Default of `[limits].grid_points`: points of the common frequency grid.
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
    pub sides: BTreeMap<String, f64>,
    /// m ∈ [−1, 1] per contact name (wins over its side's value).
    #[serde(default)]
    pub contacts: BTreeMap<String, f64>,
    /// Second component m₂ (along t₂) per damper side name, for its `jenkins-2d` points.
    #[serde(default)]
    pub sides2: BTreeMap<String, f64>,
    /// Second component m₂ per `jenkins-2d` contact name (wins over its side's value).
    #[serde(default)]
    pub contacts2: BTreeMap<String, f64>,
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

/// Default of a sweep target's `scale`: the field follows the parameter one to one.
fn unit_scale() -> f64 {
    1.0
}

impl SweepSpec {
    /// The `--set` overrides that put the parameter at `value`.
    pub fn overrides(&self, value: f64) -> Vec<String> {
        target_overrides(&self.targets, value)
    }
}

/// The `--set FIELD=VALUE` overrides that put every target at `offset + scale · value`.
fn target_overrides(targets: &[SweepTarget], value: f64) -> Vec<String> {
    targets
        .iter()
        .map(|t| format!("{}={:e}", t.field, t.offset + t.scale * value))
        .collect()
}

/// Default of `[limits.hysteresis].at_peaks`: loops at the peaks are written.
fn yes() -> bool {
    true
}
