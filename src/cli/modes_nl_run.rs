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
    let summary = summary(ctx, &limits, elapsed);
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary,
        incomplete,
        outcome: RunOutcome::NonlinearModes(Box::new(limits)),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
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
