//! `fricbound run` itself: reads and checks the scene, refuses a problem too large for the
//! machine, prepares the output folder and the linear references, then hands the run to its
//! kind: nonlinear modes (`modes_nl_run`), a sweep (`sweep_run`), a limit analysis
//! (`limits_run`) or one FRF (`frf_run`).

use super::context::{
    create_dir, default_out_dir, figure_title, linear_references, parallel_solves, CommandError,
    RunContext, RunOptions, RunReport,
};
use super::{frf_run, limits_run, modes_nl_run, sweep_run};
use crate::scene::{self, SceneError};

/// `fricbound run`: solves the scene and writes results, linear references and figures.
///
/// In order: the scene is read, overridden and checked; its size and cost are estimated and
/// the run refused ([`CommandError::TooLarge`]) when one Newton iteration would need more
/// memory than the machine has available ([`crate::hbm::cost::check_memory`]); only then is the output folder
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
    crate::hbm::cost::check_memory(&problem, parallel_solves(&scene, &problem, limits.as_ref()))
        .map_err(|e| CommandError::TooLarge {
            scene: label.clone(),
            reason: e.reason,
        })?;
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
    if ctx.problem.analysis.nonlinear_modes.is_some() {
        return modes_nl_run::run_modes(&ctx);
    }
    if ctx.limits.is_some() {
        return limits_run::run_limits(&ctx);
    }
    frf_run::run_frf(&ctx)
}

/// Stuck-contact modes written on the mesh for FE scenes (`modes_stuck.vtu`).
const MESH_MODES: usize = 10;
