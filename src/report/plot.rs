//! Figures, each written as a 1200×800 PNG and as an SVG.
//!
//! [`plot_frf`] draws the nonlinear frequency response of one output DOF (first-harmonic
//! amplitude, in path order) over the linear open- and stuck-contact references on a log
//! amplitude axis, with one strip per contact below it showing the contact state at each point.
//! [`plot_lines`] draws labelled line series on a linear or log y axis.
//!
//! Text uses the embedded DejaVu Sans font, so no system font is needed. Values that cannot be
//! drawn (non-finite, or non-positive on a log axis) are skipped and break the line there;
//! empty inputs give an empty chart, never a panic.

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::analysis::frf::FrfPoint;
use crate::analysis::linear::LinearCurve;
use crate::contact::ContactState;

/// Error of a figure.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Drawing or writing a file failed.
    #[error("{path}: cannot draw figure: {reason}")]
    Draw {
        /// File being written.
        path: String,
        /// What went wrong.
        reason: String,
    },
}

/// Inputs of the FRF figure for one output DOF.
pub struct FrfFigure<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Which output DOF (index into [`FrfPoint::amplitudes`] and the curves' amplitude rows).
    pub output_index: usize,
    /// Name of the output DOF, e.g. "y2".
    pub output_name: &'a str,
    /// Contact names, one state strip each (index into [`FrfPoint::states`]).
    pub contact_names: &'a [String],
    /// Converged nonlinear points in path order.
    pub points: &'a [FrfPoint],
    /// Linear reference with all contacts open.
    pub open: &'a LinearCurve,
    /// Linear reference with all contacts stuck.
    pub stuck: &'a LinearCurve,
}

/// One line of [`plot_lines`]; `x` and `y` are paired up to the shorter length.
pub struct Series<'a> {
    /// Legend label (no legend entry if empty).
    pub label: &'a str,
    /// Abscissae.
    pub x: &'a [f64],
    /// Ordinates.
    pub y: &'a [f64],
    /// Line colour.
    pub color: RGBColor,
    /// Dashed rather than solid.
    pub dashed: bool,
}

/// Draws the nonlinear FRF (first-harmonic amplitude, path order, as a line with markers) over the
/// linear open and stuck references (dashed lines), on a log amplitude axis, and below the main
/// chart one horizontal strip per contact showing its state at each point (colour legend: stuck,
/// stick-slip, stick-slip-liftoff, open). Writes both files.
pub fn plot_frf(fig: &FrfFigure, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let out = fig.output_index;
    let nonlinear = Line {
        label: "nonlinear (harmonic balance)".to_string(),
        runs: valid_runs(
            fig.points.iter().map(|p| {
                (
                    p.freq_hz,
                    p.amplitudes.get(out).copied().unwrap_or(f64::NAN),
                )
            }),
            true,
        ),
        color: NONLINEAR_COLOR,
        dashed: false,
        markers: true,
    };
    let reference = |curve: &LinearCurve, label: &str, color: RGBColor| Line {
        label: label.to_string(),
        runs: valid_runs(
            curve
                .freqs_hz
                .iter()
                .zip(&curve.amplitudes)
                .map(|(&f, row)| (f, row.get(out).copied().unwrap_or(f64::NAN))),
            true,
        ),
        color,
        dashed: true,
        markers: false,
    };
    let curves = vec![
        reference(fig.open, "linear, contacts open", OPEN_COLOR),
        reference(fig.stuck, "linear, contacts stuck", STUCK_COLOR),
        nonlinear,
    ];

    let mut freqs: Vec<f64> = curves.iter().flat_map(|c| c.xs()).collect();
    freqs.extend(fig.points.iter().map(|p| p.freq_hz));
    let x = linear_range(freqs.iter().copied(), 0.0);
    let y = log_range(curves.iter().flat_map(|c| c.ys()));

    let strips: Vec<Strip> = fig
        .contact_names
        .iter()
        .enumerate()
        .map(|(c, name)| Strip {
            name: name.clone(),
            marks: fig
                .points
                .iter()
                .filter(|p| p.freq_hz.is_finite())
                .filter_map(|p| p.states.get(c).map(|&s| (p.freq_hz, state_color(s))))
                .collect(),
        })
        .collect();

    let figure = StripChart {
        title: fig.title.to_string(),
        chart: ChartSpec {
            x,
            y: YAxis::Log(y.0, y.1),
            x_desc: "frequency (Hz)".to_string(),
            y_desc: format!("{} first-harmonic amplitude (m)", fig.output_name),
            bands: Vec::new(),
            curves,
        },
        strips,
        state_key: true,
    };
    write_figure(&figure, png, svg)
}

/// Draws labelled line series over a shared x axis, with a legend; `log_y` puts the y axis on a
/// log scale (non-positive values are then skipped). Writes both files.
pub fn plot_lines(
    title: &str,
    x_label: &str,
    y_label: &str,
    log_y: bool,
    series: &[Series],
    png: &Path,
    svg: &Path,
) -> Result<(), PlotError> {
    let curves: Vec<Line> = series
        .iter()
        .map(|s| Line {
            label: s.label.to_string(),
            runs: valid_runs(s.x.iter().copied().zip(s.y.iter().copied()), log_y),
            color: s.color,
            dashed: s.dashed,
            markers: false,
        })
        .collect();
    let x = linear_range(curves.iter().flat_map(|c| c.xs()), 0.0);
    let y = if log_y {
        let (lo, hi) = log_range(curves.iter().flat_map(|c| c.ys()));
        YAxis::Log(lo, hi)
    } else {
        let (lo, hi) = linear_range(curves.iter().flat_map(|c| c.ys()), 0.05);
        YAxis::Linear(lo, hi)
    };
    let figure = StripChart {
        title: title.to_string(),
        chart: ChartSpec {
            x,
            y,
            x_desc: x_label.to_string(),
            y_desc: y_label.to_string(),
            bands: Vec::new(),
            curves,
        },
        strips: Vec::new(),
        state_key: false,
    };
    write_figure(&figure, png, svg)
}

const FONT: &str = "sans-serif";
const FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
const SIZE: (u32, u32) = (1200, 800);
const TITLE_SIZE: f64 = 28.0;
const DESC_SIZE: f64 = 22.0;
const LABEL_SIZE: f64 = 18.0;
const LEGEND_SIZE: f64 = 18.0;
const RIGHT_MARGIN: u32 = 30;
const X_LABELS: usize = 12;
const BAND_ALPHA: f64 = 0.25;

const NONLINEAR_COLOR: RGBColor = RGBColor(200, 30, 30);
const OPEN_COLOR: RGBColor = RGBColor(110, 110, 110);
const STUCK_COLOR: RGBColor = RGBColor(31, 100, 180);

const STATES: [ContactState; 4] = [
    ContactState::Stuck,
    ContactState::StickSlip,
    ContactState::StickSlipLiftoff,
    ContactState::Open,
];

pub(crate) fn state_color(state: ContactState) -> RGBColor {
    match state {
        ContactState::Stuck => STUCK_COLOR,
        ContactState::StickSlip => RGBColor(44, 160, 44),
        ContactState::StickSlipLiftoff => RGBColor(255, 140, 0),
        ContactState::Open => RGBColor(170, 170, 170),
    }
}

/// Registers the embedded font under [`FONT`] once; false if it cannot be parsed.
fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY
        .get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok())
}

fn font(size: f64) -> TextStyle<'static> {
    (FONT, size).into_font().into()
}

/// A figure that can be drawn on any backend.
pub(crate) trait Figure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<(), DB>;
}

/// Draws `figure` into a 1200×800 PNG and an SVG of the same size.
pub(crate) fn write_figure<F: Figure>(figure: &F, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let fail = |path: &Path, reason: String| PlotError::Draw {
        path: path.display().to_string(),
        reason,
    };
    if !font_ready() {
        return Err(fail(png, "the embedded font cannot be loaded".to_string()));
    }
    {
        let root = BitMapBackend::new(png, SIZE).into_drawing_area();
        figure
            .draw(&root)
            .and_then(|()| root.present())
            .map_err(|e| fail(png, e.to_string()))?;
    }
    {
        let root = SVGBackend::new(svg, SIZE).into_drawing_area();
        figure
            .draw(&root)
            .and_then(|()| root.present())
            .map_err(|e| fail(svg, e.to_string()))?;
    }
    Ok(())
}

/// A line split into runs of drawable points.
pub(crate) struct Line {
    /// Legend label (no legend entry if empty).
    pub(crate) label: String,
    /// Runs of consecutive drawable points, each drawn as one polyline.
    pub(crate) runs: Vec<Vec<(f64, f64)>>,
    pub(crate) color: RGBColor,
    pub(crate) dashed: bool,
    /// A filled circle at every point.
    pub(crate) markers: bool,
}

impl Line {
    fn xs(&self) -> impl Iterator<Item = f64> + '_ {
        self.runs.iter().flatten().map(|p| p.0)
    }
    fn ys(&self) -> impl Iterator<Item = f64> + '_ {
        self.runs.iter().flatten().map(|p| p.1)
    }
    fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }
    fn style(&self) -> ShapeStyle {
        self.color.stroke_width(2)
    }
}

/// Splits points into runs of consecutive drawable points (finite, and positive y if `log_y`).
pub(crate) fn valid_runs(
    points: impl Iterator<Item = (f64, f64)>,
    log_y: bool,
) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for (x, y) in points {
        if x.is_finite() && y.is_finite() && (!log_y || y > 0.0) {
            run.push((x, y));
        } else if !run.is_empty() {
            runs.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// Range of finite values, widened by `pad` of its span; a default or widened range when empty
/// or degenerate.
pub(crate) fn linear_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return (lo - d, hi + d);
    }
    let d = pad * (hi - lo);
    (lo - d, hi + d)
}

/// Log range of the positive finite values: padded by 4 % of the decades spanned and at least a
/// factor 4 wide, so that the axis always carries several ticks.
pub(crate) fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (1e-6, 1e-3);
    }
    let (mut a, mut b) = (lo.log10(), hi.log10());
    let min_span = 4f64.log10();
    if b - a < min_span {
        let mid = 0.5 * (a + b);
        a = mid - 0.5 * min_span;
        b = mid + 0.5 * min_span;
    }
    let pad = 0.04 * (b - a);
    (10f64.powf(a - pad), 10f64.powf(b + pad))
}

/// Labelled (bold) and grid-only (light) ticks of a log axis over `lo..hi`.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let e0 = lo.log10().floor() as i32;
    let e1 = hi.log10().ceil() as i32;
    let mut all = Vec::new();
    for e in e0..=e1 {
        for m in 1..=9 {
            let v = m as f64 * 10f64.powi(e);
            if v >= lo && v <= hi {
                all.push((m, e, v));
            }
        }
    }
    let decades: Vec<_> = all.iter().filter(|t| t.0 == 1).copied().collect();
    let main: Vec<_> = all
        .iter()
        .filter(|t| matches!(t.0, 1 | 2 | 5))
        .copied()
        .collect();
    let bold: Vec<(i32, i32, f64)> = if decades.len() >= 4 {
        let step = decades.len().div_ceil(8);
        decades.into_iter().step_by(step).collect()
    } else if main.len() >= 3 {
        main
    } else {
        all.clone()
    };
    let dense = e1 - e0 <= 8;
    let light = all
        .iter()
        .filter(|t| !bold.iter().any(|b| b.0 == t.0 && b.1 == t.1))
        .filter(|t| dense || t.0 == 1)
        .map(|t| t.2)
        .collect();
    (bold.into_iter().map(|t| t.2).collect(), light)
}

/// Tick label of a log axis: "1e-5", "2.5e-5".
fn format_log(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let mut e = v.log10().floor() as i32;
    let mut m = (v / 10f64.powi(e) * 10.0).round() / 10.0;
    if m >= 10.0 {
        m /= 10.0;
        e += 1;
    }
    if m.fract() == 0.0 {
        format!("{m:.0}e{e}")
    } else {
        format!("{m:.1}e{e}")
    }
}

/// Tick label of a linear axis whose values reach `scale` in magnitude.
fn format_linear(v: f64, scale: f64) -> String {
    if scale != 0.0 && !(1e-2..1e5).contains(&scale) {
        if v == 0.0 {
            return "0".to_string();
        }
        let s = format!("{v:.2e}");
        match s.split_once('e') {
            Some((m, e)) => {
                let m = m.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{e}")
            }
            None => s,
        }
    } else {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".to_string()
        } else {
            s.to_string()
        }
    }
}

/// Range and scale of the y axis.
pub(crate) enum YAxis {
    Linear(f64, f64),
    Log(f64, f64),
}

/// A translucent filled region, drawn below the lines.
pub(crate) struct Band {
    /// Legend label (no legend entry if empty).
    pub(crate) label: String,
    /// Closed outlines in data coordinates.
    pub(crate) polygons: Vec<Vec<(f64, f64)>>,
    pub(crate) color: RGBColor,
}

impl Band {
    fn is_empty(&self) -> bool {
        self.polygons.iter().all(Vec::is_empty)
    }
}

/// Axes, bands and lines of one chart; the x axis is linear.
pub(crate) struct ChartSpec {
    pub(crate) x: (f64, f64),
    pub(crate) y: YAxis,
    pub(crate) x_desc: String,
    pub(crate) y_desc: String,
    pub(crate) bands: Vec<Band>,
    pub(crate) curves: Vec<Line>,
}

/// One row of coloured markers below the chart, e.g. the states of one contact.
pub(crate) struct Strip {
    pub(crate) name: String,
    /// Abscissa and colour of each marker.
    pub(crate) marks: Vec<(f64, RGBColor)>,
}

/// A line chart with an optional block of marker strips below it.
pub(crate) struct StripChart {
    pub(crate) title: String,
    pub(crate) chart: ChartSpec,
    pub(crate) strips: Vec<Strip>,
    /// Draw the colour key of the contact states below the strips.
    pub(crate) state_key: bool,
}

/// Pixel layout of the strip block.
struct StripLayout {
    row: u32,
    x_label_area: u32,
    legend_row: u32,
}

impl StripLayout {
    fn height(&self, n: usize) -> u32 {
        self.row * n as u32 + self.x_label_area + self.legend_row
    }
}

impl Figure for StripChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<(), DB> {
        root.fill(&WHITE)?;
        let root = root.margin(10, 10, 10, 10);
        let body = if self.title.trim().is_empty() {
            root
        } else {
            // Long titles shrink to fit the width rather than run off the figure.
            let width = root.dim_in_pixel().0;
            let mut size = TITLE_SIZE;
            while size > 14.0 && root.estimate_text_size(&self.title, &font(size))?.0 + 10 > width {
                size -= 1.0;
            }
            root.titled(&self.title, font(size))?
        };
        let (_, body_h) = body.dim_in_pixel();

        let label_style = font(LABEL_SIZE);
        let mut name_w = 0;
        for s in &self.strips {
            name_w = name_w.max(body.estimate_text_size(&s.name, &label_style)?.0);
        }
        let y_label_area = (name_w + 25).clamp(110, 300);

        if self.strips.is_empty() {
            return draw_chart(&body, &self.chart, y_label_area, true);
        }

        let n = self.strips.len();
        let mut layout = StripLayout {
            row: (200 / n as u32).clamp(14, 30),
            x_label_area: 65,
            legend_row: if self.state_key { 40 } else { 0 },
        };
        let max_h = body_h * 45 / 100;
        if layout.height(n) > max_h {
            layout.row = ((max_h - layout.x_label_area - layout.legend_row) / n as u32).max(2);
        }
        let (main, lower) = body.split_vertically(body_h.saturating_sub(layout.height(n)));
        draw_chart(&main, &self.chart, y_label_area, false)?;
        let (strip_area, legend_area) =
            lower.split_vertically(lower.dim_in_pixel().1 - layout.legend_row);
        draw_strips(
            &strip_area,
            &self.strips,
            self.chart.x,
            &self.chart.x_desc,
            y_label_area,
            &layout,
        )?;
        if self.state_key {
            draw_state_legend(&legend_area, y_label_area)?;
        }
        Ok(())
    }
}

/// Draws the line chart; `x_ticks` puts tick labels and the description on the x axis (otherwise
/// only the grid, the strips below carry the axis).
fn draw_chart<'a, DB: DrawingBackend + 'a>(
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
    match spec.y {
        YAxis::Log(lo, hi) => {
            let (bold, light) = log_ticks(lo, hi);
            let y = (lo..hi)
                .log_scale()
                .with_key_points(bold)
                .with_light_points(light);
            let chart = builder.build_cartesian_2d(x, y)?;
            finish_chart(chart, spec, x_ticks, &|v: &f64| format_log(*v))
        }
        YAxis::Linear(lo, hi) => {
            let scale = lo.abs().max(hi.abs());
            let chart = builder.build_cartesian_2d(x, lo..hi)?;
            finish_chart(chart, spec, x_ticks, &move |v: &f64| {
                format_linear(*v, scale)
            })
        }
    }
}

fn finish_chart<'a, DB: DrawingBackend + 'a, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    spec: &ChartSpec,
    x_ticks: bool,
    y_format: &dyn Fn(&f64) -> String,
) -> DrawResult<(), DB>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let hide = |_: &f64| String::new();
    let x_scale = spec.x.0.abs().max(spec.x.1.abs());
    let x_format = |v: &f64| format_linear(*v, x_scale);
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
            .x_label_formatter(&x_format);
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
        if curve.label.is_empty() || curve.is_empty() {
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
                .filter(|c| !c.label.is_empty() && !c.is_empty())
                .map(|c| c.label.as_str()),
        )
        .collect();
    if !entries.is_empty() {
        let position = legend_position(&chart, spec, &entries)?;
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

/// The legend corner covering the fewest curve pixels (band pixels count a quarter).
fn legend_position<DB: DrawingBackend, Y>(
    chart: &ChartContext<DB, Cartesian2d<RangedCoordf64, Y>>,
    spec: &ChartSpec,
    entries: &[&str],
) -> DrawResult<SeriesLabelPosition, DB>
where
    Y: Ranged<ValueType = f64>,
{
    let area = chart.plotting_area();
    let style = font(LEGEND_SIZE);
    let mut text_w = 0;
    for e in entries {
        text_w = text_w.max(area.estimate_text_size(e, &style)?.0 as i32);
    }
    let w = text_w + 50 + 24 + 10;
    let h = (entries.len() as f64 * LEGEND_SIZE * 1.3) as i32 + 24 + 10;
    let (xr, yr) = area.get_pixel_range();

    let mut samples: Vec<(i32, i32)> = Vec::new();
    for curve in &spec.curves {
        for run in &curve.runs {
            let pixels: Vec<(i32, i32)> = run.iter().map(|p| chart.backend_coord(p)).collect();
            if let [only] = pixels.as_slice() {
                samples.push(*only);
            }
            for pair in pixels.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let d = ((b.0 - a.0) as f64).hypot((b.1 - a.1) as f64);
                let k = (d / 4.0).ceil().clamp(1.0, 2000.0) as i32;
                for i in 0..=k {
                    let t = i as f64 / k as f64;
                    samples.push((
                        a.0 + ((b.0 - a.0) as f64 * t) as i32,
                        a.1 + ((b.1 - a.1) as f64 * t) as i32,
                    ));
                }
            }
        }
    }

    use SeriesLabelPosition::*;
    let (left, right, mid_x) = (xr.start, xr.end - w, (xr.start + xr.end - w) / 2);
    let (top, bottom, mid_y) = (yr.start, yr.end - h, (yr.start + yr.end - h) / 2);
    let candidates = [
        (UpperRight, right, top),
        (UpperLeft, left, top),
        (LowerRight, right, bottom),
        (LowerLeft, left, bottom),
        (UpperMiddle, mid_x, top),
        (LowerMiddle, mid_x, bottom),
        (MiddleRight, right, mid_y),
        (MiddleLeft, left, mid_y),
    ];
    let polygons: Vec<Vec<(f64, f64)>> = spec
        .bands
        .iter()
        .flat_map(|b| &b.polygons)
        .filter(|p| p.len() >= 3)
        .map(|p| {
            p.iter()
                .map(|q| {
                    let (x, y) = chart.backend_coord(q);
                    (x as f64, y as f64)
                })
                .collect()
        })
        .collect();
    let mut best = (UpperRight, f64::INFINITY);
    for (pos, x0, y0) in candidates {
        let on_lines = samples
            .iter()
            .filter(|p| p.0 >= x0 && p.0 <= x0 + w && p.1 >= y0 && p.1 <= y0 + h)
            .count();
        let mut in_bands = 0;
        if !polygons.is_empty() {
            for py in (y0..=y0 + h).step_by(8) {
                for px in (x0..=x0 + w).step_by(8) {
                    let q = (px as f64, py as f64);
                    if polygons.iter().any(|p| inside(p, q)) {
                        in_bands += 1;
                    }
                }
            }
        }
        let cost = on_lines as f64 + 0.25 * in_bands as f64;
        if cost < best.1 {
            best = (pos, cost);
        }
    }
    Ok(best.0)
}

/// Whether `q` lies inside the closed polygon (even-odd rule).
fn inside(polygon: &[(f64, f64)], q: (f64, f64)) -> bool {
    let mut odd = false;
    let mut j = polygon.len() - 1;
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[j]);
        if (a.1 > q.1) != (b.1 > q.1) && q.0 < a.0 + (q.1 - a.1) * (b.0 - a.0) / (b.1 - a.1) {
            odd = !odd;
        }
        j = i;
    }
    odd
}

/// Draws one row per strip (the first on top) with a coloured marker at each of its abscissae.
fn draw_strips<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    strips: &[Strip],
    x: (f64, f64),
    x_desc: &str,
    y_label_area: u32,
    layout: &StripLayout,
) -> DrawResult<(), DB> {
    let n = strips.len();
    let x_scale = x.0.abs().max(x.1.abs());
    let x_format = |v: &f64| format_linear(*v, x_scale);
    let mut chart = ChartBuilder::on(area)
        .margin_right(RIGHT_MARGIN)
        .x_label_area_size(layout.x_label_area)
        .y_label_area_size(y_label_area)
        .build_cartesian_2d(x.0..x.1, 0.0..n as f64)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(X_LABELS)
        .y_labels(0)
        .x_label_formatter(&x_format)
        .label_style(font(LABEL_SIZE))
        .axis_desc_style(font(DESC_SIZE))
        .x_desc(x_desc)
        .draw()?;

    let name_style = font(LABEL_SIZE).pos(Pos::new(HPos::Right, VPos::Center));
    let every = (LABEL_SIZE as u32 + 2).div_ceil(layout.row.max(1)).max(1) as usize;
    let base = area.get_base_pixel();
    for (c, strip) in strips.iter().enumerate().step_by(every) {
        let (px, py) = chart.backend_coord(&(x.0, row_center(n, c)));
        area.draw_text(&strip.name, &name_style, (px - base.0 - 10, py - base.1))?;
    }
    let separators = if layout.row >= 8 { 1..n } else { 0..0 };
    chart.draw_series(separators.map(|r| {
        PathElement::new(
            vec![(x.0, r as f64), (x.1, r as f64)],
            RGBColor(200, 200, 200),
        )
    }))?;
    let half_h = ((layout.row as f64 * 0.4).round() as i32).max(1);
    for (c, strip) in strips.iter().enumerate() {
        let y = row_center(n, c);
        chart.draw_series(strip.marks.iter().map(|&(f, color)| {
            EmptyElement::at((f, y)) + Rectangle::new([(-2, -half_h), (2, half_h)], color.filled())
        }))?;
    }
    Ok(())
}

/// Centre of contact `c`'s row, the first contact on top.
fn row_center(n: usize, c: usize) -> f64 {
    (n - 1 - c) as f64 + 0.5
}

/// Draws the colour key of the contact states in one row.
fn draw_state_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x0: u32,
) -> DrawResult<(), DB> {
    let style = font(LEGEND_SIZE).pos(Pos::new(HPos::Left, VPos::Center));
    let (_, h) = area.dim_in_pixel();
    let y = h as i32 / 2;
    let mut x = x0 as i32;
    let title = "contact state:";
    area.draw_text(title, &style, (x, y))?;
    x += area.estimate_text_size(title, &style)?.0 as i32 + 20;
    for state in STATES {
        area.draw(&Rectangle::new(
            [(x, y - 8), (x + 16, y + 8)],
            state_color(state).filled(),
        ))?;
        x += 24;
        area.draw_text(state.label(), &style, (x, y))?;
        x += area.estimate_text_size(state.label(), &style)?.0 as i32 + 30;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(f: f64, a: f64, states: Vec<ContactState>) -> FrfPoint {
        FrfPoint {
            freq_hz: f,
            amplitudes: vec![a, 0.5 * a],
            peaks: vec![a, 0.5 * a],
            states,
            newton_iterations: 3,
            residual: 1e-10,
            coefficients: Vec::new(),
        }
    }

    fn resonance(f: f64, f0: f64, zeta: f64, a0: f64) -> f64 {
        let r = f / f0;
        a0 / ((1.0 - r * r).powi(2) + (2.0 * zeta * r).powi(2)).sqrt()
    }

    fn curve(f0: f64, zeta: f64) -> LinearCurve {
        let freqs_hz: Vec<f64> = (0..=200).map(|i| 50.0 + i as f64).collect();
        let amplitudes = freqs_hz
            .iter()
            .map(|&f| {
                let a = resonance(f, f0, zeta, 1e-5);
                vec![a, 0.5 * a]
            })
            .collect();
        LinearCurve {
            freqs_hz,
            amplitudes,
        }
    }

    fn synthetic_points() -> Vec<FrfPoint> {
        (0..=400)
            .map(|i| {
                let f = 50.0 + 0.5 * i as f64;
                let a = resonance(f, 150.0, 0.03, 1e-5);
                let s = if a < 2e-5 {
                    ContactState::Stuck
                } else if a < 5e-5 {
                    ContactState::StickSlip
                } else if a < 1e-4 {
                    ContactState::StickSlipLiftoff
                } else {
                    ContactState::Open
                };
                let other = if f < 120.0 {
                    ContactState::Stuck
                } else {
                    ContactState::StickSlip
                };
                point(f, a, vec![s, other, ContactState::Open])
            })
            .collect()
    }

    fn check_files(png: &Path, svg: &Path) {
        let png_bytes = std::fs::read(png).unwrap();
        assert!(!png_bytes.is_empty());
        assert!(png_bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]));
        let svg_text = std::fs::read_to_string(svg).unwrap();
        assert!(!svg_text.is_empty());
        assert!(svg_text.contains("<svg"));
    }

    #[test]
    fn frf_figure_writes_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let (png, svg) = (dir.path().join("frf.png"), dir.path().join("frf.svg"));
        let names = vec![
            "c1".to_string(),
            "c2 (platform)".to_string(),
            "c3".to_string(),
        ];
        let points = synthetic_points();
        let (open, stuck) = (curve(120.0, 0.01), curve(190.0, 0.01));
        let fig = FrfFigure {
            title: "synthetic FRF",
            output_index: 0,
            output_name: "y2",
            contact_names: &names,
            points: &points,
            open: &open,
            stuck: &stuck,
        };
        plot_frf(&fig, &png, &svg).unwrap();
        check_files(&png, &svg);
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.contains("frequency (Hz)"));
        assert!(svg_text.contains("y2 first-harmonic amplitude (m)"));
        assert!(svg_text.contains("stick-slip-liftoff"));
        assert!(svg_text.contains("linear, contacts stuck"));
    }

    #[test]
    fn frf_figure_survives_empty_and_bad_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let empty = LinearCurve {
            freqs_hz: Vec::new(),
            amplitudes: Vec::new(),
        };
        for (k, points) in [
            Vec::new(),
            vec![
                point(10.0, 0.0, vec![]),
                point(f64::NAN, 1e-3, vec![ContactState::Open]),
                point(11.0, -1.0, vec![ContactState::Stuck]),
                point(12.0, f64::INFINITY, vec![ContactState::StickSlip]),
            ],
            vec![point(5.0, 1e-4, vec![ContactState::Stuck])],
        ]
        .into_iter()
        .enumerate()
        {
            let names: Vec<String> = (0..k).map(|c| format!("c{c}")).collect();
            let (png, svg) = (
                dir.path().join(format!("e{k}.png")),
                dir.path().join(format!("e{k}.svg")),
            );
            let fig = FrfFigure {
                title: "",
                output_index: 7,
                output_name: "x",
                contact_names: &names,
                points: &points,
                open: &empty,
                stuck: &empty,
            };
            plot_frf(&fig, &png, &svg).unwrap();
            check_files(&png, &svg);
        }
    }

    #[test]
    fn many_contacts_fit() {
        let dir = tempfile::tempdir().unwrap();
        let names: Vec<String> = (0..60).map(|c| format!("contact-{c}")).collect();
        let points: Vec<FrfPoint> = synthetic_points()
            .into_iter()
            .map(|mut p| {
                p.states = vec![p.states[0]; 60];
                p
            })
            .collect();
        let (open, stuck) = (curve(120.0, 0.01), curve(190.0, 0.01));
        let fig = FrfFigure {
            title: "many contacts",
            output_index: 1,
            output_name: "y1",
            contact_names: &names,
            points: &points,
            open: &open,
            stuck: &stuck,
        };
        let (png, svg) = (dir.path().join("m.png"), dir.path().join("m.svg"));
        plot_frf(&fig, &png, &svg).unwrap();
        check_files(&png, &svg);
    }

    #[test]
    fn lines_figure_linear_and_log() {
        let dir = tempfile::tempdir().unwrap();
        let x: Vec<f64> = (0..50).map(|i| i as f64).collect();
        let y1: Vec<f64> = x.iter().map(|v| (v / 5.0).sin()).collect();
        let y2: Vec<f64> = x.iter().map(|v| 1e-3 * (v - 10.0)).collect();
        let series = [
            Series {
                label: "sine",
                x: &x,
                y: &y1,
                color: RGBColor(200, 30, 30),
                dashed: false,
            },
            Series {
                label: "ramp",
                x: &x,
                y: &y2[..20],
                color: RGBColor(31, 100, 180),
                dashed: true,
            },
            Series {
                label: "",
                x: &[],
                y: &[],
                color: BLACK,
                dashed: false,
            },
        ];
        for log_y in [false, true] {
            let (png, svg) = (
                dir.path().join(format!("l{log_y}.png")),
                dir.path().join(format!("l{log_y}.svg")),
            );
            plot_lines("lines", "x (s)", "y (m)", log_y, &series, &png, &svg).unwrap();
            check_files(&png, &svg);
        }
        let (png, svg) = (dir.path().join("none.png"), dir.path().join("none.svg"));
        plot_lines("nothing", "x", "y", true, &[], &png, &svg).unwrap();
        check_files(&png, &svg);
    }

    #[test]
    fn unwritable_path_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("missing").join("a.png");
        let svg = dir.path().join("missing").join("a.svg");
        let err = plot_lines("t", "x", "y", false, &[], &png, &svg).unwrap_err();
        assert!(err.to_string().contains("a.png"));
    }

    #[test]
    fn log_ticks_and_labels() {
        let (bold, light) = log_ticks(1.1e-6, 3e-4);
        assert_eq!(bold.len(), 7);
        assert!(!light.is_empty());
        let (bold, light) = log_ticks(1.1e-9, 3e-4);
        assert_eq!(bold.len(), 5);
        assert!(!light.is_empty());
        let (bold, _) = log_ticks(2.2e-5, 9e-5);
        assert!(bold.len() >= 2, "{bold:?}");
        assert_eq!(format_log(2e-5), "2e-5");
        assert_eq!(format_log(1e-4), "1e-4");
        assert_eq!(format_log(2.5e-7), "2.5e-7");
        assert_eq!(format_linear(0.5, 1.0), "0.5");
        assert_eq!(format_linear(2.5e-5, 1e-4), "2.5e-5");
        let (lo, hi) = log_range([3e-5, 3e-5].into_iter());
        assert!(hi / lo >= 4.0);
        assert_eq!(log_range(std::iter::empty()), (1e-6, 1e-3));
        assert_eq!(linear_range([f64::NAN].into_iter(), 0.0), (0.0, 1.0));
    }
}
