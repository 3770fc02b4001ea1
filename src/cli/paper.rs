//! `fricbound paper`: regenerates the data and figures of the paper's §4 study (Figs. 12-19)
//! into one output folder, one sub-folder per figure, and writes `summary.md` (and
//! `summary.json`) with the key numbers computed from the runs next to the paper's statements.
//!
//! The figure scenes are the files `meshes/paper-wedge/fig*.toml`, built into the binary so
//! that the command runs from any folder. `--quick` applies coarser settings (fewer sweep
//! values, a coarser grid and continuation steps, a smaller bound scan) so that the whole study
//! runs in seconds, e.g. in a test; its numbers are coarser, not different in kind.
//!
//! Results are written as each figure finishes, and `summary.md` is rewritten after every
//! figure, so an interrupted run keeps everything finished so far. A figure that fails is
//! reported in the summary and the others still run; the command then ends with an error.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{create_dir, run, CommandError, RunOptions, RunReport};
use crate::cli::paper_summary;
use crate::report::files;

/// One figure of the study: the scene that computes it and its coarser `--quick` settings.
#[derive(Debug)]
pub struct FigureJob {
    /// Identifier, also the sub-folder name (e.g. `fig16a-d`).
    pub id: &'static str,
    /// Scene file name in `meshes/paper-wedge/`.
    pub scene_file: &'static str,
    /// Scene text (the file, built in).
    pub text: &'static str,
    /// What the figure shows, one line.
    pub caption: &'static str,
    /// `--set` overrides applied with `--quick`.
    pub quick: &'static [&'static str],
}

/// Coarser limit-analysis settings for `--quick`.
macro_rules! quick_limits {
    ($($extra:expr),*) => {
        &[
            "limits.grid_points=41",
            "limits.bound_scan=[-0.5, 0.5]",
            "analysis.max_step=0.25",
            $($extra),*
        ]
    };
}

/// The figures of the paper's §4, in the paper's order.
pub static FIGURES: [FigureJob; 13] = [
    FigureJob {
        id: "fig12",
        scene_file: "fig12-linear.toml",
        text: include_str!("../../meshes/paper-wedge/fig12-linear.toml"),
        caption:
            "linear references (contacts open and stuck) over 50-350 Hz, with one nonlinear FRF",
        quick: &["analysis.linear_points=301"],
    },
    FigureJob {
        id: "fig13-2nd",
        scene_file: "fig13-2nd.toml",
        text: include_str!("../../meshes/paper-wedge/fig13-2nd.toml"),
        caption: "limits and contact states around the 2nd resonance, F0 = 120 N (Figs. 13b, 14b)",
        quick: quick_limits!("limits.intermediate=[0.0]"),
    },
    FigureJob {
        id: "fig13-3rd",
        scene_file: "fig13-3rd.toml",
        text: include_str!("../../meshes/paper-wedge/fig13-3rd.toml"),
        caption: "limits and contact states around the 3rd resonance, F0 = 120 N (Figs. 13a, 14a)",
        quick: quick_limits!("limits.intermediate=[0.0]"),
    },
    FigureJob {
        id: "fig15a",
        scene_file: "fig15a.toml",
        text: include_str!("../../meshes/paper-wedge/fig15a.toml"),
        caption: "limits at F0 = 60, 130 and 400 N (Fig. 15a)",
        quick: quick_limits!(),
    },
    FigureJob {
        id: "fig15b",
        scene_file: "fig15b.toml",
        text: include_str!("../../meshes/paper-wedge/fig15b.toml"),
        caption: "limits and intermediate curves near the optimum, F0 = 60 N (Fig. 15b)",
        quick: quick_limits!(),
    },
    FigureJob {
        id: "fig16a-d",
        scene_file: "fig16a-d.toml",
        text: include_str!("../../meshes/paper-wedge/fig16a-d.toml"),
        caption: "optimal-curve and resonance-frequency limits over F0 = 10-500 N (Figs. 16a, 16d)",
        quick: &[
            "sweep.values=[10.0, 20.0, 40.0, 60.0, 130.0, 250.0, 500.0]",
            "analysis.max_step=0.25",
        ],
    },
    FigureJob {
        id: "fig16b",
        scene_file: "fig16b.toml",
        text: include_str!("../../meshes/paper-wedge/fig16b.toml"),
        caption: "limit and intermediate optimal curves near the optimum, F0 = 30-90 N (Fig. 16b)",
        quick: &[
            "sweep.values=[36.0, 44.0, 52.0, 60.0, 68.0]",
            "analysis.max_step=0.25",
        ],
    },
    FigureJob {
        id: "fig16c",
        scene_file: "fig16c.toml",
        text: include_str!("../../meshes/paper-wedge/fig16c.toml"),
        caption: "hysteresis loops at resonance, F0 = 80 N (Fig. 16c)",
        quick: quick_limits!(),
    },
    FigureJob {
        id: "fig17",
        scene_file: "fig17.toml",
        text: include_str!("../../meshes/paper-wedge/fig17.toml"),
        caption: "flat damper (beta = 180 deg): limits and contact states (Fig. 17)",
        quick: quick_limits!("sweep.values=[250.0]"),
    },
    FigureJob {
        id: "fig18a",
        scene_file: "fig18a.toml",
        text: include_str!("../../meshes/paper-wedge/fig18a.toml"),
        caption: "variability bands for beta = 90-180 deg (Fig. 18a)",
        quick: quick_limits!(),
    },
    FigureJob {
        id: "fig18b",
        scene_file: "fig18b.toml",
        text: include_str!("../../meshes/paper-wedge/fig18b.toml"),
        caption: "optimal-curve limits for beta = 90-180 deg (Fig. 18b)",
        quick: &["sweep.values=[120.0, 400.0]", "analysis.max_step=0.25"],
    },
    FigureJob {
        id: "fig19a",
        scene_file: "fig19a.toml",
        text: include_str!("../../meshes/paper-wedge/fig19a.toml"),
        caption: "variability bands for beta = 30-90 deg with blade pre-loads (Fig. 19a)",
        quick: quick_limits!(),
    },
    FigureJob {
        id: "fig19b",
        scene_file: "fig19b.toml",
        text: include_str!("../../meshes/paper-wedge/fig19b.toml"),
        caption: "pseudo-optimal curves over the blade pre-load, beta = 30-90 deg (Fig. 19b)",
        quick: &[
            "sweep.values=[0.0, 500.0, 1000.0]",
            "analysis.max_step=0.25",
        ],
    },
];

/// Options of `fricbound paper`.
#[derive(Debug, Clone, Default)]
pub struct PaperOptions {
    /// Output folder; default `out/paper`.
    pub out: Option<PathBuf>,
    /// Coarser settings (seconds instead of minutes).
    pub quick: bool,
    /// No progress bars or messages.
    pub quiet: bool,
}

/// The run of one figure.
#[derive(Debug)]
pub struct FigureResult {
    /// The figure.
    pub job: &'static FigureJob,
    /// Its results, or why it failed.
    pub outcome: Result<RunReport, String>,
    /// Wall time (s).
    pub elapsed_s: f64,
}

impl FigureResult {
    /// The results when the figure ran.
    pub fn report(&self) -> Option<&RunReport> {
        self.outcome.as_ref().ok()
    }
}

/// What `paper` produced.
#[derive(Debug)]
pub struct PaperReport {
    /// Output folder.
    pub dir: PathBuf,
    /// One entry per figure, in order.
    pub figures: Vec<FigureResult>,
    /// Wall time of the whole study (s).
    pub elapsed_s: f64,
}

/// `fricbound paper`: runs every figure scene into `<out>/<figure id>/` and writes
/// `<out>/summary.md` and `<out>/summary.json`. Returns an error naming the failed figures
/// (after writing everything the others produced) if any figure failed.
pub fn paper(options: &PaperOptions) -> Result<PaperReport, CommandError> {
    let dir = options
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join("paper"));
    create_dir(&dir)?;
    let started = Instant::now();
    let mut figures: Vec<FigureResult> = Vec::new();
    for job in &FIGURES {
        if !options.quiet {
            eprintln!("{}: {}", job.id, job.caption);
        }
        let t = Instant::now();
        let run_options = RunOptions {
            scene: Some(Path::new("meshes/paper-wedge").join(job.scene_file)),
            scene_text: Some(job.text.to_string()),
            out: Some(dir.join(job.id)),
            overrides: if options.quick {
                job.quick.iter().map(|s| s.to_string()).collect()
            } else {
                Vec::new()
            },
            quiet: options.quiet,
        };
        let outcome = run(&run_options).map_err(|e| e.to_string());
        if let (Err(e), false) = (&outcome, options.quiet) {
            eprintln!("{}: failed: {e}", job.id);
        }
        figures.push(FigureResult {
            job,
            outcome,
            elapsed_s: t.elapsed().as_secs_f64(),
        });
        write_summary(
            &dir,
            &figures,
            options.quick,
            started.elapsed().as_secs_f64(),
        )?;
    }
    let report = PaperReport {
        dir,
        elapsed_s: started.elapsed().as_secs_f64(),
        figures,
    };
    let failed: Vec<&str> = report
        .figures
        .iter()
        .filter(|f| f.outcome.is_err())
        .map(|f| f.job.id)
        .collect();
    if failed.is_empty() {
        Ok(report)
    } else {
        Err(CommandError::Paper {
            failed: failed.join(", "),
            dir: report.dir.display().to_string(),
        })
    }
}

fn write_summary(
    dir: &Path,
    figures: &[FigureResult],
    quick: bool,
    elapsed_s: f64,
) -> Result<(), CommandError> {
    let numbers = paper_summary::key_numbers(figures);
    let text = paper_summary::markdown(figures, &numbers, quick, elapsed_s);
    files::write_atomic(&dir.join("summary.md"), text.as_bytes())?;
    let json = serde_json::to_vec_pretty(&numbers).expect("summary numbers serialise");
    files::write_atomic(&dir.join("summary.json"), &json)?;
    Ok(())
}

/// One paragraph on a finished study.
pub fn paper_summary_line(r: &PaperReport) -> String {
    format!(
        "{} figures in {:.1} s; summary in {}",
        r.figures.len(),
        r.elapsed_s,
        r.dir.join("summary.md").display()
    )
}
