//! Linear solves on top of faer (dense LU, or sparse LU for large sparse systems), with
//! singularity reported instead of NaN.

use faer::prelude::Solve;
use faer::Mat;

/// A dense solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinearSolveError {
    /// The matrix is singular to working precision: dense, a pivot ratio below 1e-14; sparse,
    /// a backward error above 1e-10 after refinement.
    #[error("singular matrix (smallest/largest LU pivot, or backward error of a sparse solve = {ratio:.3e})")]
    Singular {
        /// Smallest over largest absolute pivot (dense), or the normwise backward error
        /// ‖b − A x‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞) (sparse).
        ratio: f64,
    },
    /// The matrix or right-hand side holds NaN or infinity.
    #[error("non-finite entries in a linear solve")]
    NonFinite,
}

/// Partial-pivoting LU of a square matrix, refused when it holds NaN or infinity or when the
/// ratio of its smallest to largest pivot is at most 1e-14 (singular to working precision).
pub fn checked_lu(
    a: &Mat<f64>,
) -> Result<faer::linalg::solvers::PartialPivLu<f64>, LinearSolveError> {
    let n = a.nrows();
    for j in 0..a.ncols() {
        for i in 0..n {
            if !a[(i, j)].is_finite() {
                return Err(LinearSolveError::NonFinite);
            }
        }
    }
    let lu = a.partial_piv_lu();
    let u = lu.U();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    for i in 0..n {
        let d = u[(i, i)].abs();
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let ratio = if hi > 0.0 { lo / hi } else { 0.0 };
    if n > 0 && (ratio.is_nan() || ratio <= 1e-14) {
        return Err(LinearSolveError::Singular { ratio });
    }
    Ok(lu)
}

/// A partial-pivoting LU kept packed in one matrix (L below the diagonal, U on and above it),
/// factorised in place. faer's `PartialPivLu` copies the input and then splits it into separate
/// L and U matrices; on the dense Newton matrices of the schur formulation (thousands of rows,
/// one factorisation per continuation point) those copies and their page faults cost a
/// quarter of the factorisation, hence this thin wrapper over faer's in-place kernels.
pub struct PackedLu<T: faer::traits::ComplexField> {
    lu: Mat<T>,
    perm: faer::perm::Perm<usize>,
}

impl<T: faer::traits::ComplexField> PackedLu<T> {
    /// Factorises `a` in place; refused when it holds NaN or infinity (`finite` says whether
    /// an entry is finite) or when the ratio of its smallest to largest pivot modulus
    /// (`modulus`) is at most 1e-14.
    pub fn new(
        mut a: Mat<T>,
        finite: impl Fn(&T) -> bool,
        modulus: impl Fn(&T) -> f64,
    ) -> Result<Self, LinearSolveError> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::linalg::lu::partial_pivoting::factor;
        let n = a.nrows();
        for j in 0..a.ncols() {
            for i in 0..n {
                if !finite(&a[(i, j)]) {
                    return Err(LinearSolveError::NonFinite);
                }
            }
        }
        let par = faer::get_global_parallelism();
        let mut fwd = vec![0usize; n];
        let mut bwd = vec![0usize; n];
        let mut mem = MemBuffer::new(factor::lu_in_place_scratch::<usize, T>(
            n,
            n,
            par,
            Default::default(),
        ));
        factor::lu_in_place(
            a.as_mut(),
            &mut fwd,
            &mut bwd,
            par,
            MemStack::new(&mut mem),
            Default::default(),
        );
        let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
        for i in 0..n {
            let d = modulus(&a[(i, i)]);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        let ratio = if hi > 0.0 { lo / hi } else { 0.0 };
        if n > 0 && (ratio.is_nan() || ratio <= 1e-14) {
            return Err(LinearSolveError::Singular { ratio });
        }
        let perm = faer::perm::Perm::new_checked(fwd.into_boxed_slice(), bwd.into_boxed_slice(), n);
        Ok(Self { lu: a, perm })
    }

    /// Solves A X = B in place (B with n rows).
    pub fn solve_in_place(&self, b: &mut Mat<T>) {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::linalg::lu::partial_pivoting::solve;
        let par = faer::get_global_parallelism();
        let n = self.lu.nrows();
        let mut mem = MemBuffer::new(solve::solve_in_place_scratch::<usize, T>(n, b.ncols(), par));
        solve::solve_in_place_with_conj(
            self.lu.as_ref(),
            self.lu.as_ref(),
            self.perm.as_ref(),
            faer::Conj::No,
            b.as_mut(),
            par,
            MemStack::new(&mut mem),
        );
    }

    /// A⁻¹ B.
    pub fn solve(&self, b: &Mat<T>) -> Mat<T> {
        let mut x = b.clone();
        self.solve_in_place(&mut x);
        x
    }
}

impl PackedLu<f64> {
    /// The sign of the factorised matrix's determinant (±1): the product of the signs of
    /// U's diagonal and of the row permutation's parity.
    pub fn det_sign(&self) -> f64 {
        let (fwd, _) = self.perm.as_ref().arrays();
        let diagonal = (0..self.lu.nrows()).map(|i| self.lu[(i, i)]);
        diagonal_sign(diagonal) * permutation_sign(fwd)
    }

    /// The same factors rounded to single precision, for fast approximate solves (half the
    /// memory traffic of the triangular solves, which are memory-bound on large factors).
    pub fn to_single(&self) -> PackedLu<f32> {
        let lu = Mat::from_fn(self.lu.nrows(), self.lu.ncols(), |i, j| {
            self.lu[(i, j)] as f32
        });
        PackedLu {
            lu,
            perm: self.perm.clone(),
        }
    }
}

/// The sign (±1) of a product of `values` (+1 for none; a zero counts as positive).
pub fn diagonal_sign(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(1.0, |s, v| if v < 0.0 { -s } else { s })
}

/// The sign (±1) of the permutation i ↦ `forward`\[i\]: its parity, from its cycles.
pub fn permutation_sign(forward: &[usize]) -> f64 {
    let mut seen = vec![false; forward.len()];
    let mut sign = 1.0;
    for start in 0..forward.len() {
        let mut i = start;
        let mut length = 0;
        while !seen[i] {
            seen[i] = true;
            i = forward[i];
            length += 1;
        }
        if length > 0 && length % 2 == 0 {
            sign = -sign;
        }
    }
    sign
}

/// [`PackedLu`] of a real matrix.
pub fn packed_lu(a: Mat<f64>) -> Result<PackedLu<f64>, LinearSolveError> {
    PackedLu::new(a, |v| v.is_finite(), |v| v.abs())
}

/// [`PackedLu`] of a complex matrix.
pub fn packed_complex_lu(a: Mat<faer::c64>) -> Result<PackedLu<faer::c64>, LinearSolveError> {
    PackedLu::new(a, |v| v.re.is_finite() && v.im.is_finite(), |v| v.norm())
}

/// Solves A x = b with partial-pivoting LU (faer). The matrix is not symmetric in general
/// (the harmonic-balance Jacobian couples cosine and sine blocks antisymmetrically).
pub fn solve_dense(a: &Mat<f64>, b: &[f64]) -> Result<Vec<f64>, LinearSolveError> {
    let n = a.nrows();
    debug_assert_eq!(b.len(), n);
    if b.iter().any(|x| !x.is_finite()) {
        return Err(LinearSolveError::NonFinite);
    }
    let lu = checked_lu(a)?;
    let rhs = Mat::from_fn(n, 1, |i, _| b[i]);
    let x = lu.solve(&rhs);
    let out: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    if out.iter().any(|v| !v.is_finite()) {
        return Err(LinearSolveError::NonFinite);
    }
    Ok(out)
}

/// Solves A x = b for A given as (row, col, value) triplets (duplicates summed): dense LU when
/// `sparse` is false, faer's sparse LU otherwise, refined up to two steps. A sparse solve whose
/// normwise backward error exceeds 1e-10 is reported singular (a zero pivot need not produce a
/// non-finite value).
pub fn solve_triplets(
    n: usize,
    entries: &[(usize, usize, f64)],
    b: &[f64],
    sparse: bool,
) -> Result<Vec<f64>, LinearSolveError> {
    if entries.iter().any(|e| !e.2.is_finite()) || b.iter().any(|v| !v.is_finite()) {
        return Err(LinearSolveError::NonFinite);
    }
    if !sparse {
        let mut a = Mat::<f64>::zeros(n, n);
        for &(i, j, v) in entries {
            a[(i, j)] += v;
        }
        return solve_dense(&a, b);
    }
    let t: Vec<faer::sparse::Triplet<usize, usize, f64>> = entries
        .iter()
        .map(|&(i, j, v)| faer::sparse::Triplet::new(i, j, v))
        .collect();
    let a = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t)
        .map_err(|_| LinearSolveError::NonFinite)?;
    let lu = a
        .sp_lu()
        .map_err(|_| LinearSolveError::Singular { ratio: 0.0 })?;
    let solve = |v: &[f64]| -> Vec<f64> {
        let x = lu.solve(Mat::from_fn(n, 1, |i, _| v[i]));
        (0..n).map(|i| x[(i, 0)]).collect()
    };
    let residual = |x: &[f64]| -> Vec<f64> {
        let mut r = b.to_vec();
        for &(i, j, v) in entries {
            r[i] -= v * x[j];
        }
        r
    };
    // Normwise backward error ‖b − A x‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞): FE matrices are ill-conditioned
    // (condition numbers of 10⁸-10¹⁰), so the relative residual of a correct solve can exceed
    // 1e-8 while the backward error stays at round-off; a singular matrix gives a large one
    // (or non-finite values).
    let mut row_sums = vec![0.0; n];
    for &(i, _, v) in entries {
        row_sums[i] += v.abs();
    }
    let a_norm = row_sums.iter().cloned().fold(0.0, f64::max);
    let max_abs = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let backward = |x: &[f64], r: &[f64]| {
        let d = a_norm * max_abs(x) + max_abs(b);
        if d > 0.0 {
            max_abs(r) / d
        } else {
            0.0
        }
    };
    let mut out = solve(b);
    // Up to two steps of iterative refinement.
    for step in 0..3 {
        if out.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::Singular { ratio: 0.0 });
        }
        let r = residual(&out);
        let e = backward(&out, &r);
        if e <= 1e-13 || step == 2 {
            if e.is_nan() || e > 1e-10 {
                return Err(LinearSolveError::Singular { ratio: e });
            }
            return Ok(out);
        }
        let d = solve(&r);
        out.iter_mut().zip(&d).for_each(|(x, d)| *x += d);
    }
    Ok(out)
}

/// Euclidean norm.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Dot product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_reports_singular() {
        let a = Mat::from_fn(2, 2, |i, j| [[2.0, 1.0], [1.0, 3.0]][i][j]);
        let x = solve_dense(&a, &[3.0, 5.0]).unwrap();
        assert!((x[0] - 0.8).abs() < 1e-14 && (x[1] - 1.4).abs() < 1e-14);
        let s = Mat::from_fn(2, 2, |i, j| [[1.0, 2.0], [2.0, 4.0]][i][j]);
        assert!(matches!(
            solve_dense(&s, &[1.0, 1.0]),
            Err(LinearSolveError::Singular { .. })
        ));
    }

    #[test]
    fn triplet_solves_agree_and_report_singular() {
        let t = [
            (0, 0, 2.0),
            (0, 1, 1.0),
            (1, 0, 1.0),
            (1, 1, 2.0),
            (1, 1, 1.0),
        ];
        let xd = solve_triplets(2, &t, &[3.0, 5.0], false).unwrap();
        let xs = solve_triplets(2, &t, &[3.0, 5.0], true).unwrap();
        assert!((xd[0] - 0.8).abs() < 1e-14 && (xd[1] - 1.4).abs() < 1e-14);
        assert!((xs[0] - 0.8).abs() < 1e-14 && (xs[1] - 1.4).abs() < 1e-14);
        let singular = [(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 4.0)];
        assert!(solve_triplets(2, &singular, &[1.0, 1.0], true).is_err());
    }

    #[test]
    fn packed_lu_solves_real_and_complex_systems_and_refuses_singular_ones() {
        let n = 40;
        let a = Mat::from_fn(n, n, |i, j| {
            ((i * 7 + j * 3) % 11) as f64 - 5.0 + if i == j { 30.0 } else { 0.0 }
        });
        let b = Mat::from_fn(n, 2, |i, j| (i + 3 * j) as f64 - 10.0);
        let lu = packed_lu(a.clone()).unwrap();
        let x = lu.solve(&b);
        let r = &a * &x - &b;
        let rn = (0..n)
            .flat_map(|i| (0..2).map(move |j| (i, j)))
            .fold(0.0_f64, |m, (i, j)| m.max(r[(i, j)].abs()));
        assert!(rn < 1e-11, "real residual {rn:e}");
        // Single-precision factors: about 1e-7 relative.
        let single = lu.to_single();
        let mut xs = Mat::from_fn(n, 1, |i, _| b[(i, 0)] as f32);
        single.solve_in_place(&mut xs);
        for i in 0..n {
            assert!((xs[(i, 0)] as f64 - x[(i, 0)]).abs() <= 1e-5 * x[(i, 0)].abs().max(1e-3));
        }
        let ac = Mat::from_fn(n, n, |i, j| {
            faer::c64::new(a[(i, j)], ((i + 2 * j) % 5) as f64 - 2.0)
        });
        let bc = Mat::from_fn(n, 1, |i, _| faer::c64::new(i as f64, 1.0 - i as f64));
        let xc = packed_complex_lu(ac.clone()).unwrap().solve(&bc);
        let rc = &ac * &xc - &bc;
        for i in 0..n {
            assert!(
                rc[(i, 0)].norm() < 1e-11,
                "complex residual {}",
                rc[(i, 0)].norm()
            );
        }
        let singular = Mat::from_fn(2, 2, |i, j| [[1.0, 2.0], [2.0, 4.0]][i][j]);
        assert!(matches!(
            packed_lu(singular),
            Err(LinearSolveError::Singular { .. })
        ));
        let nan = Mat::from_fn(2, 2, |i, j| if i == j { f64::NAN } else { 1.0 });
        assert!(matches!(packed_lu(nan), Err(LinearSolveError::NonFinite)));
    }
}
