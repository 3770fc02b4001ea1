//! The data of a figure: the public [`Curve`] a caller gives, and the drawable [`Line`]s and
//! [`Band`]s made from it. Values that cannot be drawn (non-finite, or non-positive on a log
//! axis) are left out here: they break a line into runs and split a band into regions.

use plotters::prelude::*;

/// One curve of a figure; `x` and `y` are paired up to the shorter length.
pub struct Curve<'a> {
    /// Legend label (no legend entry if empty).
    pub label: &'a str,
    /// Abscissae.
    pub x: &'a [f64],
    /// Ordinates.
    pub y: &'a [f64],
    /// Line colour, e.g. from [`super::palette`].
    pub color: RGBColor,
    /// Dashed rather than solid.
    pub dashed: bool,
    /// A filled circle at every point.
    pub markers: bool,
}

/// A line split into runs of drawable points.
pub(super) struct Line {
    /// Legend label (no legend entry if empty).
    pub(super) label: String,
    /// Runs of consecutive drawable points, each drawn as one polyline.
    pub(super) runs: Vec<Vec<(f64, f64)>>,
    /// Line colour (and marker colour).
    pub(super) color: RGBColor,
    /// Dashed rather than solid.
    pub(super) dashed: bool,
    /// A filled circle at every point.
    pub(super) markers: bool,
    /// Listed in the legend (its label, without a line sample) even when nothing of it is
    /// drawn: a curve left out on purpose, whose label says why.
    pub(super) listed: bool,
}

impl Line {
    /// Whether nothing of the line can be drawn (then it has no legend entry unless
    /// [`Line::listed`]).
    pub(super) fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }
    /// Whether the line has an entry in the legend: a label, and something drawn or
    /// [`Line::listed`].
    pub(super) fn in_legend(&self) -> bool {
        !self.label.is_empty() && (!self.is_empty() || self.listed)
    }
    /// Stroke of the line (and of its legend sample).
    pub(super) fn style(&self) -> ShapeStyle {
        self.color.stroke_width(2)
    }
}

/// Splits points into runs of consecutive drawable points (finite, and positive y if `log_y`).
pub(super) fn valid_runs(
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

/// The drawable runs of each curve.
pub(super) fn lines(curves: &[Curve], log_y: bool) -> Vec<Line> {
    curves
        .iter()
        .map(|c| Line {
            label: c.label.to_string(),
            runs: valid_runs(c.x.iter().copied().zip(c.y.iter().copied()), log_y),
            color: c.color,
            dashed: c.dashed,
            markers: c.markers,
            listed: false,
        })
        .collect()
}

/// All drawable points of the lines.
pub(super) fn points(lines: &[Line]) -> impl Iterator<Item = (f64, f64)> + '_ {
    lines.iter().flat_map(|c| c.runs.iter().flatten().copied())
}

/// A translucent filled region, drawn below the lines.
pub(super) struct Band {
    /// Legend label (no legend entry if empty).
    pub(super) label: String,
    /// Closed outlines in data coordinates.
    pub(super) polygons: Vec<Vec<(f64, f64)>>,
    /// Fill colour (drawn translucent).
    pub(super) color: RGBColor,
}

impl Band {
    /// Whether nothing of the band can be drawn (then it has no legend entry).
    pub(super) fn is_empty(&self) -> bool {
        self.polygons.iter().all(Vec::is_empty)
    }
}

/// The x range `(lo, hi)` widened to cover every band.
pub(super) fn cover((lo, hi): (f64, f64), bands: &[Band]) -> (f64, f64) {
    bands
        .iter()
        .flat_map(|b| b.polygons.iter().flatten())
        .fold((lo, hi), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)))
}

/// Outlines of the band between `lower` and `upper` over `x` (paired up to the shortest length):
/// one polygon per run of consecutive drawable entries (all finite, limits positive if `log_y`),
/// along the larger limit forwards and the smaller one backwards. An isolated drawable entry
/// becomes a narrow rectangle reaching a quarter of the way to the nearest other abscissa.
pub(super) fn band_polygons(
    x: &[f64],
    lower: &[f64],
    upper: &[f64],
    log_y: bool,
) -> Vec<Vec<(f64, f64)>> {
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
}
