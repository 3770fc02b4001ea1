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
//! - [`CommandError`]: why a command failed, naming what failed.

pub mod bench;
mod limits_run;
pub mod mesh;
pub mod paper;
mod sweep_run;

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use sha2::{Digest, Sha256};

use crate::analysis::frf::{self, FrfError, FrfObserver, FrfPoint};
use crate::analysis::limits::LimitSettings;
use crate::analysis::linear::{self, LinearCase};
use crate::contact::harmonic::Block;
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
    /// A linear reference failed.
    #[error("{scene}: linear reference: {reason}")]
    Linear {
        /// Scene label.
        scene: String,
        /// Cause.
        reason: String,
    },
}

/// Options of `fricbound run`.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Scene file; `None` runs the built-in paper scene.
    pub scene: Option<PathBuf>,
    /// Scene text to solve instead of reading `scene` (which then only names it in messages
    /// and gives the default output folder).
    pub scene_text: Option<String>,
    /// Output folder; default `out/<scene stem>`.
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
    /// Title for figures.
    pub fn title(&self) -> &str {
        if self.scene.title.is_empty() {
            &self.label
        } else {
            &self.scene.title
        }
    }

    /// Run info for JSON files.
    pub fn info(&self) -> RunInfo {
        let problem = &self.problem;
        RunInfo {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: self.label.clone(),
            scene_hash: scene_hash(&self.scene),
            dofs: problem.model.dof_names.clone(),
            blocks: block_names(problem),
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

/// Names of the harmonic blocks of the unknowns (`0`, `c1`, `s1`, ...), for the JSON files.
fn block_names(problem: &Problem) -> Vec<String> {
    problem
        .unknown_harmonics()
        .blocks()
        .iter()
        .map(|b| match b {
            Block::Constant => "0".to_string(),
            Block::Cos(h) => format!("c{h}"),
            Block::Sin(h) => format!("s{h}"),
        })
        .collect()
}

/// Progress bar plus result writer.
struct RunObserver<'a> {
    writer: FrfWriter,
    bar: Option<ProgressBar>,
    problem: &'a Problem,
    quiet: bool,
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
            match &self.bar {
                Some(bar) if !bar.is_hidden() => bar.println(msg),
                _ => eprintln!("{msg}"),
            }
        }
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.writer.turning_point(freq_hz);
    }
    fn leap(&mut self, from_hz: f64, to_hz: f64) {
        self.writer.leap(from_hz, to_hz);
        if !self.quiet {
            let msg = format!(
                "the path could not be followed past {from_hz:.4} Hz and resumed at \
                 {to_hz:.4} Hz (no points in between)"
            );
            match &self.bar {
                Some(bar) if !bar.is_hidden() => bar.println(msg),
                _ => eprintln!("{msg}"),
            }
        }
    }
}

/// `fricbound run`: solves the scene and writes results, linear references and figures.
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
    let stem = options
        .scene
        .as_deref()
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "paper-wedge".to_string());
    let dir = options
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(stem));
    create_dir(&dir)?;
    let (open, stuck) = linear_references(&label, &problem, &dir)?;
    crate::report::mesh_modes::write_stuck_modes(&dir, &problem, MESH_MODES)?;
    let ctx = RunContext {
        scene_text,
        label,
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

/// Stuck-contact modes written on the mesh for FE scenes (`modes_stuck.vtu`).
const MESH_MODES: usize = 10;

/// Creates the output folder `dir` (and its parents).
fn create_dir(dir: &Path) -> Result<(), CommandError> {
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
    observer.writer.write_solution("complete")?;

    let contact_names: Vec<String> = problem.contacts.iter().map(|c| c.name.clone()).collect();
    for (k, &d) in problem.outputs.iter().enumerate() {
        let name = &problem.model.dof_names[d];
        let fig = FrfFigure {
            title: ctx.title(),
            output_index: k,
            output_name: name,
            contact_names: &contact_names,
            points: &run.points,
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
    Ok(RunReport {
        dir: dir.clone(),
        summary: format!(
            "{} converged points in {:.3} s ({} step cuts); turning points: {turning}",
            run.points.len(),
            run.elapsed_s,
            run.rejected_steps
        ),
        outcome: RunOutcome::Frf(Box::new(run)),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
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
        problem.model.dof_names.join(", ")
    );
    let _ = writeln!(
        s,
        "harmonics    {:?} ({} blocks), {} samples per period",
        set.harmonics(),
        set.n_blocks(),
        problem.samples
    );
    let _ = writeln!(
        s,
        "unknowns     {} (+1 frequency in continuation)",
        n * set.n_blocks()
    );
    let _ = writeln!(
        s,
        "effects      normal load {:?}, lift-off {}, statics {:?}",
        e.contact.normal_load, e.contact.liftoff, e.coupling
    );
    let _ = writeln!(
        s,
        "contacts     {} on {} damper side(s)",
        problem.contacts.len(),
        problem.sides.len()
    );
    for c in problem.contacts.iter().take(CHECK_LISTED) {
        let _ = writeln!(
            s,
            "  {:<12} side {:<8} kt {:.3e} N/m  kn {:.3e} N/m  mu {}  gap {:.3e} m  m {}",
            c.name,
            problem.sides[c.side].name,
            c.law.kt,
            c.law.kn,
            c.law.mu,
            c.gap,
            c.law.initial_state
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
    Ok(s)
}

/// Most contacts and loads `check` lists one by one (FE scenes have hundreds).
const CHECK_LISTED: usize = 12;

/// The line after a list cut at [`CHECK_LISTED`] items.
fn more_line(s: &mut String, total: usize) {
    use std::fmt::Write as _;
    if total > CHECK_LISTED {
        let _ = writeln!(s, "  ... and {} more", total - CHECK_LISTED);
    }
}

/// One-paragraph summary of a finished run.
pub fn run_summary(r: &RunReport) -> String {
    format!("{}\nresults in {}", r.summary, r.dir.display())
}
