//! The extension solved to convergence where the Newton step leaves its linear range: at the
//! point's frequency, or across the path on the hyperplane the step was bordered with.

use super::estimator::{extended_newton, ErrorEstimator, Wider};
use super::problems::{amplitudes, relative_changes, wider_harmonic, Refined};
use super::rules::{solves_padded, LinearRange, WidenGate};
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::ParametricResidual;

impl<'p> ErrorEstimator<'p> {
    /// The extended system solved to convergence across the path at the converged point `x` (full
    /// coefficients) at ω = `omega` (rad/s), from the point padded with zeros, on the hyperplane
    /// `path_normal` (as [`PointAccuracy::path_normal`](super::PointAccuracy::path_normal): a
    /// covector on the full coefficients, then on ω): the relative change of each output's
    /// amplitude, None where Newton does not converge. The set is the wider one (4H + 3) when
    /// `harmonic` (as
    /// [`PointAccuracy::estimate_harmonic`](super::PointAccuracy::estimate_harmonic)) is its top,
    /// else 2H + 1. The estimate a point next to a fold reports where its across-path step leaves
    /// its linear range; here for any path point, to compare it with the true error across the path
    /// where no point reports it.
    pub fn solved_across(
        &mut self,
        x: &[f64],
        omega: f64,
        path_normal: &[f64],
        harmonic: usize,
    ) -> Option<Vec<f64>> {
        let (on_omega, on_full) = path_normal.split_last()?;
        if on_full.len() != x.len() {
            return None;
        }
        let mut normal: Vec<f64> = self.full_index.iter().map(|&i| on_full[i]).collect();
        normal.push(*on_omega);
        let base = amplitudes(self.problem, &self.set, x);
        let wider = harmonic == wider_harmonic(self.h_max);
        self.on_one_thread(|e| {
            e.converged_across(x, omega, wider, &base, &normal, (&[], f64::INFINITY))
        })
    }
}

impl<'p> ErrorEstimator<'p> {
    /// Whether a point that [`TailTest`](super::TailTest) sends to the wider set is widened
    /// ([`WidenGate`]).
    pub(super) fn widens(
        &self,
        truncation: &[f64],
        contraction: f64,
        padded_converged: bool,
    ) -> bool {
        WidenGate::widens(
            truncation,
            LinearRange::holds(contraction, padded_converged),
            self.problem.analysis.error_estimate.warn_threshold,
        )
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The border row on the unknowns of `refined` for the path normal `normal` (the run's
    /// unknowns, then ω in rad/s); None when it does not fit or is not finite.
    pub(super) fn row_on(&self, refined: &Refined, normal: &[f64]) -> Option<Vec<f64>> {
        let (on_omega, on_x) = normal.split_last()?;
        if on_x.len() != self.full_index.len() || normal.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut row = refined.on_kept_blocks(on_x, self.set.n_blocks())?;
        row.push(*on_omega);
        Some(row)
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The converged solution of the extended system (the wider one when `wider`) across the
    /// path: Newton on the extended residual bordered with the path's hyperplane through the
    /// point, `normal` · (x − x₀, ω − ω₀) = 0 (`normal` on the run's unknowns, then ω in
    /// rad/s; zero on the new harmonics), as the relative change of each output's amplitude
    /// from `base`; None when Newton does not converge. What the across-path step of
    /// [`Self::estimate`] approximates, for the points next to a fold whose step leaves its
    /// linear range ([`LinearRange`]).
    ///
    /// `step` is that across-path step on the same set (its unknowns, then δω), `contraction`
    /// its contraction: where it lowers the residual the solve starts from the stepped point
    /// (in the hyperplane, since the step is), as [`Self::converged_truncation`] does. The
    /// Newton iterations are the continuation's corrector ([`Continuation::correct`](crate::numerics::continuation::Continuation::correct)) with the
    /// hyperplane as its arc-length row, with three times the path's `max_iterations` as its
    /// limit, as the fixed-frequency solve, the iterations beyond the path's own only while
    /// the residual keeps falling ([`extended_newton`]). Three times the limit without that
    /// exit had sized 382 instead of 285 of the 607 such points of the larger blade pair at
    /// H = 1 over 855-895 Hz for 10 s more user CPU (38 s against 28 s); with it the estimate
    /// costs less than with the path's limit alone (docs/accuracy.md, "What the estimate
    /// costs").
    pub(super) fn converged_across(
        &mut self,
        x: &[f64],
        omega: f64,
        wider: bool,
        base: &[f64],
        normal: &[f64],
        (step, contraction): (&[f64], f64),
    ) -> Option<Vec<f64>> {
        let n = self.problem.model.n_dofs();
        let row = self.row_on(if wider { &self.wider } else { &self.truncation }, normal)?;
        let refined = if wider {
            &mut self.wider
        } else {
            &mut self.truncation
        };
        let xr = refined.padded(n, x);
        let dim = xr.len();
        if row.len() != dim + 1 {
            return None;
        }
        // Scaled space of the corrector: x in units of the point's largest coefficient (as
        // the fixed-frequency solve's step tolerance), ω in Hz.
        let scale = xr.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
        let hz = 2.0 * std::f64::consts::PI;
        let (start, omega_start) = if contraction < 1.0 && step.len() == dim + 1 {
            (
                xr.iter()
                    .zip(step)
                    .map(|(a, d)| a - d)
                    .collect::<Vec<f64>>(),
                omega - step[dim],
            )
        } else {
            (xr.clone(), omega)
        };
        let mut predicted: Vec<f64> = start.iter().map(|v| v / scale).collect();
        predicted.push(omega_start / hz);
        // The hyperplane's normal in the scaled space, as a unit vector.
        let mut tangent: Vec<f64> = row[..dim].iter().map(|w| w * scale).collect();
        tangent.push(row[dim] * hz);
        let length = crate::numerics::linalg::norm(&tangent);
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        tangent.iter_mut().for_each(|v| *v /= length);
        let newton = extended_newton(self.problem, vec![scale; dim], 3);
        let (y, _, _) = newton
            .correct(&mut refined.operator, &predicted, &tangent)
            .ok()?;
        let solved: Vec<f64> = y[..dim].iter().map(|v| v * scale).collect();
        let ext = refined.operator.unknowns().clone();
        let full = refined.operator.expand(&solved, y[dim] * hz).ok()?;
        full.iter()
            .all(|v| v.is_finite())
            .then(|| relative_changes(&amplitudes(self.problem, &ext, &full), base))
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The truncation estimate of the point `x` at `omega` on the wider set (4H + 3): at the
    /// fixed frequency, and across the path when the path's `normal` (run unknowns, then ω) is
    /// given and the bordered matrix factorises; None when the estimate cannot be formed.
    /// `across` says which of the two the point reports: only that step's contraction is
    /// evaluated (one residual at the stepped point), the other's is NaN.
    pub(super) fn wider_truncation(
        &mut self,
        x: &[f64],
        omega: f64,
        normal: Option<&[f64]>,
        base: &[f64],
        across: bool,
    ) -> Option<Wider> {
        let n = self.problem.model.n_dofs();
        let row = normal.and_then(|normal| self.row_on(&self.wider, normal));
        let wider = &mut self.wider;
        let xr = wider.padded(n, x);
        let dim = xr.len();
        let mut r = vec![0.0; dim];
        let mut dr = vec![0.0; dim];
        wider
            .operator
            .residual_and_jacobian(&xr, omega, &mut r, &mut wider.jacobian, &mut dr)
            .ok()?;
        let ext = wider.operator.unknowns().clone();
        let problem = self.problem;
        let r_norm = crate::numerics::linalg::norm(&r);
        let padded_converged = solves_padded(problem, &wider.operator, r_norm);
        // The change of each output and, for the step the point reports, the step's
        // contraction ([`LinearRange`]).
        let change = |w: &mut Refined, delta: &[f64], d_omega: f64, reported: bool| {
            let contraction = reported
                .then(|| w.after_step(&xr, delta, omega - d_omega))
                .flatten()
                .map_or(f64::NAN, |(_, after)| after / r_norm);
            w.stepped(&xr, delta, omega - d_omega).map(|full| {
                (
                    relative_changes(&amplitudes(problem, &ext, &full), base),
                    contraction,
                )
            })
        };
        if let Some(row) = row {
            let ones = vec![1.0; dim];
            if let Ok(factor) = wider.jacobian.factor_bordered(&ones, &dr, &row) {
                let mut b = r.clone();
                b.push(0.0);
                let mut along = vec![0.0; dim];
                along.push(1.0);
                if let (Ok(step), Ok(z)) = (factor.solve(&b), factor.solve(&along)) {
                    let (d_omega, z_omega) = (step[dim], z[dim]);
                    let s = d_omega / z_omega;
                    let fixed: Vec<f64> = step.iter().zip(&z).map(|(a, b)| a - s * b).collect();
                    let across_change = change(wider, &step[..dim], d_omega, across);
                    let fixed_change = change(wider, &fixed[..dim], fixed[dim], !across);
                    if let (Some(f), Some(a)) = (fixed_change, across_change) {
                        return Some(Wider {
                            padded_converged,
                            fixed: f.0,
                            fixed_contraction: f.1,
                            across: Some(a),
                            fixed_step: fixed[..dim].to_vec(),
                            across_step: Some(step),
                        });
                    }
                }
            }
        }
        let step = wider.jacobian.solve_many(&[&r]).ok()?.pop()?;
        // Only reported where the point reports the fixed-frequency step.
        change(wider, &step, 0.0, !across).map(|f| Wider {
            padded_converged,
            fixed: f.0,
            fixed_contraction: f.1,
            across: None,
            fixed_step: step.clone(),
            across_step: None,
        })
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The converged solution of the extended system (the wider one when `wider`) at the
    /// fixed ω (rad/s), by Newton from the point `x` padded with zeros, as the relative change
    /// of each output's amplitude from `base`; None when Newton does not converge. What the
    /// one Newton step of [`Self::estimate`] approximates, for the points where that step
    /// leaves its linear range ([`LinearRange`]).
    ///
    /// `step` is that Newton step at the fixed frequency on the same set (its unknowns), and
    /// `contraction` the residual after it relative to the residual before it. Where the step
    /// lowers the residual (contraction below 1), Newton from the padded point would take it
    /// in full as its first iteration (same Jacobian, full step accepted by the line search),
    /// so the solve starts from the stepped point instead: the same iterates, one Jacobian and
    /// factorisation fewer. Other starts that were measured change the solution some points
    /// converge to (docs/accuracy.md, "What the estimate costs").
    pub(super) fn converged_truncation(
        &mut self,
        x: &[f64],
        omega: f64,
        wider: bool,
        base: &[f64],
        (step, contraction): (&[f64], f64),
    ) -> Option<Vec<f64>> {
        let n = self.problem.model.n_dofs();
        let refined = if wider {
            &mut self.wider
        } else {
            &mut self.truncation
        };
        let xr = refined.padded(n, x);
        // The step tolerance is relative to the point's largest coefficient.
        let scale = xr.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
        let start: Vec<f64> = if contraction < 1.0 && step.len() == xr.len() {
            xr.iter().zip(step).map(|(a, d)| a - d).collect()
        } else {
            xr.clone()
        };
        let newton = extended_newton(self.problem, vec![scale; xr.len()], 1);
        let solved = newton
            .solve_fixed(&mut refined.operator, &start, omega)
            .ok()?;
        let ext = refined.operator.unknowns().clone();
        let full = refined.operator.expand(&solved.x, omega).ok()?;
        full.iter()
            .all(|v| v.is_finite())
            .then(|| relative_changes(&amplitudes(self.problem, &ext, &full), base))
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The bordered Newton steps (δx, δω) of `[[J, ∂R/∂ω], [row]]` (δx, δω) = (r, 0) for each
    /// residual r of `rhs`, with one factorisation (the Jacobian last evaluated by the
    /// truncation operator, `dr` its ∂R/∂ω).
    /// The last right-hand side takes 1 in the border row instead of 0: its solution is the
    /// path's direction.
    pub(super) fn bordered_steps(
        &mut self,
        dr: &[f64],
        row: &[f64],
        rhs: &[&[f64]],
    ) -> Result<Vec<Vec<f64>>, LinearSolveError> {
        let ones = vec![1.0; dr.len()];
        let factor = self.truncation.jacobian.factor_bordered(&ones, dr, row)?;
        let last = rhs.len() - 1;
        rhs.iter()
            .enumerate()
            .map(|(k, r)| {
                let mut b = r.to_vec();
                b.push(if k == last { 1.0 } else { 0.0 });
                let step = factor.solve(&b)?;
                if step.iter().all(|v| v.is_finite()) {
                    Ok(step)
                } else {
                    Err(LinearSolveError::NonFinite)
                }
            })
            .collect()
    }
}
