//! The FRF kind of `fricbound run` (a scene without `[limits]` or `[sweep]`): one nonlinear
//! FRF solved with a progress bar and step messages ([`RunObserver`]), its points streamed to
//! `frf.csv`, then `peaks.csv`, `solution.json`, the figures and the response on the mesh.

use indicatif::ProgressBar;

use super::context::{CommandError, RunContext, RunOutcome, RunReport};
use crate::analysis::frf::{
    self, BranchEnd, CutCheck, FrfObserver, FrfPoint, GivenUp, Jump, JumpKind, LeapCheck,
};
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
