//! The analytic Jacobian of the force harmonics through the periodic steady state: the march's
//! derivatives accumulated per sample, with the initial condition's and history's terms.

use super::march::{step_derivative, StartOrigin};
use super::settle::{pseudo_inverse, FIXED_POINT_CONDITION};
use super::workspace::Aft2dWorkspace;
use crate::contact::point::Jenkins2dLaw;
use crate::contact::{ContactEffects, NormalLoad};

impl Aft2dWorkspace {
    /// Assembles ∂T̂/∂x and ∂N̂/∂v̂ along the final period (see the module doc).
    pub(super) fn accumulate_jacobian(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        origin: StartOrigin,
    ) {
        let nb = self.set.n_blocks();
        let ns = self.n_samples;
        let w_columns = 3 * nb;
        let columns = w_columns + 2;
        // The start's own derivative when it does not come from the fixed-point equation.
        let history_start = match origin {
            StartOrigin::InitialCondition => Some(self.initial_condition_derivative(law, effects)),
            StartOrigin::History { periods } => {
                Some(self.history_derivative(law, effects, periods))
            }
            StartOrigin::FixedPoint | StartOrigin::DegenerateFixedPoint => None,
        };
        let mut d = std::mem::take(&mut self.slider_derivative);
        let mut g = std::mem::take(&mut self.force_derivative);
        d.iter_mut().for_each(|x| *x = 0.0);
        g.iter_mut().for_each(|x| *x = 0.0);
        d[w_columns] = 1.0;
        d[columns + w_columns + 1] = 1.0;
        self.dn_dv.iter_mut().for_each(|x| *x = 0.0);
        let mut dn = vec![0.0; nb];
        let mut dt = vec![0.0; 2 * columns];
        for k in 0..ns {
            self.normal_row(law, effects, k, &mut dn);
            // ∂N̂/∂v̂ += P_k ⊗ dN_k.
            for j in 0..nb {
                let pj = self.basis.projection[j * ns + k];
                if pj != 0.0 {
                    for (o, x) in self.dn_dv[j * nb..(j + 1) * nb].iter_mut().zip(&dn) {
                        *o += pj * x;
                    }
                }
            }
            step_derivative(
                self.kinds[k],
                self.basis.row(k),
                &dn,
                law,
                nb,
                &mut d,
                &mut dt,
            );
            // Σ P_k ⊗ dT_k.
            for a in 0..2 {
                for j in 0..nb {
                    let pj = self.basis.projection[j * ns + k];
                    if pj == 0.0 {
                        continue;
                    }
                    let out = &mut g[(a * nb + j) * columns..(a * nb + j + 1) * columns];
                    for (o, x) in out.iter_mut().zip(&dt[a * columns..(a + 1) * columns]) {
                        *o += pj * x;
                    }
                }
            }
        }

        // dw_start as a 2 × 3nb matrix.
        let start = history_start.unwrap_or_else(|| {
            // The periodic start solves (I − A) dw_start = B (in the least-squares sense,
            // without the singular direction, at a degenerate fixed point).
            let a = [
                d[w_columns],
                d[w_columns + 1],
                d[columns + w_columns],
                d[columns + w_columns + 1],
            ];
            let m = [1.0 - a[0], -a[1], -a[2], 1.0 - a[3]];
            let inv = if origin == StartOrigin::DegenerateFixedPoint {
                pseudo_inverse(m, FIXED_POINT_CONDITION)
            } else {
                let det = m[0] * m[3] - m[1] * m[2];
                [m[3] / det, -m[1] / det, -m[2] / det, m[0] / det]
            };
            let mut start = vec![0.0; 2 * w_columns];
            for c in 0..w_columns {
                let b0 = d[c];
                let b1 = d[columns + c];
                start[c] = inv[0] * b0 + inv[1] * b1;
                start[w_columns + c] = inv[2] * b0 + inv[3] * b1;
            }
            start
        });
        // dT̂/dx = G_x + G_w · dw_start.
        for r in 0..2 * nb {
            let grow = &g[r * columns..(r + 1) * columns];
            let out = &mut self.dt_dx[r * w_columns..(r + 1) * w_columns];
            for c in 0..w_columns {
                out[c] = grow[c]
                    + grow[w_columns] * start[c]
                    + grow[w_columns + 1] * start[w_columns + c];
            }
        }
        self.slider_derivative = d;
        self.force_derivative = g;
    }

    /// dN_k as a row over the v̂ coefficients (zero where the normal spring is inactive).
    fn normal_row(&self, law: &Jenkins2dLaw, effects: ContactEffects, k: usize, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        if !self.normal_active[k] {
            return;
        }
        match effects.normal_load {
            NormalLoad::Variable => {
                for (o, e) in out.iter_mut().zip(self.basis.row(k)) {
                    *o = law.kn * e;
                }
            }
            NormalLoad::Constant => {
                if let Some(c) = self.set.constant_block() {
                    out[c] = law.kn;
                }
            }
        }
    }

    /// Derivative (2 × 3 n_blocks) of the initial slider w = u₀ − μ N₀ m / kₜ.
    fn initial_condition_derivative(
        &self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
    ) -> Vec<f64> {
        let nb = self.set.n_blocks();
        let w_columns = 3 * nb;
        let mut dn = vec![0.0; nb];
        self.normal_row(law, effects, 0, &mut dn);
        let mut start = vec![0.0; 2 * w_columns];
        for a in 0..2 {
            for (i, ei) in self.basis.row(0).iter().enumerate() {
                start[a * w_columns + a * nb + i] = *ei;
            }
            for (i, x) in dn.iter().enumerate() {
                start[a * w_columns + 2 * nb + i] -= law.mu * law.initial_state[a] * x / law.kt;
            }
        }
        start
    }

    /// Derivative (2 × 3 n_blocks) of the start of period `periods`, reached by plain periods
    /// from the initial condition: the march is repeated with the derivative carried along,
    /// then the final period is marched again so that the sample kinds are its own.
    fn history_derivative(
        &mut self,
        law: &Jenkins2dLaw,
        effects: ContactEffects,
        periods: usize,
    ) -> Vec<f64> {
        let nb = self.set.n_blocks();
        let mut d = self.initial_condition_derivative(law, effects);
        let mut dt = vec![0.0; d.len()];
        let mut dn = vec![0.0; nb];
        let mut start = self.initial_slider;
        for period in 1..periods {
            let outcome = self.march_period(law, start, period == 1, self.march_scale);
            for k in 0..self.n_samples {
                self.normal_row(law, effects, k, &mut dn);
                step_derivative(
                    self.kinds[k],
                    self.basis.row(k),
                    &dn,
                    law,
                    nb,
                    &mut d,
                    &mut dt,
                );
            }
            start = outcome.slider_end;
        }
        self.march_period(law, start, periods == 1, self.march_scale);
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::contact::aft2d::fixtures::{
        barely_slipping_point, check_jacobian, coefficients, jacobian_mismatch, KN, KT, MU,
    };
    use crate::contact::harmonic::HarmonicSet;

    #[test]
    fn jacobian_matches_central_differences_in_every_regime() {
        let set = HarmonicSet::up_to(3);
        let c = |e: &[(usize, f64)]| coefficients(&set, e);
        let variable = ContactEffects::default();
        let constant = ContactEffects {
            normal_load: NormalLoad::Constant,
            liftoff: true,
        };
        let stick_limit = MU * KN * 1e-4 / KT; // μN/kₜ at v₀ = 1e-4 m: 6e-5 m
                                               // Stuck: a small ellipse.
        check_jacobian(
            variable,
            [0.3, -0.2],
            [
                &c(&[(1, 0.2 * stick_limit)]),
                &c(&[(2, 0.1 * stick_limit), (3, 0.05 * stick_limit)]),
                &c(&[(0, 1e-4), (1, 1e-5)]),
            ],
            "stuck",
        );
        // Full slip with a rotating direction: a large circle, constant N.
        check_jacobian(
            constant,
            [0.0, 0.0],
            [
                &c(&[(1, 3.0 * stick_limit)]),
                &c(&[(2, 3.0 * stick_limit)]),
                &c(&[(0, 1e-4)]),
            ],
            "rotating slip",
        );
        // Stick-slip on an ellipse with a variable normal load and higher harmonics.
        check_jacobian(
            variable,
            [0.5, 0.5],
            [
                &c(&[(1, 1.5 * stick_limit), (4, 0.2 * stick_limit)]),
                &c(&[(2, 0.7 * stick_limit), (1, 0.3 * stick_limit)]),
                &c(&[(0, 1e-4), (1, 3e-5), (2, -2e-5)]),
            ],
            "stick-slip",
        );
        // Lift-off over part of the period.
        check_jacobian(
            variable,
            [-1.0, 0.0],
            [
                &c(&[(1, 1.2 * stick_limit)]),
                &c(&[(1, 0.5 * stick_limit), (2, 0.8 * stick_limit)]),
                &c(&[(0, 3e-5), (1, 6e-5), (3, 1e-5)]),
            ],
            "lift-off",
        );
        // Grazing: the ellipse just reaches the friction circle.
        check_jacobian(
            constant,
            [0.0, 0.0],
            [
                &c(&[(1, 1.05 * stick_limit)]),
                &c(&[(2, 0.3 * stick_limit)]),
                &c(&[(0, 1e-4)]),
            ],
            "grazing",
        );
    }

    /// At the nearly one-directional, barely slipping point the forces' Jacobian, through the
    /// ill-conditioned fixed-point derivative (I − A)⁻¹ B, matches central differences.
    #[test]
    fn the_jacobian_of_a_nearly_one_directional_slip_matches_central_differences() {
        let ([u1, u2, v], _) = barely_slipping_point();
        // Steps of 10⁻⁸ of the largest coefficient: the fixed point moves far (relative to the
        // step) for a small change of the path, so larger steps see its curvature.
        let worst = jacobian_mismatch(
            ContactEffects::default(),
            [0.0, 1.0],
            [&u1, &u2, &v],
            "barely slipping",
            1e-8,
        );
        assert!(worst < 1e-5, "{worst:.2e}");
    }
}
