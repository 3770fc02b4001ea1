//! The FRF figure: the nonlinear frequency response of one output DOF (first-harmonic
//! amplitude, in path order, with markers) over the linear open- and stuck-contact references
//! (dashed) on a log amplitude axis, with one strip per contact below it showing the contact
//! state at each point; points found unstable (by the scene's `analysis.stability_method`)
//! are overdrawn black, dashed and marked, the legend naming the method.

use std::path::Path;

use plotters::style::RGBColor;

use super::axes::{linear_range, log_range, YAxis};
use super::backend::{write_figure, PlotError};
use super::chart::ChartSpec;
use super::series::{points, valid_runs, Line};
use super::strips::{Strip, StripChart};
use super::style::{
    state_color, unstable_label, NONLINEAR_COLOR, OPEN_COLOR, STUCK_COLOR, UNSTABLE_COLOR,
};
use crate::analysis::frf::FrfPoint;
use crate::analysis::linear::LinearCurve;

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
    /// Indices into `points` where a new branch starts (after a jump past a fold): the line is
    /// broken there instead of drawn across the jump.
    pub branch_starts: &'a [usize],
    /// Refined extrema of this output (resonances and anti-resonances) as (index of the path
    /// point each was refined from, frequency in Hz, amplitude in m): spliced into the line
    /// next to that point, so that the curve passes through the extrema instead of cutting
    /// across a dip or a peak between two path points.
    pub extrema: &'a [(usize, f64, f64)],
    /// Linear reference with all contacts open.
    pub open: &'a LinearCurve,
    /// Linear reference with all contacts stuck.
    pub stuck: &'a LinearCurve,
}

/// The nonlinear line of output `out` in path order: the path points, a NaN before each branch
/// start (which ends a run of the line), and each refined extremum next to its path point, on
/// the side of the neighbour whose frequency brackets it with the point's.
fn spliced_line<'a>(fig: &'a FrfFigure, out: usize) -> impl Iterator<Item = (f64, f64)> + 'a {
    let value = move |p: &FrfPoint| {
        (
            p.freq_hz,
            p.amplitudes.get(out).copied().unwrap_or(f64::NAN),
        )
    };
    let between = |f: f64, a: f64, b: f64| a.min(b) <= f && f <= a.max(b);
    fig.points.iter().enumerate().flat_map(move |(i, p)| {
        let gap = fig
            .branch_starts
            .contains(&i)
            .then_some((f64::NAN, f64::NAN));
        let here = fig.extrema.iter().filter(move |e| e.0 == i);
        let before = here
            .clone()
            .filter(move |e| {
                i > 0
                    && !fig.branch_starts.contains(&i)
                    && between(e.1, fig.points[i - 1].freq_hz, p.freq_hz)
            })
            .map(|e| (e.1, e.2));
        let after = here
            .filter(move |e| {
                !(i > 0
                    && !fig.branch_starts.contains(&i)
                    && between(e.1, fig.points[i - 1].freq_hz, p.freq_hz))
                    && e.1 != p.freq_hz
            })
            .map(|e| (e.1, e.2));
        gap.into_iter()
            .chain(before)
            .chain(std::iter::once(value(p)))
            .chain(after)
    })
}

/// The points Hill's method found unstable ([`FrfPoint::stability`]), as a black dashed line
/// with markers over the nonlinear line: runs of consecutive unstable path points, broken at
/// stable points, branch starts and points outside the frequency range. Empty when no point is
/// unstable (or stability was not computed), so the legend has no entry then.
fn unstable_line(fig: &FrfFigure, out: usize, in_range: &dyn Fn(f64) -> bool) -> Line {
    let gap = (f64::NAN, f64::NAN);
    let points = fig.points.iter().enumerate().flat_map(|(i, p)| {
        let start = fig.branch_starts.contains(&i).then_some(gap);
        let unstable = p.stability.is_some_and(|s| s.is_unstable()) && in_range(p.freq_hz);
        let here = if unstable {
            (
                p.freq_hz,
                p.amplitudes.get(out).copied().unwrap_or(f64::NAN),
            )
        } else {
            gap
        };
        start.into_iter().chain(std::iter::once(here))
    });
    Line {
        label: unstable_label(fig.points.iter().filter_map(|p| p.stability.as_ref())),
        runs: valid_runs(points, true),
        color: UNSTABLE_COLOR,
        dashed: true,
        markers: true,
        listed: false,
    }
}

/// Fraction of the nonlinear response's largest amplitude below which a linear reference is
/// numerically zero (the open-contact reference at a blade that only the contacts excite is
/// round-off, 1e-20 m): such a reference is not drawn, as it would stretch the log axis over
/// a dozen decades of nothing, and its legend entry says so.
pub(super) const NEGLIGIBLE_REFERENCE: f64 = 1e-9;

/// The lines of the FRF figure of output `out`, back to front: the open and stuck references,
/// the nonlinear line (points outside the frequency range left out) and, when some point is
/// unstable, its overlay. A reference whose largest amplitude is below
/// [`NEGLIGIBLE_REFERENCE`] of the nonlinear line's is not drawn and is listed in the legend
/// as `<name>: below 1e-9 of the response, not drawn`.
fn frf_lines(fig: &FrfFigure, out: usize, in_range: &dyn Fn(f64) -> bool) -> Vec<Line> {
    let nonlinear = Line {
        label: "nonlinear (harmonic balance)".to_string(),
        runs: valid_runs(
            spliced_line(fig, out).map(|(f, a)| {
                if in_range(f) {
                    (f, a)
                } else {
                    (f64::NAN, f64::NAN)
                }
            }),
            true,
        ),
        color: NONLINEAR_COLOR,
        dashed: false,
        markers: true,
        listed: false,
    };
    let response_max = nonlinear
        .runs
        .iter()
        .flatten()
        .map(|p| p.1)
        .fold(f64::NAN, f64::max);
    let reference = |curve: &LinearCurve, label: &str, color: RGBColor| {
        let values = curve
            .freqs_hz
            .iter()
            .zip(&curve.amplitudes)
            .map(|(&f, row)| (f, row.get(out).copied().unwrap_or(f64::NAN)));
        // NaN when the curve has no finite value (nothing to leave out then).
        let largest = values
            .clone()
            .map(|(_, a)| a.abs())
            .filter(|a| a.is_finite())
            .fold(f64::NAN, f64::max);
        let negligible = largest < NEGLIGIBLE_REFERENCE * response_max;
        Line {
            label: if negligible {
                format!("{label}: below {NEGLIGIBLE_REFERENCE:e} of the response, not drawn")
            } else {
                label.to_string()
            },
            runs: if negligible {
                Vec::new()
            } else {
                valid_runs(values, true)
            },
            color,
            dashed: true,
            markers: false,
            listed: negligible,
        }
    };
    let mut curves = vec![
        reference(fig.open, "linear, contacts open", OPEN_COLOR),
        reference(fig.stuck, "linear, contacts stuck", STUCK_COLOR),
        nonlinear,
    ];
    let unstable = unstable_line(fig, out, in_range);
    if !unstable.is_empty() {
        curves.push(unstable);
    }
    curves
}

/// Draws the nonlinear FRF (first-harmonic amplitude, path order, as a line with markers) over the
/// linear open and stuck references (dashed lines), on a log amplitude axis, and below the main
/// chart one horizontal strip per contact showing its state at each point (colour legend: stuck,
/// stick-slip, stick-slip-liftoff, open). Writes both files.
///
/// The frequency axis spans the analysis range (the references' grid): points a path reached
/// outside it (a fold followed below the start) are left out, and the line is broken there and
/// at every branch start. The amplitude axis spans the nonlinear line and the references drawn
/// (a numerically zero reference is not, see [`frf_lines`]).
pub fn plot_frf(fig: &FrfFigure, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let out = fig.output_index;
    let range = fig
        .open
        .freqs_hz
        .iter()
        .chain(&fig.stuck.freqs_hz)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &f| {
            (lo.min(f), hi.max(f))
        });
    let in_range = |f: f64| range.0 > range.1 || (range.0..=range.1).contains(&f);
    let curves = frf_lines(fig, out, &in_range);

    let freqs: Vec<f64> = points(&curves).map(|p| p.0).collect();
    let x = linear_range(freqs.iter().copied(), 0.0);
    let y = log_range(points(&curves).map(|p| p.1));

    let strips: Vec<Strip> = fig
        .contact_names
        .iter()
        .enumerate()
        .map(|(c, name)| Strip {
            name: name.clone(),
            marks: fig
                .points
                .iter()
                .filter(|p| p.freq_hz.is_finite() && in_range(p.freq_hz))
                .filter_map(|p| p.states.get(c).map(|&s| (p.freq_hz, state_color(s))))
                .collect(),
        })
        .collect();

    let figure = StripChart {
        title: fig.title.to_string(),
        chart: ChartSpec {
            x,
            x_log: false,
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

#[cfg(test)]
mod tests {
    use super::super::testing::{drawn, resonance};
    use super::*;
    use crate::contact::ContactState;

    fn point(f: f64, a: f64, states: Vec<ContactState>) -> FrfPoint {
        FrfPoint {
            freq_hz: f,
            amplitudes: vec![a, 0.5 * a],
            peaks: vec![a, 0.5 * a],
            states,
            newton_iterations: 3,
            residual: 1e-10,
            coefficients: Vec::new(),
            accuracy: None,
            pending_estimate: None,
            stability: None,
        }
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

    /// The figure of output `k` (named `name`) of `points`, one strip per name, over the open
    /// and stuck references.
    fn figure<'a>(
        title: &'a str,
        (k, name): (usize, &'a str),
        names: &'a [String],
        points: &'a [FrfPoint],
        (open, stuck): (&'a LinearCurve, &'a LinearCurve),
    ) -> FrfFigure<'a> {
        FrfFigure {
            title,
            output_index: k,
            output_name: name,
            contact_names: names,
            points,
            branch_starts: &[],
            extrema: &[],
            open,
            stuck,
        }
    }

    /// Refined extrema go next to their path point on the side whose neighbour brackets them,
    /// and a branch start puts a break (NaN) before its point, never an extremum across it.
    #[test]
    fn extrema_are_spliced_in_path_order_and_branches_break_the_line() {
        let points: Vec<FrfPoint> = [(1.0, 1.0), (2.0, 3.0), (3.0, 1.0), (2.5, 2.0), (4.0, 1.0)]
            .iter()
            .map(|&(f, a)| point(f, a, Vec::new()))
            .collect();
        let (open, stuck) = (curve(120.0, 0.01), curve(190.0, 0.01));
        let names: Vec<String> = Vec::new();
        let extrema = [(1, 2.2, 3.5), (1, 1.8, 2.9), (3, 2.4, 1.9)];
        let mut fig = figure("t", (0, "x"), &names, &points, (&open, &stuck));
        fig.branch_starts = &[3];
        fig.extrema = &extrema;
        let line: Vec<(f64, f64)> = spliced_line(&fig, 0).collect();
        let freqs: Vec<f64> = line.iter().map(|p| p.0).collect();
        assert_eq!(freqs.len(), 9);
        assert_eq!(&freqs[..5], &[1.0, 1.8, 2.0, 2.2, 3.0]);
        assert!(freqs[5].is_nan());
        // The branch's first point has no neighbour before it: its extremum goes after it.
        assert_eq!(&freqs[6..], &[2.5, 2.4, 4.0]);
    }

    #[test]
    fn frf_figure_writes_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let names = vec![
            "c1".to_string(),
            "c2 (platform)".to_string(),
            "c3".to_string(),
        ];
        let points = synthetic_points();
        let (open, stuck) = (curve(120.0, 0.01), curve(190.0, 0.01));
        let fig = figure("synthetic FRF", (0, "y2"), &names, &points, (&open, &stuck));
        let svg_text = drawn(dir.path(), "frf", |png, svg| plot_frf(&fig, png, svg));
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
            let fig = figure("", (7, "x"), &names, &points, (&empty, &empty));
            drawn(dir.path(), &format!("e{k}"), |png, svg| {
                plot_frf(&fig, png, svg)
            });
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
        let fig = figure("many contacts", (1, "y1"), &names, &points, (&open, &stuck));
        drawn(dir.path(), "m", |png, svg| plot_frf(&fig, png, svg));
    }

    /// A reference numerically zero at the output (the open-contact reference at a blade only
    /// the contacts excite) is not drawn and does not set the amplitude axis; its legend entry
    /// says why. A reference merely far below the response is still drawn.
    #[test]
    fn a_numerically_zero_reference_is_left_out_and_said() {
        let dir = tempfile::tempdir().unwrap();
        let names = vec!["c1".to_string()];
        let points = synthetic_points();
        let stuck = curve(190.0, 0.01);
        let mut open = curve(120.0, 0.01);
        for row in &mut open.amplitudes {
            row[0] *= 1e-16;
        }
        let fig = figure("zero open", (0, "y2"), &names, &points, (&open, &stuck));
        let lines = frf_lines(&fig, 0, &|_| true);
        assert!(
            lines[0].is_empty() && lines[0].in_legend(),
            "{}",
            lines[0].label
        );
        assert_eq!(
            lines[0].label,
            "linear, contacts open: below 1e-9 of the response, not drawn"
        );
        assert_eq!(lines[1].label, "linear, contacts stuck");
        assert!(!lines[1].is_empty());
        let lowest = points_of(&lines).fold(f64::INFINITY, f64::min);
        assert!(lowest > 1e-9, "{lowest:e}");
        let svg_text = drawn(dir.path(), "zero", |png, svg| plot_frf(&fig, png, svg));
        assert!(svg_text.contains("below 1e-9 of the response, not drawn"));

        // Some 3e-8 of the response's largest amplitude: kept.
        for row in &mut open.amplitudes {
            row[0] *= 1e8;
        }
        let fig = figure("small open", (0, "y2"), &names, &points, (&open, &stuck));
        let lines = frf_lines(&fig, 0, &|_| true);
        assert_eq!(lines[0].label, "linear, contacts open");
        assert!(!lines[0].is_empty());
    }

    /// The amplitudes of every drawn point of `lines`.
    fn points_of(lines: &[Line]) -> impl Iterator<Item = f64> + '_ {
        points(lines).map(|p| p.1)
    }

    /// The font size of the SVG `<text>` element whose text starts with `start`.
    fn font_size(svg: &str, start: &str) -> f64 {
        let at = svg
            .find(&format!(">\n{start}"))
            .or_else(|| svg.find(&format!(">{start}")));
        let element = &svg[..at.unwrap_or_else(|| panic!("no text {start:?}"))];
        let tag = &element[element.rfind("<text").unwrap()..];
        let size = tag.split("font-size=\"").nth(1).unwrap();
        size[..size.find('"').unwrap()].parse().unwrap()
    }

    /// A sweep's title with many overrides wraps, the overrides on lines of their own, at no
    /// less than the axis descriptions' size instead of shrinking to an unreadable font.
    #[test]
    fn long_titles_wrap_at_a_readable_size() {
        let dir = tempfile::tempdir().unwrap();
        let names = vec!["c1".to_string()];
        let points = synthetic_points();
        let (open, stuck) = (curve(120.0, 0.01), curve(190.0, 0.01));
        let title = "Fig. 16b: optimal curves near the optimum with intermediate states, beta = \
                     120 deg [analysis.max_step=0.25, sweep.values=[36.0, 44.0, 52.0, 60.0, \
                     68.0], limits.grid_points=41, limits.bound_scan=[-0.5, 0.5]]: F0 = 60 N";
        let fig = figure(title, (0, "y2"), &names, &points, (&open, &stuck));
        let svg = drawn(dir.path(), "long", |png, svg| plot_frf(&fig, png, svg));
        let head = "Fig. 16b: optimal curves near the optimum with intermediate states, beta = \
                    120 deg";
        assert!(svg.contains(&format!("{head}\n")), "the title's first line");
        let desc = font_size(&svg, "y2 first-harmonic amplitude (m)");
        let first = font_size(&svg, head);
        assert!(first >= desc, "title {first} < axis description {desc}");
        assert_eq!(font_size(&svg, "[analysis.max_step=0.25,"), first);
        assert!(svg.contains("F0 = 60 N"), "nothing cut");
    }
}
