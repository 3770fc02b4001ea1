//! Result tables of limit analyses and sweeps (CSV), written atomically.
//!
//! * `limits.csv`: the common grid: `freq_hz`, per limit case `<case>_amp`, `lower_amp`,
//!   `upper_amp`, `regime` (`unique`, `multiple`, `unknown`), `stuck_sides`, `slipping_sides`,
//!   per limit case `<case>_N0_slipping` (N) and `<case>_label`, per limit case and contact
//!   `<case>_<contact>_state`.
//! * `peaks.csv`: one row per curve: `curve`, `kind` (limit, intermediate, scan), m per side,
//!   `peak_freq_hz`, `peak_amp`, `refined`.
//! * `hysteresis_<curve>.csv`: per contact `u`, `T`, `v`, `N` samples over one period.
//! * `sweep.csv`: `<parameter>`, per case `<case>_peak_amp` and `<case>_peak_freq_hz`, then
//!   `limit_amp_ratio` (larger over smaller limit peak) and `limit_freq_change_pct`.

use std::fmt::Write as _;

use crate::limits::{GridPoint, HysteresisLoop, LimitCase, Peak, Regime};
use crate::model::Problem;
use crate::sweep::SweepPoint;

fn side_list(problem: &Problem, sides: &[usize]) -> String {
    sides
        .iter()
        .map(|&s| problem.sides[s].name.as_str())
        .collect::<Vec<_>>()
        .join(";")
}

/// `limits.csv` text.
pub fn limits_csv(problem: &Problem, cases: &[LimitCase], grid: &[GridPoint]) -> String {
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
    s.push('\n');
    for g in grid {
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
        s.push('\n');
    }
    s
}

/// `peaks.csv` text from (case, kind, peak) rows.
pub fn peaks_csv(problem: &Problem, rows: &[(&LimitCase, &str, &Peak)]) -> String {
    let mut s = String::from("curve,kind");
    for side in &problem.sides {
        let _ = write!(s, ",m_{}", side.name);
    }
    s.push_str(",peak_freq_hz,peak_amp,refined\n");
    for (case, kind, peak) in rows {
        let _ = write!(s, "{},{kind}", case.name);
        for m in &case.side_states {
            let _ = write!(s, ",{m}");
        }
        let _ = writeln!(
            s,
            ",{:.10e},{:.10e},{}",
            peak.freq_hz, peak.amplitude, peak.refined
        );
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

/// `sweep.csv` text for finished points (sorted by parameter value).
pub fn sweep_csv(parameter: &str, points: &[SweepPoint]) -> String {
    let mut sorted: Vec<&SweepPoint> = points.iter().collect();
    sorted.sort_by(|a, b| a.value.total_cmp(&b.value));
    let mut s = parameter.to_string();
    if let Some(first) = sorted.first() {
        for c in &first.cases {
            let _ = write!(s, ",{c}_peak_amp,{c}_peak_freq_hz");
        }
    }
    s.push_str(",limit_amp_ratio,limit_freq_change_pct\n");
    for p in sorted {
        let _ = write!(s, "{:.10e}", p.value);
        for peak in &p.peaks {
            let _ = write!(s, ",{:.10e},{:.10e}", peak.amplitude, peak.freq_hz);
        }
        let (hi, lo) = p.limit_amplitudes();
        let (fhi, flo) = p.limit_frequencies();
        let _ = writeln!(s, ",{:.10e},{:.10e}", hi / lo, 100.0 * (fhi - flo) / flo);
    }
    s
}
