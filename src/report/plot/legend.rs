//! Where the legend goes: the corner (or edge middle) of the chart that covers the fewest
//! curve pixels, so that the legend hides as little of the data as possible.

use plotters::prelude::*;

use super::series::{Band, Line};
use super::style::{font, LEGEND_SIZE};

/// The legend corner covering the fewest pixels of the chart's `curves` (pixels of its `bands`
/// count a quarter) for a legend of `entries`.
pub(super) fn legend_position<DB: DrawingBackend, X, Y>(
    chart: &ChartContext<DB, Cartesian2d<X, Y>>,
    curves: &[Line],
    bands: &[Band],
    entries: &[&str],
) -> DrawResult<SeriesLabelPosition, DB>
where
    X: Ranged<ValueType = f64>,
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
    for curve in curves {
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
    let polygons: Vec<Vec<(f64, f64)>> = bands
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
