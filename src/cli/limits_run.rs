//! `fricbound run` on a scene with `[limits]`: the two-point limit analysis with intermediate
//! curves, classification, bound scan and hysteresis loops; tables, JSON and figures.

use std::sync::Mutex;

use super::{CommandError, RunContext, RunOutcome, RunReport};
use crate::analysis::frf::FrfPoint;
use crate::analysis::limits::{self, CaseCurve, LimitAnalysis, Regime};
use crate::report::files::{self, frf_header, frf_row};
use crate::report::limit_files;
use crate::report::plot::{
    figure_files, palette, plot_hysteresis, plot_limits, plot_sweep, Curve, LimitFigure, Loop,
    SweepFigure,
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

/// What the curve callback of a limit analysis collected, for the status and for the files of
/// an analysis stopped by a failed curve.
#[derive(Default)]
struct Finished {
    /// Limit and intermediate curves, as they finished.
    curves: Vec<CaseCurve>,
    /// Scanned cases with their peaks.
    scanned: Vec<(limits::LimitCase, limits::Peak)>,
    /// Names of every finished curve.
    names: Vec<String>,
    /// "curve `<name>`: <reason>" of every finished curve that did not cover the range.
    incomplete: Vec<String>,
}

/// "curve `<name>`: <reason>" when a curve's path did not cover the range.
pub(super) fn curve_incomplete(curve: &CaseCurve) -> Option<String> {
    curve
        .run
        .incomplete_reason()
        .map(|r| format!("curve `{}`: {r}", curve.case.name))
}

/// The incomplete curves of a finished analysis (limit and intermediate ones), "; "-joined;
/// `None` when every one covered the range.
pub(super) fn analysis_incomplete(a: &LimitAnalysis) -> Option<String> {
    let reasons: Vec<String> = a
        .limits
        .iter()
        .chain(&a.intermediate)
        .filter_map(curve_incomplete)
        .collect();
    (!reasons.is_empty()).then(|| reasons.join("; "))
}

/// Runs the limit analysis of the context's scene.
///
/// A curve whose path did not reach the end frequency makes the run incomplete (status
/// `incomplete: …` in `limits.json`, [`RunReport::incomplete`]); so does a curve that failed,
/// which stops the analysis (the analysis layer returns no grid, classification or bound check
/// then): every curve finished before is still written (`curve_*.csv`, `peaks.csv`,
/// `limits.json`) and drawn (`limits_<dof>`), see [`write_stopped`].
pub fn run_limits(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let problem = &ctx.problem;
    let settings = ctx.limits.clone().expect("called for scenes with [limits]");
    let limit_cases = limits::two_point_cases(problem);
    let intermediate_cases = settings.intermediate_cases(problem);
    let scanned_cases = limits::scan_cases(problem, &settings.bound_scan);
    let n_curves = limit_cases.len() + intermediate_cases.len() + scanned_cases.len();
    let kept: Vec<&str> = limit_cases
        .iter()
        .chain(&intermediate_cases)
        .map(|c| c.name.as_str())
        .collect();
    let bar = ctx.progress(n_curves as u64);
    let write_error: Mutex<Option<CommandError>> = Mutex::new(None);
    let finished: Mutex<Finished> = Mutex::new(Finished::default());
    let started = std::time::Instant::now();
    let result = limits::analyse(problem, &settings, |curve| {
        if let Err(e) = write_curve(ctx, curve) {
            write_error
                .lock()
                .expect("no panics while holding the lock")
                .get_or_insert(e);
        }
        {
            let mut f = finished.lock().expect("no panics while holding the lock");
            f.names.push(curve.case.name.clone());
            if let Some(r) = curve_incomplete(curve) {
                f.incomplete.push(r);
            }
            if kept.contains(&curve.case.name.as_str()) {
                f.curves.push(curve.clone());
            } else {
                f.scanned.push((curve.case.clone(), curve.peak.clone()));
            }
        }
        if let Some(bar) = &bar {
            bar.inc(1);
            bar.set_message(curve.case.name.clone());
        }
    });
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    if let Some(e) = write_error.into_inner().expect("lock not poisoned") {
        return Err(e);
    }
    let mut finished = finished.into_inner().expect("lock not poisoned");
    // Curves finish in any order on the worker threads: sorted for a reproducible status.
    finished.incomplete.sort();
    let elapsed = started.elapsed().as_secs_f64();
    let analysis = match result {
        Ok(a) => a,
        Err(error) => {
            let all: Vec<&limits::LimitCase> = limit_cases
                .iter()
                .chain(&intermediate_cases)
                .chain(&scanned_cases)
                .collect();
            return write_stopped(ctx, &all, finished, &error, elapsed);
        }
    };
    let incomplete = (!finished.incomplete.is_empty()).then(|| finished.incomplete.join("; "));
    write_analysis(
        ctx,
        &analysis,
        elapsed,
        &super::status_text(incomplete.as_deref()),
    )?;
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary: summary(&analysis, elapsed),
        incomplete,
        outcome: RunOutcome::Limits(Box::new(analysis)),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
}

/// Writes what a limit analysis stopped by a failed curve (`error`) finished: `peaks.csv` of
/// the finished curves, `limits.json` with status `incomplete: <the failure; the curves not
/// solved; the finished curves that did not cover the range>` and every finished limit and
/// intermediate curve with its path, and `limits_<dof>` drawing those curves over the linear
/// references (no band: the grid is not computed). `all` lists every case of the analysis.
fn write_stopped(
    ctx: &RunContext<'_>,
    all: &[&limits::LimitCase],
    mut finished: Finished,
    error: &limits::LimitError,
    elapsed: f64,
) -> Result<RunReport, CommandError> {
    let failed = match error {
        limits::LimitError::Curve { case, .. }
        | limits::LimitError::Contacts { case, .. }
        | limits::LimitError::Incomplete { case, .. }
        | limits::LimitError::NoPeak { case, .. } => case.as_str(),
    };
    let not_solved: Vec<&str> = all
        .iter()
        .map(|c| c.name.as_str())
        .filter(|n| *n != failed && !finished.names.iter().any(|f| f == n))
        .collect();
    let mut reasons = vec![format!("{error}")];
    if !not_solved.is_empty() {
        reasons.push(format!(
            "not solved after it: {}",
            super::abbreviated_list(&not_solved)
        ));
    }
    reasons.extend(finished.incomplete.iter().cloned());
    let reason = reasons.join("; ");
    // In the order of the analysis' cases.
    let order = |name: &str| all.iter().position(|c| c.name == name);
    finished.curves.sort_by_key(|c| order(&c.case.name));
    finished.scanned.sort_by_key(|(c, _)| order(&c.name));
    let n_limits = limits::two_point_cases(&ctx.problem).len();
    let (limit_curves, intermediate): (Vec<&CaseCurve>, Vec<&CaseCurve>) = finished
        .curves
        .iter()
        .partition(|c| order(&c.case.name).is_some_and(|i| i < n_limits));

    let mut rows: Vec<(&limits::LimitCase, &str, &limits::Peak)> = Vec::new();
    rows.extend(limit_curves.iter().map(|c| (&c.case, "limit", &c.peak)));
    rows.extend(
        intermediate
            .iter()
            .map(|c| (&c.case, "intermediate", &c.peak)),
    );
    rows.extend(finished.scanned.iter().map(|(c, p)| (c, "scan", p)));
    files::write_atomic(
        &ctx.dir.join("peaks.csv"),
        limit_files::peaks_csv(&ctx.problem, &rows).as_bytes(),
    )?;
    let status = super::status_text(Some(&reason));
    let json = serde_json::json!({
        "info": ctx.info(),
        "status": status,
        "elapsed_s": elapsed,
        "error": error.to_string(),
        "not_solved": not_solved,
        "limits": limit_curves.iter().map(|c| curve_json(c)).collect::<Vec<_>>(),
        "intermediate": intermediate.iter().map(|c| curve_json(c)).collect::<Vec<_>>(),
        "scan_peaks": finished.scanned,
    });
    let bytes = serde_json::to_vec_pretty(&json).expect("JSON values serialise");
    files::write_atomic(&ctx.dir.join("limits.json"), &bytes)?;
    plot_finished_curves(ctx, &limit_curves, &intermediate)?;
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary: format!(
            "limit analysis stopped after {elapsed:.2} s: {} of {} curves finished",
            finished.names.len(),
            all.len()
        ),
        incomplete: Some(reason),
        outcome: RunOutcome::LimitCurves(finished.curves),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
}

/// `limits_<dof>` of an analysis stopped by a failed curve: the finished limit (solid) and
/// intermediate (dashed) curves over the linear references, without band or classification.
fn plot_finished_curves(
    ctx: &RunContext<'_>,
    limit_curves: &[&CaseCurve],
    intermediate: &[&CaseCurve],
) -> Result<(), CommandError> {
    let problem = &ctx.problem;
    for (k, &d) in problem.outputs.iter().enumerate() {
        let name = &problem.model.dof_names[d];
        let series = curve_series(limit_curves, intermediate, k);
        let (open_y, stuck_y) = reference_ys(ctx, k);
        let curves = curves_with_references(ctx, &series, &open_y, &stuck_y);
        let title = format!("{} (incomplete: finished curves only)", ctx.title());
        let y_label = format!("{name} first-harmonic amplitude (m)");
        let fig = SweepFigure {
            title: &title,
            x_label: "frequency (Hz)",
            y_label: &y_label,
            log_y: true,
            bands: &[],
            curves: &curves,
        };
        let (png, svg) = figure_files(&ctx.dir, &format!("limits_{name}"));
        plot_sweep(&fig, &png, &svg)?;
    }
    Ok(())
}

/// Writes the tables, hysteresis loops, JSON (with `status`: `complete` or `incomplete: …`)
/// and figures of a finished analysis (the curve files are written as the curves come, by
/// [`write_curve`]).
pub(super) fn write_analysis(
    ctx: &RunContext<'_>,
    analysis: &LimitAnalysis,
    elapsed: f64,
    status: &str,
) -> Result<(), CommandError> {
    write_tables(ctx, analysis)?;
    write_hysteresis(ctx, analysis)?;
    write_json(ctx, analysis, elapsed, status)?;
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
    /// `complete`, or `incomplete: <why the path did not cover the range>`.
    status: String,
    points: &'a [FrfPoint],
    turning_points_hz: &'a [f64],
}

/// One curve as written in `limits.json`.
fn curve_json(c: &CaseCurve) -> serde_json::Value {
    serde_json::to_value(CurveJson {
        case: &c.case,
        peak: &c.peak,
        continuation_retries: c.retries,
        status: super::status_text(c.run.incomplete_reason().as_deref()),
        points: &c.run.points,
        turning_points_hz: &c.run.turning_points,
    })
    .expect("result types serialise")
}

/// Writes `limits.json`: run info, status, every curve with its peak and path, the grid, the
/// bound check, the scanned peaks and the hysteresis loops.
fn write_json(
    ctx: &RunContext<'_>,
    a: &LimitAnalysis,
    elapsed: f64,
    status: &str,
) -> Result<(), CommandError> {
    let json = serde_json::json!({
        "info": ctx.info(),
        "status": status,
        "elapsed_s": elapsed,
        "limits": a.limits.iter().map(curve_json).collect::<Vec<_>>(),
        "intermediate": a.intermediate.iter().map(curve_json).collect::<Vec<_>>(),
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
        let limit_curves: Vec<&CaseCurve> = a.limits.iter().collect();
        let intermediate: Vec<&CaseCurve> = a.intermediate.iter().collect();
        let series = curve_series(&limit_curves, &intermediate, k);
        let (open_y, stuck_y) = reference_ys(ctx, k);
        let curves = curves_with_references(ctx, &series, &open_y, &stuck_y);
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

/// One drawn curve of a limit figure: label, frequencies (Hz), amplitudes (m), dashed.
type CurveSeries = (String, Vec<f64>, Vec<f64>, bool);

/// The limit curves (solid) and intermediate curves (dashed) of output `k` as plot series.
fn curve_series(
    limit_curves: &[&CaseCurve],
    intermediate: &[&CaseCurve],
    k: usize,
) -> Vec<CurveSeries> {
    limit_curves
        .iter()
        .map(|c| (format!("limit {}", c.case.name), c, false))
        .chain(
            intermediate
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
        .collect()
}

/// Amplitudes of output `k` of the linear references (contacts open, contacts stuck).
fn reference_ys(ctx: &RunContext<'_>, k: usize) -> (Vec<f64>, Vec<f64>) {
    (
        ctx.open.amplitudes.iter().map(|r| r[k]).collect(),
        ctx.stuck.amplitudes.iter().map(|r| r[k]).collect(),
    )
}

/// The series as coloured curves, followed by the two linear references (dashed grey: open;
/// dashed blue: stuck).
fn curves_with_references<'a>(
    ctx: &'a RunContext<'_>,
    series: &'a [CurveSeries],
    open_y: &'a [f64],
    stuck_y: &'a [f64],
) -> Vec<Curve<'a>> {
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
        y: open_y,
        color: plotters::style::RGBColor(110, 110, 110),
        dashed: true,
        markers: false,
    });
    curves.push(Curve {
        label: "linear, contacts stuck",
        x: &ctx.stuck.freqs_hz,
        y: stuck_y,
        color: plotters::style::RGBColor(40, 90, 170),
        dashed: true,
        markers: false,
    });
    curves
}
