//! `fricbound run` on a scene with `[limits]`: the two-point limit analysis with intermediate
//! curves, classification, bound scan and hysteresis loops; tables, JSON and figures.

use std::sync::Mutex;

use super::{CommandError, RunContext, RunOutcome, RunReport};
use crate::analysis::frf::FrfPoint;
use crate::analysis::limits::{self, CaseCurve, LimitAnalysis, Regime};
use crate::report::files::{self, frf_header, frf_row};
use crate::report::limit_files;
use crate::report::plot::{
    figure_files, palette, plot_hysteresis, plot_limits, Curve, LimitFigure, Loop,
};

/// Writes one curve's path as `curve_<name>.csv` (same columns as `frf.csv`).
pub(super) fn write_curve(ctx: &RunContext<'_>, curve: &CaseCurve) -> Result<(), CommandError> {
    let mut text = frf_header(&ctx.problem);
    for p in &curve.run.points {
        text.push_str(&frf_row(p));
    }
    files::write_atomic(
        &ctx.dir.join(format!("curve_{}.csv", curve.case.name)),
        text.as_bytes(),
    )?;
    Ok(())
}

/// Runs the limit analysis of the context's scene.
pub fn run_limits(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let problem = &ctx.problem;
    let settings = ctx.limits.clone().expect("called for scenes with [limits]");
    let n_curves = 2
        + settings.intermediate.len()
        + settings.cases.len()
        + settings.bound_scan.len().pow(problem.sides.len() as u32);
    let bar = ctx.progress(n_curves as u64);
    let write_error: Mutex<Option<CommandError>> = Mutex::new(None);
    let started = std::time::Instant::now();
    let result = limits::analyse(problem, &settings, |curve| {
        if let Err(e) = write_curve(ctx, curve) {
            write_error
                .lock()
                .expect("no panics while holding the lock")
                .get_or_insert(e);
        }
        if let Some(bar) = &bar {
            bar.inc(1);
            bar.set_message(curve.case.name.clone());
        }
    });
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let analysis = result.map_err(|source| CommandError::Limits {
        scene: ctx.label.clone(),
        source,
    })?;
    if let Some(e) = write_error.into_inner().expect("lock not poisoned") {
        return Err(e);
    }
    let elapsed = started.elapsed().as_secs_f64();
    write_analysis(ctx, &analysis, elapsed)?;
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary: summary(&analysis, elapsed),
        outcome: RunOutcome::Limits(Box::new(analysis)),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
}

/// Writes the tables, hysteresis loops, JSON and figures of a finished analysis (the curve
/// files are written as the curves come, by [`write_curve`]).
pub(super) fn write_analysis(
    ctx: &RunContext<'_>,
    analysis: &LimitAnalysis,
    elapsed: f64,
) -> Result<(), CommandError> {
    write_tables(ctx, analysis)?;
    write_hysteresis(ctx, analysis)?;
    write_json(ctx, analysis, elapsed)?;
    // Each limit curve's peak on the mesh (FE scenes).
    for c in &analysis.limits {
        crate::report::mesh_results::write_point(
            &ctx.dir,
            &format!("peak_{}", c.case.name),
            &ctx.problem,
            &c.peak.coefficients,
            &c.peak.states,
        )?;
    }
    plot(ctx, analysis)
}

/// Writes `limits.csv` (the limit curves on the grid) and `peaks.csv` (the peak of every
/// limit, intermediate and scanned curve).
fn write_tables(ctx: &RunContext<'_>, a: &LimitAnalysis) -> Result<(), CommandError> {
    let cases: Vec<_> = a.limits.iter().map(|c| c.case.clone()).collect();
    files::write_atomic(
        &ctx.dir.join("limits.csv"),
        limit_files::limits_csv(&ctx.problem, &cases, &a.grid).as_bytes(),
    )?;
    let mut rows: Vec<(&limits::LimitCase, &str, &limits::Peak)> = Vec::new();
    for c in &a.limits {
        rows.push((&c.case, "limit", &c.peak));
    }
    for c in &a.intermediate {
        rows.push((&c.case, "intermediate", &c.peak));
    }
    for (c, p) in &a.scan_peaks {
        rows.push((c, "scan", p));
    }
    files::write_atomic(
        &ctx.dir.join("peaks.csv"),
        limit_files::peaks_csv(&ctx.problem, &rows).as_bytes(),
    )?;
    Ok(())
}

/// File-name part of a loop set: `m+1_peak`, `m0_214.5Hz`.
fn loop_file_stem(set: &limits::LoopSet) -> String {
    format!("{}_{}", set.case, set.at.replace(' ', ""))
}

/// One `hysteresis_<curve>_<where>.csv` per requested loop set.
fn write_hysteresis(ctx: &RunContext<'_>, a: &LimitAnalysis) -> Result<(), CommandError> {
    for set in &a.loops {
        files::write_atomic(
            &ctx.dir
                .join(format!("hysteresis_{}.csv", loop_file_stem(set))),
            limit_files::hysteresis_csv(&set.loops).as_bytes(),
        )?;
    }
    Ok(())
}

#[derive(serde::Serialize)]
struct CurveJson<'a> {
    case: &'a limits::LimitCase,
    peak: &'a limits::Peak,
    continuation_retries: usize,
    points: &'a [FrfPoint],
    turning_points_hz: &'a [f64],
}

/// Writes `limits.json`: run info, every curve with its peak and path, the grid, the bound
/// check, the scanned peaks and the hysteresis loops.
fn write_json(ctx: &RunContext<'_>, a: &LimitAnalysis, elapsed: f64) -> Result<(), CommandError> {
    let curve = |c: &'_ CaseCurve| -> serde_json::Value {
        serde_json::to_value(CurveJson {
            case: &c.case,
            peak: &c.peak,
            continuation_retries: c.retries,
            points: &c.run.points,
            turning_points_hz: &c.run.turning_points,
        })
        .expect("result types serialise")
    };
    let json = serde_json::json!({
        "info": ctx.info(),
        "status": "complete",
        "elapsed_s": elapsed,
        "limits": a.limits.iter().map(curve).collect::<Vec<_>>(),
        "intermediate": a.intermediate.iter().map(curve).collect::<Vec<_>>(),
        "grid": a.grid,
        "bound_check": a.bounds,
        "scan_peaks": a.scan_peaks,
        "hysteresis": a.loops,
        "hysteresis_missing": a.loops_missing,
    });
    let bytes = serde_json::to_vec_pretty(&json).expect("JSON values serialise");
    files::write_atomic(&ctx.dir.join("limits.json"), &bytes)?;
    Ok(())
}

/// Draws `limits_<dof>` per output DOF (band, curves, multiple-solution and state rows) and
/// `hysteresis_<contact>` per contact when loops were computed.
fn plot(ctx: &RunContext<'_>, a: &LimitAnalysis) -> Result<(), CommandError> {
    let problem = &ctx.problem;
    let grid_x: Vec<f64> = a.grid.iter().map(|g| g.freq_hz).collect();
    let lower: Vec<f64> = a.grid.iter().map(|g| g.lower).collect();
    let upper: Vec<f64> = a.grid.iter().map(|g| g.upper).collect();
    let multiple: Vec<bool> = a
        .grid
        .iter()
        .map(|g| matches!(g.regime, Regime::Multiple { .. }))
        .collect();
    let mut strip_names = Vec::new();
    for c in &a.limits {
        for contact in &problem.contacts {
            strip_names.push(format!("{} {}", contact.name, c.case.name));
        }
    }
    let strip_states: Vec<Vec<crate::contact::ContactState>> = a
        .grid
        .iter()
        .map(|g| {
            if g.states.iter().any(|s| s.is_empty()) {
                Vec::new()
            } else {
                g.states.iter().flatten().copied().collect()
            }
        })
        .collect();
    for (k, &d) in problem.outputs.iter().enumerate() {
        let name = &problem.model.dof_names[d];
        let series: Vec<(String, Vec<f64>, Vec<f64>, bool)> = a
            .limits
            .iter()
            .map(|c| (format!("limit {}", c.case.name), c, false))
            .chain(
                a.intermediate
                    .iter()
                    .map(|c| (format!("intermediate {}", c.case.name), c, true)),
            )
            .map(|(label, c, dashed)| {
                (
                    label,
                    c.run.points.iter().map(|p| p.freq_hz).collect(),
                    c.run.points.iter().map(|p| p.amplitudes[k]).collect(),
                    dashed,
                )
            })
            .collect();
        let open_y: Vec<f64> = ctx.open.amplitudes.iter().map(|r| r[k]).collect();
        let stuck_y: Vec<f64> = ctx.stuck.amplitudes.iter().map(|r| r[k]).collect();
        let mut curves: Vec<Curve> = series
            .iter()
            .enumerate()
            .map(|(i, (label, x, y, dashed))| Curve {
                label,
                x,
                y,
                color: palette(i),
                dashed: *dashed,
                markers: false,
            })
            .collect();
        curves.push(Curve {
            label: "linear, contacts open",
            x: &ctx.open.freqs_hz,
            y: &open_y,
            color: plotters::style::RGBColor(110, 110, 110),
            dashed: true,
            markers: false,
        });
        curves.push(Curve {
            label: "linear, contacts stuck",
            x: &ctx.stuck.freqs_hz,
            y: &stuck_y,
            color: plotters::style::RGBColor(40, 90, 170),
            dashed: true,
            markers: false,
        });
        let fig = LimitFigure {
            title: ctx.title(),
            output_name: name,
            band_x: &grid_x,
            band_lower: &lower,
            band_upper: &upper,
            curves: &curves,
            strip_names: &strip_names,
            strip_states: &strip_states,
            multiple: &multiple,
        };
        let (png, svg) = figure_files(&ctx.dir, &format!("limits_{name}"));
        plot_limits(&fig, &png, &svg)?;
    }
    if a.loops.is_empty() {
        return Ok(());
    }
    let labels: Vec<String> = a
        .loops
        .iter()
        .map(|set| {
            if set.at == "peak" {
                format!("{} at its peak ({:.2} Hz)", set.case, set.freq_hz)
            } else {
                format!("{} at {}", set.case, set.at)
            }
        })
        .collect();
    for (ci, contact) in problem.contacts.iter().enumerate() {
        let series: Vec<Loop> = a
            .loops
            .iter()
            .zip(&labels)
            .enumerate()
            .map(|(i, (set, label))| Loop {
                label,
                u: &set.loops[ci].u,
                t: &set.loops[ci].t,
                color: palette(i),
            })
            .collect();
        let (png, svg) = figure_files(&ctx.dir, &format!("hysteresis_{}", contact.name));
        plot_hysteresis(
            &format!("{}: hysteresis of contact `{}`", ctx.title(), contact.name),
            &series,
            &png,
            &svg,
        )?;
    }
    Ok(())
}

/// A few lines on a finished analysis: peaks, regime, bound scan, retries, missing loops.
pub(super) fn summary(a: &LimitAnalysis, elapsed: f64) -> String {
    use std::fmt::Write as _;
    let mut s = format!("limit analysis in {elapsed:.2} s\n");
    for c in a.limits.iter().chain(&a.intermediate) {
        let _ = writeln!(
            s,
            "  {:<24} peak {:.5e} m at {:.4} Hz{}{}",
            c.case.name,
            c.peak.amplitude,
            c.peak.freq_hz,
            if c.peak.refined {
                ""
            } else {
                " (no local maximum in the peak window)"
            },
            if c.retries > 0 {
                format!(" ({} continuation retries)", c.retries)
            } else {
                String::new()
            }
        );
    }
    let multiple = a
        .grid
        .iter()
        .filter(|g| matches!(g.regime, Regime::Multiple { .. }))
        .count();
    let _ = writeln!(
        s,
        "  multiple-solution regime at {multiple} of {} grid frequencies",
        a.grid.len()
    );
    if let Some(b) = &a.bounds {
        let _ = writeln!(
            s,
            "  bound scan: largest excess above the upper limit {:.3} % {}, below the lower {:.3} % {}",
            100.0 * b.max_excess_above,
            b.above_at.as_ref().map(|(f, c)| format!("({c} at {f:.3} Hz)")).unwrap_or_default(),
            100.0 * b.max_excess_below,
            b.below_at.as_ref().map(|(f, c)| format!("({c} at {f:.3} Hz)")).unwrap_or_default(),
        );
    }
    for m in &a.loops_missing {
        let _ = writeln!(s, "  hysteresis not computed: {m}");
    }
    s.trim_end().to_string()
}
