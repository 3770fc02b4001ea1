//! The predictor: the unit tangent at a point and the step length along it, from the corrector's
//! iterations, the turn of the path and the change of the watched amplitudes; scale growth.

use super::settings::{Continuation, OMEGA_SCALE};
use crate::numerics::jacobian::BorderedFactor;
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::{NewtonFailure, PathPoint};
use crate::numerics::residual::ParametricResidual;

/// Change of ln(amplitude) of a watched output per step the step length aims at (see
/// [`Continuation::with_amplitude_steps`]): about 10 %.
pub(super) const TARGET_LOG_AMPLITUDE_CHANGE: f64 = 0.1;

/// Largest turn of the tangent in one step before the step is cut (a jump to another branch).
pub(super) const MAX_TURN_DEGREES: f64 = 45.0;

/// Turn of the tangent per step the step length aims at: a step that turned the tangent by
/// more is followed by a shorter one (at most halved), one that turned it by less may grow (at
/// most doubled), as Newton's iteration count allows.
pub(super) const TARGET_TURN_DEGREES: f64 = 10.0;

/// A unit tangent (scaled space, ω last) with the sign of det [J; tᵀ] where the factorisation
/// gives it (see [`Continuation::orient`]).
#[derive(Debug, Clone)]
pub(super) struct Oriented {
    pub(super) t: Vec<f64>,
    pub(super) sign: Option<f64>,
}

impl Continuation {
    /// The largest |ln(a_after / a_before)| over the watched amplitudes (0 without any).
    pub(super) fn log_amplitude_change(&self, before: &[f64], after: &[f64]) -> f64 {
        let amplitude = |x: &[f64], g: &[usize]| g.iter().map(|&i| x[i] * x[i]).sum::<f64>();
        self.amplitudes
            .iter()
            .map(|g| {
                let (a, b) = (amplitude(before, g), amplitude(after, g));
                if a > 0.0 && b > 0.0 {
                    0.5 * (b / a).ln().abs()
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
    }

    /// Grows the scale of each group whose norm at `x` (m) has outgrown it (see
    /// [`AdaptiveScale`](super::AdaptiveScale)) and carries the unit tangent over to the new scaled
    /// space. Kept factorisations are dropped: they were built in the old one.
    pub(super) fn adapt_scale(&mut self, x: &[f64], tangent: &mut [f64]) {
        let Some(adaptive) = &self.adaptive else {
            return;
        };
        let groups = adaptive.group_of.iter().copied().max().map_or(0, |g| g + 1);
        let mut norms = vec![0.0_f64; groups];
        let mut current = vec![0.0_f64; groups];
        for (i, &g) in adaptive.group_of.iter().enumerate() {
            norms[g] += x[i] * x[i];
            current[g] = current[g].max(self.x_scale[i]);
        }
        let wanted: Vec<f64> = norms.iter().map(|v| v.sqrt() / adaptive.climb).collect();
        if !(0..groups).any(|g| wanted[g] > 2.0 * current[g]) {
            return;
        }
        for (i, &g) in adaptive.group_of.iter().enumerate() {
            if wanted[g] > 2.0 * current[g] {
                let new = wanted[g];
                tangent[i] *= self.x_scale[i] / new;
                self.x_scale[i] = new;
            }
        }
        let length = norm(tangent);
        tangent.iter_mut().for_each(|v| *v /= length);
        *self.last_factor.borrow_mut() = None;
        *self.carried.borrow_mut() = None;
    }

    /// Multiplies the scale of every unknown (and the adaptive scale's climb) by `factor` and
    /// carries the unit tangent over to the new scaled space as the same direction. Kept
    /// factorisations are dropped: they were built in the old one.
    pub(super) fn rescale(&mut self, factor: f64, tangent: &mut [f64]) {
        let n = self.x_scale.len();
        self.x_scale.iter_mut().for_each(|s| *s *= factor);
        if let Some(adaptive) = &mut self.adaptive {
            adaptive.climb *= factor;
        }
        tangent[..n].iter_mut().for_each(|v| *v /= factor);
        let length = norm(tangent);
        tangent.iter_mut().for_each(|v| *v /= length);
        *self.last_factor.borrow_mut() = None;
        *self.carried.borrow_mut() = None;
    }

    /// Keeps the chord corrector's last factorisation for the tangent at its point.
    pub(super) fn keep_factor(&self, factor: Option<BorderedFactor>, tangent: &[f64]) {
        *self.last_factor.borrow_mut() = factor.map(|f| (tangent.to_vec(), f));
    }

    /// Unit tangent in scaled space at a converged point, oriented along `previous` (or
    /// towards the end frequency when there is none), with the sign of det [J; tᵀ] where the
    /// factorisation gives the sign of the bordered matrix's determinant (see
    /// [`Self::orient`]).
    pub(super) fn tangent<S: ParametricResidual>(
        &self,
        system: &mut S,
        point: &PathPoint,
        previous: Option<&[f64]>,
    ) -> Result<Oriented, NewtonFailure> {
        let n = system.dim();
        let mut rhs = vec![0.0; n + 1];
        rhs[n] = 1.0;
        // Chord corrector: the factorisation of its last iterate, built with the same tangent
        // row, gives the tangent without a new Jacobian (its iterate is within the corrector's
        // tolerance of the point, and the tangent only orients the next prediction).
        let kept = self.last_factor.borrow_mut().take();
        if let (Some((row, factor)), Some(p)) = (kept, previous) {
            if row == p {
                let mut t = factor.solve(&rhs)?;
                let nt = norm(&t);
                t.iter_mut().for_each(|v| *v /= nt);
                let mut sign = factor.det_sign();
                if dot(&t, p) < 0.0 {
                    t.iter_mut().for_each(|v| *v = -*v);
                    sign = sign.map(|s| -s);
                }
                return Ok(Oriented { t, sign });
            }
        }
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        system
            .residual_and_jacobian(&point.x, point.omega, &mut r, &mut jac, &mut dr)
            .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
        let col: Vec<f64> = dr.iter().map(|v| v * OMEGA_SCALE).collect();
        let row = match previous {
            Some(p) => p.to_vec(),
            None => {
                let mut e = vec![0.0; n + 1];
                e[n] = 1.0;
                e
            }
        };
        let (mut t, mut sign) = jac.solve_bordered(&self.x_scale, &col, &row, &rhs)?;
        let nt = norm(&t);
        t.iter_mut().for_each(|v| *v /= nt);
        let orientation = match previous {
            Some(p) => dot(&t, p),
            None => self.direction() * t[n],
        };
        if orientation < 0.0 {
            t.iter_mut().for_each(|v| *v = -*v);
            sign = sign.map(|s| -s);
        }
        Ok(Oriented { t, sign })
    }

    /// Orients the tangent at a corrected point as the path is oriented: det [J; tᵀ]
    /// keeps its sign along a path through regular points (Allgower & Georg, Introduction to
    /// Numerical Continuation Methods, 2.1), where both signs are known (the tangent's own,
    /// from [`Self::tangent`], and the path's at its last point). Along a smooth path this
    /// is the orientation along the previous tangent; they differ where the path turns back
    /// at a corner by more than 90° (a fold at a corner, where a contact's slider changes what
    /// anchors it): there the tangent oriented along the incoming one points back to the
    /// corner, and a step along it lands on the incoming piece. Without this the 3D blade
    /// pair's path over 840-900 Hz turns back at its corner fold at 886.82 Hz onto the very
    /// points it came along, down to the range's start
    /// (`blade_pair_3d::the_3d_frf_over_the_bending_pair_is_complete_through_both_folds`).
    pub(super) fn orient(&self, tangent: &mut Oriented) {
        if let (Some(path), Some(formed)) = (self.orientation, tangent.sign) {
            if formed != path {
                tangent.t.iter_mut().for_each(|v| *v = -*v);
                tangent.sign = Some(path);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::{g, settings, z_path};
    use crate::numerics::continuation::settings::AdaptiveScale;

    /// Past the Z's first fold, a corner where the path turns back by about 163°, the tangent
    /// on the middle piece is oriented down in frequency, away from the corner, as the path
    /// goes on: det [J; tᵀ] keeps its sign. Oriented along the incoming tangent alone it
    /// would point back up to the corner.
    #[test]
    fn past_a_corner_fold_the_tangent_points_away_from_the_corner() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![1.0]);
        let at = |x: f64| PathPoint {
            omega: g(x).0 * OMEGA_SCALE,
            x: vec![x],
            iterations: 1,
            residual: 0.0,
            step: 0.01,
        };
        let incoming = c.tangent(&mut z_path(), &at(0.95), None).unwrap();
        assert!(incoming.t[0] > 0.0 && incoming.t[1] > 0.0, "{incoming:?}");
        c.orientation = incoming.sign;
        assert!(c.orientation.is_some());
        let mut middle = c
            .tangent(&mut z_path(), &at(1.05), Some(&incoming.t))
            .unwrap();
        assert!(middle.t[1] > 0.0, "along the incoming tangent: back up");
        c.orient(&mut middle);
        assert!(middle.t[0] > 0.0 && middle.t[1] < 0.0, "{middle:?}");
    }

    /// The scale of a group grows with its norm along the path and the tangent is carried over
    /// to the new scaled space as the same direction.
    #[test]
    fn adaptive_scale_grows_and_keeps_the_tangent_direction() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![1.0, 1.0]).with_adaptive_scale(
            AdaptiveScale {
                group_of: vec![0, 1],
                climb: 1.0,
            },
        );
        let mut t = vec![0.6, 0.0, 0.8];
        let raw = |c: &Continuation, t: &[f64]| (t[0] * c.x_scale[0], t[2]);
        let before = raw(&c, &t);
        c.adapt_scale(&[10.0, 1.5], &mut t);
        assert_eq!(c.x_scale, vec![10.0, 1.0]);
        let after = raw(&c, &t);
        assert!((before.0 / before.1 - after.0 / after.1).abs() < 1e-12);
        assert!((norm(&t) - 1.0).abs() < 1e-12);
    }
}
