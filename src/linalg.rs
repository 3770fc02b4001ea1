//! Small dense linear solves on top of faer, with singularity reported instead of NaN.

use faer::prelude::Solve;
use faer::Mat;

/// A dense solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinearSolveError {
    /// The matrix is singular to working precision (pivot ratio below 1e-14).
    #[error("singular matrix (smallest/largest LU pivot = {ratio:.3e})")]
    Singular {
        /// Smallest over largest absolute pivot.
        ratio: f64,
    },
    /// The matrix or right-hand side holds NaN or infinity.
    #[error("non-finite entries in a linear solve")]
    NonFinite,
}

/// Solves A x = b with partial-pivoting LU (faer). The matrix is not symmetric in general
/// (the harmonic-balance Jacobian couples cosine and sine blocks antisymmetrically).
pub fn solve_dense(a: &Mat<f64>, b: &[f64]) -> Result<Vec<f64>, LinearSolveError> {
    let n = a.nrows();
    debug_assert_eq!(b.len(), n);
    if b.iter().any(|x| !x.is_finite()) {
        return Err(LinearSolveError::NonFinite);
    }
    for j in 0..n {
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
    if ratio.is_nan() || ratio <= 1e-14 {
        return Err(LinearSolveError::Singular { ratio });
    }
    let rhs = Mat::from_fn(n, 1, |i, _| b[i]);
    let x = lu.solve(&rhs);
    let out: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    if out.iter().any(|v| !v.is_finite()) {
        return Err(LinearSolveError::NonFinite);
    }
    Ok(out)
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
}
