//! The look shared by every figure: size, font and text sizes, margins, the colours of the
//! contact states, of the FRF's curves and of the variability band, and the line palette.
//!
//! Text uses the embedded DejaVu Sans font, so no system font is needed.

use std::sync::OnceLock;

use plotters::prelude::*;

use crate::analysis::stability::{methods_text, PointStability};
use crate::contact::ContactState;

/// Name the embedded font is registered under.
const FONT: &str = "sans-serif";
/// The embedded font (DejaVu Sans), so that figures need no system font.
const FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
/// Size of every figure in pixels (PNG) and user units (SVG).
pub(super) const SIZE: (u32, u32) = (1200, 800);
/// Largest title size; a title too wide at this size shrinks, down to [`TITLE_MIN_SIZE`].
pub(super) const TITLE_SIZE: f64 = 28.0;
/// Smallest title size: a title still too wide at it is wrapped onto more lines, never drawn
/// smaller (as the axis descriptions' size, it stays readable in a report).
pub(super) const TITLE_MIN_SIZE: f64 = 22.0;
/// Most lines of a wrapped title; what does not fit on them ends in "…".
pub(super) const TITLE_MAX_LINES: usize = 3;
/// Size of the axis descriptions.
pub(super) const DESC_SIZE: f64 = 22.0;
/// Size of the tick labels and the strip names.
pub(super) const LABEL_SIZE: f64 = 18.0;
/// Size of the legend text.
pub(super) const LEGEND_SIZE: f64 = 18.0;
/// Right margin of the chart and the strips (keeps the last tick label inside the figure).
pub(super) const RIGHT_MARGIN: u32 = 30;
/// Number of labelled ticks on the x axis.
pub(super) const X_LABELS: usize = 12;
/// Opacity of the bands' fill, so that the lines and grid stay visible through them.
pub(super) const BAND_ALPHA: f64 = 0.25;

/// Colour of the nonlinear FRF.
pub(super) const NONLINEAR_COLOR: RGBColor = RGBColor(200, 30, 30);
/// Colour of the linear reference with the contacts open.
pub(super) const OPEN_COLOR: RGBColor = RGBColor(110, 110, 110);
/// Colour of the linear reference with the contacts stuck (and of the stuck state).
pub(super) const STUCK_COLOR: RGBColor = RGBColor(31, 100, 180);

/// Colour of the overlay on points found unstable (dashed, marked).
pub const UNSTABLE_COLOR: RGBColor = RGBColor(0, 0, 0);

/// Legend label of that overlay, naming the method that gave the verdicts of `verdicts` (the
/// points of the drawn paths): `unstable (Hill)`, `unstable (Hill, unreliable on stick-slip)`
/// when some Hill verdict is not reliable, `unstable (monodromy)`, or `unstable (monodromy on
/// stick-slip, Hill elsewhere)` when both gave verdicts.
pub fn unstable_label<'a>(verdicts: impl IntoIterator<Item = &'a PointStability>) -> String {
    format!("unstable ({}): dashed, marked", methods_text(verdicts))
}

/// Label of the shaded band in the legends.
pub(super) const BAND_LABEL: &str = "variability band";
/// Fill colour of the band (drawn translucent).
pub(super) const BAND_COLOR: RGBColor = RGBColor(70, 130, 180);

/// The contact states in the order of the colour key.
pub(super) const STATES: [ContactState; 4] = [
    ContactState::Stuck,
    ContactState::StickSlip,
    ContactState::StickSlipLiftoff,
    ContactState::Open,
];

/// Marker colour of a contact state in the state strips and their key.
pub(super) fn state_color(state: ContactState) -> RGBColor {
    match state {
        ContactState::Stuck => STUCK_COLOR,
        ContactState::StickSlip => RGBColor(44, 160, 44),
        ContactState::StickSlipLiftoff => RGBColor(255, 140, 0),
        ContactState::Open => RGBColor(170, 170, 170),
    }
}

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

/// Registers the embedded font under [`FONT`] once; false if it cannot be parsed.
pub(super) fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY
        .get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok())
}

/// The embedded font at `size`.
pub(super) fn font(size: f64) -> TextStyle<'static> {
    (FONT, size).into_font().into()
}

#[cfg(test)]
mod tests {
    use super::*;

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
