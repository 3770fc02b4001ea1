//! Internal compressed-sparse-column storage: validation of the user's
//! matrices, extraction of the interior/boundary blocks, and the few sparse
//! products the reduction needs.

use crate::ReductionError;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};

/// Plain CSC matrix with sorted row indices and no duplicates.
#[derive(Debug, Clone)]
pub(crate) struct Csc {
    pub nrows: usize,
    pub ncols: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    pub val: Vec<f64>,
}

impl Csc {
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    #[inline]
    pub fn col(&self, j: usize) -> (&[usize], &[f64]) {
        let r = self.col_ptr[j]..self.col_ptr[j + 1];
        (&self.row_idx[r.clone()], &self.val[r])
    }

    /// Transpose by counting sort: rows of the result come out sorted.
    /// Duplicated entries of `self` stay adjacent in the result.
    pub fn transpose(&self) -> Csc {
        let mut count = vec![0usize; self.nrows + 1];
        for &i in &self.row_idx {
            count[i + 1] += 1;
        }
        for i in 0..self.nrows {
            count[i + 1] += count[i];
        }
        let col_ptr = count.clone();
        let mut next = count;
        let nnz = self.nnz();
        let mut row_idx = vec![0usize; nnz];
        let mut val = vec![0.0; nnz];
        for j in 0..self.ncols {
            let (rows, vals) = self.col(j);
            for (&i, &v) in rows.iter().zip(vals) {
                let p = next[i];
                row_idx[p] = j;
                val[p] = v;
                next[i] += 1;
            }
        }
        Csc {
            nrows: self.ncols,
            ncols: self.nrows,
            col_ptr,
            row_idx,
            val,
        }
    }

    /// Sum adjacent duplicates in place (rows must be sorted within columns).
    fn merge_duplicates(&mut self) {
        let mut write = 0usize;
        let mut new_ptr = vec![0usize; self.ncols + 1];
        for j in 0..self.ncols {
            let (start, end) = (self.col_ptr[j], self.col_ptr[j + 1]);
            let col_start = write;
            for p in start..end {
                let i = self.row_idx[p];
                let v = self.val[p];
                if write > col_start && self.row_idx[write - 1] == i {
                    self.val[write - 1] += v;
                } else {
                    self.row_idx[write] = i;
                    self.val[write] = v;
                    write += 1;
                }
            }
            new_ptr[j + 1] = write;
        }
        self.row_idx.truncate(write);
        self.val.truncate(write);
        self.col_ptr = new_ptr;
    }

    /// Lower triangle of `P A Pᵀ` (new index `inv[old]`) for `self` the
    /// lower triangle of a symmetric `A`; rows sorted.
    pub fn permute_sym_lower(&self, inv: &[usize]) -> Csc {
        let n = self.ncols;
        let mut count = vec![0usize; n + 1];
        for j in 0..n {
            for &i in self.col(j).0 {
                let c = inv[i].min(inv[j]);
                count[c + 1] += 1;
            }
        }
        for c in 0..n {
            count[c + 1] += count[c];
        }
        let col_ptr = count.clone();
        let mut next = count;
        let mut row_idx = vec![0usize; self.nnz()];
        let mut val = vec![0.0; self.nnz()];
        for j in 0..n {
            let (rows, vals) = self.col(j);
            for (&i, &v) in rows.iter().zip(vals) {
                let (a, b) = (inv[i], inv[j]);
                let (r, c) = (a.max(b), a.min(b));
                row_idx[next[c]] = r;
                val[next[c]] = v;
                next[c] += 1;
            }
        }
        let mut out = Csc {
            nrows: n,
            ncols: n,
            col_ptr,
            row_idx,
            val,
        };
        out.sort_columns();
        out
    }

    /// Rows renumbered: row `i` becomes `inv[i]`; rows sorted.
    pub fn permute_rows(&self, inv: &[usize]) -> Csc {
        let mut out = self.clone();
        for r in out.row_idx.iter_mut() {
            *r = inv[*r];
        }
        out.sort_columns();
        out
    }

    fn sort_columns(&mut self) {
        let mut pairs: Vec<(usize, f64)> = Vec::new();
        for j in 0..self.ncols {
            let r = self.col_ptr[j]..self.col_ptr[j + 1];
            pairs.clear();
            pairs.extend(
                self.row_idx[r.clone()]
                    .iter()
                    .copied()
                    .zip(self.val[r.clone()].iter().copied()),
            );
            pairs.sort_unstable_by_key(|&(i, _)| i);
            for (k, (i, v)) in pairs.iter().enumerate() {
                self.row_idx[r.start + k] = *i;
                self.val[r.start + k] = *v;
            }
        }
    }

    /// The lower triangle as a faer matrix (sorted, for the factorisation).
    pub fn to_faer(&self) -> SparseColMat<usize, f64> {
        let symbolic = SymbolicSparseColMat::new_checked(
            self.nrows,
            self.ncols,
            self.col_ptr.clone(),
            None,
            self.row_idx.clone(),
        );
        SparseColMat::new(symbolic, self.val.clone())
    }
}

/// A symmetric matrix stored as its lower triangle in natural order, seen
/// in a permuted numbering (`inv[natural] = permuted`).
#[derive(Clone, Copy)]
pub(crate) struct SymView<'a> {
    pub lower: &'a Csc,
    pub inv: Option<&'a [usize]>,
}

impl SymView<'_> {
    pub fn n(&self) -> usize {
        self.lower.ncols
    }

    /// Dense copy in the permuted numbering.
    pub fn dense(&self) -> faer::Mat<f64> {
        let n = self.n();
        let map = |i: usize| self.inv.map(|v| v[i]).unwrap_or(i);
        let mut a = faer::Mat::zeros(n, n);
        for j in 0..n {
            let (rows, vals) = self.lower.col(j);
            for (&i, &v) in rows.iter().zip(vals) {
                a[(map(i), map(j))] = v;
                a[(map(j), map(i))] = v;
            }
        }
        a
    }
}

/// Read a user matrix, check that it is `n × n`, finite and symmetric, and
/// return it in canonical form (sorted, duplicates summed).
pub(crate) fn canonical_symmetric(
    a: SparseColMatRef<'_, usize, f64>,
    name: &'static str,
    n: usize,
) -> Result<Csc, ReductionError> {
    if a.nrows() != n || a.ncols() != n {
        return Err(ReductionError::BadShape {
            matrix: name,
            rows: a.nrows(),
            cols: a.ncols(),
            expected: n,
        });
    }
    // copy (columns may be unsorted or non-compact)
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0usize);
    let nnz = a.compute_nnz();
    let mut row_idx = Vec::with_capacity(nnz);
    let mut val = Vec::with_capacity(nnz);
    let mut max_abs = 0.0f64;
    for j in 0..n {
        let rows = a.symbolic().row_idx_of_col_raw(j);
        let vals = a.val_of_col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            if !v.is_finite() {
                return Err(ReductionError::NonFinite {
                    matrix: name,
                    row: i,
                    col: j,
                    value: v,
                });
            }
            max_abs = max_abs.max(v.abs());
            row_idx.push(i);
            val.push(v);
        }
        col_ptr.push(row_idx.len());
    }
    let raw = Csc {
        nrows: n,
        ncols: n,
        col_ptr,
        row_idx,
        val,
    };
    let mut t = raw.transpose();
    drop(raw);
    t.merge_duplicates();
    let mut c = t.transpose();
    c.merge_duplicates();
    // c = A (canonical), t = Aᵀ (canonical); compare.
    let tol = SYMMETRY_RTOL * max_abs;
    for j in 0..n {
        let (ra, va) = c.col(j);
        let (rt, vt) = t.col(j);
        let (mut p, mut q) = (0, 0);
        while p < ra.len() || q < rt.len() {
            let (i, x, y) = if q >= rt.len() || (p < ra.len() && ra[p] < rt[q]) {
                p += 1;
                (ra[p - 1], va[p - 1], 0.0)
            } else if p >= ra.len() || rt[q] < ra[p] {
                q += 1;
                (rt[q - 1], 0.0, vt[q - 1])
            } else {
                p += 1;
                q += 1;
                (ra[p - 1], va[p - 1], vt[q - 1])
            };
            if (x - y).abs() > tol {
                return Err(ReductionError::NotSymmetric {
                    matrix: name,
                    row: i,
                    col: j,
                    a_ij: x,
                    a_ji: y,
                    tolerance: SYMMETRY_RTOL,
                });
            }
        }
    }
    Ok(c)
}

/// Relative (to the largest entry) tolerance of the symmetry check.
pub(crate) const SYMMETRY_RTOL: f64 = 1e-10;

/// Where a full-model DOF goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Part {
    Interior(usize),
    Boundary(usize),
}

/// Blocks of a symmetric matrix split into interior (I) and boundary (B) DOFs.
pub(crate) struct Blocks {
    /// lower triangle of A_II (interior numbering, sorted)
    pub ii_lower: Csc,
    /// A_IB, `n_I × n_B`, column b = boundary DOF b
    pub ib: Csc,
    /// A_BB dense, column-major `n_B × n_B`
    pub bb: faer::Mat<f64>,
}

pub(crate) fn split(a: &Csc, part: &[Part], n_i: usize, n_b: usize) -> Blocks {
    let n = a.ncols;
    // A_II lower
    let mut ii_ptr = Vec::with_capacity(n_i + 1);
    ii_ptr.push(0);
    let mut ii_rows = Vec::new();
    let mut ii_vals = Vec::new();
    let mut bb = faer::Mat::<f64>::zeros(n_b, n_b);
    // A_IB built column by column in boundary order
    let mut ib_cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n_b];
    for j in 0..n {
        let (rows, vals) = a.col(j);
        match part[j] {
            Part::Interior(jj) => {
                for (&i, &v) in rows.iter().zip(vals) {
                    if let Part::Interior(ii) = part[i] {
                        if ii >= jj {
                            ii_rows.push(ii);
                            ii_vals.push(v);
                        }
                    }
                }
                ii_ptr.push(ii_rows.len());
            }
            Part::Boundary(jb) => {
                for (&i, &v) in rows.iter().zip(vals) {
                    match part[i] {
                        Part::Interior(ii) => ib_cols[jb].push((ii, v)),
                        Part::Boundary(ib) => bb[(ib, jb)] = v,
                    }
                }
            }
        }
    }
    let mut ib_ptr = Vec::with_capacity(n_b + 1);
    ib_ptr.push(0);
    let mut ib_rows = Vec::new();
    let mut ib_vals = Vec::new();
    for col in ib_cols {
        // interior numbering is monotone in the full numbering: rows are sorted
        for (i, v) in col {
            ib_rows.push(i);
            ib_vals.push(v);
        }
        ib_ptr.push(ib_rows.len());
    }
    Blocks {
        ii_lower: Csc {
            nrows: n_i,
            ncols: n_i,
            col_ptr: ii_ptr,
            row_idx: ii_rows,
            val: ii_vals,
        },
        ib: Csc {
            nrows: n_i,
            ncols: n_b,
            col_ptr: ib_ptr,
            row_idx: ib_rows,
            val: ib_vals,
        },
        bb,
    }
}

/// Lower triangle of a canonical symmetric matrix (all DOFs interior).
pub(crate) fn lower(a: &Csc) -> Csc {
    let part: Vec<Part> = (0..a.ncols).map(Part::Interior).collect();
    split(a, &part, a.ncols, 0).ii_lower
}

/// `a + alpha * b` for two lower-triangle CSC of the same size.
pub(crate) fn add_scaled(a: &Csc, b: &Csc, alpha: f64) -> Csc {
    let n = a.ncols;
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::with_capacity(a.nnz().max(b.nnz()));
    let mut val = Vec::with_capacity(a.nnz().max(b.nnz()));
    for j in 0..n {
        let (ra, va) = a.col(j);
        let (rb, vb) = b.col(j);
        let (mut p, mut q) = (0, 0);
        while p < ra.len() || q < rb.len() {
            if q >= rb.len() || (p < ra.len() && ra[p] < rb[q]) {
                row_idx.push(ra[p]);
                val.push(va[p]);
                p += 1;
            } else if p >= ra.len() || rb[q] < ra[p] {
                row_idx.push(rb[q]);
                val.push(alpha * vb[q]);
                q += 1;
            } else {
                row_idx.push(ra[p]);
                val.push(va[p] + alpha * vb[q]);
                p += 1;
                q += 1;
            }
        }
        col_ptr.push(row_idx.len());
    }
    Csc {
        nrows: n,
        ncols: n,
        col_ptr,
        row_idx,
        val,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;
    use faer::Mat;

    fn from_triplets(n: usize, t: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
        let t: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
        SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    #[test]
    fn symmetric_matvec_matches_dense() {
        let a = from_triplets(
            4,
            &[
                (0, 0, 4.0),
                (1, 0, 1.0),
                (0, 1, 1.0),
                (1, 1, 3.0),
                (3, 1, -2.0),
                (1, 3, -2.0),
                (2, 2, 5.0),
                (3, 3, 6.0),
            ],
        );
        let c = canonical_symmetric(a.as_ref(), "A", 4).unwrap();
        let l = lower(&c);
        let x = Mat::from_fn(4, 3, |i, j| (i * 3 + j) as f64 - 2.5);
        let dense = a.to_dense();
        let y_ref = &dense * &x;
        let xr = crate::block::RowBlock::from_mat(x.as_ref());
        let mut yr = crate::block::RowBlock::zeros(4, 3);
        crate::block::sym_mul_rows(&l, None, &xr, &mut yr);
        assert!((yr.view() - &y_ref).norm_max() < 1e-14);
        // permuted numbering: y_p = P A Pᵀ x_p
        let inv = [2usize, 0, 3, 1];
        let xp = Mat::from_fn(4, 3, |i, j| {
            x[(inv.iter().position(|&v| v == i).unwrap(), j)]
        });
        let xr = crate::block::RowBlock::from_mat(xp.as_ref());
        crate::block::sym_mul_rows(&l, Some(&inv), &xr, &mut yr);
        for i in 0..4 {
            for j in 0..3 {
                assert!((yr.view()[(inv[i], j)] - y_ref[(i, j)]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn asymmetry_is_found() {
        let a = from_triplets(2, &[(0, 0, 1.0), (1, 0, 0.5), (1, 1, 1.0)]);
        let e = canonical_symmetric(a.as_ref(), "K", 2).unwrap_err();
        assert!(matches!(e, ReductionError::NotSymmetric { .. }), "{e}");
    }
}
