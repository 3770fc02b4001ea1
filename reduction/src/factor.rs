//! Sparse Cholesky `A = P Lᵀ L Pᵀ` of a symmetric positive definite matrix
//! with faer's low-level supernodal factorisation and a METIS or AMD ordering.

use crate::block::{supernodal_solve_rows, AlignedVec, RowBlock};
use crate::csc::Csc;
use crate::ordering::{metis_nd, Ordering};
use crate::ReductionError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::{Conj, MatMut, Par, Side};
use std::time::Instant;

/// Relative pivot below which the matrix is declared singular:
/// `L_jj² / A_jj < PIVOT_RATIO_TOL`.
pub(crate) const PIVOT_RATIO_TOL: f64 = 1e-11;

pub(crate) struct SpdFactor {
    symbolic: SymbolicCholesky<usize>,
    values: AlignedVec,
    pub symbolic_seconds: f64,
    pub numeric_seconds: f64,
}

/// How to name a failing pivot.
pub(crate) struct PivotContext<'a> {
    pub matrix: &'static str,
    pub context: &'static str,
    /// index reported as "local" (e.g. natural interior index) of the
    /// factored (permuted) index `i`
    pub local_index: &'a dyn Fn(usize) -> usize,
    /// full-model index of the factored (permuted) index `i`
    pub full_index: &'a dyn Fn(usize) -> usize,
}

/// Fill-reducing ordering of the symmetric matrix whose lower triangle is
/// `lower`: `(fwd, inv, seconds)` with `fwd[new] = old`.
pub(crate) fn fill_reducing_order(
    lower: &Csc,
    ordering: Ordering,
) -> Result<(Vec<usize>, Vec<usize>, f64), ReductionError> {
    let t0 = Instant::now();
    let n = lower.ncols;
    let (fwd, inv) = match ordering {
        Ordering::Metis => metis_nd(lower)?,
        Ordering::Amd => {
            let a = lower.to_faer();
            let mut fwd = vec![0usize; n];
            let mut inv = vec![0usize; n];
            let req = faer::sparse::linalg::amd::order_scratch::<usize>(n, lower.nnz());
            let mut mem = MemBuffer::try_new(req).map_err(|_| {
                ReductionError::LinearAlgebra("out of memory for the AMD ordering".into())
            })?;
            faer::sparse::linalg::amd::order(
                &mut fwd,
                &mut inv,
                a.symbolic(),
                Default::default(),
                MemStack::new(&mut mem),
            )
            .map_err(|e| ReductionError::Ordering(format!("AMD failed: {e:?}")))?;
            (fwd, inv)
        }
    };
    Ok((fwd, inv, t0.elapsed().as_secs_f64()))
}

impl SpdFactor {
    /// Factor the SPD matrix whose lower triangle is `lower`, already in
    /// its elimination order (see [`fill_reducing_order`] and
    /// [`Csc::permute_sym_lower`]): no permutation is applied by the
    /// factor, so solves run on the right-hand side in place.
    pub fn new(lower: &Csc, ctx: &PivotContext<'_>) -> Result<Self, ReductionError> {
        let n = lower.ncols;
        let la = |what: &str, e: &dyn std::fmt::Debug| {
            ReductionError::LinearAlgebra(format!("{what} ({e:?})"))
        };
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let t0 = Instant::now();
        // with the identity ordering faer's symbolic analysis reads the upper triangle
        let upper = lower.transpose().to_faer();
        let symbolic = factorize_symbolic_cholesky(
            upper.symbolic(),
            Side::Upper,
            SymmetricOrdering::Identity,
            params,
        )
        .map_err(|e| la("symbolic Cholesky", &e))?;
        drop(upper);
        let symbolic_seconds = t0.elapsed().as_secs_f64();
        let a = lower.to_faer();
        let t1 = Instant::now();
        // 64-byte aligned: faer's kernels then split their loops the same
        // way at every run, and the factor is reproducible bit for bit
        let mut values = AlignedVec::try_zeros(symbolic.len_val()).ok_or_else(|| {
            ReductionError::LinearAlgebra(format!(
                "out of memory for a Cholesky factor of {} entries",
                symbolic.len_val()
            ))
        })?;
        let req = symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        let mut mem = MemBuffer::try_new(req).map_err(|_| {
            ReductionError::LinearAlgebra("out of memory for Cholesky scratch".into())
        })?;
        let stack = MemStack::new(&mut mem);
        let result = symbolic.factorize_numeric_llt(
            &mut values,
            a.as_ref(),
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            stack,
            Default::default(),
        );
        if let Err(LltError::NonPositivePivot { index }) = result {
            return Err(ReductionError::NotPositiveDefinite {
                matrix: ctx.matrix,
                context: ctx.context,
                local: (ctx.local_index)(index),
                full: (ctx.full_index)(index),
                ratio: 0.0,
            });
        }
        drop(mem);
        drop(a);
        let numeric_seconds = t1.elapsed().as_secs_f64();
        let this = SpdFactor {
            symbolic,
            values,
            symbolic_seconds,
            numeric_seconds,
        };
        // Near-singular pivots: a free body factors with round-off pivots.
        let diag = lower_diagonal(lower);
        let mut worst = (f64::INFINITY, 0usize);
        this.for_each_pivot(|j, l_jj| {
            let d = diag[j];
            let ratio = if d > 0.0 { l_jj * l_jj / d } else { 0.0 };
            if ratio < worst.0 {
                worst = (ratio, j);
            }
        });
        if n > 0 && worst.0 < PIVOT_RATIO_TOL {
            return Err(ReductionError::NotPositiveDefinite {
                matrix: ctx.matrix,
                context: ctx.context,
                local: (ctx.local_index)(worst.1),
                full: (ctx.full_index)(worst.1),
                ratio: worst.0,
            });
        }
        Ok(this)
    }

    fn for_each_pivot(&self, mut f: impl FnMut(usize, f64)) {
        if let SymbolicCholeskyRaw::Supernodal(s) = self.symbolic.raw() {
            let l = SupernodalLltRef::new(s, &self.values);
            for k in 0..s.n_supernodes() {
                let node = l.supernode(k);
                let start = node.start();
                let v = node.val();
                for c in 0..v.ncols() {
                    f(start + c, v[(c, c)]);
                }
            }
        }
    }

    /// Number of stored entries of the Cholesky factor (supernodal storage).
    pub fn factor_entries(&self) -> usize {
        self.values.len()
    }

    /// Solve `A X = B` in place for a row-major block.
    pub fn solve_rows(&self, x: &mut RowBlock) {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => supernodal_solve_rows(s, &self.values, x),
            SymbolicCholeskyRaw::Simplicial(_) => {
                let mut m = x.view().to_owned();
                self.solve_in_place(m.as_mut(), Par::Seq);
                x.view_mut().copy_from(&m);
            }
        }
    }

    /// Solve `A X = B` in place for the `n × k` block `rhs`.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>, par: Par) {
        let k = rhs.ncols();
        let req = self.symbolic.solve_in_place_scratch::<f64>(k, par);
        let mut mem = MemBuffer::new(req);
        let stack = MemStack::new(&mut mem);
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            stack,
        );
    }
}

/// Number of negative pivots of `L D Lᵀ` (supernodal, no pivoting) of the
/// symmetric matrix whose lower triangle, in its elimination order, is
/// `lower`; by Sylvester's law of inertia, its number of negative
/// eigenvalues (a Sturm-sequence count). `None` if a zero pivot occurred.
pub(crate) fn negative_pivots(lower: &Csc) -> Result<Option<usize>, ReductionError> {
    use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
    use faer::sparse::linalg::cholesky::supernodal::SupernodalLdltRef;
    let la = |what: &str, e: &dyn std::fmt::Debug| {
        ReductionError::LinearAlgebra(format!("{what} ({e:?})"))
    };
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    };
    let upper = lower.transpose().to_faer();
    let symbolic = factorize_symbolic_cholesky(
        upper.symbolic(),
        Side::Upper,
        SymmetricOrdering::Identity,
        params,
    )
    .map_err(|e| la("symbolic LDLᵀ", &e))?;
    drop(upper);
    let a = lower.to_faer();
    let mut values = AlignedVec::try_zeros(symbolic.len_val()).ok_or_else(|| {
        ReductionError::LinearAlgebra(format!(
            "out of memory for an LDLᵀ factor of {} entries",
            symbolic.len_val()
        ))
    })?;
    let req = symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default());
    let mut mem = MemBuffer::try_new(req)
        .map_err(|_| ReductionError::LinearAlgebra("out of memory for LDLᵀ scratch".into()))?;
    let result = symbolic.factorize_numeric_ldlt(
        &mut values,
        a.as_ref(),
        Side::Lower,
        LdltRegularization::default(),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    );
    if result.is_err() {
        return Ok(None);
    }
    let SymbolicCholeskyRaw::Supernodal(s) = symbolic.raw() else {
        return Err(ReductionError::LinearAlgebra(
            "LDLᵀ factor is not supernodal".into(),
        ));
    };
    let l = SupernodalLdltRef::new(s, &values);
    let mut count = 0usize;
    for k in 0..s.n_supernodes() {
        let v = l.supernode(k).val();
        for c in 0..v.ncols() {
            let d = v[(c, c)];
            if !d.is_finite() {
                return Ok(None);
            }
            if d < 0.0 {
                count += 1;
            }
        }
    }
    Ok(Some(count))
}

fn lower_diagonal(lower: &Csc) -> Vec<f64> {
    (0..lower.ncols)
        .map(|j| {
            let (rows, vals) = lower.col(j);
            match rows.first() {
                Some(&i) if i == j => vals[0],
                _ => 0.0,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csc::{add_scaled, canonical_symmetric, lower};
    use crate::testmodels::cantilever_2d;

    #[test]
    fn sturm_count_matches_dense_eigenvalues() {
        let mesh = cantilever_2d(600, 3.0);
        let n = mesh.n();
        let k = lower(&canonical_symmetric(mesh.k.as_ref(), "K", n).unwrap());
        let m = lower(&canonical_symmetric(mesh.m.as_ref(), "M", n).unwrap());
        let (vals, _) = crate::dense_generalized_eigenvalues(
            mesh.k.to_dense().as_ref(),
            mesh.m.to_dense().as_ref(),
        )
        .unwrap();
        for below in [1usize, 7, 30] {
            let sigma = 0.5 * (vals[below - 1] + vals[below]);
            let a = add_scaled(&k, &m, -sigma);
            let (_, inv, _) = fill_reducing_order(&a, Ordering::Metis).unwrap();
            let count = negative_pivots(&a.permute_sym_lower(&inv)).unwrap();
            assert_eq!(
                count,
                Some(below),
                "shift between eigenvalues {below} and {}",
                below + 1
            );
        }
    }
}
