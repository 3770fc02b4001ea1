//! Small operations on faer sparse matrices that FE input needs: building from triplets,
//! matrix-vector products, symmetry defects and removing rows/columns (clamping).
//!
//! All matrices are faer [`SparseColMat<usize, f64>`] in full (not triangular) storage, the
//! form the solver and the reduction crate consume. faer 0.24 has no symmetry check or
//! row/column deletion for sparse matrices, so these few loops are written here.

use faer::sparse::{CreationError, SparseColMat, Triplet};

/// The sparse matrix type of FE models: compressed sparse columns, `usize` indices, full
/// symmetric storage.
pub type SparseMatrix = SparseColMat<usize, f64>;

/// Builds an `nrows × ncols` matrix from triplets; repeated (row, column) entries are summed,
/// as element assembly needs.
pub fn from_triplets(
    nrows: usize,
    ncols: usize,
    triplets: &[Triplet<usize, usize, f64>],
) -> Result<SparseMatrix, CreationError> {
    SparseColMat::try_new_from_triplets(nrows, ncols, triplets)
}

/// Calls `f(row, col, value)` for every stored entry, column by column.
pub fn for_each_entry(a: &SparseMatrix, mut f: impl FnMut(usize, usize, f64)) {
    let symbolic = a.symbolic();
    for col in 0..a.ncols() {
        let rows = symbolic.row_idx_of_col_raw(col);
        let vals = a.val_of_col(col);
        for (&row, &val) in rows.iter().zip(vals) {
            f(row, col, val);
        }
    }
}

/// y = A x. `x.len()` must equal the number of columns.
pub fn mul_vec(a: &SparseMatrix, x: &[f64]) -> Vec<f64> {
    assert_eq!(
        x.len(),
        a.ncols(),
        "mul_vec: vector length must match columns"
    );
    let mut y = vec![0.0; a.nrows()];
    for_each_entry(a, |row, col, val| y[row] += val * x[col]);
    y
}

/// xᵀ A x.
pub fn quadratic_form(a: &SparseMatrix, x: &[f64]) -> f64 {
    mul_vec(a, x).iter().zip(x).map(|(ax, xi)| ax * xi).sum()
}

/// Largest absolute stored value (0 for an empty matrix).
pub fn max_abs(a: &SparseMatrix) -> f64 {
    a.val().iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

/// The entry where A and Aᵀ differ most: `(row, col, a_ij, a_ji)` with the largest
/// |a_ij − a_ji|, or `None` if A is exactly symmetric. A must be square.
pub fn worst_asymmetry(a: &SparseMatrix) -> Option<(usize, usize, f64, f64)> {
    let mut worst: Option<(usize, usize, f64, f64)> = None;
    let mut worst_defect = 0.0;
    for_each_entry(a, |row, col, val| {
        if row == col {
            return;
        }
        let transposed = get(a, col, row);
        let defect = (val - transposed).abs();
        if defect > worst_defect || (defect.is_nan() && worst.is_none()) {
            worst_defect = defect;
            worst = Some((row, col, val, transposed));
        }
    });
    worst
}

/// Entry (row, col), 0 where not stored (duplicates were summed at creation).
pub fn get(a: &SparseMatrix, row: usize, col: usize) -> f64 {
    let rows = a.symbolic().row_idx_of_col_raw(col);
    match rows.binary_search(&row) {
        Ok(k) => a.val_of_col(col)[k],
        Err(_) => 0.0,
    }
}

/// Keeps the rows and columns whose `new_of_old` entry is `Some(new index)`; `new_len` is the
/// number of kept indices, and the kept indices must keep their order (as
/// [`crate::fe::dof::DofMap::retain`] gives). Used to remove clamped DOFs from K and M; one
/// pass over the stored entries, no sorting.
pub fn keep_rows_cols(
    a: &SparseMatrix,
    new_of_old: &[Option<usize>],
    new_len: usize,
) -> SparseMatrix {
    let symbolic = a.symbolic();
    let mut col_ptr = Vec::with_capacity(new_len + 1);
    let mut row_idx = Vec::with_capacity(a.val().len());
    let mut values = Vec::with_capacity(a.val().len());
    col_ptr.push(0);
    for col in 0..a.ncols() {
        if new_of_old[col].is_none() {
            continue;
        }
        let rows = symbolic.row_idx_of_col_raw(col);
        for (&row, &val) in rows.iter().zip(a.val_of_col(col)) {
            if let Some(r) = new_of_old[row] {
                row_idx.push(r);
                values.push(val);
            }
        }
        col_ptr.push(row_idx.len());
    }
    assert_eq!(
        col_ptr.len(),
        new_len + 1,
        "keep_rows_cols: new_len must count the kept indices"
    );
    let symbolic =
        faer::sparse::SymbolicSparseColMat::new_checked(new_len, new_len, col_ptr, None, row_idx);
    SparseColMat::new(symbolic, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> SparseMatrix {
        let t = [
            Triplet::new(0, 0, 2.0),
            Triplet::new(1, 0, -1.0),
            Triplet::new(0, 1, -1.0),
            Triplet::new(1, 1, 2.0),
            Triplet::new(1, 1, 1.0),
            Triplet::new(2, 2, 5.0),
        ];
        from_triplets(3, 3, &t).unwrap()
    }

    #[test]
    fn duplicates_are_summed_and_products_match() {
        let a = sample();
        assert_eq!(get(&a, 1, 1), 3.0);
        assert_eq!(mul_vec(&a, &[1.0, 2.0, 3.0]), vec![0.0, 5.0, 15.0]);
        assert_eq!(quadratic_form(&a, &[1.0, 1.0, 0.0]), 3.0);
        assert_eq!(max_abs(&a), 5.0);
        assert!(worst_asymmetry(&a).is_none());
    }

    #[test]
    fn asymmetry_and_row_removal() {
        let t = [Triplet::new(0, 1, 1.0), Triplet::new(1, 0, 1.5)];
        let a = from_triplets(2, 2, &t).unwrap();
        let (r, c, aij, aji) = worst_asymmetry(&a).unwrap();
        assert_eq!((aij - aji).abs(), 0.5);
        assert_ne!(r, c);
        let b = keep_rows_cols(&sample(), &[None, Some(0), Some(1)], 2);
        assert_eq!(get(&b, 0, 0), 3.0);
        assert_eq!(get(&b, 1, 1), 5.0);
        assert_eq!(get(&b, 0, 1), 0.0);
    }
}
