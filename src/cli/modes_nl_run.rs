//! The nonlinear-mode kind of `fricbound run` (`analysis.kind = "nonlinear-modes"`): the mode
//! of the scene, or with `[limits]` the mode per initial tangential state and their band, then
//! `modes_nl.csv`, `modes_nl.json`, the backbone figures and, for FE scenes, the mode shapes
//! on the mesh.

use super::context::{CommandError, RunContext, RunOutcome, RunReport};
use crate::analysis::nonlinear_modes::{self, ModeLimits, NonlinearModeSettings};
use crate::report::files::status_text;
use crate::report::modes_nl_files::{plot_modes_nl, write_mode_shapes, write_modes_nl};

/// A nonlinear-mode run.
pub(super) fn run_modes(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let problem = &ctx.problem;
    let settings =
        NonlinearModeSettings::of_problem(problem).ok_or_else(|| CommandError::Study {
            scene: ctx.label.clone(),
            reason: "the scene asks for no nonlinear mode".to_string(),
        })?;
    let started = std::time::Instant::now();
    let limits = nonlinear_modes::scene_modes(problem, &settings, ctx.limits.as_ref());
    let elapsed = started.elapsed().as_secs_f64();
    let dof = settings.dof;
    let incomplete = limits.incomplete_reason();
    let status = status_text(incomplete.as_deref());
    write_modes_nl(
        &ctx.dir,
        &ctx.info(),
        &status,
        problem,
        (dof, settings.amplitude),
        &limits,
    )?;
    if ctx.limits.is_none() {
        if let Err(source) = &limits.cases[0].run {
            return Err(CommandError::NonlinearMode {
                scene: ctx.label.clone(),
                source: source.clone(),
            });
        }
    }
    plot_modes_nl(&ctx.dir, ctx.title(), problem, dof, &limits)?;
    write_mode_shapes(&ctx.dir, problem, &limits)?;
    let warnings = accuracy_warnings(ctx, &limits);
    if !ctx.options.quiet {
        for w in &warnings {
            eprintln!("warning: {w}");
        }
    }
    let mut summary = summary(ctx, &limits, elapsed);
    summary.push_str(&accuracy_line(ctx, &limits, warnings.len()));
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary,
        incomplete,
        outcome: RunOutcome::NonlinearModes(Box::new(limits)),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
}

/// The error estimate's warnings of every case (prefixed by the case's name where there are
/// several).
fn accuracy_warnings(ctx: &RunContext<'_>, limits: &ModeLimits) -> Vec<String> {
    let problem = &ctx.problem;
    let Some(m) = problem.analysis.nonlinear_modes else {
        return Vec::new();
    };
    let dof_name = &problem.model.dof_names[m.dof];
    let threshold = problem.analysis.error_estimate.warn_threshold;
    let several = limits.cases.len() > 1;
    let mut out = Vec::new();
    for c in &limits.cases {
        let Ok(run) = &c.run else { continue };
        for w in nonlinear_modes::warnings::warnings(&run.points, dof_name, threshold) {
            out.push(if several {
                format!("case {}: {w}", c.case.name)
            } else {
                w
            });
        }
    }
    out
}

/// The summary line of the error estimate: the largest estimates over every case's points,
/// the points not sized, the threshold and the number of warnings (empty when the estimate is
/// off).
fn accuracy_line(ctx: &RunContext<'_>, limits: &ModeLimits, warnings: usize) -> String {
    let mut largest: Option<([f64; 3], usize)> = None;
    for run in limits.cases.iter().filter_map(|c| c.run.as_ref().ok()) {
        if let Some((l, n)) = nonlinear_modes::warnings::largest(&run.points) {
            let (o, not_sized) = largest.get_or_insert(([0.0; 3], 0));
            *not_sized += n;
            for k in 0..3 {
                o[k] = o[k].max(l[k]);
            }
        }
    }
    let Some(([f, d, a], not_sized)) = largest else {
        return String::new();
    };
    let threshold = ctx.problem.analysis.error_estimate.warn_threshold;
    let not_sized = if not_sized > 0 {
        format!("; {not_sized} point(s) not sized")
    } else {
        String::new()
    };
    format!(
        "\nerror estimate (harmonics raised to 2H + 1): largest change of the frequency {f:.2e}, \
         damping ratio {d:.2e}, amplitude at the DOF {a:.2e}{not_sized} (threshold \
         {threshold:.2e}; {warnings} warning(s))"
    )
}

/// What was computed, a line per case, and the band's wide stretches.
fn summary(ctx: &RunContext<'_>, limits: &ModeLimits, elapsed: f64) -> String {
    let dof_name = ctx
        .problem
        .analysis
        .nonlinear_modes
        .map_or("", |m| ctx.problem.model.dof_names[m.dof].as_str());
    let mut lines = Vec::new();
    for c in &limits.cases {
        lines.push(match &c.run {
            Ok(r) => {
                let (first, last) = (r.points.first(), r.points.last());
                match (first, last) {
                    (Some(a), Some(b)) => format!(
                        "{}: mode {} ({:.4} Hz, D = {:.3e} at rest); {} points, {:.4} Hz and D = {:.3e} at {:.3e} m ({dof_name}); {:.3} s{}",
                        c.case.name,
                        r.mode,
                        a.freq_hz,
                        a.damping_ratio,
                        r.points.len(),
                        b.freq_hz,
                        b.damping_ratio,
                        b.dof_amplitude,
                        r.elapsed_s,
                        match nonlinear_modes::predicted_peak(&ctx.problem, r) {
                            Some(p) => format!(
                                "; predicted peak under the scene's harmonic loads {:.4e} m at {:.4} Hz",
                                p.dof_amplitude, p.freq_hz
                            ),
                            None => String::new(),
                        }
                    ),
                    _ => format!("{}: no point", c.case.name),
                }
            }
            Err(e) => format!("{}: failed: {e}", c.case.name),
        });
    }
    if limits.cases.len() > 1 {
        if limits.band.wide.is_empty() {
            lines.push("band of the cases: narrow over the whole range".to_string());
        } else {
            let stretches: Vec<String> = limits
                .band
                .wide
                .iter()
                .map(|[a, b]| format!("{a:.3e}-{b:.3e} m"))
                .collect();
            lines.push(format!(
                "band of the cases wide (frequency by more than {:.1e} or damping ratio by more than {:.0} %) at {}",
                nonlinear_modes::limits::WIDE_FREQUENCY,
                100.0 * nonlinear_modes::limits::WIDE_DAMPING,
                stretches.join(", ")
            ));
        }
    }
    lines.push(format!("nonlinear modes in {elapsed:.3} s"));
    lines.join("\n")
}
