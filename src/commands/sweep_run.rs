//! `fricbound run` on a scene with `[sweep]`: the limit analysis' refined peaks at every
//! parameter value (optimal curves, resonance-frequency limits), streamed to `sweep.csv` as
//! values finish, then `sweep.json` and figures.

use std::sync::Mutex;

use super::{CommandError, RunContext, RunReport};
use crate::report::files;
use crate::report::limit_files;
use crate::report::limit_plots::{self, palette, Curve, SweepFigure};
use crate::sweep::{self, SweepPoint};

/// Runs the sweep of the context's scene.
pub fn run_sweep(ctx: &RunContext<'_>) -> Result<RunReport, CommandError> {
    let spec = ctx
        .scene
        .sweep
        .clone()
        .expect("called for scenes with [sweep]");
    let bar = ctx.progress(spec.values.len() as u64);
    let finished: Mutex<(Vec<SweepPoint>, Option<CommandError>)> = Mutex::new((Vec::new(), None));
    let path = ctx.dir.join("sweep.csv");
    let started = std::time::Instant::now();
    let result = sweep::run(
        &ctx.scene_text,
        &ctx.label,
        &ctx.options.overrides,
        &spec,
        |point| {
            let mut guard = finished.lock().expect("no panics while holding the lock");
            guard.0.push(point.clone());
            let text = limit_files::sweep_csv(&spec.parameter, &guard.0);
            if let Err(e) = files::write_atomic(&path, text.as_bytes()) {
                guard.1.get_or_insert(e.into());
            }
            if let Some(bar) = &bar {
                bar.inc(1);
                bar.set_message(format!("{} = {}", spec.parameter, point.value));
            }
        },
    );
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let points = result.map_err(|source| CommandError::Sweep {
        scene: ctx.label.clone(),
        source,
    })?;
    if let Some(e) = finished.into_inner().expect("lock not poisoned").1 {
        return Err(e);
    }
    let elapsed = started.elapsed().as_secs_f64();
    let json = serde_json::json!({
        "info": ctx.info(),
        "status": "complete",
        "elapsed_s": elapsed,
        "parameter": spec.parameter,
        "unit": spec.unit,
        "targets": spec.targets,
        "points": points,
    });
    files::write_atomic(
        &ctx.dir.join("sweep.json"),
        &serde_json::to_vec_pretty(&json).expect("JSON values serialise"),
    )?;
    plot(ctx, &spec, &points)?;
    let ratio = points
        .iter()
        .map(|p| {
            let (hi, lo) = p.limit_amplitudes();
            (hi / lo, p.value)
        })
        .fold((0.0, f64::NAN), |a, b| if b.0 > a.0 { b } else { a });
    Ok(RunReport {
        dir: ctx.dir.clone(),
        summary: format!(
            "sweep of {} over {} values in {elapsed:.2} s; largest ratio of the limit peaks {:.3} at {} = {} {}",
            spec.parameter,
            points.len(),
            ratio.0,
            spec.parameter,
            ratio.1,
            spec.unit
        ),
    })
}

fn plot(
    ctx: &RunContext<'_>,
    spec: &crate::scene::SweepSpec,
    points: &[SweepPoint],
) -> Result<(), CommandError> {
    let Some(first) = points.first() else {
        return Ok(());
    };
    let x: Vec<f64> = points.iter().map(|p| p.value).collect();
    let x_label = if spec.unit.is_empty() {
        spec.parameter.clone()
    } else {
        format!("{} ({})", spec.parameter, spec.unit)
    };
    let output = &ctx.problem.model.dof_names[ctx.problem.outputs[0]];
    for (kind, log_y, y_label, file) in [
        (
            0,
            true,
            format!("{output} peak first-harmonic amplitude (m)"),
            "optimal",
        ),
        (
            1,
            false,
            "resonance frequency (Hz)".to_string(),
            "resonance",
        ),
    ] {
        let value = |p: &SweepPoint, c: usize| {
            if kind == 0 {
                p.peaks[c].amplitude
            } else {
                p.peaks[c].freq_hz
            }
        };
        let ys: Vec<Vec<f64>> = (0..first.cases.len())
            .map(|c| points.iter().map(|p| value(p, c)).collect())
            .collect();
        let lower: Vec<f64> = points
            .iter()
            .map(|p| value(p, 0).min(value(p, 1)))
            .collect();
        let upper: Vec<f64> = points
            .iter()
            .map(|p| value(p, 0).max(value(p, 1)))
            .collect();
        let labels: Vec<String> = first
            .cases
            .iter()
            .enumerate()
            .map(|(i, c)| {
                if i < 2 {
                    format!("limit {c}")
                } else {
                    format!("intermediate {c}")
                }
            })
            .collect();
        let curves: Vec<Curve> = ys
            .iter()
            .enumerate()
            .map(|(i, y)| Curve {
                label: &labels[i],
                x: &x,
                y,
                color: palette(i),
                dashed: i >= 2,
                markers: true,
            })
            .collect();
        let title = format!(
            "{}: {} vs {}",
            ctx.title(),
            if kind == 0 {
                "peak amplitude"
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
            band: Some((&x, &lower, &upper)),
            curves: &curves,
        };
        limit_plots::plot_sweep(
            &fig,
            &ctx.dir.join(format!("{file}_{output}.png")),
            &ctx.dir.join(format!("{file}_{output}.svg")),
        )?;
    }
    Ok(())
}
