//! Finite-difference Jacobians of any residual, and the check of an operator's own Jacobian
//! against central differences (the derivative checks of the validation ladder).

use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::residual::ParametricResidual;

/// ∂R/∂x of any residual by forward (one evaluation per unknown) or central (two) differences,
/// given R at x. Steps are relative to |xᵢ| or, when smaller, to the RMS of x.
pub fn finite_difference_jacobian<E>(
    mut residual: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    x: &[f64],
    r0: &[f64],
    central: bool,
    jac: &mut AssembledJacobian,
) -> Result<(), E> {
    let dim = x.len();
    let mut xp = x.to_vec();
    let mut rp = vec![0.0; dim];
    let mut rm = vec![0.0; if central { dim } else { 0 }];
    let mut column = vec![0.0; dim];
    let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim.max(1) as f64).sqrt();
    let eps = if central { 6e-6 } else { 1.5e-8 };
    jac.clear();
    for i in 0..dim {
        let step = eps * x[i].abs().max(typical).max(1e-12);
        xp[i] = x[i] + step;
        residual(&xp, &mut rp)?;
        if central {
            xp[i] = x[i] - step;
            residual(&xp, &mut rm)?;
            for k in 0..dim {
                column[k] = (rp[k] - rm[k]) / (2.0 * step);
            }
        } else {
            for k in 0..dim {
                column[k] = (rp[k] - r0[k]) / step;
            }
        }
        jac.set_column(i, &column);
        xp[i] = x[i];
    }
    Ok(())
}

/// Comparison of the analytic Jacobian with central differences at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobianCheck {
    /// Largest |analytic − central difference| over ∂R/∂x and ∂R/∂ω (scaled per column).
    pub max_error: f64,
    /// Largest |entry| of the analytic Jacobian (same scaling).
    pub max_entry: f64,
}

impl JacobianCheck {
    /// max_error / max_entry.
    pub fn relative(&self) -> f64 {
        self.max_error / self.max_entry.max(f64::MIN_POSITIVE)
    }
}

/// Checks the Jacobian of any operator: compares the Jacobian the operator forms (whatever its
/// strategy and storage, entries outside a sparse pattern count as zero) with central
/// differences of its residual.
pub fn check_operator_jacobian<S: ParametricResidual>(
    system: &mut S,
    x: &[f64],
    omega: f64,
    rel_step: f64,
) -> Result<JacobianCheck, S::Error> {
    let dim = system.dim();
    let mut r = vec![0.0; dim];
    let mut jac = system.new_jacobian();
    let mut dw = vec![0.0; dim];
    let result = (|| {
        system.residual_and_jacobian(x, omega, &mut r, &mut jac, &mut dw)?;
        let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim as f64)
            .sqrt()
            .max(1e-12);
        let mut xp = x.to_vec();
        let (mut rp, mut rm) = (vec![0.0; dim], vec![0.0; dim]);
        let mut max_error = 0.0_f64;
        let mut max_entry = 0.0_f64;
        for i in 0..=dim {
            let (scale, step) = if i < dim {
                (typical, rel_step * typical)
            } else {
                (omega, rel_step * omega)
            };
            if i < dim {
                xp[i] = x[i] + step;
                system.residual(&xp, omega, &mut rp)?;
                xp[i] = x[i] - step;
                system.residual(&xp, omega, &mut rm)?;
                xp[i] = x[i];
            } else {
                system.residual(x, omega + step, &mut rp)?;
                system.residual(x, omega - step, &mut rm)?;
            }
            for k in 0..dim {
                let fd = (rp[k] - rm[k]) / (2.0 * step);
                let an = if i < dim { jac.get(k, i) } else { dw[k] };
                max_error = max_error.max((fd - an).abs() * scale);
                max_entry = max_entry.max(an.abs() * scale);
            }
        }
        Ok(JacobianCheck {
            max_error,
            max_entry,
        })
    })();
    result
}

/// How far an operator's own Jacobian is from forward and from central differences of its
/// residual (see [`compare_with_differences`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DifferenceComparison {
    /// Largest |J − forward difference| over the checked columns, over the largest |J|
    /// (entries scaled per column as in [`check_operator_jacobian`]).
    pub forward: f64,
    /// The same against central differences.
    pub central: f64,
    /// Columns compared (the last one is ∂R/∂λ).
    pub columns: usize,
}

/// Compares the Jacobian the operator forms at (x, λ) (∂R/∂x and ∂R/∂λ) with forward and with
/// central differences of its residual, on at most `max_columns` columns (evenly spaced, ∂R/∂λ
/// always among them). Steps are those of [`finite_difference_jacobian`]: 1.5·10⁻⁸ (forward) and
/// 6·10⁻⁶ (central) relative to |xᵢ| or, when larger, the RMS of x (λ: relative to |λ|).
/// Costs 3 residual evaluations per column.
pub fn compare_with_differences<S: ParametricResidual>(
    system: &mut S,
    x: &[f64],
    lambda: f64,
    max_columns: usize,
) -> Result<DifferenceComparison, S::Error> {
    let dim = system.dim();
    let mut r0 = vec![0.0; dim];
    let mut jac = system.new_jacobian();
    let mut dl = vec![0.0; dim];
    system.residual_and_jacobian(x, lambda, &mut r0, &mut jac, &mut dl)?;
    let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim.max(1) as f64).sqrt();
    let total = dim + 1;
    let wanted = max_columns.clamp(1, total);
    let mut columns: Vec<usize> = (0..wanted)
        .map(|k| {
            if wanted == 1 {
                dim
            } else {
                k * (total - 1) / (wanted - 1)
            }
        })
        .collect();
    columns.dedup();
    let mut xp = x.to_vec();
    let (mut rf, mut rp, mut rm) = (vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]);
    let (mut err_f, mut err_c, mut max_entry) = (0.0_f64, 0.0_f64, 0.0_f64);
    for &i in &columns {
        let scale = if i < dim {
            x[i].abs().max(typical).max(1e-12)
        } else {
            lambda.abs().max(1e-12)
        };
        let (hf, hc) = (1.5e-8 * scale, 6e-6 * scale);
        let mut eval = |shift: f64, out: &mut [f64]| -> Result<(), S::Error> {
            if i < dim {
                xp[i] = x[i] + shift;
                let r = system.residual(&xp, lambda, out);
                xp[i] = x[i];
                r
            } else {
                system.residual(x, lambda + shift, out)
            }
        };
        eval(hf, &mut rf)?;
        eval(hc, &mut rp)?;
        eval(-hc, &mut rm)?;
        for k in 0..dim {
            let an = if i < dim { jac.get(k, i) } else { dl[k] };
            let forward = (rf[k] - r0[k]) / hf;
            let central = (rp[k] - rm[k]) / (2.0 * hc);
            err_f = err_f.max((forward - an).abs() * scale);
            err_c = err_c.max((central - an).abs() * scale);
            max_entry = max_entry.max(an.abs() * scale);
        }
    }
    let denominator = max_entry.max(f64::MIN_POSITIVE);
    Ok(DifferenceComparison {
        forward: err_f / denominator,
        central: err_c / denominator,
        columns: columns.len(),
    })
}
