//! The commands of the `fricbound` binary, as library functions: `main.rs` only parses the
//! arguments and dispatches here, so that tests run a command exactly as the binary does.
//!
//! The top layer: it may use every layer below it (`numerics`, `contact`, `fe`, `model`, `hbm`,
//! `analysis`, `scene`, `study`, `report`); nothing in `src/` uses it but `main.rs`. This file
//! only declares the commands and re-exports their entry points.
//!
//! The files, lowest first (a file uses only the ones before it):
//! - `context`: what the commands share: [`CommandError`] (why a command failed, naming what
//!   failed) and the exit codes, [`RunOptions`], [`RunReport`], [`RunOutcome`], the
//!   [`RunContext`] each kind of run works in, [`load_scene`], [`scene_hash`],
//!   [`default_out_dir`], [`figure_title`], [`run_summary`];
//! - [`check`](mod@check) (`fricbound check`): validates a scene and describes it;
//! - [`mesh`] (`fricbound mesh`): generates the blade-pair mesh;
//! - [`modes`] (`fricbound modes`, `fricbound reduce`): natural frequencies of the full and
//!   reduced models, the reduced model written out;
//! - `frf_run`, `limits_run`, `sweep_run`, `modes_nl_run`: the kinds of `fricbound run`, one
//!   FRF, a limit analysis (`[limits]`), a parameter sweep of it (`[sweep]`), nonlinear modes
//!   (`analysis.kind = "nonlinear-modes"`, with or without `[limits]`);
//! - [`run()`] (`fricbound run`): reads and checks the scene, prepares the output folder and
//!   hands the run to its kind;
//! - [`paper`] (`fricbound paper`): runs the scenes of the paper's §4 study
//!   (`meshes/paper-wedge/fig*.toml`, built into the binary) and writes a summary of the key
//!   numbers next to the paper's statements;
//! - [`bench`](mod@bench) (`fricbound bench`): the scaling study of the reduction and the solves,
//!   and (`bench_contacts`) the cost of one limit curve against the contact count;
//! - [`study`] (`fricbound study accuracy`, `fricbound study jacobian`): what each solver
//!   setting costs and gives in accuracy, and the formulations side by side;
//! - [`verify_modes`] (`fricbound verify` on a nonlinear-mode scene): mode points integrated in
//!   time with the artificial damping applied;
//! - [`verify_run`] (`fricbound verify`): time integration of HBM points, against the HBM and
//!   Hill (and the mode points through `verify_modes`).

pub mod bench;
mod bench_contacts;
mod check;
mod context;
mod frf_run;
mod limits_run;
pub mod mesh;
pub mod modes;
mod modes_nl_run;
pub mod paper;
mod run;
pub mod study;
mod sweep_run;
pub mod verify_modes;
pub mod verify_run;

pub use check::{abbreviated_list, check};
pub use context::{
    default_out_dir, figure_title, load_scene, run_summary, scene_hash, CommandError, LoadedScene,
    RunContext, RunOptions, RunOutcome, RunReport, EXIT_COMPLETE, EXIT_ERROR, EXIT_INCOMPLETE,
};
pub use run::run;
