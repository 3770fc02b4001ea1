//! Assembled Jacobians ∂R/∂x, dense or sparse, and the linear solves continuation needs.
//!
//! Newton at fixed frequency solves J Δx = −R; the pseudo-arc-length corrector and the
//! tangent solve the bordered system
//!
//! ```text
//! ⎡ s·J   b ⎤ ⎡Δy ⎤   ⎡ f ⎤
//! ⎣  cᵀ     ⎦ ⎣   ⎦ = ⎣ g ⎦
//! ```
//!
//! with the column scale s of the arc-length space, b = ∂R/∂ω (scaled) and c the tangent.
//!
//! Storage is chosen once per problem ([`JacobianLayout`]): dense column-major values for
//! lumped and reduced models, or a faer sparse matrix whose pattern already holds the border
//! row and column. The sparse pattern is fixed for a scene, so its symbolic LU (fill-reducing
//! column ordering, elimination structure) is computed once, with the pattern, and shared by
//! every copy of the Jacobian; each solve is a numeric refactorisation only. The fixed-frequency solve reuses the same
//! bordered pattern with the border set to the identity row, so one symbolic factorisation
//! serves both.
//!
//! The harmonic-balance Jacobian couples cosine and sine blocks antisymmetrically and the
//! complex dynamic stiffness K + iωC − ω²M is complex-symmetric, not Hermitian: Cholesky or
//! LDLᵀ cannot factor it, so both storages use LU with partial pivoting on the real form.

use faer::prelude::Solve;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::Mat;

use crate::linalg::{solve_dense, LinearSolveError};

/// Dense or sparse storage of a Jacobian, chosen per problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// Dense column-major n × n.
    Dense,
    /// Sparse (faer CSC) with the continuation border in the pattern.
    Sparse,
}

/// An n × n Jacobian with a fixed pattern; entries are addressed by slots computed once.
#[derive(Debug, Clone)]
pub struct AssembledJacobian {
    n: usize,
    storage: Storage,
    /// Dense: n² values, column-major. Sparse: the values of `matrix` (border included).
    values: Vec<f64>,
    /// Sparse only: pattern of the (n + 1) × (n + 1) bordered matrix.
    pattern: Option<SymbolicSparseColMat<usize>>,
    /// Sparse only: slot of each border entry (row n, columns 0..=n) and (rows 0..n, column n).
    border_row_slots: Vec<usize>,
    border_col_slots: Vec<usize>,
    /// Sparse only: symbolic LU of the pattern (shared by clones).
    symbolic_lu: Option<faer::sparse::linalg::solvers::SymbolicLu<usize>>,
    /// Numeric factorisations made (for reports and tests).
    pub factorisations: usize,
}

impl AssembledJacobian {
    /// A dense n × n Jacobian.
    pub fn dense(n: usize) -> Self {
        Self {
            n,
            storage: Storage::Dense,
            values: vec![0.0; n * n],
            pattern: None,
            border_row_slots: Vec::new(),
            border_col_slots: Vec::new(),
            symbolic_lu: None,
            factorisations: 0,
        }
    }

    /// A sparse n × n Jacobian whose pattern holds `entries` (duplicates allowed), the whole
    /// diagonal, and the continuation border.
    pub fn sparse(n: usize, entries: impl IntoIterator<Item = (usize, usize)>) -> Self {
        use faer::sparse::Pair;
        let mut idx: Vec<Pair<usize, usize>> = entries
            .into_iter()
            .map(|(row, col)| Pair { row, col })
            .collect();
        for i in 0..=n {
            idx.push(Pair { row: i, col: i });
            idx.push(Pair { row: n, col: i });
            idx.push(Pair { row: i, col: n });
        }
        let (pattern, _) = SymbolicSparseColMat::try_new_from_indices(n + 1, n + 1, &idx)
            .expect("pattern indices are in range");
        let nnz = pattern.row_idx().len();
        // The symbolic LU depends on the pattern only: computed here, shared by every clone.
        let symbolic_lu = faer::sparse::linalg::solvers::SymbolicLu::try_new(pattern.as_ref()).ok();
        let mut jac = Self {
            n,
            storage: Storage::Sparse,
            values: vec![0.0; nnz],
            pattern: Some(pattern),
            border_row_slots: Vec::new(),
            border_col_slots: Vec::new(),
            symbolic_lu,
            factorisations: 0,
        };
        jac.border_row_slots = (0..=n)
            .map(|j| jac.find_slot(n, j).expect("border row is in the pattern"))
            .collect();
        jac.border_col_slots = (0..n)
            .map(|i| {
                jac.find_slot(i, n)
                    .expect("border column is in the pattern")
            })
            .collect();
        jac
    }

    /// Dimension n of J (without the border).
    pub fn n(&self) -> usize {
        self.n
    }

    /// Storage kind.
    pub fn storage(&self) -> Storage {
        self.storage
    }

    /// Stored entries of J and its border (dense: n²).
    pub fn stored_entries(&self) -> usize {
        self.values.len()
    }

    fn find_slot(&self, i: usize, j: usize) -> Option<usize> {
        match &self.pattern {
            None => (i < self.n && j < self.n).then_some(i + j * self.n),
            Some(p) => {
                let col_ptr = p.col_ptr();
                let rows = &p.row_idx()[col_ptr[j]..col_ptr[j + 1]];
                rows.binary_search(&i).ok().map(|k| col_ptr[j] + k)
            }
        }
    }

    /// Slot of entry (i, j).
    ///
    /// # Panics
    /// If (i, j) is not in the pattern: the pattern is built from the same structure that
    /// fills it, so this is a programming error.
    #[track_caller]
    pub fn slot(&self, i: usize, j: usize) -> usize {
        self.find_slot(i, j)
            .unwrap_or_else(|| panic!("Jacobian entry ({i}, {j}) is not in the pattern"))
    }

    /// Sets every value to zero.
    pub fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }

    /// Adds v at a slot.
    #[inline]
    pub fn add_at(&mut self, slot: usize, v: f64) {
        self.values[slot] += v;
    }

    /// Entry (i, j) (zero outside the pattern).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.find_slot(i, j).map(|s| self.values[s]).unwrap_or(0.0)
    }

    /// Sets column j of J from a dense column (entries outside the pattern are dropped; in
    /// sparse storage they are structurally zero by construction).
    pub fn set_column(&mut self, j: usize, column: &[f64]) {
        match &self.pattern {
            None => self.values[j * self.n..(j + 1) * self.n].copy_from_slice(column),
            Some(p) => {
                let col_ptr = p.col_ptr();
                let rows = p.row_idx();
                for k in col_ptr[j]..col_ptr[j + 1] {
                    if rows[k] < self.n {
                        self.values[k] = column[rows[k]];
                    }
                }
            }
        }
    }

    /// Dense copy of J (for checks and small problems).
    pub fn to_dense(&self) -> Mat<f64> {
        Mat::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }

    /// Solves J x = b.
    pub fn solve(&mut self, b: &[f64]) -> Result<Vec<f64>, LinearSolveError> {
        match self.storage {
            Storage::Dense => {
                let n = self.n;
                let a = Mat::from_fn(n, n, |i, j| self.values[i + j * n]);
                solve_dense(&a, b)
            }
            Storage::Sparse => {
                let mut row = vec![0.0; self.n + 1];
                row[self.n] = 1.0;
                let col = vec![0.0; self.n];
                let mut rhs = b.to_vec();
                rhs.push(0.0);
                let mut y = self.solve_sparse_bordered(1.0, &col, &row, &rhs)?;
                y.pop();
                Ok(y)
            }
        }
    }

    /// Solves the bordered system [[s·J, col], [row]] y = rhs, with `col` of length n and
    /// `row`, `rhs` of length n + 1.
    pub fn solve_bordered(
        &mut self,
        col_scale: f64,
        col: &[f64],
        row: &[f64],
        rhs: &[f64],
    ) -> Result<Vec<f64>, LinearSolveError> {
        match self.storage {
            Storage::Dense => {
                let n = self.n;
                let mut a = Mat::<f64>::zeros(n + 1, n + 1);
                for j in 0..n {
                    for i in 0..n {
                        a[(i, j)] = self.values[i + j * n] * col_scale;
                    }
                }
                for i in 0..n {
                    a[(i, n)] = col[i];
                }
                for j in 0..=n {
                    a[(n, j)] = row[j];
                }
                solve_dense(&a, rhs)
            }
            Storage::Sparse => self.solve_sparse_bordered(col_scale, col, row, rhs),
        }
    }

    fn solve_sparse_bordered(
        &mut self,
        col_scale: f64,
        col: &[f64],
        row: &[f64],
        rhs: &[f64],
    ) -> Result<Vec<f64>, LinearSolveError> {
        let n = self.n;
        if rhs.iter().chain(col).chain(row).any(|v| !v.is_finite())
            || self.values.iter().any(|v| !v.is_finite())
        {
            return Err(LinearSolveError::NonFinite);
        }
        let pattern = self.pattern.clone().expect("sparse storage has a pattern");
        // Scaled J, then the border (the border slots of J's own entries are overwritten).
        let mut vals: Vec<f64> = self.values.iter().map(|v| v * col_scale).collect();
        for (j, &s) in self.border_row_slots.iter().enumerate() {
            vals[s] = row[j];
        }
        for (i, &s) in self.border_col_slots.iter().enumerate() {
            vals[s] = col[i];
        }
        let matrix = SparseColMat::new(pattern, vals);
        if self.symbolic_lu.is_none() {
            let symbolic = faer::sparse::linalg::solvers::SymbolicLu::try_new(matrix.symbolic())
                .map_err(|_| LinearSolveError::Singular { ratio: 0.0 })?;
            self.symbolic_lu = Some(symbolic);
        }
        let symbolic = self.symbolic_lu.clone().expect("set above");
        let lu =
            faer::sparse::linalg::solvers::Lu::try_new_with_symbolic(symbolic, matrix.as_ref())
                .map_err(|_| LinearSolveError::Singular { ratio: 0.0 })?;
        self.factorisations += 1;
        let b = Mat::from_fn(n + 1, 1, |i, _| rhs[i]);
        let x = lu.solve(&b);
        let out: Vec<f64> = (0..=n).map(|i| x[(i, 0)]).collect();
        if out.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::Singular { ratio: 0.0 });
        }
        // A numerically singular matrix can give finite garbage: check the residual.
        let mut r: Vec<f64> = rhs.to_vec();
        let col_ptr = matrix.symbolic().col_ptr();
        let rows = matrix.symbolic().row_idx();
        let v = matrix.val();
        for j in 0..=n {
            for k in col_ptr[j]..col_ptr[j + 1] {
                r[rows[k]] -= v[k] * out[j];
            }
        }
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        let bn = rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
        if rn > 1e-6 * bn.max(f64::MIN_POSITIVE) {
            return Err(LinearSolveError::Singular { ratio: rn / bn });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fill(j: &mut AssembledJacobian, a: &[[f64; 3]; 3]) {
        j.clear();
        for (r, row) in a.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    let s = j.slot(r, c);
                    j.add_at(s, v);
                }
            }
        }
    }

    #[test]
    fn dense_and_sparse_solve_alike() {
        let a = [[4.0, 1.0, 0.0], [-1.0, 3.0, 2.0], [0.0, -2.0, 5.0]];
        let mut d = AssembledJacobian::dense(3);
        let pattern: Vec<(usize, usize)> = (0..3)
            .flat_map(|r| (0..3).map(move |c| (r, c)))
            .filter(|&(r, c)| a[r][c] != 0.0)
            .collect();
        let mut s = AssembledJacobian::sparse(3, pattern);
        fill(&mut d, &a);
        fill(&mut s, &a);
        let b = [1.0, 2.0, 3.0];
        let xd = d.solve(&b).unwrap();
        let xs = s.solve(&b).unwrap();
        for i in 0..3 {
            assert!((xd[i] - xs[i]).abs() < 1e-14);
            let ax: f64 = (0..3).map(|j| a[i][j] * xd[j]).sum();
            assert!((ax - b[i]).abs() < 1e-13);
        }
        let col = [0.5, -1.0, 2.0];
        let row = [1.0, 0.0, 1.0, 3.0];
        let rhs = [0.0, 1.0, 0.0, 1.0];
        let yd = d.solve_bordered(2.0, &col, &row, &rhs).unwrap();
        let ys = s.solve_bordered(2.0, &col, &row, &rhs).unwrap();
        for i in 0..4 {
            assert!((yd[i] - ys[i]).abs() < 1e-13, "{yd:?} vs {ys:?}");
        }
        // Refactorisation reuses the symbolic LU.
        fill(
            &mut s,
            &[[2.0, 1.0, 0.0], [-1.0, 6.0, 2.0], [0.0, -2.0, 1.0]],
        );
        s.solve(&b).unwrap();
        assert_eq!(s.factorisations, 3);
    }

    #[test]
    fn singular_sparse_is_reported() {
        let mut s = AssembledJacobian::sparse(2, [(0, 0), (0, 1), (1, 0), (1, 1)]);
        fill2(&mut s, [[1.0, 2.0], [2.0, 4.0]]);
        assert!(matches!(
            s.solve(&[1.0, 1.0]),
            Err(LinearSolveError::Singular { .. })
        ));
    }

    fn fill2(j: &mut AssembledJacobian, a: [[f64; 2]; 2]) {
        for r in 0..2 {
            for c in 0..2 {
                let s = j.slot(r, c);
                j.add_at(s, a[r][c]);
            }
        }
    }
}
