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

/// Smallest fraction of a Newton step the backtracking line search tries.
const MIN_STEP_FRACTION: f64 = 1e-3;

/// An operator error as a Newton failure.
fn evaluation(e: impl std::fmt::Display) -> NewtonFailure {
    NewtonFailure::Evaluation(e.to_string())
}

/// The work of one Newton solve: with chord steps, [`CHORD_STEPS_PER_ITERATION`] of them and
/// each factorisation count as one iteration.
struct Effort {
    chord: bool,
    factorisations: usize,
    chord_steps: usize,
}

impl Effort {
    fn new(chord: bool) -> Self {
        Effort {
            chord,
            factorisations: 0,
            chord_steps: 0,
        }
    }

    /// Steps allowed for an iteration limit of `iterations`.
    fn step_limit(&self, iterations: usize) -> usize {
        iterations
            * if self.chord {
                CHORD_STEPS_PER_ITERATION
            } else {
                1
            }
    }

    /// The iterations reported after `steps` steps.
    fn iterations(&self, steps: usize) -> usize {
        if self.chord {
            (self.factorisations + self.chord_steps / CHORD_STEPS_PER_ITERATION).max(1)
        } else {
            steps
        }
    }
}

/// The residual at (x, ω), left in `r`, relative to the residual scale.
fn relative_residual<S: ParametricResidual>(
    system: &mut S,
    (x, omega): (&[f64], f64),
    r: &mut [f64],
) -> Result<f64, NewtonFailure> {
    system.residual(x, omega, r).map_err(evaluation)?;
    Ok(norm(r) / system.residual_scale())
}

/// Backtracking line search on the residual norm: the trial residual at α = 1, ½, ¼, … until it
/// falls below `rel` or α drops below [`MIN_STEP_FRACTION`] (or at α = 1 only when `single`).
/// `place(α, x)` writes the trial unknowns for α into x and returns the trial ω. Returns α, the
/// trial's relative residual (left in `r`) and whether it fell below `rel`.
fn line_search<S: ParametricResidual>(
    system: &mut S,
    rel: f64,
    single: bool,
    (trial, r): (&mut [f64], &mut [f64]),
    mut place: impl FnMut(f64, &mut [f64]) -> f64,
) -> Result<(f64, f64, bool), NewtonFailure> {
    let mut alpha = 1.0;
    loop {
        let omega = place(alpha, trial);
        let rel_trial = relative_residual(system, (trial, omega), r)?;
        let improved = rel_trial < rel;
        if improved || single || alpha < MIN_STEP_FRACTION {
            return Ok((alpha, rel_trial, improved));
        }
        alpha *= 0.5;
    }
}

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
        let scale = system.residual_scale();
        if factor.is_some() {
            if !r_current {
                system.residual(x, omega, r).map_err(evaluation)?;
            }
            let rel = norm(r) / scale;
            if rel <= CHORD_CONTRACTION * previous || rel <= self.settings.residual_tolerance {
                return Ok(rel);
            }
            *factor = None;
        }
        system
            .residual_and_jacobian(x, omega, r, jac, dr)
            .map_err(evaluation)?;
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
        let mut x = x0.to_vec();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        let mut trial = vec![0.0; n];
        // Chord steps on large problems, as in the corrector: the factorisation is kept while
        // each step cuts the residual by CHORD_CONTRACTION.
        let mut effort = Effort::new(n >= self.settings.chord_min_unknowns);
        let max_iter = effort.step_limit(self.settings.max_iterations.max(1) * 3);
        let mut factor: Option<BorderedFactor> = None;
        // Whether r holds the residual at x (the accepted trial of the previous step).
        let mut r_current = false;
        let mut rel = f64::INFINITY;
        let mut history = Vec::new();
        for it in 1..=max_iter {
            rel = self.chord_evaluate(
                system,
                (&x, omega),
                (&mut r, &mut jac, &mut dr),
                &mut factor,
                r_current,
                rel,
            )?;
            let tolerance = self.tolerance_at(system, (&x, omega), rel);
            let at_tolerance = rel <= tolerance;
            history.push(rel);
            if !at_tolerance && self.stagnates(&history, effort.chord) {
                return Err(NewtonFailure::MaxIterations {
                    iterations: it,
                    residual: rel,
                });
            }
            let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            let dx = if effort.chord {
                rhs.push(0.0);
                let mut d = match &factor {
                    Some(f) => {
                        effort.chord_steps += 1;
                        f.solve_chord(&rhs)?
                    }
                    None => {
                        // J bordered by a unit row: its factorisation solves J alone.
                        effort.factorisations += 1;
                        let mut row = vec![0.0; n + 1];
                        row[n] = 1.0;
                        let f = jac.factor_bordered(&vec![1.0; n], &vec![0.0; n], &row)?;
                        let d = f.solve(&rhs)?;
                        factor = Some(f);
                        d
                    }
                };
                d.truncate(n);
                d
            } else {
                jac.solve(&rhs)?
            };
            let step_norm = scaled_norm(&dx, &self.x_scale);
            // At tolerance only the full step is tried: one that does not lower the residual
            // only moves through round-off, and the current point is kept (as in `correct`).
            let (alpha, rel_trial, improved) =
                line_search(system, rel, at_tolerance, (&mut trial, &mut r), |a, t| {
                    for i in 0..n {
                        t[i] = x[i] + a * dx[i];
                    }
                    omega
                })?;
            let stalled_at_tolerance = at_tolerance && !improved;
            if !stalled_at_tolerance {
                rel = rel_trial;
                x.copy_from_slice(&trial);
            }
            r_current = true;
            if stalled_at_tolerance || self.converged(rel, alpha * step_norm, tolerance) {
                // Leave the operator evaluated at the returned point.
                system
                    .residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dr)
                    .map_err(evaluation)?;
                return Ok(PathPoint {
                    omega,
                    x,
                    iterations: effort.iterations(it),
                    residual: norm(&r) / system.residual_scale(),
                    step: 0.0,
                });
            }
        }
        Err(NewtonFailure::MaxIterations {
            iterations: max_iter,
            residual: rel,
        })
    }

    /// The factorisation carried from an earlier point of the path (at most [`CARRY_POINTS`]
    /// back), bordered with this tangent: when the contact states have not moved much, the
    /// point converges on it without a new factorisation.
    fn carried_factor(&self, tangent: &[f64]) -> Option<BorderedFactor> {
        let mut carried = self.carried.borrow_mut();
        let (f, age) = carried.as_mut()?;
        if *age < CARRY_POINTS {
            *age += 1;
            f.rebordered(tangent)
        } else {
            *carried = None;
            None
        }
    }

    /// The corrector's Newton direction for `rhs`: a chord step on the kept factorisation
    /// `factor` (with Broyden's updates), else, with chord steps, a new factorisation of the
    /// bordered Jacobian, kept for the next steps and carried to later points, or without
    /// them a bordered solve.
    fn corrector_direction(
        &self,
        (jac, dr): (&mut AssembledJacobian, &[f64]),
        tangent: &[f64],
        rhs: &[f64],
        (factor, broyden, effort): (
            &mut Option<BorderedFactor>,
            &mut BroydenUpdates,
            &mut Effort,
        ),
    ) -> Result<Vec<f64>, NewtonFailure> {
        if let Some(f) = factor {
            effort.chord_steps += 1;
            return Ok(broyden.direction(f.solve_chord(rhs)?));
        }
        let col: Vec<f64> = dr.iter().map(|v| v * OMEGA_SCALE).collect();
        effort.factorisations += 1;
        if !effort.chord {
            return Ok(jac.solve_bordered(&self.x_scale, &col, tangent, rhs)?.0);
        }
        let f = jac.factor_bordered(&self.x_scale, &col, tangent)?;
        let d = f.solve(rhs)?;
        broyden.restart(&d);
        *self.carried.borrow_mut() = f.rebordered(tangent).map(|c| (c, 0));
        *factor = Some(f);
        Ok(d)
    }

    /// Whether Newton gives up at iteration `it`, from the relative residuals `history` of its
    /// steps: the residual grew 10⁴ times above the first one (diverged), or it stagnates above
    /// `tolerance` (see [`Continuation::stagnates`]).
    fn diverged_or_stagnated(
        &self,
        history: &[f64],
        tolerance: f64,
        (it, chord): (usize, bool),
    ) -> Result<(), NewtonFailure> {
        let (first, rel) = (history[0], history[history.len() - 1]);
        if rel > 1e4 * first.max(self.settings.residual_tolerance) {
            return Err(NewtonFailure::Diverged { residual: rel });
        }
        if rel > tolerance && self.stagnates(history, chord) {
            return Err(NewtonFailure::MaxIterations {
                iterations: it,
                residual: rel,
            });
        }
        Ok(())
    }

    /// Corrector: Newton on R = 0 and tᵀ(y − y_p) = 0 in scaled space (y = (x / x_scale,
    /// ω / 2π), `tangent` a unit vector); returns the corrected y, the iterations and the
    /// relative residual. A corrector that fails carries no factorisation to the next try:
    /// its factorisations are of iterates that did not reach the path (past a fold, of a step
    /// that overshot it), and chord steps on them would converge with a Jacobian of the wrong
    /// piece, whose null direction would then orient the path.
    pub fn correct<S: ParametricResidual>(
        &self,
        system: &mut S,
        predicted: &[f64],
        tangent: &[f64],
    ) -> Result<(Vec<f64>, usize, f64), NewtonFailure> {
        let outcome = self.correct_from(system, predicted, tangent);
        if outcome.is_err() {
            *self.carried.borrow_mut() = None;
        }
        outcome
    }

    /// The corrector's Newton loop (see [`Self::correct`]).
    fn correct_from<S: ParametricResidual>(
        &self,
        system: &mut S,
        predicted: &[f64],
        tangent: &[f64],
    ) -> Result<(Vec<f64>, usize, f64), NewtonFailure> {
        let n = system.dim();
        let mut y = predicted.to_vec();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        let mut x = vec![0.0; n];
        let mut trial = vec![0.0; n];
        let mut rel = f64::INFINITY;
        let mut history = Vec::new();
        // Chord iterations on large problems: the factorised bordered matrix is reused while
        // the residual keeps falling fast enough (see the module docs).
        let mut effort = Effort::new(n >= self.settings.chord_min_unknowns);
        *self.last_factor.borrow_mut() = None;
        let mut factor = effort.chord.then(|| self.carried_factor(tangent)).flatten();
        let mut from_carried = factor.is_some();
        // Whether r holds the residual at the current iterate y (the accepted trial of the
        // previous step), so that a chord step need not evaluate it again.
        let mut r_current = false;
        let mut broyden = BroydenUpdates::default();
        let limit = effort.step_limit(self.settings.max_iterations);
        for it in 1..=limit {
            for i in 0..n {
                x[i] = y[i] * self.x_scale[i];
            }
            let omega = y[n] * OMEGA_SCALE;
            rel = self.chord_evaluate(
                system,
                (&x, omega),
                (&mut r, &mut jac, &mut dr),
                &mut factor,
                r_current,
                rel,
            )?;
            let tolerance = self.tolerance_at(system, (&x, omega), rel);
            history.push(rel);
            self.diverged_or_stagnated(&history, tolerance, (it, effort.chord))?;
            let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            rhs.push(
                -(0..=n)
                    .map(|j| tangent[j] * (y[j] - predicted[j]))
                    .sum::<f64>(),
            );
            if factor.is_none() {
                from_carried = false;
            }
            let mut dy = self.corrector_direction(
                (&mut jac, &dr),
                tangent,
                &rhs,
                (&mut factor, &mut broyden, &mut effort),
            )?;
            let it = effort.iterations(it);
            // At tolerance only the full step is tried: one that does not lower the residual
            // only moves through round-off (amplified by the Jacobian's condition number near a
            // lightly damped resonance), and the point is converged. Elsewhere the step is
            // halved while it does not lower the residual, except on a factorisation carried
            // from an earlier point, which is not worth backtracking on: stay, and factorise
            // afresh at this iterate. The arc-length equation is linear, so every fraction of
            // the step keeps it.
            let at_tolerance = rel <= tolerance;
            let (mut alpha, _, improved) = line_search(
                system,
                rel,
                at_tolerance || from_carried,
                (&mut trial, &mut r),
                |a, t| {
                    for j in 0..n {
                        t[j] = (y[j] + a * dy[j]) * self.x_scale[j];
                    }
                    (y[n] + a * dy[n]) * OMEGA_SCALE
                },
            )?;
            if at_tolerance && !improved {
                self.keep_factor(factor.take(), tangent);
                return Ok((y, it, rel));
            }
            if from_carried && !improved {
                alpha = 0.0;
                factor = None;
                from_carried = false;
            }
            // r holds the residual at the accepted iterate (not after a rejected carried
            // step, which leaves the iterate where it was).
            r_current = alpha > 0.0;
            dy.iter_mut().for_each(|v| *v *= alpha);
            if !at_tolerance {
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
                let rel_new = relative_residual(system, (&x, y[n] * OMEGA_SCALE), &mut r)?;
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
    use crate::numerics::continuation::fixtures::{settings, z_path};
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
        match plain.solve_fixed(&mut z_path(), &[1.1], omega) {
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
        match stopping.solve_fixed(&mut z_path(), &[1.1], omega) {
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
            chord.solve_fixed(&mut z_path(), &[1.1], omega),
            chord_stopping.solve_fixed(&mut z_path(), &[1.1], omega),
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
            .solve_fixed(&mut z_path(), &[1.5], omega)
            .expect("converges");
        let b = stopping
            .solve_fixed(&mut z_path(), &[1.5], omega)
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
