//! The hysteresis figure: closed tangential force–displacement loops T(u) of one contact over
//! one period, one loop per curve and place (e.g. each limit curve at its resonance peak).

use std::path::Path;

use plotters::style::RGBColor;

use super::axes::{linear_range, YAxis};
use super::backend::{write_figure, PlotError};
use super::chart::ChartSpec;
use super::series::{points, valid_runs, Line};
use super::strips::StripChart;

/// One closed hysteresis loop; `u` and `t` are paired up to the shorter length.
pub struct Loop<'a> {
    /// Legend label (no legend entry if empty).
    pub label: &'a str,
    /// Tangential relative displacement over one period (m).
    pub u: &'a [f64],
    /// Tangential force over one period (N).
    pub t: &'a [f64],
    /// Line colour.
    pub color: RGBColor,
}

/// Draws one closed loop T(u) per series (its first point repeated at the end) on linear axes,
/// with a legend. Writes both files.
pub fn plot_hysteresis(
    title: &str,
    loops: &[Loop],
    png: &Path,
    svg: &Path,
) -> Result<(), PlotError> {
    let curves: Vec<Line> = loops
        .iter()
        .map(|l| {
            let n = l.u.len().min(l.t.len());
            let pairs = l.u[..n].iter().copied().zip(l.t[..n].iter().copied());
            let first = l.u.first().copied().zip(l.t.first().copied());
            Line {
                label: l.label.to_string(),
                runs: valid_runs(pairs.chain(first), false),
                color: l.color,
                dashed: false,
                markers: false,
                listed: false,
            }
        })
        .collect();
    let chart = ChartSpec {
        x: linear_range(points(&curves).map(|p| p.0), 0.05),
        x_log: false,
        y: YAxis::fit(points(&curves).map(|p| p.1), false),
        x_desc: "tangential relative displacement u (m)".to_string(),
        y_desc: "tangential force T (N)".to_string(),
        bands: Vec::new(),
        curves,
    };
    write_figure(&StripChart::plain(title, chart), png, svg)
}

#[cfg(test)]
mod tests {
    use super::super::style::palette;
    use super::super::testing::check_files;
    use super::*;

    /// Tangential force of a Jenkins element (stiffness `k`, slip force `mu_n`) under
    /// `u = a sin(phase)`, over one period.
    fn jenkins(a: f64, k: f64, mu_n: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let phases = (0..n).map(|i| 2.0 * std::f64::consts::PI * i as f64 / n as f64);
        let u: Vec<f64> = phases.map(|p| a * p.sin()).collect();
        // Start from the steady state at the displacement maximum: T = min(k a, mu N).
        let mut t = Vec::with_capacity(n);
        let mut prev_u = u[0];
        let mut prev_t = if k * a > mu_n {
            (-mu_n + k * a).min(mu_n)
        } else {
            0.0
        };
        for &ui in &u {
            let trial = prev_t + k * (ui - prev_u);
            let ti = trial.clamp(-mu_n, mu_n);
            t.push(ti);
            prev_u = ui;
            prev_t = ti;
        }
        (u, t)
    }

    #[test]
    fn hysteresis_figure_writes_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let (u1, t1) = jenkins(2e-6, 1e6, 1.0, 256);
        let (u2, t2) = jenkins(5e-6, 1e6, 2.0, 256);
        let (u3, mut t3) = jenkins(8e-6, 1e6, 3.0, 128);
        t3[40] = f64::NAN;
        let loops = [
            Loop {
                label: "c1, 140 Hz",
                u: &u1,
                t: &t1,
                color: palette(0),
            },
            Loop {
                label: "c1, 150 Hz",
                u: &u2,
                t: &t2,
                color: palette(1),
            },
            Loop {
                label: "c1, 160 Hz (one bad sample)",
                u: &u3,
                t: &t3,
                color: palette(2),
            },
            Loop {
                label: "empty",
                u: &[],
                t: &[],
                color: palette(3),
            },
        ];
        let (png, svg) = (dir.path().join("h.png"), dir.path().join("h.svg"));
        plot_hysteresis("hysteresis loops", &loops, &png, &svg).unwrap();
        check_files(&png, &svg);
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.contains("tangential relative displacement u (m)"));
        assert!(svg_text.contains("tangential force T (N)"));
        assert!(svg_text.contains("c1, 150 Hz"));
        assert!(!svg_text.contains(">empty<"));

        let (png, svg) = (dir.path().join("h0.png"), dir.path().join("h0.svg"));
        plot_hysteresis("", &[], &png, &svg).unwrap();
        check_files(&png, &svg);
        let nan = [f64::NAN, 1.0];
        let one = [Loop {
            label: "degenerate",
            u: &nan,
            t: &[1.0],
            color: palette(0),
        }];
        let (png, svg) = (dir.path().join("h1.png"), dir.path().join("h1.svg"));
        plot_hysteresis("degenerate", &one, &png, &svg).unwrap();
        check_files(&png, &svg);
    }
}
