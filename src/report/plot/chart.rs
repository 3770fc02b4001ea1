//! One chart: axes with grid, tick labels and descriptions, the translucent bands, the lines
//! (solid or dashed, with optional markers) over them, and the legend.

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::axes::{format_linear, format_log, log_ticks, YAxis};
use super::legend::legend_position;
use super::series::{Band, Line};
use super::style::{font, BAND_ALPHA, DESC_SIZE, LABEL_SIZE, LEGEND_SIZE, RIGHT_MARGIN, X_LABELS};

/// Axes, bands and lines of one chart.
pub(super) struct ChartSpec {
    /// Range of the x axis (both positive when `x_log`).
    pub(super) x: (f64, f64),
    /// Put the x axis on a log scale (decade ticks, as a log y axis).
    pub(super) x_log: bool,
    /// Range and scale of the y axis.
    pub(super) y: YAxis,
    /// Description of the x axis, with unit.
    pub(super) x_desc: String,
    /// Description of the y axis, with unit.
    pub(super) y_desc: String,
    /// Translucent regions, drawn first.
    pub(super) bands: Vec<Band>,
    /// Lines, drawn over the bands.
    pub(super) curves: Vec<Line>,
}

/// Draws the line chart; `x_ticks` puts tick labels and the description on the x axis (otherwise
/// only the grid, the strips below carry the axis).
pub(super) fn draw_chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    spec: &ChartSpec,
    y_label_area: u32,
    x_ticks: bool,
) -> DrawResult<(), DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin_top(10)
        .margin_right(RIGHT_MARGIN)
        .x_label_area_size(if x_ticks { 65 } else { 8 })
        .y_label_area_size(y_label_area);
    let x = spec.x.0..spec.x.1;
    let x_scale = spec.x.0.abs().max(spec.x.1.abs());
    let x_lin = move |v: &f64| format_linear(*v, x_scale);
    let x_log = |v: &f64| format_log(*v);
    let (x_bold, x_light) = log_ticks(spec.x.0, spec.x.1);
    let x_log_coord = || {
        x.clone()
            .log_scale()
            .with_key_points(x_bold.clone())
            .with_light_points(x_light.clone())
    };
    match spec.y {
        YAxis::Log(lo, hi) => {
            let (bold, light) = log_ticks(lo, hi);
            let y = (lo..hi)
                .log_scale()
                .with_key_points(bold)
                .with_light_points(light);
            let y_format = |v: &f64| format_log(*v);
            if spec.x_log {
                let chart = builder.build_cartesian_2d(x_log_coord(), y)?;
                finish_chart(chart, spec, x_ticks, (&x_log, &y_format))
            } else {
                let chart = builder.build_cartesian_2d(x.clone(), y)?;
                finish_chart(chart, spec, x_ticks, (&x_lin, &y_format))
            }
        }
        YAxis::Linear(lo, hi) => {
            let scale = lo.abs().max(hi.abs());
            let y_format = move |v: &f64| format_linear(*v, scale);
            if spec.x_log {
                let chart = builder.build_cartesian_2d(x_log_coord(), lo..hi)?;
                finish_chart(chart, spec, x_ticks, (&x_log, &y_format))
            } else {
                let chart = builder.build_cartesian_2d(x.clone(), lo..hi)?;
                finish_chart(chart, spec, x_ticks, (&x_lin, &y_format))
            }
        }
    }
}

/// Label formatters of the x and y ticks.
type Formats<'f> = (&'f dyn Fn(&f64) -> String, &'f dyn Fn(&f64) -> String);

/// Draws the mesh, bands, lines and legend of a built chart; `formats` label the x and y ticks.
fn finish_chart<'a, DB: DrawingBackend + 'a, X, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    spec: &ChartSpec,
    x_ticks: bool,
    (x_format, y_format): Formats,
) -> DrawResult<(), DB>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let hide = |_: &f64| String::new();
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(X_LABELS)
        .y_labels(10)
        .label_style(font(LABEL_SIZE))
        .axis_desc_style(font(DESC_SIZE))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(200, 200, 200))
        .y_label_formatter(y_format)
        .y_desc(spec.y_desc.as_str());
    if x_ticks {
        mesh.x_desc(spec.x_desc.as_str())
            .x_label_formatter(x_format);
    } else {
        mesh.x_label_formatter(&hide);
    }
    mesh.draw()?;

    for band in &spec.bands {
        let fill = band.color.mix(BAND_ALPHA).filled();
        let drawn = chart.draw_series(
            band.polygons
                .iter()
                .filter(|p| !p.is_empty())
                .map(|p| Polygon::new(p.clone(), fill)),
        )?;
        if !band.label.is_empty() && !band.is_empty() {
            drawn
                .label(band.label.as_str())
                .legend(move |(x, y)| Rectangle::new([(x, y - 8), (x + 40, y + 8)], fill));
        }
    }

    for curve in &spec.curves {
        let style = curve.style();
        let drawn = if curve.dashed {
            chart.draw_series(
                curve
                    .runs
                    .iter()
                    .map(|r| DashedPathElement::new(r.clone(), 10, 6, style)),
            )?
        } else {
            chart.draw_series(
                curve
                    .runs
                    .iter()
                    .map(|r| PathElement::new(r.clone(), style)),
            )?
        };
        if !curve.in_legend() {
            continue;
        }
        if curve.is_empty() {
            // Listed but not drawn: the label alone says why.
            drawn
                .label(curve.label.as_str())
                .legend(|(x, y)| EmptyElement::at((x, y)));
            continue;
        }
        let (color, dashed, markers) = (curve.color, curve.dashed, curve.markers);
        let anno = drawn.label(curve.label.as_str());
        let at = move |(x, y): (i32, i32)| EmptyElement::at((x + 20, y));
        let seg = || vec![(-20, 0), (20, 0)];
        let dot = move || Circle::new((0, 0), 4, color.filled());
        match (dashed, markers) {
            (true, true) => {
                anno.legend(move |p| at(p) + DashedPathElement::new(seg(), 10, 6, style) + dot())
            }
            (true, false) => {
                anno.legend(move |p| at(p) + DashedPathElement::new(seg(), 10, 6, style))
            }
            (false, true) => anno.legend(move |p| at(p) + PathElement::new(seg(), style) + dot()),
            (false, false) => anno.legend(move |p| at(p) + PathElement::new(seg(), style)),
        };
        if curve.markers {
            let radius = if curve.runs.iter().map(Vec::len).sum::<usize>() > 200 {
                2
            } else {
                3
            };
            chart.draw_series(
                curve
                    .runs
                    .iter()
                    .flatten()
                    .map(|&p| Circle::new(p, radius, curve.color.filled())),
            )?;
        }
    }

    let entries: Vec<&str> = spec
        .bands
        .iter()
        .filter(|b| !b.label.is_empty() && !b.is_empty())
        .map(|b| b.label.as_str())
        .chain(
            spec.curves
                .iter()
                .filter(|c| c.in_legend())
                .map(|c| c.label.as_str()),
        )
        .collect();
    if !entries.is_empty() {
        let position = legend_position(&chart, &spec.curves, &spec.bands, &entries)?;
        chart
            .configure_series_labels()
            .position(position)
            .legend_area_size(50)
            .margin(12)
            .label_font(font(LEGEND_SIZE))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(120, 120, 120))
            .draw()?;
    }
    Ok(())
}
