//! Structural matrices (M, C, K) in dense or sparse storage.
//!
//! Lumped and reduced models are small and dense; unreduced FE models are large and sparse.
//! [`StructuralMatrix`] holds either, with the few operations the solver needs: products,
//! iteration over non-zeros (to build Jacobian patterns), entry lookup, conversion. Sparse
//! matrices are faer `SparseColMat<usize, f64>` in full (both triangles) storage.

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

/// A square real matrix, dense or sparse (full storage).
#[derive(Debug, Clone)]
pub enum StructuralMatrix {
    /// Dense storage.
    Dense(Mat<f64>),
    /// Compressed sparse column storage, both triangles stored.
    Sparse(SparseColMat<usize, f64>),
}

impl StructuralMatrix {
    /// n × n zeros in the given storage.
    pub fn zeros(n: usize, sparse: bool) -> Self {
        if sparse {
            StructuralMatrix::Sparse(
                SparseColMat::try_new_from_triplets(n, n, &[])
                    .expect("an empty pattern is always valid"),
            )
        } else {
            StructuralMatrix::Dense(Mat::zeros(n, n))
        }
    }

    /// Sparse matrix from (row, col, value) triplets; duplicates are summed.
    ///
    /// # Panics
    /// If an index is out of range (a programming error: callers check user indices).
    #[track_caller]
    pub fn sparse_from_triplets(n: usize, entries: &[(usize, usize, f64)]) -> Self {
        let t: Vec<Triplet<usize, usize, f64>> = entries
            .iter()
            .map(|&(row, col, val)| Triplet::new(row, col, val))
            .collect();
        StructuralMatrix::Sparse(
            SparseColMat::try_new_from_triplets(n, n, &t).expect("triplet indices in range"),
        )
    }

    /// Dimension n.
    pub fn n(&self) -> usize {
        match self {
            StructuralMatrix::Dense(m) => m.nrows(),
            StructuralMatrix::Sparse(s) => s.nrows(),
        }
    }

    /// Whether the storage is sparse.
    pub fn is_sparse(&self) -> bool {
        matches!(self, StructuralMatrix::Sparse(_))
    }

    /// Calls `f(row, col, value)` for every stored non-zero (dense: every non-zero entry).
    pub fn for_each_nonzero(&self, mut f: impl FnMut(usize, usize, f64)) {
        match self {
            StructuralMatrix::Dense(m) => {
                for j in 0..m.ncols() {
                    for i in 0..m.nrows() {
                        let v = m[(i, j)];
                        if v != 0.0 {
                            f(i, j, v);
                        }
                    }
                }
            }
            StructuralMatrix::Sparse(s) => {
                let col_ptr = s.symbolic().col_ptr();
                let rows = s.symbolic().row_idx();
                let vals = s.val();
                for j in 0..s.ncols() {
                    for k in col_ptr[j]..col_ptr[j + 1] {
                        if vals[k] != 0.0 {
                            f(rows[k], j, vals[k]);
                        }
                    }
                }
            }
        }
    }

    /// Non-zero entries as triplets.
    pub fn triplets(&self) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::new();
        self.for_each_nonzero(|i, j, v| out.push((i, j, v)));
        out
    }

    /// M X for X holding `blocks` vectors of length n one after the other (harmonic-major
    /// coefficients); the result is n × blocks. Dense matrices use one matrix product, so M is
    /// read once for all blocks (the harmonic-balance residual applies K, M and C to every
    /// coefficient block).
    pub fn mul_blocks(&self, x: &[f64], blocks: usize) -> Mat<f64> {
        let n = self.n();
        debug_assert_eq!(x.len(), n * blocks);
        let xm = faer::MatRef::from_column_major_slice(x, n, blocks);
        match self {
            StructuralMatrix::Dense(m) => {
                let mut out = Mat::zeros(n, blocks);
                faer::linalg::matmul::matmul(
                    out.as_mut(),
                    faer::Accum::Replace,
                    m.as_ref(),
                    xm,
                    1.0,
                    faer::Par::Seq,
                );
                out
            }
            StructuralMatrix::Sparse(_) => {
                let mut out = Mat::zeros(n, blocks);
                for j in 0..blocks {
                    let col = out.col_mut(j).try_as_col_major_mut().expect("owned column");
                    self.mul_add(1.0, &x[j * n..(j + 1) * n], col.as_slice_mut());
                }
                out
            }
        }
    }

    /// y += α A x.
    pub fn mul_add(&self, alpha: f64, x: &[f64], y: &mut [f64]) {
        if alpha == 0.0 {
            return;
        }
        match self {
            StructuralMatrix::Dense(m) => {
                // y += α M x as one faer matrix-vector product (vectorised, M read once).
                let xs = faer::ColRef::from_slice(x);
                let ys = faer::ColMut::from_slice_mut(y);
                faer::linalg::matmul::matmul(
                    ys.as_mat_mut(),
                    faer::Accum::Add,
                    m.as_ref(),
                    xs.as_mat(),
                    alpha,
                    faer::Par::Seq,
                );
            }
            StructuralMatrix::Sparse(s) => {
                let col_ptr = s.symbolic().col_ptr();
                let rows = s.symbolic().row_idx();
                let vals = s.val();
                for j in 0..s.ncols() {
                    let xj = alpha * x[j];
                    if xj == 0.0 {
                        continue;
                    }
                    for k in col_ptr[j]..col_ptr[j + 1] {
                        y[rows[k]] += vals[k] * xj;
                    }
                }
            }
        }
    }

    /// Entry (i, j) (a binary search in sparse storage).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        match self {
            StructuralMatrix::Dense(m) => m[(i, j)],
            StructuralMatrix::Sparse(s) => {
                let col_ptr = s.symbolic().col_ptr();
                let rows = &s.symbolic().row_idx()[col_ptr[j]..col_ptr[j + 1]];
                match rows.binary_search(&i) {
                    Ok(k) => s.val()[col_ptr[j] + k],
                    Err(_) => 0.0,
                }
            }
        }
    }

    /// Dense copy.
    pub fn to_dense(&self) -> Mat<f64> {
        match self {
            StructuralMatrix::Dense(m) => m.clone(),
            StructuralMatrix::Sparse(s) => {
                let mut m = Mat::zeros(s.nrows(), s.ncols());
                self.for_each_nonzero(|i, j, v| m[(i, j)] += v);
                m
            }
        }
    }

    /// Number of stored non-zeros (dense: non-zero entries).
    pub fn nnz(&self) -> usize {
        let mut count = 0;
        self.for_each_nonzero(|_, _, _| count += 1);
        count
    }

    /// Whether every entry is finite.
    pub fn all_finite(&self) -> bool {
        let mut ok = true;
        self.for_each_nonzero(|_, _, v| ok &= v.is_finite());
        ok
    }

    /// Largest |a_ij − a_ji| relative to the largest |a_ij|, and the (i, j) where it occurs.
    pub fn asymmetry(&self) -> (f64, Option<(usize, usize)>) {
        let mut max_entry = 0.0_f64;
        self.for_each_nonzero(|_, _, v| max_entry = max_entry.max(v.abs()));
        if max_entry == 0.0 {
            return (0.0, None);
        }
        let mut worst = (0.0, None);
        self.for_each_nonzero(|i, j, v| {
            let d = (v - self.get(j, i)).abs() / max_entry;
            if d > worst.0 {
                worst = (d, Some((i, j)));
            }
        });
        worst
    }

    /// The principal submatrix on `dofs` (in that order), in the same storage kind.
    pub fn submatrix(&self, dofs: &[usize]) -> StructuralMatrix {
        let mut position = vec![usize::MAX; self.n()];
        for (k, &d) in dofs.iter().enumerate() {
            position[d] = k;
        }
        match self {
            StructuralMatrix::Dense(m) => {
                StructuralMatrix::Dense(Mat::from_fn(dofs.len(), dofs.len(), |i, j| {
                    m[(dofs[i], dofs[j])]
                }))
            }
            StructuralMatrix::Sparse(_) => {
                let mut t = Vec::new();
                self.for_each_nonzero(|i, j, v| {
                    if position[i] != usize::MAX && position[j] != usize::MAX {
                        t.push((position[i], position[j], v));
                    }
                });
                StructuralMatrix::sparse_from_triplets(dofs.len(), &t)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair() -> (StructuralMatrix, StructuralMatrix) {
        let d = Mat::from_fn(3, 3, |i, j| {
            [[4.0, -1.0, 0.0], [-1.0, 4.0, 2.0], [0.0, 2.0, 5.0]][i][j]
        });
        let s = StructuralMatrix::sparse_from_triplets(
            3,
            &[
                (0, 0, 4.0),
                (0, 1, -1.0),
                (1, 0, -1.0),
                (1, 1, 3.0),
                (1, 1, 1.0),
                (1, 2, 2.0),
                (2, 1, 2.0),
                (2, 2, 5.0),
            ],
        );
        (StructuralMatrix::Dense(d), s)
    }

    #[test]
    fn dense_and_sparse_agree() {
        let (d, s) = pair();
        let x = [1.0, -2.0, 0.5];
        let (mut yd, mut ys) = (vec![1.0; 3], vec![1.0; 3]);
        d.mul_add(2.0, &x, &mut yd);
        s.mul_add(2.0, &x, &mut ys);
        assert_eq!(yd, ys);
        assert_eq!(
            yd,
            vec![1.0 + 2.0 * 6.0, 1.0 + 2.0 * -8.0, 1.0 + 2.0 * -1.5]
        );
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(d.get(i, j), s.get(i, j));
            }
        }
        assert_eq!(s.nnz(), 7);
        assert_eq!(s.to_dense(), d.to_dense());
        assert_eq!(s.asymmetry().0, 0.0);
        let sub = s.submatrix(&[2, 1]);
        assert_eq!(sub.get(0, 0), 5.0);
        assert_eq!(sub.get(0, 1), 2.0);
        assert!(sub.is_sparse());
    }

    #[test]
    fn asymmetry_is_located() {
        let s = StructuralMatrix::sparse_from_triplets(2, &[(0, 0, 2.0), (0, 1, 1.0)]);
        let (a, at) = s.asymmetry();
        assert_eq!(a, 0.5);
        assert_eq!(at, Some((0, 1)));
    }
}
