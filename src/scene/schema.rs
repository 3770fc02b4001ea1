//! The scene schema: the serde structs of a scene file's TOML tables (model, contacts, loads,
//! harmonics, effects, analysis, output) with their defaults. Every table rejects unknown
//! fields; the values are checked later, at validation. The `[limits]` and `[sweep]` tables are
//! in [`crate::scene::limits_schema`], the FE tables in [`crate::scene::fe_input`].

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::contact::NormalLoad;
use crate::model::{BeyondLinearRange, Coupling, Formulation, JacobianStrategy};
use crate::scene::fe_input::{
    ContactPatchSpec, MaterialSpec, MatrixMarketSpec, PlaneSpec, ReductionSpec,
};
use crate::scene::limits_schema::{LimitsSpec, SweepSpec};

/// Reads a tangential stiffness kₜ (N/m): one number (integer or float). An array, such as
/// `kt = [k1, k2]` for an anisotropic stiffness along t₁ and t₂, is refused with a message that
/// says why: the `jenkins-2d` law is isotropic (kₜ is the same in every direction of the tangent
/// plane). With kₜ₁ ≠ kₜ₂ the maximum-dissipation return onto the Coulomb circle is a
/// closest-point projection in the compliance metric, not the radial return the march and its
/// Jacobian implement (README, "2D tangential friction"). The parser adds the file, line and
/// source line to the message.
pub(crate) fn one_tangential_stiffness<'de, D>(deserializer: D) -> Result<f64, D::Error>
where
    D: serde::Deserializer<'de>,
{
    struct OneStiffness;
    impl<'de> serde::de::Visitor<'de> for OneStiffness {
        type Value = f64;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("one number, the tangential stiffness kt in N/m")
        }
        fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<f64, E> {
            Ok(v)
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<f64, E> {
            Ok(v as f64)
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<f64, E> {
            Ok(v as f64)
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<f64, A::Error> {
            let mut count = 0usize;
            while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                count += 1;
            }
            Err(serde::de::Error::custom(format!(
                "`kt` takes one number (N/m), got an array of {count}: the tangential stiffness \
                 is isotropic, the same along every tangent direction (an anisotropic kt, one \
                 per tangent direction, is not supported: README, \"2D tangential friction\")"
            )))
        }
    }
    deserializer.deserialize_any(OneStiffness)
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
    /// The a-posteriori error estimate on every converged point; absent: on, 1 % threshold.
    #[serde(default, skip_serializing_if = "AccuracySpec::is_default")]
    pub accuracy: AccuracySpec,
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
    /// Tangential stiffness (N/m): one number, the same in every tangential direction (a
    /// `jenkins-2d` point is isotropic; `one_tangential_stiffness` refuses an array).
    #[serde(deserialize_with = "one_tangential_stiffness")]
    pub kt: f64,
    /// Normal stiffness (N/m).
    pub kn: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Initial normal gap (m); negative for an interference.
    #[serde(default)]
    pub gap: f64,
    /// Initial tangential state m ∈ [−1, 1] (for a `jenkins-2d` point, its component m₁ along
    /// `tangent`).
    #[serde(default)]
    pub initial_state: f64,
    /// Tangential friction law: `"jenkins-1d"` (default, the paper's element along `tangent`)
    /// or `"jenkins-2d"` (isotropic friction in the tangent plane; 3 DOFs per point).
    #[serde(default)]
    pub law: crate::contact::FrictionLaw,
    /// Second tangent direction of a `jenkins-2d` point (normalised here, perpendicular to
    /// `tangent` and `normal`); default n × t.
    #[serde(default)]
    pub tangent2: Option<Vec<f64>>,
    /// Component m₂ of the initial tangential state along the second tangent of a `jenkins-2d`
    /// point; (m₁, m₂) must lie in the unit disc.
    #[serde(default)]
    pub initial_state2: f64,
}

impl ContactSpec {
    /// The damper side the point belongs to: `side`, or the contact name when absent.
    pub fn side_name(&self) -> String {
        self.side.clone().unwrap_or_else(|| self.name.clone())
    }
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

/// Default harmonic of a harmonic load: the fundamental.
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

/// Default AFT time samples per period.
fn default_samples() -> usize {
    256
}
/// Default most periods of the contact march.
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

/// Default of `[effects].liftoff`: contacts may separate.
fn yes() -> bool {
    true
}

/// Frequency range and continuation settings.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysisSpec {
    /// Start frequency (Hz). Required for a forced response; optional for a nonlinear mode
    /// (`kind = "nonlinear-modes"`), where it only sets the range of the linear references
    /// and defaults to half the chosen mode's linear frequency (contacts stuck).
    #[serde(default)]
    pub freq_start_hz: Option<f64>,
    /// End frequency (Hz). Required for a forced response; optional for a nonlinear mode,
    /// where it defaults to 1.5 times the chosen mode's linear frequency (contacts stuck).
    #[serde(default)]
    pub freq_end_hz: Option<f64>,
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
    /// Hill stability (Floquet exponents) of every converged point; default off.
    #[serde(default)]
    pub stability: bool,
    /// Which method gives the stability verdict: `hill` (default), `monodromy` or
    /// `hill+monodromy`; needs `stability = true`.
    #[serde(default)]
    pub stability_method: Option<crate::model::StabilityMethod>,
    /// Newmark steps per period of the monodromy's time integration (default 256·H).
    #[serde(default)]
    pub monodromy_steps_per_period: Option<usize>,
    /// How Hill's eigenvalue problem is solved: `auto` (default: dense up to 600 unknowns,
    /// sparse shift-invert above), `dense` or `shift-invert`; needs `stability = true`.
    #[serde(default)]
    pub hill_solver: Option<crate::model::HillSolve>,
    /// Highest frequency (Hz) of the exponents the shift-invert Hill solve must find; default:
    /// every mode of the model. Applies to the shift-invert solve only.
    #[serde(default)]
    pub hill_max_freq_hz: Option<f64>,
    /// What is computed: `"frf"` (default, the forced response over the range) or
    /// `"nonlinear-modes"` (a nonlinear mode by EPMC, `docs/src/nonlinear-modes.md`).
    #[serde(default, skip_serializing_if = "AnalysisKind::is_frf")]
    pub kind: AnalysisKind,
    /// Nonlinear modes: the mode's number among the elastic modes at rest (1-based).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<usize>,
    /// Nonlinear modes: the mode nearest this frequency (Hz), in place of `mode`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode_freq_hz: Option<f64>,
    /// Nonlinear modes: the DOF that fixes the phase and at which the amplitude range is given;
    /// default the first output DOF.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof: Option<String>,
    /// Nonlinear modes: the first-harmonic amplitude range [low, high] at `dof` (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<[f64; 2]>,
}

/// What an analysis computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AnalysisKind {
    /// The forced response over the frequency range.
    #[default]
    Frf,
    /// A nonlinear mode by EPMC.
    NonlinearModes,
}

impl AnalysisKind {
    /// Whether this is the default (then left out of the canonical scene).
    pub fn is_frf(&self) -> bool {
        *self == AnalysisKind::Frf
    }
}

/// Default most continuation points.
fn default_max_points() -> usize {
    5000
}
/// Default Newton iterations aimed at per step.
fn default_target_iterations() -> usize {
    4
}
/// Default Newton iterations before a step is cut.
fn default_max_iterations() -> usize {
    12
}
/// Default relative residual tolerance (to the load norm).
fn default_residual_tolerance() -> f64 {
    1e-10
}
/// Default scaled step tolerance.
fn default_step_tolerance() -> f64 {
    1e-8
}
/// Default points of the linear references' frequency grid.
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

/// The `[accuracy]` table: the a-posteriori error estimate of every converged point
/// (truncation of the harmonic set and AFT sampling, see `crate::analysis::error_estimate`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccuracySpec {
    /// Whether the estimate is computed (default true).
    #[serde(default = "yes")]
    pub estimate: bool,
    /// Relative error of a first-harmonic amplitude above which a run warns (default 0.01).
    #[serde(default = "default_warn_threshold")]
    pub threshold: f64,
    /// What a point whose one-step estimate leaves its linear range gets: `"solve"` (default,
    /// the extended system solved to convergence there) or `"flag"` (not solved, flagged as
    /// not sized).
    #[serde(default)]
    pub beyond_linear_range: BeyondLinearRange,
}

impl Default for AccuracySpec {
    fn default() -> Self {
        Self {
            estimate: true,
            threshold: default_warn_threshold(),
            beyond_linear_range: BeyondLinearRange::default(),
        }
    }
}

impl AccuracySpec {
    /// Whether the table holds its defaults (then it is left out of the canonical scene, so
    /// the scene hash of a scene without it does not change).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// Default of `[accuracy].threshold`: 1 %.
fn default_warn_threshold() -> f64 {
    0.01
}
