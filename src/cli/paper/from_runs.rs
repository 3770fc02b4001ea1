//! The key numbers computed from the runs of `fricbound paper` ([`key_numbers`]): every number
//! of the summary comes from the figures' results; nothing is typed in.
//!
//! Peaks are the refined resonance peaks of the first output DOF (y2) in each scene's peak
//! window; a sweep value whose limit peak is not an interior maximum, or whose curve failed, is
//! left out of maxima and rankings and listed instead.

use super::figures::{EnvelopeUse, FigureJob, FigureResult};
use super::numbers::{
    AnalysisRow, BetaRow, BoundRow, EnvelopeRow, KeyNumbers, Located, LoopRow, ResonanceEnds,
    SweepRow,
};
use crate::analysis::limits::LimitAnalysis;
use crate::analysis::linear::LinearCurve;
use crate::cli::context::RunOutcome;
use crate::cli::sweep_run::parameter_label;
use crate::scene::SweepSpec;
use crate::study::sweep::SweepPoint;

/// Relative tolerance below which two resonance peaks count as equal: the peak amplitude of a
/// curve is resolved to about 1e-4 where contacts lift off (state changes snap to the AFT
/// samples, which puts ripples of that size on the amplitude along the path).
pub const PEAK_TOLERANCE: f64 = 1e-3;

/// The run of figure `id`, if it is among `figures`.
fn find<'a>(figures: &'a [FigureResult], id: &str) -> Option<&'a FigureResult> {
    figures.iter().find(|f| f.job.id == id)
}

/// The sweep points of figure `id`, if it ran as a sweep.
fn sweep_of<'a>(figures: &'a [FigureResult], id: &str) -> Option<&'a [SweepPoint]> {
    match &find(figures, id)?.report()?.outcome {
        RunOutcome::Sweep(points) => Some(points),
        _ => None,
    }
}

/// The limit analysis of figure `id`, if it ran as a single analysis.
fn analysis_of<'a>(figures: &'a [FigureResult], id: &str) -> Option<&'a LimitAnalysis> {
    match &find(figures, id)?.report()?.outcome {
        RunOutcome::Limits(a) => Some(a),
        _ => None,
    }
}

/// Resonance frequencies of a linear reference: local maxima of the first output (Hz).
fn resonances(curve: &LinearCurve) -> Vec<f64> {
    let a: Vec<f64> = curve.amplitudes.iter().map(|r| r[0]).collect();
    (1..a.len().saturating_sub(1))
        .filter(|&i| a[i] > a[i - 1] && a[i] >= a[i + 1])
        .map(|i| curve.freqs_hz[i])
        .collect()
}

/// The row of one limit analysis of figure `figure` (at sweep point `at`, value `value`):
/// limit peaks, their ratio and frequency change, band, states and bound check. `None` unless
/// every case of the analysis covered the range (an unfinished analysis has no numbers to
/// compare with the paper; its cases are listed as failures).
fn analysis_row(
    figure: &str,
    at: String,
    value: Option<f64>,
    a: &LimitAnalysis,
) -> Option<AnalysisRow> {
    if !a.is_complete() {
        return None;
    }
    let v = a.variability();
    let (p, q) = (a.limits[0].peak.as_ref()?, a.limits[1].peak.as_ref()?);
    let (up, lo) = if p.amplitude >= q.amplitude {
        ((&a.limits[0].case, p), (&a.limits[1].case, q))
    } else {
        ((&a.limits[1].case, q), (&a.limits[0].case, p))
    };
    let intermediate_peaks: Vec<(&str, &crate::analysis::limits::Peak)> = a
        .intermediate
        .iter()
        .filter_map(|c| Some((c.case.name.as_str(), c.peak.as_ref()?)))
        .collect();
    let peak_states = [(&a.limits[0].case, p), (&a.limits[1].case, q)]
        .iter()
        .map(|(case, peak)| {
            format!(
                "{}: {}",
                case.name,
                peak.states
                    .iter()
                    .map(|s| s.label())
                    .collect::<Vec<_>>()
                    .join(" / ")
            )
        })
        .collect();
    // A side stuck at every grid frequency in both limit curves (paper Fig. 14a).
    let always_stuck_side = (0..p.states.len())
        .find(|&contact| {
            !a.grid.is_empty()
                && a.grid.iter().all(|g| {
                    g.states.iter().all(|s| {
                        s.get(contact)
                            .is_some_and(|&x| x == crate::contact::ContactState::Stuck)
                    })
                })
        })
        .map(|c| format!("contact {}", c + 1));
    let (hi, low) = (v.upper_peak, v.lower_peak);
    let intermediates_outside = intermediate_peaks
        .iter()
        .filter(|(_, c)| {
            c.amplitude > hi * (1.0 + PEAK_TOLERANCE) || c.amplitude < low * (1.0 - PEAK_TOLERANCE)
        })
        .map(|(name, c)| format!("{name} ({:.4e} m)", c.amplitude))
        .collect();
    let bound = a.bounds.as_ref().map(|b| BoundRow {
        above_pct: 100.0 * b.max_excess_above,
        above_at: b.above_at.clone(),
        below_pct: 100.0 * b.max_excess_below,
        below_at: b.below_at.clone(),
        peak_above_pct: 100.0 * b.peak_excess_above,
        peak_below_pct: 100.0 * b.peak_excess_below,
        above_stuck_limit_vs_slipping: b.above_states.as_ref().is_some_and(|st| {
            let upper = if p.amplitude >= q.amplitude { 0 } else { 1 };
            st.limits.get(upper).is_some_and(|l| {
                !l.is_empty() && l.iter().all(|&x| x == crate::contact::ContactState::Stuck)
            }) && st
                .scanned
                .iter()
                .any(|&x| x != crate::contact::ContactState::Stuck)
        }),
    });
    let envelope = a.envelope.as_ref().map(|e| EnvelopeRow {
        sides: e.groups.clone(),
        compared: e.check.compared,
        points_above: e.check.points_above,
        points_below: e.check.points_below,
        above_pct: 100.0 * e.check.max_excess_above,
        above_at: e.check.above_at.clone(),
        below_pct: 100.0 * e.check.max_excess_below,
        below_at: e.check.below_at.clone(),
        peak_above_pct: 100.0 * e.check.peak_excess_above,
        unsolved: e.unsolved,
        solves: e.solves,
        elapsed_s: e.elapsed_s,
    });
    Some(AnalysisRow {
        figure: figure.to_string(),
        at,
        value,
        upper: (up.0.name.clone(), up.1.amplitude, up.1.freq_hz),
        lower: (lo.0.name.clone(), lo.1.amplitude, lo.1.freq_hz),
        ratio: v.peak_ratio,
        freq_change_pct: v.peak_freq_change_pct,
        refined: p.refined && q.refined,
        widest_band: (v.widest_band, v.widest_band_hz),
        multiple_share: v.multiple_points as f64 / v.grid_points.max(1) as f64,
        peak_states,
        always_stuck_side,
        intermediates_outside,
        bound,
        envelope,
    })
}

/// One row per sweep point: the peaks of every case, and the ratio and frequency change of
/// the limit peaks.
fn sweep_rows(points: &[SweepPoint]) -> Vec<SweepRow> {
    points
        .iter()
        .map(|p| {
            let (ratio, freq_change_pct) = match (p.limit_amplitudes(), p.limit_frequencies()) {
                (Some((hi, lo)), Some((fhi, flo))) => (hi / lo, 100.0 * (fhi - flo) / flo),
                _ => (f64::NAN, f64::NAN),
            };
            SweepRow {
                series: p.series,
                value: p.value,
                peaks: p
                    .peaks
                    .iter()
                    .map(|q| q.as_ref().map_or(f64::NAN, |q| q.amplitude))
                    .collect(),
                ratio,
                freq_change_pct,
                refined: p.limits_refined(),
            }
        })
        .collect()
}

/// Parabolic vertex through three points (x, y); the middle x when degenerate.
fn vertex(p: [(f64, f64); 3]) -> f64 {
    let [(x0, y0), (x1, y1), (x2, y2)] = p;
    let d = (x0 - x1) * (x0 - x2) * (x1 - x2);
    let a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
    let b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
    if a > 0.0 && a.is_finite() && b.is_finite() {
        (-b / (2.0 * a)).clamp(x0.min(x2), x0.max(x2))
    } else {
        x1
    }
}

/// Minimum of the resonance peak of case `c` over a sweep: (F0, at a sweep end).
fn optimum(rows: &[SweepRow], c: usize) -> Option<(f64, bool)> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.refined && r.peaks[c].is_finite())
        .map(|r| (r.value, r.peaks[c]))
        .collect();
    let i = (0..pts.len()).min_by(|&i, &j| pts[i].1.total_cmp(&pts[j].1))?;
    if i == 0 || i + 1 == pts.len() {
        return Some((pts[i].0, true));
    }
    Some((vertex([pts[i - 1], pts[i], pts[i + 1]]), false))
}

/// F0 values where the two limit peaks cross (sign change of their difference between swept
/// values where they differ by more than 1 %), by linear interpolation.
fn crossings(rows: &[SweepRow]) -> Vec<f64> {
    let d: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.refined && r.peaks[0].is_finite() && r.peaks[1].is_finite())
        .map(|r| {
            (
                r.value,
                (r.peaks[0] - r.peaks[1]) / r.peaks[0].max(r.peaks[1]),
            )
        })
        .filter(|(_, d)| d.abs() > 0.01)
        .collect();
    d.windows(2)
        .filter(|w| w[0].1.signum() != w[1].1.signum())
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1))
        .collect()
}

/// Keeps `value` in `best` if it is finite and larger (a running maximum with its place).
fn consider(best: &mut Option<Located>, value: f64, figure: &str, at: String) {
    if value.is_finite() && best.as_ref().is_none_or(|b| value > b.value) {
        *best = Some(Located {
            value,
            figure: figure.to_string(),
            at,
        });
    }
}

/// Computes every key number from the figures that ran.
pub fn key_numbers(figures: &[FigureResult]) -> KeyNumbers {
    let mut k = KeyNumbers::default();
    for f in figures {
        match &f.outcome {
            Err(e) => k.failures.push(format!("{}: {e}", f.job.id)),
            // A sweep's failed cases are listed per point below.
            Ok(r) if !matches!(r.outcome, RunOutcome::Sweep(_)) => {
                if let Some(reason) = &r.incomplete {
                    k.failures
                        .push(format!("{}: incomplete: {reason}", f.job.id));
                }
            }
            Ok(_) => {}
        }
    }
    if let Some(r) = find(figures, "fig12").and_then(|f| f.report()) {
        k.linear_resonances_hz = Some((resonances(&r.open), resonances(&r.stuck)));
    }

    // Every limit analysis: single ones and those of sweeps with output = "limits".
    for f in figures {
        let Some(report) = f.report() else { continue };
        match &report.outcome {
            RunOutcome::Limits(a) => {
                k.analyses
                    .extend(analysis_row(f.job.id, String::new(), None, a));
            }
            RunOutcome::Sweep(points) => {
                let spec = sweep_spec(f.job);
                for p in points {
                    for e in &p.failures {
                        k.failures.push(format!(
                            "{} at {} = {}: {e}",
                            f.job.id,
                            sweep_name(&spec),
                            p.value
                        ));
                    }
                    if let Some(a) = &p.analysis {
                        let at = at_label(&spec, p.value);
                        k.analyses
                            .extend(analysis_row(f.job.id, at, Some(p.value), a));
                    }
                }
            }
            RunOutcome::Frf(_) | RunOutcome::NonlinearModes(_) => {}
        }
    }
    // Figures that compute the envelope in the full study, run without it (`--quick`).
    k.envelope_skipped = figures
        .iter()
        .filter(|f| f.report().is_some() && f.job.envelope != EnvelopeUse::Off)
        .filter(|f| {
            !k.analyses
                .iter()
                .any(|r| r.figure == f.job.id && r.envelope.is_some())
        })
        .map(|f| f.job.id.to_string())
        .collect();
    for row in &k.analyses {
        if row.refined {
            let at = if row.at.is_empty() {
                "F0 as in the scene".to_string()
            } else {
                row.at.clone()
            };
            consider(&mut k.max_peak_ratio, row.ratio, &row.figure, at.clone());
            consider(
                &mut k.max_freq_change_pct,
                row.freq_change_pct,
                &row.figure,
                at,
            );
        }
    }

    // Optimal curves over F0 (Figs. 16a, 16b, 16d).
    if let Some(points) = sweep_of(figures, "fig16a-d") {
        k.f0_sweep = sweep_rows(points);
        let best = |key: fn(&SweepRow) -> f64| {
            k.f0_sweep
                .iter()
                .filter(|r| r.refined && key(r).is_finite())
                .max_by(|a, b| key(a).total_cmp(&key(b)))
                .map(|r| (key(r), r.value))
        };
        k.f0_sweep_max_ratio = best(|r| r.ratio);
        k.f0_sweep_max_freq_change_pct = best(|r| r.freq_change_pct);
        for r in k.f0_sweep.iter().filter(|r| r.refined) {
            let at = format!("F0 = {} N", r.value);
            consider(&mut k.max_peak_ratio, r.ratio, "fig16a-d", at.clone());
            consider(
                &mut k.max_freq_change_pct,
                r.freq_change_pct,
                "fig16a-d",
                at,
            );
        }
        let mut sorted: Vec<&SweepRow> =
            k.f0_sweep.iter().filter(|r| r.ratio.is_finite()).collect();
        sorted.sort_by(|a, b| a.value.total_cmp(&b.value));
        let unique: Vec<&&SweepRow> = sorted.iter().take_while(|r| r.ratio < 1.01).collect();
        if let Some(last) = unique.last() {
            k.unique_up_to_f0 = Some((last.value, sorted.get(unique.len()).map(|r| r.value)));
        }
        let stuck = find(figures, "fig16a-d")
            .and_then(|f| f.report())
            .and_then(|r| {
                crate::analysis::limits::linear_resonance(&r.stuck, 0, Some((190.0, 235.0)))
            });
        if let (Some(top), Some((stuck_hz, stuck_amp))) = (sorted.last(), stuck) {
            let (hi, lo) = (
                top.peaks[0].max(top.peaks[1]),
                top.peaks[0].min(top.peaks[1]),
            );
            k.high_f0_over_stuck = Some((top.value, hi / stuck_amp, lo / stuck_amp));
            let freqs = |r: &SweepRow| {
                points
                    .iter()
                    .find(|p| p.value == r.value)
                    .and_then(|p| p.limit_frequencies())
            };
            if let (Some(low), Some(high)) = (sorted.first().and_then(|r| freqs(r)), freqs(top)) {
                k.f0_sweep_frequencies = Some(ResonanceEnds {
                    smallest_f0: low,
                    largest_f0: high,
                    stuck: stuck_hz,
                });
            }
        }
    }
    if let Some(points) = sweep_of(figures, "fig16b") {
        k.f0_fine = sweep_rows(points);
        k.f0_fine_cases = points.first().map(|p| p.cases.clone()).unwrap_or_default();
        for r in &k.f0_fine {
            let (hi, lo) = (r.peaks[0].max(r.peaks[1]), r.peaks[0].min(r.peaks[1]));
            if r.refined
                && r.peaks[2..]
                    .iter()
                    .any(|&p| p > hi * (1.0 + PEAK_TOLERANCE) || p < lo * (1.0 - PEAK_TOLERANCE))
            {
                k.intermediates_outside_f0.push(r.value);
            }
        }
    }
    // The fine sweep locates the crossing and the optima best; the coarse one otherwise.
    let (rows, cases): (&[SweepRow], Vec<String>) = if !k.f0_fine.is_empty() {
        (&k.f0_fine, k.f0_fine_cases.clone())
    } else {
        (
            &k.f0_sweep,
            sweep_of(figures, "fig16a-d")
                .and_then(|p| p.first())
                .map(|p| p.cases.clone())
                .unwrap_or_default(),
        )
    };
    k.limit_peaks_cross_f0 = crossings(rows);
    if k.limit_peaks_cross_f0.is_empty() && !k.f0_fine.is_empty() {
        k.limit_peaks_cross_f0 = crossings(&k.f0_sweep);
    }
    k.optimum_f0 = cases
        .iter()
        .enumerate()
        .filter_map(|(c, name)| optimum(rows, c).map(|(f0, end)| (name.clone(), f0, end)))
        .collect();

    // Apical angles.
    let beta_frf = |id: &str| -> Vec<BetaRow> {
        k.analyses
            .iter()
            .filter(|r| r.figure == id && r.refined)
            .filter_map(|r| {
                Some(BetaRow {
                    beta: r.value?,
                    ratio: r.ratio,
                    at: String::new(),
                    widest_band: Some(r.widest_band.0),
                })
            })
            .collect()
    };
    k.beta_high_frf = beta_frf("fig18a");
    k.beta_low_frf = beta_frf("fig19a");
    let beta_sweep = |id: &str, k: &mut KeyNumbers| -> (Vec<BetaRow>, Vec<(f64, f64, f64)>) {
        let Some(points) = sweep_of(figures, id) else {
            return (Vec::new(), Vec::new());
        };
        let spec = find(figures, id).and_then(|f| sweep_spec(f.job));
        let rows = sweep_rows(points);
        let mut betas: Vec<f64> = rows.iter().filter_map(|r| r.series).collect();
        betas.sort_by(f64::total_cmp);
        betas.dedup();
        let mut out = Vec::new();
        let mut spread = Vec::new();
        for b in betas {
            let of_b: Vec<&SweepRow> = rows
                .iter()
                .filter(|r| r.series == Some(b) && r.refined && r.ratio.is_finite())
                .collect();
            let Some(best) = of_b.iter().max_by(|x, y| x.ratio.total_cmp(&y.ratio)) else {
                continue;
            };
            let at = at_label(&spec, best.value);
            consider(
                &mut k.max_peak_ratio,
                best.ratio,
                id,
                format!("beta = {b} deg, {at}"),
            );
            for r in &of_b {
                let at = at_label(&spec, r.value);
                consider(
                    &mut k.max_freq_change_pct,
                    r.freq_change_pct,
                    id,
                    format!("beta = {b} deg, {at}"),
                );
            }
            let min = of_b.iter().map(|r| r.ratio).fold(f64::INFINITY, f64::min);
            spread.push((b, min, best.ratio));
            out.push(BetaRow {
                beta: b,
                ratio: best.ratio,
                at,
                widest_band: None,
            });
        }
        (out, spread)
    };
    let (high, _) = beta_sweep("fig18b", &mut k);
    k.beta_high_optimal = high;
    let (low, spread) = beta_sweep("fig19b", &mut k);
    k.beta_low_pseudo = low;
    k.beta_low_pseudo_spread = spread;

    // Hysteresis at resonance (Fig. 16c).
    if let Some(a) = analysis_of(figures, "fig16c") {
        k.loops = a
            .loops
            .iter()
            .map(|set| LoopRow {
                case: set.case.clone(),
                freq_hz: set.freq_hz,
                amplitude: set.amplitude,
                energy: set
                    .loops
                    .iter()
                    .map(|l| (l.contact.clone(), l.dissipated_energy()))
                    .collect(),
            })
            .collect();
    }
    k
}

/// The `[sweep]` of a figure's scene as written (without the `--quick` overrides).
fn sweep_spec(job: &FigureJob) -> Option<SweepSpec> {
    crate::scene::parse(job.text, job.id, &[])
        .ok()
        .and_then(|s| s.sweep)
}

/// Name of the swept parameter, for messages ("value" without a sweep).
fn sweep_name(spec: &Option<SweepSpec>) -> String {
    spec.as_ref()
        .map_or("value".to_string(), |s| s.parameter.clone())
}

/// Where a sweep point is, e.g. `F0 = 60 N` (empty without a sweep).
fn at_label(spec: &Option<SweepSpec>, v: f64) -> String {
    spec.as_ref()
        .map_or(String::new(), |s| parameter_label(&s.parameter, &s.unit, v))
}
