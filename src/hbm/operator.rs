//! The harmonic-balance operator a run solves: the full system (dense or sparse Jacobian) or
//! the system condensed on the contact DOFs, chosen by the problem's formulation.
//!
//! Whatever the formulation, callers see full coefficients (all DOFs, harmonic-major): the
//! operator restricts guesses to its unknowns and expands solutions back.

use crate::contact::harmonic::HarmonicSet;
use crate::contact::ContactState;
use crate::hbm::condensed::CondensedHbm;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::{Formulation, JacobianStrategy, Problem};
use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::work::{self, Work};
use crate::numerics::ParametricResidual;

/// Full or condensed harmonic balance.
pub enum HbmOperator<'p> {
    /// Unknowns on all DOFs.
    Full(Box<HbmSystem<'p>>),
    /// Unknowns on the contact DOFs.
    Condensed(Box<CondensedHbm<'p>>),
}

impl<'p> HbmOperator<'p> {
    /// The operator of the problem's formulation.
    pub fn new(problem: &'p Problem) -> Result<Self, HbmError> {
        Ok(match problem.formulation() {
            Formulation::Condensed => HbmOperator::Condensed(Box::new(CondensedHbm::new(problem)?)),
            _ => HbmOperator::Full(Box::new(HbmSystem::new(problem)?)),
        })
    }

    /// The full system (contact forces and time histories on full coefficients).
    pub fn full(&mut self) -> &mut HbmSystem<'p> {
        match self {
            HbmOperator::Full(s) => s,
            HbmOperator::Condensed(c) => c.full(),
        }
    }

    /// The full system, read-only.
    pub fn full_ref(&self) -> &HbmSystem<'p> {
        match self {
            HbmOperator::Full(s) => s,
            HbmOperator::Condensed(c) => c.full_ref(),
        }
    }

    /// Harmonic set of the unknowns.
    pub fn unknowns(&self) -> &HarmonicSet {
        self.full_ref().unknowns()
    }

    /// Contact states of the last evaluation.
    pub fn states(&self) -> &[ContactState] {
        &self.full_ref().states
    }

    /// The operator's unknowns from full coefficients.
    pub fn restrict(&self, x_full: &[f64]) -> Vec<f64> {
        match self {
            HbmOperator::Full(_) => x_full.to_vec(),
            HbmOperator::Condensed(c) => c.restrict(x_full),
        }
    }

    /// Full coefficients from the operator's unknowns at ω (rad/s).
    pub fn expand(&mut self, x: &[f64], omega: f64) -> Result<Vec<f64>, HbmError> {
        match self {
            HbmOperator::Full(_) => Ok(x.to_vec()),
            HbmOperator::Condensed(c) => c.expand(x, omega),
        }
    }

    fn strategy(&self) -> JacobianStrategy {
        self.full_ref().strategy
    }
}

impl ParametricResidual for HbmOperator<'_> {
    type Error = HbmError;

    fn dim(&self) -> usize {
        match self {
            HbmOperator::Full(s) => s.dim(),
            HbmOperator::Condensed(c) => c.dim(),
        }
    }

    fn residual_scale(&self) -> f64 {
        self.full_ref().load_norm()
    }

    fn round_off(&mut self, x: &[f64], lambda: f64) -> f64 {
        match self {
            HbmOperator::Full(s) => s.round_off(x, lambda),
            // The condensed residual is formed after the elimination: its round-off level is
            // not estimated (none is claimed).
            HbmOperator::Condensed(_) => 0.0,
        }
    }

    fn residual(&mut self, x: &[f64], lambda: f64, r: &mut [f64]) -> Result<(), HbmError> {
        let started = std::time::Instant::now();
        let out = match self {
            HbmOperator::Full(s) => s.residual(x, lambda, r),
            HbmOperator::Condensed(c) => c.residual(x, lambda, r),
        };
        work::record(Work::Evaluation, started);
        out
    }

    fn new_jacobian(&mut self) -> AssembledJacobian {
        match self {
            HbmOperator::Full(s) => s.new_jacobian(),
            HbmOperator::Condensed(c) => c.new_jacobian(),
        }
    }

    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), HbmError> {
        let started = std::time::Instant::now();
        let out = self.evaluate_with_jacobian(x, lambda, r, jac, dr_dlambda);
        work::record(Work::Evaluation, started);
        out
    }
}

impl HbmOperator<'_> {
    /// [`ParametricResidual::residual_and_jacobian`] without its timing.
    fn evaluate_with_jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), HbmError> {
        let strategy = self.strategy();
        match self {
            HbmOperator::Full(s) => s.residual_and_jacobian(x, lambda, r, jac, dr_dlambda),
            HbmOperator::Condensed(c) => {
                c.residual_and_jacobian(x, lambda, r, jac, dr_dlambda)?;
                if strategy != JacobianStrategy::Analytic {
                    let states = c.states().to_vec();
                    crate::numerics::derivatives::finite_difference_jacobian(
                        |x, r| c.residual(x, lambda, r),
                        x,
                        r,
                        strategy == JacobianStrategy::CentralDifference,
                        jac,
                    )?;
                    c.full().states = states;
                }
                Ok(())
            }
        }
    }
}
