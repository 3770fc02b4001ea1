//! Figures, each written as a 1200×800 PNG and as an SVG (`<stem>.png`, `<stem>.svg`).
//!
//! The figures, one file each:
//! - [`plot_frf`] (`frf`): the nonlinear FRF of one output DOF over the linear open- and
//!   stuck-contact references, with one contact-state strip per contact below it;
//! - [`plot_limits`] (`limits`): the FRF variability band between the two limit curves, the
//!   limit, intermediate and reference curves, with rows marking multiple solutions and the
//!   contact states below;
//! - [`plot_sweep`] (`sweep`): quantities against a swept parameter (optimal curves, resonance
//!   frequencies) over shaded bands, or the FRF bands of several sweep values;
//! - [`plot_hysteresis`] (`hysteresis`): closed tangential force–displacement loops;
//! - [`plot_lines`] (`lines`): labelled curves on a linear or log y axis;
//! - [`plot_backbone`] (`backbone`): a nonlinear mode's frequency or damping ratio against the
//!   amplitude on a log axis, with one contact-state strip per contact below it.
//!
//! The drawing they share, lowest first: `style` (size, fonts, colours, [`palette`]), `axes`
//! (ranges, log ticks, tick labels), `series` (the caller's [`Curve`]s made into drawable lines
//! and bands), `backend` (the PNG and SVG files, [`PlotError`], [`figure_files`]), `legend`
//! (where the legend covers the least data), `chart` (axes, bands, lines, legend) and `strips`
//! (the figure's layout: title, chart and the marker rows below it).
//!
//! Text uses the embedded DejaVu Sans font, so no system font is needed. Values that cannot be
//! drawn (non-finite, or non-positive on a log axis) are skipped: they break lines and split
//! bands into separate regions. Empty inputs give an empty chart, never a panic.

mod axes;
mod backbone;
mod backend;
mod chart;
mod frf;
mod hysteresis;
mod legend;
mod limits;
mod lines;
mod series;
mod strips;
mod style;
mod sweep;
#[cfg(test)]
mod testing;

pub use backbone::{plot_backbone, BackboneFigure, StateRow};
pub use backend::{figure_files, PlotError};
pub use frf::{plot_frf, FrfFigure};
pub use hysteresis::{plot_hysteresis, Loop};
pub use limits::{plot_limits, LimitFigure};
pub use lines::plot_lines;
pub use series::Curve;
pub use style::{palette, unstable_label, UNSTABLE_COLOR};
pub use sweep::{plot_sweep, BandSpec, SweepFigure};
