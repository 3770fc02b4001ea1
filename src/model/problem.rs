//! The checked problem: linear structure, contacts, loads, effects and analysis settings.
//!
//! A [`Problem`] is what a validated scene becomes (see [`crate::scene`]); the solver never
//! sees unchecked input. Units are SI throughout: masses in kg, stiffness in N/m, damping in
//! N·s/m, forces in N, displacements in m; frequencies are in Hz in [`Analysis`] and converted
//! to ω (rad/s) by the solver.

use crate::contact::aft::MarchSettings;
use crate::contact::harmonic::HarmonicSet;
use crate::contact::{ContactEffects, ContactPoint, DamperSide};
use crate::model::matrix::StructuralMatrix;
use crate::numerics::ContinuationSettings;

/// Linear structure: dense for lumped or reduced models, sparse for unreduced FE models.
#[derive(Debug, Clone)]
pub struct LinearModel {
    /// DOF names, in matrix order.
    pub dof_names: Vec<String>,
    /// Mass matrix M (kg), symmetric positive semi-definite.
    pub mass: StructuralMatrix,
    /// Viscous damping matrix C (N·s/m).
    pub damping: StructuralMatrix,
    /// Stiffness matrix K (N/m), symmetric positive semi-definite (free bodies allowed).
    pub stiffness: StructuralMatrix,
}

impl LinearModel {
    /// Number of DOFs.
    pub fn n_dofs(&self) -> usize {
        self.dof_names.len()
    }

    /// Index of a DOF by name.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dof_names.iter().position(|d| d == name)
    }
}

/// A harmonic force on one DOF: F(τ) = cos·cos(hτ) + sin·sin(hτ) (N).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicLoad {
    /// DOF index.
    pub dof: usize,
    /// Harmonic number h ≥ 1.
    pub harmonic: usize,
    /// Cosine amplitude (N).
    pub cos: f64,
    /// Sine amplitude (N).
    pub sin: f64,
}

/// Whether statics and dynamics are solved together.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Coupling {
    /// The 0th harmonic is an unknown of the harmonic balance (paper Eq. 3, coupled approach).
    #[default]
    Coupled,
    /// A static pre-solve fixes the 0th harmonic; only h ≥ 1 are solved dynamically.
    Uncoupled,
}

/// Effects switched on by the scene. An effect that is off adds no unknowns and no work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effects {
    /// Contact-law effects (normal-load model, lift-off).
    pub contact: ContactEffects,
    /// Static/dynamic coupling through the 0th harmonic.
    pub coupling: Coupling,
}

/// How the Jacobian of the harmonic-balance residual is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum JacobianStrategy {
    /// Chain rule through the contact march (default).
    #[default]
    Analytic,
    /// Forward finite differences (one residual per unknown).
    ForwardDifference,
    /// Central finite differences (two residuals per unknown).
    CentralDifference,
}

/// How the harmonic-balance equations are stored and solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Formulation {
    /// Dense for small models, sparse for large or sparse ones, condensed for dense models
    /// whose contact DOFs are few compared with the rest (see [`Problem::formulation`]).
    #[default]
    Auto,
    /// All DOFs, dense Jacobian (dense LU).
    Dense,
    /// All DOFs, sparse Jacobian (sparse LU, symbolic factorisation once per scene).
    Sparse,
    /// Contact DOFs only: the linear DOFs are eliminated per harmonic (dynamic Schur
    /// complement), dense Jacobian on the contact DOFs.
    Condensed,
    /// All DOFs in the residual; each linear solve eliminates everything but the relative
    /// contact coordinates (two per contact point) per harmonic, and factorises a dense
    /// matrix on those only ([`crate::hbm::schur`]). For dense (lumped or reduced) models.
    Schur,
    /// The schur formulation with its reduced matrix factorised by structure
    /// ([`crate::hbm::schur::lowrank`]): one LU per harmonic of the linear part with each contact's
    /// mean stiffness, and a low-rank update for the contacts whose Jacobian couples harmonics
    /// (those that slip or lift off); a dense LU where that update would cost more. For many
    /// contact points.
    #[serde(rename = "schur-lowrank")]
    SchurLowRank,
}

/// Which method gives each converged point its stability verdict (scene field
/// `analysis.stability_method`; see [`crate::analysis::stability`] and
/// [`crate::analysis::monodromy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
pub enum StabilityMethod {
    /// Hill's method on every point (default): the harmonic-balance Jacobian's quadratic
    /// eigenproblem. Exact on points where every contact is stuck, open or frictionless, a
    /// warning only on stick-slip points (flagged `stability_reliable = false`).
    #[default]
    #[serde(rename = "hill")]
    Hill,
    /// The monodromy matrix of the time integration's periodic orbit (shooting from the
    /// harmonic-balance point) on every point: linearises the non-smooth Jenkins dynamics.
    #[serde(rename = "monodromy")]
    Monodromy,
    /// Hill on every point, and the monodromy on the points where Hill is not reliable (some
    /// contact with friction slips or separates for part of the period); the monodromy's
    /// verdict replaces Hill's there.
    #[serde(rename = "hill+monodromy")]
    HillMonodromy,
}

impl StabilityMethod {
    /// The scene's spelling.
    pub fn label(self) -> &'static str {
        match self {
            StabilityMethod::Hill => "hill",
            StabilityMethod::Monodromy => "monodromy",
            StabilityMethod::HillMonodromy => "hill+monodromy",
        }
    }

    /// Whether Hill's eigen solve runs (on every point, or as the first pass).
    pub fn uses_hill(self) -> bool {
        matches!(self, StabilityMethod::Hill | StabilityMethod::HillMonodromy)
    }

    /// Whether the monodromy may run on some point.
    pub fn uses_monodromy(self) -> bool {
        matches!(
            self,
            StabilityMethod::Monodromy | StabilityMethod::HillMonodromy
        )
    }
}

/// How Hill's eigenvalue problem is solved (scene field `analysis.hill_solver`; see
/// [`crate::analysis::stability`] and [`crate::analysis::stability_sparse`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
pub enum HillSolve {
    /// The dense solve of the whole spectrum up to
    /// [`crate::analysis::stability::MAX_HILL_UNKNOWNS`] unknowns, the sparse shift-invert
    /// solve above it (default).
    #[default]
    #[serde(rename = "auto")]
    Auto,
    /// The dense solve of the whole spectrum (refused above the limit).
    #[serde(rename = "dense")]
    Dense,
    /// The sparse shift-invert solve at every size.
    #[serde(rename = "shift-invert")]
    ShiftInvert,
}

/// Settings of a frequency-response analysis: the continuation over the range (frequencies in
/// Hz; arc-length steps in the scaled space where a unit of frequency is 1 Hz, see
/// [`crate::numerics::continuation`]) and how the harmonic balance is formed and stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Analysis {
    /// Range, steps, point budget and Newton tolerances of the continuation.
    pub continuation: ContinuationSettings,
    /// Jacobian strategy.
    pub jacobian: JacobianStrategy,
    /// Storage and elimination of the harmonic-balance equations.
    pub formulation: Formulation,
    /// Points of the uniform frequency grid of the linear references.
    pub linear_points: usize,
    /// Hill stability of every converged point ([`crate::analysis::stability`]); off costs
    /// nothing.
    pub stability: bool,
    /// Which method gives the verdict when `stability` is on.
    pub stability_method: StabilityMethod,
    /// Newmark steps per period of the monodromy's time integration (0: 256·H, the default of
    /// `fricbound verify`).
    pub monodromy_steps_per_period: usize,
    /// How Hill's eigenvalue problem is solved when Hill's method runs.
    pub hill_solver: HillSolve,
    /// Highest frequency (Hz) of the exponents the shift-invert Hill solve must cover (`None`:
    /// every mode of the model); exponents above it are not sought and the verdict says
    /// nothing about them.
    pub hill_max_freq_hz: Option<f64>,
    /// The a-posteriori error estimate on every converged point (scene table `[accuracy]`).
    pub error_estimate: ErrorEstimateSettings,
    /// A nonlinear-mode analysis (`analysis.kind = "nonlinear-modes"`) in place of the FRF;
    /// None: the FRF over the range.
    pub nonlinear_modes: Option<ModeAnalysis>,
}

/// Which linear mode of the structure at rest a nonlinear mode continues.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum ModeChoice {
    /// The k-th elastic mode (1-based, ascending frequency).
    Number(usize),
    /// The elastic mode whose frequency is nearest this one (Hz).
    NearestHz(f64),
}

/// What a nonlinear-mode analysis asks (scene fields `analysis.mode` or
/// `analysis.mode_freq_hz`, `analysis.dof`, `analysis.amplitude`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeAnalysis {
    /// The mode.
    pub mode: ModeChoice,
    /// DOF whose first-harmonic sine is fixed at zero and at which the range is given.
    pub dof: usize,
    /// First-harmonic amplitude range at `dof` (m), low to high.
    pub amplitude: [f64; 2],
}

/// Settings of the a-posteriori error estimate computed on every converged continuation point
/// (`crate::analysis::error_estimate`): whether it runs, and the relative amplitude error above
/// which a run warns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimateSettings {
    /// Whether the estimate is computed (off: no extra work and no extra columns).
    pub enabled: bool,
    /// Relative first-harmonic amplitude error above which the run warns (default 0.01).
    pub warn_threshold: f64,
    /// What a point whose one-step estimate leaves its linear range gets (scene field
    /// `accuracy.beyond_linear_range`).
    pub beyond_linear_range: BeyondLinearRange,
}

impl Default for ErrorEstimateSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            warn_threshold: 0.01,
            beyond_linear_range: BeyondLinearRange::Auto,
        }
    }
}

/// What the error estimate does at a point whose one Newton step on the extended harmonic set
/// leaves the range where its linearisation holds (its residual contraction above 5 %,
/// `crate::analysis::error_estimate::LinearRange`): the step's value is then no size of the
/// error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BeyondLinearRange {
    /// [`Self::Solve`] on an extended set where the cost model (`crate::hbm::cost`) estimates
    /// a solve at the iteration limit at most
    /// `crate::analysis::error_estimate::SolveBudget::SOLVE_RUN_POINTS` points of the run,
    /// [`Self::Flag`] on a costlier one; and the wider set (4H + 3) stepped on only where a
    /// point's two steps are estimated at most `SolveBudget::STEP_RUN_POINTS` (see
    /// `SolveBudget`).
    #[default]
    Auto,
    /// Solve the extended system to convergence at the point (at its frequency, or across the
    /// path next to a fold) and report that change; where the solve fails the point is not
    /// sizeable. Costs Newton solves of the extended system at those points (on the larger
    /// blade pair at H = 1, next to its small folds, most of the estimate's time).
    Solve,
    /// Do not solve: flag the point as not sized (`unsolved`) and warn, at the cost of the
    /// step alone.
    Flag,
}

/// Default of [`ContinuationSettings::chord_min_unknowns`].
pub const CHORD_MIN_UNKNOWNS: usize = 1500;

/// A checked problem, ready to solve.
#[derive(Debug, Clone)]
pub struct Problem {
    /// Linear structure.
    pub model: LinearModel,
    /// Contact points.
    pub contacts: Vec<ContactPoint>,
    /// Damper sides grouping the contact points.
    pub sides: Vec<DamperSide>,
    /// Static loads per DOF (N), length n_dofs.
    pub static_load: Vec<f64>,
    /// Harmonic loads.
    pub harmonic_loads: Vec<HarmonicLoad>,
    /// Dynamic harmonics h ≥ 1 balanced (the 0th is added by the coupling effect).
    pub harmonics: Vec<usize>,
    /// AFT time samples per period.
    pub samples: usize,
    /// Switched effects.
    pub effects: Effects,
    /// March limits of the AFT.
    pub march: MarchSettings,
    /// Analysis settings.
    pub analysis: Analysis,
    /// DOF indices reported in outputs.
    pub outputs: Vec<usize>,
    /// The FE mesh the problem comes from, for results on the mesh (None for lumped models
    /// and Matrix Market input).
    pub fe: Option<std::sync::Arc<FeOrigin>>,
}

/// The FE mesh of a problem and the map from the problem's coordinates to its nodes.
#[derive(Debug)]
pub struct FeOrigin {
    /// The mesh.
    pub mesh: crate::fe::Mesh,
    /// DOF (node, direction) of each row of the full FE model.
    pub dofs: crate::fe::DofMap,
    /// For a reduced problem, row d holds the full-model displacement of DOF d per reduced
    /// coordinate (the Craig-Bampton basis T); None when the problem is the full model, or when
    /// the basis would be too large to keep (then results on the mesh are not written).
    pub recovery: Option<Vec<Vec<f64>>>,
    /// Whether the problem is reduced.
    pub reduced: bool,
}

impl FeOrigin {
    /// Full-model values of DOF rows from problem coordinates `q` (one block of coefficients);
    /// None when a reduced problem has no recovery basis.
    pub fn full_values(&self, q: &[f64]) -> Option<Vec<f64>> {
        match (&self.recovery, self.reduced) {
            (_, false) => Some(q.to_vec()),
            (Some(rows), true) => Some(
                rows.iter()
                    .map(|r| r.iter().zip(q).map(|(a, b)| a * b).sum())
                    .collect(),
            ),
            (None, true) => None,
        }
    }
}

impl Problem {
    /// The harmonic set of the unknowns: the dynamic harmonics, plus 0 when coupled.
    pub fn unknown_harmonics(&self) -> HarmonicSet {
        let mut h = self.harmonics.clone();
        if self.effects.coupling == Coupling::Coupled {
            h.push(0);
        }
        HarmonicSet::new(h)
    }

    /// The harmonic set used by the AFT (always includes the 0th harmonic).
    pub fn force_harmonics(&self) -> HarmonicSet {
        let mut h = self.harmonics.clone();
        h.push(0);
        HarmonicSet::new(h)
    }

    /// For each contact point, whether each of its rows ([`ContactPoint::rows`]: tangential,
    /// second tangential of a 2D point, normal) is non-zero. A row whose coefficients are all
    /// zero (a contact to ground with a zero normal direction, whose normal load is constant:
    /// N = kn·gap) moves with no DOF; the schur formulation gives such a contact its non-zero
    /// coordinates only.
    pub fn nonzero_contact_rows(&self) -> Vec<Vec<bool>> {
        let nonzero = |row: &[(usize, f64)]| row.iter().any(|&(_, a)| a != 0.0);
        self.contacts
            .iter()
            .map(|c| c.rows().map(nonzero).collect())
            .collect()
    }

    /// Number of relative contact coordinates: the non-zero rows of the contact points
    /// ([`Self::nonzero_contact_rows`]), 2 per 1D point and 3 per 2D point unless a row is zero.
    pub fn relative_coordinate_count(&self) -> usize {
        self.nonzero_contact_rows()
            .iter()
            .map(|r| r.iter().filter(|&&a| a).count())
            .sum()
    }

    /// DOFs touched by some contact (sorted, unique): the nonlinear DOFs.
    pub fn contact_dofs(&self) -> Vec<usize> {
        let mut dofs: Vec<usize> = self
            .contacts
            .iter()
            .flat_map(|c| c.row_entries().map(|&(d, _)| d))
            .collect();
        dofs.sort_unstable();
        dofs.dedup();
        dofs
    }

    /// The DOFs split into the contact DOFs and the others (the linear DOFs), with each DOF's
    /// index among the contact DOFs: the partition that the condensed and schur formulations
    /// eliminate along.
    pub fn dof_split(&self) -> DofSplit {
        let n = self.model.n_dofs();
        let contact = self.contact_dofs();
        let mut local = vec![None; n];
        for (i, &d) in contact.iter().enumerate() {
            local[d] = Some(i);
        }
        let linear = (0..n).filter(|&d| local[d].is_none()).collect();
        DofSplit {
            contact,
            linear,
            local,
        }
    }
}

/// The DOFs of a problem split by [`Problem::dof_split`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DofSplit {
    /// DOFs touched by some contact (sorted, unique).
    pub contact: Vec<usize>,
    /// All other DOFs (sorted).
    pub linear: Vec<usize>,
    /// Per DOF, its index in `contact` (None for a linear DOF).
    pub local: Vec<Option<usize>>,
}
