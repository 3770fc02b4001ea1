//! Events of a path that end or turn it: leaving the range, passing the end frequency, the
//! direction of travel, and the no-progress rules (new ground, stagnation, frequency reversals).

use super::corrector::CHORD_STEPS_PER_ITERATION;
use super::settings::Continuation;
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::PathPoint;

/// Fewest points a path may take without progress before it is given up (see
/// [`Continuation::stagnation_points`]).
const MIN_STAGNATION_POINTS: usize = 200;

/// The ground a path has covered, for its no-progress test ([`Continuation::stagnation_points`]):
/// the cells of frequency ([`Self::FREQUENCY_CELLS`] across the range) and of the size of the
/// unknowns (ln ‖x‖ in steps of [`Self::SIZE_CELL`]) its points have entered. A path makes
/// progress where a point enters a cell no point entered before: a branch climbing toward the
/// end frequency, and as well one running back after a fold toward a resonance below it (the
/// middle branch of the 2D blade pair runs down from a fold at 878.9 Hz to its peak at
/// 865.3 Hz over about 2000 points, the corners of its 14 contact points making the steps
/// short), or climbing from it on the upper branch; a path wandering back and forth over the
/// same stretch, or going round a loop it went round before, enters none. (Counting only a new
/// highest frequency as progress gave that middle branch up at 866.9 Hz, above its peak.)
pub(super) struct VisitedGround {
    cells: std::collections::HashSet<(i64, i64)>,
    cell_hz: f64,
}

impl VisitedGround {
    /// Frequency cells across the run's range.
    const FREQUENCY_CELLS: f64 = 4000.0;
    /// Width of a size cell in ln ‖x‖ (about 5 %).
    const SIZE_CELL: f64 = 0.05;

    pub(super) fn new(freq_start_hz: f64, freq_end_hz: f64) -> Self {
        let range = (freq_end_hz - freq_start_hz).abs();
        Self {
            cells: std::collections::HashSet::new(),
            cell_hz: if range > 0.0 {
                range / Self::FREQUENCY_CELLS
            } else {
                1.0
            },
        }
    }

    /// Whether the point at `freq_hz` with unknowns `x` enters a cell no point entered before
    /// (and marks it entered).
    pub(super) fn enters_new(&mut self, freq_hz: f64, x: &[f64]) -> bool {
        let size = norm(x);
        let size_cell = if size > 0.0 && size.is_finite() {
            (size.ln() / Self::SIZE_CELL).floor() as i64
        } else {
            i64::MIN
        };
        let freq_cell = (freq_hz / self.cell_hz).floor() as i64;
        self.cells.insert((freq_cell, size_cell))
    }
}

/// Accepted points (the last ones of the path) that a corner point found behind the incoming
/// direction is checked against (see [`Continuation::runs_back_along`]).
pub(super) const RETRACE_HISTORY: usize = 64;

/// Look-ahead steps from a corner point found behind the incoming direction, as fractions of
/// the first step (the initial step, at most half the extent of the checked points), tried in
/// turn until one converges (see [`Continuation::runs_back_along`]).
pub(super) const RETRACE_LOOKAHEADS: &[f64] = &[1.0, 0.25, 0.0625];

/// A look-ahead point closer to the path already followed than this fraction of its distance
/// from the corner (about 3°) lies on it: the corner point would resume the incoming branch
/// backwards (see [`Continuation::runs_back_along`]).
pub(super) const RETRACE_FRACTION: f64 = 0.05;

/// Relative distance ‖x − x'‖ / ‖x‖ on the unknowns within which two solutions converged by
/// Newton at one frequency are the same solution. Measured: the same solution reached from two
/// starts differs by 3·10⁻¹⁶ to 5·10⁻¹⁴ on the paper's system at F0 = 1 and 5 N, and by
/// 5·10⁻¹¹ to 4.5·10⁻¹⁰ on the 3D blade pair (schur); the two sides of a fold of the paper's
/// system at F0 = 1 N one step out of it differ by 5.1·10⁻⁷ (19.7275 Hz) to 10⁻².
pub const SAME_SOLUTION_TOLERANCE: f64 = 1e-8;

impl Continuation {
    /// Whether the solve with relative residuals `history` (one per step) is to be given up for
    /// stagnation. With `chord` steps [`CHORD_STEPS_PER_ITERATION`] of them count as one iteration
    /// of [`StagnationExit::after`](super::StagnationExit::after) and of its window, as of the
    /// iteration limit.
    pub(super) fn stagnates(&self, history: &[f64], chord: bool) -> bool {
        self.stagnation.is_some_and(|exit| {
            if chord {
                // Every third step back from the current one.
                let iterations: Vec<f64> = history
                    .iter()
                    .rev()
                    .step_by(CHORD_STEPS_PER_ITERATION)
                    .rev()
                    .copied()
                    .collect();
                exit.stagnated(&iterations)
            } else {
                exit.stagnated(history)
            }
        })
    }

    /// Whether `point` lies back on the path already followed (`points`, the last
    /// [`RETRACE_HISTORY`] of them looked at): closer to the polyline through them than
    /// [`RETRACE_FRACTION`] of its distance from the last one, as in
    /// [`Continuation::runs_back_along`]. A step that goes on from the last point has its
    /// distance from the polyline equal to its distance from that point.
    pub(super) fn retraces(&self, point: &PathPoint, points: &[PathPoint]) -> bool {
        let recent = &points[points.len().saturating_sub(RETRACE_HISTORY)..];
        let path = self.scaled_points(recent);
        let (Some(last), Some(q)) = (
            path.last(),
            self.scaled_points(std::slice::from_ref(point)).pop(),
        ) else {
            return false;
        };
        let reach = norm(&q.iter().zip(last).map(|(a, b)| a - b).collect::<Vec<_>>());
        distance_to_polyline(&q, &path) <= RETRACE_FRACTION * reach
    }

    /// Whether the path has left the range for good behind the start frequency. A path that
    /// turns back behind the start (a fold: the response overhangs) is followed on, within the
    /// point budget, since it usually turns again and comes back; only one that runs on to
    /// half the range behind the start (or, running up, to a tenth of the start frequency) is
    /// given up.
    pub(super) fn left_range(&self, point: &PathPoint) -> bool {
        let a = &self.settings;
        let behind = self.direction() * (a.freq_start_hz - point.freq_hz());
        let range = (a.freq_end_hz - a.freq_start_hz).abs();
        behind > 0.5 * range || (self.direction() > 0.0 && point.freq_hz() < 0.1 * a.freq_start_hz)
    }

    /// +1 when the path runs up in frequency (end above start), −1 when it runs down.
    pub(super) fn direction(&self) -> f64 {
        if self.settings.freq_end_hz < self.settings.freq_start_hz {
            -1.0
        } else {
            1.0
        }
    }

    /// Whether a predicted y (scaled, ω last) lands at or past the end frequency in the
    /// direction of travel.
    pub(super) fn past_end(&self, predicted: &[f64]) -> bool {
        let n = predicted.len() - 1;
        self.direction() * (predicted[n] - self.settings.freq_end_hz) >= 0.0
    }

    /// Points a path may take without entering ground it had not covered ([`VisitedGround`])
    /// before it is given up as wandering ([`PathEnd::NoProgress`]): a fifth of the point
    /// budget, at least [`MIN_STAGNATION_POINTS`].
    pub(super) fn stagnation_points(&self) -> usize {
        (self.settings.max_points / 5).max(MIN_STAGNATION_POINTS)
    }
}

/// How many times the frequency of consecutive `points` changes direction (steps that leave
/// the frequency unchanged are skipped): 0 on a stretch monotone in frequency.
///
/// Decides whether a dead end at the highest frequency reached gets the narrow windows (see
/// [`Continuation::run`]): only with no reversal among the last [`RETRACE_HISTORY`] points.
/// Why, measured (benches/README.md, "Narrow windows at dead ends"): the 3D blade pair's dead
/// end at 886.6853 Hz (840-900 Hz and 884-944 Hz) is met on a stretch rising monotonically from
/// 884 Hz (0 reversals), and a window passes it onto the middle branch of the bending pair's
/// resonance. The paper's system at F0 = 1 N meets its dead end at 151.8405 Hz after bouncing
/// between corners of the sampled law (6 reversals in the last 64 points, turning points every
/// 0.03-0.1 Hz over 147.7-151.8 Hz); a window there stepped over the turning points the run
/// finds at 152.1-153.1 Hz (151.84 → 152.42 → 153.88 Hz in two points), and the path beyond was
/// not the one the run follows with the jump past the dead end (it ended at a dead end at
/// 241.65 Hz that Newton cannot go past). The stall signature does not tell the two apart:
/// at both the corrector's residual after 12 iterations falls in proportion to the step over the
/// halvings (a kink), and the corner search ends on a point leading back onto the path.
pub(super) fn frequency_reversals(points: &[PathPoint]) -> usize {
    let mut last_sign = 0.0;
    let mut count = 0;
    for pair in points.windows(2) {
        if pair[1].omega == pair[0].omega {
            continue;
        }
        let sign = (pair[1].omega - pair[0].omega).signum();
        if last_sign != 0.0 && sign != last_sign {
            count += 1;
        }
        last_sign = sign;
    }
    count
}

/// Euclidean distance from `q` to the polyline through `points` (to the point itself when
/// there is one; infinite when there is none).
pub(super) fn distance_to_polyline(q: &[f64], points: &[Vec<f64>]) -> f64 {
    let distance_to_segment = |a: &[f64], b: &[f64]| {
        let ab: Vec<f64> = b.iter().zip(a).map(|(u, v)| u - v).collect();
        let aq: Vec<f64> = q.iter().zip(a).map(|(u, v)| u - v).collect();
        let length2 = dot(&ab, &ab);
        let s = if length2 > 0.0 {
            (dot(&aq, &ab) / length2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        aq.iter()
            .zip(&ab)
            .map(|(u, v)| (u - s * v) * (u - s * v))
            .sum::<f64>()
            .sqrt()
    };
    match points {
        [] => f64::INFINITY,
        [only] => distance_to_segment(only, only),
        _ => points
            .windows(2)
            .map(|w| distance_to_segment(&w[0], &w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::settings::OMEGA_SCALE;

    /// New ground is a frequency cell (a 4000th of the range) or a size cell (5 % in ‖x‖) no
    /// point entered before: a path running back down a stretch at a growing size (a middle
    /// branch toward a resonance below its fold) enters new cells; one going back and forth
    /// over a stretch it covered does not.
    #[test]
    fn new_ground_is_a_frequency_or_size_no_point_reached() {
        let mut ground = VisitedGround::new(100.0, 140.0);
        // Cells of 0.01 Hz; up the range at one size.
        for k in 0..10 {
            assert!(ground.enters_new(120.0 + 0.01 * f64::from(k) + 0.005, &[1.0]));
        }
        // Back down the same frequencies at the same size: covered ground.
        for k in (0..10).rev() {
            assert!(!ground.enters_new(120.0 + 0.01 * f64::from(k) + 0.002, &[1.0, 0.0]));
        }
        // Back down at a size 6 % larger each step: new ground at every point.
        for k in (0..10).rev() {
            let size = 1.06_f64.powi(10 - k);
            assert!(ground.enters_new(120.0 + 0.01 * f64::from(k) + 0.005, &[0.0, size]));
        }
        // 1 % larger than a size entered at that frequency, in the same size cell: covered.
        assert!(!ground.enters_new(120.005, &[1.06_f64.powi(10) * 1.01]));
        // A point without a finite size has a cell of its own.
        assert!(ground.enters_new(120.005, &[f64::NAN]));
        assert!(!ground.enters_new(120.005, &[f64::NAN]));
    }

    /// The reversals that keep the narrow windows from a dead end: none on a monotone stretch
    /// (steps at an unchanged frequency, e.g. a creep toward a kink, skipped), one per change
    /// of direction on a stretch bouncing between corners.
    #[test]
    fn frequency_reversals_count_the_changes_of_direction() {
        let at = |hz: &[f64]| -> Vec<PathPoint> {
            hz.iter()
                .map(|&f| PathPoint {
                    omega: f * OMEGA_SCALE,
                    x: vec![0.0],
                    iterations: 1,
                    residual: 0.0,
                    step: 0.0,
                })
                .collect()
        };
        assert_eq!(frequency_reversals(&at(&[])), 0);
        assert_eq!(frequency_reversals(&at(&[1.0, 2.0, 2.0, 2.0, 3.0])), 0);
        assert_eq!(frequency_reversals(&at(&[3.0, 2.0, 1.0])), 0);
        assert_eq!(frequency_reversals(&at(&[1.0, 2.0, 2.0, 1.5, 1.7, 1.6])), 3);
    }
}
