//! The figure's layout: a title, the chart, and below it optional rows of coloured markers
//! (the state of each contact at each point, or the frequencies with multiple solutions), one
//! row per strip, with the colour key of the contact states. With many strips the rows narrow
//! so that the chart keeps at least 55 % of the height.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;

use super::axes::{format_linear, format_log, log_ticks};
use super::backend::Figure;
use super::chart::{draw_chart, ChartSpec};
use super::style::{
    font, state_color, DESC_SIZE, LABEL_SIZE, LEGEND_SIZE, RIGHT_MARGIN, STATES, TITLE_MAX_LINES,
    TITLE_MIN_SIZE, TITLE_SIZE, X_LABELS,
};

/// One row of coloured markers below the chart, e.g. the states of one contact.
pub(super) struct Strip {
    /// Name written left of the row.
    pub(super) name: String,
    /// Abscissa and colour of each marker.
    pub(super) marks: Vec<(f64, RGBColor)>,
}

/// A line chart with an optional block of marker strips below it.
pub(super) struct StripChart {
    /// Figure title (none if blank).
    pub(super) title: String,
    /// The chart.
    pub(super) chart: ChartSpec,
    /// Marker rows below the chart, the first on top.
    pub(super) strips: Vec<Strip>,
    /// Draw the colour key of the contact states below the strips.
    pub(super) state_key: bool,
}

impl StripChart {
    /// A figure of the chart alone, without strips or state key.
    pub(super) fn plain(title: &str, chart: ChartSpec) -> Self {
        StripChart {
            title: title.to_string(),
            chart,
            strips: Vec::new(),
            state_key: false,
        }
    }
}

/// Pixel layout of the strip block.
struct StripLayout {
    /// Height of one row.
    row: u32,
    /// Height of the x tick labels and description below the rows.
    x_label_area: u32,
    /// Height of the state key (0 without it).
    legend_row: u32,
}

impl StripLayout {
    /// Height of the whole block for `n` rows.
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
            draw_title(&root, &self.title)?
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
            (self.chart.x, self.chart.x_log),
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

/// Draws the title centred on top of `area` and returns the area below it. A long title
/// shrinks from [`TITLE_SIZE`] to at most [`TITLE_MIN_SIZE`] to fit on one line, and is
/// otherwise wrapped at that size onto up to [`TITLE_MAX_LINES`] lines ([`wrap_title`]).
fn draw_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> DrawResult<DrawingArea<DB, Shift>, DB> {
    let width = area.dim_in_pixel().0.saturating_sub(10);
    let fits = |text: &str, size: f64| -> DrawResult<bool, DB> {
        Ok(area.estimate_text_size(text, &font(size))?.0 <= width)
    };
    let mut size = TITLE_SIZE;
    while size > TITLE_MIN_SIZE && !fits(title, size)? {
        size -= 1.0;
    }
    let mut error = None;
    let lines = wrap_title(title, TITLE_MAX_LINES, |text| {
        fits(text, size).unwrap_or_else(|e| {
            error.get_or_insert(e);
            true
        })
    });
    if let Some(e) = error {
        return Err(e);
    }
    let line_h = (size * 1.25).ceil() as i32;
    let style = font(size).pos(Pos::new(HPos::Center, VPos::Top));
    let centre = area.dim_in_pixel().0 as i32 / 2;
    for (i, line) in lines.iter().enumerate() {
        area.draw_text(line, &style, (centre, 5 + i as i32 * line_h))?;
    }
    let used = 10 + lines.len() as i32 * line_h;
    Ok(area.split_vertically(used).1)
}

/// A title as lines that each `fits`: words (split at spaces) filled greedily onto at most
/// `max_lines` lines, the overrides a title ends with (` [a=1, b=2]`) starting a line of their
/// own when the title does not fit on one. What does not fit on them (more words, or a word
/// too wide for a line of its own) is left out and the last line ends in "…", so that the
/// title never runs off the figure.
pub(super) fn wrap_title(
    title: &str,
    max_lines: usize,
    mut fits: impl FnMut(&str) -> bool,
) -> Vec<String> {
    let (head, overrides) = match title.split_once(" [") {
        Some((head, rest)) if !fits(title) => (head, Some(format!("[{rest}"))),
        _ => (title, None),
    };
    let mut lines = vec![String::new()];
    let mut cut = false;
    let words = head.split_whitespace().map(|w| (false, w)).chain(
        overrides
            .iter()
            .flat_map(|o| o.split_whitespace().enumerate().map(|(i, w)| (i == 0, w))),
    );
    for (new_line, word) in words {
        if new_line && !lines.last().expect("at least one line").is_empty() {
            if lines.len() == max_lines.max(1) {
                cut = true;
                break;
            }
            lines.push(String::new());
        }
        let last = lines.last_mut().expect("at least one line");
        let joined = if last.is_empty() {
            word.to_string()
        } else {
            format!("{last} {word}")
        };
        if fits(&joined) {
            *last = joined;
            continue;
        }
        if !last.is_empty() {
            if lines.len() == max_lines.max(1) {
                cut = true;
                break;
            }
            lines.push(String::new());
        }
        let last = lines.last_mut().expect("at least one line");
        *last = word.to_string();
        if !fits(word) {
            cut = true;
            break;
        }
    }
    if cut {
        let last = lines.last_mut().expect("at least one line");
        while !last.is_empty() && !fits(&format!("{last}…")) {
            last.pop();
        }
        last.push('…');
    }
    lines
}

/// Draws one row per strip (the first on top) with a coloured marker at each of its abscissae,
/// over the x range `x.0`, on a log scale if `x.1`.
fn draw_strips<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    strips: &[Strip],
    x: ((f64, f64), bool),
    x_desc: &str,
    y_label_area: u32,
    layout: &StripLayout,
) -> DrawResult<(), DB> {
    let ((lo, hi), log) = x;
    let n = strips.len();
    let mut builder = ChartBuilder::on(area);
    builder
        .margin_right(RIGHT_MARGIN)
        .x_label_area_size(layout.x_label_area)
        .y_label_area_size(y_label_area);
    let rows = StripRows {
        strips,
        x: (lo, hi),
        x_desc,
        layout,
    };
    if log {
        let (bold, light) = log_ticks(lo, hi);
        let coord = (lo..hi)
            .log_scale()
            .with_key_points(bold)
            .with_light_points(light);
        let chart = builder.build_cartesian_2d(coord, 0.0..n as f64)?;
        rows.draw(area, chart, &|v: &f64| format_log(*v))
    } else {
        let scale = lo.abs().max(hi.abs());
        let chart = builder.build_cartesian_2d(lo..hi, 0.0..n as f64)?;
        rows.draw(area, chart, &move |v: &f64| format_linear(*v, scale))
    }
}

/// The strip rows to draw on a built chart.
struct StripRows<'s> {
    strips: &'s [Strip],
    x: (f64, f64),
    x_desc: &'s str,
    layout: &'s StripLayout,
}

impl StripRows<'_> {
    /// Draws the x axis (ticks labelled by `x_format`), the row names, separators and markers.
    fn draw<'a, DB: DrawingBackend + 'a, X>(
        &self,
        area: &DrawingArea<DB, Shift>,
        mut chart: ChartContext<'a, DB, Cartesian2d<X, RangedCoordf64>>,
        x_format: &dyn Fn(&f64) -> String,
    ) -> DrawResult<(), DB>
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let (strips, x, layout) = (self.strips, self.x, self.layout);
        let n = strips.len();
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(X_LABELS)
            .y_labels(0)
            .x_label_formatter(x_format)
            .label_style(font(LABEL_SIZE))
            .axis_desc_style(font(DESC_SIZE))
            .x_desc(self.x_desc)
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
                EmptyElement::at((f, y))
                    + Rectangle::new([(-2, -half_h), (2, half_h)], color.filled())
            }))?;
        }
        Ok(())
    }
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

    /// Titles wrap at spaces onto at most the lines given, each within the width; what is
    /// left over ends the last line in "…".
    #[test]
    fn titles_wrap_and_shorten() {
        let fits = |t: &str| t.chars().count() <= 12;
        assert_eq!(wrap_title("short", 3, fits), ["short"]);
        assert_eq!(
            wrap_title("aaaa bbbb cccc dddd", 3, fits),
            ["aaaa bbbb", "cccc dddd"]
        );
        assert_eq!(
            wrap_title("aaaa bbbb cccc dddd eeee ffff gggg", 2, fits),
            ["aaaa bbbb", "cccc dddd…"]
        );
        assert_eq!(
            wrap_title("x [limits.bound_scan=[-0.5,0.5]]", 3, fits),
            ["x", "[limits.bou…"]
        );
        // The overrides start a line of their own.
        assert_eq!(
            wrap_title("aaaa bbbb cc [d=1, e=2]", 3, fits),
            ["aaaa bbbb cc", "[d=1, e=2]"]
        );
        assert_eq!(wrap_title("aa [d=1]", 3, fits), ["aa [d=1]"]);
        for lines in [
            wrap_title("aaaa bbbb cccc dddd eeee ffff gggg", 2, fits),
            wrap_title("x [limits.bound_scan=[-0.5,0.5]]", 3, fits),
        ] {
            assert!(lines.iter().all(|l| fits(l)), "{lines:?}");
        }
    }
}
