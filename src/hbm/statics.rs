//! The static pre-solve of the uncoupled mode: the 0th harmonic fixed before the dynamic
//! harmonics are solved.

use crate::contact::harmonic::HarmonicSet;
use crate::hbm::error::HbmError;
use crate::hbm::pattern::JacobianLayout;
use crate::model::{Formulation, Problem};
use crate::numerics::jacobian::{AssembledJacobian, Storage};

/// Static pre-solve of the uncoupled mode: K q + F_c,static(q) = F_static, with each contact
/// loaded from rest (slider at zero): N = kₙ max(v, 0), T = clamp(kₜ u, −μN, μN). Newton with
/// backtracking, on the Jacobian storage of the problem's formulation.
pub fn static_solve(problem: &Problem) -> Result<Vec<f64>, HbmError> {
    if let Some(c) = problem.contacts.iter().find(|c| c.second_tangent.is_some()) {
        return Err(HbmError::TwoDimensionalFriction {
            contact: c.name.clone(),
            evaluation:
                "the static pre-solve of effects.coupling = \"uncoupled\" (use \"coupled\")",
        });
    }
    let n = problem.model.n_dofs();
    let k = &problem.model.stiffness;
    let f = &problem.static_load;
    let fnorm = f
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    // The static system has one block: dense unless the model is held sparse (the schur
    // formulation's elimination would not pay off on one block).
    let storage = if problem.formulation() == Formulation::Sparse {
        Storage::Sparse
    } else {
        Storage::Dense
    };
    let layout = JacobianLayout::new(problem, &HarmonicSet::new(vec![0]), storage);
    let residual_of = |q: &[f64], r: &mut [f64], jac: Option<&mut AssembledJacobian>| {
        for (p, v) in r.iter_mut().enumerate() {
            *v = -f[p];
        }
        k.mul_add(1.0, q, r);
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.clear();
            for &(slot, kv, _) in &layout.stiffness[0] {
                j.add_at(slot, kv);
            }
        }
        for (c, lc) in problem.contacts.iter().zip(&layout.contacts) {
            let law = &c.law;
            let u = c.tangential_of(q);
            let v = c.normal_of(q) - c.gap;
            let nf = (law.kn * v).max(0.0);
            let limit = law.mu * nf;
            let tp = law.kt * u;
            let t = tp.clamp(-limit, limit);
            for &(p, a) in &c.tangential {
                r[p] += a * t;
            }
            for &(p, a) in &c.normal {
                r[p] += a * nf;
            }
            if let Some(j) = jac.as_deref_mut() {
                if v >= 0.0 {
                    let d = lc.dofs;
                    for &(a, ap) in &lc.normal {
                        for &(b, aq) in &lc.normal {
                            j.add_at(lc.slots[a * d + b], ap * law.kn * aq);
                        }
                    }
                    for &(a, ap) in &lc.tangential {
                        if tp.abs() <= limit || limit == 0.0 {
                            for &(b, aq) in &lc.tangential {
                                j.add_at(lc.slots[a * d + b], ap * law.kt * aq);
                            }
                        } else {
                            for &(b, aq) in &lc.normal {
                                j.add_at(
                                    lc.slots[a * d + b],
                                    ap * tp.signum() * law.mu * law.kn * aq,
                                );
                            }
                        }
                    }
                }
            }
        }
    };
    let mut q = vec![0.0; n];
    let mut r = vec![0.0; n];
    let mut jac = layout.new_jacobian();
    let max_iterations = 100;
    let mut rel = f64::INFINITY;
    let mut trial = vec![0.0; n];
    let mut rt = vec![0.0; n];
    for _ in 0..max_iterations {
        residual_of(&q, &mut r, Some(&mut jac));
        rel = r.iter().map(|x| x * x).sum::<f64>().sqrt() / fnorm;
        if rel <= 1e-12 {
            return Ok(q);
        }
        let neg: Vec<f64> = r.iter().map(|x| -x).collect();
        let dq = jac.solve(&neg)?;
        // Backtracking on the residual norm keeps the non-smooth contact law from cycling.
        let mut alpha = 1.0;
        loop {
            for p in 0..n {
                trial[p] = q[p] + alpha * dq[p];
            }
            residual_of(&trial, &mut rt, None);
            let rel_t = rt.iter().map(|x| x * x).sum::<f64>().sqrt() / fnorm;
            if rel_t < rel || alpha < 1e-4 {
                break;
            }
            alpha *= 0.5;
        }
        q.copy_from_slice(&trial);
    }
    Err(HbmError::StaticNotConverged {
        iterations: max_iterations,
        residual: rel,
    })
}
