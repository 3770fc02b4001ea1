//! Sparse Cholesky `A = P Lᵀ L Pᵀ` of a symmetric positive definite matrix
//! with faer's low-level supernodal factorisation and a METIS or AMD ordering.

use crate::csc::Csc;
use crate::ordering::{metis_nd, Ordering};
use crate::ReductionError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::perm::PermRef;
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
    values: Vec<f64>,
    pub ordering_seconds: f64,
    pub symbolic_seconds: f64,
    pub numeric_seconds: f64,
}

/// How to name a failing pivot.
pub(crate) struct PivotContext<'a> {
    pub matrix: &'static str,
    pub context: &'static str,
    /// full-model index of local index `i`
    pub full_index: &'a dyn Fn(usize) -> usize,
}

impl SpdFactor {
    /// Factor the SPD matrix whose lower triangle is `lower`.
    pub fn new(
        lower: &Csc,
        ordering: Ordering,
        par: Par,
        ctx: &PivotContext<'_>,
    ) -> Result<Self, ReductionError> {
        let n = lower.ncols;
        let la = |what: &str, e: &dyn std::fmt::Debug| {
            ReductionError::LinearAlgebra(format!("{what} ({e:?})"))
        };
        let a = lower.to_faer();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let t0 = Instant::now();
        let (symbolic, ordering_seconds) = match ordering {
            Ordering::Metis => {
                let (fwd, inv) = metis_nd(lower)?;
                let ordering_seconds = t0.elapsed().as_secs_f64();
                let perm = PermRef::new_checked(&fwd, &inv, n);
                let s = factorize_symbolic_cholesky(
                    a.symbolic(),
                    Side::Lower,
                    SymmetricOrdering::Custom(perm),
                    params,
                )
                .map_err(|e| la("symbolic Cholesky", &e))?;
                (s, ordering_seconds)
            }
            Ordering::Amd => {
                // AMD runs inside the symbolic analysis; its time is counted there.
                let s = factorize_symbolic_cholesky(
                    a.symbolic(),
                    Side::Lower,
                    SymmetricOrdering::Amd,
                    params,
                )
                .map_err(|e| la("symbolic Cholesky", &e))?;
                (s, 0.0)
            }
        };
        let symbolic_seconds = t0.elapsed().as_secs_f64() - ordering_seconds;
        let t1 = Instant::now();
        let mut values = Vec::new();
        values.try_reserve_exact(symbolic.len_val()).map_err(|_| {
            ReductionError::LinearAlgebra(format!(
                "out of memory for a Cholesky factor of {} entries",
                symbolic.len_val()
            ))
        })?;
        values.resize(symbolic.len_val(), 0.0);
        let req = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut mem = MemBuffer::try_new(req).map_err(|_| {
            ReductionError::LinearAlgebra("out of memory for Cholesky scratch".into())
        })?;
        let stack = MemStack::new(&mut mem);
        let fwd_of = |j: usize| -> usize { symbolic.perm().map(|p| p.arrays().0[j]).unwrap_or(j) };
        let result = symbolic.factorize_numeric_llt(
            &mut values,
            a.as_ref(),
            Side::Lower,
            LltRegularization::default(),
            par,
            stack,
            Default::default(),
        );
        if let Err(LltError::NonPositivePivot { index }) = result {
            let local = fwd_of(index);
            return Err(ReductionError::NotPositiveDefinite {
                matrix: ctx.matrix,
                context: ctx.context,
                local,
                full: (ctx.full_index)(local),
                ratio: 0.0,
            });
        }
        drop(mem);
        let numeric_seconds = t1.elapsed().as_secs_f64();
        let this = SpdFactor {
            symbolic,
            values,
            ordering_seconds,
            symbolic_seconds,
            numeric_seconds,
        };
        // Near-singular pivots: a free body factors with round-off pivots.
        let diag = lower_diagonal(lower);
        let mut worst = (f64::INFINITY, 0usize);
        this.for_each_pivot(|j, l_jj| {
            let old = fwd_of_sym(&this.symbolic, j);
            let d = diag[old];
            let ratio = if d > 0.0 { l_jj * l_jj / d } else { 0.0 };
            if ratio < worst.0 {
                worst = (ratio, old);
            }
        });
        if n > 0 && worst.0 < PIVOT_RATIO_TOL {
            return Err(ReductionError::NotPositiveDefinite {
                matrix: ctx.matrix,
                context: ctx.context,
                local: worst.1,
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

fn fwd_of_sym(s: &SymbolicCholesky<usize>, j: usize) -> usize {
    s.perm().map(|p| p.arrays().0[j]).unwrap_or(j)
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
