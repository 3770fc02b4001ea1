//! Result tables of limit analyses and sweeps (CSV), written atomically.
//!
//! * `limits.csv`: the common grid: `freq_hz`, per limit case `<case>_amp`, `lower_amp`,
//!   `upper_amp`, `regime` (`unique`, `multiple`, `unknown`), `stuck_sides`, `slipping_sides`,
//!   per limit case `<case>_N0_slipping` (N) and `<case>_label`, per limit case and contact
//!   `<case>_<contact>_state`, then with `[limits] envelope` per output DOF
//!   `<dof>_envelope_min_amp` and `<dof>_envelope_max_amp` (m; NaN where no state was solved).
//!   A limit curve that did not cover the range has NaN amplitudes
//!   (and empty states) where it has no solution; the band (`lower_amp`, `upper_amp`) is NaN
//!   and the regime `unknown` wherever either limit curve is missing.
//! * `peaks.csv`: one row per case: `curve`, `kind` (limit, intermediate, scan), `m_<contact>`
//!   per contact point, `peak_freq_hz`, `peak_amp`, `refined` (empty where the case has no
//!   finished point in the peak window), `status` (`complete`, `incomplete: …`, `failed: …`).
//! * `hysteresis_<curve>_<where>.csv`: `tau`, then per contact `u` (m), `T` (N), `v` (m), `N`
//!   (N) samples over one period.
//! * `sweep.csv`: `[<series>,]<parameter>`, per case `<case>_peak_amp` (m) and
//!   `<case>_peak_freq_hz`, then `limit_amp_ratio` (larger over smaller limit peak),
//!   `limit_freq_change_pct` (100·(higher − lower)/lower resonance frequency), `refined`
//!   (both limit peaks are interior maxima) and `failures`. Empty cells where a case failed.
//! * `variability.csv` (sweeps of whole limit analyses): per sweep point the limit peaks, their
//!   ratio and frequency change, the widest band, the multiple-solution share and the bound
//!   scan's largest excesses.

use std::fmt::Write as _;

use crate::analysis::limits::{
    CurveStatus, Envelope, GridPoint, HysteresisLoop, LimitCase, Peak, Regime,
};
use crate::model::Problem;
use crate::study::sweep::SweepPoint;

fn side_list(problem: &Problem, sides: &[usize]) -> String {
    sides
        .iter()
        .map(|&s| problem.sides[s].name.as_str())
        .collect::<Vec<_>>()
        .join(";")
}

/// `limits.csv` text (with the envelope's columns when one is given).
pub fn limits_csv(
    problem: &Problem,
    cases: &[LimitCase],
    grid: &[GridPoint],
    envelope: Option<&Envelope>,
) -> String {
    let mut s = String::from("freq_hz");
    for c in cases {
        let _ = write!(s, ",{}_amp", c.name);
    }
    s.push_str(",lower_amp,upper_amp,regime,stuck_sides,slipping_sides");
    for c in cases {
        let _ = write!(s, ",{0}_N0_slipping,{0}_label", c.name);
    }
    for c in cases {
        for contact in &problem.contacts {
            let _ = write!(s, ",{}_{}_state", c.name, contact.name);
        }
    }
    if envelope.is_some() {
        for &d in &problem.outputs {
            let dof = &problem.model.dof_names[d];
            let _ = write!(s, ",{dof}_envelope_min_amp,{dof}_envelope_max_amp");
        }
    }
    s.push('\n');
    for (i, g) in grid.iter().enumerate() {
        let _ = write!(s, "{:.10e}", g.freq_hz);
        for a in &g.amplitudes {
            let _ = write!(s, ",{a:.10e}");
        }
        let _ = write!(s, ",{:.10e},{:.10e}", g.lower, g.upper);
        let (regime, stuck, slipping) = match &g.regime {
            Regime::Unique => ("unique", String::new(), String::new()),
            Regime::Multiple {
                stuck_sides,
                slipping_sides,
            } => (
                "multiple",
                side_list(problem, stuck_sides),
                side_list(problem, slipping_sides),
            ),
            Regime::Unknown => ("unknown", String::new(), String::new()),
        };
        let _ = write!(s, ",{regime},{stuck},{slipping}");
        for (c, label) in g.labels.iter().enumerate() {
            let n0 = match &g.regime {
                Regime::Multiple { slipping_sides, .. } if !g.statics[c].is_empty() => {
                    format!(
                        "{:.10e}",
                        slipping_sides
                            .iter()
                            .map(|&k| g.statics[c][k].normal)
                            .sum::<f64>()
                    )
                }
                _ => String::new(),
            };
            let _ = write!(s, ",{n0},{}", label.map(|l| l.text()).unwrap_or(""));
        }
        for states in &g.states {
            if states.is_empty() {
                for _ in &problem.contacts {
                    s.push(',');
                }
            } else {
                for st in states {
                    let _ = write!(s, ",{}", st.label());
                }
            }
        }
        if let Some(e) = envelope {
            let p = e.points.get(i);
            for o in 0..problem.outputs.len() {
                let amp = |b: Option<&Option<crate::analysis::limits::EnvelopeBound>>| {
                    b.and_then(|b| b.as_ref()).map_or(f64::NAN, |b| b.amplitude)
                };
                let _ = write!(
                    s,
                    ",{:.10e},{:.10e}",
                    amp(p.and_then(|p| p.min.get(o))),
                    amp(p.and_then(|p| p.max.get(o)))
                );
            }
        }
        s.push('\n');
    }
    s
}

/// One row of `peaks.csv`: the case, its kind (`limit`, `intermediate`, `scan`), its peak
/// (`None`: no finished point in the peak window) and how it ended.
pub type PeakRow<'a> = (&'a LimitCase, &'a str, Option<&'a Peak>, &'a CurveStatus);

/// `peaks.csv` text: one row per case, empty peak cells where the case has no peak, and its
/// status (`complete`, `incomplete: …`, `failed: …`, quoted).
pub fn peaks_csv(problem: &Problem, rows: &[PeakRow<'_>]) -> String {
    let mut s = String::from("curve,kind");
    for contact in &problem.contacts {
        let _ = write!(s, ",m_{}", contact.name);
    }
    s.push_str(",peak_freq_hz,peak_amp,refined,status\n");
    for (case, kind, peak, status) in rows {
        let _ = write!(s, "{},{kind}", case.name);
        for m in &case.contact_states {
            let _ = write!(s, ",{m}");
        }
        match peak {
            Some(peak) => {
                let _ = write!(
                    s,
                    ",{:.10e},{:.10e},{}",
                    peak.freq_hz, peak.amplitude, peak.refined
                );
            }
            None => s.push_str(",,,"),
        }
        let _ = writeln!(s, ",\"{}\"", status.text().replace('"', "'"));
    }
    s
}

/// `hysteresis_<curve>.csv` text.
pub fn hysteresis_csv(loops: &[HysteresisLoop]) -> String {
    let mut s = String::from("tau");
    for l in loops {
        let _ = write!(s, ",{0}_u,{0}_T,{0}_v,{0}_N", l.contact);
    }
    s.push('\n');
    let n = loops.first().map(|l| l.u.len()).unwrap_or(0);
    for k in 0..n {
        let _ = write!(
            s,
            "{:.10e}",
            2.0 * std::f64::consts::PI * k as f64 / n as f64
        );
        for l in loops {
            let _ = write!(
                s,
                ",{:.10e},{:.10e},{:.10e},{:.10e}",
                l.u[k], l.t[k], l.v[k], l.n[k]
            );
        }
        s.push('\n');
    }
    s
}

/// `sweep.csv` text for finished points (sorted by series, then parameter value).
pub fn sweep_csv(series: Option<&str>, parameter: &str, points: &[SweepPoint]) -> String {
    let mut sorted: Vec<&SweepPoint> = points.iter().collect();
    sorted.sort_by(|a, b| {
        a.series
            .unwrap_or(0.0)
            .total_cmp(&b.series.unwrap_or(0.0))
            .then(a.value.total_cmp(&b.value))
    });
    let mut s = String::new();
    if let Some(name) = series {
        let _ = write!(s, "{name},");
    }
    s.push_str(parameter);
    if let Some(first) = sorted.first() {
        for c in &first.cases {
            let _ = write!(s, ",{c}_peak_amp,{c}_peak_freq_hz");
        }
    }
    s.push_str(",limit_amp_ratio,limit_freq_change_pct,refined,failures\n");
    for p in sorted {
        if series.is_some() {
            let _ = write!(s, "{:.10e},", p.series.unwrap_or(f64::NAN));
        }
        let _ = write!(s, "{:.10e}", p.value);
        for peak in &p.peaks {
            match peak {
                Some(peak) => {
                    let _ = write!(s, ",{:.10e},{:.10e}", peak.amplitude, peak.freq_hz);
                }
                None => s.push_str(",,"),
            }
        }
        match (p.limit_amplitudes(), p.limit_frequencies()) {
            (Some((hi, lo)), Some((fhi, flo))) => {
                let _ = write!(s, ",{:.10e},{:.10e}", hi / lo, 100.0 * (fhi - flo) / flo);
            }
            _ => s.push_str(",,"),
        }
        let _ = writeln!(
            s,
            ",{},\"{}\"",
            p.limits_refined(),
            p.failures.join("; ").replace('"', "'")
        );
    }
    s
}

/// `variability.csv` text: one row per sweep point with a limit analysis.
pub fn variability_csv(series: Option<&str>, parameter: &str, points: &[SweepPoint]) -> String {
    let mut s = String::new();
    if let Some(name) = series {
        let _ = write!(s, "{name},");
    }
    s.push_str(parameter);
    s.push_str(
        ",upper_peak_amp,lower_peak_amp,limit_amp_ratio,limit_freq_change_pct,widest_band_amp,\
         widest_band_freq_hz,multiple_points,grid_points,bound_excess_above_pct,\
         bound_excess_below_pct\n",
    );
    for p in points {
        let Some(a) = &p.analysis else { continue };
        let v = a.variability();
        if series.is_some() {
            let _ = write!(s, "{:.10e},", p.series.unwrap_or(f64::NAN));
        }
        let _ = write!(
            s,
            "{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{},{}",
            p.value,
            v.upper_peak,
            v.lower_peak,
            v.peak_ratio,
            v.peak_freq_change_pct,
            v.widest_band,
            v.widest_band_hz,
            v.multiple_points,
            v.grid_points
        );
        match &a.bounds {
            Some(b) => {
                let _ = writeln!(
                    s,
                    ",{:.6e},{:.6e}",
                    100.0 * b.max_excess_above,
                    100.0 * b.max_excess_below
                );
            }
            None => s.push_str(",,\n"),
        }
    }
    s
}
