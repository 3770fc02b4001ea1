//! Accepting a corrected point: its tangent and how far the step turned the path, the turning
//! points, the observer's report, and the ends at a point: the range's end behind the start, the
//! observer's own.

use super::predictor::{Oriented, MAX_TURN_DEGREES};
use super::settings::{Continuation, OMEGA_SCALE};
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::{NewtonFailure, Observer, PathEnd, PathPoint, PathSummary};
use crate::numerics::residual::ParametricResidual;

impl Continuation {
    /// The path point of a corrected y (scaled, ω last), its unit tangent oriented along
    /// `tangent`, the distance of the correction from `predicted` relative to the step `ds`,
    /// and the angle (degrees) the tangent turned by over the step. The tangent comes from the
    /// corrector's last factorisation where it kept one; where that tangent turns the path
    /// back in frequency (a fold) or by more than [`MAX_TURN_DEGREES`], it is formed again
    /// from the Jacobian at the point.
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
    ) -> Result<(PathPoint, Oriented, f64, f64), NewtonFailure> {
        let n = yc.len() - 1;
        let apart: Vec<f64> = yc.iter().zip(predicted).map(|(a, b)| a - b).collect();
        let point = PathPoint {
            iterations,
            residual,
            step: ds,
            ..self.unscaled(yc)
        };
        let from_chord = self.last_factor.borrow().is_some();
        let mut t_new = self.tangent(system, &point, Some(tangent))?;
        let turn = |t: &[f64]| dot(t, tangent).clamp(-1.0, 1.0).acos().to_degrees();
        if from_chord && (t_new.t[n] * tangent[n] < 0.0 || turn(&t_new.t) > MAX_TURN_DEGREES) {
            // The chord's factorisation is of an earlier iterate, or carried from an earlier
            // point: near a fold its null direction lags the path's (or, made at an iterate
            // of a step that overshot the fold, leads it), and a fold it flags may not be
            // there. A fold or a sharp turn is judged on the Jacobian at the point itself.
            t_new = self.tangent(system, &point, Some(tangent))?;
        }
        self.orient(&mut t_new);
        let degrees = turn(&t_new.t);
        Ok((point, t_new, norm(&apart) / ds, degrees))
    }

    /// Takes a converged point with its tangent onto the path: reports it (and a turning point
    /// when dω/ds changed sign from `tangent`), makes its tangent the current one and lets the
    /// scale follow the response. Returns true when the path ends at the point: it left the
    /// range for good behind the start ([`PathEnd::LeftRangeBelow`]), or the observer's own end
    /// is reached ([`Observer::reached_end`]: [`PathEnd::EndFrequency`]).
    pub(super) fn accept<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        summary: &mut PathSummary,
        point: PathPoint,
        t_new: Oriented,
        tangent: &mut Vec<f64>,
    ) -> bool {
        let n = t_new.t.len() - 1;
        if t_new.t[n] * tangent[n] < 0.0 {
            summary.turning_points.push(point.freq_hz());
            observer.turning_point(point.freq_hz());
        }
        observer.accepted(system, &point, Some(&self.path_normal(&t_new.t)));
        self.orientation = t_new.sign;
        let left = self.left_range(&point);
        *tangent = t_new.t;
        self.adapt_scale(&point.x, tangent);
        summary.points.push(point);
        let observer_end = observer.reached_end();
        if left {
            summary.end = PathEnd::LeftRangeBelow;
        } else if observer_end {
            summary.end = PathEnd::EndFrequency;
        }
        left || observer_end
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

    /// The path point (unknowns in m, ω in rad/s) of a y in the scaled space (x / x_scale,
    /// ω / 2π), with no iterations, residual or step.
    pub fn unscaled(&self, y: &[f64]) -> PathPoint {
        let n = y.len() - 1;
        PathPoint {
            omega: y[n] * OMEGA_SCALE,
            x: (0..n).map(|j| y[j] * self.x_scale[j]).collect(),
            iterations: 0,
            residual: 0.0,
            step: 0.0,
        }
    }

    /// The point `last` in the scaled space (x / x_scale, ω / 2π).
    pub(super) fn scaled(&self, last: &PathPoint) -> Vec<f64> {
        last.x
            .iter()
            .zip(&self.x_scale)
            .map(|(v, s)| v / s)
            .chain(std::iter::once(last.omega / OMEGA_SCALE))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::{settings, SmoothS};

    /// The unit tangent of the smooth S at x, oriented with x rising (scaled space: x, Hz).
    fn s_tangent(x: f64) -> Vec<f64> {
        let slope = 3.0 * x * x - 3.0;
        let length = (1.0 + slope * slope).sqrt();
        vec![1.0 / length, slope / length]
    }

    /// A chord factorisation made on the S's middle piece (x = −0.5, where a step that
    /// overshot the fold at x = −1 left it) gives, just below the fold on the rising piece, a
    /// tangent that runs back in frequency (a fold that is not there: from x = −1.05) or back
    /// in x by more than [`MAX_TURN_DEGREES`] (from x = −1.1). Either way the tangent is formed
    /// again on the Jacobian at the point, and runs on up to the fold.
    #[test]
    fn a_turn_flagged_by_a_stale_chord_factorisation_is_judged_at_the_point() {
        let mut s = settings(12.0, 17.0);
        s.chord_min_unknowns = 1;
        let c = Continuation::new(s, vec![1.0]);
        let mut system = SmoothS::whole();
        let stale_x = -0.5;
        for (previous_x, x, false_fold) in [(-1.05, -1.04, true), (-1.1, -1.09, false)] {
            let previous = s_tangent(previous_x);
            let mut jac = system.new_jacobian();
            let (mut r, mut dr) = (vec![0.0], vec![0.0]);
            system
                .residual_and_jacobian(
                    &[stale_x],
                    SmoothS::g(stale_x) * OMEGA_SCALE,
                    &mut r,
                    &mut jac,
                    &mut dr,
                )
                .unwrap();
            let col = [dr[0] * OMEGA_SCALE];
            let stale = jac.factor_bordered(&[1.0], &col, &previous).unwrap();
            // What the stale factorisation alone gives.
            let t_stale = stale.solve(&[0.0, 1.0]).unwrap();
            if false_fold {
                assert!(t_stale[1] < 0.0, "{t_stale:?}");
            } else {
                let cos = dot(&t_stale, &previous) / norm(&t_stale);
                assert!(t_stale[0] < 0.0 && cos < MAX_TURN_DEGREES.to_radians().cos());
            }
            c.keep_factor(Some(stale), &previous);
            let yc = [x, SmoothS::g(x)];
            let (_, t_new, _, degrees) = c
                .corrected_point(&mut system, &yc, 3, 0.0, 0.01, &yc, &previous)
                .unwrap();
            let exact = s_tangent(x);
            assert!((t_new.t[0] - exact[0]).abs() < 1e-12, "{t_new:?} {exact:?}");
            assert!((t_new.t[1] - exact[1]).abs() < 1e-12, "{t_new:?} {exact:?}");
            assert!(degrees < MAX_TURN_DEGREES, "{degrees}");
        }
    }

    /// A corrector that converges keeps its factorisation for the next point; one that fails
    /// leaves none to carry to the next try.
    #[test]
    fn a_failed_corrector_carries_no_factorisation() {
        let mut s = settings(12.0, 20.0);
        s.chord_min_unknowns = 1;
        let c = Continuation::new(s, vec![1.0]);
        // Past x = 1.5 the residual has no zero.
        let mut system = SmoothS::ending_at(1.5).with_sparse_jacobian();
        let predicted = [1.2, SmoothS::g(1.2) + 0.01];
        c.correct(&mut system, &predicted, &s_tangent(1.2)).unwrap();
        assert!(c.carried.borrow().is_some());
        // On the hyperplane x = 3 (the tangent along x) the residual has no zero.
        let predicted = [3.0, SmoothS::g(3.0)];
        assert!(c.correct(&mut system, &predicted, &[1.0, 0.0]).is_err());
        assert!(c.carried.borrow().is_none());
    }
}
