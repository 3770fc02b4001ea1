//! The commands of the `fricbound` binary, as library functions: `main.rs` only parses the
//! arguments and dispatches here, so that tests run a command exactly as the binary does.
//!
//! The top layer: it may use every layer below it (`numerics`, `contact`, `fe`, `model`, `hbm`,
//! `analysis`, `scene`, `study`, `report`); nothing in `src/` uses it but `main.rs`.
//!
//! - [`run`] (`fricbound run`): solves what the scene asks for, a parameter sweep of the limit
//!   analysis (`[sweep]`, `sweep_run`), a limit analysis (`[limits]`, `limits_run`) or one FRF,
//!   and writes results, linear references and figures: [`RunOptions`] in, [`RunReport`] with
//!   its [`RunOutcome`] out, [`run_summary`] to print it;
//! - [`RunContext`]: what each kind of run needs (scene, problem, output folder, references);
//! - [`check`] (`fricbound check`): validates a scene and describes it ([`load_scene`],
//!   [`scene_hash`]);
//! - [`paper`] (`fricbound paper`): runs the scenes of the paper's §4 study
//!   (`meshes/paper-wedge/fig*.toml`, built into the binary) and writes a summary of the key
//!   numbers next to the paper's statements;
//! - [`bench`](mod@bench) (`fricbound bench`): the scaling study of the reduction and the solves;
//! - [`mesh`] (`fricbound mesh`): generates the blade-pair mesh;
//! - [`modes`] (`fricbound modes`, `fricbound reduce`): natural frequencies of the full and
//!   reduced models, the reduced model written out;
//! - [`study`] (`fricbound study accuracy`): what each solver setting costs and gives in accuracy;
//! - [`verify_run`] (`fricbound verify`): time integration of HBM points, against the HBM and Hill;
//! - [`CommandError`]: why a command failed, naming what failed.

pub mod bench;
mod limits_run;
pub mod mesh;
pub mod modes;
pub mod paper;
pub mod study;
mod sweep_run;
pub mod verify_run;

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use sha2::{Digest, Sha256};

use crate::analysis::frf::{
    self, BranchEnd, CutCheck, FrfError, FrfObserver, FrfPoint, GivenUp, Jump, JumpKind, LeapCheck,
};
use crate::analysis::limits::LimitSettings;
use crate::analysis::linear::{self, LinearCase};
use crate::analysis::peaks::{self, ExtremumKind};
use crate::model::Problem;
use crate::numerics::NewtonFailure;
use crate::report::files::{self, FrfWriter, RunInfo, WriteError};
use crate::report::plot::{self, figure_files, FrfFigure, PlotError};
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

/// Progress bar plus result writer.
struct RunObserver<'a> {
    writer: FrfWriter,
    bar: Option<ProgressBar>,
    problem: &'a Problem,
    quiet: bool,
}

impl RunObserver<'_> {
    /// Prints a message above the progress bar, or on stderr when there is none.
    fn say(&self, msg: String) {
        match &self.bar {
            Some(bar) if !bar.is_hidden() => bar.println(msg),
            _ => eprintln!("{msg}"),
        }
    }
}

impl FrfObserver for RunObserver<'_> {
    fn point(&mut self, point: &FrfPoint) {
        self.writer.point(point);
        if let Some(bar) = &self.bar {
            let a = &self.problem.analysis.continuation;
            let frac = ((point.freq_hz - a.freq_start_hz) / (a.freq_end_hz - a.freq_start_hz))
                .clamp(0.0, 1.0);
            bar.set_position((frac * 1000.0) as u64);
            bar.set_message(format!(
                "{:.3} Hz, {} points",
                point.freq_hz,
                self.writer.points().len()
            ));
        }
    }
    fn step_cut(&mut self, freq_hz: f64, step: f64, new_step: f64, reason: &NewtonFailure) {
        self.writer.step_cut(freq_hz, step, new_step, reason);
        if !self.quiet {
            let msg =
                format!("step cut after {freq_hz:.4} Hz ({step:.3e} -> {new_step:.3e}): {reason}");
            self.say(msg);
        }
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.writer.turning_point(freq_hz);
    }
    fn jump(&mut self, jump: &Jump) {
        self.writer.jump(jump);
        // Always said, quiet or not: the curve holds two branches from here on.
        let uncovered = if jump.uncovered_hz() > 0.0 {
            format!(
                "; {:.4}-{:.4} Hz not computed on any branch",
                jump.from_hz, jump.to_hz
            )
        } else {
            String::new()
        };
        let before = match (jump.before.words(), jump.abandons_branch()) {
            (Some(words), true) => format!(
                "\nABANDONED: the branch before it was {words}, and the run will be reported \
                 incomplete unless Newton past that point, once the run is over, lands on a \
                 stretch of the run (the jump's end_check)"
            ),
            (Some(words), false) => format!("\nthe branch before it was {words}"),
            (None, _) => String::new(),
        };
        let before = jump.cuts().fold(before, |before, (g, _)| {
            format!(
                "{before}\nthe branch past it (a fill or bridge) was left {}: it may go on \
                 beyond {:.4} Hz, not followed (the jump's fill_cut; judged by Newton past it \
                 once the run is over)",
                g.describe(),
                g.freq_hz
            )
        });
        let msg = match jump.kind {
            JumpKind::PastFold => format!(
                "the path turned back at a fold below {:.4} Hz and did not return: it goes on \
                 on a branch found past it, from {:.4} Hz{uncovered}",
                jump.from_hz, jump.to_hz
            ),
            JumpKind::PastDeadEnd => format!(
                "the path could not be followed on below {:.4} Hz (only the way back was \
                 found): it goes on on a branch found past it, from {:.4} Hz{uncovered}",
                jump.from_hz, jump.to_hz
            ),
            JumpKind::Bridge => format!(
                "a branch solved between the fold's two sides goes on from {:.4} Hz (the \
                 previous branch reached {:.4} Hz){uncovered}",
                jump.to_hz, jump.from_hz
            ),
        } + &before;
        self.say(msg);
    }
    fn narrow_pass(&mut self, from_hz: f64, to_hz: f64) {
        self.writer.narrow_pass(from_hz, to_hz);
        if !self.quiet {
            let msg = format!(
                "the path stalled past {from_hz:.4} Hz and was followed on over a narrow window \
                 around it up to {to_hz:.4} Hz"
            );
            self.say(msg);
        }
    }
    fn cut_judged(&mut self, index: usize, jump: &Jump) {
        self.writer.cut_judged(index, jump);
        // Always said, as the jump was.
        if let (BranchEnd::Abandoned(g), Some(check)) = (&jump.before, &jump.end_check) {
            let msg = format!(
                "{}the branch given up at {:.4} Hz before the jump at {:.4} Hz: {}{}",
                if check.uncovered() { "ABANDONED: " } else { "" },
                g.freq_hz,
                jump.from_hz,
                check.describe_past("the point given up"),
                if check.uncovered() {
                    "; the run will be reported incomplete"
                } else {
                    "; nothing is missing there"
                }
            );
            self.say(msg);
        }
        let judged: Vec<(GivenUp, CutCheck)> = jump
            .cuts()
            .filter_map(|(g, check)| check.map(|c| (*g, *c)))
            .collect();
        for (g, check) in judged {
            let msg = format!(
                "{}the cut at {:.4} Hz of the branch past the jump at {:.4} Hz: {}{}",
                if check.uncovered() {
                    "NOT COVERED: "
                } else {
                    ""
                },
                g.freq_hz,
                jump.from_hz,
                check.describe(),
                if check.uncovered() {
                    "; the run will be reported incomplete"
                } else {
                    ""
                }
            );
            self.say(msg);
        }
    }
    fn leap_judged(&mut self, check: &LeapCheck) {
        self.writer.leap_judged(check);
        // An uncovered leap is always said, as an uncovered cut is.
        if check.uncovered() {
            self.say(format!(
                "NOT COVERED: {}; the run will be reported incomplete",
                check.describe()
            ));
        } else if !self.quiet {
            self.say(check.describe());
        }
    }
    fn leap(&mut self, from_hz: f64, to_hz: f64) {
        self.writer.leap(from_hz, to_hz);
        if !self.quiet {
            let msg = format!(
                "the path could not be followed past {from_hz:.4} Hz and resumed at \
                 {to_hz:.4} Hz (no points in between)"
            );
            self.say(msg);
        }
    }
}

/// `fricbound run`: solves the scene and writes results, linear references and figures.
///
/// In order: the scene is read, overridden and checked; its size and cost are estimated and
/// the run refused ([`CommandError::TooLarge`]) when one Newton iteration would need more
/// memory than the machine has available ([`check_memory`]); only then is the output folder
/// created and the result files of an earlier run removed from it
/// ([`crate::report::owned::clear_results`]), so that a failed or incomplete run never sits
/// beside an earlier run's results.
pub fn run(options: &RunOptions) -> Result<RunReport, CommandError> {
    let label = match &options.scene {
        Some(p) => p.display().to_string(),
        None => scene::default_scene_label().display().to_string(),
    };
    let scene_text = match (&options.scene_text, &options.scene) {
        (Some(text), _) => text.clone(),
        (None, Some(p)) => std::fs::read_to_string(p).map_err(|source| SceneError::Io {
            file: label.clone(),
            source,
        })?,
        (None, None) => scene::PAPER_DEFAULT_SCENE.to_string(),
    };
    let scene = scene::parse(&scene_text, &label, &options.overrides)?;
    let (problem, limits) = scene.validate_with_limits(&label)?;
    check_memory(
        &label,
        &problem,
        parallel_solves(&scene, &problem, limits.as_ref()),
    )?;
    let dir = options
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(options.scene.as_deref(), &options.overrides));
    create_dir(&dir)?;
    crate::report::owned::clear_results(&dir)?;
    let (open, stuck) = linear_references(&label, &problem, &dir)?;
    crate::report::mesh_modes::write_stuck_modes(&dir, &problem, MESH_MODES)?;
    let title = figure_title(&scene, &label, &options.overrides);
    let ctx = RunContext {
        scene_text,
        label,
        title,
        scene,
        problem,
        limits,
        dir,
        open,
        stuck,
        options,
    };
    if ctx.scene.sweep.is_some() {
        return sweep_run::run_sweep(&ctx);
    }
    if ctx.limits.is_some() {
        return limits_run::run_limits(&ctx);
    }
    run_frf(&ctx)
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
fn parallel_solves(scene: &Scene, problem: &Problem, limits: Option<&LimitSettings>) -> usize {
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

/// Where the available memory was read, for messages.
const MEMINFO: &str = "/proc/meminfo";

/// The memory available to a new process (bytes): `MemAvailable` of `/proc/meminfo`, lowered
/// to the room left under the cgroup's limit (`/sys/fs/cgroup/memory.max` minus
/// `memory.current`) when the process runs in a limited cgroup (a container). `None` when
/// `/proc/meminfo` cannot be read or has no `MemAvailable` line (not Linux): the caller then
/// skips the refusal.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string(MEMINFO).ok()?;
    let available = parse_mem_available(&meminfo)?;
    let read = |f: &str| -> Option<u64> {
        std::fs::read_to_string(Path::new("/sys/fs/cgroup").join(f))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let cgroup_room =
        read("memory.max").map(|max| max.saturating_sub(read("memory.current").unwrap_or(0)));
    Some(cgroup_room.map_or(available, |room| room.min(available)))
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes (the file gives kB).
pub fn parse_mem_available(meminfo: &str) -> Option<u64> {
    meminfo.lines().find_map(|line| {
        let rest = line.strip_prefix("MemAvailable:")?;
        let mut parts = rest.split_whitespace();
        let value: u64 = parts.next()?.parse().ok()?;
        match parts.next() {
            Some("kB") | None => Some(value * 1024),
            Some(_) => None,
        }
    })
}

/// Refuses a problem whose estimated memory, one Newton iteration
/// ([`crate::hbm::cost::estimate`]) times the solves that run at the same time, exceeds the
/// memory available ([`available_memory`]); nothing is allocated in proportion to the problem
/// before this check. When the available memory cannot be read the check is skipped.
pub fn check_memory(label: &str, problem: &Problem, parallel: usize) -> Result<(), CommandError> {
    let Some(available) = available_memory() else {
        return Ok(());
    };
    let cost = crate::hbm::cost::estimate(problem);
    match memory_refusal(problem, &cost, parallel, available as f64) {
        Some(reason) => Err(CommandError::TooLarge {
            scene: label.to_string(),
            reason,
        }),
        None => Ok(()),
    }
}

/// Why a problem of estimate `cost`, solved `parallel` times at once, does not fit in
/// `available` bytes; `None` when it fits. Names the fields to lower.
pub fn memory_refusal(
    problem: &Problem,
    cost: &crate::hbm::cost::CostEstimate,
    parallel: usize,
    available: f64,
) -> Option<String> {
    use crate::hbm::cost::{format_bytes, formulation_name};
    let needed = cost.bytes() * parallel.max(1) as f64;
    if needed <= available {
        return None;
    }
    let max_h = problem.harmonics.iter().copied().max().unwrap_or(0);
    Some(format!(
        "refused: one Newton iteration is estimated to need {}{} ({} formulation: {} unknowns, \
         factorised matrix of {} rows; AFT {} samples x {} coefficient blocks), more than the {} \
         available ({MEMINFO}); lower harmonics.max (highest harmonic {max_h}, {} blocks), \
         harmonics.samples ({}) or the model size ({} DOFs, {} contact points: coarser mesh, \
         [reduction], fewer contact pairs){}{}",
        format_bytes(needed),
        if parallel > 1 {
            format!(" for {parallel} curves solved at once")
        } else {
            String::new()
        },
        formulation_name(cost.formulation),
        cost.unknowns,
        cost.factored,
        cost.samples,
        cost.force_blocks,
        format_bytes(available),
        cost.blocks,
        cost.samples,
        cost.dofs,
        cost.contacts,
        if parallel > 1 {
            ", or the curves solved at once (RAYON_NUM_THREADS)"
        } else {
            ""
        },
        if cost.formulation == crate::model::Formulation::Condensed
            && problem.model.stiffness.is_sparse()
        {
            ", or change analysis.formulation: `condensed` holds K, M and C of the whole model \
             dense, `sparse` (or `auto`) keeps them sparse"
        } else {
            ""
        },
    ))
}

/// Stuck-contact modes written on the mesh for FE scenes (`modes_stuck.vtu`).
const MESH_MODES: usize = 10;

/// Creates the output folder `dir` (and its parents).
pub(crate) fn create_dir(dir: &Path) -> Result<(), CommandError> {
    std::fs::create_dir_all(dir).map_err(|source| CommandError::OutputDir {
        path: dir.display().to_string(),
        source,
    })
}

/// The linear references with contacts open and stuck, written to `linear_open.csv` and
/// `linear_stuck.csv` in `dir`.
fn linear_references(
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

/// A single nonlinear FRF (no limit analysis asked for).
fn run_frf(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let problem = &ctx.problem;
    let dir = &ctx.dir;
    let bar = ctx.progress(1000);
    let mut observer = RunObserver {
        writer: FrfWriter::new(dir, problem, ctx.info()),
        bar,
        problem,
        quiet: ctx.options.quiet,
    };
    let result = frf::solve(problem, &mut observer);
    if let Some(bar) = &observer.bar {
        bar.finish_and_clear();
    }
    // The refined resonances and anti-resonances of what was computed, complete or not (a
    // failed refinement reports the path point, never fails the run), within each branch of
    // the path (the branch starts of a failed run are not known: one branch).
    let branch_starts = result
        .as_ref()
        .map(frf::FrfRun::branch_starts)
        .unwrap_or_default();
    let extrema = peaks::path_extrema(problem, observer.writer.points(), &branch_starts);
    observer.writer.write_peaks(&extrema)?;
    let run = match result {
        Ok(run) => run,
        Err(source) => {
            let status = format!("failed: {source}");
            observer.writer.write_solution(&status)?;
            return Err(CommandError::Solve {
                scene: ctx.label.clone(),
                source,
                points: observer.writer.points().len(),
                dir: dir.display().to_string(),
            });
        }
    };
    if let Some(e) = observer.writer.error.take() {
        return Err(e.into());
    }
    // Complete only when the path reached the end frequency; otherwise every finished point
    // is still written and drawn, and the status says what was not covered.
    let incomplete = run.incomplete_reason();
    observer
        .writer
        .write_solution(&status_text(incomplete.as_deref()))?;

    let contact_names: Vec<String> = problem.contacts.iter().map(|c| c.name.clone()).collect();
    for (k, &d) in problem.outputs.iter().enumerate() {
        let name = &problem.model.dof_names[d];
        let refined: Vec<(usize, f64, f64)> = extrema
            .iter()
            .filter(|e| e.output == k && e.peak.refined)
            .map(|e| (e.path_index, e.peak.freq_hz, e.peak.amplitude))
            .collect();
        let fig = FrfFigure {
            title: ctx.title(),
            output_index: k,
            output_name: name,
            contact_names: &contact_names,
            points: &run.points,
            branch_starts: &branch_starts,
            extrema: &refined,
            open: &ctx.open,
            stuck: &ctx.stuck,
        };
        let (png, svg) = figure_files(dir, &format!("frf_{name}"));
        plot::plot_frf(&fig, &png, &svg)?;
    }
    // The response on the mesh at the largest amplitude of the first output (FE scenes).
    if let Some(peak) = run
        .points
        .iter()
        .max_by(|a, b| a.amplitudes[0].total_cmp(&b.amplitudes[0]))
    {
        crate::report::mesh_results::write_point(
            dir,
            "response_peak",
            problem,
            &peak.coefficients,
            &peak.states,
        )?;
    }
    let turning = if run.turning_points.is_empty() {
        "none".to_string()
    } else {
        run.turning_points
            .iter()
            .map(|f| format!("{f:.3} Hz"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    // On stderr unless quiet (a quiet complete run writes nothing there); the largest
    // estimates are in solution.json either way.
    let accuracy_warnings =
        crate::analysis::error_estimate::run_warnings(problem, &frf::accuracy_of(&run.points));
    if !ctx.options.quiet {
        for w in &accuracy_warnings {
            eprintln!("warning: {w}");
        }
    }
    let count = |kind: ExtremumKind| extrema.iter().filter(|e| e.kind == kind).count();
    let unrefined = extrema.iter().filter(|e| !e.peak.refined).count();
    let unrefined = if unrefined > 0 {
        format!(" ({unrefined} could not be refined: path values)")
    } else {
        String::new()
    };
    Ok(RunReport {
        dir: dir.clone(),
        summary: format!(
            "{} converged points in {:.3} s ({} step cuts, {} formulation{}); turning points: \
             {turning}\n{} resonance peaks and {} anti-resonances refined{unrefined}{}",
            run.points.len(),
            run.elapsed_s,
            run.rejected_steps,
            crate::hbm::cost::formulation_name(problem.formulation()),
            if problem.analysis.formulation == crate::model::Formulation::Auto {
                format!(", chosen by auto: {}", problem.auto_formulation().1)
            } else {
                String::new()
            },
            count(ExtremumKind::Resonance),
            count(ExtremumKind::AntiResonance),
            accuracy_line(problem, &run.points, accuracy_warnings.len()),
        ),
        incomplete,
        outcome: RunOutcome::Frf(Box::new(run)),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
}

/// The summary line of the error estimate: the largest estimates over the run's points and how
/// many warnings were printed (empty when the estimate is off).
fn accuracy_line(problem: &Problem, points: &[FrfPoint], warnings: usize) -> String {
    let outputs: Vec<String> = problem
        .outputs
        .iter()
        .map(|&d| problem.model.dof_names[d].clone())
        .collect();
    let threshold = problem.analysis.error_estimate.warn_threshold;
    match files::accuracy_summary(&outputs, threshold, points) {
        None => String::new(),
        Some(s) => {
            let largest = |v: &[f64]| v.iter().copied().fold(0.0_f64, f64::max);
            format!(
                "\nerror estimate: largest truncation {:.2e}, sampling {:.2e} (threshold {:.2e}; \
                 {warnings} warning(s))",
                largest(&s.max_trunc_err),
                largest(&s.max_sampling_err),
                threshold
            )
        }
    }
}

/// `fricbound check`: validates the scene and returns a printable summary.
pub fn check(scene_path: Option<&Path>, overrides: &[String]) -> Result<String, CommandError> {
    let (label, scene, problem, limits) = load_scene(scene_path, overrides)?;
    let set = problem.unknown_harmonics();
    let n = problem.model.n_dofs();
    let e = &problem.effects;
    let a = &problem.analysis.continuation;
    let mut s = String::new();
    use std::fmt::Write as _;
    let _ = writeln!(s, "scene        {label}");
    if !scene.title.is_empty() {
        let _ = writeln!(s, "title        {}", scene.title);
    }
    let _ = writeln!(
        s,
        "DOFs         {n}: {}",
        abbreviated_list(&problem.model.dof_names)
    );
    let harmonics = set.harmonics();
    let _ = writeln!(
        s,
        "harmonics    [{}] ({}{} blocks), {} samples per period",
        abbreviated_list(harmonics),
        if harmonics.len() > CHECK_LISTED {
            format!("{} harmonics, ", harmonics.len())
        } else {
            String::new()
        },
        set.n_blocks(),
        problem.samples
    );
    let _ = writeln!(
        s,
        "unknowns     {} (+1 frequency in continuation)",
        n * set.n_blocks()
    );
    let cost = crate::hbm::cost::estimate(&problem);
    let _ = writeln!(
        s,
        "formulation  {}{}: {} Newton unknowns, factorised matrix of {} rows",
        crate::hbm::cost::formulation_name(cost.formulation),
        if problem.analysis.formulation == crate::model::Formulation::Auto {
            " (auto)"
        } else {
            ""
        },
        cost.unknowns,
        cost.factored
    );
    if problem.analysis.formulation == crate::model::Formulation::Auto {
        let _ = writeln!(s, "  auto       {}", problem.auto_formulation().1);
    }
    let _ = writeln!(s, "cost         {}", cost.summary());
    let parallel = parallel_solves(&scene, &problem, limits.as_ref());
    match available_memory() {
        Some(available) => {
            let verdict = match memory_refusal(&problem, &cost, parallel, available as f64) {
                Some(_) => "`run` refuses this scene: lower harmonics.max, harmonics.samples or \
                            the model size"
                    .to_string(),
                None => format!(
                    "fits{}",
                    if parallel > 1 {
                        format!(" ({parallel} curves solved at once)")
                    } else {
                        String::new()
                    }
                ),
            };
            let _ = writeln!(
                s,
                "memory       {} available ({MEMINFO}): {verdict}",
                crate::hbm::cost::format_bytes(available as f64)
            );
        }
        None => {
            let _ = writeln!(
                s,
                "memory       available memory unknown ({MEMINFO} unreadable): not checked"
            );
        }
    }
    let _ = writeln!(
        s,
        "effects      normal load {:?}, lift-off {}, statics {:?}",
        e.contact.normal_load, e.contact.liftoff, e.coupling
    );
    let estimate = &problem.analysis.error_estimate;
    let _ = writeln!(
        s,
        "accuracy     {}",
        if estimate.enabled {
            let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
            format!(
                "error estimate on every point (truncation to H = {}, or {} where contacts \
                 stay stuck or the harmonics decay slowly; sampling at {} samples), warning \
                 above {} %",
                crate::analysis::error_estimate::extended_harmonic(h_max),
                crate::analysis::error_estimate::wider_harmonic(h_max),
                2 * problem.samples,
                100.0 * estimate.warn_threshold,
            )
        } else {
            "error estimate off ([accuracy] estimate = false)".to_string()
        }
    );
    if let Some(refined) = crate::analysis::error_estimate::EstimateProblems::new(&problem) {
        let budget = crate::analysis::error_estimate::SolveBudget::new(&problem, &refined);
        let _ = writeln!(
            s,
            "  beyond     the step's linear range: {}",
            budget.summary(estimate.beyond_linear_range)
        );
    }
    let _ = writeln!(
        s,
        "contacts     {} on {} damper side(s)",
        problem.contacts.len(),
        problem.sides.len()
    );
    let laws = contact_laws(&problem);
    let _ = writeln!(s, "  laws       {laws}");
    for c in problem.contacts.iter().take(CHECK_LISTED) {
        let _ = writeln!(
            s,
            "  {:<12} side {:<8} kt {:.3e} N/m  kn {:.3e} N/m  mu {}  gap {:.3e} m  m {}  law {}",
            c.name,
            problem.sides[c.side].name,
            c.law.kt,
            c.law.kn,
            c.law.mu,
            c.gap,
            c.law.initial_state,
            c.friction_law().name()
        );
    }
    more_line(&mut s, problem.contacts.len());
    let statics: Vec<String> = problem
        .static_load
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(i, v)| format!("{} {v} N", problem.model.dof_names[i]))
        .collect();
    let _ = writeln!(
        s,
        "static loads {}",
        if statics.is_empty() {
            "none".into()
        } else if statics.len() > CHECK_LISTED {
            format!(
                "{}, ... ({} DOFs loaded)",
                statics[..CHECK_LISTED].join(", "),
                statics.len()
            )
        } else {
            statics.join(", ")
        }
    );
    for l in problem.harmonic_loads.iter().take(CHECK_LISTED) {
        let _ = writeln!(
            s,
            "harmonic load {} h{}: cos {} N, sin {} N",
            problem.model.dof_names[l.dof], l.harmonic, l.cos, l.sin
        );
    }
    more_line(&mut s, problem.harmonic_loads.len());
    let _ = writeln!(
        s,
        "analysis     {} .. {} Hz, steps {:.3e} (min {:.3e}, max {:.3e}), jacobian {:?}",
        a.freq_start_hz,
        a.freq_end_hz,
        a.initial_step,
        a.min_step,
        a.max_step,
        problem.analysis.jacobian
    );
    let _ = writeln!(
        s,
        "outputs      {}",
        problem
            .outputs
            .iter()
            .map(|&d| problem.model.dof_names[d].as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    if let Some(l) = &limits {
        let cases: Vec<String> = crate::analysis::limits::two_point_cases(&problem)
            .into_iter()
            .chain(l.intermediate_cases(&problem))
            .map(|c| c.name)
            .collect();
        let _ = writeln!(
            s,
            "limits       curves {}; grid {} points; bound scan {:?}; peak window {}",
            cases.join(", "),
            l.grid_points,
            l.bound_scan,
            l.peak_window_hz
                .map(|(a, b)| format!("{a} .. {b} Hz"))
                .unwrap_or_else(|| "the range".to_string())
        );
    }
    if let Some(sw) = &scene.sweep {
        let mut line = format!(
            "sweep        {} over {} values ({:?} each)",
            sw.parameter,
            sw.values.len(),
            sw.output
        );
        if let Some(series) = &sw.series {
            let _ = write!(
                line,
                ", for each of {} values of {}",
                series.values.len(),
                series.parameter
            );
        }
        let _ = writeln!(s, "{line}");
    }
    s.push_str(&modes::boundary_check_lines(&scene, &label)?);
    Ok(s)
}

/// Most contacts and loads `check` lists one by one (FE scenes have hundreds).
const CHECK_LISTED: usize = 12;

/// Items shown at each end of a long list by [`abbreviated_list`].
const LIST_ENDS: usize = 5;

/// A list as "a, b, c", or for more than [`CHECK_LISTED`] items its first and last
/// [`LIST_ENDS`] around "…" (a scene with 10 000 harmonics or DOFs must not print them all).
pub fn abbreviated_list<T: std::fmt::Display>(items: &[T]) -> String {
    let join = |part: &[T]| {
        part.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if items.len() <= CHECK_LISTED {
        join(items)
    } else {
        format!(
            "{}, …, {}",
            join(&items[..LIST_ENDS]),
            join(&items[items.len() - LIST_ENDS..])
        )
    }
}

/// Which contact laws a problem uses and how each resolves time, e.g. `jenkins-1d × 2
/// (transitions located in continuous time, the samples bracket them)`.
fn contact_laws(problem: &Problem) -> String {
    use crate::contact::FrictionLaw;
    [
        FrictionLaw::Jenkins1d,
        FrictionLaw::Jenkins1dSampled,
        FrictionLaw::Jenkins2d,
    ]
    .into_iter()
    .filter_map(|law| {
        let count = problem
            .contacts
            .iter()
            .filter(|c| c.friction_law() == law)
            .count();
        (count > 0).then(|| {
            let how = match law {
                FrictionLaw::Jenkins1d => {
                    "transitions located in continuous time, the samples bracket them"
                }
                _ => "marched on the samples",
            };
            format!("{} × {count} ({how})", law.name())
        })
    })
    .collect::<Vec<_>>()
    .join(", ")
}

/// The line after a list cut at [`CHECK_LISTED`] items.
fn more_line(s: &mut String, total: usize) {
    use std::fmt::Write as _;
    if total > CHECK_LISTED {
        let _ = writeln!(s, "  ... and {} more", total - CHECK_LISTED);
    }
}

/// The status written into a run's JSON file: `complete`, or `incomplete: <reason>`.
pub fn status_text(incomplete: Option<&str>) -> String {
    match incomplete {
        None => "complete".to_string(),
        Some(reason) => format!("incomplete: {reason}"),
    }
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
    fn reads_mem_available() {
        let text = "MemTotal:       24585944 kB\nMemFree:         1000000 kB\n\
                    MemAvailable:   20000000 kB\nBuffers:          100 kB\n";
        assert_eq!(parse_mem_available(text), Some(20_000_000 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 1 kB\n"), None);
        assert_eq!(parse_mem_available("MemAvailable: lots\n"), None);
    }

    #[test]
    fn abbreviates_long_lists() {
        assert_eq!(abbreviated_list(&[0, 1, 2]), "0, 1, 2");
        let long: Vec<usize> = (0..=10_000).collect();
        assert_eq!(
            abbreviated_list(&long),
            "0, 1, 2, 3, 4, …, 9996, 9997, 9998, 9999, 10000"
        );
        let twelve: Vec<usize> = (0..CHECK_LISTED).collect();
        assert_eq!(
            abbreviated_list(&twelve).matches(", ").count(),
            CHECK_LISTED - 1
        );
    }

    /// The refusal compares the estimate (times the solves at once) with the memory given and
    /// names the fields to lower.
    #[test]
    fn refuses_what_does_not_fit() {
        let (_, _, problem, _) = load_scene(None, &[]).unwrap();
        let cost = crate::hbm::cost::estimate(&problem);
        assert!(memory_refusal(&problem, &cost, 1, 2.0 * cost.bytes()).is_none());
        let why = memory_refusal(&problem, &cost, 1, 0.5 * cost.bytes()).unwrap();
        for field in [
            "harmonics.max",
            "harmonics.samples",
            "model size",
            "dense formulation",
        ] {
            assert!(why.contains(field), "{field}: {why}");
        }
        // Four curves at once need four times the memory.
        assert!(memory_refusal(&problem, &cost, 4, 2.0 * cost.bytes())
            .unwrap()
            .contains("RAYON_NUM_THREADS"));
        assert!(!why.contains("analysis.formulation"), "{why}");
    }

    /// A sparse FE model asked to run `condensed` (which holds K, M and C dense: the 18 574-DOF
    /// blade pair needs 54 GiB) is also told that another formulation keeps them sparse.
    #[test]
    fn a_condensed_fe_model_is_pointed_to_a_sparse_formulation() {
        let scene =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/blade-pair/blade-pair-2d.toml");
        let overrides = [
            "reduction=".to_string(),
            "analysis.formulation=condensed".to_string(),
        ];
        let (_, _, problem, _) = load_scene(Some(&scene), &overrides).unwrap();
        let cost = crate::hbm::cost::estimate(&problem);
        let why = memory_refusal(&problem, &cost, 1, 0.5 * cost.bytes()).unwrap();
        assert!(why.contains("analysis.formulation"), "{why}");
    }

    #[test]
    fn titles_carry_the_overrides() {
        let (label, scene, _, _) = load_scene(None, &[]).unwrap();
        assert_eq!(figure_title(&scene, &label, &[]), scene.title);
        let t = figure_title(&scene, &label, &["static_loads.0.value=5".to_string()]);
        assert_eq!(t, format!("{} [static_loads.0.value=5]", scene.title));
    }
}
