//! `fricbound` command line: parses arguments and dispatches to [`fricbound::cli`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Steady-state forced response of friction-damped structures, and its limits.
#[derive(Parser)]
#[command(name = "fricbound", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene (the paper's wedge-damper scene when none is given) and write results.
    Run {
        /// Scene file (TOML).
        scene: Option<PathBuf>,
        /// Output folder (default: out/<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene field by its dotted path, e.g. --set harmonics.max=5
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
        /// No progress bar or step messages; stdout is then the output folder alone, one line.
        #[arg(long)]
        quiet: bool,
    },
    /// Regenerate the data and figures of the paper's §4 study (Figs. 12-19) and a summary.
    Paper {
        /// Output folder (default: out/paper).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Coarser sweeps and grids: seconds instead of minutes.
        #[arg(long)]
        quick: bool,
        /// No progress bars or messages; stdout is then the output folder alone, one line.
        #[arg(long)]
        quiet: bool,
    },
    /// Validate a scene and print a summary.
    Check {
        /// Scene file (TOML).
        scene: Option<PathBuf>,
        /// Override a scene field by its dotted path.
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
    },
    /// Natural frequencies of the full and reduced models, contacts open and stuck, with
    /// their relative errors; damped modes; mode shapes; the reduction report.
    Modes {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Modes per contact case, ≥ 1 (every copy of a repeated last frequency is added).
        #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..))]
        count: u64,
        /// Contact cases: open (removed), stuck (kt, kn springs) or both.
        #[arg(long, value_enum, default_value_t = fricbound::cli::modes::ContactCases::Both)]
        contacts: fricbound::cli::modes::ContactCases,
        /// Output folder (default: out/<scene name>/modes).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene field by its dotted path.
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
    },
    /// Write the Craig-Bampton reduced model (K_r, M_r, C_r as Matrix Market, reduced DOF map,
    /// recovery rows of the outputs, reduction report).
    Reduce {
        /// Scene file (TOML) with a [reduction] table.
        scene: PathBuf,
        /// Output folder (default: out/<scene name>/reduced).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene field by its dotted path.
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
    },
    /// Check HBM points by time integration (Newmark, same contact law): steady-state
    /// amplitude against the HBM, dt convergence, periodicity, and Hill's verdict. Writes
    /// verify.csv, verify.json and a time-history figure per frequency; exit 3 if a case failed
    /// or did not settle. On a nonlinear-mode scene, the mode points nearest --amplitudes
    /// with the artificial damping applied (verify_modes.csv, .json; exit 3 if one fails).
    Verify {
        /// Scene file (TOML; the built-in paper scene when omitted).
        scene: Option<PathBuf>,
        /// Excitation frequencies (Hz), comma separated (forced-response scenes).
        #[arg(long, value_delimiter = ',', required_unless_present = "amplitudes")]
        freqs: Vec<f64>,
        /// First-harmonic amplitudes at the mode's DOF (m), comma separated (nonlinear-mode
        /// scenes): the points nearest them are checked.
        #[arg(long, value_delimiter = ',')]
        amplitudes: Vec<f64>,
        /// Newmark steps per period (default 256·H; the dt check also runs twice as many).
        #[arg(long)]
        steps_per_period: Option<usize>,
        /// Most periods integrated per run (default 300).
        #[arg(long)]
        max_periods: Option<usize>,
        /// Output folder (default: out/<scene name>/verify).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene field by its dotted path.
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        overrides: Vec<String>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Start on the HBM solution (default) or at rest at the static deflection.
        #[arg(long, value_enum, default_value_t = fricbound::cli::verify_run::StartFrom::Hbm)]
        from: fricbound::cli::verify_run::StartFrom,
        /// Initial tangential states m in [-1, 1], comma separated, each applied to every
        /// contact (one case per frequency and state; default: the scene's).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = parse_initial_state)]
        initial_states: Vec<f64>,
    },
    /// Generate or inspect FE meshes.
    Mesh {
        #[command(subcommand)]
        command: fricbound::cli::mesh::MeshCommand,
    },
    /// Studies over solver settings (`study accuracy SCENE`).
    Study {
        #[command(subcommand)]
        command: fricbound::cli::study::StudyCommand,
    },
    /// Scaling study of FE size, contact points, harmonics and solver strategies.
    Bench {
        #[command(subcommand)]
        command: fricbound::cli::bench::BenchCommand,
    },
}

/// An initial tangential state m: a number in [−1, 1].
fn parse_initial_state(s: &str) -> Result<f64, String> {
    let m: f64 = s.trim().parse().map_err(|e| format!("{s}: {e}"))?;
    if (-1.0..=1.0).contains(&m) {
        Ok(m)
    } else {
        Err(format!("{m} is outside [-1, 1]"))
    }
}

/// Parses the arguments, runs the command and maps its result to the exit code: 0 complete
/// ([`fricbound::cli::EXIT_COMPLETE`]), 1 error ([`fricbound::cli::EXIT_ERROR`], one `error:`
/// line on stderr), 3 a run that wrote its results but did not cover the range or every case
/// ([`fricbound::cli::EXIT_INCOMPLETE`], one `incomplete:` line on stderr); clap exits with 2
/// on usage errors.
fn main() -> ExitCode {
    let cli = Cli::parse();
    // Why a run is incomplete, when it is.
    let mut incomplete: Option<String> = None;
    let result = match cli.command {
        Command::Run {
            scene,
            out,
            overrides,
            quiet,
        } => {
            let options = fricbound::cli::RunOptions {
                scene,
                out,
                overrides,
                quiet,
                ..Default::default()
            };
            fricbound::cli::run(&options)
                .map(|r| {
                    // Quiet or not, stdout names the output folder, for scripts to find it.
                    if quiet {
                        println!("{}", r.dir.display());
                    } else {
                        println!("{}", fricbound::cli::run_summary(&r));
                    }
                    incomplete = r.incomplete;
                })
                .map_err(|e| e.to_string())
        }
        Command::Paper { out, quick, quiet } => {
            let options = fricbound::cli::paper::PaperOptions { out, quick, quiet };
            fricbound::cli::paper::paper(&options)
                .map(|r| {
                    if quiet {
                        println!("{}", r.dir.display());
                    } else {
                        println!("{}", fricbound::cli::paper::paper_summary_line(&r));
                    }
                })
                .map_err(|e| e.to_string())
        }
        Command::Check { scene, overrides } => fricbound::cli::check(scene.as_deref(), &overrides)
            .map(|s| print!("{s}"))
            .map_err(|e| e.to_string()),
        Command::Modes {
            scene,
            count,
            contacts,
            out,
            overrides,
        } => fricbound::cli::modes::modes(&fricbound::cli::modes::ModesOptions {
            scene,
            count: usize::try_from(count).unwrap_or(usize::MAX),
            contacts,
            out,
            overrides,
        })
        .map(|r| print!("{}", r.text))
        .map_err(|e| e.to_string()),
        Command::Reduce {
            scene,
            out,
            overrides,
        } => fricbound::cli::modes::reduce(&fricbound::cli::modes::ReduceOptions {
            scene,
            out,
            overrides,
        })
        .map(|r| print!("{}", r.text))
        .map_err(|e| e.to_string()),
        Command::Study { command } => fricbound::cli::study::run(&command)
            .map(|r| {
                print!("{}", r.summary);
                incomplete = r.incomplete;
            })
            .map_err(|e| e.to_string()),
        Command::Bench { command } => fricbound::cli::bench::run(&command)
            .map(|text| print!("{text}"))
            .map_err(|e| e.to_string()),
        Command::Verify {
            scene,
            freqs,
            steps_per_period,
            max_periods,
            out,
            overrides,
            quiet,
            from,
            initial_states,
            amplitudes,
        } => fricbound::cli::verify_run::run(&fricbound::cli::verify_run::VerifyOptions {
            scene,
            freqs,
            out,
            overrides,
            steps_per_period,
            max_periods,
            quiet,
            from,
            initial_states,
            amplitudes,
        })
        .map(|r| {
            print!("{}", r.text);
            incomplete = r.incomplete;
        })
        .map_err(|e| e.to_string()),
        Command::Mesh { command } => fricbound::cli::mesh::run(&command)
            .map(|text| print!("{text}"))
            .map_err(|e| e.to_string()),
    };
    match (result, incomplete) {
        (Ok(()), None) => ExitCode::from(fricbound::cli::EXIT_COMPLETE),
        (Ok(()), Some(reason)) => {
            eprintln!("incomplete: {reason}");
            ExitCode::from(fricbound::cli::EXIT_INCOMPLETE)
        }
        (Err(e), _) => {
            eprintln!("error: {e}");
            ExitCode::from(fricbound::cli::EXIT_ERROR)
        }
    }
}
