//! Symmetric generalized eigenproblems `K φ = λ M φ`.
//!
//! * Sparse: shift-invert **block Lanczos** in the M-inner product, written by
//!   hand (no Rust crate solves sparse generalized symmetric eigenproblems).
//!   The operator is `Op = (K − σM)⁻¹ M`, self-adjoint in `⟨x, y⟩_M = xᵀMy`;
//!   its largest eigenvalues `θ = 1/(λ − σ)` are the eigenvalues `λ` closest
//!   above the shift `σ`. The basis is kept M-orthonormal by full block
//!   classical Gram–Schmidt done twice (CGS2); the projected matrix is
//!   restarted by thick restart (Krylov–Schur for symmetric operators): the
//!   best Ritz vectors and the residual block are kept. A block of `p ≥ 2`
//!   random start vectors and full re-orthogonalisation find every copy of a
//!   repeated eigenvalue (symmetric pairs of substructures). The Ritz
//!   residual estimate `‖Op y − θ y‖_M ≤ tol·θ` decides convergence, then the
//!   true residuals `‖Kφ − λMφ‖ / ‖(K − σM)φ‖` are computed and reported.
//! * Dense: `K − σM = L Lᵀ`, eigen-decomposition of `L⁻¹ M L⁻ᵀ` (also the
//!   fallback of the sparse solver for small problems), and the reduced-model
//!   solver [`dense_generalized_eigenvalues`] (Cholesky of `M_r`).

use crate::csc::Csc;
use crate::factor::SpdFactor;
use crate::ReductionError;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

/// Eigenpairs of `K φ = λ M φ`: values ascending (rad²/s² for SI models),
/// vectors mass-normalised (`φᵀ M φ = 1`), one per column.
#[derive(Debug, Clone)]
pub struct Eigen {
    /// eigenvalues λ = ω², ascending
    pub values: Vec<f64>,
    /// eigenvectors, `n × values.len()`, mass-normalised
    pub vectors: Mat<f64>,
    /// largest relative residual `‖Kφ − λMφ‖ / ‖(K − σM)φ‖` (σ the shift)
    pub max_residual: f64,
    /// number of thick restarts of the Lanczos process (0 for the dense path)
    pub restarts: usize,
    /// number of block solves with the factor of `K − σM`
    pub solves: usize,
}

impl Eigen {
    /// Eigenfrequencies in Hz: `√max(λ, 0) / 2π`.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.values.iter().map(|&l| lambda_to_hz(l)).collect()
    }
}

pub(crate) fn lambda_to_hz(l: f64) -> f64 {
    l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// Settings of the block Lanczos solver.
#[derive(Clone, Copy, Debug)]
pub struct LanczosOptions {
    /// block size `p` (≥ 2 keeps repeated eigenvalues safe)
    pub block: usize,
    /// Ritz convergence tolerance on `‖Op y − θy‖_M / θ`
    pub tol: f64,
    /// maximum number of thick restarts
    pub max_restarts: usize,
    /// seed of the deterministic random start block
    pub seed: u64,
    /// problems with at most this many DOFs are solved densely
    pub dense_below: usize,
}

impl Default for LanczosOptions {
    fn default() -> Self {
        LanczosOptions {
            block: 8,
            tol: 1e-10,
            max_restarts: 200,
            seed: 0x5eed_cb01,
            dense_below: 400,
        }
    }
}

/// SplitMix64 in [-1, 1).
pub(crate) struct Rng(u64);
impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// The lowest `nev` eigenpairs of `K φ = λ M φ` above `sigma`, given the
/// factor of `K − σM`. `k_lower`, `m_lower`: lower triangles.
pub(crate) fn lowest_modes(
    k_lower: &Csc,
    m_lower: &Csc,
    factor: &SpdFactor,
    sigma: f64,
    nev: usize,
    opts: &LanczosOptions,
    par: Par,
) -> Result<Eigen, ReductionError> {
    let n = k_lower.ncols;
    if nev > n {
        return Err(ReductionError::TooManyModes {
            asked: nev,
            available: n,
            what: "matrix",
        });
    }
    if nev == 0 {
        return Ok(Eigen {
            values: Vec::new(),
            vectors: Mat::zeros(n, 0),
            max_residual: 0.0,
            restarts: 0,
            solves: 0,
        });
    }
    let p = opts.block.max(1);
    let ncv = round_up((2 * nev).max(nev + 3 * p), p);
    let mut eig = if n <= opts.dense_below || ncv + p > n / 2 {
        dense_lowest(k_lower, m_lower, sigma, nev)?
    } else {
        block_lanczos(m_lower, factor, sigma, nev, ncv, opts, par)?
    };
    normalise_and_check(k_lower, m_lower, sigma, &mut eig)?;
    Ok(eig)
}

fn round_up(x: usize, p: usize) -> usize {
    x.div_ceil(p) * p
}

/// Mass-normalise, replace λ by the Rayleigh quotient, compute residuals.
fn normalise_and_check(
    k_lower: &Csc,
    m_lower: &Csc,
    sigma: f64,
    eig: &mut Eigen,
) -> Result<(), ReductionError> {
    let n = k_lower.ncols;
    let q = eig.values.len();
    let mut kx = Mat::zeros(n, q);
    let mut mx = Mat::zeros(n, q);
    k_lower.sym_lower_mul(eig.vectors.as_ref(), kx.as_mut());
    m_lower.sym_lower_mul(eig.vectors.as_ref(), mx.as_mut());
    let mut worst = 0.0f64;
    for c in 0..q {
        let x = eig.vectors.col(c);
        let xmx: f64 = (0..n).map(|i| x[i] * mx[(i, c)]).sum();
        let xkx: f64 = (0..n).map(|i| x[i] * kx[(i, c)]).sum();
        if xmx <= 0.0 || !xmx.is_finite() {
            return Err(ReductionError::MassNotPositive {
                matrix: "M",
                detail: format!("eigenvector {c} has mass {xmx:e}"),
            });
        }
        let lambda = xkx / xmx;
        let s = 1.0 / xmx.sqrt();
        let (mut r2, mut k2, mut a2) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let r = kx[(i, c)] - lambda * mx[(i, c)];
            let a = kx[(i, c)] - sigma * mx[(i, c)];
            r2 += r * r;
            k2 += kx[(i, c)] * kx[(i, c)];
            a2 += a * a;
        }
        let denom = k2.max(a2).sqrt();
        let res = if denom > 0.0 { r2.sqrt() / denom } else { 0.0 };
        worst = worst.max(res);
        eig.values[c] = lambda;
        let mut col = eig.vectors.col_mut(c);
        for i in 0..n {
            col[i] *= s;
        }
    }
    eig.max_residual = worst;
    // keep ascending order after the Rayleigh-quotient update
    let mut idx: Vec<usize> = (0..q).collect();
    idx.sort_by(|&a, &b| eig.values[a].total_cmp(&eig.values[b]));
    if idx.iter().enumerate().any(|(i, &j)| i != j) {
        let vals = idx.iter().map(|&j| eig.values[j]).collect();
        let vecs = Mat::from_fn(n, q, |i, c| eig.vectors[(i, idx[c])]);
        eig.values = vals;
        eig.vectors = vecs;
    }
    Ok(())
}

fn to_dense_sym(lower: &Csc) -> Mat<f64> {
    let n = lower.ncols;
    let mut a = Mat::zeros(n, n);
    for j in 0..n {
        let (rows, vals) = lower.col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
    a
}

/// Dense path: `K − σM = L Lᵀ`, `C = L⁻¹ M L⁻ᵀ`, `θ = 1/(λ − σ)`.
fn dense_lowest(
    k_lower: &Csc,
    m_lower: &Csc,
    sigma: f64,
    nev: usize,
) -> Result<Eigen, ReductionError> {
    let n = k_lower.ncols;
    let k = to_dense_sym(k_lower);
    let m = to_dense_sym(m_lower);
    let a = &k - sigma * &m;
    let llt = a
        .llt(Side::Lower)
        .map_err(|e| ReductionError::LinearAlgebra(format!("dense Cholesky of K − σM ({e:?})")))?;
    let l = llt.L();
    // C = L⁻¹ M L⁻ᵀ
    let mut x = m.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut c = x.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, c.as_mut(), Par::Seq);
    let c = symmetrise(c.as_ref());
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| ReductionError::LinearAlgebra(format!("dense eigen solver ({e:?})")))?;
    let s = evd.S().column_vector();
    let u = evd.U();
    // largest θ first
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    let take: Vec<usize> = order.into_iter().take(nev).collect();
    if let Some(&j) = take.iter().find(|&&j| s[j] <= 0.0) {
        return Err(ReductionError::MassNotPositive {
            matrix: "M",
            detail: format!("only {j} finite eigenvalues: M is singular on the wanted subspace"),
        });
    }
    let mut y = Mat::from_fn(n, nev, |i, c| u[(i, take[c])]);
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        y.as_mut(),
        Par::Seq,
    );
    let values: Vec<f64> = take.iter().map(|&j| sigma + 1.0 / s[j]).collect();
    Ok(Eigen {
        values,
        vectors: y,
        max_residual: 0.0,
        restarts: 0,
        solves: 0,
    })
}

fn symmetrise(a: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// `C = Vᵀ Z`, `W -= V C`; returns C.
fn gs_pass(v: MatRef<'_, f64>, z: MatRef<'_, f64>, w: MatMut<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = Mat::zeros(v.ncols(), z.ncols());
    matmul(c.as_mut(), Accum::Replace, v.transpose(), z, 1.0, par);
    matmul(w, Accum::Add, v, c.as_ref(), -1.0, par);
    c
}

fn m_mul(m_lower: &Csc, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut z = Mat::zeros(x.nrows(), x.ncols());
    m_lower.sym_lower_mul(x, z.as_mut());
    z
}

/// `(V_new, M V_new, R)`
type OrthoBlock = (Mat<f64>, Mat<f64>, Mat<f64>);

/// M-orthonormalise `w` (already orthogonal to `v_prev`): `w = V_new R`.
/// Returns `(V_new, M V_new, R)`. Directions of `w` below the rank threshold
/// are replaced by random vectors M-orthogonal to everything (their row of
/// `R` is zero).
fn orthonormalise(
    m_lower: &Csc,
    v_prev: MatRef<'_, f64>,
    w: Mat<f64>,
    norm_ref: f64,
    rng: &mut Rng,
    par: Par,
) -> Result<OrthoBlock, ReductionError> {
    let n = w.nrows();
    let p = w.ncols();
    let z = m_mul(m_lower, w.as_ref());
    let mut g = Mat::zeros(p, p);
    matmul(
        g.as_mut(),
        Accum::Replace,
        w.transpose(),
        z.as_ref(),
        1.0,
        par,
    );
    let g = symmetrise(g.as_ref());
    let evd = g
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| ReductionError::LinearAlgebra(format!("Gram eigen ({e:?})")))?;
    let d = evd.S().column_vector().to_owned();
    let q = evd.U().to_owned();
    let mut vnew = Mat::zeros(n, p);
    let mut mvnew = Mat::zeros(n, p);
    let mut r = Mat::zeros(p, p);
    matmul(
        vnew.as_mut(),
        Accum::Replace,
        w.as_ref(),
        q.as_ref(),
        1.0,
        par,
    );
    matmul(
        mvnew.as_mut(),
        Accum::Replace,
        z.as_ref(),
        q.as_ref(),
        1.0,
        par,
    );
    // reference squared norm: the block before Gram-Schmidt (or its own
    // largest direction for a start block)
    let norm_ref = if norm_ref > 0.0 {
        norm_ref
    } else {
        (0..p).map(|i| d[i]).fold(0.0, f64::max)
    };
    let thresh = 1e-20 * norm_ref.max(f64::MIN_POSITIVE);
    let mut bad = Vec::new();
    for i in 0..p {
        if d[i] > thresh {
            let s = d[i].sqrt();
            for row in 0..n {
                vnew[(row, i)] /= s;
                mvnew[(row, i)] /= s;
            }
            for c in 0..p {
                r[(i, c)] = s * q[(c, i)];
            }
        } else {
            bad.push(i);
        }
    }
    for &i in &bad {
        // fresh random direction, M-orthogonal to v_prev and to the other
        // columns of vnew (bad columns not yet replaced are skipped)
        let mut x = Mat::from_fn(n, 1, |_, _| rng.next());
        let good: Vec<usize> = (0..p).filter(|c| !bad.contains(c) || *c < i).collect();
        for _ in 0..2 {
            let mx = m_mul(m_lower, x.as_ref());
            gs_pass(v_prev, mx.as_ref(), x.as_mut(), par);
            for &c in &good {
                let dot: f64 = (0..n).map(|row| mvnew[(row, c)] * x[(row, 0)]).sum();
                for row in 0..n {
                    x[(row, 0)] -= dot * vnew[(row, c)];
                }
            }
        }
        let mx = m_mul(m_lower, x.as_ref());
        let nn: f64 = (0..n).map(|row| x[(row, 0)] * mx[(row, 0)]).sum();
        if nn <= 0.0 || !nn.is_finite() {
            return Err(ReductionError::MassNotPositive {
                matrix: "M",
                detail: "a random vector has no M-norm: M is singular on the search space".into(),
            });
        }
        let s = nn.sqrt();
        for row in 0..n {
            vnew[(row, i)] = x[(row, 0)] / s;
            mvnew[(row, i)] = mx[(row, 0)] / s;
        }
        for c in 0..p {
            r[(i, c)] = 0.0;
        }
    }
    Ok((vnew, mvnew, r))
}

fn block_lanczos(
    m_lower: &Csc,
    factor: &SpdFactor,
    sigma: f64,
    nev: usize,
    ncv: usize,
    opts: &LanczosOptions,
    par: Par,
) -> Result<Eigen, ReductionError> {
    let n = m_lower.ncols;
    let p = opts.block.max(1);
    let mut rng = Rng::new(opts.seed);
    let mut v = Mat::<f64>::zeros(n, ncv + p);
    let mut h = Mat::<f64>::zeros(ncv + p, ncv);
    // start block
    let w0 = Mat::from_fn(n, p, |_, _| rng.next());
    let (b0, mut mv_cur, _) = orthonormalise(m_lower, v.subcols(0, 0), w0, 0.0, &mut rng, par)?;
    v.subcols_mut(0, p).copy_from(&b0);
    let mut cur = p;
    let mut restarts = 0usize;
    let mut solves = 0usize;
    // number of Ritz vectors kept at a restart
    let keep = ncv - round_up((ncv - nev).div_ceil(2), p).min(ncv - nev).max(p);
    let keep = keep.min(ncv - p);
    loop {
        while cur < ncv + p {
            let j0 = cur - p;
            let mut w = mv_cur.clone();
            factor.solve_in_place(w.as_mut(), par);
            solves += 1;
            let mut norm_ref = 0.0f64;
            for pass in 0..2 {
                let z = m_mul(m_lower, w.as_ref());
                if pass == 0 {
                    for c in 0..p {
                        let nn: f64 = (0..n).map(|i| w[(i, c)] * z[(i, c)]).sum();
                        norm_ref = norm_ref.max(nn);
                    }
                }
                let c = gs_pass(v.subcols(0, cur), z.as_ref(), w.as_mut(), par);
                let mut hb = h.as_mut().submatrix_mut(0, j0, cur, p);
                for jj in 0..p {
                    for ii in 0..cur {
                        hb[(ii, jj)] += c[(ii, jj)];
                    }
                }
            }
            let (vn, mvn, r) =
                orthonormalise(m_lower, v.subcols(0, cur), w, norm_ref, &mut rng, par)?;
            v.subcols_mut(cur, p).copy_from(&vn);
            h.as_mut().submatrix_mut(cur, j0, p, p).copy_from(&r);
            mv_cur = mvn;
            cur += p;
        }
        // Rayleigh-Ritz on the symmetric part of the projected matrix
        let t = symmetrise(h.submatrix(0, 0, ncv, ncv));
        let evd = t
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| ReductionError::LinearAlgebra(format!("projected eigen ({e:?})")))?;
        let theta = evd.S().column_vector().to_owned();
        let s = evd.U().to_owned();
        let mut order: Vec<usize> = (0..ncv).collect();
        order.sort_by(|&a, &b| theta[b].total_cmp(&theta[a]));
        let r_last = h.submatrix(ncv, ncv - p, p, p).to_owned();
        let mut resid = vec![0.0; ncv];
        for (slot, &i) in order.iter().enumerate() {
            let mut nn = 0.0;
            for a in 0..p {
                let mut acc = 0.0;
                for b in 0..p {
                    acc += r_last[(a, b)] * s[(ncv - p + b, i)];
                }
                nn += acc * acc;
            }
            resid[slot] = nn.sqrt() / theta[i].abs().max(f64::MIN_POSITIVE);
        }
        let converged = resid.iter().take_while(|&&r| r <= opts.tol).count();
        let all_positive = order.iter().take(nev).all(|&i| theta[i] > 0.0);
        if converged >= nev && all_positive {
            let sel: Vec<usize> = order[..nev].to_vec();
            let s_sel = Mat::from_fn(ncv, nev, |i, c| s[(i, sel[c])]);
            let mut phi = Mat::zeros(n, nev);
            matmul(
                phi.as_mut(),
                Accum::Replace,
                v.subcols(0, ncv),
                s_sel.as_ref(),
                1.0,
                par,
            );
            let values = sel.iter().map(|&i| sigma + 1.0 / theta[i]).collect();
            // ascending λ = descending θ already
            return Ok(Eigen {
                values,
                vectors: phi,
                max_residual: 0.0,
                restarts,
                solves,
            });
        }
        if restarts >= opts.max_restarts {
            return Err(ReductionError::EigenNotConverged {
                wanted: nev,
                converged: converged.min(nev),
                restarts,
                residual: resid[..nev].iter().cloned().fold(0.0, f64::max),
            });
        }
        // thick restart: V[:, 0..keep] = V[:, 0..ncv] S_keep (row chunks, in place)
        let sel: Vec<usize> = order[..keep].to_vec();
        let s_keep = Mat::from_fn(ncv, keep, |i, c| s[(i, sel[c])]);
        let chunk = 2048usize;
        let mut tmp = Mat::zeros(chunk, keep);
        let mut r0 = 0;
        while r0 < n {
            let rows = chunk.min(n - r0);
            matmul(
                tmp.as_mut().subrows_mut(0, rows),
                Accum::Replace,
                v.as_ref().submatrix(r0, 0, rows, ncv),
                s_keep.as_ref(),
                1.0,
                Par::Seq,
            );
            v.as_mut()
                .submatrix_mut(r0, 0, rows, keep)
                .copy_from(tmp.as_ref().subrows(0, rows));
            r0 += rows;
        }
        let res_block = v.subcols(ncv, p).to_owned();
        v.subcols_mut(keep, p).copy_from(&res_block);
        h.fill(0.0);
        for (c, &i) in sel.iter().enumerate() {
            h[(c, c)] = theta[i];
            for a in 0..p {
                let mut acc = 0.0;
                for b in 0..p {
                    acc += r_last[(a, b)] * s[(ncv - p + b, i)];
                }
                h[(keep + a, c)] = acc;
            }
        }
        cur = keep + p;
        restarts += 1;
    }
}

/// Eigenvalues and mass-normalised eigenvectors of a small dense symmetric
/// pencil `K_r x = λ M_r x` (e.g. a reduced model), `M_r` positive definite.
/// Values ascending.
pub fn dense_generalized_eigenvalues(
    k_r: MatRef<'_, f64>,
    m_r: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>), ReductionError> {
    let n = k_r.nrows();
    for (name, a) in [("K_r", k_r), ("M_r", m_r)] {
        if a.nrows() != n || a.ncols() != n {
            return Err(ReductionError::BadShape {
                matrix: name,
                rows: a.nrows(),
                cols: a.ncols(),
                expected: n,
            });
        }
        for j in 0..n {
            for i in 0..n {
                let v = a[(i, j)];
                if !v.is_finite() {
                    return Err(ReductionError::NonFinite {
                        matrix: name,
                        row: i,
                        col: j,
                        value: v,
                    });
                }
            }
        }
    }
    let m = symmetrise(m_r);
    let llt = m
        .llt(Side::Lower)
        .map_err(|e| ReductionError::MassNotPositive {
            matrix: "M_r",
            detail: format!("dense Cholesky failed: {e:?}"),
        })?;
    let l = llt.L();
    let k = symmetrise(k_r);
    let mut x = k.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut c = x.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, c.as_mut(), Par::Seq);
    let c = symmetrise(c.as_ref());
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| ReductionError::LinearAlgebra(format!("dense eigen solver ({e:?})")))?;
    let s = evd.S().column_vector();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| s[a].total_cmp(&s[b]));
    let values: Vec<f64> = order.iter().map(|&j| s[j]).collect();
    let mut y = Mat::from_fn(n, n, |i, c| evd.U()[(i, order[c])]);
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        y.as_mut(),
        Par::Seq,
    );
    Ok((values, y))
}
