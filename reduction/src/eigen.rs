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

use crate::block::RowBlock;
use crate::csc::SymView;
use crate::factor::SpdFactor;
use crate::ReductionError;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use std::time::Instant;

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
    /// where the time of the Lanczos process went
    pub timings: EigenTimings,
}

/// Seconds spent in the parts of the block Lanczos process.
#[derive(Clone, Copy, Debug, Default)]
pub struct EigenTimings {
    /// solves with the factor of `K − σM`
    pub solve: f64,
    /// sparse products with `M`
    pub mass: f64,
    /// Gram-Schmidt and block orthonormalisation (dense)
    pub orthogonalise: f64,
    /// Rayleigh-Ritz and thick restarts
    pub restart: f64,
    /// final residual check and normalisation
    pub check: f64,
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
    /// size of the Lanczos basis as a multiple of the wanted pairs
    /// (at least `nev + 3·block`)
    pub basis_factor: f64,
}

impl Default for LanczosOptions {
    fn default() -> Self {
        LanczosOptions {
            block: 8,
            tol: 1e-10,
            max_restarts: 200,
            seed: 0x5eed_cb01,
            dense_below: 400,
            basis_factor: 2.0,
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
    k_lower: SymView<'_>,
    m_lower: SymView<'_>,
    factor: &SpdFactor,
    sigma: f64,
    nev: usize,
    opts: &LanczosOptions,
    par: Par,
) -> Result<Eigen, ReductionError> {
    let n = k_lower.n();
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
            timings: EigenTimings::default(),
        });
    }
    let p = opts.block.max(1);
    let ncv = round_up(
        ((opts.basis_factor.max(1.0) * nev as f64).ceil() as usize).max(nev + 3 * p),
        p,
    );
    let mut eig = if n <= opts.dense_below || ncv + p > n / 2 {
        dense_lowest(k_lower, m_lower, sigma, nev)?
    } else {
        block_lanczos(m_lower, factor, sigma, nev, ncv, opts, par)?
    };
    let t0 = std::time::Instant::now();
    normalise_and_check(k_lower, m_lower, sigma, &mut eig)?;
    eig.timings.check = t0.elapsed().as_secs_f64();
    Ok(eig)
}

fn round_up(x: usize, p: usize) -> usize {
    x.div_ceil(p) * p
}

/// Mass-normalise, replace λ by the Rayleigh quotient, compute residuals.
fn normalise_and_check(
    k_lower: SymView<'_>,
    m_lower: SymView<'_>,
    sigma: f64,
    eig: &mut Eigen,
) -> Result<(), ReductionError> {
    let n = k_lower.n();
    let q = eig.values.len();
    let kx = m_mul(k_lower, eig.vectors.as_ref());
    let mx = m_mul(m_lower, eig.vectors.as_ref());
    let mut worst = 0.0f64;
    for c in 0..q {
        let x = eig.vectors.col_as_slice(c);
        let kc = kx.col_as_slice(c);
        let mc = mx.col_as_slice(c);
        let xmx: f64 = x.iter().zip(mc).map(|(a, b)| a * b).sum();
        let xkx: f64 = x.iter().zip(kc).map(|(a, b)| a * b).sum();
        if xmx <= 0.0 || !xmx.is_finite() {
            return Err(ReductionError::MassNotPositive {
                matrix: "M",
                detail: format!("eigenvector {c} has mass {xmx:e}"),
            });
        }
        let lambda = xkx / xmx;
        let s = 1.0 / xmx.sqrt();
        let (mut r2, mut k2, mut a2) = (0.0, 0.0, 0.0);
        for (kv, mv) in kc.iter().zip(mc) {
            let r = kv - lambda * mv;
            let a = kv - sigma * mv;
            r2 += r * r;
            k2 += kv * kv;
            a2 += a * a;
        }
        let denom = k2.max(a2).sqrt();
        let res = if denom > 0.0 { r2.sqrt() / denom } else { 0.0 };
        worst = worst.max(res);
        eig.values[c] = lambda;
        // sign: the first (in natural order) largest component is positive
        let col = eig.vectors.col(c);
        let big = (0..n).map(|i| col[i].abs()).fold(0.0, f64::max);
        let first = (0..n)
            .map(|i| k_lower.inv.map(|v| v[i]).unwrap_or(i))
            .find(|&r| col[r].abs() >= (1.0 - 1e-6) * big)
            .unwrap_or(0);
        let s = if col[first] < 0.0 { -s } else { s };
        eig.vectors
            .col_as_slice_mut(c)
            .iter_mut()
            .for_each(|v| *v *= s);
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

/// Dense path: `K − σM = L Lᵀ`, `C = L⁻¹ M L⁻ᵀ`, `θ = 1/(λ − σ)`.
fn dense_lowest(
    k_lower: SymView<'_>,
    m_lower: SymView<'_>,
    sigma: f64,
    nev: usize,
) -> Result<Eigen, ReductionError> {
    let n = k_lower.n();
    let k = k_lower.dense();
    let m = m_lower.dense();
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
    let (s, u) = sym_eigen(c.as_ref())?;
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
        timings: EigenTimings::default(),
    })
}

/// Eigen-decomposition of a small dense symmetric matrix (lower triangle
/// read): values ascending, orthonormal vectors. Uses faer's tridiagonal QR
/// algorithm at every size: in faer 0.24.4 the divide-and-conquer path
/// (taken by `self_adjoint_eigen` from n = 128 on) returned eigenvectors with
/// relative residuals near 1e-3 on our reduced matrices.
pub(crate) fn sym_eigen(a: MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>), ReductionError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{
        self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors, SelfAdjointEvdParams,
    };
    let n = a.nrows();
    let mut params: faer::Spec<SelfAdjointEvdParams, f64> = Default::default();
    params.config.recursion_threshold = usize::MAX;
    let req = self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, Par::Seq, params);
    let mut mem = MemBuffer::try_new(req).map_err(|_| {
        ReductionError::LinearAlgebra("out of memory for a dense eigen solve".into())
    })?;
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    self_adjoint_evd(
        a,
        s.as_mut(),
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        params,
    )
    .map_err(|e| ReductionError::LinearAlgebra(format!("dense symmetric eigen solver ({e:?})")))?;
    let sv = s.column_vector();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| sv[x].total_cmp(&sv[y]));
    let values = order.iter().map(|&i| sv[i]).collect();
    let vectors = Mat::from_fn(n, n, |i, c| u[(i, order[c])]);
    Ok((values, vectors))
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

/// `A x` for a column-major block (through a row-major copy).
fn m_mul(a: SymView<'_>, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut xr = RowBlock::take(x.nrows(), x.ncols());
    xr.view_mut().copy_from(x);
    let mut z = RowBlock::take(x.nrows(), x.ncols());
    a.mul_rows(&xr, &mut z);
    let out = z.view().to_owned();
    xr.give_back();
    z.give_back();
    out
}

/// `(V_new, M V_new, R)`
type OrthoBlock = (Mat<f64>, Mat<f64>, Mat<f64>);

/// M-orthonormalise `w` (already orthogonal to `v_prev`): `w = V_new R`.
/// Returns `(V_new, M V_new, R)`. Directions of `w` below the rank threshold
/// are replaced by random vectors M-orthogonal to everything (their row of
/// `R` is zero).
fn orthonormalise(
    m_lower: SymView<'_>,
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
    let (d, q) = sym_eigen(g.as_ref())?;
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
            vnew.col_as_slice_mut(i).iter_mut().for_each(|v| *v /= s);
            mvnew.col_as_slice_mut(i).iter_mut().for_each(|v| *v /= s);
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
    m_lower: SymView<'_>,
    factor: &SpdFactor,
    sigma: f64,
    nev: usize,
    ncv: usize,
    opts: &LanczosOptions,
    par: Par,
) -> Result<Eigen, ReductionError> {
    let n = m_lower.n();
    let p = opts.block.max(1);
    let mut rng = Rng::new(opts.seed);
    let mut v = Mat::<f64>::zeros(n, ncv + p);
    let mut h = Mat::<f64>::zeros(ncv + p, ncv);
    // start block
    // random start block drawn in the natural numbering, so that the Krylov
    // space does not depend on the fill-reducing ordering
    let mut w0 = Mat::zeros(n, p);
    for c in 0..p {
        for i in 0..n {
            let r = m_lower.inv.map(|v| v[i]).unwrap_or(i);
            w0[(r, c)] = rng.next();
        }
    }
    let (b0, mut mv_cur, _) = orthonormalise(m_lower, v.subcols(0, 0), w0, 0.0, &mut rng, par)?;
    v.subcols_mut(0, p).copy_from(&b0);
    let mut cur = p;
    // first column of the block preceding the current one (the kept Ritz
    // vectors after a restart)
    let mut prev_start = 0usize;
    let mut restarts = 0usize;
    let mut solves = 0usize;
    let mut tm = EigenTimings::default();
    // number of Ritz vectors kept at a restart
    let keep = ncv - round_up((ncv - nev).div_ceil(2), p).min(ncv - nev).max(p);
    let keep = keep.min(ncv - p);
    loop {
        while cur < ncv + p {
            let j0 = cur - p;
            let t = Instant::now();
            let mut wr = RowBlock::take(n, p);
            wr.view_mut().copy_from(&mv_cur);
            factor.solve_rows(&mut wr);
            let mut w = wr.view().to_owned();
            wr.give_back();
            tm.solve += t.elapsed().as_secs_f64();
            solves += 1;
            // local block recurrence first (uses M V_j, known): removes the
            // large components along the current and previous blocks
            let t = Instant::now();
            let mut a_loc = Mat::zeros(p, p);
            matmul(
                a_loc.as_mut(),
                Accum::Replace,
                mv_cur.transpose(),
                w.as_ref(),
                1.0,
                par,
            );
            let a_loc = symmetrise(a_loc.as_ref());
            // scale of ‖W‖²_M for the rank test: ‖W_c‖_M ≥ |(V_c, W_c)_M| = |a_cc|
            let norm_ref = (0..p)
                .map(|c| a_loc[(c, c)].abs())
                .fold(0.0, f64::max)
                .powi(2);
            matmul(
                w.as_mut(),
                Accum::Add,
                v.subcols(j0, p),
                a_loc.as_ref(),
                -1.0,
                par,
            );
            let (ps, pw) = (prev_start, j0 - prev_start);
            let mut b_loc = Mat::zeros(pw, p);
            for c in 0..p {
                for r in 0..pw {
                    b_loc[(r, c)] = h[(j0 + c, ps + r)];
                }
            }
            if pw > 0 {
                matmul(
                    w.as_mut(),
                    Accum::Add,
                    v.subcols(ps, pw),
                    b_loc.as_ref(),
                    -1.0,
                    par,
                );
            }
            {
                let mut hb = h.as_mut().submatrix_mut(0, j0, cur, p);
                for jj in 0..p {
                    for ii in 0..p {
                        hb[(j0 + ii, jj)] += a_loc[(ii, jj)];
                    }
                    for ii in 0..pw {
                        hb[(ps + ii, jj)] += b_loc[(ii, jj)];
                    }
                }
            }
            tm.orthogonalise += t.elapsed().as_secs_f64();
            // one full re-orthogonalisation pass against the whole basis
            {
                let t = Instant::now();
                let z = m_mul(m_lower, w.as_ref());
                tm.mass += t.elapsed().as_secs_f64();
                let t = Instant::now();
                let c = gs_pass(v.subcols(0, cur), z.as_ref(), w.as_mut(), par);
                let mut hb = h.as_mut().submatrix_mut(0, j0, cur, p);
                for jj in 0..p {
                    for ii in 0..cur {
                        hb[(ii, jj)] += c[(ii, jj)];
                    }
                }
                tm.orthogonalise += t.elapsed().as_secs_f64();
            }
            let t = Instant::now();
            let (vn, mvn, r) =
                orthonormalise(m_lower, v.subcols(0, cur), w, norm_ref, &mut rng, par)?;
            v.subcols_mut(cur, p).copy_from(&vn);
            h.as_mut().submatrix_mut(cur, j0, p, p).copy_from(&r);
            mv_cur = mvn;
            prev_start = j0;
            cur += p;
            tm.orthogonalise += t.elapsed().as_secs_f64();
        }
        let t_rr = Instant::now();
        // Rayleigh-Ritz on the symmetric part of the projected matrix
        let t = symmetrise(h.submatrix(0, 0, ncv, ncv));
        let (theta, s) = sym_eigen(t.as_ref())?;
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
            tm.restart += t_rr.elapsed().as_secs_f64();
            // ascending λ = descending θ already
            return Ok(Eigen {
                values,
                vectors: phi,
                max_residual: 0.0,
                restarts,
                solves,
                timings: tm,
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
        prev_start = 0;
        restarts += 1;
        tm.restart += t_rr.elapsed().as_secs_f64();
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
    let (values, mut y) = sym_eigen(c.as_ref())?;
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        y.as_mut(),
        Par::Seq,
    );
    Ok((values, y))
}
