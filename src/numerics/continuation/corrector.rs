//! The corrector: Newton on the hyperplane normal to the tangent, and at a fixed frequency, with
//! chord iterations and carried factorisations on large problems, to the same convergence tests.

use super::settings::{Continuation, OMEGA_SCALE};
use crate::numerics::broyden::BroydenUpdates;
use crate::numerics::jacobian::{AssembledJacobian, BorderedFactor};
use crate::numerics::linalg::norm;
use crate::numerics::path::{NewtonFailure, PathPoint};
use crate::numerics::residual::ParametricResidual;

/// Chord iterations of the corrector counted as one Newton iteration (for step adaptation and
/// reports), and the factor of the iteration limit allowed with chord iterations.
pub(super) const CHORD_STEPS_PER_ITERATION: usize = 3;

/// Newton accepts a residual within this many times the operator's round-off level (see
/// `Continuation::tolerance_at`): iterates at that level only move through rounding errors.
const ROUND_OFF_FACTOR: f64 = 4.0;

/// Relative residual below which the round-off level is looked at; a level above it would be
/// a badly scaled residual, not round-off.
const ROUND_OFF_CHECK_BELOW: f64 = 1e-6;

/// A chord iteration must cut the relative residual at least by this factor, else the
/// Jacobian is recomputed and factorised at the current iterate.
const CHORD_CONTRACTION: f64 = 0.5;

/// Continuation points a factorisation may be carried over to (see [`Continuation::correct`]).
const CARRY_POINTS: usize = 8;

impl Continuation {
    /// The residual tolerance at the iterate (x, ω), relative to the residual scale: the
    /// settings' `residual_tolerance`, raised to [`ROUND_OFF_FACTOR`] times the operator's
    /// round-off level ([`ParametricResidual::round_off`]) where that is larger, since no
    /// Newton step can bring the residual below it. The level is looked at only while the
    /// residual `rel` is above the tolerance and below [`ROUND_OFF_CHECK_BELOW`].
    fn tolerance_at<S: ParametricResidual>(
        &self,
        system: &mut S,
        (x, omega): (&[f64], f64),
        rel: f64,
    ) -> f64 {
        let tolerance = self.settings.residual_tolerance;
        if rel <= tolerance || rel > ROUND_OFF_CHECK_BELOW {
            return tolerance;
        }
        tolerance.max(ROUND_OFF_FACTOR * system.round_off(x, omega) / system.residual_scale())
    }

    /// Convergence test of a Newton iterate: the relative residual at tolerance and the scaled
    /// step below its tolerance.
    fn converged(&self, relative_residual: f64, step: f64, tolerance: f64) -> bool {
        relative_residual <= tolerance && step <= self.settings.step_tolerance.max(1e-14)
    }

    /// The residual at an iterate of a chord iteration, returned relative to the load: with a
    /// kept factorisation only the residual (unless `r_current` says r holds it already), and
    /// the factorisation dropped when the residual fell by less than CHORD_CONTRACTION from
    /// `previous`; without one (or once dropped) the residual with the Jacobian and ∂R/∂ω.
    fn chord_evaluate<S: ParametricResidual>(
        &self,
        system: &mut S,
        (x, omega): (&[f64], f64),
        (r, jac, dr): (&mut [f64], &mut AssembledJacobian, &mut [f64]),
        factor: &mut Option<BorderedFactor>,
        r_current: bool,
        previous: f64,
    ) -> Result<f64, NewtonFailure> {
        let eval_err = |e: S::Error| NewtonFailure::Evaluation(e.to_string());
        let scale = system.residual_scale();
        if factor.is_some() {
            if !r_current {
                system.residual(x, omega, r).map_err(eval_err)?;
            }
            let rel = norm(r) / scale;
            if rel <= CHORD_CONTRACTION * previous || rel <= self.settings.residual_tolerance {
                return Ok(rel);
            }
            *factor = None;
        }
        system
            .residual_and_jacobian(x, omega, r, jac, dr)
            .map_err(eval_err)?;
        Ok(norm(r) / scale)
    }

    /// Newton at fixed ω from `x0`, with backtracking on the residual norm.
    pub fn solve_fixed<S: ParametricResidual>(
        &self,
        system: &mut S,
        x0: &[f64],
        omega: f64,
    ) -> Result<PathPoint, NewtonFailure> {
        let n = system.dim();
        let scale = system.residual_scale();
        let mut x = x0.to_vec();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        let mut trial = vec![0.0; n];
        let mut rt = vec![0.0; n];
        let eval_err = |e: S::Error| NewtonFailure::Evaluation(e.to_string());
        // Chord steps on large problems, as in the corrector: the factorisation is kept while
        // each step cuts the residual by CHORD_CONTRACTION.
        let chord = n >= self.settings.chord_min_unknowns;
        let max_iter = self.settings.max_iterations.max(1)
            * 3
            * if chord { CHORD_STEPS_PER_ITERATION } else { 1 };
        let mut factor: Option<BorderedFactor> = None;
        let (mut factorisations, mut chord_steps) = (0usize, 0usize);
        // Whether r holds the residual at x (the accepted trial of the previous step).
        let mut r_current = false;
        let mut rel = f64::INFINITY;
        let mut history = Vec::new();
        for it in 1..=max_iter {
            let previous = rel;
            rel = self.chord_evaluate(
                system,
                (&x, omega),
                (&mut r, &mut jac, &mut dr),
                &mut factor,
                r_current,
                previous,
            )?;
            let tolerance = self.tolerance_at(system, (&x, omega), rel);
            let at_tolerance = rel <= tolerance;
            history.push(rel);
            if !at_tolerance && self.stagnates(&history, chord) {
                return Err(NewtonFailure::MaxIterations {
                    iterations: it,
                    residual: rel,
                });
            }
            let neg: Vec<f64> = r.iter().map(|v| -v).collect();
            let dx = match &factor {
                Some(f) => {
                    chord_steps += 1;
                    let mut rhs = neg;
                    rhs.push(0.0);
                    let mut d = f.solve_chord(&rhs)?;
                    d.truncate(n);
                    d
                }
                None if chord => {
                    // J bordered by a unit row: its factorisation solves J alone.
                    factorisations += 1;
                    let mut row = vec![0.0; n + 1];
                    row[n] = 1.0;
                    let f = jac.factor_bordered(&vec![1.0; n], &vec![0.0; n], &row)?;
                    let mut rhs = neg;
                    rhs.push(0.0);
                    let mut d = f.solve(&rhs)?;
                    d.truncate(n);
                    factor = Some(f);
                    d
                }
                None => jac.solve(&neg)?,
            };
            let step_norm = scaled_norm(&dx, &self.x_scale);
            let mut alpha = 1.0;
            let improved = loop {
                for i in 0..n {
                    trial[i] = x[i] + alpha * dx[i];
                }
                system.residual(&trial, omega, &mut rt).map_err(eval_err)?;
                let rel_t = norm(&rt) / scale;
                let improved = rel_t < rel;
                if improved || alpha < 1e-3 || at_tolerance {
                    if improved || !at_tolerance {
                        rel = rel_t;
                    }
                    break improved;
                }
                alpha *= 0.5;
            };
            // At tolerance, a step that does not lower the residual only moves through
            // round-off: keep the current point (see `correct`).
            let stalled_at_tolerance = at_tolerance && !improved;
            if !stalled_at_tolerance {
                x.copy_from_slice(&trial);
                r.copy_from_slice(&rt);
            }
            r_current = true;
            let it = if chord {
                (factorisations + chord_steps / CHORD_STEPS_PER_ITERATION).max(1)
            } else {
                it
            };
            if stalled_at_tolerance || self.converged(rel, alpha * step_norm, tolerance) {
                // Leave the operator evaluated at the returned point.
                system
                    .residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dr)
                    .map_err(eval_err)?;
                return Ok(PathPoint {
                    omega,
                    x,
                    iterations: it,
                    residual: norm(&r) / scale,
                    step: 0.0,
                });
            }
        }
        Err(NewtonFailure::MaxIterations {
            iterations: max_iter,
            residual: rel,
        })
    }

    /// Corrector: Newton on R = 0 and tᵀ(y − y_p) = 0 in scaled space (y = (x / x_scale,
    /// ω / 2π), `tangent` a unit vector); returns the corrected y, the iterations and the
    /// relative residual.
    pub fn correct<S: ParametricResidual>(
        &self,
        system: &mut S,
        predicted: &[f64],
        tangent: &[f64],
    ) -> Result<(Vec<f64>, usize, f64), NewtonFailure> {
        let n = system.dim();
        let scale = system.residual_scale();
        let mut y = predicted.to_vec();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        let mut col = vec![0.0; n];
        let mut x = vec![0.0; n];
        let mut trial = vec![0.0; n];
        let mut first = f64::NAN;
        let mut rel = f64::INFINITY;
        let mut history = Vec::new();
        // Chord iterations on large problems: the factorised bordered matrix is reused while
        // the residual keeps falling fast enough (see the module docs).
        let chord = n >= self.settings.chord_min_unknowns;
        *self.last_factor.borrow_mut() = None;
        let mut factor: Option<BorderedFactor> = None;
        // A factorisation made at an earlier point of the path (at most CARRY_POINTS back),
        // bordered with this tangent, serves for the first chord steps: when the contact
        // states have not moved much, the point converges without a new factorisation.
        let mut from_carried = false;
        // Whether r holds the residual at the current iterate y (the accepted trial of the
        // previous step), so that a chord step need not evaluate it again.
        let mut r_current = false;
        let mut broyden = BroydenUpdates::default();
        if chord {
            let mut carried = self.carried.borrow_mut();
            if let Some((f, age)) = carried.as_mut() {
                if *age < CARRY_POINTS {
                    *age += 1;
                    factor = f.rebordered(tangent);
                    from_carried = factor.is_some();
                    broyden.clear();
                } else {
                    *carried = None;
                }
            }
        }
        let (mut factorisations, mut chord_steps) = (0usize, 0usize);
        let effort = |f: usize, c: usize| (f + c / CHORD_STEPS_PER_ITERATION).max(1);
        let limit = if chord {
            CHORD_STEPS_PER_ITERATION * self.settings.max_iterations
        } else {
            self.settings.max_iterations
        };
        for it in 1..=limit {
            for i in 0..n {
                x[i] = y[i] * self.x_scale[i];
            }
            let omega = y[n] * OMEGA_SCALE;
            let previous = rel;
            rel = self.chord_evaluate(
                system,
                (&x, omega),
                (&mut r, &mut jac, &mut dr),
                &mut factor,
                r_current,
                previous,
            )?;
            let tolerance = self.tolerance_at(system, (&x, omega), rel);
            if first.is_nan() {
                first = rel;
            } else if rel > 1e4 * first.max(self.settings.residual_tolerance) {
                return Err(NewtonFailure::Diverged { residual: rel });
            }
            history.push(rel);
            if rel > tolerance && self.stagnates(&history, chord) {
                return Err(NewtonFailure::MaxIterations {
                    iterations: it,
                    residual: rel,
                });
            }
            let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            rhs.push(
                -(0..=n)
                    .map(|j| tangent[j] * (y[j] - predicted[j]))
                    .sum::<f64>(),
            );
            let mut dy = match (&factor, chord) {
                (Some(f), _) => {
                    chord_steps += 1;
                    let p = f.solve_chord(&rhs)?;
                    broyden.direction(p)
                }
                (None, _) => {
                    for i in 0..n {
                        col[i] = dr[i] * OMEGA_SCALE;
                    }
                    factorisations += 1;
                    if chord {
                        let f = jac.factor_bordered(&self.x_scale, &col, tangent)?;
                        let d = f.solve(&rhs)?;
                        broyden.restart(&d);
                        *self.carried.borrow_mut() = f.rebordered(tangent).map(|c| (c, 0));
                        from_carried = false;
                        factor = Some(f);
                        d
                    } else {
                        jac.solve_bordered(&self.x_scale, &col, tangent, &rhs)?
                    }
                }
            };
            let it = if chord {
                effort(factorisations, chord_steps)
            } else {
                it
            };
            if rel <= tolerance {
                // At tolerance, a Newton step that does not lower the residual only moves
                // through round-off (amplified by the Jacobian's condition number near a
                // lightly damped resonance): the point is converged.
                for j in 0..n {
                    trial[j] = (y[j] + dy[j]) * self.x_scale[j];
                }
                system
                    .residual(&trial, (y[n] + dy[n]) * OMEGA_SCALE, &mut r)
                    .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                if norm(&r) / scale >= rel {
                    self.keep_factor(factor.take(), tangent);
                    return Ok((y, it, rel));
                }
                r_current = true;
            } else {
                // Backtracking: halve the step while it does not reduce the residual (the
                // contact law is only piecewise smooth, and full steps can cycle between
                // contact states). The arc-length equation is linear, so every fraction of
                // the step keeps it.
                let mut alpha = 1.0;
                loop {
                    for j in 0..n {
                        trial[j] = (y[j] + alpha * dy[j]) * self.x_scale[j];
                    }
                    system
                        .residual(&trial, (y[n] + alpha * dy[n]) * OMEGA_SCALE, &mut r)
                        .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                    if norm(&r) / scale < rel || alpha < 1e-3 {
                        break;
                    }
                    if from_carried {
                        // A factorisation carried from an earlier point that does not lower
                        // the residual with a full step is not worth backtracking on: stay,
                        // and factorise afresh at this iterate.
                        alpha = 0.0;
                        factor = None;
                        from_carried = false;
                        break;
                    }
                    alpha *= 0.5;
                }
                // r now holds the residual at the accepted iterate (not after a rejected
                // carried step, which leaves the iterate where it was).
                r_current = alpha > 0.0;
                dy.iter_mut().for_each(|v| *v *= alpha);
                broyden.stepped(alpha);
            }
            for j in 0..=n {
                y[j] += dy[j];
            }
            let step = norm(&dy);
            if self.converged(rel, step, tolerance) {
                self.keep_factor(factor.take(), tangent);
                return Ok((y, it, rel));
            }
            if step <= self.settings.step_tolerance {
                // The step is converged: check the residual at the updated point.
                for i in 0..n {
                    x[i] = y[i] * self.x_scale[i];
                }
                system
                    .residual(&x, y[n] * OMEGA_SCALE, &mut r)
                    .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                let rel_new = norm(&r) / scale;
                r_current = true;
                if rel_new <= tolerance {
                    self.keep_factor(factor.take(), tangent);
                    return Ok((y, it, rel_new));
                }
            }
        }
        Err(NewtonFailure::MaxIterations {
            iterations: limit,
            residual: rel,
        })
    }
}

/// Norm of v scaled per entry: ‖(vᵢ / sᵢ)‖.
fn scaled_norm(v: &[f64], scale: &[f64]) -> f64 {
    v.iter()
        .zip(scale)
        .map(|(a, s)| (a / s) * (a / s))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::{settings, ZPath};
    use crate::numerics::continuation::settings::StagnationExit;

    /// A solve that does not converge because the residual has no root nearby (on the Z at
    /// 16 Hz from x = 1.1 Newton creeps toward the fold at x = 1, where |R| has a kink minimum
    /// of 1): without the exit it spends the fixed-frequency limit (three times
    /// `max_iterations`); with it, it is given up once past the iterations it always gets,
    /// when its residual has not fallen by a tenth over the window. A solve that converges is
    /// not touched by the exit.
    #[test]
    fn a_stagnating_solve_is_given_up_after_its_guaranteed_iterations() {
        let omega = 16.0 * OMEGA_SCALE;
        let plain = Continuation::new(settings(10.0, 20.0), vec![1.0]);
        match plain.solve_fixed(&mut ZPath, &[1.1], omega) {
            Err(NewtonFailure::MaxIterations {
                iterations,
                residual,
            }) => {
                assert_eq!(iterations, 36);
                assert!(residual > 0.99 && residual < 1.2, "{residual}");
            }
            other => panic!("expected the iteration limit, got {other:?}"),
        }
        let exit = StagnationExit { after: 12 };
        let stopping =
            Continuation::new(settings(10.0, 20.0), vec![1.0]).with_stagnation_exit(exit);
        match stopping.solve_fixed(&mut ZPath, &[1.1], omega) {
            Err(NewtonFailure::MaxIterations { iterations, .. }) => {
                assert_eq!(
                    iterations, 13,
                    "given up at the first iteration past the 12th"
                );
            }
            other => panic!("expected the stagnation exit, got {other:?}"),
        }
        // With chord steps (three to an iteration) the guaranteed iterations count three steps
        // each, as the limit does.
        let mut chord_settings = settings(10.0, 20.0);
        chord_settings.chord_min_unknowns = 1;
        let chord = Continuation::new(chord_settings, vec![1.0]);
        let chord_stopping =
            Continuation::new(chord_settings, vec![1.0]).with_stagnation_exit(exit);
        match (
            chord.solve_fixed(&mut ZPath, &[1.1], omega),
            chord_stopping.solve_fixed(&mut ZPath, &[1.1], omega),
        ) {
            (
                Err(NewtonFailure::MaxIterations {
                    iterations: all, ..
                }),
                Err(NewtonFailure::MaxIterations {
                    iterations: given_up,
                    ..
                }),
            ) => {
                assert_eq!(all, 108);
                assert_eq!(given_up, 37, "given up at the first step past the 36th");
            }
            other => panic!("expected both to fail, got {other:?}"),
        }
        // A converging solve on the third piece (g = 16 at x = 1.8) is the same either way.
        let a = plain
            .solve_fixed(&mut ZPath, &[1.5], omega)
            .expect("converges");
        let b = stopping
            .solve_fixed(&mut ZPath, &[1.5], omega)
            .expect("converges");
        assert_eq!(a, b);
        assert!((a.x[0] - 1.8).abs() < 1e-12);
        // The rule itself: a fall to 0.9 of the value 8 iterations before is progress.
        let exit = StagnationExit { after: 0 };
        let falling: Vec<f64> = (0..9).map(|k| 0.986_f64.powi(k)).collect();
        assert!(!exit.stagnated(&falling), "0.986⁸ = 0.893, below 0.9");
        let slower: Vec<f64> = (0..9).map(|k| 0.987_f64.powi(k)).collect();
        assert!(exit.stagnated(&slower), "0.987⁸ = 0.901, above 0.9");
        let flat = vec![0.2; 9];
        assert!(exit.stagnated(&flat));
        assert!(!exit.stagnated(&flat[..8]), "the window is not full yet");
        assert!(!StagnationExit { after: 9 }.stagnated(&flat));
    }
}
