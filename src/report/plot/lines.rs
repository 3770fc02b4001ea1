//! The plain line figure: labelled curves over a shared x axis, on a linear or log y axis,
//! with a legend (e.g. the scaling study of `fricbound bench`).

use std::path::Path;

use super::axes::{linear_range, YAxis};
use super::backend::{write_figure, PlotError};
use super::chart::ChartSpec;
use super::series::{lines, points, Curve};
use super::strips::StripChart;

/// Draws labelled curves over a shared x axis, with a legend; `log_y` puts the y axis on a log
/// scale (non-positive values are then skipped). Writes both files.
pub fn plot_lines(
    title: &str,
    x_label: &str,
    y_label: &str,
    log_y: bool,
    series: &[Curve],
    png: &Path,
    svg: &Path,
) -> Result<(), PlotError> {
    let curves = lines(series, log_y);
    let x = linear_range(points(&curves).map(|p| p.0), 0.0);
    let y = YAxis::fit(points(&curves).map(|p| p.1), log_y);
    let chart = ChartSpec {
        x,
        x_log: false,
        y,
        x_desc: x_label.to_string(),
        y_desc: y_label.to_string(),
        bands: Vec::new(),
        curves,
    };
    write_figure(&StripChart::plain(title, chart), png, svg)
}

#[cfg(test)]
mod tests {
    use plotters::style::{RGBColor, BLACK};

    use super::super::testing::drawn;
    use super::*;

    #[test]
    fn lines_figure_linear_and_log() {
        let dir = tempfile::tempdir().unwrap();
        let x: Vec<f64> = (0..50).map(|i| i as f64).collect();
        let y1: Vec<f64> = x.iter().map(|v| (v / 5.0).sin()).collect();
        let y2: Vec<f64> = x.iter().map(|v| 1e-3 * (v - 10.0)).collect();
        let series = [
            Curve {
                label: "sine",
                x: &x,
                y: &y1,
                color: RGBColor(200, 30, 30),
                dashed: false,
                markers: false,
            },
            Curve {
                label: "ramp",
                x: &x,
                y: &y2[..20],
                color: RGBColor(31, 100, 180),
                dashed: true,
                markers: false,
            },
            Curve {
                label: "",
                x: &[],
                y: &[],
                color: BLACK,
                dashed: false,
                markers: false,
            },
        ];
        for log_y in [false, true] {
            drawn(dir.path(), &format!("l{log_y}"), |png, svg| {
                plot_lines("lines", "x (s)", "y (m)", log_y, &series, png, svg)
            });
        }
        drawn(dir.path(), "none", |png, svg| {
            plot_lines("nothing", "x", "y", true, &[], png, svg)
        });
    }

    #[test]
    fn unwritable_path_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("missing").join("a.png");
        let svg = dir.path().join("missing").join("a.svg");
        let err = plot_lines("t", "x", "y", false, &[], &png, &svg).unwrap_err();
        assert!(err.to_string().contains("a.png"));
    }
}
