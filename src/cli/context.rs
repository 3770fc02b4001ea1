//! What the commands share, below them all: [`CommandError`] (why a command failed) and the
//! exit codes, the options and report of `fricbound run` ([`RunOptions`], [`RunReport`],
//! [`RunOutcome`]), the [`RunContext`] each kind of run works in, loading a scene
//! ([`load_scene`], [`scene_hash`]), the output folder ([`default_out_dir`], [`create_dir`]),
//! figure titles ([`figure_title`]), the linear references every run writes, and the summary
//! of a run ([`run_summary`]). It uses only the library's layers below `cli`, never a command.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use sha2::{Digest, Sha256};

use crate::analysis::frf::{self, FrfError};
use crate::analysis::limits::LimitSettings;
use crate::analysis::linear::{self, LinearCase};
use crate::model::Problem;
use crate::report::files::{self, RunInfo, WriteError};
use crate::report::plot::PlotError;
use crate::scene::{self, Scene, SceneError};

/// Errors of a command, each naming what failed.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// The scene is unreadable or invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Results on the mesh could not be written.
    #[error(transparent)]
    Vtu(#[from] crate::fe::VtuError),
    /// The stuck-contact modes on the mesh could not be computed or written.
    #[error(transparent)]
    Modes(#[from] crate::report::mesh_modes::MeshModesError),
    /// A result file could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// A figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// Natural frequencies could not be computed.
    #[error(transparent)]
    Eigen(#[from] crate::analysis::modes::ModesError),
    /// The output folder could not be created.
    #[error("{path}: cannot create output folder: {source}")]
    OutputDir {
        /// Folder.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// The solve failed; the points finished before are on disk.
    #[error("{scene}: {source} ({points} converged points kept in {dir})")]
    Solve {
        /// Scene label.
        scene: String,
        /// Cause.
        source: FrfError,
        /// Points written before the failure.
        points: usize,
        /// Output folder.
        dir: String,
    },
    /// A limit analysis failed.
    #[error("{scene}: {source}")]
    Limits {
        /// Scene label.
        scene: String,
        /// Cause.
        source: crate::analysis::limits::LimitError,
    },
    /// A sweep failed.
    #[error("{scene}: {source}")]
    Sweep {
        /// Scene label.
        scene: String,
        /// Cause (boxed: a scene error is large).
        source: Box<crate::study::sweep::SweepError>,
    },
    /// Figures of `fricbound paper` failed; the others' results and the summary are written.
    #[error("paper study: figure(s) {failed} failed (see {dir}/summary.md)")]
    Paper {
        /// Identifiers of the failed figures.
        failed: String,
        /// Output folder.
        dir: String,
    },
    /// The problem is estimated to need more memory than the machine has available; refused
    /// before anything was created or written.
    #[error("{scene}: {reason}")]
    TooLarge {
        /// Scene label.
        scene: String,
        /// The estimate, the memory available and the fields to lower.
        reason: String,
    },
    /// A study could not be carried out (its reference did not solve).
    #[error("{scene}: {reason}")]
    Study {
        /// Scene label.
        scene: String,
        /// What failed.
        reason: String,
    },
    /// A nonlinear mode could not be computed.
    #[error("{scene}: {source}")]
    NonlinearMode {
        /// Scene label.
        scene: String,
        /// Cause.
        source: crate::analysis::nonlinear_modes::NonlinearModeError,
    },
    /// A linear reference failed.
    #[error("{scene}: linear reference: {reason}")]
    Linear {
        /// Scene label.
        scene: String,
        /// Cause.
        reason: String,
    },
}

/// Exit code of a run that covered what the scene asks for (and of every other command that
/// succeeded).
pub const EXIT_COMPLETE: u8 = 0;
/// Exit code of an error: bad input, a failed solve, an I/O error, a problem too large for the
/// machine. (clap exits with 2 on usage errors.)
pub const EXIT_ERROR: u8 = 1;
/// Exit code of a run that ran and wrote its results but did not cover the range or every case
/// ([`RunReport::incomplete`]).
pub const EXIT_INCOMPLETE: u8 = 3;

/// Options of `fricbound run`.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Scene file; `None` runs the built-in paper scene.
    pub scene: Option<PathBuf>,
    /// Scene text to solve instead of reading `scene` (which then only names it in messages
    /// and gives the default output folder).
    pub scene_text: Option<String>,
    /// Output folder; default `out/<scene stem>`, or `out/<scene stem>-<hash>` with overrides
    /// (see [`default_out_dir`]).
    pub out: Option<PathBuf>,
    /// `FIELD=VALUE` overrides.
    pub overrides: Vec<String>,
    /// No progress bar and no per-step messages.
    pub quiet: bool,
}

/// What `run` produced.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Output folder.
    pub dir: PathBuf,
    /// What was computed, in a few lines.
    pub summary: String,
    /// Why the run did not cover what the scene asks for (the FRF did not reach the end
    /// frequency; a limit curve or sweep case failed or is incomplete), `None` when it did. The
    /// same text follows `incomplete: ` in the status of the run's JSON file; the binary prints
    /// it on stderr and exits with [`EXIT_INCOMPLETE`].
    pub incomplete: Option<String>,
    /// The results themselves.
    pub outcome: RunOutcome,
    /// Linear reference with contacts open.
    pub open: linear::LinearCurve,
    /// Linear reference with contacts stuck.
    pub stuck: linear::LinearCurve,
}

/// The results of a run, by kind.
#[derive(Debug, Clone)]
pub enum RunOutcome {
    /// One nonlinear FRF.
    Frf(Box<frf::FrfRun>),
    /// A limit analysis.
    Limits(Box<crate::analysis::limits::LimitAnalysis>),
    /// A parameter sweep, points in [`crate::study::sweep::sweep_points`] order.
    Sweep(Vec<crate::study::sweep::SweepPoint>),
    /// Nonlinear modes: the scene's (one case named `scene`), or one per limit case with their
    /// band.
    NonlinearModes(Box<crate::analysis::nonlinear_modes::ModeLimits>),
}

/// Everything a run kind needs: the scene, the checked problem, the output folder and the
/// linear references.
pub struct RunContext<'a> {
    /// Scene label (file name or the built-in default).
    pub label: String,
    /// Title of the figures: the scene's title (or its label) with the overrides it was
    /// solved with, see [`figure_title`].
    pub title: String,
    /// The scene as solved (after overrides).
    pub scene: Scene,
    /// The checked problem.
    pub problem: Problem,
    /// The limit analysis the scene asks for, if any.
    pub limits: Option<LimitSettings>,
    /// Output folder.
    pub dir: PathBuf,
    /// Linear reference with contacts open.
    pub open: linear::LinearCurve,
    /// Linear reference with contacts stuck.
    pub stuck: linear::LinearCurve,
    /// Command-line options.
    pub options: &'a RunOptions,
    /// Scene text as read (before overrides), for sweeps that re-apply overrides per value.
    pub scene_text: String,
}

impl RunContext<'_> {
    /// Title for figures (see [`figure_title`]).
    pub fn title(&self) -> &str {
        &self.title
    }

    /// Run info for JSON files.
    pub fn info(&self) -> RunInfo {
        let problem = &self.problem;
        RunInfo {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: self.label.clone(),
            scene_hash: scene_hash(&self.scene),
            dofs: problem.model.dof_names.clone(),
            blocks: problem.unknown_harmonics().block_labels(),
            contacts: problem.contacts.iter().map(|c| c.name.clone()).collect(),
            outputs: problem
                .outputs
                .iter()
                .map(|&d| problem.model.dof_names[d].clone())
                .collect(),
        }
    }

    /// Progress bar unless quiet.
    pub fn progress(&self, len: u64) -> Option<ProgressBar> {
        if self.options.quiet {
            return None;
        }
        let bar = ProgressBar::new(len);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}",
            )
            .expect("static template"),
        );
        Some(bar)
    }
}

/// A scene loaded and checked: its label, the scene, the problem and the limit analysis it
/// asks for.
pub type LoadedScene = (String, Scene, Problem, Option<LimitSettings>);

/// Loads the scene named by `path` (or the built-in default) with overrides.
pub fn load_scene(path: Option<&Path>, overrides: &[String]) -> Result<LoadedScene, SceneError> {
    let (label, scene) = match path {
        Some(p) => (p.display().to_string(), scene::load(p, overrides)?),
        None => {
            let label = scene::default_scene_label().display().to_string();
            let scene = scene::parse(scene::PAPER_DEFAULT_SCENE, &label, overrides)?;
            (label, scene)
        }
    };
    let (problem, limits) = scene.validate_with_limits(&label)?;
    Ok((label, scene, problem, limits))
}

/// SHA-256 of the scene's canonical TOML, hex.
pub fn scene_hash(scene: &Scene) -> String {
    let canonical = toml::to_string(scene).unwrap_or_default();
    let digest = Sha256::digest(canonical.as_bytes());
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Hex digits of the overrides' hash in a default output folder's name.
const OVERRIDES_HASH_DIGITS: usize = 8;

/// The default output folder of a run: `out/<scene stem>` (`out/paper-wedge` for the built-in
/// scene), and with `--set` overrides `out/<scene stem>-<hash>`, the hash being the first
/// [`OVERRIDES_HASH_DIGITS`] hex digits of the SHA-256 of the overrides joined by newlines, so
/// that variants of a scene do not overwrite each other's results (nor the scene's own).
pub fn default_out_dir(scene: Option<&Path>, overrides: &[String]) -> PathBuf {
    let stem = scene
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "paper-wedge".to_string());
    if overrides.is_empty() {
        return PathBuf::from("out").join(stem);
    }
    let digest = Sha256::digest(overrides.join("\n").as_bytes());
    let hash: String = digest
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<String>()
        .chars()
        .take(OVERRIDES_HASH_DIGITS)
        .collect();
    PathBuf::from("out").join(format!("{stem}-{hash}"))
}

/// The title of a run's figures: the scene's title (its label when it has none), followed by
/// the overrides in brackets when there are any (`… [static_loads.0.value=5]`), so that a
/// title naming a value of the scene file is never shown alone over a run solved with another.
pub fn figure_title(scene: &Scene, label: &str, overrides: &[String]) -> String {
    let base = if scene.title.is_empty() {
        label
    } else {
        scene.title.as_str()
    };
    if overrides.is_empty() {
        base.to_string()
    } else {
        format!("{base} [{}]", overrides.join(", "))
    }
}

/// How many problems of the scene's size a run solves at the same time: one for an FRF, up to
/// the rayon thread count for the curves of a limit analysis or the values of a sweep.
pub(crate) fn parallel_solves(
    scene: &Scene,
    problem: &Problem,
    limits: Option<&LimitSettings>,
) -> usize {
    let threads = rayon::current_num_threads().max(1);
    if let Some(sweep) = &scene.sweep {
        let series = sweep.series.as_ref().map_or(1, |s| s.values.len().max(1));
        return threads.min(sweep.values.len().max(1) * series);
    }
    match limits {
        Some(l) => {
            let curves = 2
                + l.intermediate.len()
                + l.cases.len()
                + l.bound_scan.len().pow(problem.sides.len() as u32);
            threads.min(curves)
        }
        None => 1,
    }
}

/// Creates the output folder `dir` (and its parents).
pub(crate) fn create_dir(dir: &Path) -> Result<(), CommandError> {
    std::fs::create_dir_all(dir).map_err(|source| CommandError::OutputDir {
        path: dir.display().to_string(),
        source,
    })
}

/// The linear references with contacts open and stuck, written to `linear_open.csv` and
/// `linear_stuck.csv` in `dir`.
pub(crate) fn linear_references(
    label: &str,
    problem: &Problem,
    dir: &Path,
) -> Result<(linear::LinearCurve, linear::LinearCurve), CommandError> {
    let linear_err = |e: crate::numerics::linalg::LinearSolveError| CommandError::Linear {
        scene: label.to_string(),
        reason: e.to_string(),
    };
    let points = problem.analysis.linear_points;
    let open = linear::reference_curve(problem, LinearCase::Open, points).map_err(linear_err)?;
    let stuck = linear::reference_curve(problem, LinearCase::Stuck, points).map_err(linear_err)?;
    files::write_atomic(
        &dir.join("linear_open.csv"),
        files::linear_csv(problem, &open).as_bytes(),
    )?;
    files::write_atomic(
        &dir.join("linear_stuck.csv"),
        files::linear_csv(problem, &stuck).as_bytes(),
    )?;
    Ok((open, stuck))
}

/// One-paragraph summary of a finished run: what was computed, whether it is incomplete, and
/// the output folder.
pub fn run_summary(r: &RunReport) -> String {
    let status = match &r.incomplete {
        Some(reason) => format!("\nincomplete: {reason}"),
        None => String::new(),
    };
    format!("{}{status}\nresults in {}", r.summary, r.dir.display())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn titles_carry_the_overrides() {
        let (label, scene, _, _) = load_scene(None, &[]).unwrap();
        assert_eq!(figure_title(&scene, &label, &[]), scene.title);
        let t = figure_title(&scene, &label, &["static_loads.0.value=5".to_string()]);
        assert_eq!(t, format!("{} [static_loads.0.value=5]", scene.title));
    }
}
