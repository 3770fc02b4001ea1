//! The scaling study: what FE size, contact count, harmonic count and solver strategy cost.
//!
//! Every case is the blade-pair model of `meshes/blade-pair/` made by the generator at a given
//! refinement (2D quadrangles or 3D hexahedra): assembled, clamped, its contact patches paired,
//! reduced by Craig-Bampton, and solved by continuation over a frequency window around the
//! first bending pair. Nothing is synthetic: the contact count per side grows with the
//! refinement of the contact faces (3·refine·contact_refine + 1 pairs per side in 2D), or is
//! set directly (`contact_pairs`, for the 2-pair end of the ladder).
//!
//! The solver configurations ([`SolverConfig`]: harmonics, formulation, Jacobian strategy,
//! limit case) and the timed iteration ([`NewtonIteration`]) are shared by the study and the
//! criterion bench `hbm_formulations`.
//!
//! Two measurements:
//! - [`measure_reduction`]: mesh generation, assembly and clamping, then Craig-Bampton, with
//!   the reduction's own report (phase times, factor size, peak resident memory). Peak memory
//!   is a per-process figure, so the command runs each size in its own process.
//! - [`measure_solve`]: one Newton iteration (residual, Jacobian, linear solve) of a reduced
//!   (or unreduced) problem with a given formulation and Jacobian strategy, and where that is
//!   affordable an FRF over the window limited to a number of continuation points: wall time
//!   per point and per Newton iteration (FRF time over its Newton iterations, tangent solves
//!   included).

use std::path::Path;
use std::time::Instant;

use crate::analysis::frf;
use crate::fe::blade_pair::{self, BladePairParams};
use crate::fe::msh_write::{write_msh, MshFormat};
use crate::hbm::operator::HbmOperator;
use crate::model::reduce::{self, ReductionSettings};
use crate::model::{Formulation, JacobianStrategy, Problem};
use crate::numerics::ParametricResidual;
use crate::scene;

/// Errors of a scaling case.
#[derive(Debug, thiserror::Error)]
pub enum ScalingError {
    /// The generator, a file or the scene failed.
    #[error("{0}")]
    Setup(String),
}

fn setup<E: std::fmt::Display>(e: E) -> ScalingError {
    ScalingError::Setup(e.to_string())
}

/// One blade-pair model size.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ModelSize {
    /// 3D hexahedra (else 2D quadrangles).
    pub three_d: bool,
    /// Generator refinement.
    pub refine: usize,
    /// Extra refinement of the contact faces and the damper.
    pub contact_refine: usize,
    /// Contact pairs per side set directly (see [`BladePairParams::contact_pairs`]).
    pub contact_pairs: Option<usize>,
}

impl ModelSize {
    /// A model of the generator's uniform refinement `refine`.
    pub fn uniform(three_d: bool, refine: usize) -> Self {
        Self {
            three_d,
            refine,
            contact_refine: 1,
            contact_pairs: None,
        }
    }

    /// Short label: `2D r2`, `2D r2 c8` (contact refinement), `2D r2 p2` (contact pairs),
    /// `3D r1`.
    pub fn label(&self) -> String {
        let dim = if self.three_d { "3D" } else { "2D" };
        if let Some(pairs) = self.contact_pairs {
            format!("{dim} r{} p{pairs}", self.refine)
        } else if self.contact_refine > 1 {
            format!("{dim} r{} c{}", self.refine, self.contact_refine)
        } else {
            format!("{dim} r{}", self.refine)
        }
    }

    fn params(&self) -> BladePairParams {
        BladePairParams {
            refine: self.refine,
            contact_refine: self.contact_refine,
            contact_pairs: self.contact_pairs,
            three_d: self.three_d,
            ..Default::default()
        }
    }
}

/// The blade-pair scene text for a mesh file (the physics of `meshes/blade-pair/`).
///
/// `mesh_file` is written into the scene's `model.mesh` as given, and a scene resolves a
/// relative path against its own folder (docs/scene.md): pass the mesh's path relative to
/// the folder the scene is labelled in (its file name when both share a folder) or an
/// absolute path, never a path relative to the working folder.
pub fn blade_pair_scene(mesh_file: &Path, three_d: bool, harmonics: usize) -> String {
    let thickness = if three_d { "" } else { "thickness = 0.01\n" };
    let tangents = if three_d {
        (
            "tangent = [0.8660254037844387, 0.5, 0.0]\n",
            "tangent = [0.8660254037844387, -0.5, 0.0]\n",
        )
    } else {
        ("", "")
    };
    let materials: String = ["blade1", "blade2", "damper"]
        .iter()
        .map(|g| {
            format!(
                "[[model.materials]]\ngroup = \"{g}\"\nyoung = 2.1e11\npoisson = 0.3\ndensity = 7850.0\n{thickness}\n"
            )
        })
        .collect();
    let patch = |side: &str, tangent: &str| {
        format!(
            "[[contact_patches]]\nside = \"{side}\"\ndamper = \"damper_{side}\"\nbody = \"platform_{side}\"\n\
             kt = 2.0e7\nkn = 2.0e7\nmu = 0.3\ntolerance = 1e-6\n{tangent}\n"
        )
    };
    format!(
        "title = \"blade pair scaling case\"\n\n[model]\nmesh = \"{}\"\nclamp = [\"clamp\"]\n\n{materials}\
         {}{}\
         [[static_loads]]\ngroup = \"damper\"\ndirection = \"y\"\nvalue = 500.0\n\n\
         [[harmonic_loads]]\ngroup = \"excitation\"\ndirection = \"x\"\nharmonic = 1\ncos = 0.5\n\n\
         [harmonics]\nmax = {harmonics}\nsamples = {}\n\n\
         [analysis]\nfreq_start_hz = 700.0\nfreq_end_hz = 1000.0\nmax_points = 1000\n\n\
         [output]\ngroups = [{{ group = \"response\", direction = \"x\" }}]\n",
        mesh_file.display(),
        patch("left", tangents.0),
        patch("right", tangents.1),
        (32 * harmonics).max(128),
    )
}

/// The unreduced problem of a model size (mesh written into `dir`).
pub fn full_problem(
    size: ModelSize,
    harmonics: usize,
    dir: &Path,
) -> Result<Problem, ScalingError> {
    let params = size.params();
    let mesh = blade_pair::generate(&params).map_err(setup)?;
    let name = format!(
        "blade-pair-{}.msh",
        size.label().replace(' ', "-").to_lowercase()
    );
    let file = dir.join(&name);
    write_msh(&file, &mesh, MshFormat::Binary).map_err(setup)?;
    // The scene is labelled in `dir`, beside the mesh: it names the mesh by its file name,
    // which resolves to `file` whether `dir` is absolute or relative to the working folder.
    let text = blade_pair_scene(Path::new(&name), size.three_d, harmonics);
    let label = dir.join("scaling.toml").display().to_string();
    scene::parse(&text, &label, &[])
        .and_then(|s| s.validate(&label))
        .map_err(setup)
}

/// Scene text of the small reduced 2D blade pair that the FE accuracy tests and examples
/// share: the generator's coarsest mesh with 2 contact pairs per side (its mesh written into
/// `dir` as `blade-pair-2d-r1-p2.msh`), 8 interior Craig-Bampton modes and 0.2 % modal damping,
/// H = 1; its resonance is near 918-934 Hz. Small enough for a test, yet with the folds and
/// stick-slip transitions of an FE damper. The scene names its mesh by file name: it is to be
/// written into (or labelled in) `dir`.
pub fn small_reduced_blade_pair_scene(dir: &Path) -> Result<String, ScalingError> {
    let size = ModelSize {
        contact_pairs: Some(2),
        ..ModelSize::uniform(false, 1)
    };
    // Writes the mesh `blade-pair-2d-r1-p2.msh` into the folder.
    full_problem(size, 1, dir)?;
    let mesh = Path::new("blade-pair-2d-r1-p2.msh");
    Ok(format!(
        "{}\n[reduction]\nmodes = 8\nmodal_damping = 0.002\n",
        blade_pair_scene(mesh, false, 1)
    ))
}

/// Sizes, times and memory of one reduction.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ReductionMeasure {
    /// 3D model.
    pub three_d: bool,
    /// Generator refinement.
    pub refine: usize,
    /// Free DOFs of the FE model (after clamping).
    pub dofs: usize,
    /// Contact pairs per damper side.
    pub pairs_per_side: usize,
    /// Boundary DOFs kept.
    pub boundary: usize,
    /// Fixed-interface modes kept.
    pub modes: usize,
    /// Mesh generation, assembly, clamping, pairing and scene checks (s).
    pub model_s: f64,
    /// Craig-Bampton (s).
    pub reduction_s: f64,
    /// Of which the interior Cholesky factorisation, symbolic and numeric (s).
    pub factor_s: f64,
    /// Of which the fixed-interface eigen solve (s).
    pub eigen_s: f64,
    /// Of which the constraint modes and reduced matrices (s).
    pub constraint_s: f64,
    /// Stored entries of the Cholesky factor.
    pub factor_entries: usize,
    /// Peak resident memory of the process (bytes), where known.
    pub peak_memory_bytes: Option<u64>,
    /// The reduction's full report (phase and sub-phase times, CPU seconds, solver counts).
    #[serde(default)]
    pub report: String,
}

/// Builds and reduces one model size, with `modes` fixed-interface modes: mesh generation,
/// assembly with steel for every body, clamping of the roots and pairing of the contact
/// patches, then Craig-Bampton with the contact DOFs and the response node as boundary. (The
/// FE model is reduced directly, without a scene: the 3D model's damper has no contact
/// stiffness out of the plane, where the 1D friction law acts, so it is a measure of the
/// reduction, not a friction problem.)
pub fn measure_reduction(size: ModelSize, modes: usize) -> Result<ReductionMeasure, ScalingError> {
    use crate::fe::{self, Direction, GroupMaterial, Material, PlaneAssumption};
    let started = Instant::now();
    let params = size.params();
    let mesh = blade_pair::generate(&params).map_err(setup)?;
    let materials: Vec<GroupMaterial> = ["blade1", "blade2", "damper"]
        .iter()
        .map(|g| GroupMaterial::new(g, Material::steel(params.thickness)))
        .collect();
    let model = fe::assemble(&mesh, &materials, PlaneAssumption::Stress)
        .and_then(|m| m.clamp_group(&mesh, "clamp"))
        .map_err(setup)?;
    let mut boundary = Vec::new();
    let mut pairs_per_side = 0;
    for spec in params.patch_specs().map_err(setup)? {
        let patch = fe::pair_patch(&mesh, &model.dofs, &spec).map_err(setup)?;
        pairs_per_side = patch.pairs.len();
        for pair in &patch.pairs {
            boundary.extend(pair.damper_dofs.iter().chain(&pair.body_dofs).copied());
        }
    }
    boundary.extend(
        model
            .group_rows(&mesh, "response", Direction::X)
            .map_err(setup)?,
    );
    boundary.sort_unstable();
    boundary.dedup();
    let model_s = started.elapsed().as_secs_f64();
    let mut options = fricbound_reduction::CbOptions::with_modes(modes);
    options.ordering = fricbound_reduction::Ordering::Metis;
    let started = Instant::now();
    let reduced = fricbound_reduction::craig_bampton(
        model.stiffness.as_ref(),
        model.mass.as_ref(),
        &boundary,
        &[],
        &options,
    )
    .map_err(setup)?;
    let reduction_s = started.elapsed().as_secs_f64();
    let report = &reduced.report;
    Ok(ReductionMeasure {
        three_d: size.three_d,
        refine: size.refine,
        dofs: model.dofs.len(),
        pairs_per_side,
        boundary: report.n_boundary,
        modes: report.n_modes,
        model_s,
        reduction_s,
        factor_s: report.t_ordering + report.t_symbolic + report.t_numeric,
        eigen_s: report.t_eigen,
        constraint_s: report.t_constraint,
        factor_entries: report.factor_nnz,
        peak_memory_bytes: fricbound_reduction::peak_memory_bytes(),
        report: report.to_string(),
    })
}

/// The reduced problem of a 2D model size (mesh written into `dir`), with `modes`
/// fixed-interface modes.
pub fn reduced_problem(size: ModelSize, modes: usize, dir: &Path) -> Result<Problem, ScalingError> {
    let full = full_problem(size, 1, dir)?;
    let settings = ReductionSettings {
        modes,
        modal_damping: 0.002,
        rayleigh: (0.0, 0.0),
        ordering: fricbound_reduction::Ordering::Metis,
        recover: Vec::new(),
        boundary: Vec::new(),
    };
    Ok(reduce::reduce(&full, &settings).map_err(setup)?.problem)
}

/// Cost of one solver configuration.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SolveMeasure {
    /// Case label (model, reduced or not).
    pub case: String,
    /// Contact pairs per side.
    pub pairs_per_side: usize,
    /// Harmonics 1..H.
    pub harmonics: usize,
    /// Formulation used.
    pub formulation: String,
    /// Jacobian strategy.
    pub jacobian: String,
    /// Initial tangential state m of every contact point (0, or ±1 for a limit curve).
    pub m: f64,
    /// Unknowns of the operator solved.
    pub unknowns: usize,
    /// Wall time of one Newton iteration at the stuck linear guess at the window's centre
    /// (residual, Jacobian, linear solve; ms).
    pub iteration_ms: f64,
    /// Whether an FRF was run (else only the iteration was timed).
    pub frf: bool,
    /// Most continuation points the FRF was allowed.
    pub max_points: usize,
    /// Continuation points (FRF runs).
    pub points: usize,
    /// Newton iterations (FRF runs).
    pub iterations: usize,
    /// Whether the FRF covered its window within `max_points` (`FrfRun::is_complete`: the end
    /// reached, every stretch on some branch).
    pub complete: bool,
    /// Wall time of the FRF (s; FRF runs).
    pub frf_s: f64,
    /// Wall time per continuation point (ms; FRF runs).
    pub per_point_ms: f64,
    /// Wall time per Newton iteration within the FRF (ms): FRF time over its Newton
    /// iterations, tangent solves included (FRF runs).
    pub frf_iteration_ms: f64,
}

/// Formulations the study and the criterion bench compare.
pub const FORMULATIONS: [Formulation; 5] = [
    Formulation::Dense,
    Formulation::Sparse,
    Formulation::Condensed,
    Formulation::Schur,
    Formulation::SchurLowRank,
];

/// Jacobian strategies the study and the criterion bench compare: the analytic AFT Jacobian
/// and its finite-difference baseline.
pub const JACOBIANS: [JacobianStrategy; 2] = [
    JacobianStrategy::Analytic,
    JacobianStrategy::ForwardDifference,
];

/// One solver configuration: harmonics 1..H (with the 0th), formulation, Jacobian strategy
/// and the initial tangential state m of every contact point (0, or ±1 for a limit curve).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverConfig {
    /// Highest harmonic H.
    pub harmonics: usize,
    /// Formulation.
    pub formulation: Formulation,
    /// Jacobian strategy.
    pub jacobian: JacobianStrategy,
    /// Initial tangential state of every contact point, T(0) = m·μN.
    pub m: f64,
}

impl SolverConfig {
    /// Every formulation × Jacobian strategy of [`FORMULATIONS`] and [`JACOBIANS`] for each H
    /// in `harmonics`, with m = 0, in the order the study runs them.
    pub fn grid(harmonics: &[usize]) -> Vec<SolverConfig> {
        harmonics
            .iter()
            .flat_map(|&h| {
                FORMULATIONS.into_iter().flat_map(move |formulation| {
                    JACOBIANS.into_iter().map(move |jacobian| SolverConfig {
                        harmonics: h,
                        formulation,
                        jacobian,
                        m: 0.0,
                    })
                })
            })
            .collect()
    }

    /// `base` set up for this configuration (harmonics, AFT samples 32·H but at least 128,
    /// formulation, Jacobian, limit case; no error estimate); the one copy of the problem a configuration makes.
    pub fn apply(&self, base: &Problem) -> Problem {
        let mut p = crate::analysis::limits::LimitCase::uniform(base, self.m).apply(base);
        p.harmonics = (1..=self.harmonics).collect();
        p.samples = p.samples.max(32 * self.harmonics).max(128);
        p.analysis.formulation = self.formulation;
        p.analysis.jacobian = self.jacobian;
        // The study times the solver; the error estimate of every point is measured apart.
        p.analysis.error_estimate.enabled = false;
        p
    }

    /// Label `H = 3, schur, analytic` (the formulation as given, `auto` unresolved).
    pub fn label(&self) -> String {
        format!(
            "H = {}, {}, {}",
            self.harmonics,
            formulation_name(self.formulation),
            jacobian_name(self.jacobian)
        )
    }
}

// The unknowns, the factorised size and the formulation names are counted where the
// formulations live (`hbm::cost`, which also estimates memory and time from them); re-exported
// here for the study and its callers.
pub use crate::hbm::cost::{factored_size, formulation_name, unknowns};

/// Label of a Jacobian strategy.
pub fn jacobian_name(j: JacobianStrategy) -> &'static str {
    match j {
        JacobianStrategy::Analytic => "analytic",
        JacobianStrategy::ForwardDifference => "forward-difference",
        JacobianStrategy::CentralDifference => "central-difference",
    }
}

/// One Newton iteration of a problem, ready to repeat: residual, Jacobian and linear solve at
/// the stuck linear guess at one frequency. The study times it once, the criterion bench many
/// times.
pub struct NewtonIteration<'a> {
    operator: HbmOperator<'a>,
    jacobian: crate::numerics::jacobian::AssembledJacobian,
    x: Vec<f64>,
    omega: f64,
    residual: Vec<f64>,
    d_residual: Vec<f64>,
}

impl<'a> NewtonIteration<'a> {
    /// Prepares the iteration of `p` at `freq_hz` (operator, Jacobian storage, linear guess).
    pub fn new(p: &'a Problem, freq_hz: f64) -> Result<Self, ScalingError> {
        let mut operator = HbmOperator::new(p).map_err(setup)?;
        let omega = 2.0 * std::f64::consts::PI * freq_hz;
        let guess =
            crate::analysis::linear::stuck_guess(p, operator.unknowns(), omega).map_err(setup)?;
        let x = operator.restrict(&guess);
        let n = operator.dim();
        Ok(Self {
            jacobian: operator.new_jacobian(),
            operator,
            x,
            omega,
            residual: vec![0.0; n],
            d_residual: vec![0.0; n],
        })
    }

    /// Unknowns of the iteration.
    pub fn unknowns(&self) -> usize {
        self.operator.dim()
    }

    /// Runs the iteration once: residual and Jacobian, then the Newton step (returned).
    pub fn run(&mut self) -> Result<Vec<f64>, ScalingError> {
        self.operator
            .residual_and_jacobian(
                &self.x,
                self.omega,
                &mut self.residual,
                &mut self.jacobian,
                &mut self.d_residual,
            )
            .map_err(setup)?;
        let neg: Vec<f64> = self.residual.iter().map(|v| -v).collect();
        self.jacobian.solve(&neg).map_err(setup)
    }
}

/// Measures `p`, set up by `config` (see [`SolverConfig::apply`]): the time of one Newton
/// iteration at the stuck linear guess at the window's centre, and with `frf` an FRF over the
/// window limited to `p.analysis.continuation.max_points` continuation points.
pub fn measure_solve(
    case: &str,
    p: &Problem,
    config: &SolverConfig,
    frf: bool,
) -> Result<SolveMeasure, ScalingError> {
    let centre =
        0.5 * (p.analysis.continuation.freq_start_hz + p.analysis.continuation.freq_end_hz);
    let mut iteration = NewtonIteration::new(p, centre)?;
    let mut m = SolveMeasure {
        case: case.to_string(),
        pairs_per_side: p.contacts.len() / p.sides.len().max(1),
        harmonics: config.harmonics,
        formulation: formulation_name(p.formulation()).to_string(),
        jacobian: jacobian_name(config.jacobian).to_string(),
        m: config.m,
        unknowns: iteration.unknowns(),
        iteration_ms: 0.0,
        frf,
        max_points: if frf {
            p.analysis.continuation.max_points
        } else {
            0
        },
        points: 0,
        iterations: 0,
        complete: false,
        frf_s: 0.0,
        per_point_ms: 0.0,
        frf_iteration_ms: 0.0,
    };
    let started = Instant::now();
    iteration.run()?;
    m.iteration_ms = 1e3 * started.elapsed().as_secs_f64();
    drop(iteration);
    if frf {
        let started = Instant::now();
        let mut points = Vec::new();
        let outcome = frf::solve(p, &mut Collect(&mut points));
        m.frf_s = started.elapsed().as_secs_f64();
        m.points = points.len();
        m.complete = outcome.as_ref().is_ok_and(|run| run.is_complete());
        m.iterations = points.iter().map(|q| q.newton_iterations).sum();
        m.per_point_ms = 1e3 * m.frf_s / m.points.max(1) as f64;
        m.frf_iteration_ms = 1e3 * m.frf_s / m.iterations.max(1) as f64;
    }
    Ok(m)
}

/// Collects FRF points (also when the run fails part-way).
struct Collect<'a>(&'a mut Vec<frf::FrfPoint>);

impl frf::FrfObserver for Collect<'_> {
    fn point(&mut self, point: &frf::FrfPoint) {
        self.0.push(point.clone());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A work folder given relative to the working folder (as `out/…` is by default): the
    /// generated scene still finds its mesh, as it names the mesh relative to its own folder.
    #[test]
    fn a_relative_work_folder_finds_its_mesh() {
        let tmp = tempfile::tempdir().unwrap();
        let cwd = std::env::current_dir().unwrap();
        // The same folder as a relative path: up to the root, then down to it.
        let mut relative = PathBuf::new();
        for _ in cwd.components().skip(1) {
            relative.push("..");
        }
        relative.push(tmp.path().strip_prefix("/").unwrap());
        assert!(relative.is_relative());
        for sub in ["work", "small"] {
            std::fs::create_dir_all(relative.join(sub)).unwrap();
        }
        let size = ModelSize {
            contact_pairs: Some(2),
            ..ModelSize::uniform(false, 1)
        };
        let problem = full_problem(size, 1, &relative.join("work"));
        assert!(problem.is_ok(), "{}", problem.unwrap_err());
        let text = small_reduced_blade_pair_scene(&relative.join("small")).unwrap();
        let label = relative.join("small/blade-pair.toml").display().to_string();
        let scene = scene::parse(&text, &label, &[]).unwrap();
        assert!(scene.validate(&label).is_ok());
    }
}
