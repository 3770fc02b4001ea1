//! The key numbers of the paper's §4 study, computed from the runs of `fricbound paper`, and
//! `summary.md`, which sets each next to the paper's own statement and says whether they agree.
//!
//! Nothing here is typed in but the paper's statements and the criteria of agreement: every
//! number comes from the figures' results ([`key_numbers`]). Peaks are the refined resonance
//! peaks of the first output DOF (y2) in each scene's peak window; a sweep value whose limit
//! peak is not an interior maximum, or whose curve failed, is left out of maxima and rankings
//! and listed instead.

use std::fmt::Write as _;

use serde::Serialize;

use crate::analysis::limits::LimitAnalysis;
use crate::analysis::linear::LinearCurve;
use crate::cli::paper::FigureResult;
use crate::cli::RunOutcome;
use crate::study::sweep::SweepPoint;

/// Relative tolerance below which two resonance peaks count as equal: the peak amplitude of a
/// curve is resolved to about 1e-4 where contacts lift off (state changes snap to the AFT
/// samples, which puts ripples of that size on the amplitude along the path).
pub const PEAK_TOLERANCE: f64 = 1e-3;

/// A number and where it was found.
#[derive(Debug, Clone, Serialize)]
pub struct Located {
    /// The value.
    pub value: f64,
    /// Figure identifier.
    pub figure: String,
    /// Parameter values, e.g. `beta = 90 deg, F0 = 500 N`.
    pub at: String,
}

/// Bound check of one limit analysis (in % of the limit there).
#[derive(Debug, Clone, Serialize)]
pub struct BoundRow {
    /// Largest excess of a scanned curve above the upper limit, pointwise (%).
    pub above_pct: f64,
    /// Where: frequency (Hz) and scanned case.
    pub above_at: Option<(f64, String)>,
    /// Largest excess below the lower limit, pointwise (%).
    pub below_pct: f64,
    /// Where: frequency (Hz) and scanned case.
    pub below_at: Option<(f64, String)>,
    /// Largest scanned resonance peak above the larger limit peak (%).
    pub peak_above_pct: f64,
    /// Smallest scanned resonance peak below the smaller limit peak (%).
    pub peak_below_pct: f64,
    /// At the largest excess above: every limit curve fully stuck while the scanned state
    /// slips (the mechanism described in the summary).
    pub above_stuck_limit_vs_slipping: bool,
}

/// One limit analysis of the study.
#[derive(Debug, Clone, Serialize)]
pub struct AnalysisRow {
    /// Figure identifier.
    pub figure: String,
    /// Sweep point (empty for a single analysis).
    pub at: String,
    /// Swept parameter value, if any.
    pub value: Option<f64>,
    /// Limit case with the larger resonance peak, its peak (m) and frequency (Hz).
    pub upper: (String, f64, f64),
    /// Limit case with the smaller resonance peak, its peak (m) and frequency (Hz).
    pub lower: (String, f64, f64),
    /// Ratio of the limit peaks.
    pub ratio: f64,
    /// Resonance-frequency change between the limit peaks (%).
    pub freq_change_pct: f64,
    /// Whether both limit peaks are interior maxima.
    pub refined: bool,
    /// Widest band (m) and its frequency (Hz).
    pub widest_band: (f64, f64),
    /// Share of grid frequencies with multiple solutions.
    pub multiple_share: f64,
    /// Contact states at each limit peak, `case: contact state, ...`.
    pub peak_states: Vec<String>,
    /// Whether every grid point has the same side stuck in both limit curves, and which.
    pub always_stuck_side: Option<String>,
    /// Intermediate curves whose resonance peak lies outside the two limit peaks.
    pub intermediates_outside: Vec<String>,
    /// Bound check, when the scene asked for a scan.
    pub bound: Option<BoundRow>,
}

/// One value of a peak sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SweepRow {
    /// Series value, if any.
    pub series: Option<f64>,
    /// Parameter value.
    pub value: f64,
    /// Resonance peak per case (m); NaN where it failed.
    pub peaks: Vec<f64>,
    /// Ratio of the limit peaks (NaN if missing).
    pub ratio: f64,
    /// Frequency change between the limit peaks (%).
    pub freq_change_pct: f64,
    /// Both limit peaks are interior maxima.
    pub refined: bool,
}

/// Variability of one apical angle.
#[derive(Debug, Clone, Serialize)]
pub struct BetaRow {
    /// Apical angle (deg).
    pub beta: f64,
    /// Ratio of the limit peaks (for sweeps: the largest over the sweep).
    pub ratio: f64,
    /// Where the largest ratio is (sweeps), e.g. `F0 = 500 N`.
    pub at: String,
    /// Widest FRF band (m), for limit analyses.
    pub widest_band: Option<f64>,
}

/// Energy dissipated per cycle at one curve's resonance (Fig. 16c).
#[derive(Debug, Clone, Serialize)]
pub struct LoopRow {
    /// Curve.
    pub case: String,
    /// Frequency of the loop (Hz).
    pub freq_hz: f64,
    /// Output amplitude there (m).
    pub amplitude: f64,
    /// (contact, ∮T du in J) per contact.
    pub energy: Vec<(String, f64)>,
}

/// Resonance frequencies (Hz) of the two limit curves (higher, lower) at the smallest and the
/// largest swept pre-load, and the stuck-linear resonance (Fig. 16d).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ResonanceEnds {
    /// At the smallest F0.
    pub smallest_f0: (f64, f64),
    /// At the largest F0.
    pub largest_f0: (f64, f64),
    /// Stuck-linear 3rd resonance.
    pub stuck: f64,
}

/// Agreement of a fricbound number with the paper's statement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Agreement {
    /// Within the stated criterion.
    Agrees,
    /// Same trend or overlapping ranges, but not within the criterion.
    Partly,
    /// Outside.
    Disagrees,
    /// The figures it needs did not run.
    NotComputed,
}

impl Agreement {
    fn text(self) -> &'static str {
        match self {
            Agreement::Agrees => "yes",
            Agreement::Partly => "partly",
            Agreement::Disagrees => "no",
            Agreement::NotComputed => "not computed",
        }
    }
}

/// Every key number of the study.
#[derive(Debug, Clone, Default, Serialize)]
pub struct KeyNumbers {
    /// Resonance frequencies (Hz) of the linear references: contacts open, stuck (Fig. 12).
    pub linear_resonances_hz: Option<(Vec<f64>, Vec<f64>)>,
    /// Every limit analysis.
    pub analyses: Vec<AnalysisRow>,
    /// Optimal-curve sweep over F0 (Figs. 16a, 16d).
    pub f0_sweep: Vec<SweepRow>,
    /// Fine sweep near the optimum with intermediate cases (Fig. 16b), and its case names.
    pub f0_fine: Vec<SweepRow>,
    /// Case names of the fine sweep.
    pub f0_fine_cases: Vec<String>,
    /// Largest ratio of the limit peaks over the study.
    pub max_peak_ratio: Option<Located>,
    /// Largest resonance-frequency change between the limit peaks over the study (%).
    pub max_freq_change_pct: Option<Located>,
    /// F0 (N) where the two limit peaks cross (the closed band collapses).
    pub limit_peaks_cross_f0: Vec<f64>,
    /// Largest F0 (N) up to which the limit peaks agree within 1 %, and the next swept F0.
    pub unique_up_to_f0: Option<(f64, Option<f64>)>,
    /// Pre-load of the minimum resonance peak (the optimum) per case (N); flag: at a sweep end.
    pub optimum_f0: Vec<(String, f64, bool)>,
    /// F0 values (N) of the fine sweep at which an intermediate peak lies outside the limits.
    pub intermediates_outside_f0: Vec<f64>,
    /// Upper and lower limit peak at the largest F0 of the sweep over the stuck-linear peak.
    pub high_f0_over_stuck: Option<(f64, f64, f64)>,
    /// Resonance frequencies of the two limit curves at the ends of the F0 sweep.
    pub f0_sweep_frequencies: Option<ResonanceEnds>,
    /// β ≥ 90°: FRF variability at a fixed pre-load (Fig. 18a).
    pub beta_high_frf: Vec<BetaRow>,
    /// β ≥ 90°: largest variability over the F0 sweep (Fig. 18b).
    pub beta_high_optimal: Vec<BetaRow>,
    /// β ≤ 90°: FRF variability with blade pre-loads (Fig. 19a).
    pub beta_low_frf: Vec<BetaRow>,
    /// β ≤ 90°: largest variability over the blade pre-load sweep (Fig. 19b).
    pub beta_low_pseudo: Vec<BetaRow>,
    /// Smallest and largest ratio over the blade pre-load per β (Fig. 19b).
    pub beta_low_pseudo_spread: Vec<(f64, f64, f64)>,
    /// Largest ratio of the limit peaks in the F0 sweep at β = 120° (Fig. 16a), and F0 (N).
    pub f0_sweep_max_ratio: Option<(f64, f64)>,
    /// Largest resonance-frequency change in the F0 sweep at β = 120° (Fig. 16d), and F0 (N).
    pub f0_sweep_max_freq_change_pct: Option<(f64, f64)>,
    /// Loops at resonance (Fig. 16c).
    pub loops: Vec<LoopRow>,
    /// Curves that needed continuation retries, one line each.
    pub retries: Vec<String>,
    /// Sweep points or figures that failed, one line each.
    pub failures: Vec<String>,
}

fn find<'a>(figures: &'a [FigureResult], id: &str) -> Option<&'a FigureResult> {
    figures.iter().find(|f| f.job.id == id)
}

fn sweep_of<'a>(figures: &'a [FigureResult], id: &str) -> Option<&'a [SweepPoint]> {
    match &find(figures, id)?.report()?.outcome {
        RunOutcome::Sweep(points) => Some(points),
        _ => None,
    }
}

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

fn analysis_row(figure: &str, at: String, value: Option<f64>, a: &LimitAnalysis) -> AnalysisRow {
    let v = a.variability();
    let (p, q) = (&a.limits[0], &a.limits[1]);
    let (up, lo) = if p.peak.amplitude >= q.peak.amplitude {
        (p, q)
    } else {
        (q, p)
    };
    let peak_states = a
        .limits
        .iter()
        .map(|c| {
            format!(
                "{}: {}",
                c.case.name,
                c.peak
                    .states
                    .iter()
                    .map(|s| s.label())
                    .collect::<Vec<_>>()
                    .join(" / ")
            )
        })
        .collect();
    // A side stuck at every grid frequency in both limit curves (paper Fig. 14a).
    let always_stuck_side = (0..a.limits[0].peak.states.len())
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
    let intermediates_outside = a
        .intermediate
        .iter()
        .filter(|c| {
            c.peak.amplitude > hi * (1.0 + PEAK_TOLERANCE)
                || c.peak.amplitude < low * (1.0 - PEAK_TOLERANCE)
        })
        .map(|c| format!("{} ({:.4e} m)", c.case.name, c.peak.amplitude))
        .collect();
    let bound = a.bounds.as_ref().map(|b| BoundRow {
        above_pct: 100.0 * b.max_excess_above,
        above_at: b.above_at.clone(),
        below_pct: 100.0 * b.max_excess_below,
        below_at: b.below_at.clone(),
        peak_above_pct: 100.0 * b.peak_excess_above,
        peak_below_pct: 100.0 * b.peak_excess_below,
        above_stuck_limit_vs_slipping: b.above_states.as_ref().is_some_and(|st| {
            let upper = if a.limits[0].peak.amplitude >= a.limits[1].peak.amplitude {
                0
            } else {
                1
            };
            st.limits.get(upper).is_some_and(|l| {
                !l.is_empty() && l.iter().all(|&x| x == crate::contact::ContactState::Stuck)
            }) && st
                .scanned
                .iter()
                .any(|&x| x != crate::contact::ContactState::Stuck)
        }),
    });
    AnalysisRow {
        figure: figure.to_string(),
        at,
        value,
        upper: (up.case.name.clone(), up.peak.amplitude, up.peak.freq_hz),
        lower: (lo.case.name.clone(), lo.peak.amplitude, lo.peak.freq_hz),
        ratio: v.peak_ratio,
        freq_change_pct: v.peak_freq_change_pct,
        refined: p.peak.refined && q.peak.refined,
        widest_band: (v.widest_band, v.widest_band_hz),
        multiple_share: v.multiple_points as f64 / v.grid_points.max(1) as f64,
        peak_states,
        always_stuck_side,
        intermediates_outside,
        bound,
    }
}

fn unit_label(name: &str, unit: &str, v: f64) -> String {
    if unit.is_empty() {
        format!("{name} = {v}")
    } else {
        format!("{name} = {v} {unit}")
    }
}

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
        if let Err(e) = &f.outcome {
            k.failures.push(format!("{}: {e}", f.job.id));
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
                for c in a.limits.iter().chain(&a.intermediate) {
                    if c.retries > 0 {
                        k.retries.push(format!(
                            "{}: curve {}, {} retries",
                            f.job.id, c.case.name, c.retries
                        ));
                    }
                }
                k.analyses
                    .push(analysis_row(f.job.id, String::new(), None, a));
            }
            RunOutcome::Sweep(points) => {
                let spec = crate::scene::parse(f.job.text, f.job.id, &[])
                    .ok()
                    .and_then(|s| s.sweep);
                for p in points {
                    for (case, r) in p.cases.iter().zip(&p.retries) {
                        if *r > 0 {
                            k.retries.push(format!(
                                "{} at {} = {}: curve {case}, {r} retries",
                                f.job.id,
                                sweep_name(&spec),
                                p.value
                            ));
                        }
                    }
                    for e in &p.failures {
                        k.failures.push(format!(
                            "{} at {} = {}: {e}",
                            f.job.id,
                            sweep_name(&spec),
                            p.value
                        ));
                    }
                    if let Some(a) = &p.analysis {
                        let at = spec.as_ref().map_or(String::new(), |s| {
                            unit_label(&s.parameter, &s.unit, p.value)
                        });
                        k.analyses
                            .push(analysis_row(f.job.id, at, Some(p.value), a));
                    }
                }
            }
            RunOutcome::Frf(_) => {}
        }
    }
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
        let spec = crate::scene::parse(find(figures, id).map_or("", |f| f.job.text), id, &[])
            .ok()
            .and_then(|s| s.sweep);
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
            let at = spec.as_ref().map_or(String::new(), |s| {
                unit_label(&s.parameter, &s.unit, best.value)
            });
            consider(
                &mut k.max_peak_ratio,
                best.ratio,
                id,
                format!("beta = {b} deg, {at}"),
            );
            for r in &of_b {
                let at = spec.as_ref().map_or(String::new(), |s| {
                    unit_label(&s.parameter, &s.unit, r.value)
                });
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

fn sweep_name(spec: &Option<crate::scene::SweepSpec>) -> String {
    spec.as_ref()
        .map_or("value".to_string(), |s| s.parameter.clone())
}

fn e(v: f64) -> String {
    format!("{v:.4e}")
}

fn ranking(rows: &[BetaRow]) -> String {
    let mut sorted: Vec<&BetaRow> = rows.iter().collect();
    sorted.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    sorted
        .iter()
        .map(|r| format!("{}° ({:.3})", r.beta, r.ratio))
        .collect::<Vec<_>>()
        .join(" > ")
}

fn ratio_at(rows: &[BetaRow], beta: f64) -> Option<f64> {
    rows.iter().find(|r| r.beta == beta).map(|r| r.ratio)
}

/// The paper's three claims on β ≥ 90°: largest variability at 90°, nearly none at 180°,
/// and 160° above 150° (not monotonic).
fn high_beta_checks(rows: &[BetaRow]) -> Option<(bool, bool, bool)> {
    let top = rows.iter().max_by(|a, b| a.ratio.total_cmp(&b.ratio))?;
    let flat = ratio_at(rows, 180.0)?;
    let (r150, r160) = (ratio_at(rows, 150.0)?, ratio_at(rows, 160.0)?);
    Some((top.beta == 90.0, flat < 1.01, r160 > r150))
}

/// The paper's claim on β ≤ 90°: the variability shrinks steadily as β decreases from 90°.
fn low_beta_monotonic(rows: &[BetaRow]) -> Option<bool> {
    if rows.len() < 2 {
        return None;
    }
    let mut sorted: Vec<&BetaRow> = rows.iter().collect();
    sorted.sort_by(|a, b| a.beta.total_cmp(&b.beta));
    Some(sorted.windows(2).all(|w| w[1].ratio > w[0].ratio))
}

/// `summary.md`: the key numbers next to the paper's statements.
pub fn markdown(figures: &[FigureResult], k: &KeyNumbers, quick: bool, elapsed_s: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# fricbound: the paper's §4 study, key numbers\n");
    let _ = writeln!(
        s,
        "Ferhatoglu & Zucca, JSV 494 (2021), §4 (Figs. 12-19), recomputed by `fricbound paper{}` \
         (fricbound {}) in {elapsed_s:.1} s. Every number below is computed from the runs in \
         this folder; only the paper's statements are quoted. Amplitudes are the first-harmonic \
         amplitude of y2 (m); peaks are the refined resonance peaks of each curve in the 3rd \
         resonance region (190-235 Hz) unless said otherwise.\n",
        if quick { " --quick" } else { "" },
        env!("CARGO_PKG_VERSION")
    );
    if quick {
        let _ = writeln!(
            s,
            "**Quick mode:** coarser sweeps, grid, continuation steps and bound scan; the \
             numbers are indicative only (run without `--quick` for the study).\n"
        );
    }
    let ran: Vec<&str> = figures.iter().map(|f| f.job.id).collect();
    let _ = writeln!(s, "Figures run: {}.\n", ran.join(", "));

    key_table(&mut s, k);
    bounds_table(&mut s, k);
    figure_sections(&mut s, figures, k);
    differences(&mut s, k);
    if !k.retries.is_empty() {
        let _ = writeln!(
            s,
            "## Continuation retries\n\nThese curves stalled with the scene's continuation steps \
             and were solved with other steps (`limits::solve_case`):\n"
        );
        for r in &k.retries {
            let _ = writeln!(s, "- {r}");
        }
        s.push('\n');
    }
    if !k.failures.is_empty() {
        let _ = writeln!(s, "## Failures\n");
        for f in &k.failures {
            let _ = writeln!(s, "- {f}");
        }
        s.push('\n');
    }
    s
}

fn key_table(s: &mut String, k: &KeyNumbers) {
    let _ = writeln!(s, "## Key numbers\n");
    let _ = writeln!(
        s,
        "| quantity | the paper | fricbound | agrees? |\n| --- | --- | --- | --- |"
    );
    // 1. Ratio of the limit peaks.
    let (text, agree) = match &k.max_peak_ratio {
        Some(m) => {
            let a = if (m.value - 3.0).abs() <= 0.2 * 3.0 {
                Agreement::Agrees
            } else if m.value >= 1.5 {
                Agreement::Partly
            } else {
                Agreement::Disagrees
            };
            (
                format!("largest {:.2}× ({}, {})", m.value, m.figure, m.at),
                a,
            )
        }
        None => ("—".to_string(), Agreement::NotComputed),
    };
    let mut text = text;
    if let Some((r, f0)) = k.f0_sweep_max_ratio {
        let _ = write!(
            text,
            "; in the F0 sweep at β = 120° (Fig. 16a) {r:.2}× at F0 = {f0} N"
        );
    }
    if let Some(b) = k.beta_high_optimal.iter().find(|b| b.beta == 90.0) {
        let _ = write!(text, "; at β = 90° (Fig. 18b) {:.2}× at {}", b.ratio, b.at);
    }
    let _ = writeln!(
        s,
        "| ratio of the limit peak amplitudes (upper/lower) | up to 3× | {text} | {} |",
        agree.text()
    );
    // 2. Resonance-frequency change: over the whole study, and in the paper's Fig. 16d sweep.
    let near3 = |v: f64| (v - 3.0).abs() <= 1.0;
    let (text, agree) = match (&k.max_freq_change_pct, k.f0_sweep_max_freq_change_pct) {
        (Some(m), sweep) => {
            let mut t = format!("largest {:.2} % ({}, {})", m.value, m.figure, m.at);
            if let Some((v, f0)) = sweep {
                let _ = write!(
                    t,
                    "; in the F0 sweep at β = 120° (Fig. 16d) {v:.2} % at F0 = {f0} N"
                );
            }
            let a = if near3(m.value) {
                Agreement::Agrees
            } else if sweep.is_some_and(|(v, _)| near3(v)) || m.value > 0.5 {
                Agreement::Partly
            } else {
                Agreement::Disagrees
            };
            (t, a)
        }
        (None, _) => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| resonance-frequency change between the limits | up to 3 % | {text} | {} |",
        agree.text()
    );
    // 3. Pre-load where the variability disappears.
    let (text, agree) = if k.limit_peaks_cross_f0.is_empty() && k.unique_up_to_f0.is_none() {
        ("—".to_string(), Agreement::NotComputed)
    } else {
        let mut t = String::new();
        if !k.limit_peaks_cross_f0.is_empty() {
            let _ = write!(
                t,
                "the limit peaks cross (closed band collapses) at F0 ≈ {} N",
                k.limit_peaks_cross_f0
                    .iter()
                    .map(|f| format!("{f:.0}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        if let Some((f, next)) = k.unique_up_to_f0 {
            let _ = write!(
                t,
                "{}limit peaks within 1 % for F0 ≤ {f} N{}",
                if t.is_empty() { "" } else { "; " },
                next.map(|n| format!(", apart from the next swept value ({n} N) on"))
                    .unwrap_or_default()
            );
        }
        let a = match k.limit_peaks_cross_f0.first() {
            Some(f) if (f - 60.0).abs() <= 15.0 => Agreement::Agrees,
            Some(f) if (30.0..=90.0).contains(f) => Agreement::Partly,
            Some(_) => Agreement::Disagrees,
            None => Agreement::Partly,
        };
        (t, a)
    };
    let _ = writeln!(
        s,
        "| pre-load where the variability (closed band) disappears | near 60 N (Fig. 15a) | {text} | {} |",
        agree.text()
    );
    // 4. Optimum pre-load range.
    let limits_opt: Vec<&(String, f64, bool)> = k
        .optimum_f0
        .iter()
        .filter(|(c, _, _)| c == "m+1" || c == "m-1")
        .collect();
    let (text, agree) = if limits_opt.len() == 2 {
        let lo = limits_opt.iter().map(|o| o.1).fold(f64::INFINITY, f64::min);
        let hi = limits_opt
            .iter()
            .map(|o| o.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let inside = |v: f64| (45.0..=80.0).contains(&v);
        let a = if inside(lo) && inside(hi) {
            Agreement::Agrees
        } else if hi >= 45.0 && lo <= 80.0 {
            Agreement::Partly
        } else {
            Agreement::Disagrees
        };
        (
            format!(
                "{lo:.0}-{hi:.0} N ({}){}",
                limits_opt
                    .iter()
                    .map(|(c, f, _)| format!("{c}: {f:.1} N"))
                    .collect::<Vec<_>>()
                    .join(", "),
                if limits_opt.iter().any(|o| o.2) {
                    " — a minimum lies at an end of the sweep"
                } else {
                    ""
                }
            ),
            a,
        )
    } else {
        ("—".to_string(), Agreement::NotComputed)
    };
    let _ = writeln!(
        s,
        "| optimum pre-load (minimum of the limit optimal curves) | around 45-80 N | {text} | {} |",
        agree.text()
    );
    // 5. β ranking.
    let rows = if k.beta_high_frf.is_empty() {
        &k.beta_high_optimal
    } else {
        &k.beta_high_frf
    };
    let (text, agree) = match high_beta_checks(rows) {
        Some((top90, flat, non_mono)) => {
            let n = [top90, flat, non_mono].iter().filter(|x| **x).count();
            (
                format!(
                    "FRF limit-peak ratio at F0 = 120 N: {}; largest at 90°: {}, flat ≈ unique: {}, 160° > 150°: {}",
                    ranking(rows),
                    yes(top90),
                    yes(flat),
                    yes(non_mono)
                ),
                match n {
                    3 => Agreement::Agrees,
                    0 => Agreement::Disagrees,
                    _ => Agreement::Partly,
                },
            )
        }
        None => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| β ranking of the variability (β ≥ 90°) | largest at β = 90°, almost none at 180°, not monotonic between 150° and 160° (160° wider in Fig. 18a) | {text} | {} |",
        agree.text()
    );
    // The limits bound at high pre-loads and need not near the optimum (Fig. 15).
    let row = |f0: f64| {
        k.analyses
            .iter()
            .find(|r| r.figure == "fig15a" && r.value == Some(f0))
    };
    let bounded = |r: &AnalysisRow| {
        r.bound
            .as_ref()
            .map(|b| b.above_pct.max(b.below_pct) < 0.1 && r.intermediates_outside.is_empty())
    };
    let (text, agree) = match (row(130.0), row(400.0), row(60.0)) {
        (Some(a), Some(b), Some(c)) => match (bounded(a), bounded(b), bounded(c)) {
            (Some(x), Some(y), Some(z)) => {
                let excess = |r: &AnalysisRow| {
                    r.bound
                        .as_ref()
                        .map_or(0.0, |b| b.above_pct.max(b.below_pct))
                };
                (
                    format!(
                        "largest pointwise excess of the scanned states: {:.3} % at 130 N, {:.3} % at 400 N, {:.3} % at 60 N; bounded at 130 N: {}, at 400 N: {}, at 60 N: {}",
                        excess(a),
                        excess(b),
                        excess(c),
                        yes(x),
                        yes(y),
                        yes(z)
                    ),
                    match (x && y, z) {
                        (true, false) => Agreement::Agrees,
                        (true, true) | (false, false) => Agreement::Partly,
                        (false, true) => Agreement::Disagrees,
                    },
                )
            }
            _ => ("— (no bound scan)".to_string(), Agreement::NotComputed),
        },
        _ => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| do the limits bound the other solutions? | yes at 130 and 400 N (closed band), not necessarily near the optimum, 60 N (Fig. 15) | {text} | {} |",
        agree.text()
    );
    let (text, agree) = match low_beta_monotonic(&k.beta_low_frf) {
        Some(m) => (
            format!("{} (F0 = 500 N, P = 500 N)", ranking(&k.beta_low_frf)),
            if m {
                Agreement::Agrees
            } else {
                Agreement::Disagrees
            },
        ),
        None => ("—".to_string(), Agreement::NotComputed),
    };
    let _ = writeln!(
        s,
        "| β ranking of the variability (β ≤ 90°) | shrinks steadily as β decreases from 90° (Fig. 19a) | {text} | {} |",
        agree.text()
    );
    let _ = writeln!(
        s,
        "\nCriteria: ratio within 20 % of 3; frequency change within 1 percentage point of 3 %; \
         crossing within 15 N of 60 N; both optima inside 45-80 N (partly: the ranges overlap); \
         all three β claims (partly: some); bounded means no scanned state more than 0.1 % \
         outside the band at any grid frequency and no intermediate peak outside the limit \
         peaks. \"partly\" means the same kind of behaviour with different numbers.\n"
    );
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn bounds_table(s: &mut String, k: &KeyNumbers) {
    let _ = writeln!(s, "## Do the limits bound the other solutions?\n");
    let _ = writeln!(
        s,
        "For every limit analysis with a bound scan, every combination of intermediate initial \
         states m per damper side is solved and compared with the band: pointwise at each grid \
         frequency, and at the resonance peaks. The paper: the limits enclose a closed band at \
         high pre-loads (130 and 400 N, Fig. 15a) and need not near the optimum (60 N, Fig. \
         15b).\n"
    );
    let _ = writeln!(
        s,
        "| figure | at | largest excess above the upper limit (pointwise) | below the lower limit (pointwise) | scanned peaks above / below the limit peaks | intermediate peaks outside the limit peaks |\n| --- | --- | --- | --- | --- | --- |"
    );
    for r in &k.analyses {
        let Some(b) = &r.bound else { continue };
        // Where, for excesses above the round-off of the comparison.
        let place = |p: &Option<(f64, String)>, pct: f64| {
            p.as_ref()
                .filter(|_| pct > 1e-4)
                .map(|(f, c)| format!(" ({c} at {f:.2} Hz)"))
                .unwrap_or_default()
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} %{} | {:.3} %{} | {:.3} % / {:.3} % | {} |",
            r.figure,
            if r.at.is_empty() { "—" } else { &r.at },
            b.above_pct,
            place(&b.above_at, b.above_pct),
            b.below_pct,
            place(&b.below_at, b.below_pct),
            b.peak_above_pct,
            b.peak_below_pct,
            if r.intermediates_outside.is_empty() {
                "none".to_string()
            } else {
                r.intermediates_outside.join(", ")
            }
        );
    }
    s.push('\n');
}

fn figure_sections(s: &mut String, figures: &[FigureResult], k: &KeyNumbers) {
    let _ = writeln!(s, "## Figure by figure\n");
    for f in figures {
        let _ = writeln!(
            s,
            "### {}: {}\n\nScene `meshes/paper-wedge/{}`, results in `{}/` ({:.1} s).\n",
            f.job.id, f.job.caption, f.job.scene_file, f.job.id, f.elapsed_s
        );
        let report = match &f.outcome {
            Ok(r) => r,
            Err(e) => {
                let _ = writeln!(s, "**Failed:** {e}\n");
                continue;
            }
        };
        figure_links(s, f.job.id, &report.dir);
        match f.job.id {
            "fig12" => {
                if let Some((open, stuck)) = &k.linear_resonances_hz {
                    let list = |v: &[f64]| {
                        v.iter()
                            .map(|f| format!("{f:.1}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    };
                    let _ = writeln!(
                        s,
                        "Linear resonances of y2 (grid of the linear references): contacts open \
                         (blades alone) {} Hz; contacts stuck (damper attached through kt, kn) {} \
                         Hz. The paper: the damper does not affect the 1st mode but its mass \
                         lowers it slightly, and it stiffens modes 2-4.\n",
                        list(open),
                        list(stuck)
                    );
                }
            }
            "fig16a-d" => f0_section(s, k),
            "fig16b" => fine_section(s, k),
            "fig16c" => loops_section(s, k),
            "fig18b" => beta_sweep_section(s, &k.beta_high_optimal, "F0"),
            "fig19b" => {
                beta_sweep_section(s, &k.beta_low_pseudo, "P");
                if !k.beta_low_pseudo_spread.is_empty() {
                    let _ = writeln!(
                        s,
                        "Smallest and largest limit-peak ratio over P per β: {}. The paper: the \
                         limits stay parallel (constant band) as P grows, until the stuck \
                         resonance is reached.\n",
                        k.beta_low_pseudo_spread
                            .iter()
                            .map(|(b, lo, hi)| format!("{b}°: {lo:.3}-{hi:.3}"))
                            .collect::<Vec<_>>()
                            .join("; ")
                    );
                }
            }
            _ => {}
        }
        analysis_rows(s, k, f.job.id);
        if f.job.id == "fig13-2nd" || f.job.id == "fig13-3rd" {
            states_note(s, k, f.job.id);
        }
    }
}

/// Embeds the figure's main image and links its other top-level images (PNG; each has an
/// SVG twin).
fn figure_links(s: &mut String, id: &str, dir: &std::path::Path) {
    let mut pngs: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".png"))
        .collect();
    pngs.sort();
    let main = ["bands_", "limits_", "optimal_", "frf_"]
        .iter()
        .find_map(|p| pngs.iter().find(|n| n.starts_with(p)));
    if let Some(m) = main {
        let _ = writeln!(s, "![{id}]({id}/{m})\n");
    }
    let others: Vec<String> = pngs
        .iter()
        .filter(|n| Some(*n) != main)
        .map(|n| format!("[{n}]({id}/{n})"))
        .collect();
    if !others.is_empty() {
        let _ = writeln!(s, "Other figures: {}.\n", others.join(", "));
    }
}

fn analysis_rows(s: &mut String, k: &KeyNumbers, id: &str) {
    let rows: Vec<&AnalysisRow> = k.analyses.iter().filter(|r| r.figure == id).collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "| at | upper limit peak | lower limit peak | ratio | frequency change | widest band | multiple-solution share | peaks refined |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} {} m at {:.2} Hz | {} {} m at {:.2} Hz | {:.4} | {:.3} % | {} m at {:.2} Hz | {:.0} % | {} |",
            if r.at.is_empty() { "—" } else { &r.at },
            r.upper.0,
            e(r.upper.1),
            r.upper.2,
            r.lower.0,
            e(r.lower.1),
            r.lower.2,
            r.ratio,
            r.freq_change_pct,
            e(r.widest_band.0),
            r.widest_band.1,
            100.0 * r.multiple_share,
            yes(r.refined)
        );
    }
    s.push('\n');
}

fn states_note(s: &mut String, k: &KeyNumbers, id: &str) {
    let Some(r) = k.analyses.iter().find(|r| r.figure == id) else {
        return;
    };
    let paper = if id == "fig13-2nd" {
        "both contacts slip at the 2nd resonance (contact 1 stick-slip, contact 2 \
         stick-slip-lift-off, Fig. 14b), so the limit curves coincide"
    } else {
        "contact 1 stays fully stuck over the whole interval while contact 2 stick-slips \
         (Fig. 14a), so the curves differ"
    };
    let _ = writeln!(
        s,
        "Contact states (contact 1 = `left`, blade 1; contact 2 = `right`, blade 2) at the limit \
         peaks: {}. Side stuck at every grid frequency in both limit curves: {}. Limit peaks \
         differ by {:.2e} (relative). The paper: {paper}.\n",
        r.peak_states.join("; "),
        r.always_stuck_side.as_deref().unwrap_or("none"),
        r.ratio - 1.0
    );
}

fn f0_section(s: &mut String, k: &KeyNumbers) {
    if k.f0_sweep.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "| F0 (N) | m+1 peak (m) | m-1 peak (m) | ratio | frequency change |\n| --- | --- | --- | --- | --- |"
    );
    for r in &k.f0_sweep {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.4} | {:.3} %{} |",
            r.value,
            e(r.peaks[0]),
            e(r.peaks[1]),
            r.ratio,
            r.freq_change_pct,
            if r.refined { "" } else { " (no interior peak)" }
        );
    }
    s.push('\n');
    if let Some((f0, hi, lo)) = k.high_f0_over_stuck {
        let _ = writeln!(
            s,
            "At F0 = {f0} N the limit peaks are {:.0} % and {:.0} % of the stuck-linear 3rd \
             resonance peak (the paper: the optimal-curve limits saturate at the fully stuck \
             linear case).",
            100.0 * hi,
            100.0 * lo
        );
    }
    if let Some(ResonanceEnds {
        smallest_f0: (lo_hi, lo_lo),
        largest_f0: (hi_hi, hi_lo),
        stuck,
    }) = k.f0_sweep_frequencies
    {
        let _ = writeln!(
            s,
            "Resonance-frequency limits (Fig. 16d): {lo_lo:.2}-{lo_hi:.2} Hz at the smallest F0, \
             {hi_lo:.2}-{hi_hi:.2} Hz at the largest; stuck-linear resonance {stuck:.2} Hz (the \
             paper: the limits start together and end together at the stuck resonance)."
        );
    }
    s.push('\n');
}

fn fine_section(s: &mut String, k: &KeyNumbers) {
    if k.f0_fine.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "Optimum pre-load (minimum of each optimal curve, parabolic through the three lowest \
         swept values): {}.\n",
        k.optimum_f0
            .iter()
            .map(|(c, f, end)| format!(
                "{c} {f:.1} N{}",
                if *end { " (at a sweep end)" } else { "" }
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "Pre-loads at which an intermediate curve's resonance peak lies outside the two limit \
         peaks (the transition region of Fig. 15b): {}.\n",
        if k.intermediates_outside_f0.is_empty() {
            "none".to_string()
        } else {
            let lo = k
                .intermediates_outside_f0
                .iter()
                .cloned()
                .fold(f64::INFINITY, f64::min);
            let hi = k
                .intermediates_outside_f0
                .iter()
                .cloned()
                .fold(f64::NEG_INFINITY, f64::max);
            format!(
                "{lo}-{hi} N ({} of {} swept values)",
                k.intermediates_outside_f0.len(),
                k.f0_fine.len()
            )
        }
    );
}

fn loops_section(s: &mut String, k: &KeyNumbers) {
    if k.loops.is_empty() {
        return;
    }
    let contacts: Vec<&String> = k.loops[0].energy.iter().map(|(c, _)| c).collect();
    let _ = write!(s, "| curve | resonance | amplitude |");
    for c in &contacts {
        let _ = write!(s, " energy dissipated per cycle, `{c}` (J) |");
    }
    let _ = write!(s, "\n| --- | --- | --- |");
    for _ in &contacts {
        s.push_str(" --- |");
    }
    s.push('\n');
    for l in &k.loops {
        let _ = write!(
            s,
            "| {} | {:.2} Hz | {} m |",
            l.case,
            l.freq_hz,
            e(l.amplitude)
        );
        for (_, w) in &l.energy {
            // Round-off of a stuck contact's closed loop is ~1e-19 J: print it as zero.
            if w.abs() < 1e-12 {
                s.push_str(" 0 |");
            } else {
                let _ = write!(s, " {} |", e(*w));
            }
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "\nThe paper: the slipping contact has quite different loops for the limit and \
         intermediate states, so the damping differs; the stuck contact dissipates nothing. \
         Loops: `hysteresis_<contact>.png` and `hysteresis_<curve>_peak.csv`.\n"
    );
}

fn beta_sweep_section(s: &mut String, rows: &[BetaRow], parameter: &str) {
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "Largest limit-peak ratio over the {parameter} sweep per apical angle: {}.\n",
        rows.iter()
            .map(|r| format!("β = {}°: {:.3} ({})", r.beta, r.ratio, r.at))
            .collect::<Vec<_>>()
            .join("; ")
    );
    let _ = writeln!(s, "Ranking: {}.\n", ranking(rows));
}

fn differences(s: &mut String, k: &KeyNumbers) {
    let _ = writeln!(s, "## Where fricbound and the paper differ, and why\n");
    if let Some(m) = &k.max_peak_ratio {
        if (m.value - 3.0).abs() > 0.6 {
            let _ = writeln!(
                s,
                "- **Ratio of the limit peaks** ({:.2}× at most here, 3× in the paper). The \
                 ratio grows with the pre-load and with the damper-induced cross coupling (it \
                 is largest at β = 90° and high F0 here too), so the largest value depends on \
                 the pre-loads and angles swept, which the paper gives only for some figures \
                 (its Fig. 18 pre-loads and Fig. 19 blade pre-loads are not stated; this study \
                 assumes them, see below). It also depends on which blade each contact frame \
                 belongs to and on the direction of the pre-load: with the paper's Table 1 \
                 stiffness k_xy couples x and y with a fixed sign, so mirroring the geometry \
                 (damper above vs below the blades) is not a symmetry of the model and changes \
                 how the excitation loads each contact.",
                m.value
            );
        }
    }
    if let Some(m) = &k.max_freq_change_pct {
        if (m.value - 3.0).abs() > 1.0 {
            let _ = writeln!(
                s,
                "- **Resonance-frequency change** ({:.2} % at most here, up to 3 % in the \
                 paper).{} The larger changes come from configurations where the two limit \
                 peaks lie far apart in frequency ({}, {}); the paper states its maximum over \
                 its own sweeps, whose points it does not list.",
                m.value,
                k.f0_sweep_max_freq_change_pct
                    .map(|(v, f0)| format!(
                        " In the paper's Fig. 16d configuration (β = 120°, F0 sweep) it is \
                         {v:.2} % at most (F0 = {f0} N)."
                    ))
                    .unwrap_or_default(),
                m.figure,
                m.at
            );
        }
    }
    let unbounded: Vec<&AnalysisRow> = k
        .analyses
        .iter()
        .filter(|r| r.bound.as_ref().is_some_and(|b| b.above_pct > 0.1))
        .collect();
    if !unbounded.is_empty() {
        let softening = unbounded
            .iter()
            .filter(|r| {
                r.bound
                    .as_ref()
                    .is_some_and(|b| b.above_stuck_limit_vs_slipping)
            })
            .count();
        let _ = writeln!(
            s,
            "- **Pointwise bounds.** In {} of the limit analyses with a scan, some intermediate \
             state rises above the upper limit at some frequency, although no scanned resonance \
             peak exceeds the limit peaks. In {softening} of them the upper limit curve is fully \
             stuck on every contact there while the scanned state slips: a slightly slipping \
             contact is softer, which moves its resonance down towards that frequency, above the \
             stuck response. The paper draws its closed bands by eye at 130 and 400 N; here they \
             hold for the resonance peaks, and pointwise only where no limit curve is fully \
             stuck next to a slipping intermediate one.",
            unbounded.len()
        );
    }
    if let Some(f) = k.limit_peaks_cross_f0.first() {
        if (f - 60.0).abs() > 15.0 {
            let _ = writeln!(
                s,
                "- **Pre-load of the collapse** (≈ {f:.0} N here, near 60 N in the paper). The \
                 band collapses where the two limit curves straddle the optimum pre-load, so it \
                 moves with the optimum (next item)."
            );
        }
    }
    let opt: Vec<f64> = k
        .optimum_f0
        .iter()
        .filter(|(c, _, _)| c == "m+1" || c == "m-1")
        .map(|o| o.1)
        .collect();
    if opt.iter().any(|v| !(45.0..=80.0).contains(v)) {
        let _ = writeln!(
            s,
            "- **Optimum pre-load** ({}, 45-80 N in the paper). The optimum lies where the \
             slipping side's static normal load N⁰, set by F0 through the damper's static balance \
             (Eq. 11 with K_D), lets it slip over a useful part of the cycle, so it depends on \
             how the excitation moves each face relative to its blade. That depends on the \
             contact-frame and sign conventions (described below), which the paper gives only \
             as Eq. (16), without saying which blade each frame belongs to or which way the \
             normal points; these scenes follow the free-body diagram of Eq. (11) and reproduce \
             the contact numbering of Fig. 14. The paper's range is read off a plot whose sweep \
             points it does not give; the data here cannot single out one cause.",
            opt.iter()
                .map(|v| format!("{v:.0} N"))
                .collect::<Vec<_>>()
                .join(" and ")
        );
    }
    if low_beta_monotonic(&k.beta_low_frf) == Some(false) {
        let _ = writeln!(
            s,
            "- **β < 90°** (not a steady decrease here). The paper explains its β < 90° results \
             by the damper losing contact under the pre-load unless the blades are pressed \
             onto it. In this model the wedge keeps contact without blade pre-loads too (it \
             spreads the elastically held blades), so the extra pre-loads P only add normal \
             load, and the variability need not shrink with β. The blade pre-load of Fig. 19a \
             is not given in the paper (P = 500 N assumed)."
        );
    }
    let _ = writeln!(
        s,
        "\n**The model, as solved here** (the same for every figure): the paper's Table 1 \
         lumped system with the damper spring K_D; one Jenkins element per damper face with \
         kt = kn = 3·10⁵ N/m, μ = 0.5, variable normal load and lift-off; harmonic balance with \
         the 1st harmonic and the 0th coupled (statics and dynamics solved together), 256 AFT \
         samples per period; contact frames of Eq. (16) as rotations by ∓α of the damper faces, \
         normal from the damper into the blade, contact 1 (`left`) on blade 1; the pre-load F0 \
         along −y on the damper (Eq. 11 read with the contact forces holding the damper up); for \
         β < 90° the blade pre-loads +P on x1 and −P on x2. The limit cases are m = ±1 on every \
         point (Eqs. 14-15); which one is closest to stuck is decided at each frequency from the \
         slipping side's static normal load, not assumed.\n"
    );
    let _ = writeln!(
        s,
        "**Inputs the paper does not give, assumed here:** F0 = 120 N for the β sweep of Fig. \
         18a; F0 = 500 N with P = 500 N and β = 30, 45, 60, 75, 90° for Fig. 19a; the pre-loads \
         of Fig. 17a (100, 250, 400 N); the sweep ranges (F0 = 10-500 N, P = 0-1000 N). Nothing \
         was fitted to the paper's numbers.\n"
    );
}
