//! `fricbound study accuracy`: the accuracy study of a scene ([`crate::study::accuracy`]) on its
//! FRF, or on each limit curve of a limit scene, with its files: `study.csv` (one row per curve
//! and setting, appended as each finishes), `study.md` (a section per curve) and the
//! error-against-time figure `accuracy_pareto.png`/`.svg` with the Pareto front (a limit scene:
//! every curve in it, and one `accuracy_pareto_<curve>` figure per curve).
//!
//! `fricbound study jacobian`: the Jacobian study ([`crate::study::jacobian`]) of a scene and
//! of the reference ladder, with `jacobian.csv` (one row per case and formulation, appended as
//! each finishes) and `jacobian.md`.
//!
//! The files: `accuracy` (the accuracy study and its files, figures and summary), `jacobian`
//! (the Jacobian study and its tables); this file holds the subcommands, their arguments, the
//! report and what both share (`shared`: reading the scene, the output folder).

mod accuracy;
mod jacobian;
mod shared;

use std::path::PathBuf;

use clap::{Args, Subcommand};

use super::context::CommandError;
use accuracy::accuracy_study;
use jacobian::jacobian_study;
pub use shared::StudyReport;

/// Studies over solver settings.
#[derive(Debug, Clone, Subcommand)]
pub enum StudyCommand {
    /// What accuracy costs in time: each setting (harmonics, samples, tolerance, interior modes,
    /// effect switches) against a converged reference.
    Accuracy(StudyArgs),
    /// The analytic Jacobian against finite differences, and the dense, sparse, condensed and
    /// schur formulations side by side (time per residual, Jacobian, Newton iteration and FRF
    /// point), on the scene and on the paper case, chains with Jenkins elements to ground and
    /// the reduced blade pair; the formulation `auto` picks is marked.
    Jacobian(StudyArgs),
}

/// The arguments every study takes.
#[derive(Debug, Clone, Args)]
pub struct StudyArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Short setting lists and budgets (seconds on the paper case).
    #[arg(long)]
    pub quick: bool,
    /// Output folder (default: `out/<scene name>-accuracy` or `-jacobian`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override a scene field by its dotted path (accuracy: applied to every setting;
    /// jacobian: the scene's own case only).
    #[arg(long = "set", value_name = "FIELD=VALUE")]
    pub overrides: Vec<String>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs a study command.
pub fn run(command: &StudyCommand) -> Result<StudyReport, CommandError> {
    match command {
        StudyCommand::Accuracy(a) => {
            accuracy_study(&a.scene, a.quick, a.out.clone(), &a.overrides, a.quiet)
        }
        StudyCommand::Jacobian(a) => {
            jacobian_study(&a.scene, a.quick, a.out.clone(), &a.overrides, a.quiet)
        }
    }
}
