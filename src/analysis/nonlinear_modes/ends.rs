//! The ends of a nonlinear mode's path at the amplitudes asked: the point whose first-harmonic
//! amplitude at the mode's DOF is a given value, by Newton on the EPMC system bordered with
//! that amplitude as an extra equation and the modal amplitude as an extra unknown.
//!
//! The continuation runs in the modal amplitude a (the normalisation keeps the first harmonic
//! of ψ at unit mass norm, [`super::operator`]), while the range is asked as the first-harmonic
//! amplitude A at a DOF (m). A = a |ψ₁(d)| with |ψ₁(d)| = √(ψ_c1(d)² + ψ_s1(d)²), which follows
//! the mode's shape as the contacts slip and lift off: converted with the linear shape at rest,
//! a = A / |φ_d| lands elsewhere once the shape has changed. The ends are solved instead on
//!
//! ```text
//! R̃(ψ, ω, ξ; λ) = 0,     g = s · (ln(a(λ) |ψ₁(d)|) − ln A*) = 0
//! ```
//!
//! for (ψ, ω, ξ, λ), λ the continuation's parameter (the decade of a, [`LogAmplitude`]), with
//! the normalisation and the phase condition of the operator kept, and s the operator's row
//! weight (its residual scale), so that Newton's tolerance on the residual holds ln A to the
//! run's relative tolerance.

use super::operator::{EpmcOperator, LogAmplitude};
use crate::hbm::HbmError;
use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::path::{NewtonFailure, PathPoint};
use crate::numerics::{Continuation, ParametricResidual};

/// The EPMC system bordered with the amplitude at a DOF (module docs): unknowns (ψ, ω, ξ, λ),
/// its own parameter unused.
pub(super) struct AtDofAmplitude<'o, 'p> {
    op: &'o mut EpmcOperator<'p>,
    dof: usize,
    /// ln A* (A* in m).
    log_target: f64,
    jac: AssembledJacobian,
    dr: Vec<f64>,
    r: Vec<f64>,
}

impl<'o, 'p> AtDofAmplitude<'o, 'p> {
    /// The bordered system of `op` with the first-harmonic amplitude at `dof` fixed at
    /// `target` (m, > 0).
    pub(super) fn new(op: &'o mut EpmcOperator<'p>, dof: usize, target: f64) -> Self {
        let jac = op.new_jacobian();
        let dim = op.dim();
        Self {
            op,
            dof,
            log_target: target.ln(),
            jac,
            dr: vec![0.0; dim],
            r: vec![0.0; dim],
        }
    }

    /// The first-harmonic cosine and sine of ψ at the DOF.
    fn first_at_dof(&self, z: &[f64]) -> (f64, f64) {
        let (cos1, sin1) = self.op.first_harmonic();
        let n = self.op.problem().model.n_dofs();
        (z[cos1 * n + self.dof], z[sin1 * n + self.dof])
    }

    /// The extra row g (module docs).
    fn amplitude_row(&self, z: &[f64]) -> f64 {
        let lambda = z[self.op.dim()];
        let (c, s) = self.first_at_dof(z);
        let a = self.op.map().amplitude(lambda);
        self.op.residual_scale() * ((a * c.hypot(s)).ln() - self.log_target)
    }
}

impl ParametricResidual for AtDofAmplitude<'_, '_> {
    type Error = HbmError;

    fn dim(&self) -> usize {
        self.op.dim() + 1
    }

    fn residual_scale(&self) -> f64 {
        self.op.residual_scale()
    }

    fn round_off(&mut self, z: &[f64], _lambda: f64) -> f64 {
        let d = self.op.dim();
        self.op.round_off(&z[..d], z[d])
    }

    fn residual(&mut self, z: &[f64], _lambda: f64, r: &mut [f64]) -> Result<(), HbmError> {
        let d = self.op.dim();
        self.op.residual(&z[..d], z[d], &mut r[..d])?;
        r[d] = self.amplitude_row(z);
        Ok(())
    }

    fn new_jacobian(&mut self) -> AssembledJacobian {
        AssembledJacobian::dense(self.dim())
    }

    /// The operator's Jacobian and its ∂/∂λ as the last column; the last row
    /// ∂g/∂ψ_c1(d) = s ψ_c1(d) / |ψ₁(d)|², likewise for the sine, and ∂g/∂λ = s ln 10 / 2π.
    fn residual_and_jacobian(
        &mut self,
        z: &[f64],
        _lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), HbmError> {
        let d = self.op.dim();
        self.op
            .residual_and_jacobian(&z[..d], z[d], &mut self.r, &mut self.jac, &mut self.dr)?;
        r[..d].copy_from_slice(&self.r);
        r[d] = self.amplitude_row(z);
        jac.clear();
        for (i, j, v) in self.jac.triplets() {
            let slot = jac.slot(i, j);
            jac.add_at(slot, v);
        }
        for (i, v) in self.dr.iter().enumerate() {
            let slot = jac.slot(i, d);
            jac.add_at(slot, *v);
        }
        let s = self.op.residual_scale();
        let (cos1, sin1) = self.op.first_harmonic();
        let n = self.op.problem().model.n_dofs();
        let (c, sn) = self.first_at_dof(z);
        let square = (c * c + sn * sn).max(f64::MIN_POSITIVE);
        for (block, v) in [(cos1, c), (sin1, sn)] {
            let slot = jac.slot(d, block * n + self.dof);
            jac.add_at(slot, s * v / square);
        }
        let slot = jac.slot(d, d);
        jac.add_at(slot, s * LogAmplitude::log_derivative());
        dr_dlambda.iter_mut().for_each(|v| *v = 0.0);
        Ok(())
    }
}

/// The point of the mode whose first-harmonic amplitude at `dof` is `target` (m): Newton on
/// the bordered system (module docs) from `guess` = (ψ, ω, ξ, λ), with the driver `newton`
/// (its scale per unknown of the operator, λ scaled by a decade). Returns the point with λ in
/// its `omega` field and (ψ, ω, ξ) in `x`, as the continuation gives its points; the operator
/// is left evaluated at it.
pub(super) fn solve_at_dof_amplitude(
    op: &mut EpmcOperator<'_>,
    newton: &Continuation,
    (dof, target): (usize, f64),
    guess: &[f64],
) -> Result<PathPoint, NewtonFailure> {
    let d = op.dim();
    let mut scale = newton.x_scale.clone();
    scale.push(std::f64::consts::TAU);
    let driver = Continuation::new(newton.settings, scale);
    let mut system = AtDofAmplitude::new(op, dof, target);
    let solved = driver.solve_fixed(&mut system, guess, 0.0)?;
    Ok(PathPoint {
        omega: solved.x[d],
        x: solved.x[..d].to_vec(),
        iterations: solved.iterations,
        residual: solved.residual,
        step: 0.0,
    })
}
