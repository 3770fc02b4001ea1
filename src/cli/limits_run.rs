//! `fricbound run` on a scene with `[limits]`: the two-point limit analysis with intermediate
//! curves, classification, bound scan and hysteresis loops; tables, JSON and figures.

use std::sync::Mutex;

use super::context::{CommandError, RunContext, RunOutcome, RunReport};
use crate::analysis::frf::FrfPoint;
use crate::analysis::limits::{self, CaseCurve, LimitAnalysis, Regime};
use crate::analysis::stability::{methods_text, stretches_text, unstable_stretches};
use crate::report::files::{self, frf_header, frf_row};
use crate::report::limit_files;
use crate::report::plot::{
    figure_files, palette, plot_hysteresis, plot_limits, unstable_label, Curve, LimitFigure, Loop,
    UNSTABLE_COLOR,
};

/// Writes one curve's path as `curve_<name>.csv` (same columns as `frf.csv`): the whole path of
/// a complete case, the finished points of an unfinished one (only the header when it failed at
/// its first point).
pub(super) fn write_curve(ctx: &RunContext<'_>, curve: &CaseCurve) -> Result<(), CommandError> {
    let mut text = frf_header(&ctx.problem);
    for p in &curve.points {
        text.push_str(&frf_row(p));
    }
    files::write_atomic(
        &ctx.dir.join(format!("curve_{}.csv", curve.case.name)),
        text.as_bytes(),
    )?;
    Ok(())
}

/// Most unfinished curves named in an analysis' status (all are in `limits.json`).
const STATUS_CURVES: usize = 6;

/// Why an analysis did not cover what it asks for: every limit, intermediate or scanned case
/// that is incomplete or failed ([`LimitAnalysis::unfinished`], the first [`STATUS_CURVES`]
/// named, the others counted), and where the band exists when that is not the whole grid;
/// `None` when every case covered the range.
pub(super) fn analysis_incomplete(a: &LimitAnalysis) -> Option<String> {
    let reasons = a.unfinished();
    if reasons.is_empty() {
        return None;
    }
    let mut text = reasons[..reasons.len().min(STATUS_CURVES)].join("; ");
    if reasons.len() > STATUS_CURVES {
        text.push_str(&format!(
            "; ... and {} more unfinished curves (see limits.json)",
            reasons.len() - STATUS_CURVES
        ));
    }
    let band = a.band_points();
    if band < a.grid.len() {
        text.push_str(&format!(
            "; the band exists at {band} of {} grid frequencies (both limit curves solved), NaN \
             elsewhere",
            a.grid.len()
        ));
    }
    Some(text)
}

/// Runs the limit analysis of the context's scene.
///
/// Every case is attempted whatever the others do ([`limits::analyse`]). A case whose path did
/// not reach the end frequency, or that failed, makes the run incomplete (status
/// `incomplete: …` in `limits.json` naming the curves, [`RunReport::incomplete`], exit code 3);
/// its finished points are still written (`curve_<name>.csv`) and drawn, `limits.json` gives
/// every curve's status, and the band of `limits.csv` and of the figure exists where both limit
/// curves were solved (NaN elsewhere).
pub fn run_limits(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let problem = &ctx.problem;
    let settings = ctx.limits.clone().expect("called for scenes with [limits]");
    let n_curves = limits::two_point_cases(problem).len()
        + settings.intermediate_cases(problem).len()
        + limits::scan_cases(problem, &settings.bound_scan).len();
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
            if let Some(reason) = curve.unfinished_reason() {
                bar.println(reason);
            }
        }
    });
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    if let Some(e) = write_error.into_inner().expect("lock not poisoned") {
        return Err(e);
    }
    let analysis = result.map_err(|source| CommandError::Limits {
        scene: ctx.label.clone(),
        source,
    })?;
    let elapsed = started.elapsed().as_secs_f64();
    // The error estimate's warnings per limit and intermediate curve, unless quiet (the
    // largest estimates are in limits.json either way).
    if !ctx.options.quiet {
        for c in analysis.limits.iter().chain(&analysis.intermediate) {
            let points = crate::analysis::frf::accuracy_of(&c.points);
            for w in crate::analysis::error_estimate::run_warnings(problem, &points) {
                eprintln!("warning: curve {}: {w}", c.case.name);
            }
        }
    }
    let incomplete = analysis_incomplete(&analysis);
    write_analysis(
        ctx,
        &analysis,
        elapsed,
        &crate::report::files::status_text(incomplete.as_deref()),
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
    // Each limit curve's peak on the mesh (FE scenes), where the curve has one.
    for c in &analysis.limits {
        let Some(peak) = &c.peak else { continue };
        crate::report::mesh_results::write_point(
            &ctx.dir,
            &format!("peak_{}", c.case.name),
            &ctx.problem,
            &peak.coefficients,
            &peak.states,
        )?;
    }
    plot(ctx, analysis)
}

/// Writes `limits.csv` (the limit curves on the grid: amplitudes, band and regime where they
/// were solved, NaN / `unknown` elsewhere) and `peaks.csv` (peak and status of every limit,
/// intermediate and scanned case).
fn write_tables(ctx: &RunContext<'_>, a: &LimitAnalysis) -> Result<(), CommandError> {
    let cases: Vec<_> = a.limits.iter().map(|c| c.case.clone()).collect();
    files::write_atomic(
        &ctx.dir.join("limits.csv"),
        limit_files::limits_csv(&ctx.problem, &cases, &a.grid, a.envelope.as_ref()).as_bytes(),
    )?;
    let mut rows: Vec<limit_files::PeakRow> = Vec::new();
    for c in &a.limits {
        rows.push((&c.case, "limit", c.peak.as_ref(), &c.status));
    }
    for c in &a.intermediate {
        rows.push((&c.case, "intermediate", c.peak.as_ref(), &c.status));
    }
    for c in &a.scanned {
        rows.push((&c.case, "scan", c.peak.as_ref(), &c.status));
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
    /// `complete`, `incomplete: <why the path did not cover the range>` or `failed: <cause>`.
    status: &'a limits::CurveStatus,
    peak: Option<&'a limits::Peak>,
    /// Largest error estimates over the curve's points (when the scene asks for them).
    #[serde(skip_serializing_if = "Option::is_none")]
    accuracy: Option<files::AccuracySummary>,
    /// The whole path, or the finished points of an unfinished case.
    points: &'a [FrfPoint],
    turning_points_hz: &'a [f64],
    /// With `analysis.stability`: the stretches `[from_hz, to_hz]` of unstable points.
    #[serde(skip_serializing_if = "Option::is_none")]
    unstable_hz: Option<Vec<[f64; 2]>>,
}

/// One curve as written in `limits.json` (with `unstable_hz` when `stability` is on).
fn curve_json(ctx: &RunContext<'_>, c: &CaseCurve, stability: bool) -> serde_json::Value {
    let info = ctx.info();
    serde_json::to_value(CurveJson {
        case: &c.case,
        status: &c.status,
        peak: c.peak.as_ref(),
        accuracy: files::accuracy_summary(
            &info.outputs,
            ctx.problem.analysis.error_estimate.warn_threshold,
            &c.points,
        ),
        points: &c.points,
        turning_points_hz: &c.turning_points,
        unstable_hz: stability
            .then(|| unstable_stretches(c.points.iter().map(|p| (p.freq_hz, p.stability)))),
    })
    .expect("result types serialise")
}

/// The status of every case in one list, in case order (limit, intermediate, scan): name, kind,
/// status, points finished and the highest frequency reached (Hz; NaN without points; not for
/// scanned cases, whose paths are not kept).
fn curve_statuses(a: &LimitAnalysis) -> Vec<serde_json::Value> {
    let reach = |c: &CaseCurve| {
        c.points
            .iter()
            .map(|p| p.freq_hz)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let curve = |c: &CaseCurve, kind: &str| {
        let reached = reach(c);
        serde_json::json!({
            "case": c.case.name,
            "kind": kind,
            "status": c.status.text(),
            "points": c.points.len(),
            "reached_hz": reached.is_finite().then_some(reached),
        })
    };
    a.limits
        .iter()
        .map(|c| curve(c, "limit"))
        .chain(a.intermediate.iter().map(|c| curve(c, "intermediate")))
        .chain(a.scanned.iter().map(|c| {
            serde_json::json!({
                "case": c.case.name,
                "kind": "scan",
                "status": c.status.text(),
            })
        }))
        .collect()
}

/// Writes `limits.json`: run info, status, every case's status (`curves`), every limit and
/// intermediate curve with its peak and path (finished points of an unfinished one), where the
/// band exists, the grid, the bound check, the scanned cases and the hysteresis loops.
fn write_json(
    ctx: &RunContext<'_>,
    a: &LimitAnalysis,
    elapsed: f64,
    status: &str,
) -> Result<(), CommandError> {
    let stability = ctx.problem.analysis.stability;
    let mut json = serde_json::json!({
        "info": ctx.info(),
        "status": status,
        "elapsed_s": elapsed,
        "curves": curve_statuses(a),
        "limits": a.limits.iter().map(|c| curve_json(ctx, c, stability)).collect::<Vec<_>>(),
        "intermediate": a
            .intermediate
            .iter()
            .map(|c| curve_json(ctx, c, stability))
            .collect::<Vec<_>>(),
        "band": {
            "grid_points": a.grid.len(),
            "defined_points": a.band_points(),
            "note": "lower/upper (and the regime) exist at the grid frequencies where both \
                     limit curves were solved; NaN (unknown) elsewhere",
        },
        "grid": a.grid,
        "bound_check": a.bounds,
        "scanned": a.scanned,
        "hysteresis": a.loops,
        "hysteresis_missing": a.loops_missing,
    });
    if let Some(e) = &a.envelope {
        json["envelope"] = serde_json::to_value(e).expect("result types serialise");
    }
    if stability {
        json["stability"] = band_stability_json(a, ctx.problem.analysis.stability_method);
    }
    let bytes = serde_json::to_vec_pretty(&json).expect("JSON values serialise");
    files::write_atomic(&ctx.dir.join("limits.json"), &bytes)?;
    Ok(())
}

/// `limits.json` → `stability`: for each limit curve (the two that form the band), the
/// stretches where the scene's stability method finds it unstable, and the grid frequencies where the band
/// exists but is bounded by an unstable limit point (a state the structure does not keep).
fn band_stability_json(
    a: &LimitAnalysis,
    method: crate::model::StabilityMethod,
) -> serde_json::Value {
    let curves: Vec<serde_json::Value> = a
        .limits
        .iter()
        .map(|c| {
            let stretches = unstable_stretches(c.points.iter().map(|p| (p.freq_hz, p.stability)));
            serde_json::json!({
                "case": c.case.name,
                "unstable_hz": stretches,
                "unstable_points": c.points.iter().filter(|p| p.stability.is_some_and(|s| s.is_unstable())).count(),
                "unreliable_points": c.points.iter().filter(|p| p.stability.is_some_and(|s| !s.reliable)).count(),
                "points": c.points.len(),
                "verdicts": methods_text(c.points.iter().filter_map(|p| p.stability.as_ref())),
                "text": stretches_text(&stretches),
            })
        })
        .collect();
    serde_json::json!({
        "method": method.label(),
        "about": "hill: Floquet exponents of the harmonic-balance Jacobian (unreliable on stick-slip \
                  points); monodromy: Floquet multipliers of the time integration's periodic orbit; \
                  hill+monodromy: the monodromy where Hill is unreliable. A limit curve is not a \
                  reachable bound where it is unstable",
        "limit_curves": curves,
    })
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
    // An unfinished analysis says so in its title: some curves end early or are missing.
    let title = if a.is_complete() {
        ctx.title().to_string()
    } else {
        format!("{} (incomplete: see limits.json)", ctx.title())
    };
    for (k, &d) in problem.outputs.iter().enumerate() {
        let name = &problem.model.dof_names[d];
        let limit_curves: Vec<&CaseCurve> = a.limits.iter().collect();
        let intermediate: Vec<&CaseCurve> = a.intermediate.iter().collect();
        let series = curve_series(&limit_curves, &intermediate, k);
        let (open_y, stuck_y) = reference_ys(ctx, k);
        let overlays: Vec<(Vec<f64>, Vec<f64>)> = limit_curves
            .iter()
            .chain(&intermediate)
            .map(|c| unstable_overlay(&c.points, k))
            .filter(|(x, _)| !x.is_empty())
            .collect();
        let overlay_label = unstable_label(
            limit_curves
                .iter()
                .chain(&intermediate)
                .flat_map(|c| c.points.iter().filter_map(|p| p.stability.as_ref())),
        );
        let mut curves = curves_with_references(ctx, &series, &open_y, &stuck_y);
        let (env_min, env_max) = envelope_series(a, k);
        if !env_max.is_empty() {
            for (i, y) in [&env_max, &env_min].into_iter().enumerate() {
                curves.push(Curve {
                    label: if i == 0 {
                        "envelope over all m (max, min)"
                    } else {
                        ""
                    },
                    x: &grid_x,
                    y,
                    color: plotters::style::RGBColor(0, 0, 0),
                    dashed: false,
                    markers: false,
                });
            }
        }
        for (i, (x, y)) in overlays.iter().enumerate() {
            curves.push(Curve {
                label: if i == 0 { &overlay_label } else { "" },
                x,
                y,
                color: UNSTABLE_COLOR,
                dashed: true,
                markers: true,
            });
        }
        let fig = LimitFigure {
            title: &title,
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

/// A few lines on a finished analysis: peaks, regime, bound scan, missing loops.
pub(super) fn summary(a: &LimitAnalysis, elapsed: f64) -> String {
    use std::fmt::Write as _;
    let mut s = format!("limit analysis in {elapsed:.2} s\n");
    for c in a.limits.iter().chain(&a.intermediate) {
        let peak = match &c.peak {
            Some(p) => format!(
                "peak {:.5e} m at {:.4} Hz{}",
                p.amplitude,
                p.freq_hz,
                if p.refined {
                    ""
                } else {
                    " (no local maximum in the peak window)"
                }
            ),
            None => "no peak".to_string(),
        };
        let _ = writeln!(
            s,
            "  {:<24} {peak}{}",
            c.case.name,
            if c.status.is_complete() {
                String::new()
            } else {
                format!(" [{}]", c.status.text())
            }
        );
    }
    for c in &a.limits {
        if c.points.iter().any(|p| p.stability.is_some()) {
            let _ = writeln!(
                s,
                "  {:<24} stability ({}): {}",
                c.case.name,
                methods_text(c.points.iter().filter_map(|p| p.stability.as_ref())),
                match unstable_stretches(c.points.iter().map(|p| (p.freq_hz, p.stability))) {
                    v if v.is_empty() => "stable throughout".to_string(),
                    v => format!("UNSTABLE over {}", stretches_text(&v)),
                }
            );
        }
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
    if let Some(e) = &a.envelope {
        let _ = writeln!(s, "{}", envelope_summary(e));
    }
    for m in &a.loops_missing {
        let _ = writeln!(s, "  hysteresis not computed: {m}");
    }
    s.trim_end().to_string()
}

/// The envelope's lines of the summary: cost, and where and by how much the two limit curves
/// fail to bound it (first output DOF).
fn envelope_summary(e: &limits::Envelope) -> String {
    let m_text = |m: &[f64]| {
        e.groups
            .iter()
            .zip(m)
            .map(|(g, m)| format!("{g} {m:+.3}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let c = &e.check;
    let mut s = format!(
        "  envelope ({} m per {}): {} solves in {:.2} s",
        e.groups.len(),
        match e.mode {
            limits::EnvelopeMode::Sides => "side",
            limits::EnvelopeMode::Points => "contact point",
        },
        e.solves,
        e.elapsed_s
    );
    if e.unsolved > 0 {
        s.push_str(&format!(
            "; NO state solved at {} grid frequencies",
            e.unsolved
        ));
    }
    s.push_str(&format!(
        "\n  envelope above the upper limit at {} of {} grid frequencies, by at most {:.3} %{}",
        c.points_above,
        c.compared,
        100.0 * c.max_excess_above,
        c.above_at
            .as_ref()
            .map(|(f, m)| format!(" ({f:.3} Hz, m: {})", m_text(m)))
            .unwrap_or_default()
    ));
    s.push_str(&format!(
        "\n  envelope below the lower limit at {} of {} grid frequencies, by at most {:.3} %{}",
        c.points_below,
        c.compared,
        100.0 * c.max_excess_below,
        c.below_at
            .as_ref()
            .map(|(f, m)| format!(" ({f:.3} Hz, m: {})", m_text(m)))
            .unwrap_or_default()
    ));
    for p in &e.peaks {
        if let Some(Some(hi)) = p.point.max.first() {
            s.push_str(&format!(
                "\n  envelope at the peak of {} ({:.4} Hz): max {:.5e} m (m: {}), limit {:.5e} m",
                p.case,
                p.point.freq_hz,
                hi.amplitude,
                m_text(&hi.m),
                p.limit_amplitude
            ));
        }
    }
    s
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
                c.points.iter().map(|p| p.freq_hz).collect(),
                c.points.iter().map(|p| p.amplitudes[k]).collect(),
                dashed,
            )
        })
        .collect()
}

/// The envelope's smallest and largest amplitude of output `k` on the grid (NaN where no state
/// was solved); empty without an envelope.
fn envelope_series(a: &LimitAnalysis, k: usize) -> (Vec<f64>, Vec<f64>) {
    let Some(e) = &a.envelope else {
        return (Vec::new(), Vec::new());
    };
    let amp = |b: Option<&Option<limits::EnvelopeBound>>| {
        b.and_then(|b| b.as_ref()).map_or(f64::NAN, |b| b.amplitude)
    };
    e.points
        .iter()
        .map(|p| (amp(p.min.get(k)), amp(p.max.get(k))))
        .unzip()
}

/// Amplitudes of output `k` of the linear references (contacts open, contacts stuck).
fn reference_ys(ctx: &RunContext<'_>, k: usize) -> (Vec<f64>, Vec<f64>) {
    (
        ctx.open.amplitudes.iter().map(|r| r[k]).collect(),
        ctx.stuck.amplitudes.iter().map(|r| r[k]).collect(),
    )
}

/// The unstable points of a curve's path for output `k` as (frequencies, amplitudes), NaN at
/// stable points so that the drawn runs break there; empty when no point is unstable.
fn unstable_overlay(points: &[FrfPoint], k: usize) -> (Vec<f64>, Vec<f64>) {
    if !points
        .iter()
        .any(|p| p.stability.is_some_and(|s| s.is_unstable()))
    {
        return (Vec::new(), Vec::new());
    }
    points
        .iter()
        .map(|p| {
            if p.stability.is_some_and(|s| s.is_unstable()) {
                (p.freq_hz, p.amplitudes.get(k).copied().unwrap_or(f64::NAN))
            } else {
                (f64::NAN, f64::NAN)
            }
        })
        .unzip()
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
