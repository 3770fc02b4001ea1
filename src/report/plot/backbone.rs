//! The backbone figure of a nonlinear mode: a modal property (frequency, damping ratio)
//! against the vibration amplitude on a logarithmic amplitude axis, one curve per case, with
//! one strip per contact below it showing the contact state at each point (as the FRF figure).

use std::path::Path;

use super::axes::{log_range, YAxis};
use super::backend::{write_figure, PlotError};
use super::chart::ChartSpec;
use super::series::{lines, points, Curve};
use super::strips::{Strip, StripChart};
use super::style::state_color;
use crate::contact::ContactState;

/// The contact states along one curve of a backbone figure.
pub struct StateRow<'a> {
    /// Name written left of the strip, e.g. a contact name.
    pub name: String,
    /// Amplitude of each point (m), the figure's abscissa.
    pub x: &'a [f64],
    /// The contact's state at each point (none where unknown: no marker).
    pub states: Vec<Option<ContactState>>,
}

/// Inputs of a backbone figure.
pub struct BackboneFigure<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Description of the amplitude axis, with unit.
    pub x_label: &'a str,
    /// Description of the property axis, with unit.
    pub y_label: &'a str,
    /// One curve per case, abscissae being amplitudes (non-positive ones are skipped).
    pub curves: &'a [Curve<'a>],
    /// One strip per contact (and case), the first on top.
    pub states: &'a [StateRow<'a>],
}

/// Draws the curves on a log amplitude axis and a linear property axis, and below the chart one
/// strip per state row with the contact-state colour key. Writes both files.
pub fn plot_backbone(fig: &BackboneFigure, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let positive: Vec<Vec<f64>> = fig
        .curves
        .iter()
        .map(|c| {
            c.x.iter()
                .map(|&v| if v > 0.0 { v } else { f64::NAN })
                .collect()
        })
        .collect();
    let curves: Vec<Curve> = fig
        .curves
        .iter()
        .zip(&positive)
        .map(|(c, x)| Curve { x, ..*c })
        .collect();
    let curves = lines(&curves, false);
    let x = log_range(points(&curves).map(|p| p.0));
    let y = YAxis::fit(points(&curves).map(|p| p.1), false);
    let strips = fig
        .states
        .iter()
        .map(|row| Strip {
            name: row.name.clone(),
            marks: row
                .x
                .iter()
                .zip(&row.states)
                .filter(|(&a, _)| a.is_finite() && a > 0.0)
                .filter_map(|(&a, s)| s.map(|s| (a, state_color(s))))
                .collect(),
        })
        .collect();
    let figure = StripChart {
        title: fig.title.to_string(),
        chart: ChartSpec {
            x,
            x_log: true,
            y,
            x_desc: fig.x_label.to_string(),
            y_desc: fig.y_label.to_string(),
            bands: Vec::new(),
            curves,
        },
        strips,
        state_key: !fig.states.is_empty(),
    };
    write_figure(&figure, png, svg)
}

#[cfg(test)]
mod tests {
    use plotters::style::RGBColor;

    use super::super::testing::drawn;
    use super::*;

    #[test]
    fn backbone_with_strips_and_empty() {
        let dir = tempfile::tempdir().unwrap();
        let a: Vec<f64> = (0..40)
            .map(|i| 1e-7 * 10f64.powf(i as f64 / 10.0))
            .collect();
        let f: Vec<f64> = a.iter().map(|v| 100.0 - 10.0 * (v / 1e-5).atan()).collect();
        let states: Vec<Option<ContactState>> = a
            .iter()
            .map(|&v| {
                Some(if v < 1e-6 {
                    ContactState::Stuck
                } else if v < 1e-4 {
                    ContactState::StickSlip
                } else {
                    ContactState::Open
                })
            })
            .collect();
        let curves = [Curve {
            label: "",
            x: &a,
            y: &f,
            color: RGBColor(31, 100, 180),
            dashed: false,
            markers: true,
        }];
        let rows = [StateRow {
            name: "c1".to_string(),
            x: &a,
            states,
        }];
        let svg = drawn(dir.path(), "bb", |png, svg| {
            plot_backbone(
                &BackboneFigure {
                    title: "backbone",
                    x_label: "amplitude (m)",
                    y_label: "frequency (Hz)",
                    curves: &curves,
                    states: &rows,
                },
                png,
                svg,
            )
        });
        // Decade tick labels of the log amplitude axis, and the state key.
        assert!(svg.contains("1e-6"), "no decade tick");
        assert!(svg.contains("contact state:"));
        drawn(dir.path(), "empty", |png, svg| {
            plot_backbone(
                &BackboneFigure {
                    title: "nothing",
                    x_label: "a",
                    y_label: "f",
                    curves: &[],
                    states: &[],
                },
                png,
                svg,
            )
        });
    }
}
