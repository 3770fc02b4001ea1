//! Broyden's secant updates of a factorised Newton matrix, for the chord steps of the
//! continuation corrector ([`crate::numerics::continuation`]).

use crate::numerics::linalg::{dot, norm};

/// Broyden's ("good") updates of a factorised bordered Newton matrix B₀ over the chord steps
/// of one corrector, in inverse product form: H_k = (I + a_{k−1} s_{k−1}ᵀ) ⋯ (I + a₀ s₀ᵀ) B₀⁻¹
/// with s_j the steps taken. Each step needs one solve with B₀ (the same as a plain chord
/// step) and O(n·k) vector work; the secant updates follow the change of the contact
/// Jacobian along the iterates, so the residual falls faster than with B₀ alone.
/// With p = −H_k G(y_{k+1}) and d_k the previous direction, H_k (G_{k+1} − G_k) = d_k − p,
/// so a_k = (s_k − d_k + p) / (s_kᵀ(d_k − p)) and the next direction is p + a_k (s_kᵀ p).
#[derive(Default)]
pub struct BroydenUpdates {
    /// (a_j, s_j), oldest first.
    pairs: Vec<(Vec<f64>, Vec<f64>)>,
    /// The last direction d_k and the step s_k = α d_k taken along it (None before the step).
    last: Option<(Vec<f64>, Option<Vec<f64>>)>,
}

impl BroydenUpdates {
    /// Forgets the updates (a new base factorisation or border).
    pub fn clear(&mut self) {
        self.pairs.clear();
        self.last = None;
    }

    /// A new base factorisation whose first direction is `d`.
    pub fn restart(&mut self, d: &[f64]) {
        self.pairs.clear();
        self.last = Some((d.to_vec(), None));
    }

    /// The step along the last direction was taken with length α (α = 0: not taken).
    pub fn stepped(&mut self, alpha: f64) {
        if alpha == 0.0 {
            self.clear();
        } else if let Some((d, step)) = &mut self.last {
            *step = Some(d.iter().map(|v| alpha * v).collect());
        }
    }

    /// The next direction from p = −B₀⁻¹ G(y) at the new iterate.
    pub fn direction(&mut self, mut p: Vec<f64>) -> Vec<f64> {
        for (a, s) in &self.pairs {
            let c = dot(s, &p);
            p.iter_mut().zip(a).for_each(|(v, ai)| *v += ai * c);
        }
        if let Some((d, Some(s))) = self.last.take() {
            let hy: Vec<f64> = d.iter().zip(&p).map(|(di, pi)| di - pi).collect();
            let denominator = dot(s.as_slice(), &hy);
            if denominator.abs() > 1e-12 * norm(&s) * norm(&hy) && denominator.is_finite() {
                let a: Vec<f64> = s
                    .iter()
                    .zip(&hy)
                    .map(|(si, hi)| (si - hi) / denominator)
                    .collect();
                let c = dot(&s, &p);
                p.iter_mut().zip(&a).for_each(|(v, ai)| *v += ai * c);
                self.pairs.push((a, s));
            }
        }
        self.last = Some((p.clone(), None));
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::linalg::norm;
    use faer::prelude::Solve;
    use faer::Mat;

    /// On a linear system G(y) = A y − b with a wrong base matrix B₀, Broyden's updates reach
    /// the solution in at most 2n steps (Gay's theorem), where the plain chord iteration with
    /// B₀ is still far off.
    #[test]
    fn broyden_updates_solve_a_linear_system_with_a_wrong_base_matrix() {
        let n = 4;
        let a = Mat::from_fn(n, n, |i, j| {
            [
                [4.0, 1.0, 0.5, 0.0],
                [0.3, 3.0, -1.0, 0.2],
                [0.0, 1.2, 5.0, 1.0],
                [0.7, 0.0, -0.4, 2.0],
            ][i][j]
        });
        let b0 = Mat::from_fn(n, n, |i, j| if i == j { 1.6 * a[(i, i)] } else { 0.0 });
        let lu = b0.partial_piv_lu();
        let rhs = [1.0, -2.0, 0.5, 3.0];
        let residual = |y: &[f64]| -> Vec<f64> {
            (0..n)
                .map(|i| (0..n).map(|j| a[(i, j)] * y[j]).sum::<f64>() - rhs[i])
                .collect()
        };
        let base_step = |g: &[f64]| -> Vec<f64> {
            let x = lu.solve(Mat::from_fn(n, 1, |i, _| -g[i]));
            (0..n).map(|i| x[(i, 0)]).collect()
        };
        let run = |broyden: bool| -> f64 {
            let mut y = vec![0.0; n];
            let mut updates = BroydenUpdates::default();
            let mut d = base_step(&residual(&y));
            updates.restart(&d);
            for _ in 0..2 * n {
                y.iter_mut().zip(&d).for_each(|(v, s)| *v += s);
                updates.stepped(1.0);
                let p = base_step(&residual(&y));
                d = if broyden { updates.direction(p) } else { p };
            }
            norm(&residual(&y))
        };
        let (with, without) = (run(true), run(false));
        assert!(with < 1e-10, "Broyden residual {with:e}");
        assert!(without > 1e-3, "chord residual {without:e}");
    }
}
