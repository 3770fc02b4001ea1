//! The operator continuation works on: R(x, λ) with its Jacobian ∂R/∂x and ∂R/∂λ.
//!
//! Newton and continuation ([`crate::numerics::continuation`]) know only this trait; the
//! harmonic balance implements it (`crate::hbm`), and so can any other residual.

use crate::numerics::jacobian::AssembledJacobian;

/// An operator R(x, λ) with its Jacobian, as continuation needs it.
pub trait ParametricResidual {
    /// Evaluation error of the operator.
    type Error: std::error::Error + Clone;
    /// Number of unknowns x.
    fn dim(&self) -> usize;
    /// Norm that makes residuals relative (e.g. the load norm).
    fn residual_scale(&self) -> f64;
    /// Round-off level of ‖R(x, λ)‖ (absolute, same norm as the residual): the size below
    /// which floating-point evaluation cannot bring the residual, because R sums terms much
    /// larger than itself that cancel (an FE body displaced as a whole by a gap: each row of
    /// K q sums entries of about 10¹¹ N/m times 10⁻⁴ m to nearly zero). Newton accepts a point
    /// whose residual is within a few times this level even where the relative tolerance asks
    /// for less ([`crate::numerics::continuation`]). The default, 0, claims no such level.
    fn round_off(&mut self, _x: &[f64], _lambda: f64) -> f64 {
        0.0
    }
    /// R(x, λ) into r.
    fn residual(&mut self, x: &[f64], lambda: f64, r: &mut [f64]) -> Result<(), Self::Error>;
    /// An empty Jacobian with the operator's storage and pattern.
    fn new_jacobian(&mut self) -> AssembledJacobian;
    /// R, ∂R/∂x and ∂R/∂λ.
    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), Self::Error>;
}
