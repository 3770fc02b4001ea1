//! Finite-difference Jacobians of the harmonic-balance operator: the whole ∂R/∂x by forward
//! or central differences, or only the contact blocks of the schur storage, a checked
//! alternative to the analytic contact Jacobian for comparisons and benchmarks.

use super::HbmSystem;
use crate::hbm::error::HbmError;
use crate::model::JacobianStrategy;
use crate::numerics::derivatives::finite_difference_jacobian;
use crate::numerics::jacobian::AssembledJacobian;

impl HbmSystem<'_> {
    /// The contact blocks of the schur storage by forward or central differences of each
    /// contact's AFT with respect to its own relative-coordinate coefficients (û, v̂ on every
    /// unknown block; û₁, û₂, v̂ for a 2D point): k·blocks (forward) or 2k·blocks (central)
    /// contact evaluations per contact of k coordinates, the linear part being exact. Steps as
    /// in [`finite_difference_jacobian`], relative to |coefficient| or, when smaller, the RMS
    /// of x.
    pub(super) fn contact_difference_blocks(
        &mut self,
        x: &[f64],
        central: bool,
        jac: &mut AssembledJacobian,
    ) -> Result<(), HbmError> {
        let nb = self.block_map.len();
        let dim = x.len().max(1);
        let typical = (x.iter().map(|v| v * v).sum::<f64>() / dim as f64).sqrt();
        let eps = if central { 6e-6 } else { 1.5e-8 };
        let problem = self.problem;
        let slots = self
            .layout()
            .contacts
            .iter()
            .map(|c| c.slots.clone())
            .collect::<Vec<_>>();
        for c in 0..problem.contacts.len() {
            self.contact_coefficients(c, x);
            // The coordinates' coefficients in force order: û (, û₂), v̂.
            let coordinates: Vec<Vec<f64>> = if problem.contacts[c].second_tangent.is_some() {
                vec![
                    self.u_coef.clone(),
                    self.u2_coef.clone(),
                    self.v_coef.clone(),
                ]
            } else {
                vec![self.u_coef.clone(), self.v_coef.clone()]
            };
            let k = coordinates.len();
            let base = self.contact_force_coefficients(c, &coordinates)?;
            for (i, &if_) in self.block_map.clone().iter().enumerate() {
                for b in 0..k {
                    let value = coordinates[b][if_];
                    let step = eps * value.abs().max(typical).max(1e-12);
                    let perturbed = |sign: f64| {
                        let mut shifted = coordinates.clone();
                        shifted[b][if_] += sign * step;
                        shifted
                    };
                    let plus = self.contact_force_coefficients(c, &perturbed(1.0))?;
                    let minus = if central {
                        Some(self.contact_force_coefficients(c, &perturbed(-1.0))?)
                    } else {
                        None
                    };
                    for (j, &jf) in self.block_map.iter().enumerate() {
                        for a in 0..k {
                            let d = match &minus {
                                Some(m) => (plus[a][jf] - m[a][jf]) / (2.0 * step),
                                None => (plus[a][jf] - base[a][jf]) / step,
                            };
                            jac.add_at(slots[c][((j * nb + i) * k + a) * k + b], d);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The force coefficients (AFT blocks) of contact `c` at given coordinate coefficients in
    /// force order: [T̂, N̂] from [û, v̂] for a 1D point, [T̂₁, T̂₂, N̂] from [û₁, û₂, v̂] for a 2D
    /// point (v̂ including the gap). Overwrites the coefficient buffers of
    /// [`Self::contact_coefficients`].
    fn contact_force_coefficients(
        &mut self,
        c: usize,
        coordinates: &[Vec<f64>],
    ) -> Result<Vec<Vec<f64>>, HbmError> {
        let (normal, tangential) = coordinates
            .split_last()
            .expect("a normal and at least one tangential coordinate");
        self.u_coef.copy_from_slice(&tangential[0]);
        match tangential.get(1) {
            Some(second) => self.u2_coef.copy_from_slice(second),
            None => self.u2_coef.iter_mut().for_each(|v| *v = 0.0),
        }
        self.v_coef.copy_from_slice(normal);
        self.march_contact(c, false)?;
        Ok(
            match (
                &self.aft2d,
                self.problem.contacts[c].second_tangent.is_some(),
            ) {
                (Some(aft), true) => vec![
                    aft.t_hat[0].clone(),
                    aft.t_hat[1].clone(),
                    aft.n_hat.clone(),
                ],
                _ => vec![self.aft.t_hat.clone(), self.aft.n_hat.clone()],
            },
        )
    }

    /// ∂R/∂x by forward or central differences (the strategy decides), given R at x.
    pub(super) fn finite_difference_jacobian(
        &mut self,
        x: &[f64],
        omega: f64,
        r0: &[f64],
        jac: &mut AssembledJacobian,
    ) -> Result<(), HbmError> {
        let central = self.strategy == JacobianStrategy::CentralDifference;
        finite_difference_jacobian(|x, r| self.residual(x, omega, r), x, r0, central, jac)
    }
}
