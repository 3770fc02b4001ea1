//! Linear references: the structure with all contacts open, and with all contacts stuck
//! (tangential and normal contact springs kₜ aₜaₜᵀ + kₙ aₙaₙᵀ added to K).
//!
//! These are closed-form linear solves of the real 2n-block form of (K − ω²M + iωC) q = F
//! (the complex dynamic stiffness is complex-symmetric, not Hermitian, so an LU is used).
//! With contacts open, a free body such as an unloaded wedge damper would make the system
//! singular; only the DOFs connected (through M, C, K) to a loaded DOF are solved, the others
//! do not move.

use crate::contact::harmonic::Block;
use crate::model::Problem;
use crate::numerics::linalg::{solve_triplets, LinearSolveError};

/// Which linear reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinearCase {
    /// Contacts removed.
    Open,
    /// Contacts replaced by their tangential and normal springs.
    Stuck,
}

/// Stiffness of all contacts as linear springs: Σ kₜ aₜaₜᵀ + kₙ aₙaₙᵀ (N/m), as triplets.
pub fn contact_stiffness(problem: &Problem) -> Vec<(usize, usize, f64)> {
    let mut k = Vec::new();
    for c in &problem.contacts {
        for row in c.tangential_rows() {
            for &(p, ap) in row {
                for &(q, aq) in row {
                    k.push((p, q, c.law.kt * ap * aq));
                }
            }
        }
        for &(p, ap) in &c.normal {
            for &(q, aq) in &c.normal {
                k.push((p, q, c.law.kn * ap * aq));
            }
        }
    }
    k
}

/// Static state (m) with every contact replaced by its normal spring only (no tangential
/// spring: the contacts slide freely), pressed by the static loads and the gap pre-loads
/// kₙ g aₙ: where the rest position leaves gaps open, the damper slides onto its contacts
/// here instead of being held off them by stuck tangential springs. An error when the
/// structure is singular without the tangential springs (a flat damper free to slide).
pub fn sliding_static(problem: &Problem) -> Result<Vec<f64>, LinearSolveError> {
    let n = problem.model.n_dofs();
    let mut k = problem.model.stiffness.triplets();
    let mut rhs = problem.static_load.clone();
    for c in &problem.contacts {
        for &(p, ap) in &c.normal {
            for &(q, aq) in &c.normal {
                k.push((p, q, c.law.kn * ap * aq));
            }
            rhs[p] += c.law.kn * c.gap * ap;
        }
    }
    solve_triplets(n, &k, &rhs, problem.model.stiffness.is_sparse())
}

/// Stiffness of a linear case as triplets (duplicates to be summed).
fn case_stiffness(problem: &Problem, case: LinearCase) -> Vec<(usize, usize, f64)> {
    let mut k = problem.model.stiffness.triplets();
    if case == LinearCase::Stuck {
        k.extend(contact_stiffness(problem));
    }
    k
}

/// DOFs connected to a loaded DOF through nonzero entries of M, C and `k`.
fn connected_to_loads(problem: &Problem, k: &[(usize, usize, f64)], harmonic: usize) -> Vec<usize> {
    let n = problem.model.n_dofs();
    let m = &problem.model;
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut link = |p: usize, q: usize, v: f64| {
        if v != 0.0 && p != q {
            neighbours[p].push(q);
        }
    };
    for &(p, q, v) in k {
        link(p, q, v);
    }
    m.mass.for_each_nonzero(&mut link);
    m.damping.for_each_nonzero(&mut link);
    let mut seen = vec![false; n];
    let mut stack: Vec<usize> = problem
        .harmonic_loads
        .iter()
        .filter(|l| l.harmonic == harmonic && (l.cos != 0.0 || l.sin != 0.0))
        .map(|l| l.dof)
        .collect();
    while let Some(p) = stack.pop() {
        if seen[p] {
            continue;
        }
        seen[p] = true;
        stack.extend(neighbours[p].iter().filter(|&&q| !seen[q]));
    }
    (0..n).filter(|&p| seen[p]).collect()
}

/// Cosine and sine response (m) to the loads of harmonic `h` at ω (rad/s), for stiffness `k`
/// (triplets), solved on `dofs` only (the others stay at rest).
fn harmonic_response(
    problem: &Problem,
    k: &[(usize, usize, f64)],
    dofs: &[usize],
    harmonic: usize,
    omega: f64,
) -> Result<(Vec<f64>, Vec<f64>), LinearSolveError> {
    let n = problem.model.n_dofs();
    let m = &problem.model;
    let na = dofs.len();
    let hw = harmonic as f64 * omega;
    let mut position = vec![usize::MAX; n];
    for (i, &p) in dofs.iter().enumerate() {
        position[p] = i;
    }
    if !problem.model.stiffness.is_sparse() && na > 0 {
        return dense_harmonic_response(problem, k, dofs, &position, harmonic, hw);
    }
    // Real 2n form [[D, hωC], [−hωC, D]] with D = K − (hω)²M.
    let mut a: Vec<(usize, usize, f64)> = Vec::new();
    let mut push_d = |p: usize, q: usize, d: f64| {
        let (i, j) = (position[p], position[q]);
        if i != usize::MAX && j != usize::MAX {
            a.push((i, j, d));
            a.push((na + i, na + j, d));
        }
    };
    for &(p, q, v) in k {
        push_d(p, q, v);
    }
    m.mass
        .for_each_nonzero(|p, q, v| push_d(p, q, -hw * hw * v));
    m.damping.for_each_nonzero(|p, q, v| {
        let (i, j) = (position[p], position[q]);
        if i != usize::MAX && j != usize::MAX {
            a.push((i, na + j, hw * v));
            a.push((na + i, j, -hw * v));
        }
    });
    let mut rhs = vec![0.0; 2 * na];
    for l in problem
        .harmonic_loads
        .iter()
        .filter(|l| l.harmonic == harmonic)
    {
        if position[l.dof] != usize::MAX {
            rhs[position[l.dof]] += l.cos;
            rhs[na + position[l.dof]] += l.sin;
        }
    }
    let mut qc = vec![0.0; n];
    let mut qs = vec![0.0; n];
    if na == 0 {
        return Ok((qc, qs));
    }
    let sol = solve_triplets(2 * na, &a, &rhs, problem.model.stiffness.is_sparse())?;
    for (i, &p) in dofs.iter().enumerate() {
        qc[p] = sol[i];
        qs[p] = sol[na + i];
    }
    Ok((qc, qs))
}

/// [`harmonic_response`] of a dense model: the complex dynamic stiffness
/// D + i hωC (D = K − (hω)²M; complex-symmetric, so LU rather than Cholesky) acting on
/// q_c − i q_s with load f_c − i f_s, by dense complex LU: half the work of the real 2n form.
fn dense_harmonic_response(
    problem: &Problem,
    k: &[(usize, usize, f64)],
    dofs: &[usize],
    position: &[usize],
    harmonic: usize,
    hw: f64,
) -> Result<(Vec<f64>, Vec<f64>), LinearSolveError> {
    use faer::c64;
    let n = problem.model.n_dofs();
    let na = dofs.len();
    let mut a = faer::Mat::<c64>::zeros(na, na);
    let mut add = |p: usize, q: usize, v: c64| {
        let (i, j) = (position[p], position[q]);
        if i != usize::MAX && j != usize::MAX {
            a[(i, j)] += v;
        }
    };
    for &(p, q, v) in k {
        add(p, q, c64::new(v, 0.0));
    }
    let m = &problem.model;
    m.mass
        .for_each_nonzero(|p, q, v| add(p, q, c64::new(-hw * hw * v, 0.0)));
    m.damping
        .for_each_nonzero(|p, q, v| add(p, q, c64::new(0.0, hw * v)));
    let mut rhs = faer::Mat::<c64>::zeros(na, 1);
    for l in problem
        .harmonic_loads
        .iter()
        .filter(|l| l.harmonic == harmonic)
    {
        if position[l.dof] != usize::MAX {
            rhs[(position[l.dof], 0)] += c64::new(l.cos, -l.sin);
        }
    }
    if (0..na).any(|i| !(rhs[(i, 0)].re.is_finite() && rhs[(i, 0)].im.is_finite())) {
        return Err(LinearSolveError::NonFinite);
    }
    let lu = crate::numerics::linalg::packed_complex_lu(a)?;
    lu.solve_in_place(&mut rhs);
    let mut qc = vec![0.0; n];
    let mut qs = vec![0.0; n];
    for (i, &p) in dofs.iter().enumerate() {
        qc[p] = rhs[(i, 0)].re;
        qs[p] = -rhs[(i, 0)].im;
        if !(qc[p].is_finite() && qs[p].is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
    }
    Ok((qc, qs))
}

/// First-harmonic amplitude √(c² + s²) of every DOF (m) at each frequency (Hz).
pub fn frf(
    problem: &Problem,
    case: LinearCase,
    freqs_hz: &[f64],
) -> Result<Vec<Vec<f64>>, LinearSolveError> {
    let k = case_stiffness(problem, case);
    let dofs = connected_to_loads(problem, &k, 1);
    freqs_hz
        .iter()
        .map(|f| {
            let (c, s) = harmonic_response(problem, &k, &dofs, 1, 2.0 * std::f64::consts::PI * f)?;
            Ok(c.iter().zip(&s).map(|(a, b)| a.hypot(*b)).collect())
        })
        .collect()
}

/// Stuck-contact linear solution in the unknown layout of `set` at ω (rad/s): the starting
/// guess of the nonlinear solve. The constant block includes the gap preload kₙ g aₙ.
pub fn stuck_guess(
    problem: &Problem,
    set: &crate::contact::harmonic::HarmonicSet,
    omega: f64,
) -> Result<Vec<f64>, LinearSolveError> {
    linear_guess(problem, set, omega, LinearCase::Stuck)
}

/// A guess for a nonlinear solve where the contacts carry little (a low pre-load, a damper that
/// bounces): the static block of [`stuck_guess`] (the pre-load pressing the contacts) with the
/// harmonics of the open-contact linear response, zero on the DOFs open contacts leave without
/// load (a free damper).
pub fn open_guess(
    problem: &Problem,
    set: &crate::contact::harmonic::HarmonicSet,
    omega: f64,
) -> Result<Vec<f64>, LinearSolveError> {
    linear_guess(problem, set, omega, LinearCase::Open)
}

/// The linear guess with the stuck static block and the harmonics of `dynamic` contacts.
fn linear_guess(
    problem: &Problem,
    set: &crate::contact::harmonic::HarmonicSet,
    omega: f64,
    dynamic: LinearCase,
) -> Result<Vec<f64>, LinearSolveError> {
    let n = problem.model.n_dofs();
    let k = case_stiffness(problem, LinearCase::Stuck);
    let mut x = vec![0.0; n * set.n_blocks()];
    let k_dynamic = case_stiffness(problem, dynamic);
    for &h in set.harmonics() {
        if h == 0 {
            let mut rhs = problem.static_load.clone();
            for c in &problem.contacts {
                for &(p, a) in &c.normal {
                    rhs[p] += c.law.kn * c.gap * a;
                }
            }
            let q0 = solve_triplets(n, &k, &rhs, problem.model.stiffness.is_sparse())?;
            let j = set.constant_block().expect("h = 0 is in the set");
            x[j * n..(j + 1) * n].copy_from_slice(&q0);
        } else if problem.harmonic_loads.iter().any(|l| l.harmonic == h) {
            // Harmonics without a load have a zero linear response (x stays zero).
            let dofs: Vec<usize> = match dynamic {
                LinearCase::Stuck => (0..n).collect(),
                LinearCase::Open => connected_to_loads(problem, &k_dynamic, h),
            };
            let (qc, qs) = harmonic_response(problem, &k_dynamic, &dofs, h, omega)?;
            for (j, b) in set.blocks().iter().enumerate() {
                match *b {
                    Block::Cos(hh) if hh == h => x[j * n..(j + 1) * n].copy_from_slice(&qc),
                    Block::Sin(hh) if hh == h => x[j * n..(j + 1) * n].copy_from_slice(&qs),
                    _ => {}
                }
            }
        }
    }
    Ok(x)
}

/// A linear reference curve on a frequency grid, for the output DOFs.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LinearCurve {
    /// Frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// First-harmonic amplitude (m), indexed `[frequency][output]`.
    pub amplitudes: Vec<Vec<f64>>,
}

/// The linear reference of `case` on `points` uniformly spaced frequencies of the analysis
/// range, for the problem's output DOFs.
pub fn reference_curve(
    problem: &Problem,
    case: LinearCase,
    points: usize,
) -> Result<LinearCurve, LinearSolveError> {
    let a = &problem.analysis.continuation;
    let freqs_hz: Vec<f64> = (0..points)
        .map(|i| {
            a.freq_start_hz
                + (a.freq_end_hz - a.freq_start_hz) * i as f64 / (points - 1).max(1) as f64
        })
        .collect();
    let all = frf(problem, case, &freqs_hz)?;
    let amplitudes = all
        .iter()
        .map(|row| problem.outputs.iter().map(|&d| row[d]).collect())
        .collect();
    Ok(LinearCurve {
        freqs_hz,
        amplitudes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The complex dense path and the real 2n sparse path give the same response.
    #[test]
    fn dense_complex_and_sparse_real_form_responses_agree() {
        let dense = crate::scene::parse(crate::scene::paper_wedge_scene(), "paper", &[])
            .unwrap()
            .validate("paper")
            .unwrap();
        let mut sparse = dense.clone();
        for m in [
            &mut sparse.model.stiffness,
            &mut sparse.model.mass,
            &mut sparse.model.damping,
        ] {
            *m = crate::model::matrix::StructuralMatrix::sparse_from_triplets(m.n(), &m.triplets());
        }
        for case in [LinearCase::Stuck, LinearCase::Open] {
            let k = case_stiffness(&dense, case);
            let all = connected_to_loads(&dense, &k, 1);
            for f in [50.0, 180.0, 221.0, 400.0] {
                let w = 2.0 * std::f64::consts::PI * f;
                let (dc, ds) = harmonic_response(&dense, &k, &all, 1, w).unwrap();
                let (sc, ss) = harmonic_response(&sparse, &k, &all, 1, w).unwrap();
                let scale = dc.iter().chain(&ds).fold(0.0_f64, |m, v| m.max(v.abs()));
                assert!(scale > 0.0);
                for (a, b) in dc.iter().chain(&ds).zip(sc.iter().chain(&ss)) {
                    assert!(
                        (a - b).abs() <= 1e-10 * scale,
                        "{case:?} at {f} Hz: {a:e} vs {b:e}"
                    );
                }
            }
        }
    }
}
