//! The static pre-solve of the uncoupled mode: the 0th harmonic fixed before the dynamic
//! harmonics are solved.
//!
//! Every contact is loaded from rest, slider at zero, whatever its initial tangential state
//! (`law.initial_state` sets where the dynamic march starts, not the static load path): the
//! 1D law gives T = clamp(kₜu, −μN, μN), the 2D law (`jenkins-2d`) the radial return of the
//! elastic predictor onto the friction circle ([`static_point_2d`]). A 2D point whose motion
//! stays along t₁ gets exactly the 1D forces.

use crate::contact::harmonic::HarmonicSet;
use crate::contact::Jenkins2dLaw;
use crate::hbm::error::HbmError;
use crate::hbm::pattern::JacobianLayout;
use crate::model::{Formulation, Problem};
use crate::numerics::jacobian::{AssembledJacobian, Storage};

/// Static forces of a 2D-friction point loaded from rest, and their consistent tangent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticPoint2d {
    /// Tangential force (T₁, T₂) along t₁, t₂ (N).
    pub tangential: [f64; 2],
    /// Normal force N (N).
    pub normal: f64,
    /// ∂(T₁, T₂, N)/∂(u₁, u₂, v) (N/m), rows force, columns displacement.
    pub tangent: [[f64; 3]; 3],
}

/// The static 2D Jenkins law from rest (slider at zero), the 2D form of the paper's Eqs. (4-6)
/// without history: N = kₙ max(v, 0); elastic predictor T_pred = kₜ (u₁, u₂); T = T_pred when
/// |T_pred| ≤ μN (stuck), else the radial return T = μN · T_pred/|T_pred| (slipping).
///
/// `u` is (u₁, u₂) (m), `v` the normal approach with the gap removed (m, > 0 in contact).
/// Consistent tangent: stuck kₜ I₂ on the tangent plane; slipping (μN/|T_pred|) kₜ (I − t̂t̂ᵀ)
/// with t̂ = T_pred/|T_pred|, plus μkₙ t̂ on the normal column; open (v < 0) zero. The normal
/// row is kₙ where v ≥ 0. As in the 1D static law, a point exactly at v = 0 (μN = 0) takes the
/// stuck tangent kₜ I₂ (a Newton choice at a grazing point; the forces are zero there).
pub fn static_point_2d(law: &Jenkins2dLaw, u: [f64; 2], v: f64) -> StaticPoint2d {
    let mut out = StaticPoint2d {
        tangential: [0.0; 2],
        normal: 0.0,
        tangent: [[0.0; 3]; 3],
    };
    if v < 0.0 {
        return out;
    }
    let normal = law.kn * v;
    let limit = law.mu * normal;
    let predictor = [law.kt * u[0], law.kt * u[1]];
    let size = predictor[0].hypot(predictor[1]);
    out.normal = normal;
    out.tangent[2][2] = law.kn;
    if size <= limit || limit == 0.0 {
        out.tangential = if size <= limit { predictor } else { [0.0; 2] };
        out.tangent[0][0] = law.kt;
        out.tangent[1][1] = law.kt;
    } else {
        let direction = [predictor[0] / size, predictor[1] / size];
        let ratio = limit / size;
        for i in 0..2 {
            out.tangential[i] = limit * direction[i];
            for j in 0..2 {
                let identity = if i == j { 1.0 } else { 0.0 };
                out.tangent[i][j] = ratio * law.kt * (identity - direction[i] * direction[j]);
            }
            out.tangent[i][2] = law.mu * law.kn * direction[i];
        }
    }
    out
}

/// The static system K q + F_c,static(q) − F_static of the uncoupled mode and its Jacobian on
/// the problem's storage (dense, or sparse for the sparse formulation).
pub struct StaticSystem<'p> {
    problem: &'p Problem,
    layout: JacobianLayout,
}

impl<'p> StaticSystem<'p> {
    /// Slot tables of the one-block (0th harmonic) static Jacobian.
    pub fn new(problem: &'p Problem) -> Self {
        // The static system has one block: dense unless the model is held sparse (the schur
        // formulation's elimination would not pay off on one block).
        let storage = if problem.formulation() == Formulation::Sparse {
            Storage::Sparse
        } else {
            Storage::Dense
        };
        let layout = JacobianLayout::new(problem, &HarmonicSet::new(vec![0]), storage);
        Self { problem, layout }
    }

    /// An empty Jacobian with this system's pattern.
    pub fn new_jacobian(&self) -> AssembledJacobian {
        self.layout.new_jacobian()
    }

    /// Residual r = K q + F_c,static(q) − F_static (N) and, if asked, its Jacobian ∂r/∂q (N/m).
    pub fn evaluate(&self, q: &[f64], r: &mut [f64], jac: Option<&mut AssembledJacobian>) {
        let problem = self.problem;
        let layout = &self.layout;
        let k = &problem.model.stiffness;
        let f = &problem.static_load;
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
            let v = c.normal_of(q) - c.gap;
            if let Some(law) = c.law_2d() {
                let u = [c.tangential_of(q), c.second_tangential_of(q)];
                let point = static_point_2d(&law, u, v);
                let second = c.second_tangent.as_ref().map_or(&[][..], |s| &s.row[..]);
                for (row, force) in [
                    (&c.tangential[..], point.tangential[0]),
                    (second, point.tangential[1]),
                    (&c.normal[..], point.normal),
                ] {
                    for &(p, a) in row {
                        r[p] += a * force;
                    }
                }
                if let Some(j) = jac.as_deref_mut() {
                    let d = lc.dofs;
                    let rows = [&lc.tangential, &lc.tangential2, &lc.normal];
                    for (force_row, derivatives) in rows.iter().zip(&point.tangent) {
                        for (displacement_row, &value) in rows.iter().zip(derivatives) {
                            if value == 0.0 {
                                continue;
                            }
                            for &(a, ap) in force_row.iter() {
                                for &(b, aq) in displacement_row.iter() {
                                    j.add_at(lc.slots[a * d + b], ap * value * aq);
                                }
                            }
                        }
                    }
                }
                continue;
            }
            let law = &c.law;
            let u = c.tangential_of(q);
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
    }
}

/// Static pre-solve of the uncoupled mode: K q + F_c,static(q) = F_static, with each contact
/// loaded from rest (slider at zero): N = kₙ max(v, 0), T = clamp(kₜ u, −μN, μN) for a 1D point,
/// the radial return of [`static_point_2d`] for a 2D point. Newton with backtracking, on the
/// Jacobian storage of the problem's formulation (a 2D point's second tangential row fills the
/// same contact slots as in the dynamic Jacobian).
pub fn static_solve(problem: &Problem) -> Result<Vec<f64>, HbmError> {
    let n = problem.model.n_dofs();
    let f = &problem.static_load;
    let fnorm = f
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let system = StaticSystem::new(problem);
    let residual_of =
        |q: &[f64], r: &mut [f64], jac: Option<&mut AssembledJacobian>| system.evaluate(q, r, jac);
    let mut q = vec![0.0; n];
    let mut r = vec![0.0; n];
    let mut jac = system.new_jacobian();
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
