//! The sweep figure: quantities against a swept parameter (for example the resonance-peak
//! amplitude or the resonance frequency against the pre-load) over shaded bands, or the FRF
//! bands of several sweep values on one chart.

use std::path::Path;

use plotters::style::RGBColor;

use super::axes::{linear_range, YAxis};
use super::backend::{write_figure, PlotError};
use super::chart::ChartSpec;
use super::series::{band_polygons, cover, lines, points, Band, Curve};
use super::strips::StripChart;
use super::style::{BAND_COLOR, BAND_LABEL};

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
    let chart = ChartSpec {
        x,
        x_log: false,
        y: YAxis::fit(ys(), fig.log_y),
        x_desc: fig.x_label.to_string(),
        y_desc: fig.y_label.to_string(),
        bands,
        curves,
    };
    write_figure(&StripChart::plain(fig.title, chart), png, svg)
}

#[cfg(test)]
mod tests {
    use super::super::style::palette;
    use super::super::testing::check_files;
    use super::*;

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
}
