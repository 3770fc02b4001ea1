//! The per-harmonic elimination of z = (w, x_o) from the modes of the glued structure, computed
//! once per harmonic-balance system (each curve, limit case and point solver builds its own), in
//! place of a dense LU of Ã_zz at every frequency (the `schur-lowrank`
//! formulation).
//!
//! Ã_zz(s) = K_zz − s²M_zz + i s C_zz (s = hω) is the structure with every contact glued. Solve
//! the real symmetric generalized eigenproblem M_zz φ = μ K_zz φ once (Cholesky of K_zz, then a
//! self-adjoint eigendecomposition), with Φ stiffness-normalised: Φᵀ K_zz Φ = I,
//! Φᵀ M_zz Φ = diag(μ), μ_k = 1/ω_k². Every mode is kept (no truncation), so this is the exact
//! elimination, not a reduction; normalising on K (not on M) keeps Φ Φᵀ = K_zz⁻¹ as accurate as
//! a Cholesky solve and the lowest modes' μ accurate to rounding (with M-normalised modes the
//! static Schur complement of the reduced blade pair lost five digits). Without damping, per
//! harmonic
//!
//! ```text
//! A₀ = K − s²M,   G = A₀_qz Φ = (K_qzΦ) − s² (M_qzΦ),   Δ = I − s² diag(μ)
//! S₀ = A₀_qq − G Δ⁻¹ Gᵀ                                    (real, 2·n_q²·n_z flops)
//! ```
//!
//! against about (8/3)·n_z³ + 8·n_z²·n_q + 8·n_q²·n_z for the complex LU, its solve and the
//! product. The damping of a Craig-Bampton model with modal damping on its fixed-interface modes
//! is of low rank (C = V D Vᵀ, r = the number of damped modes): with U = V and W = i s D the
//! Schur complement of A₀ + U W Uᵀ is that of A₀ plus a rank-r term (eliminate z, then the
//! auxiliary t = W Uᵀ y of the bordered matrix [[A₀, U], [Uᵀ, −W⁻¹]]):
//!
//! ```text
//! Y = Φᵀ U_z,   Ũ = U_q − G Δ⁻¹ Y,   C_r = W⁻¹ + Yᵀ Δ⁻¹ Y   (r × r, complex)
//! S_h = S₀ + Ũ C_r⁻¹ Ũᵀ
//! ```
//!
//! and Ã_zz⁻¹ = Φ (Δ⁻¹ − Δ⁻¹ Y C_r⁻¹ Yᵀ Δ⁻¹) Φᵀ (Woodbury) for the solves. Δ_k = 1 − s²μ_k is
//! not damped: close to a glued mode (|Δ_k| below [`GAP`] of max(1, s²μ_k)) the two terms of
//! S_h would cancel, and that harmonic is eliminated by LU instead. A scene whose damping is not
//! of low rank (Rayleigh damping on every DOF) or whose glued structure is not held (K_zz not
//! positive definite) keeps the LU elimination for every harmonic ([`ModalBasis::new`] returns
//! None).

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{c64, Accum, Mat, MatRef, Side};

use crate::numerics::linalg::{packed_complex_lu, LinearSolveError, PackedLu};

/// A harmonic is eliminated by LU instead of modes when some glued mode's |1 − s²μ_k| is below
/// this fraction of max(1, s²μ_k) (see the module docs): the cancellation then amplifies
/// rounding by at most about 2ζ/GAP (2·10³ at 0.1 % damping).
pub const GAP: f64 = 1e-6;

/// The damping is used in low-rank form when its rank is at most this fraction of n_q (above,
/// the rank-r terms cost as much as the elimination they replace).
pub const MAX_DAMPING_RANK_FRACTION: f64 = 0.25;

/// Eigenvalues of the damping matrix below this fraction of the largest are rounding.
const RANK_TOLERANCE: f64 = 1e-13;

/// The modes of the glued structure and the products that the per-harmonic elimination needs,
/// computed once per harmonic-balance system (on its first factorisation).
#[derive(Debug)]
pub(super) struct ModalBasis {
    /// Φ (n_z × n_z), stiffness-normalised modes of (K_zz, M_zz): Φᵀ K_zz Φ = I.
    phi: Mat<f64>,
    /// μ_k = 1/ω_k² (s²/rad²): Φᵀ M_zz Φ = diag(μ).
    mu: Vec<f64>,
    /// K_qz Φ and M_qz Φ (n_q × n_z).
    k_qz_phi: Mat<f64>,
    m_qz_phi: Mat<f64>,
    /// K_qq, M_qq.
    k_qq: Mat<f64>,
    m_qq: Mat<f64>,
    /// C = V D Vᵀ: V on the q rows (n_q × r), Y = Φᵀ V_z (n_z × r) and D; None without damping.
    damping: Option<(Mat<f64>, Mat<f64>, Vec<f64>)>,
}

/// Largest |A − Aᵀ| over largest |A|.
fn asymmetry(a: &Mat<f64>) -> f64 {
    let (mut diff, mut big) = (0.0_f64, 0.0_f64);
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            big = big.max(a[(i, j)].abs());
            diff = diff.max((a[(i, j)] - a[(j, i)]).abs());
        }
    }
    if big > 0.0 {
        diff / big
    } else {
        0.0
    }
}

impl ModalBasis {
    /// The basis of K, M, C in y = (q, z) coordinates with the first `n_q` rows relative:
    /// None when the matrices are not symmetric, K_zz is not positive definite, the damping's
    /// rank exceeds [`MAX_DAMPING_RANK_FRACTION`] of n_q, or the decomposition fails.
    pub(super) fn new(k: &Mat<f64>, m: &Mat<f64>, c: &Mat<f64>, n_q: usize) -> Option<Self> {
        let n = k.nrows();
        if n == n_q || [k, m, c].iter().any(|a| asymmetry(a) > 1e-12) {
            return None;
        }
        let n_z = n - n_q;
        let par = faer::get_global_parallelism();
        let block = |a: &Mat<f64>, r: std::ops::Range<usize>, col: std::ops::Range<usize>| {
            a.as_ref()
                .subrows(r.start, r.len())
                .subcols(col.start, col.len())
                .to_owned()
        };
        // Stiffness-normalised: K_zz = L Lᵀ, B = L⁻¹ M_zz L⁻ᵀ = V diag(μ) Vᵀ, Φ = L⁻ᵀ V. Then
        // Φᵀ K_zz Φ = I and Φ Φᵀ = K_zz⁻¹ as accurately as the Cholesky factor; the eigenvalues
        // μ = 1/ω_k² are accurate to rounding of the largest, the lowest modes', which dominate
        // the dynamics (a mass normalisation would lose the relative accuracy of those).
        let k_zz = block(k, n_q..n, n_q..n);
        let llt = k_zz.llt(Side::Lower).ok()?;
        let l = llt.L();
        // B = L⁻¹ M_zz L⁻ᵀ: X = L⁻¹ M_zz, then L⁻¹ Xᵀ.
        let mut x = block(m, n_q..n, n_q..n);
        solve_lower_triangular_in_place(l, x.as_mut(), par);
        let mut a = x.transpose().to_owned();
        solve_lower_triangular_in_place(l, a.as_mut(), par);
        let a = Mat::from_fn(n_z, n_z, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let eig = a.self_adjoint_eigen(Side::Lower).ok()?;
        let mu: Vec<f64> = (0..n_z).map(|i| eig.S()[i]).collect();
        let mut phi = eig.U().to_owned();
        solve_upper_triangular_in_place(l.transpose(), phi.as_mut(), par);
        if phi.as_ref().norm_max().is_nan() {
            return None;
        }
        let k_qz_phi = block(k, 0..n_q, n_q..n) * &phi;
        let m_qz_phi = block(m, 0..n_q, n_q..n) * &phi;
        let damping = match low_rank(c) {
            Some((_, d)) if d.is_empty() => None,
            Some((v, d)) if (d.len() as f64) <= MAX_DAMPING_RANK_FRACTION * n_q as f64 => {
                let v_q = v.as_ref().subrows(0, n_q).to_owned();
                let y = phi.transpose() * v.as_ref().subrows(n_q, n_z);
                Some((v_q, y, d))
            }
            _ => return None,
        };
        Some(Self {
            phi,
            mu,
            k_qz_phi,
            m_qz_phi,
            k_qq: block(k, 0..n_q, 0..n_q),
            m_qq: block(m, 0..n_q, 0..n_q),
            damping,
        })
    }

    /// Number of glued modes n_z.
    pub(super) fn n_modes(&self) -> usize {
        self.mu.len()
    }

    /// Rank of the damping (0 without damping).
    #[cfg(test)]
    pub(super) fn damping_rank(&self) -> usize {
        self.damping.as_ref().map_or(0, |d| d.2.len())
    }

    /// The elimination of one harmonic at s = hω (rad/s), `damped` for a cosine/sine pair
    /// (whose damping term acts), None when s is within [`GAP`] of a glued mode.
    pub(super) fn harmonic(
        &self,
        s: f64,
        damped: bool,
    ) -> Result<Option<ModalHarmonic>, LinearSolveError> {
        let s2 = s * s;
        let delta: Vec<f64> = self.mu.iter().map(|m| 1.0 - s2 * m).collect();
        let near = self
            .mu
            .iter()
            .zip(&delta)
            .any(|(m, d)| d.abs() < GAP * (s2 * m).max(1.0));
        if near {
            return Ok(None);
        }
        let (n_q, n_z) = (self.k_qq.nrows(), self.n_modes());
        let g = Mat::from_fn(n_q, n_z, |i, j| {
            self.k_qz_phi[(i, j)] - s2 * self.m_qz_phi[(i, j)]
        });
        let g_scaled = Mat::from_fn(n_q, n_z, |i, j| g[(i, j)] / delta[j]);
        let mut s0 = Mat::from_fn(n_q, n_q, |i, j| self.k_qq[(i, j)] - s2 * self.m_qq[(i, j)]);
        let par = faer::get_global_parallelism();
        matmul(
            s0.as_mut(),
            Accum::Add,
            g_scaled.as_ref(),
            g.transpose(),
            -1.0,
            par,
        );
        let damping = match (&self.damping, damped && s != 0.0) {
            (Some((v_q, y, d)), true) => {
                // Ũ = V_q − G Δ⁻¹ Y, C_r = W⁻¹ + Yᵀ Δ⁻¹ Y with W = i s D.
                let u = v_q - &g_scaled * y;
                let r = d.len();
                let cap = Mat::from_fn(r, r, |i, j| {
                    let re: f64 = (0..n_z).map(|k| y[(k, i)] * y[(k, j)] / delta[k]).sum();
                    // 1/(i s d) = −i/(s d) on the diagonal.
                    let im = if i == j { -1.0 / (s * d[i]) } else { 0.0 };
                    c64::new(re, im)
                });
                let cap = packed_complex_lu(cap)?;
                Some((u, cap))
            }
            _ => None,
        };
        let schur = match &damping {
            None if !damped => ModalSchur::Real(s0),
            None => ModalSchur::Complex(Mat::from_fn(n_q, n_q, |i, j| c64::new(s0[(i, j)], 0.0))),
            Some((u, cap)) => {
                // S = S₀ + Ũ C_r⁻¹ Ũᵀ.
                let mut t = Mat::from_fn(u.ncols(), n_q, |i, j| c64::new(u[(j, i)], 0.0));
                cap.solve_in_place(&mut t);
                let tr = Mat::from_fn(t.nrows(), t.ncols(), |i, j| t[(i, j)].re);
                let ti = Mat::from_fn(t.nrows(), t.ncols(), |i, j| t[(i, j)].im);
                let re = &s0 + u * &tr;
                let im = u * &ti;
                ModalSchur::Complex(Mat::from_fn(n_q, n_q, |i, j| {
                    c64::new(re[(i, j)], im[(i, j)])
                }))
            }
        };
        Ok(Some(ModalHarmonic {
            s,
            delta,
            g,
            damping: damping.map(|(_, cap)| cap),
            schur,
        }))
    }

    /// Φᵀ b for a complex b (n_z rows): the modal coordinates of a z right-hand side.
    pub(super) fn to_modes(&self, b: &Mat<c64>) -> Mat<c64> {
        complex_product(self.phi.transpose(), b)
    }

    /// Φ μ: the z displacements of modal coordinates μ.
    pub(super) fn displacements_of_modes(&self, mu: &Mat<c64>) -> Mat<c64> {
        complex_product(self.phi.as_ref(), mu)
    }
}

/// Real matrix times complex matrix.
fn complex_product(a: MatRef<'_, f64>, b: &Mat<c64>) -> Mat<c64> {
    let part = |f: fn(c64) -> f64| Mat::from_fn(b.nrows(), b.ncols(), |i, j| f(b[(i, j)]));
    let re = a * part(|v| v.re);
    let im = a * part(|v| v.im);
    Mat::from_fn(re.nrows(), re.ncols(), |i, j| {
        c64::new(re[(i, j)], im[(i, j)])
    })
}

/// C = V D Vᵀ from the eigendecomposition of C on the rows and columns where it is not zero,
/// dropping eigenvalues below [`RANK_TOLERANCE`] of the largest (V: n × r, D: r).
fn low_rank(c: &Mat<f64>) -> Option<(Mat<f64>, Vec<f64>)> {
    let n = c.nrows();
    let support: Vec<usize> = (0..n)
        .filter(|&i| (0..n).any(|j| c[(i, j)] != 0.0))
        .collect();
    if support.is_empty() {
        return Some((Mat::zeros(n, 0), Vec::new()));
    }
    let sub = Mat::from_fn(support.len(), support.len(), |i, j| {
        0.5 * (c[(support[i], support[j])] + c[(support[j], support[i])])
    });
    let eig = sub.self_adjoint_eigen(Side::Lower).ok()?;
    let values: Vec<f64> = (0..support.len()).map(|i| eig.S()[i]).collect();
    let largest = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let kept: Vec<usize> = (0..values.len())
        .filter(|&i| values[i].abs() > RANK_TOLERANCE * largest)
        .collect();
    let mut v = Mat::zeros(n, kept.len());
    for (col, &e) in kept.iter().enumerate() {
        for (row, &dof) in support.iter().enumerate() {
            v[(dof, col)] = eig.U()[(row, e)];
        }
    }
    Some((v, kept.iter().map(|&i| values[i]).collect()))
}

/// The Schur complement of one harmonic: real without damping (or for a single block), else
/// complex (on x_cos − i x_sin).
pub(super) enum ModalSchur {
    Real(Mat<f64>),
    Complex(Mat<c64>),
}

/// One harmonic's modal elimination: what its solves need, and S_h.
pub(super) struct ModalHarmonic {
    /// s = hω (rad/s).
    s: f64,
    /// Δ = Λ − s².
    delta: Vec<f64>,
    /// G = (K_qz − s² M_qz) Φ.
    g: Mat<f64>,
    /// LU of C_r = W⁻¹ + Yᵀ Δ⁻¹ Y when the damping acts.
    damping: Option<PackedLu<c64>>,
    pub(super) schur: ModalSchur,
}

impl ModalHarmonic {
    /// (Φᵀ Ã_zz Φ)⁻¹ μ = Δ⁻¹ μ − Δ⁻¹ Y C_r⁻¹ Yᵀ Δ⁻¹ μ (modal coordinates).
    fn modal_inverse(&self, basis: &ModalBasis, mu: &Mat<c64>) -> Mat<c64> {
        let mut out = Mat::from_fn(mu.nrows(), mu.ncols(), |i, j| mu[(i, j)] / self.delta[i]);
        if let (Some(cap), Some((_, y, _))) = (&self.damping, &basis.damping) {
            let mut t = complex_product(y.transpose(), &out);
            cap.solve_in_place(&mut t);
            let yt = complex_product(y.as_ref(), &t);
            for j in 0..out.ncols() {
                for i in 0..out.nrows() {
                    out[(i, j)] -= yt[(i, j)] / self.delta[i];
                }
            }
        }
        out
    }

    /// Ã_qz Φ m = G m + i s V_q D Yᵀ m (damping when it acts).
    fn coupling(&self, basis: &ModalBasis, m: &Mat<c64>) -> Mat<c64> {
        let mut out = complex_product(self.g.as_ref(), m);
        if let (Some(_), Some((v_q, y, d))) = (&self.damping, &basis.damping) {
            let mut t = complex_product(y.transpose(), m);
            scale_damping(&mut t, self.s, d);
            out += complex_product(v_q.as_ref(), &t);
        }
        out
    }

    /// Φᵀ Ã_zq y_q = Gᵀ y_q + i s Y D V_qᵀ y_q.
    fn coupling_transposed(&self, basis: &ModalBasis, y_q: &Mat<c64>) -> Mat<c64> {
        let mut out = complex_product(self.g.transpose(), y_q);
        if let (Some(_), Some((v_q, y, d))) = (&self.damping, &basis.damping) {
            let mut t = complex_product(v_q.transpose(), y_q);
            scale_damping(&mut t, self.s, d);
            out += complex_product(y.as_ref(), &t);
        }
        out
    }

    /// The first pass of a solve with right-hand side (b_q, b_z): returns b_q − Ã_qz Ã_zz⁻¹ b_z
    /// and the modal coordinates m = Φ⁻¹ Ã_zz⁻¹ b_z kept for [`Self::back_substitute`].
    pub(super) fn reduce(
        &self,
        basis: &ModalBasis,
        b_q: Mat<c64>,
        b_z: &Mat<c64>,
    ) -> (Mat<c64>, Mat<c64>) {
        let m = self.modal_inverse(basis, &basis.to_modes(b_z));
        let r_q = b_q - self.coupling(basis, &m);
        (r_q, m)
    }

    /// y_z = Ã_zz⁻¹ (b_z − Ã_zq y_q) = Φ (m − (Φᵀ Ã_zz Φ)⁻¹ Φᵀ Ã_zq y_q).
    pub(super) fn back_substitute(
        &self,
        basis: &ModalBasis,
        m: Mat<c64>,
        y_q: &Mat<c64>,
    ) -> Mat<c64> {
        let correction = self.modal_inverse(basis, &self.coupling_transposed(basis, y_q));
        basis.displacements_of_modes(&(m - correction))
    }
}

/// t ← i s D t (rows scaled).
fn scale_damping(t: &mut Mat<c64>, s: f64, d: &[f64]) {
    for j in 0..t.ncols() {
        for (i, &di) in d.iter().enumerate() {
            t[(i, j)] *= c64::new(0.0, s * di);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use faer::{c64, Mat};

    use crate::hbm::schur::elimination::SchurRef;
    use crate::hbm::schur::RelativeCoordinates;
    use crate::model::matrix::StructuralMatrix;
    use crate::model::Problem;
    use crate::study::scaling::{self, ModelSize};

    /// The reduced 2D blade pair with 5 pairs per side, 8 fixed-interface modes with 0.2 %
    /// modal damping (C of rank 8), harmonics 0 to 3.
    fn blade_pair() -> Problem {
        let dir = tempfile::tempdir().unwrap();
        let size = ModelSize {
            contact_refine: 2,
            ..ModelSize::uniform(false, 2)
        };
        let mut p = scaling::reduced_problem(size, 8, dir.path()).unwrap();
        p.harmonics = vec![0, 1, 2, 3];
        p
    }

    /// Largest |S_modal − S_lu| over largest |S_lu| over every harmonic at ω, and the number
    /// of harmonics eliminated from modes.
    fn modal_against_lu(p: &Problem, omega: f64) -> (f64, usize) {
        let coords = Arc::new(RelativeCoordinates::new(p, &p.unknown_harmonics()).unwrap());
        assert!(coords.has_modal_elimination());
        let lu = coords.eliminated_at(omega, false).unwrap();
        let modal = coords.eliminated_at(omega, true).unwrap();
        let (mut diff, mut scale, mut modes) = (0.0_f64, 0.0_f64, 0);
        for (a, b) in lu.iter().zip(modal.iter()) {
            modes += usize::from(matches!(
                b.elimination,
                crate::hbm::schur::elimination::Elimination::Modal(_)
            ));
            let as_complex = |s: SchurRef<'_>| match s {
                SchurRef::Real(m) => {
                    Mat::from_fn(m.nrows(), m.ncols(), |i, j| c64::new(m[(i, j)], 0.0))
                }
                SchurRef::Complex(m) => m.clone(),
            };
            let (sa, sb) = (as_complex(a.schur()), as_complex(b.schur()));
            for j in 0..sa.ncols() {
                for i in 0..sa.nrows() {
                    scale = scale.max(sa[(i, j)].norm());
                    diff = diff.max((sa[(i, j)] - sb[(i, j)]).norm());
                }
            }
        }
        (diff / scale, modes)
    }

    #[test]
    fn schur_complements_from_modes_equal_the_lu_elimination_with_low_rank_damping() {
        let p = blade_pair();
        for hz in [150.0, 850.0, 2400.0] {
            let (rel, modes) = modal_against_lu(&p, 2.0 * std::f64::consts::PI * hz);
            assert_eq!(modes, 4, "every harmonic from modes at {hz} Hz");
            assert!(rel <= 1e-10, "{hz} Hz: {rel:e}");
        }
    }

    #[test]
    fn schur_complements_from_modes_equal_the_lu_elimination_without_damping() {
        let mut p = blade_pair();
        p.model.damping = StructuralMatrix::zeros(p.model.n_dofs(), false);
        for hz in [150.0, 850.0, 2400.0] {
            let (rel, modes) = modal_against_lu(&p, 2.0 * std::f64::consts::PI * hz);
            assert_eq!(modes, 4);
            assert!(rel <= 1e-10, "{hz} Hz: {rel:e}");
        }
    }

    #[test]
    fn the_damping_is_split_into_its_rank() {
        let p = blade_pair();
        let coords = RelativeCoordinates::new(&p, &p.unknown_harmonics()).unwrap();
        let basis = coords.modal_basis().unwrap();
        // 8 damped fixed-interface modes per reduction (one reduced body).
        let damped = (0..p.model.n_dofs())
            .filter(|&i| p.model.damping.get(i, i) != 0.0)
            .count();
        assert!(damped > 0);
        assert_eq!(basis.damping_rank(), damped);
    }

    #[test]
    fn full_rank_damping_keeps_the_lu_elimination() {
        let mut p = blade_pair();
        // Rayleigh damping on every DOF: C = 1e-6·K is of full rank.
        let n = p.model.n_dofs();
        let k = p.model.stiffness.to_dense();
        let entries: Vec<(usize, usize, f64)> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|&(i, j)| k[(i, j)] != 0.0)
            .map(|(i, j)| (i, j, 1e-6 * k[(i, j)]))
            .collect();
        p.model.damping = StructuralMatrix::sparse_from_triplets(n, &entries);
        let coords = RelativeCoordinates::new(&p, &p.unknown_harmonics()).unwrap();
        assert!(!coords.has_modal_elimination());
        let eliminated = coords.eliminated_at(1000.0, true).unwrap();
        assert!(eliminated.iter().all(|e| !matches!(
            e.elimination,
            crate::hbm::schur::elimination::Elimination::Modal(_)
        )));
    }

    /// Solves J x = b with the schur-lowrank factor (modal elimination) and returns the relative
    /// residual ‖J x − b‖/‖b‖, with every contact stuck (kt = kn = `stiffness` on every block).
    fn solve_residual(
        p: &Problem,
        omega: f64,
        stiffness: f64,
        solver: crate::hbm::schur::ReducedSolver,
    ) -> f64 {
        use crate::numerics::ImplicitFactor;
        let coords = Arc::new(RelativeCoordinates::new(p, &p.unknown_harmonics()).unwrap());
        let (offsets, nb) = (coords.value_offsets().to_vec(), coords.n_blocks());
        let mut values = vec![0.0; *offsets.last().unwrap()];
        for (c, &offset) in offsets.iter().enumerate().take(coords.n_contacts()) {
            let k = coords.contact_rows(c);
            for j in 0..nb {
                for a in 0..k {
                    values[offset + ((j * nb + j) * k + a) * k + a] = stiffness;
                }
            }
        }
        let n = coords.n_dofs() * nb;
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 101) as f64 - 50.0).collect();
        let f = coords.factor(omega, &values, solver).unwrap();
        let x = f.solve(&b, false);
        let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
        coords.mul_add(omega, &values, 1.0, &x, &mut r);
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        norm(&r) / norm(&b)
    }

    #[test]
    fn a_solve_through_the_modal_elimination_solves_the_jacobian() {
        let mut p = blade_pair();
        for (harmonics, hz) in [
            (vec![0], 0.0),
            (vec![0, 1, 2, 3], 850.0),
            (vec![1, 3], 400.0),
        ] {
            p.harmonics = harmonics.clone();
            let omega = 2.0 * std::f64::consts::PI * hz;
            let lu = solve_residual(&p, omega, 2.0e7, crate::hbm::schur::ReducedSolver::Dense);
            let rel = solve_residual(
                &p,
                omega,
                2.0e7,
                crate::hbm::schur::ReducedSolver::Structured,
            );
            // As accurate as the LU elimination (4e-14 at the static harmonic).
            assert!(lu <= 1e-12, "harmonics {harmonics:?}: LU residual {lu:e}");
            assert!(rel <= 1e-12, "harmonics {harmonics:?}: residual {rel:e}");
        }
    }
}
