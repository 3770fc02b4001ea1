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
//! Storage is chosen once per problem ([`crate::hbm::pattern::JacobianLayout`]): dense column-major
//! values for lumped and reduced models (the bordered matrix is then factored whole), or a faer
//! sparse matrix of J alone. The sparse pattern is fixed for a scene, so its symbolic LU
//! (fill-reducing column ordering, elimination structure) is computed once, with the pattern,
//! and shared by every copy of the Jacobian; each solve is a numeric refactorisation only.
//!
//! The border is kept out of the sparse matrix on purpose: its dense row would make the
//! elimination structure that partial pivoting must allow for (that of AᵀA) completely dense.
//! The bordered system is solved instead by block elimination with the one LU of s·J,
//! s·J [a b] = [f c], z = (g − r·a)/(d − r·b), Δy = a − b z, followed by refinement steps on
//! the full bordered residual (block elimination alone loses accuracy near folds, where J is
//! nearly singular).
//!
//! The harmonic-balance Jacobian couples cosine and sine blocks antisymmetrically and the
//! complex dynamic stiffness K + iωC − ω²M is complex-symmetric, not Hermitian: Cholesky or
//! LDLᵀ cannot factor it, so both storages use LU with partial pivoting on the real form.

use std::sync::Arc;

use faer::prelude::Solve;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::Mat;

use crate::numerics::linalg::{checked_lu, norm, solve_dense, LinearSolveError};
use crate::numerics::work::{self, Work};

/// A Jacobian whose linear part is implied by an operator instead of stored: its values are
/// only the blocks the operator needs (for the harmonic balance's schur formulation, one dense
/// block per contact point on its relative coordinates), and it forms, applies and factorises
/// J from them and the parameter λ (the angular frequency ω of the linear part).
pub trait ImplicitJacobian: std::fmt::Debug + Send + Sync {
    /// Dimension n of J.
    fn dim(&self) -> usize;
    /// Number of stored values.
    fn values_len(&self) -> usize;
    /// Entry (i, j) of J at `lambda` with stored `values`.
    fn entry(&self, lambda: f64, values: &[f64], i: usize, j: usize) -> f64;
    /// y += s·J x.
    fn mul_add(&self, lambda: f64, values: &[f64], col_scale: f64, x: &[f64], y: &mut [f64]);
    /// A factorisation of J.
    fn factor(
        &self,
        lambda: f64,
        values: &[f64],
    ) -> Result<Box<dyn ImplicitFactor>, LinearSolveError>;
}

/// A factorisation made by an [`ImplicitJacobian`].
pub trait ImplicitFactor: Send + Sync {
    /// J⁻¹ b; with `single`, an approximate solve with factors rounded to single precision
    /// where the factorisation keeps them (for chord steps, judged on the true residual).
    fn solve(&self, b: &[f64], single: bool) -> Vec<f64>;
    /// The sign (±1) of det J where the factorisation gives it, up to a factor that is the
    /// same for every factorisation of the same Jacobian structure (a fixed change of
    /// coordinates); None where it does not.
    fn det_sign(&self) -> Option<f64> {
        None
    }
}

/// A factorised bordered matrix `[[s·J, col], [row]]`, kept for several solves (the chord
/// iterations of the corrector on large problems, see [`crate::numerics::continuation`]).
pub struct BorderedFactor {
    kind: FactorKind,
}

enum FactorKind {
    /// LU of the whole (n + 1) × (n + 1) matrix.
    Dense(faer::linalg::solvers::PartialPivLu<f64>),
    /// A factorisation of s·J with the border eliminated by blocks: a = (sJ)⁻¹ f,
    /// z = (g − r·a)/d, y = a − b z with b = (sJ)⁻¹ col and d = row\[n\] − r·b.
    Eliminated {
        lu: Arc<InnerFactor>,
        b_col: Vec<f64>,
        row: Vec<f64>,
        denominator: f64,
    },
}

/// A factorisation of J S alone, S = diag(s) the column scale: a factorisation of J (sparse
/// LU, or an implicit Jacobian's own) and s, since (J S)⁻¹ b = S⁻¹ J⁻¹ b.
struct InnerFactor {
    kind: InnerKind,
    /// Column scale s (length n).
    col_scale: Vec<f64>,
}

/// A factorisation of J.
enum InnerKind {
    /// Sparse LU of J.
    Sparse(Box<faer::sparse::linalg::solvers::Lu<usize, f64>>),
    /// An implicit Jacobian's factorisation of J.
    Implicit(Box<dyn ImplicitFactor>),
}

impl InnerFactor {
    /// The sign of det(J S), where the factorisation gives it (not faer's sparse LU).
    fn det_sign(&self) -> Option<f64> {
        let scale = crate::numerics::linalg::diagonal_sign(self.col_scale.iter().copied());
        match &self.kind {
            InnerKind::Sparse(_) => None,
            InnerKind::Implicit(f) => f.det_sign().map(|s| s * scale),
        }
    }

    /// (J S)⁻¹ b.
    fn solve(&self, b: &[f64]) -> Vec<f64> {
        self.solve_with(b, false)
    }

    /// (J S)⁻¹ b, in single precision where the factorisation offers it (`fast`).
    fn solve_with(&self, b: &[f64], fast: bool) -> Vec<f64> {
        let mut x = match &self.kind {
            InnerKind::Sparse(lu) => {
                let x = lu.solve(Mat::from_fn(b.len(), 1, |i, _| b[i]));
                (0..b.len()).map(|i| x[(i, 0)]).collect()
            }
            InnerKind::Implicit(f) => f.solve(b, fast),
        };
        x.iter_mut().zip(&self.col_scale).for_each(|(v, s)| *v /= s);
        x
    }
}

impl BorderedFactor {
    /// The same factorisation of s·J with another border row (the border column is kept),
    /// sharing the factorisation: a continuation step can start its corrector from the
    /// previous point's factorisation with its own tangent row. None for the dense storage,
    /// whose row is inside the factorisation, and when the new border is singular.
    pub fn rebordered(&self, row: &[f64]) -> Option<BorderedFactor> {
        match &self.kind {
            FactorKind::Dense(_) => None,
            FactorKind::Eliminated { lu, b_col, .. } => {
                let n = b_col.len();
                if row.len() != n + 1 || row.iter().any(|v| !v.is_finite()) {
                    return None;
                }
                let denominator = row[n] - (0..n).map(|i| row[i] * b_col[i]).sum::<f64>();
                (denominator != 0.0 && denominator.is_finite()).then(|| BorderedFactor {
                    kind: FactorKind::Eliminated {
                        lu: Arc::clone(lu),
                        b_col: b_col.clone(),
                        row: row.to_vec(),
                        denominator,
                    },
                })
            }
        }
    }

    /// The sign (±1) of the bordered matrix's determinant, where the factorisation gives it
    /// (up to a factor fixed by the Jacobian's structure, see [`ImplicitFactor::det_sign`]):
    /// from the dense LU, or det(s·J)·d for the border eliminated by blocks.
    pub fn det_sign(&self) -> Option<f64> {
        use crate::numerics::linalg::{diagonal_sign, permutation_sign};
        match &self.kind {
            FactorKind::Dense(lu) => {
                let u = lu.U();
                let (fwd, _) = lu.P().arrays();
                Some(diagonal_sign((0..u.nrows()).map(|i| u[(i, i)])) * permutation_sign(fwd))
            }
            FactorKind::Eliminated {
                lu, denominator, ..
            } => lu.det_sign().map(|s| s * denominator.signum()),
        }
    }

    /// Solves the factorised bordered system for `rhs` (length n + 1).
    pub fn solve(&self, rhs: &[f64]) -> Result<Vec<f64>, LinearSolveError> {
        self.solve_with(rhs, false)
    }

    /// An approximate solve for chord steps: where the factorisation keeps single-precision
    /// factors (an implicit Jacobian such as the schur formulation's), the reduced system is solved with them — half the
    /// memory traffic, relative error about 10⁻⁷ times the condition number. Otherwise the
    /// same as [`Self::solve`].
    pub fn solve_chord(&self, rhs: &[f64]) -> Result<Vec<f64>, LinearSolveError> {
        self.solve_with(rhs, true)
    }

    fn solve_with(&self, rhs: &[f64], fast: bool) -> Result<Vec<f64>, LinearSolveError> {
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let n1 = rhs.len();
        let started = std::time::Instant::now();
        let y: Vec<f64> = match &self.kind {
            FactorKind::Dense(lu) => {
                let x = lu.solve(Mat::from_fn(n1, 1, |i, _| rhs[i]));
                (0..n1).map(|i| x[(i, 0)]).collect()
            }
            FactorKind::Eliminated {
                lu,
                b_col,
                row,
                denominator,
            } => {
                let n = n1 - 1;
                let a = lu.solve_with(&rhs[..n], fast);
                let z = (rhs[n] - (0..n).map(|i| row[i] * a[i]).sum::<f64>()) / denominator;
                let mut y: Vec<f64> = (0..n).map(|i| a[i] - b_col[i] * z).collect();
                y.push(z);
                y
            }
        };
        work::record(Work::Solve, started);
        if y.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::Singular { ratio: 0.0 });
        }
        Ok(y)
    }
}

/// Dense or sparse storage of a Jacobian, chosen per problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// Dense column-major n × n.
    Dense,
    /// Sparse (faer CSC) of J alone; the border is eliminated by blocks.
    Sparse,
    /// An [`ImplicitJacobian`] that solves by Schur-complement elimination (the harmonic
    /// balance's schur formulation): the values it keeps and the parameter λ; the linear part
    /// is implied. The border is eliminated by blocks.
    Schur,
}

/// An n × n Jacobian with a fixed pattern; entries are addressed by slots computed once.
#[derive(Debug, Clone)]
pub struct AssembledJacobian {
    n: usize,
    storage: Storage,
    /// Dense: n² values, column-major. Sparse: the values of the pattern's entries.
    values: Vec<f64>,
    /// Sparse only: pattern of J.
    pattern: Option<SymbolicSparseColMat<usize>>,
    /// Sparse only: symbolic LU of the pattern (shared by clones).
    symbolic_lu: Option<faer::sparse::linalg::solvers::SymbolicLu<usize>>,
    /// Implicit only: the operator that forms J (shared by clones).
    implicit: Option<Arc<dyn ImplicitJacobian>>,
    /// Parameter λ (the frequency ω, rad/s) the linear part was formed at (used by the
    /// implicit storage).
    omega: f64,
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
            symbolic_lu: None,
            implicit: None,
            omega: 0.0,
            factorisations: 0,
        }
    }

    /// A Jacobian formed by `operator` from the values it keeps.
    pub fn implicit(operator: Arc<dyn ImplicitJacobian>) -> Self {
        Self {
            n: operator.dim(),
            storage: Storage::Schur,
            values: vec![0.0; operator.values_len()],
            pattern: None,
            symbolic_lu: None,
            implicit: Some(operator),
            omega: 0.0,
            factorisations: 0,
        }
    }

    /// Sets the frequency ω (rad/s) of the linear part (the dense and sparse storages hold the
    /// linear part in their values; the implicit storage forms it from ω when it factorises).
    pub fn set_frequency(&mut self, omega: f64) {
        self.omega = omega;
    }

    /// A sparse n × n Jacobian whose pattern holds `entries` (duplicates allowed) and the whole
    /// diagonal.
    pub fn sparse(n: usize, entries: impl IntoIterator<Item = (usize, usize)>) -> Self {
        use faer::sparse::Pair;
        let mut idx: Vec<Pair<usize, usize>> = entries
            .into_iter()
            .map(|(row, col)| Pair { row, col })
            .collect();
        idx.extend((0..n).map(|i| Pair { row: i, col: i }));
        let (pattern, _) = SymbolicSparseColMat::try_new_from_indices(n, n, &idx)
            .expect("pattern indices are in range");
        let nnz = pattern.row_idx().len();
        // The symbolic LU depends on the pattern only: computed here, shared by every clone.
        let symbolic_lu = faer::sparse::linalg::solvers::SymbolicLu::try_new(pattern.as_ref()).ok();
        Self {
            n,
            storage: Storage::Sparse,
            values: vec![0.0; nnz],
            pattern: Some(pattern),
            symbolic_lu,
            implicit: None,
            omega: 0.0,
            factorisations: 0,
        }
    }

    /// Dimension n of J (without the border).
    pub fn n(&self) -> usize {
        self.n
    }

    /// Storage kind.
    pub fn storage(&self) -> Storage {
        self.storage
    }

    /// Stored entries of J (dense: n²).
    pub fn stored_entries(&self) -> usize {
        self.values.len()
    }

    fn find_slot(&self, i: usize, j: usize) -> Option<usize> {
        if self.storage == Storage::Schur {
            return None;
        }
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
        if let Some(r) = &self.implicit {
            return r.entry(self.omega, &self.values, i, j);
        }
        self.find_slot(i, j).map(|s| self.values[s]).unwrap_or(0.0)
    }

    /// Sets column j of J from a dense column (entries outside the pattern are dropped; in
    /// sparse storage they are structurally zero by construction).
    ///
    /// The implicit storage has no columns (the schur formulation's finite-difference
    /// Jacobian is formed per contact): a call is a programming error and changes nothing.
    pub fn set_column(&mut self, j: usize, column: &[f64]) {
        if self.storage == Storage::Schur {
            debug_assert!(false, "set_column on an implicit Jacobian");
            return;
        }
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

    /// The stored non-zero entries of J as (row, col, value) triplets: the pattern's entries in
    /// sparse storage, the non-zero values in dense storage, and in the implicit storage every
    /// entry formed one by one (n² calls: for checks, or after switching to sparse storage).
    pub fn triplets(&self) -> Vec<(usize, usize, f64)> {
        match (&self.pattern, self.storage) {
            (Some(p), Storage::Sparse) => {
                let col_ptr = p.col_ptr();
                let rows = p.row_idx();
                let mut out = Vec::with_capacity(self.values.len());
                for j in 0..self.n {
                    for k in col_ptr[j]..col_ptr[j + 1] {
                        if self.values[k] != 0.0 {
                            out.push((rows[k], j, self.values[k]));
                        }
                    }
                }
                out
            }
            _ => {
                let mut out = Vec::new();
                for j in 0..self.n {
                    for i in 0..self.n {
                        let v = self.get(i, j);
                        if v != 0.0 {
                            out.push((i, j, v));
                        }
                    }
                }
                out
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
                let started = std::time::Instant::now();
                let x = solve_dense(&a, b);
                work::record(Work::Factorisation, started);
                x
            }
            Storage::Sparse | Storage::Schur => {
                let ones = vec![1.0; self.n];
                let lu = self.inner_factor(&ones)?;
                let x = self.checked_solve(&lu, &ones, b)?;
                Ok(x)
            }
        }
    }

    /// Solves J x = b for every b of `rhs` with one factorisation (each solution as
    /// [`Self::solve`] gives it): several right-hand sides at the cost of one factorisation.
    pub fn solve_many(&mut self, rhs: &[&[f64]]) -> Result<Vec<Vec<f64>>, LinearSolveError> {
        match self.storage {
            Storage::Dense => {
                let n = self.n;
                if rhs.iter().any(|b| b.iter().any(|v| !v.is_finite())) {
                    return Err(LinearSolveError::NonFinite);
                }
                let a = Mat::from_fn(n, n, |i, j| self.values[i + j * n]);
                let started = std::time::Instant::now();
                let lu = checked_lu(&a)?;
                work::record(Work::Factorisation, started);
                let b = Mat::from_fn(n, rhs.len(), |i, k| rhs[k][i]);
                let x = lu.solve(&b);
                let out: Vec<Vec<f64>> = (0..rhs.len())
                    .map(|k| (0..n).map(|i| x[(i, k)]).collect())
                    .collect();
                if out.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(LinearSolveError::NonFinite);
                }
                Ok(out)
            }
            Storage::Sparse | Storage::Schur => {
                let ones = vec![1.0; self.n];
                let lu = self.inner_factor(&ones)?;
                rhs.iter()
                    .map(|b| self.checked_solve(&lu, &ones, b))
                    .collect()
            }
        }
    }

    /// Solves the bordered system `[[s·J, col], [row]] y = rhs`, with `col` of length n and
    /// `row`, `rhs` of length n + 1; with the sign of the bordered matrix's determinant where
    /// the factorisation gives it ([`BorderedFactor::det_sign`]).
    pub fn solve_bordered(
        &mut self,
        col_scale: &[f64],
        col: &[f64],
        row: &[f64],
        rhs: &[f64],
    ) -> Result<(Vec<f64>, Option<f64>), LinearSolveError> {
        match self.storage {
            Storage::Dense => {
                let factor = self.factor_bordered(col_scale, col, row)?;
                Ok((factor.solve(rhs)?, factor.det_sign()))
            }
            Storage::Sparse | Storage::Schur => {
                self.solve_eliminated_bordered(col_scale, col, row, rhs)
            }
        }
    }

    /// Factorises the bordered matrix `[[s·J, col], [row]]` for several solves
    /// ([`BorderedFactor::solve`], without the refinement steps of [`Self::solve_bordered`]).
    pub fn factor_bordered(
        &mut self,
        col_scale: &[f64],
        col: &[f64],
        row: &[f64],
    ) -> Result<BorderedFactor, LinearSolveError> {
        let n = self.n;
        if col.iter().chain(row).any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let kind = match self.storage {
            Storage::Dense => {
                let a = Mat::from_fn(n + 1, n + 1, |i, j| match (i < n, j < n) {
                    (true, true) => self.values[i + j * n] * col_scale[j],
                    (true, false) => col[i],
                    (false, _) => row[j],
                });
                let started = std::time::Instant::now();
                let lu = checked_lu(&a)?;
                work::record(Work::Factorisation, started);
                self.factorisations += 1;
                FactorKind::Dense(lu)
            }
            Storage::Sparse | Storage::Schur => {
                let lu = self.inner_factor(col_scale)?;
                let b_col = lu.solve(col);
                let denominator = row[n] - (0..n).map(|i| row[i] * b_col[i]).sum::<f64>();
                if denominator == 0.0 || !denominator.is_finite() {
                    return Err(LinearSolveError::Singular { ratio: 0.0 });
                }
                FactorKind::Eliminated {
                    lu: Arc::new(lu),
                    b_col,
                    row: row.to_vec(),
                    denominator,
                }
            }
        };
        Ok(BorderedFactor { kind })
    }

    /// Factorisation of J S: sparse LU of J, or the implicit Jacobian's own, with the scale.
    fn inner_factor(&mut self, col_scale: &[f64]) -> Result<InnerFactor, LinearSolveError> {
        if col_scale.len() != self.n || col_scale.iter().any(|s| !s.is_finite() || *s == 0.0) {
            return Err(LinearSolveError::NonFinite);
        }
        let started = std::time::Instant::now();
        let kind = match &self.implicit {
            Some(r) => {
                let f = r.factor(self.omega, &self.values)?;
                self.factorisations += 1;
                InnerKind::Implicit(f)
            }
            None => InnerKind::Sparse(Box::new(self.sparse_lu()?)),
        };
        work::record(Work::Factorisation, started);
        Ok(InnerFactor {
            kind,
            col_scale: col_scale.to_vec(),
        })
    }

    /// Numeric LU of J with the shared symbolic factorisation.
    fn sparse_lu(
        &mut self,
    ) -> Result<faer::sparse::linalg::solvers::Lu<usize, f64>, LinearSolveError> {
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let pattern = self.pattern.clone().expect("sparse storage has a pattern");
        if self.symbolic_lu.is_none() {
            let symbolic = faer::sparse::linalg::solvers::SymbolicLu::try_new(pattern.as_ref())
                .map_err(|_| LinearSolveError::Singular { ratio: 0.0 })?;
            self.symbolic_lu = Some(symbolic);
        }
        let symbolic = self.symbolic_lu.clone().expect("set above");
        let matrix = SparseColMat::new(pattern, self.values.clone());
        let lu =
            faer::sparse::linalg::solvers::Lu::try_new_with_symbolic(symbolic, matrix.as_ref())
                .map_err(|_| LinearSolveError::Singular { ratio: 0.0 })?;
        self.factorisations += 1;
        Ok(lu)
    }

    /// y += s·J x.
    fn mul_add(&self, col_scale: &[f64], x: &[f64], y: &mut [f64]) {
        let scaled: Vec<f64> = x.iter().zip(col_scale).map(|(v, s)| v * s).collect();
        if let Some(r) = &self.implicit {
            r.mul_add(self.omega, &self.values, 1.0, &scaled, y);
            return;
        }
        let p = self.pattern.as_ref().expect("sparse storage has a pattern");
        let (col_ptr, rows) = (p.col_ptr(), p.row_idx());
        for j in 0..self.n {
            let xj = scaled[j];
            for k in col_ptr[j]..col_ptr[j + 1] {
                y[rows[k]] += self.values[k] * xj;
            }
        }
    }

    /// Solves s·J x = b with a factorisation of s·J, with one refinement step, and refuses a
    /// solution whose residual exceeds 1e-6 of ‖b‖ (a numerically singular J can give finite
    /// garbage).
    fn checked_solve(
        &self,
        lu: &InnerFactor,
        col_scale: &[f64],
        b: &[f64],
    ) -> Result<Vec<f64>, LinearSolveError> {
        if b.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let solve = |rhs: &[f64]| -> Result<Vec<f64>, LinearSolveError> {
            let started = std::time::Instant::now();
            let out = lu.solve(rhs);
            work::record(Work::Solve, started);
            if out.iter().any(|v| !v.is_finite()) {
                return Err(LinearSolveError::Singular { ratio: 0.0 });
            }
            Ok(out)
        };
        let mut x = solve(b)?;
        let residual = |x: &[f64]| {
            let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
            self.mul_add(col_scale, x, &mut r);
            r
        };
        let r = residual(&x);
        let dx = solve(&r)?;
        x.iter_mut().zip(&dx).for_each(|(a, d)| *a -= d);
        let rn = norm(&residual(&x));
        let bn = norm(b);
        if rn > 1e-6 * bn.max(f64::MIN_POSITIVE) {
            return Err(LinearSolveError::Singular { ratio: rn / bn });
        }
        Ok(x)
    }

    /// The bordered solve by block elimination with one factorisation of s·J (see the module
    /// docs), refined on the full bordered residual.
    fn solve_eliminated_bordered(
        &mut self,
        col_scale: &[f64],
        col: &[f64],
        row: &[f64],
        rhs: &[f64],
    ) -> Result<(Vec<f64>, Option<f64>), LinearSolveError> {
        let n = self.n;
        // One LU of s·J (non-finite input is refused by the factorisation and its solves); each solve eliminates the border by blocks.
        let factor = self.factor_bordered(col_scale, col, row)?;
        let dot_row = |y: &[f64]| (0..n).map(|i| row[i] * y[i]).sum::<f64>();
        // Bordered residual of (y, z): [f − sJ y − c z; g − r·y − d z].
        let bordered_residual = |y: &[f64], z: f64| -> Vec<f64> {
            let mut r: Vec<f64> = (0..n).map(|i| -(rhs[i] - col[i] * z)).collect();
            self.mul_add(col_scale, y, &mut r);
            let mut out: Vec<f64> = r.iter().map(|v| -v).collect();
            out.push(rhs[n] - dot_row(y) - row[n] * z);
            out
        };
        let mut y = factor.solve(rhs)?;
        let scale = norm(rhs).max(f64::MIN_POSITIVE);
        for _ in 0..3 {
            let r = bordered_residual(&y[..n], y[n]);
            if y.iter().any(|v| !v.is_finite()) {
                return Err(LinearSolveError::Singular { ratio: 0.0 });
            }
            if norm(&r) <= 1e-12 * scale {
                break;
            }
            let d = factor.solve(&r)?;
            y.iter_mut().zip(&d).for_each(|(a, b)| *a += b);
        }
        let rn = norm(&bordered_residual(&y[..n], y[n]));
        if !rn.is_finite() || rn > 1e-6 * scale {
            return Err(LinearSolveError::Singular { ratio: rn / scale });
        }
        Ok((y, factor.det_sign()))
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
        let scale = [2.0, 0.5, 3.0];
        let (yd, _) = d.solve_bordered(&scale, &col, &row, &rhs).unwrap();
        let (ys, _) = s.solve_bordered(&scale, &col, &row, &rhs).unwrap();
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
    fn solve_many_factorises_once_and_matches_single_solves() {
        let a = [[4.0, 1.0, 0.0], [-1.0, 3.0, 2.0], [0.0, -2.0, 5.0]];
        let pattern: Vec<(usize, usize)> = (0..3)
            .flat_map(|r| (0..3).map(move |c| (r, c)))
            .filter(|&(r, c)| a[r][c] != 0.0)
            .collect();
        let (b1, b2) = ([1.0, 2.0, 3.0], [-0.5, 0.0, 4.0]);
        for mut j in [
            AssembledJacobian::dense(3),
            AssembledJacobian::sparse(3, pattern),
        ] {
            fill(&mut j, &a);
            let many = j.solve_many(&[&b1, &b2]).unwrap();
            let before = j.factorisations;
            let one = [j.solve(&b1).unwrap(), j.solve(&b2).unwrap()];
            for k in 0..2 {
                for i in 0..3 {
                    assert!(
                        (many[k][i] - one[k][i]).abs() < 1e-14,
                        "{many:?} vs {one:?}"
                    );
                }
            }
            if j.storage() == Storage::Sparse {
                // One factorisation for both right-hand sides, one per single solve.
                assert_eq!((before, j.factorisations), (1, 3));
            }
        }
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
