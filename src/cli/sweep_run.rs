//! `fricbound run` on a scene with `[sweep]`: the limit analysis at every parameter value
//! (and series value), streamed to disk as values finish.
//!
//! * `sweep.csv`: resonance peaks of the limit and intermediate cases per value (optimal
//!   curves, resonance-frequency limits), rewritten as each value finishes;
//! * with `output = "limits"`, one folder `<parameter>_<value>` (with a series:
//!   `<series>_<value>_<parameter>_<value>`) per value holding the whole limit analysis as
//!   `fricbound run` writes it, and `variability.csv`;
//! * at the end `sweep.json`, the figures `optimal_<dof>` (peak amplitude vs the parameter) and
//!   `resonance_<dof>` (peak frequency vs the parameter), and with `output = "limits"`
//!   `bands_<dof>` (the FRF bands of all values on one chart, one chart per series value).

use std::path::PathBuf;
use std::sync::Mutex;

use super::context::{CommandError, RunContext, RunOutcome, RunReport};
use super::limits_run;
use crate::analysis::limits::LimitSettings;
use crate::model::Problem;
use crate::report::files;
use crate::report::limit_files;
use crate::report::plot::{figure_files, palette, plot_sweep, BandSpec, Curve, SweepFigure};
use crate::scene::{Scene, SweepOutput, SweepSpec};
use crate::study::sweep::{self, SweepPoint};

/// Text of a parameter value in folder names and labels ("60", "30.5").
fn value_text(v: f64) -> String {
    format!("{v}")
}

/// Folder of one sweep point's limit analysis.
fn point_dir(ctx: &RunContext<'_>, spec: &SweepSpec, series: Option<f64>, value: f64) -> PathBuf {
    let mut name = String::new();
    if let (Some(s), Some(v)) = (&spec.series, series) {
        name.push_str(&format!("{}_{}_", s.parameter, value_text(v)));
    }
    name.push_str(&format!("{}_{}", spec.parameter, value_text(value)));
    ctx.dir.join(name)
}

/// Parameter `name` at value `v`, with its unit if it has one: "F0 = 60 N", "m = 0".
pub(super) fn parameter_label(name: &str, unit: &str, v: f64) -> String {
    if unit.is_empty() {
        format!("{name} = {}", value_text(v))
    } else {
        format!("{name} = {} {unit}", value_text(v))
    }
}

/// "F0 = 60 N", "beta = 90 deg, F0 = 60 N".
fn point_label(spec: &SweepSpec, series: Option<f64>, value: f64) -> String {
    let mut s = String::new();
    if let (Some(sp), Some(v)) = (&spec.series, series) {
        s = parameter_label(&sp.parameter, &sp.unit, v) + ", ";
    }
    s + &parameter_label(&spec.parameter, &spec.unit, value)
}

/// Writes one sweep point's limit analysis into its own folder, as `run` would.
fn write_point_analysis(
    ctx: &RunContext<'_>,
    spec: &SweepSpec,
    point: &SweepPoint,
    (scene, problem, limits): (&Scene, &Problem, &LimitSettings),
) -> Result<(), CommandError> {
    let Some(analysis) = &point.analysis else {
        return Ok(());
    };
    let dir = point_dir(ctx, spec, point.series, point.value);
    super::context::create_dir(&dir)?;
    let label = format!(
        "{} ({})",
        ctx.label,
        point_label(spec, point.series, point.value)
    );
    let (open, stuck) = super::context::linear_references(&label, problem, &dir)?;
    let mut scene = scene.clone();
    scene.title = format!(
        "{}: {}",
        ctx.title(),
        point_label(spec, point.series, point.value)
    );
    let sub = RunContext {
        label,
        // The parent's title already carries the overrides.
        title: scene.title.clone(),
        scene,
        problem: problem.clone(),
        limits: Some(limits.clone()),
        dir,
        open,
        stuck,
        options: ctx.options,
        scene_text: ctx.scene_text.clone(),
    };
    for c in analysis.limits.iter().chain(&analysis.intermediate) {
        limits_run::write_curve(&sub, c)?;
    }
    let incomplete = limits_run::analysis_incomplete(analysis);
    limits_run::write_analysis(
        &sub,
        analysis,
        f64::NAN,
        &crate::report::files::status_text(incomplete.as_deref()),
    )
}

/// Most sweep points named in an incomplete sweep's status (all are in `sweep.json`).
const STATUS_POINTS: usize = 5;

/// Why a sweep did not cover every value and case: per point in sweep order, its cases that
/// failed or did not reach the end frequency ([`SweepPoint::failures`]: limit and intermediate
/// cases, and with `output = "limits"` the scanned ones); `None` when every point is complete.
/// Lists the first [`STATUS_POINTS`] points and counts the others.
fn sweep_incomplete(spec: &SweepSpec, points: &[SweepPoint]) -> Option<String> {
    let lines: Vec<String> = points
        .iter()
        .filter(|p| !p.failures.is_empty())
        .map(|p| {
            format!(
                "{}: {}",
                point_label(spec, p.series, p.value),
                p.failures.join("; ")
            )
        })
        .collect();
    if lines.is_empty() {
        return None;
    }
    let mut text = format!(
        "{} of {} sweep points not covered: {}",
        lines.len(),
        points.len(),
        lines[..lines.len().min(STATUS_POINTS)].join(" | ")
    );
    if lines.len() > STATUS_POINTS {
        text.push_str(&format!(
            " | ... and {} more (see sweep.json)",
            lines.len() - STATUS_POINTS
        ));
    }
    Some(text)
}

/// Runs the sweep of the context's scene.
pub fn run_sweep(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let spec = ctx
        .scene
        .sweep
        .clone()
        .expect("called for scenes with [sweep]");
    let series_name = spec.series.as_ref().map(|s| s.parameter.as_str());
    let total = sweep::sweep_points(&spec).len();
    let bar = ctx.progress(total as u64);
    let finished: Mutex<(Vec<SweepPoint>, Option<CommandError>)> = Mutex::new((Vec::new(), None));
    let started = std::time::Instant::now();
    let result = sweep::run_with_problems(
        &ctx.scene_text,
        &ctx.label,
        &ctx.options.overrides,
        &spec,
        |point, scene, problem, limits| {
            let written = write_point_analysis(ctx, &spec, point, (scene, problem, limits));
            let mut guard = finished.lock().expect("no panics while holding the lock");
            if let Err(e) = written {
                guard.1.get_or_insert(e);
            }
            guard.0.push(point.clone());
            let mut tables = vec![(
                "sweep.csv",
                limit_files::sweep_csv(series_name, &spec.parameter, &guard.0),
            )];
            if spec.output == SweepOutput::Limits {
                tables.push((
                    "variability.csv",
                    limit_files::variability_csv(series_name, &spec.parameter, &guard.0),
                ));
            }
            for (name, text) in tables {
                if let Err(e) = files::write_atomic(&ctx.dir.join(name), text.as_bytes()) {
                    guard.1.get_or_insert(e.into());
                }
            }
            if let Some(bar) = &bar {
                bar.inc(1);
                bar.set_message(point_label(&spec, point.series, point.value));
                for f in &point.failures {
                    bar.println(format!(
                        "{}: {f}",
                        point_label(&spec, point.series, point.value)
                    ));
                }
            }
        },
    );
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let points = result.map_err(|source| CommandError::Sweep {
        scene: ctx.label.clone(),
        source: Box::new(source),
    })?;
    if let Some(e) = finished.into_inner().expect("lock not poisoned").1 {
        return Err(e);
    }
    // The streamed tables are in completion order; rewrite them in sweep order.
    files::write_atomic(
        &ctx.dir.join("sweep.csv"),
        limit_files::sweep_csv(series_name, &spec.parameter, &points).as_bytes(),
    )?;
    if spec.output == SweepOutput::Limits {
        files::write_atomic(
            &ctx.dir.join("variability.csv"),
            limit_files::variability_csv(series_name, &spec.parameter, &points).as_bytes(),
        )?;
    }
    let elapsed = started.elapsed().as_secs_f64();
    let variability: Vec<_> = points
        .iter()
        .map(|p| p.analysis.as_ref().map(|a| a.variability()))
        .collect();
    let incomplete = sweep_incomplete(&spec, &points);
    let json = serde_json::json!({
        "info": ctx.info(),
        "status": crate::report::files::status_text(incomplete.as_deref()),
        "elapsed_s": elapsed,
        "parameter": spec.parameter,
        "unit": spec.unit,
        "targets": spec.targets,
        "series": spec.series,
        "output": spec.output,
        "peaks_from": sweep::peaks_from(&ctx.problem),
        "points": points,
        "variability": variability,
    });
    files::write_atomic(
        &ctx.dir.join("sweep.json"),
        &serde_json::to_vec_pretty(&json).expect("JSON values serialise"),
    )?;
    plot_peaks(ctx, &spec, &points)?;
    if spec.output == SweepOutput::Limits {
        plot_bands(ctx, &spec, &points)?;
    }
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary: summary(&spec, &points, elapsed, sweep::peaks_from(&ctx.problem)),
        incomplete,
        outcome: RunOutcome::Sweep(points),
        open: ctx.open.clone(),
        stuck: ctx.stuck.clone(),
    })
}

/// A few lines on a finished sweep: its size and time, the largest limit-peak ratio and how
/// many points have failed cases.
fn summary(spec: &SweepSpec, points: &[SweepPoint], elapsed: f64, peaks_from: &str) -> String {
    use std::fmt::Write as _;
    let mut s = format!(
        "sweep of {} over {} points in {elapsed:.2} s (peaks {peaks_from})",
        spec.parameter,
        points.len()
    );
    let ratio = points
        .iter()
        .filter_map(|p| p.limit_amplitudes().map(|(hi, lo)| (hi / lo, p)))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((r, p)) = ratio {
        let _ = write!(
            s,
            "; largest ratio of the limit peaks {r:.3} at {}",
            point_label(spec, p.series, p.value)
        );
    }
    let failed: usize = points.iter().filter(|p| !p.failures.is_empty()).count();
    if failed > 0 {
        let _ = write!(
            s,
            "\n  {failed} of {} points have failed or incomplete cases (see sweep.csv)",
            points.len()
        );
    }
    s
}

/// The sweep points of one series value (all points without a series), in sweep order.
fn by_series(spec: &SweepSpec, points: &[SweepPoint]) -> Vec<(Option<f64>, Vec<SweepPoint>)> {
    let series: Vec<Option<f64>> = match &spec.series {
        Some(s) => s.values.iter().map(|&v| Some(v)).collect(),
        None => vec![None],
    };
    series
        .into_iter()
        .map(|s| {
            (
                s,
                points.iter().filter(|p| p.series == s).cloned().collect(),
            )
        })
        .collect()
}

/// `optimal_<dof>` (resonance-peak amplitude vs the parameter) and `resonance_<dof>`
/// (resonance frequency vs the parameter), with the band between the limit cases; with a
/// series, one band and one pair of limit lines per series value.
fn plot_peaks(
    ctx: &RunContext<'_>,
    spec: &SweepSpec,
    points: &[SweepPoint],
) -> Result<(), CommandError> {
    let Some(first) = points.first() else {
        return Ok(());
    };
    let x_label = if spec.unit.is_empty() {
        spec.parameter.clone()
    } else {
        format!("{} ({})", spec.parameter, spec.unit)
    };
    let output = &ctx.problem.model.dof_names[ctx.problem.outputs[0]];
    let groups = by_series(spec, points);
    for (amplitude, log_y, y_label, file) in [
        (
            true,
            true,
            format!("{output} resonance-peak first-harmonic amplitude (m)"),
            "optimal",
        ),
        (
            false,
            false,
            "resonance frequency (Hz)".to_string(),
            "resonance",
        ),
    ] {
        let value =
            |p: &SweepPoint, c: usize| {
                p.peaks[c].as_ref().map_or(f64::NAN, |q| {
                    if amplitude {
                        q.amplitude
                    } else {
                        q.freq_hz
                    }
                })
            };
        struct Group {
            label: String,
            x: Vec<f64>,
            ys: Vec<Vec<f64>>,
            lower: Vec<f64>,
            upper: Vec<f64>,
        }
        let limits = first.limit_cases.clamp(1, first.cases.len());
        let data: Vec<Group> = groups
            .iter()
            .map(|(s, pts)| {
                let label = match (&spec.series, s) {
                    (Some(sp), Some(v)) => parameter_label(&sp.parameter, &sp.unit, *v),
                    _ => String::new(),
                };
                let x = pts.iter().map(|p| p.value).collect();
                let ys: Vec<Vec<f64>> = (0..first.cases.len())
                    .map(|c| pts.iter().map(|p| value(p, c)).collect())
                    .collect();
                // The band spans the limit cases (two for a forced response, every sign
                // combination per damper side for a nonlinear mode); none where one failed.
                let range = |p: &SweepPoint| {
                    if amplitude {
                        p.limit_amplitudes()
                    } else {
                        p.limit_frequencies()
                    }
                    .unwrap_or((f64::NAN, f64::NAN))
                };
                let lower = pts.iter().map(|p| range(p).1).collect();
                let upper = pts.iter().map(|p| range(p).0).collect();
                Group {
                    label,
                    x,
                    ys,
                    lower,
                    upper,
                }
            })
            .collect();
        let series = spec.series.is_some();
        // With a series the limit lines carry the legend; the bands share their colours.
        let bands: Vec<BandSpec> = data
            .iter()
            .enumerate()
            .map(|(i, g)| {
                if series {
                    group_band(i, &g.x, &g.lower, &g.upper)
                } else {
                    BandSpec::variability(&g.x, &g.lower, &g.upper)
                }
            })
            .collect();
        let mut labels = Vec::new();
        let mut specs = Vec::new();
        for (gi, g) in data.iter().enumerate() {
            for (c, name) in first.cases.iter().enumerate() {
                if series && c >= limits {
                    continue;
                }
                let kind = if c < limits { "limit" } else { "intermediate" };
                labels.push(if series {
                    format!("{}: {kind} {name}", g.label)
                } else {
                    format!("{kind} {name}")
                });
                specs.push((gi, c));
            }
        }
        let mut curves: Vec<Curve> = specs
            .iter()
            .zip(&labels)
            .map(|(&(gi, c), label)| Curve {
                label,
                x: &data[gi].x,
                y: &data[gi].ys[c],
                color: if series { palette(gi) } else { palette(c) },
                dashed: if series { c % 2 == 1 } else { c >= limits },
                markers: true,
            })
            .collect();
        // The linear references' resonance in the peak window, as levels the limits start
        // from and tend to (valid for every value when only static loads are swept).
        let window = ctx.limits.as_ref().and_then(|l| l.peak_window_hz);
        let x_span: Vec<f64> = {
            let xs = data.iter().flat_map(|g| g.x.iter().copied());
            let lo = xs.clone().fold(f64::INFINITY, f64::min);
            let hi = xs.fold(f64::NEG_INFINITY, f64::max);
            vec![lo, hi]
        };
        let references: Vec<(String, Vec<f64>, plotters::style::RGBColor)> =
            if only_static_loads(spec) {
                [
                    (
                        &ctx.open,
                        "linear, contacts open",
                        plotters::style::RGBColor(140, 140, 140),
                    ),
                    (
                        &ctx.stuck,
                        "linear, contacts stuck",
                        plotters::style::RGBColor(40, 40, 40),
                    ),
                ]
                .into_iter()
                .filter_map(|(curve, name, color)| {
                    let (f, a) = crate::analysis::limits::linear_resonance(curve, 0, window)?;
                    let (v, text) = if amplitude {
                        (a, format!("{name}: resonance peak"))
                    } else {
                        (f, format!("{name}: resonance"))
                    };
                    Some((text, vec![v, v], color))
                })
                .collect()
            } else {
                Vec::new()
            };
        for (label, y, color) in &references {
            curves.push(Curve {
                label,
                x: &x_span,
                y,
                color: *color,
                dashed: true,
                markers: false,
            });
        }
        let title = format!(
            "{}: {} vs {}",
            ctx.title(),
            if amplitude {
                "resonance-peak amplitude"
            } else {
                "resonance frequency"
            },
            spec.parameter
        );
        let fig = SweepFigure {
            title: &title,
            x_label: &x_label,
            y_label: &y_label,
            log_y,
            bands: &bands,
            curves: &curves,
        };
        let (png, svg) = figure_files(&ctx.dir, &format!("{file}_{output}"));
        plot_sweep(&fig, &png, &svg)?;
    }
    Ok(())
}

/// `bands_<dof>`: the FRF band between the two limit curves of every sweep value on one chart
/// (one chart per series value: `bands_<dof>_<series>_<value>`).
fn plot_bands(
    ctx: &RunContext<'_>,
    spec: &SweepSpec,
    points: &[SweepPoint],
) -> Result<(), CommandError> {
    // The band on the grid is of the first output DOF (as the peaks).
    let problem = &ctx.problem;
    let k = 0;
    let output = &problem.model.dof_names[problem.outputs[k]];
    for (s, pts) in by_series(spec, points) {
        struct Data {
            x: Vec<f64>,
            lower: Vec<f64>,
            upper: Vec<f64>,
            curves: Vec<(String, Vec<f64>, Vec<f64>)>,
        }
        let data: Vec<Data> = pts
            .iter()
            .filter_map(|p| {
                let a = p.analysis.as_ref()?;
                let label = point_label(spec, None, p.value);
                let curves = a
                    .limits
                    .iter()
                    .map(|c| {
                        (
                            format!("{label}: limit {}", c.case.name),
                            c.points.iter().map(|q| q.freq_hz).collect(),
                            c.points.iter().map(|q| q.amplitudes[k]).collect(),
                        )
                    })
                    .collect();
                Some(Data {
                    x: a.grid.iter().map(|g| g.freq_hz).collect(),
                    lower: a.grid.iter().map(|g| g.lower).collect(),
                    upper: a.grid.iter().map(|g| g.upper).collect(),
                    curves,
                })
            })
            .collect();
        if data.is_empty() {
            continue;
        }
        // The limit lines carry the legend; each band shares its lines' colour.
        let bands: Vec<BandSpec> = data
            .iter()
            .enumerate()
            .map(|(i, d)| group_band(i, &d.x, &d.lower, &d.upper))
            .collect();
        let mut curves: Vec<Curve> = Vec::new();
        for (i, d) in data.iter().enumerate() {
            for (j, (label, x, y)) in d.curves.iter().enumerate() {
                curves.push(Curve {
                    label,
                    x,
                    y,
                    color: palette(i),
                    dashed: j == 1,
                    markers: false,
                });
            }
        }
        let open_y: Vec<f64> = ctx.open.amplitudes.iter().map(|r| r[k]).collect();
        let stuck_y: Vec<f64> = ctx.stuck.amplitudes.iter().map(|r| r[k]).collect();
        if only_static_loads(spec) {
            curves.push(Curve {
                label: "linear, contacts stuck",
                x: &ctx.stuck.freqs_hz,
                y: &stuck_y,
                color: plotters::style::RGBColor(40, 40, 40),
                dashed: true,
                markers: false,
            });
            curves.push(Curve {
                label: "linear, contacts open",
                x: &ctx.open.freqs_hz,
                y: &open_y,
                color: plotters::style::RGBColor(140, 140, 140),
                dashed: true,
                markers: false,
            });
        }
        let (suffix, series_label) = match (&spec.series, s) {
            (Some(sp), Some(v)) => (
                format!("_{}_{}", sp.parameter, value_text(v)),
                format!(", {} = {} {}", sp.parameter, value_text(v), sp.unit),
            ),
            _ => (String::new(), String::new()),
        };
        let title = format!("{}{series_label}", ctx.title());
        let y_label = format!("{output} first-harmonic amplitude (m)");
        let fig = SweepFigure {
            title: &title,
            x_label: "frequency (Hz)",
            y_label: &y_label,
            log_y: true,
            bands: &bands,
            curves: &curves,
        };
        let (png, svg) = figure_files(&ctx.dir, &format!("bands_{output}{suffix}"));
        plot_sweep(&fig, &png, &svg)?;
    }
    Ok(())
}

/// The band of group `i` (a series value, or a sweep value on the bands chart) in the colour
/// of its limit lines, [`palette`]`(i)`, without a legend entry: the lines carry the legend.
fn group_band<'a>(i: usize, x: &'a [f64], lower: &'a [f64], upper: &'a [f64]) -> BandSpec<'a> {
    BandSpec {
        label: "",
        color: palette(i),
        ..BandSpec::variability(x, lower, upper)
    }
}

/// Whether the sweep moves static loads only: then the scene's linear references (which do not
/// depend on static loads) belong to every band; otherwise each value has its own, in its
/// folder.
fn only_static_loads(spec: &SweepSpec) -> bool {
    spec.targets
        .iter()
        .chain(spec.series.iter().flat_map(|s| &s.targets))
        .all(|t| t.field.starts_with("static_loads"))
}
