//! The limit figure: the amplitude of one output DOF against frequency on a log axis, with the
//! variability band between the lower and upper limit shaded, the limit, intermediate and
//! reference curves on top, and below the chart optional marker rows: one marking the
//! frequencies with multiple solutions, and one per contact showing its state.

use std::path::Path;

use plotters::style::RGBColor;

use super::axes::{linear_range, log_range, YAxis};
use super::backend::{write_figure, PlotError};
use super::chart::ChartSpec;
use super::series::{band_polygons, cover, lines, points, Band, Curve};
use super::strips::{Strip, StripChart};
use super::style::{state_color, BAND_COLOR, BAND_LABEL};
use crate::contact::ContactState;

/// Frequency response of one output DOF with the variability band between the two limit curves.
pub struct LimitFigure<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Name of the output DOF, e.g. "y2"; the y label is `<name> first-harmonic amplitude (m)`.
    pub output_name: &'a str,
    /// Common frequency grid of the band and the marker rows (Hz).
    pub band_x: &'a [f64],
    /// Lower limit at each grid frequency (m); NaN where there is no solution.
    pub band_lower: &'a [f64],
    /// Upper limit at each grid frequency (m); NaN where there is no solution.
    pub band_upper: &'a [f64],
    /// Limit curves, intermediate curves and linear references.
    pub curves: &'a [Curve<'a>],
    /// Names of the state rows below the frequency axis, e.g. contact names.
    pub strip_names: &'a [String],
    /// State of each row at each grid point, `[grid point][row]`; empty for no state rows.
    pub strip_states: &'a [Vec<ContactState>],
    /// Whether multiple solutions exist at each grid point; empty for no "multiple solutions" row.
    pub multiple: &'a [bool],
}

/// Marker colour of the "multiple solutions" row.
const MULTIPLE_COLOR: RGBColor = RGBColor(118, 42, 131);
/// Name of the row marking multiple solutions.
const MULTIPLE_LABEL: &str = "multiple solutions";

/// Draws the amplitude of one output DOF against frequency on a log axis: the translucent band
/// between the lower and upper limit (one region per run of grid points with a solution), the
/// curves over it, and below the chart a "multiple solutions" row (if `multiple` is not empty)
/// and one state row per strip name (if `strip_states` is not empty) with the colour key of the
/// contact states. Writes both files.
pub fn plot_limits(fig: &LimitFigure, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let band = Band {
        label: BAND_LABEL.to_string(),
        polygons: band_polygons(fig.band_x, fig.band_lower, fig.band_upper, true),
        color: BAND_COLOR,
    };
    let curves = lines(fig.curves, true);

    let grid = fig.band_x.iter().copied();
    let x = linear_range(grid.chain(points(&curves).map(|p| p.0)), 0.0);
    let x = cover(x, std::slice::from_ref(&band));
    let band_ys = band.polygons.iter().flatten().map(|p| p.1);
    let y = log_range(band_ys.chain(points(&curves).map(|p| p.1)));

    let mut strips = Vec::new();
    if !fig.multiple.is_empty() {
        strips.push(Strip {
            name: MULTIPLE_LABEL.to_string(),
            marks: fig
                .band_x
                .iter()
                .zip(fig.multiple)
                .filter(|(x, &m)| m && x.is_finite())
                .map(|(&x, _)| (x, MULTIPLE_COLOR))
                .collect(),
        });
    }
    let state_rows = !fig.strip_states.is_empty() && !fig.strip_names.is_empty();
    if state_rows {
        for (row, name) in fig.strip_names.iter().enumerate() {
            strips.push(Strip {
                name: name.clone(),
                marks: fig
                    .band_x
                    .iter()
                    .zip(fig.strip_states)
                    .filter(|(x, _)| x.is_finite())
                    .filter_map(|(&x, states)| states.get(row).map(|&s| (x, state_color(s))))
                    .collect(),
            });
        }
    }

    let figure = StripChart {
        title: fig.title.to_string(),
        chart: ChartSpec {
            x,
            x_log: false,
            y: YAxis::Log(y.0, y.1),
            x_desc: "frequency (Hz)".to_string(),
            y_desc: format!("{} first-harmonic amplitude (m)", fig.output_name),
            bands: vec![band],
            curves,
        },
        strips,
        state_key: state_rows,
    };
    write_figure(&figure, png, svg)
}

#[cfg(test)]
mod tests {
    use super::super::style::palette;
    use super::super::testing::{check_files, resonance};
    use super::*;

    /// Limits of a synthetic friction-damped resonance: the band opens between the open and
    /// stuck resonances and has no solution in two frequency windows.
    struct Synthetic {
        f: Vec<f64>,
        lower: Vec<f64>,
        upper: Vec<f64>,
        open: Vec<f64>,
        stuck: Vec<f64>,
        states: Vec<Vec<ContactState>>,
        multiple: Vec<bool>,
    }

    fn synthetic() -> Synthetic {
        let f: Vec<f64> = (0..=300).map(|i| 80.0 + 0.5 * i as f64).collect();
        let open: Vec<f64> = f.iter().map(|&f| resonance(f, 120.0, 0.01, 1e-5)).collect();
        let stuck: Vec<f64> = f.iter().map(|&f| resonance(f, 190.0, 0.01, 1e-5)).collect();
        let mut lower: Vec<f64> = f.iter().map(|&f| resonance(f, 150.0, 0.08, 1e-5)).collect();
        let mut upper: Vec<f64> = f.iter().map(|&f| resonance(f, 150.0, 0.02, 1e-5)).collect();
        for (i, &fi) in f.iter().enumerate() {
            if (140.0..143.0).contains(&fi) || (fi - 170.0).abs() < 0.3 {
                lower[i] = f64::NAN;
                upper[i] = f64::NAN;
            }
        }
        lower[10] = 0.0;
        let multiple: Vec<bool> = lower.iter().zip(&upper).map(|(l, u)| u / l > 2.0).collect();
        let states = upper
            .iter()
            .zip(&f)
            .map(|(&a, &fi)| {
                let first = if a < 2e-5 {
                    ContactState::Stuck
                } else if a < 5e-5 {
                    ContactState::StickSlip
                } else {
                    ContactState::StickSlipLiftoff
                };
                let second = if fi < 130.0 {
                    ContactState::Open
                } else {
                    ContactState::Stuck
                };
                vec![first, second]
            })
            .collect();
        Synthetic {
            f,
            lower,
            upper,
            open,
            stuck,
            states,
            multiple,
        }
    }

    #[test]
    fn limits_figure_writes_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let s = synthetic();
        let names = vec!["c1".to_string(), "c2 (platform)".to_string()];
        let mid: Vec<f64> = s
            .lower
            .iter()
            .zip(&s.upper)
            .map(|(l, u)| (l * u).sqrt())
            .collect();
        let curves = [
            Curve {
                label: "linear, contacts open",
                x: &s.f,
                y: &s.open,
                color: palette(6),
                dashed: true,
                markers: false,
            },
            Curve {
                label: "linear, contacts stuck",
                x: &s.f,
                y: &s.stuck,
                color: palette(5),
                dashed: true,
                markers: false,
            },
            Curve {
                label: "lower limit",
                x: &s.f,
                y: &s.lower,
                color: palette(0),
                dashed: false,
                markers: false,
            },
            Curve {
                label: "upper limit",
                x: &s.f,
                y: &s.upper,
                color: palette(1),
                dashed: false,
                markers: false,
            },
            Curve {
                label: "intermediate solution",
                x: &s.f[..150],
                y: &mid,
                color: palette(2),
                dashed: false,
                markers: true,
            },
        ];
        let fig = LimitFigure {
            title: "synthetic limits",
            output_name: "y2",
            band_x: &s.f,
            band_lower: &s.lower,
            band_upper: &s.upper,
            curves: &curves,
            strip_names: &names,
            strip_states: &s.states,
            multiple: &s.multiple,
        };
        let (png, svg) = (dir.path().join("lim.png"), dir.path().join("lim.svg"));
        plot_limits(&fig, &png, &svg).unwrap();
        check_files(&png, &svg);
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.contains("y2 first-harmonic amplitude (m)"));
        assert!(svg_text.contains("frequency (Hz)"));
        assert!(svg_text.contains(MULTIPLE_LABEL));
        assert!(svg_text.contains(BAND_LABEL));
        assert!(svg_text.contains("c2 (platform)"));
        assert!(svg_text.contains("stick-slip-liftoff"));
        assert!(svg_text.contains("<polygon"));

        // Only the "multiple solutions" row, no state rows and no state key.
        let fig = LimitFigure {
            strip_states: &[],
            ..fig
        };
        let (png, svg) = (dir.path().join("lim2.png"), dir.path().join("lim2.svg"));
        plot_limits(&fig, &png, &svg).unwrap();
        check_files(&png, &svg);
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.contains(MULTIPLE_LABEL));
        assert!(!svg_text.contains("stick-slip-liftoff"));
    }

    #[test]
    fn limits_figure_survives_empty_and_bad_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let names = vec!["c1".to_string()];
        let nan = [f64::NAN; 4];
        let x = [1.0, f64::NAN, 3.0, 4.0];
        let lower = [1e-5, 1e-5, -1.0, f64::INFINITY];
        let upper = [2e-5, 2e-5, 1e-5, 1e-4];
        let states = vec![vec![ContactState::Stuck], vec![], vec![ContactState::Open]];
        let bad = [Curve {
            label: "bad",
            x: &x,
            y: &nan,
            color: palette(0),
            dashed: false,
            markers: true,
        }];
        let cases: Vec<LimitFigure> = vec![
            LimitFigure {
                title: "",
                output_name: "",
                band_x: &[],
                band_lower: &[],
                band_upper: &[],
                curves: &[],
                strip_names: &[],
                strip_states: &[],
                multiple: &[],
            },
            LimitFigure {
                title: "all NaN",
                output_name: "y1",
                band_x: &x,
                band_lower: &nan,
                band_upper: &nan,
                curves: &bad,
                strip_names: &names,
                strip_states: &states,
                multiple: &[true],
            },
            LimitFigure {
                title: "mismatched lengths",
                output_name: "y1",
                band_x: &x,
                band_lower: &lower,
                band_upper: &upper[..2],
                curves: &[],
                strip_names: &names,
                strip_states: &states,
                multiple: &[false, true, true, true, true, true],
            },
            LimitFigure {
                title: "one point",
                output_name: "y1",
                band_x: &x[..1],
                band_lower: &lower[..1],
                band_upper: &upper[..1],
                curves: &[],
                strip_names: &[],
                strip_states: &states,
                multiple: &[],
            },
        ];
        for (k, fig) in cases.iter().enumerate() {
            let (png, svg) = (
                dir.path().join(format!("e{k}.png")),
                dir.path().join(format!("e{k}.svg")),
            );
            plot_limits(fig, &png, &svg).unwrap();
            check_files(&png, &svg);
        }
    }
}
