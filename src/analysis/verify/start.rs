//! Where a time integration starts: the state of a harmonic-balance point at τ = 0 (with its
//! sliders from a march over a period), or the static equilibrium with the contacts.

use std::f64::consts::PI;

use faer::Mat;

use super::contact::{return_map, slider_dims, slider_offsets, tangential_pair, TimeState};
use super::newmark::mat_vec_add;
use super::settings::VerifyError;
use crate::contact::aft2d::Aft2dWorkspace;
use crate::contact::harmonic::HarmonicSet;
use crate::contact::ContactPoint;
use crate::model::Problem;
use crate::numerics::linalg::solve_dense;

/// The state at τ = 0 of a harmonic-balance solution with full coefficients `x` (harmonic-major
/// on `set`, which must contain the constant block) at `freq_hz`: q(0), q̇(0), and the slider of
/// each contact from the contact law marched over the periodic motion sampled at `samples`
/// points per period, starting from T(0) = m μ N(0) (the AFT's initial condition), until the
/// slider repeats (at most 64 periods); for a 2D point, the slider at the start of the periodic
/// period of the AFT's own 2D march ([`Aft2dWorkspace`], on the point's coefficients, with
/// `samples` samples), an error if that march does not settle.
pub fn hbm_state(
    problem: &Problem,
    set: &HarmonicSet,
    x: &[f64],
    freq_hz: f64,
    samples: usize,
) -> Result<TimeState, VerifyError> {
    let n = problem.model.n_dofs();
    let nb = set.n_blocks();
    if x.len() != n * nb {
        return Err(VerifyError::WrongLength {
            expected: n * nb,
            found: x.len(),
        });
    }
    if !set.has_constant() {
        return Err(VerifyError::Unsupported {
            reason: "the harmonic-balance point has no 0th harmonic (effects.coupling = \"uncoupled\"); verify needs \"coupled\"".into(),
        });
    }
    let omega = 2.0 * PI * freq_hz;
    let at = |tau: f64| -> (Vec<f64>, Vec<f64>) {
        let mut q = vec![0.0; n];
        let mut qd = vec![0.0; n];
        for (j, b) in set.blocks().iter().enumerate() {
            let h = b.harmonic() as f64;
            let (val, der) = match b {
                crate::contact::harmonic::Block::Constant => (1.0, 0.0),
                crate::contact::harmonic::Block::Cos(_) => ((h * tau).cos(), -h * (h * tau).sin()),
                crate::contact::harmonic::Block::Sin(_) => ((h * tau).sin(), h * (h * tau).cos()),
            };
            for i in 0..n {
                q[i] += x[j * n + i] * val;
                qd[i] += x[j * n + i] * der * omega;
            }
        }
        (q, qd)
    };
    let (q0, qd0) = at(0.0);
    let samples = samples.max(8);
    let qs: Vec<Vec<f64>> = (0..samples)
        .map(|k| at(2.0 * PI * k as f64 / samples as f64).0)
        .collect();
    let liftoff = problem.effects.contact.liftoff;
    let mut sliders = Vec::with_capacity(slider_offsets(problem)[problem.contacts.len()]);
    let mut aft2d: Option<Aft2dWorkspace> = None;
    for p in &problem.contacts {
        if let Some(law) = p.law_2d() {
            // The sampled 2D march on the point's own coefficients (u₁, u₂, v per block),
            // whatever the point's time resolution: its slider start is that of a law applied
            // at discrete instants, as the time integration applies it, and the 1D points'
            // starts below are sampled alike.
            let row_coefficients = |row: &[(usize, f64)]| -> Vec<f64> {
                (0..nb)
                    .map(|j| row.iter().map(|&(i, a)| a * x[j * n + i]).sum())
                    .collect()
            };
            let rows: Vec<&[(usize, f64)]> = p.tangential_rows().collect();
            let u1 = row_coefficients(rows[0]);
            let u2 = row_coefficients(rows[1]);
            let mut v = row_coefficients(&p.normal);
            if let Some(j0) = set.constant_block() {
                v[j0] -= p.gap;
            }
            let ws = aft2d.get_or_insert_with(|| Aft2dWorkspace::new(set, samples));
            ws.evaluate(&law, problem.effects.contact, [&u1, &u2], &v, false)
                .map_err(|e| VerifyError::Unsupported {
                    reason: format!(
                        "the 2D march of contact `{}` on the harmonic-balance point: {e}",
                        p.name
                    ),
                })?;
            sliders.extend_from_slice(&ws.slider_start);
            continue;
        }
        let u0 = p.tangential_of(&qs[0]);
        let v0 = p.normal_of(&qs[0]) - p.gap;
        let n0 = if liftoff {
            (p.law.kn * v0).max(0.0)
        } else {
            p.law.kn * v0
        };
        let mut w = if n0 > 0.0 {
            u0 - p.law.initial_state * p.law.mu * n0 / p.law.kt
        } else {
            u0
        };
        for _ in 0..64 {
            let w_start = w;
            for qk in qs.iter().skip(1).chain(std::iter::once(&qs[0])) {
                let u = p.tangential_of(qk);
                let v = p.normal_of(qk) - p.gap;
                w = return_map(p, liftoff, [u, 0.0], v, [w, 0.0]).slider[0];
            }
            if (w - w_start).abs() <= 1e-14 * (w.abs() + 1e-12) {
                break;
            }
        }
        sliders.push(w);
    }
    Ok(TimeState {
        q: q0,
        qdot: qd0,
        sliders,
    })
}

/// A start at rest (q̇ = 0) at a nonlinear static equilibrium in which every closed contact
/// carries the tangential force T = m μ N of its initial state m (`law.initial_state`, the
/// paper's T(τ_ini) = m μ N of Eqs. 14-15 applied to the static state; for a 2D point
/// m = (m₁, m₂) and T = μN m along t₁, t₂): Newton with backtracking on
///
/// ```text
/// K q + Σ_c [ aₜ m μ N(q) + aₙ N(q) ] = F_static,   N = kₙ max(v, 0) (kₙ v without lift-off),
/// ```
///
/// from the stuck static deflection ([`crate::analysis::linear::stuck_guess`] at h = 0), to a
/// residual of 10⁻¹² of the load. Each slider is then placed at w = u − m μ N / kₜ, so that the
/// return mapping gives back T = m μ N (|m| ≤ 1: the contact sticks) and the start is an
/// equilibrium of the equations of motion without the harmonic load; an open contact's slider
/// is at u. An error if Newton does not converge in 100 iterations.
pub fn static_state(problem: &Problem) -> Result<TimeState, VerifyError> {
    let set = HarmonicSet::new(vec![0]);
    let mut q = crate::analysis::linear::stuck_guess(problem, &set, 0.0)
        .map_err(|e| VerifyError::Static(e.to_string()))?;
    let n = q.len();
    let liftoff = problem.effects.contact.liftoff;
    let k = problem.model.stiffness.to_dense();
    let f = &problem.static_load;
    let fnorm = f.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-30);
    let normal = |p: &ContactPoint, q: &[f64]| -> (f64, f64) {
        let v = p.normal_of(q) - p.gap;
        if liftoff && v <= 0.0 {
            (0.0, 0.0)
        } else {
            (p.law.kn * v, p.law.kn)
        }
    };
    let residual = |q: &[f64], jac: Option<&mut Mat<f64>>| -> Vec<f64> {
        let mut r: Vec<f64> = f.iter().map(|x| -x).collect();
        mat_vec_add(&k, 1.0, q, &mut r);
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.copy_from(&k);
        }
        for p in &problem.contacts {
            let (nf, dn) = normal(p, q);
            let m = initial_pair(p);
            for (row, m_a) in p.tangential_rows().zip(m) {
                for &(i, a) in row {
                    r[i] += a * m_a * p.law.mu * nf;
                }
            }
            for &(i, a) in &p.normal {
                r[i] += a * nf;
            }
            if let Some(j) = jac.as_deref_mut() {
                for &(b, ab) in &p.normal {
                    for (row, m_a) in p.tangential_rows().zip(m) {
                        for &(i, a) in row {
                            j[(i, b)] += a * m_a * p.law.mu * dn * ab;
                        }
                    }
                    for &(i, a) in &p.normal {
                        j[(i, b)] += a * dn * ab;
                    }
                }
            }
        }
        r
    };
    let norm = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>().sqrt() / fnorm;
    let mut jac = Mat::<f64>::zeros(n, n);
    let mut rel = f64::INFINITY;
    let mut converged = false;
    for _ in 0..100 {
        let r = residual(&q, Some(&mut jac));
        rel = norm(&r);
        if rel <= 1e-12 {
            converged = true;
            break;
        }
        let dq = solve_dense(&jac, &r).map_err(|e| VerifyError::Static(e.to_string()))?;
        // Backtracking on the residual norm keeps the lift-off kink from cycling.
        let mut alpha = 1.0;
        loop {
            let trial: Vec<f64> = q.iter().zip(&dq).map(|(x, d)| x - alpha * d).collect();
            if norm(&residual(&trial, None)) < rel || alpha < 1e-4 {
                q = trial;
                break;
            }
            alpha *= 0.5;
        }
    }
    if !converged {
        return Err(VerifyError::Static(format!(
            "Newton did not converge in 100 iterations (residual {rel:.3e} of the load)"
        )));
    }
    let sliders = problem
        .contacts
        .iter()
        .flat_map(|p| {
            let u = tangential_pair(p, &q);
            let (nf, _) = normal(p, &q);
            let m = initial_pair(p);
            (0..slider_dims(p)).map(move |a| {
                if nf > 0.0 {
                    u[a] - m[a] * p.law.mu * nf / p.law.kt
                } else {
                    u[a]
                }
            })
        })
        .collect();
    Ok(TimeState {
        qdot: vec![0.0; n],
        q,
        sliders,
    })
}

/// The initial tangential state (m₁, m₂) of a point (m₂ = 0 for a 1D point).
fn initial_pair(point: &ContactPoint) -> [f64; 2] {
    [
        point.law.initial_state,
        point
            .second_tangent
            .as_ref()
            .map_or(0.0, |s| s.initial_state),
    ]
}
