//! Accepting a corrected point: its tangent and how far the step turned the path, the turning
//! points, the observer's report, and the range's end behind the start.

use super::settings::{Continuation, OMEGA_SCALE};
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::{NewtonFailure, Observer, PathEnd, PathPoint, PathSummary};
use crate::numerics::residual::ParametricResidual;

impl Continuation {
    /// The path point of a corrected y (scaled, ω last), its unit tangent oriented along
    /// `tangent`, the distance of the correction from `predicted` relative to the step `ds`,
    /// and the angle (degrees) the tangent turned by over the step.
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
        let apart: Vec<f64> = yc.iter().zip(predicted).map(|(a, b)| a - b).collect();
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
        Ok((point, t_new, norm(&apart) / ds, degrees))
    }

    /// Takes a converged point with its tangent onto the path: reports it (and a turning point
    /// when dω/ds changed sign from `tangent`), makes its tangent the current one and lets the
    /// scale follow the response. Returns true when the point left the range for good behind
    /// the start (the summary's end is then [`PathEnd::LeftRangeBelow`]).
    pub(super) fn accept<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        summary: &mut PathSummary,
        point: PathPoint,
        t_new: Vec<f64>,
        tangent: &mut Vec<f64>,
    ) -> bool {
        let n = t_new.len() - 1;
        if t_new[n] * tangent[n] < 0.0 {
            summary.turning_points.push(point.freq_hz());
            observer.turning_point(point.freq_hz());
        }
        observer.accepted(system, &point, Some(&self.path_normal(&t_new)));
        let left = self.left_range(&point);
        *tangent = t_new;
        self.adapt_scale(&point.x, tangent);
        summary.points.push(point);
        if left {
            summary.end = PathEnd::LeftRangeBelow;
        }
        left
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
