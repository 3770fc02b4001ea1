//! Turning a corner of the path: where a contact's periodic state changes from the one its
//! initial tangential state sets (stuck all period) to the one its slip sets, the residual is
//! continuous but its Jacobian jumps, so the path has a corner there, with either law.
//!
//! The event-resolved law makes the residual continuously differentiable wherever a contact
//! slips or lifts off, but a contact stuck all period keeps its initial state (T(0) = m μ N(0),
//! the limit method's m), while one that slips is anchored by its slip: at the onset of slip
//! the two orbits coincide but their derivatives with respect to the motion do not
//! (−kₜ du(0) + m μ dN(0) against −kₜ du(t*) + μ dN(t*), t* the touching instant). Where the
//! path turns back at such a corner (a fold with a corner, the two pieces meeting at more than
//! 90° in the arc length's metric), no hyperplane normal to the incoming tangent meets the
//! outgoing piece, so the corrector fails at every step down to the minimum. Measured on the
//! paper's system with μ = 5: the stuck branch ends at 160.4396 Hz, where the left contact
//! starts to slip, and the path stalled there without this.
//!
//! The corrector on a hyperplane normal to the incoming tangent cannot pass such a corner where
//! the outgoing piece runs nearly along the hyperplane (the pieces meet at close to 90° or
//! more): on the paper's system with μ = 5 the Jacobian jumps by half its size across the seam
//! at 160.4396 Hz, and Newton's iterates on every hyperplane down to the minimum step end at
//! the kink's minimum of ‖R‖ (2.6·10⁻⁸, above the tolerance). So past a corner the path is
//! taken on by the corrector on a hyperplane normal to the outgoing piece, refusing a landing
//! back on the incoming piece or further from the corner than the largest step; the tangent
//! there is oriented along the chord from the corner.
//!
//! Still needed with the event-resolved laws: without it the paper's system over 50-600 Hz
//! (`hard_cases::starts_on_resonances_and_ranges_across_the_damper_mode_cover_the_range`)
//! stalls at 396.5722 Hz and the reduced blade pair of
//! `error_estimate_fe::truncation_estimate_tracks_the_true_error_on_the_blade_pair` at
//! 924.6755 Hz (re-tried with the corner test of [`super::run`]; the out-of-plane 2D run of
//! `friction_2d`, which stalled at 160.0984 Hz without it before, now passes without it).
//! Landings by Newton at a fixed frequency ahead of the corner and behind it
//! are gone: with the tangent oriented by the determinant's sign ([`Continuation::orient`])
//! no path of the tests needs them.

use super::predictor::Oriented;
use super::settings::Continuation;
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::PathPoint;
use crate::numerics::residual::ParametricResidual;

/// Offsets from the corner (arc length, Hz-equivalent), as multiples of the minimum step,
/// tried in turn.
const CORNER_OFFSETS: &[f64] = &[4.0, 64.0, 1024.0];

/// A landing closer than this fraction of its distance from the corner to the path already
/// followed (the polyline through its last [`FOLLOWED_POINTS`] points, in the arc length's
/// metric) lies back on it, and is refused: a corner fold's outgoing piece may leave the
/// corner backwards, but apart from the incoming piece.
const ON_PATH_FRACTION: f64 = 0.05;

/// Points of the path already followed that a landing is checked against.
const FOLLOWED_POINTS: usize = 64;

impl Continuation {
    /// A point past a corner at `y` (scaled, ω last) where the path arrived along `tangent`,
    /// with its unit tangent oriented along the chord from `y`. For each offset of
    /// [`CORNER_OFFSETS`] (h, in the arc length's units), the path is sought along the
    /// outgoing piece, whose direction is the null direction t_out of the Jacobian just past
    /// the corner (at y + h·t_in, on the outgoing side of the seam), by the corrector on the
    /// hyperplane normal to t_out through y ± h·t_out. The first landing that lies neither
    /// back on the path already `followed` ([`ON_PATH_FRACTION`]) nor further than the largest
    /// step from the corner is taken. None when there is none.
    pub(super) fn turn_corner<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        tangent: &[f64],
        followed: &[PathPoint],
    ) -> Option<(PathPoint, Oriented)> {
        let recent: Vec<Vec<f64>> = followed[followed.len().saturating_sub(FOLLOWED_POINTS)..]
            .iter()
            .map(|p| self.scaled(p))
            .collect();
        for factor in CORNER_OFFSETS {
            let h = factor * self.settings.min_step;
            if h > self.settings.max_step {
                break;
            }
            let past: Vec<f64> = y.iter().zip(tangent).map(|(a, t)| a + h * t).collect();
            let outgoing = self
                .tangent(system, &self.unscaled(&past), None)
                .ok()
                .map(|o| o.t);
            let mut landings: Vec<PathPoint> = Vec::new();
            for sign in [1.0, -1.0] {
                let Some(t_out) = &outgoing else { break };
                let predicted: Vec<f64> =
                    y.iter().zip(t_out).map(|(a, t)| a + sign * h * t).collect();
                let normal: Vec<f64> = t_out.iter().map(|t| sign * t).collect();
                if let Ok((yc, iterations, residual)) = self.correct(system, &predicted, &normal) {
                    landings.push(PathPoint {
                        iterations,
                        residual,
                        ..self.unscaled(&yc)
                    });
                }
            }
            for mut point in landings {
                let landing = self.scaled(&point);
                let chord: Vec<f64> = landing.iter().zip(y).map(|(a, b)| a - b).collect();
                let length = norm(&chord);
                if length.is_nan()
                    || length <= 0.0
                    || length > self.settings.max_step
                    || distance_to_polyline(&landing, &recent) <= ON_PATH_FRACTION * length
                {
                    continue;
                }
                point.step = length;
                let along: Vec<f64> = chord.iter().map(|v| v / length).collect();
                if let Ok(t) = self.tangent(system, &point, Some(&along)) {
                    return Some((point, t));
                }
            }
        }
        None
    }
}

/// Euclidean distance from `q` to the polyline through `points` (to the point itself when
/// there is one; infinite when there is none).
fn distance_to_polyline(q: &[f64], points: &[Vec<f64>]) -> f64 {
    let to_segment = |a: &[f64], b: &[f64]| {
        let ab: Vec<f64> = b.iter().zip(a).map(|(u, v)| u - v).collect();
        let aq: Vec<f64> = q.iter().zip(a).map(|(u, v)| u - v).collect();
        let length2 = dot(&ab, &ab);
        let s = if length2 > 0.0 {
            (dot(&aq, &ab) / length2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let off: Vec<f64> = aq.iter().zip(&ab).map(|(u, v)| u - s * v).collect();
        norm(&off)
    };
    match points {
        [] => f64::INFINITY,
        [only] => to_segment(only, only),
        _ => points
            .windows(2)
            .map(|w| to_segment(&w[0], &w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::{g, settings, z_path};
    use crate::numerics::continuation::settings::OMEGA_SCALE;

    /// At the Z's first fold, a corner where the path turns back by about 163°, the path goes
    /// on along the steep middle piece, behind the corner in frequency, not back along the
    /// incoming piece.
    #[test]
    fn past_a_corner_fold_the_path_goes_on_along_the_outgoing_piece() {
        let c = Continuation::new(settings(10.0, 18.0), vec![1.0]);
        // The corner at x = 1, 15 Hz; the incoming tangent along (dx, df) = (1, 5).
        let y = [1.0, 15.0];
        let t = [1.0 / 26f64.sqrt(), 5.0 / 26f64.sqrt()];
        let followed: Vec<PathPoint> = (0..=10)
            .map(|k| {
                let x = 0.9 + 0.01 * f64::from(k);
                PathPoint {
                    omega: g(x).0 * OMEGA_SCALE,
                    x: vec![x],
                    iterations: 1,
                    residual: 0.0,
                    step: 0.01,
                }
            })
            .collect();
        let (point, tangent) = c
            .turn_corner(&mut z_path(), &y, &t, &followed)
            .expect("a way on");
        assert!(point.x[0] > 1.0 && point.x[0] < 1.2, "{point:?}");
        assert!((point.freq_hz() - g(point.x[0]).0).abs() < 1e-9);
        assert!(
            tangent.t[1] < 0.0,
            "the middle piece runs down in frequency"
        );
    }
}
