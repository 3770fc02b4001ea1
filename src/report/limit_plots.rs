//! Figures of the limit analysis, each written as a 1200×800 PNG and as an SVG.
//!
//! [`plot_limits`] draws the first-harmonic amplitude of one output DOF against frequency on a
//! log axis, with the variability band between the lower and upper limit shaded, the limit,
//! intermediate and reference curves on top, and below the chart optional marker rows: one
//! marking the frequencies with multiple solutions, and one per contact showing its state.
//! [`plot_sweep`] draws quantities against a swept parameter (for example the peak amplitude or
//! the resonance frequency against the pre-load), or several FRF bands on one chart, over
//! shaded bands ([`BandSpec`]).
//! [`plot_hysteresis`] draws closed tangential force–displacement loops over one period.
//! [`palette`] gives distinct line colours.
//!
//! Layout, fonts, axes and legends are those of [`crate::report::plot`]. Values that cannot be
//! drawn (non-finite, or non-positive on a log axis) are skipped: they break lines and split the
//! band into separate regions. Empty inputs give an empty chart, never a panic.

use std::path::Path;

use plotters::style::RGBColor;

use crate::contact::ContactState;
use crate::report::plot::{
    linear_range, log_range, state_color, valid_runs, write_figure, Band, ChartSpec, Line,
    PlotError, Strip, StripChart, YAxis,
};

/// One curve of a limit figure; `x` and `y` are paired up to the shorter length.
pub struct Curve<'a> {
    /// Legend label (no legend entry if empty).
    pub label: &'a str,
    /// Abscissae.
    pub x: &'a [f64],
    /// Ordinates.
    pub y: &'a [f64],
    /// Line colour, e.g. from [`palette`].
    pub color: RGBColor,
    /// Dashed rather than solid.
    pub dashed: bool,
    /// A filled circle at every point.
    pub markers: bool,
}

/// Frequency response of one output DOF with the variability band between the two limit curves.
pub struct LimitFigure<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Name of the output DOF, e.g. "y2"; the y label is "<name> first-harmonic amplitude (m)".
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

/// A quantity against a swept parameter, with an optional shaded band.
pub struct SweepFigure<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Description of the x axis, with unit.
    pub x_label: &'a str,
    /// Description of the y axis, with unit.
    pub y_label: &'a str,
    /// Log y axis (non-positive values are then skipped).
    pub log_y: bool,
    /// Translucent bands; entries with a non-drawable value are skipped.
    pub bands: &'a [BandSpec<'a>],
    /// Lines drawn over the bands.
    pub curves: &'a [Curve<'a>],
}

/// A translucent band between two curves over shared abscissae (paired up to the shortest).
pub struct BandSpec<'a> {
    /// Legend label (no legend entry if empty).
    pub label: &'a str,
    /// Abscissae.
    pub x: &'a [f64],
    /// One limit.
    pub lower: &'a [f64],
    /// The other limit (the two may cross).
    pub upper: &'a [f64],
    /// Fill colour (drawn translucent).
    pub color: RGBColor,
}

impl BandSpec<'_> {
    /// The default variability-band label and colour.
    pub fn variability<'a>(x: &'a [f64], lower: &'a [f64], upper: &'a [f64]) -> BandSpec<'a> {
        BandSpec {
            label: BAND_LABEL,
            x,
            lower,
            upper,
            color: BAND_COLOR,
        }
    }
}

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

/// Label of the shaded band in the legends.
const BAND_LABEL: &str = "variability band";
/// Fill colour of the band (drawn translucent).
const BAND_COLOR: RGBColor = RGBColor(70, 130, 180);
/// Marker colour of the "multiple solutions" row.
const MULTIPLE_COLOR: RGBColor = RGBColor(118, 42, 131);
/// Name of the row marking multiple solutions.
const MULTIPLE_LABEL: &str = "multiple solutions";

/// Okabe–Ito colours without yellow (too faint on white), then Tol's muted wine, olive, indigo
/// and teal, and grey.
const PALETTE: [RGBColor; 12] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(136, 34, 85),
    RGBColor(153, 153, 51),
    RGBColor(51, 34, 136),
    RGBColor(68, 170, 153),
    RGBColor(120, 120, 120),
];

/// Colour of curve `i`: twelve distinct colours, the first seven the colour-blind-safe
/// Okabe–Ito set; repeats after twelve.
pub fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

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

/// Draws the curves against the swept parameter (or any x quantity) over the translucent bands,
/// on a linear x axis and a linear or log y axis, with a legend. Writes both files.
pub fn plot_sweep(fig: &SweepFigure, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let bands: Vec<Band> = fig
        .bands
        .iter()
        .map(|b| Band {
            label: b.label.to_string(),
            polygons: band_polygons(b.x, b.lower, b.upper, fig.log_y),
            color: b.color,
        })
        .collect();
    let curves = lines(fig.curves, fig.log_y);
    let ys = || {
        let band_ys = bands.iter().flat_map(|b| b.polygons.iter().flatten());
        band_ys.map(|p| p.1).chain(points(&curves).map(|p| p.1))
    };
    let grid = fig.bands.iter().flat_map(|b| b.x.iter().copied());
    let x = linear_range(grid.chain(points(&curves).map(|p| p.0)), 0.02);
    let x = cover(x, &bands);
    let y = if fig.log_y {
        let (lo, hi) = log_range(ys());
        YAxis::Log(lo, hi)
    } else {
        let (lo, hi) = linear_range(ys(), 0.05);
        YAxis::Linear(lo, hi)
    };
    let figure = StripChart {
        title: fig.title.to_string(),
        chart: ChartSpec {
            x,
            y,
            x_desc: fig.x_label.to_string(),
            y_desc: fig.y_label.to_string(),
            bands,
            curves,
        },
        strips: Vec::new(),
        state_key: false,
    };
    write_figure(&figure, png, svg)
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
            }
        })
        .collect();
    let x = linear_range(points(&curves).map(|p| p.0), 0.05);
    let (lo, hi) = linear_range(points(&curves).map(|p| p.1), 0.05);
    let figure = StripChart {
        title: title.to_string(),
        chart: ChartSpec {
            x,
            y: YAxis::Linear(lo, hi),
            x_desc: "tangential relative displacement u (m)".to_string(),
            y_desc: "tangential force T (N)".to_string(),
            bands: Vec::new(),
            curves,
        },
        strips: Vec::new(),
        state_key: false,
    };
    write_figure(&figure, png, svg)
}

/// All drawable points of the lines.
fn points(lines: &[Line]) -> impl Iterator<Item = (f64, f64)> + '_ {
    lines.iter().flat_map(|c| c.runs.iter().flatten().copied())
}

/// The x range `(lo, hi)` widened to cover every band.
fn cover((lo, hi): (f64, f64), bands: &[Band]) -> (f64, f64) {
    bands
        .iter()
        .flat_map(|b| b.polygons.iter().flatten())
        .fold((lo, hi), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)))
}

/// The drawable runs of each curve.
fn lines(curves: &[Curve], log_y: bool) -> Vec<Line> {
    curves
        .iter()
        .map(|c| Line {
            label: c.label.to_string(),
            runs: valid_runs(c.x.iter().copied().zip(c.y.iter().copied()), log_y),
            color: c.color,
            dashed: c.dashed,
            markers: c.markers,
        })
        .collect()
}

/// Outlines of the band between `lower` and `upper` over `x` (paired up to the shortest length):
/// one polygon per run of consecutive drawable entries (all finite, limits positive if `log_y`),
/// along the larger limit forwards and the smaller one backwards. An isolated drawable entry
/// becomes a narrow rectangle reaching a quarter of the way to the nearest other abscissa.
fn band_polygons(x: &[f64], lower: &[f64], upper: &[f64], log_y: bool) -> Vec<Vec<(f64, f64)>> {
    let n = x.len().min(lower.len()).min(upper.len());
    let ok = |i: usize| {
        let (a, b) = (lower[i], upper[i]);
        x[i].is_finite() && a.is_finite() && b.is_finite() && (!log_y || (a > 0.0 && b > 0.0))
    };
    let mut polygons = Vec::new();
    let mut i = 0;
    while i < n {
        if !ok(i) {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && ok(i) {
            i += 1;
        }
        let run = start..i;
        if run.len() == 1 {
            let (lo, hi) = (
                lower[start].min(upper[start]),
                lower[start].max(upper[start]),
            );
            let left = x[..start].iter().rev().find(|v| v.is_finite());
            let right = x[start + 1..].iter().find(|v| v.is_finite());
            let gap = left
                .into_iter()
                .chain(right)
                .map(|v| (v - x[start]).abs())
                .filter(|d| *d > 0.0)
                .fold(f64::INFINITY, f64::min);
            let half = if gap.is_finite() {
                0.25 * gap
            } else {
                0.005 * x[start].abs().max(1.0)
            };
            let (l, r) = (x[start] - half, x[start] + half);
            polygons.push(vec![(l, hi), (r, hi), (r, lo), (l, lo)]);
            continue;
        }
        let mut polygon: Vec<(f64, f64)> = run
            .clone()
            .map(|j| (x[j], lower[j].max(upper[j])))
            .collect();
        polygon.extend(run.rev().map(|j| (x[j], lower[j].min(upper[j]))));
        polygons.push(polygon);
    }
    polygons
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_files(png: &Path, svg: &Path) {
        let png_bytes = std::fs::read(png).unwrap();
        assert!(png_bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]));
        let svg_text = std::fs::read_to_string(svg).unwrap();
        assert!(svg_text.contains("<svg"));
    }

    fn resonance(f: f64, f0: f64, zeta: f64, a0: f64) -> f64 {
        let r = f / f0;
        a0 / ((1.0 - r * r).powi(2) + (2.0 * zeta * r).powi(2)).sqrt()
    }

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

    #[test]
    fn sweep_figure_linear_and_log() {
        let dir = tempfile::tempdir().unwrap();
        let n0: Vec<f64> = (0..40).map(|i| 10.0 * i as f64).collect();
        let mut upper: Vec<f64> = n0.iter().map(|n| 1e-4 / (1.0 + n / 50.0)).collect();
        let lower: Vec<f64> = n0
            .iter()
            .map(|n| 1e-4 / (1.0 + n / 50.0) * (0.3 + 0.7 * (n / 390.0)))
            .collect();
        upper[12] = f64::NAN;
        upper[20] = 0.0;
        let peak: Vec<f64> = lower
            .iter()
            .zip(&upper)
            .map(|(l, u)| 0.5 * (l + u))
            .collect();
        let freq: Vec<f64> = n0.iter().map(|n| 120.0 + 70.0 * n / (n + 80.0)).collect();
        let curves = [
            Curve {
                label: "upper limit of the peak amplitude",
                x: &n0,
                y: &upper,
                color: palette(1),
                dashed: false,
                markers: true,
            },
            Curve {
                label: "lower limit of the peak amplitude",
                x: &n0,
                y: &lower,
                color: palette(0),
                dashed: false,
                markers: true,
            },
            Curve {
                label: "mean",
                x: &n0,
                y: &peak,
                color: palette(2),
                dashed: true,
                markers: false,
            },
        ];
        for log_y in [false, true] {
            let fig = SweepFigure {
                title: "peak amplitude against pre-load",
                x_label: "normal pre-load N0 (N)",
                y_label: "peak amplitude (m)",
                log_y,
                bands: &[BandSpec::variability(&n0, &lower, &upper)],
                curves: &curves,
            };
            let (png, svg) = (
                dir.path().join(format!("s{log_y}.png")),
                dir.path().join(format!("s{log_y}.svg")),
            );
            plot_sweep(&fig, &png, &svg).unwrap();
            check_files(&png, &svg);
            let svg_text = std::fs::read_to_string(&svg).unwrap();
            assert!(svg_text.contains("normal pre-load N0 (N)"));
            assert!(svg_text.contains(BAND_LABEL));
        }
        let freq_curve = [Curve {
            label: "resonance frequency",
            x: &n0,
            y: &freq,
            color: palette(3),
            dashed: false,
            markers: true,
        }];
        let fig = SweepFigure {
            title: "resonance frequency against pre-load",
            x_label: "normal pre-load N0 (N)",
            y_label: "resonance frequency (Hz)",
            log_y: false,
            bands: &[],
            curves: &freq_curve,
        };
        let (png, svg) = (dir.path().join("freq.png"), dir.path().join("freq.svg"));
        plot_sweep(&fig, &png, &svg).unwrap();
        check_files(&png, &svg);
        assert!(!std::fs::read_to_string(&svg).unwrap().contains(BAND_LABEL));

        let negative = [-1.0, 0.0, f64::NAN];
        for (k, fig) in [
            SweepFigure {
                title: "",
                x_label: "",
                y_label: "",
                log_y: true,
                bands: &[],
                curves: &[],
            },
            SweepFigure {
                title: "nothing positive",
                x_label: "x",
                y_label: "y",
                log_y: true,
                bands: &[BandSpec::variability(&negative, &negative, &negative)],
                curves: &[Curve {
                    label: "negative",
                    x: &negative,
                    y: &negative,
                    color: palette(0),
                    dashed: false,
                    markers: true,
                }],
            },
            SweepFigure {
                title: "empty band",
                x_label: "x",
                y_label: "y",
                log_y: false,
                bands: &[BandSpec::variability(&[], &[], &[])],
                curves: &[],
            },
        ]
        .iter()
        .enumerate()
        {
            let (png, svg) = (
                dir.path().join(format!("se{k}.png")),
                dir.path().join(format!("se{k}.svg")),
            );
            plot_sweep(fig, &png, &svg).unwrap();
            check_files(&png, &svg);
        }
    }

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

    #[test]
    fn loops_are_closed_and_bands_split_at_gaps() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let lower = [1.0, 1.0, f64::NAN, 1.0, 3.0, 1.0];
        let upper = [2.0, 2.0, 2.0, 2.0, 1.0, -1.0];
        let polygons = band_polygons(&x, &lower, &upper, true);
        assert_eq!(polygons.len(), 2);
        assert_eq!(
            polygons[0],
            vec![(1.0, 2.0), (2.0, 2.0), (2.0, 1.0), (1.0, 1.0)]
        );
        // The limits are ordered per point; the negative limit ends the run on a log axis.
        assert_eq!(
            polygons[1],
            vec![(4.0, 2.0), (5.0, 3.0), (5.0, 1.0), (4.0, 1.0)]
        );
        let polygons = band_polygons(&x, &lower, &upper, false);
        assert_eq!(polygons[1].len(), 6);
        // An isolated point becomes a narrow rectangle.
        let polygons = band_polygons(&x[..3], &[f64::NAN, 1.0, f64::NAN], &[2.0; 3], true);
        assert_eq!(
            polygons,
            vec![vec![(1.75, 2.0), (2.25, 2.0), (2.25, 1.0), (1.75, 1.0)]]
        );
        assert!(band_polygons(&[], &[], &[], true).is_empty());
    }

    #[test]
    fn palette_colours_are_distinct() {
        let colours: Vec<RGBColor> = (0..PALETTE.len()).map(palette).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                assert_ne!((a.0, a.1, a.2), (b.0, b.1, b.2));
            }
        }
        assert_eq!(palette(PALETTE.len()), palette(0));
    }
}
