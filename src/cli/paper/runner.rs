//! The `paper` command itself: runs every figure's scene into its sub-folder, one after the
//! other, and rewrites `summary.md` and `summary.json` after each, so that an interrupted run
//! keeps everything finished so far; a failed figure is reported and the others still run.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::figures::{FigureResult, FIGURES};
use super::from_runs::key_numbers;
use super::markdown::markdown;
use super::stability::{stability_folders, stability_markdown, stability_study, StabilityStudy};
use crate::cli::context::{create_dir, CommandError, RunOptions, RunOutcome};
use crate::cli::run;
use crate::report::{files, owned};

/// The files `paper` writes into its output folder itself (each figure's run writes its own
/// into the figure's sub-folder).
const PAPER_FILES: &[&str] = &["summary.md", "summary.json", "stability.json"];

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

/// What `paper` produced.
#[derive(Debug)]
pub struct PaperReport {
    /// Output folder.
    pub dir: PathBuf,
    /// One entry per figure, in order.
    pub figures: Vec<FigureResult>,
    /// Wall time of the whole study (s).
    pub elapsed_s: f64,
    /// Hill stability of the 3rd-resonance limit curves, without and with damper damping.
    pub stability: StabilityStudy,
}

/// `fricbound paper`: runs every figure scene into `<out>/<figure id>/` and writes
/// `<out>/summary.md` and `<out>/summary.json`. Returns an error naming the failed figures
/// (after writing everything the others produced) if any figure failed.
///
/// Like `run`, it owns its output folder: before the first figure runs, the results of an
/// earlier study are removed ([`owned::clear_study_results`]: every figure's and stability
/// run's sub-folder is cleared as `run` clears its folder, and the summaries are removed), so
/// that an interrupted study never leaves an earlier one's files beside its own.
pub fn paper(options: &PaperOptions) -> Result<PaperReport, CommandError> {
    let dir = options
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join("paper"));
    create_dir(&dir)?;
    let sub_folders: Vec<&str> = FIGURES
        .iter()
        .map(|f| f.id)
        .chain(stability_folders())
        .collect();
    owned::clear_study_results(&dir, &sub_folders, PAPER_FILES)?;
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
            overrides: job.overrides(options.quick),
            quiet: options.quiet,
        };
        // A limit analysis with a failed or incomplete case has no numbers to compare with the
        // paper: the figure failed (what it finished is on disk).
        let outcome = run(&run_options).map_err(|e| e.to_string()).and_then(|r| {
            match (&r.outcome, &r.incomplete) {
                (RunOutcome::Limits(a), Some(reason)) if !a.is_complete() => {
                    Err(format!("incomplete: {reason}"))
                }
                _ => Ok(r),
            }
        });
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
            None,
        )?;
    }
    let stability = stability_study(&dir, options.quick, options.quiet);
    write_summary(
        &dir,
        &figures,
        options.quick,
        started.elapsed().as_secs_f64(),
        Some(&stability),
    )?;
    let report = PaperReport {
        dir,
        elapsed_s: started.elapsed().as_secs_f64(),
        figures,
        stability,
    };
    let failed: Vec<&str> = report
        .figures
        .iter()
        .filter(|f| f.outcome.is_err())
        .map(|f| f.job.id)
        .chain(
            report
                .stability
                .failed
                .iter()
                .map(|f| f.split(':').next().unwrap_or("stability")),
        )
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

/// Writes `summary.md` and `summary.json` (the key numbers) of the figures run so far, and
/// the stability section and `stability.json` once the stability runs are done.
fn write_summary(
    dir: &Path,
    figures: &[FigureResult],
    quick: bool,
    elapsed_s: f64,
    stability: Option<&StabilityStudy>,
) -> Result<(), CommandError> {
    let numbers = key_numbers(figures);
    let mut text = markdown(figures, &numbers, quick, elapsed_s);
    if let Some(s) = stability {
        text.push_str(&stability_markdown(s));
        let json = serde_json::to_vec_pretty(s).expect("stability rows serialise");
        files::write_atomic(&dir.join("stability.json"), &json)?;
    }
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
