//! Past a spot the corrector cannot pass: a corner along the outgoing piece, a leap further
//! ahead, or a narrow window around the spot, never back onto the path already followed.

use super::events::{
    distance_to_polyline, RETRACE_FRACTION, RETRACE_HISTORY, RETRACE_LOOKAHEADS,
    SAME_SOLUTION_TOLERANCE,
};
use super::settings::{Continuation, NarrowPass, OMEGA_SCALE};
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::{ContinuationError, NewtonFailure, PathPoint};
use crate::numerics::residual::ParametricResidual;

/// Leaps tried past a spot the corrector cannot pass, as fractions of the largest step.
const LEAPS: &[f64] = &[0.02, 0.1, 0.5];

/// Steps tried to turn a sharp corner of the path, as multiples of the minimum step (see
/// [`Continuation::corner`]).
const CORNER_STEPS: &[f64] = &[4.0, 64.0, 1024.0];

/// A point found past a corner whose chord from the corner makes a cosine above this with the
/// reversed incoming tangent, and whose tangent makes a cosine above
/// [`CORNER_SAME_PIECE_COSINE`] with the incoming one, lies back on the incoming piece of the
/// path and is rejected.
const CORNER_BACKWARD_COSINE: f64 = 0.95;

/// See [`CORNER_BACKWARD_COSINE`] (cos 0.5°).
const CORNER_SAME_PIECE_COSINE: f64 = 0.999_96;

/// Widths of the window of a narrow-window pass past a stall, as fractions of the range, tried
/// in turn, each from the last point reached, while the path stalls inside the window (see
/// [`Continuation::enter_narrow`]). On the 3D blade pair's limit curves over 845-900 Hz a
/// hundredth passed the stall of m = +1 at 852.78 Hz, and a thousandth or a tenth that of
/// m = −1 at 852.74 Hz, where a hundredth stalled again (benches/README.md).
pub(super) const NARROW_WINDOW_FRACTIONS: &[f64] = &[0.01, 0.001, 0.1];

/// Most narrow-window passes in one run.
pub(super) const MAX_NARROW_PASSES: usize = 8;

impl Continuation {
    /// Starts a narrow-window pass from the last point before a stall, at `from_hz` (the
    /// path having first stalled after `stalled_hz`): the scales and the climb become those of
    /// a range the fraction `NARROW_WINDOW_FRACTIONS[attempt]` of this one's, until a point
    /// lands farther than half that width from `from_hz` ([`Self::leave_narrow`]). The step
    /// bounds stay the scene's (its `min_step` is where the path gives up).
    ///
    /// Why: the response's arc-length scale is set from the range (a climb to the response
    /// costs a quarter of it), so over a wide range the response weighs little against the
    /// frequency in the arc length. It is that scale which decides whether the corrector gets
    /// across some contact transitions: over 845-900 Hz the 3D blade pair's m = +1 limit curve
    /// stalls at 852.78 Hz with the range's scale, whether the steps are the range's or a
    /// hundredth of them, and passes with a hundredth of the scale, whether the steps are the
    /// range's or a hundredth of them (benches/README.md).
    pub(super) fn enter_narrow(
        &mut self,
        from_hz: f64,
        stalled_hz: f64,
        attempt: usize,
        tangent: &mut [f64],
    ) {
        let range = (self.settings.freq_end_hz - self.settings.freq_start_hz).abs();
        let factor = NARROW_WINDOW_FRACTIONS[attempt];
        self.narrow = Some(NarrowPass {
            from_hz,
            stalled_hz,
            half_width_hz: 0.5 * factor * range,
            factor,
            attempt,
        });
        self.rescale(factor, tangent);
    }

    /// Ends the narrow-window pass under way, if any: the scales and climb of the range again
    /// (a scale the adaptive scale grew during the pass keeps its growth). Returns the
    /// frequency of the last point before the pass's first stall (Hz).
    pub(super) fn leave_narrow(&mut self, tangent: &mut [f64]) -> Option<f64> {
        let pass = self.narrow.take()?;
        self.rescale(1.0 / pass.factor, tangent);
        Some(pass.stalled_hz)
    }

    /// Whether a narrow-window pass is under way and `freq_hz` lies outside its window.
    pub(super) fn past_narrow_window(&self, freq_hz: f64) -> bool {
        self.narrow
            .is_some_and(|pass| (freq_hz - pass.from_hz).abs() > pass.half_width_hz)
    }

    /// The hyperplane normal to the path of the unit tangent `t` (scaled space), as a covector
    /// on the unknowns (x, ω in rad/s): tᵢ / x_scaleᵢ and t_ω / 2π (see
    /// [`Observer::accepted`]).
    pub(super) fn path_normal(&self, t: &[f64]) -> Vec<f64> {
        let n = self.x_scale.len();
        (0..=n)
            .map(|i| {
                if i < n {
                    t[i] / self.x_scale[i]
                } else {
                    t[n] / OMEGA_SCALE
                }
            })
            .collect()
    }

    /// Tries to continue past a spot where the corrector fails at every step down to the
    /// minimum: predictions [`LEAPS`] of the largest step ahead along the tangent, each
    /// corrected to full tolerance; the first whose correction stays within the leap, whose
    /// tangent keeps the direction of travel and which does not land on the path already
    /// followed ([`Continuation::on_followed_path`]) is returned with its tangent. Steps
    /// that land beyond the end frequency are not tried (the end point is solved separately).
    pub(super) fn leap<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        tangent: &[f64],
        followed: &[PathPoint],
        refused_retrace: &mut bool,
    ) -> Result<Option<(PathPoint, Vec<f64>)>, ContinuationError> {
        let n = y.len() - 1;
        for &fraction in LEAPS {
            let ds = fraction * self.settings.max_step;
            let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            if self.past_end(&predicted) {
                continue;
            }
            let Ok((yc, it, rel)) = self.correct(system, &predicted, tangent) else {
                continue;
            };
            let Ok((point, t_new, _, _)) =
                self.corrected_point(system, &yc, it, rel, ds, &predicted, tangent)
            else {
                continue;
            };
            let distance = norm(
                &yc.iter()
                    .zip(&predicted)
                    .map(|(a, b)| a - b)
                    .collect::<Vec<_>>(),
            );
            let reach = norm(&yc.iter().zip(y).map(|(a, b)| a - b).collect::<Vec<_>>());
            if distance <= ds && dot(&t_new, tangent) > 0.0 {
                if !self.on_followed_path(system, &yc, reach, followed) {
                    // The test evaluated the operator elsewhere: the observer expects it
                    // evaluated at the point.
                    let mut r = vec![0.0; n];
                    if system.residual(&point.x, point.omega, &mut r).is_ok() {
                        return Ok(Some((point, t_new)));
                    }
                    continue;
                }
                *refused_retrace = true;
            }
        }
        Ok(None)
    }

    /// Points of the path in the scaled space (x / x_scale, ω / 2π).
    pub(super) fn scaled_points(&self, points: &[PathPoint]) -> Vec<Vec<f64>> {
        points
            .iter()
            .map(|p| {
                p.x.iter()
                    .zip(&self.x_scale)
                    .map(|(v, s)| v / s)
                    .chain(std::iter::once(p.omega / OMEGA_SCALE))
                    .collect()
            })
            .collect()
    }

    /// Tries to turn a corner of the piecewise-smooth path at `y`, where the corrector fails at
    /// every step down to the minimum because the path leaves `y` in a direction far from the
    /// incoming tangent (a contact sample changing state at `y`: the sampled Jenkins law makes
    /// the residual only piecewise smooth, and at a sharp corner, e.g. a fold whose two
    /// branches meet at an angle, the hyperplane normal to the incoming tangent does not meet
    /// the outgoing branch at all).
    ///
    /// Past the corner (at `y + ds·t_in`) the Jacobian is that of the outgoing piece; its null
    /// direction t_out is the outgoing tangent up to sign. Both signs are corrected on the
    /// hyperplane normal to them at `y ± ds·t_out`; a corrected point that lies back along the
    /// incoming branch (its chord from `y` within [`CORNER_BACKWARD_COSINE`] of −t_in, with the
    /// incoming tangent) or further than the step from its prediction is rejected, and so is
    /// one behind the incoming direction (chord · t_in < 0) from which the path runs back onto
    /// the path already followed (`followed`, [`Continuation::runs_back_along`]): only a sharp
    /// fold's outgoing piece may leave a corner backwards. Returns the point and its tangent
    /// oriented along the chord from `y`.
    pub(super) fn corner<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        tangent: &[f64],
        followed: &[PathPoint],
        refused_retrace: &mut bool,
    ) -> Result<Option<(PathPoint, Vec<f64>)>, ContinuationError> {
        let n = y.len() - 1;
        for &multiple in CORNER_STEPS {
            let ds = (multiple * self.settings.min_step).min(self.settings.max_step);
            let beyond: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            let probe = PathPoint {
                omega: beyond[n] * OMEGA_SCALE,
                x: (0..n).map(|j| beyond[j] * self.x_scale[j]).collect(),
                iterations: 0,
                residual: f64::NAN,
                step: ds,
            };
            let Ok(outgoing) = self.tangent(system, &probe, Some(tangent)) else {
                continue;
            };
            for sign in [1.0, -1.0] {
                let direction: Vec<f64> = outgoing.iter().map(|v| sign * v).collect();
                let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * direction[j]).collect();
                if self.past_end(&predicted) {
                    continue;
                }
                let Ok((yc, it, rel)) = self.correct(system, &predicted, &direction) else {
                    continue;
                };
                let chord: Vec<f64> = yc.iter().zip(y).map(|(a, b)| a - b).collect();
                let length = norm(&chord);
                let off = norm(
                    &yc.iter()
                        .zip(&predicted)
                        .map(|(a, b)| a - b)
                        .collect::<Vec<_>>(),
                );
                if length == 0.0 || off > ds {
                    continue;
                }
                let chord: Vec<f64> = chord.iter().map(|v| v / length).collect();
                let Ok((point, t_new, _, _)) =
                    self.corrected_point(system, &yc, it, rel, ds, &predicted, &chord)
                else {
                    continue;
                };
                // Back along the incoming piece: the chord points back and the tangent there
                // is the incoming one. A sharp fold's outgoing piece may run back close to
                // the incoming one, but with its own tangent.
                if -dot(&chord, tangent) > CORNER_BACKWARD_COSINE
                    && dot(&t_new, tangent).abs() > CORNER_SAME_PIECE_COSINE
                {
                    continue;
                }
                // Behind the incoming direction: a sharp fold's outgoing piece, or a piece that
                // leads back onto the incoming branch (its tangent there need not be the
                // incoming one, which the test above relies on). Look ahead along it.
                if dot(&chord, tangent) < 0.0 {
                    if self.runs_back_along(system, (&yc, &t_new), y, followed) {
                        *refused_retrace = true;
                        continue;
                    }
                    // The look-ahead evaluated the operator elsewhere: the observer expects it
                    // evaluated at the point.
                    let mut r = vec![0.0; n];
                    if system.residual(&point.x, point.omega, &mut r).is_err() {
                        continue;
                    }
                }
                return Ok(Some((point, t_new)));
            }
        }
        Ok(None)
    }

    /// Whether the path from a corner point `from` (scaled y) along its tangent `t` runs back
    /// onto the path already followed (`followed`, the accepted points, the corner `y` last).
    /// One step is taken along `t` ([`RETRACE_LOOKAHEADS`] of the initial step, at most half
    /// the extent of the last [`RETRACE_HISTORY`] points from `y`) and corrected; the point
    /// reached is tested by [`Continuation::on_followed_path`]. At a contact transition of the
    /// sampled contact law, a piece found behind the incoming direction can lead straight back
    /// onto the incoming branch (the run would then retrace it downwards), or onto an earlier
    /// stretch of the path (the run would then go round the same loop again and again: the m =
    /// −1 limit curve of the 3D blade pair, whose branch coming down from a fold at 868.68 Hz
    /// met the branch that had risen to it at 854.62 Hz and turned up it again, seven times). A
    /// sharp fold's outgoing piece leaves the followed path, however close to it, and is kept.
    /// When no look-ahead step converges there is no evidence either way and the point is kept.
    pub(super) fn runs_back_along<S: ParametricResidual>(
        &self,
        system: &mut S,
        (from, t): (&[f64], &[f64]),
        y: &[f64],
        followed: &[PathPoint],
    ) -> bool {
        let n = y.len() - 1;
        let recent = &followed[followed.len().saturating_sub(RETRACE_HISTORY)..];
        let distance = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(p, q)| (p - q) * (p - q))
                .sum::<f64>()
                .sqrt()
        };
        let extent = self
            .scaled_points(recent)
            .iter()
            .map(|p| distance(p, y))
            .fold(0.0, f64::max);
        let first = self.settings.initial_step.min(0.5 * extent);
        if first <= 0.0 {
            return false;
        }
        for &fraction in RETRACE_LOOKAHEADS {
            let h = fraction * first;
            let predicted: Vec<f64> = (0..=n).map(|j| from[j] + h * t[j]).collect();
            let Ok((q, _, _)) = self.correct(system, &predicted, t) else {
                continue;
            };
            if distance(&q, &predicted) > h {
                continue;
            }
            return self.on_followed_path(system, &q, distance(&q, y), followed);
        }
        false
    }

    /// Whether a converged point `q` (scaled y) at distance `reach` from where the path is
    /// lies on the path already followed (`followed`, all its points): closer to the polyline
    /// through them than [`RETRACE_FRACTION`] of `reach` (about 3°), and the same solution as
    /// the path's own at q's frequency ([`Continuation::apart_from_path`] within
    /// [`SAME_SOLUTION_TOLERANCE`], or not resolved by Newton). The polyline alone cannot tell
    /// a retrace from the other side of a sharp fold that runs within a fraction of a per cent
    /// of the side followed (the 3D blade pair's fold at 874.57 Hz: 4·10⁻² of the reach off the
    /// polyline, 2.3·10⁻² apart by Newton; a retrace at 886.69 Hz: 7·10⁻⁴ off, 1.2·10⁻¹⁰ apart).
    pub(super) fn on_followed_path<S: ParametricResidual>(
        &self,
        system: &mut S,
        q: &[f64],
        reach: f64,
        followed: &[PathPoint],
    ) -> bool {
        let path = self.scaled_points(followed);
        if distance_to_polyline(q, &path) > RETRACE_FRACTION * reach {
            return false;
        }
        !self
            .apart_from_path(system, q, &path)
            .is_some_and(|d| d > SAME_SOLUTION_TOLERANCE)
    }

    /// How far a converged point `q` (scaled y) near the polyline through `path` (scaled
    /// points) lies from the solution the path itself has at q's frequency: Newton at that
    /// frequency, started from the path's point there (interpolated along the polyline segment
    /// nearest to q, or that segment's nearer end where it does not span the frequency), and
    /// ‖x_N − x_q‖ / ‖x_q‖ on the unknowns. Near a sharp fold of the path the other side runs
    /// within a fraction of a per cent of the side followed (measured on the 3D blade pair at
    /// 873.56 Hz: 2·10⁻⁴ apart in amplitude 0.01 Hz from the fold), closer than the polyline
    /// can resolve, but it is another solution: above [`SAME_SOLUTION_TOLERANCE`]. None when
    /// Newton does not converge.
    fn apart_from_path<S: ParametricResidual>(
        &self,
        system: &mut S,
        q: &[f64],
        path: &[Vec<f64>],
    ) -> Option<f64> {
        let n = q.len() - 1;
        let segment = path
            .windows(2)
            .min_by(|a, b| distance_to_polyline(q, a).total_cmp(&distance_to_polyline(q, b)))?;
        let (a, b) = (&segment[0], &segment[1]);
        let guess_scaled: Vec<f64> = if (a[n] - q[n]) * (b[n] - q[n]) <= 0.0 && a[n] != b[n] {
            let t = (q[n] - a[n]) / (b[n] - a[n]);
            a.iter().zip(b).map(|(u, v)| u + t * (v - u)).collect()
        } else if (a[n] - q[n]).abs() <= (b[n] - q[n]).abs() {
            a.clone()
        } else {
            b.clone()
        };
        let guess: Vec<f64> = (0..n).map(|j| guess_scaled[j] * self.x_scale[j]).collect();
        let solved = self.solve_fixed(system, &guess, q[n] * OMEGA_SCALE).ok()?;
        let xq: Vec<f64> = (0..n).map(|j| q[j] * self.x_scale[j]).collect();
        let apart: Vec<f64> = solved.x.iter().zip(&xq).map(|(u, v)| u - v).collect();
        Some(norm(&apart) / norm(&xq))
    }

    /// The path point of a corrected y, its tangent, the distance of the correction relative
    /// to the step, and the angle (degrees) the tangent turned by over the step.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn corrected_point<S: ParametricResidual>(
        &self,
        system: &mut S,
        yc: &[f64],
        iterations: usize,
        residual: f64,
        ds: f64,
        predicted: &[f64],
        tangent: &[f64],
    ) -> Result<(PathPoint, Vec<f64>, f64, f64), NewtonFailure> {
        let n = yc.len() - 1;
        let distance = norm(
            &yc.iter()
                .zip(predicted)
                .map(|(a, b)| a - b)
                .collect::<Vec<_>>(),
        );
        let point = PathPoint {
            omega: yc[n] * OMEGA_SCALE,
            x: yc[..n]
                .iter()
                .zip(&self.x_scale)
                .map(|(v, s)| v * s)
                .collect(),
            iterations,
            residual,
            step: ds,
        };
        let t_new = self.tangent(system, &point, Some(tangent))?;
        let degrees = dot(&t_new, tangent).clamp(-1.0, 1.0).acos().to_degrees();
        Ok((point, t_new, distance / ds, degrees))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::settings;
    use crate::numerics::continuation::settings::AdaptiveScale;

    /// A narrow-window pass makes the scales and the adaptive climb those of a range a
    /// hundredth as wide, keeps the tangent's direction and the step bounds, spans half that
    /// width on each side of the stall, and its end restores the range's scales.
    #[test]
    fn a_narrow_pass_scales_the_arc_length_to_its_window_and_restores_it() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![2.0, 0.5]).with_adaptive_scale(
            AdaptiveScale {
                group_of: vec![0, 1],
                climb: 2.0,
            },
        );
        let range = c.settings;
        let mut t = vec![0.6, 0.0, 0.8];
        let raw = |c: &Continuation, t: &[f64]| (t[0] * c.x_scale[0], t[2]);
        let before = raw(&c, &t);
        c.enter_narrow(12.0, 12.0, 0, &mut t);
        let f = NARROW_WINDOW_FRACTIONS[0];
        assert_eq!(c.x_scale, vec![2.0 * f, 0.5 * f]);
        assert_eq!(c.adaptive.as_ref().unwrap().climb, 2.0 * f);
        assert_eq!(c.settings, range);
        let inside = raw(&c, &t);
        assert!((before.0 / before.1 - inside.0 / inside.1).abs() < 1e-12);
        assert!((norm(&t) - 1.0).abs() < 1e-12);
        // The window: 0.08 Hz wide (a hundredth of 8 Hz) around 12 Hz.
        assert!(!c.past_narrow_window(12.039) && !c.past_narrow_window(11.961));
        assert!(c.past_narrow_window(12.041) && c.past_narrow_window(11.959));
        assert_eq!(c.leave_narrow(&mut t), Some(12.0));
        assert_eq!(c.settings, range);
        for (s, s0) in c.x_scale.iter().zip([2.0, 0.5]) {
            assert!((s / s0 - 1.0).abs() < 1e-14, "{s}");
        }
        assert!((c.adaptive.as_ref().unwrap().climb / 2.0 - 1.0).abs() < 1e-14);
        let after = raw(&c, &t);
        assert!((before.0 / before.1 - after.0 / after.1).abs() < 1e-12);
        assert!(!c.past_narrow_window(100.0));
        assert_eq!(c.leave_narrow(&mut t), None);
    }
}
