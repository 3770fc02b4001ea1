//! The FRF kind of `fricbound run` (a scene without `[limits]` or `[sweep]`): one nonlinear
//! FRF solved with a progress bar and step messages ([`RunObserver`]), its points streamed to
//! `frf.csv`, then `peaks.csv`, `solution.json`, the figures and the response on the mesh.

use indicatif::ProgressBar;

use super::context::{CommandError, RunContext, RunOutcome, RunReport};
use crate::analysis::frf::{self, FrfObserver, FrfPoint, Jump};
use crate::analysis::peaks::{self, ExtremumKind};
use crate::model::Problem;
use crate::numerics::NewtonFailure;
use crate::report::files::{self, FrfWriter};
use crate::report::plot::{self, figure_files, FrfFigure};

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
        self.say(format!(
            "the path turned back at a fold below {:.4} Hz and left the range: it goes on on a \
             branch found past it, from {:.4} Hz{uncovered}",
            jump.from_hz, jump.to_hz
        ));
    }
}

/// A single nonlinear FRF (no limit analysis asked for).
pub(super) fn run_frf(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
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
        .write_solution(&files::status_text(incomplete.as_deref()))?;

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
