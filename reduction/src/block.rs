//! Row-major blocks of vectors (`n × k`, each row contiguous) and the two
//! sparse kernels that dominate the reduction on them: the supernodal
//! triangular solves with the Cholesky factor, and symmetric sparse products.
//! With rows contiguous, the scatter/gather of a supernode's pattern and the
//! entries of a sparse matrix each touch one contiguous `k`-vector.

use crate::csc::{Csc, SymView};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::sparse::linalg::cholesky::supernodal::{SupernodalLltRef, SymbolicSupernodalCholesky};
use faer::{Accum, MatMut, MatRef, Par};

/// 64 bytes, 64-byte aligned.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Line([f64; 8]);

/// A zero-initialised `f64` buffer starting on a 64-byte boundary. The SIMD
/// kernels of faer split their loops by alignment; with a fixed alignment the
/// results do not depend on where the allocator placed the buffer (nor on
/// which thread made it), so they are reproducible bit for bit.
#[derive(Clone, Debug)]
pub(crate) struct AlignedVec {
    lines: Vec<Line>,
    len: usize,
}

impl AlignedVec {
    pub fn zeros(len: usize) -> Self {
        AlignedVec {
            lines: vec![Line([0.0; 8]); len.div_ceil(8)],
            len,
        }
    }

    /// `zeros`, or `None` if the memory cannot be had.
    pub fn try_zeros(len: usize) -> Option<Self> {
        let mut lines = Vec::new();
        lines.try_reserve_exact(len.div_ceil(8)).ok()?;
        lines.resize(len.div_ceil(8), Line([0.0; 8]));
        Some(AlignedVec { lines, len })
    }
}

impl std::ops::Deref for AlignedVec {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: `lines` holds at least `len` contiguous, initialised f64
        // (Line is repr(C) over [f64; 8], no padding).
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<f64>(), self.len) }
    }
}

impl std::ops::DerefMut for AlignedVec {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as in `deref`, with unique access through `&mut self`.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<f64>(), self.len) }
    }
}

/// `n × k` block stored row by row.
#[derive(Clone, Debug)]
pub(crate) struct RowBlock {
    pub n: usize,
    pub k: usize,
    pub data: AlignedVec,
}

impl RowBlock {
    pub fn zeros(n: usize, k: usize) -> Self {
        RowBlock {
            n,
            k,
            data: AlignedVec::zeros(n * k),
        }
    }

    /// A block whose contents are unspecified (to be overwritten), reusing
    /// a buffer of this thread's pool when one of the same size is there:
    /// large fresh allocations are mapped lazily and fault on every page.
    pub fn take(n: usize, k: usize) -> Self {
        let data = POOL.with(|pool| {
            let mut pool = pool.borrow_mut();
            pool.iter()
                .position(|b| b.len == n * k)
                .map(|pos| pool.swap_remove(pos))
        });
        match data {
            Some(data) => RowBlock { n, k, data },
            None => RowBlock::zeros(n, k),
        }
    }

    /// Return the buffer to this thread's pool (the four most recent are
    /// kept).
    pub fn give_back(self) {
        POOL.with(|pool| {
            let mut pool = pool.borrow_mut();
            if pool.len() >= 4 {
                pool.remove(0);
            }
            pool.push(self.data);
        });
    }

    /// Copy of a (column-major or any) matrix view.
    pub fn from_mat(a: MatRef<'_, f64>) -> Self {
        let mut b = Self::zeros(a.nrows(), a.ncols());
        b.view_mut().copy_from(a);
        b
    }

    /// `n × k` view (row stride `k`).
    pub fn view(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.data, self.k, self.n).transpose()
    }

    pub fn view_mut(&mut self) -> MatMut<'_, f64> {
        MatMut::from_column_major_slice_mut(&mut self.data, self.k, self.n).transpose_mut()
    }

    #[inline(always)]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.k..(i + 1) * self.k]
    }

    #[inline(always)]
    pub fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.data[i * self.k..(i + 1) * self.k]
    }
}

#[inline(always)]
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yv, xv) in y.iter_mut().zip(x) {
        *yv += a * xv;
    }
}

/// Supernodes with at most this many columns are solved with plain loops
/// (dense kernels have a fixed cost per call).
const SMALL_SUPERNODE: usize = 8;

/// Solve `L Lᵀ X = B` in place (`x` holds B on entry), `L` the supernodal
/// Cholesky factor, no permutation (the matrix was factored in its
/// elimination order). Sequential and deterministic.
pub(crate) fn supernodal_solve_rows(
    symbolic: &SymbolicSupernodalCholesky<usize>,
    values: &[f64],
    x: &mut RowBlock,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        unsafe { supernodal_solve_rows_avx2(symbolic, values, x) };
        return;
    }
    supernodal_solve_rows_impl(symbolic, values, x)
}

/// The same code compiled for AVX2 (wider vectors, same operations, so the
/// same results bit for bit).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn supernodal_solve_rows_avx2(
    symbolic: &SymbolicSupernodalCholesky<usize>,
    values: &[f64],
    x: &mut RowBlock,
) {
    supernodal_solve_rows_impl(symbolic, values, x)
}

#[inline(always)]
fn supernodal_solve_rows_impl(
    symbolic: &SymbolicSupernodalCholesky<usize>,
    values: &[f64],
    x: &mut RowBlock,
) {
    let l = SupernodalLltRef::new(symbolic, values);
    let k = x.k;
    if k == 0 {
        return;
    }
    let ns = symbolic.n_supernodes();
    let max_pat = (0..ns)
        .map(|s| l.supernode(s).pattern().len())
        .max()
        .unwrap_or(0);
    let mut tmp = RowBlock::zeros(max_pat, k);
    let mut acc = vec![0.0; k];
    // forward: L y = b
    for s in 0..ns {
        let node = l.supernode(s);
        let start = node.start();
        let pat = node.pattern();
        let lv = node.val();
        let size = lv.ncols();
        if size <= SMALL_SUPERNODE {
            for c in 0..size {
                let col = lv
                    .col(c)
                    .try_as_col_major()
                    .expect("supernode columns are contiguous");
                let col = col.as_slice();
                let j = start + c;
                let d = 1.0 / col[c];
                acc.copy_from_slice(x.row(j));
                acc.iter_mut().for_each(|v| *v *= d);
                x.row_mut(j).copy_from_slice(&acc);
                for (r, &l_rc) in col.iter().enumerate().take(size).skip(c + 1) {
                    axpy(x.row_mut(start + r), -l_rc, &acc);
                }
                for (idx, &i) in pat.iter().enumerate() {
                    axpy(x.row_mut(i), -col[size + idx], &acc);
                }
            }
        } else {
            let (ltop, lbot) = lv.split_at_row(size);
            solve_lower_triangular_in_place(ltop, x.view_mut().subrows_mut(start, size), Par::Seq);
            let np = pat.len();
            if np > 0 {
                let xtop = x.view().subrows(start, size);
                let tv = tmp.view_mut();
                matmul(
                    tv.subrows_mut(0, np),
                    Accum::Replace,
                    lbot,
                    xtop,
                    1.0,
                    Par::Seq,
                );
                for (idx, &i) in pat.iter().enumerate() {
                    let t = &tmp.data[idx * k..(idx + 1) * k];
                    for (xv, tv) in x.data[i * k..(i + 1) * k].iter_mut().zip(t) {
                        *xv -= tv;
                    }
                }
            }
        }
    }
    // backward: Lᵀ x = y
    for s in (0..ns).rev() {
        let node = l.supernode(s);
        let start = node.start();
        let pat = node.pattern();
        let lv = node.val();
        let size = lv.ncols();
        if size <= SMALL_SUPERNODE {
            for c in (0..size).rev() {
                let col = lv
                    .col(c)
                    .try_as_col_major()
                    .expect("supernode columns are contiguous");
                let col = col.as_slice();
                let j = start + c;
                acc.copy_from_slice(x.row(j));
                for (r, &l_rc) in col.iter().enumerate().take(size).skip(c + 1) {
                    axpy(&mut acc, -l_rc, x.row(start + r));
                }
                for (idx, &i) in pat.iter().enumerate() {
                    axpy(&mut acc, -col[size + idx], x.row(i));
                }
                let d = 1.0 / col[c];
                for (xv, a) in x.row_mut(j).iter_mut().zip(&acc) {
                    *xv = a * d;
                }
            }
        } else {
            let (ltop, lbot) = lv.split_at_row(size);
            let np = pat.len();
            if np > 0 {
                for (idx, &i) in pat.iter().enumerate() {
                    tmp.data[idx * k..(idx + 1) * k].copy_from_slice(&x.data[i * k..(i + 1) * k]);
                }
                let tv = tmp.view();
                matmul(
                    x.view_mut().subrows_mut(start, size),
                    Accum::Add,
                    lbot.transpose(),
                    tv.subrows(0, np),
                    -1.0,
                    Par::Seq,
                );
            }
            solve_upper_triangular_in_place(
                ltop.transpose(),
                x.view_mut().subrows_mut(start, size),
                Par::Seq,
            );
        }
    }
}

// Products of the sparse matrices with row-major blocks live here, with the blocks: the
// sparse storage (`csc`) knows nothing of them.
impl Csc {
    /// `selfᵀ x` for a general CSC and a row-major `x` (`nrows × k`):
    /// returns `ncols × k` (column-major).
    pub fn transpose_mul_rows(&self, x: &RowBlock) -> faer::Mat<f64> {
        let k = x.k;
        let mut out = faer::Mat::zeros(self.ncols, k);
        let mut acc = vec![0.0; k];
        for j in 0..self.ncols {
            let (rows, vals) = self.col(j);
            acc.iter_mut().for_each(|a| *a = 0.0);
            for (&i, &v) in rows.iter().zip(vals) {
                for (a, xv) in acc.iter_mut().zip(x.row(i)) {
                    *a += v * xv;
                }
            }
            for (c, a) in acc.iter().enumerate() {
                out[(j, c)] = *a;
            }
        }
        out
    }
}

impl SymView<'_> {
    /// `y = A x` on row-major blocks.
    pub fn mul_rows(&self, x: &RowBlock, y: &mut RowBlock) {
        sym_mul_rows(self.lower, self.inv, x, y)
    }
}

/// `y = A x` for `A` symmetric stored as its lower triangle in natural
/// order, `x`, `y` in the permuted numbering (`inv[natural] = permuted`).
/// The rows are gathered into natural order (one contiguous copy per row),
/// multiplied there (neighbouring entries, cache-friendly) and scattered back.
pub(crate) fn sym_mul_rows(a: &Csc, inv: Option<&[usize]>, x: &RowBlock, y: &mut RowBlock) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        unsafe { sym_mul_rows_avx2(a, inv, x, y) };
        return;
    }
    sym_mul_rows_impl(a, inv, x, y)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sym_mul_rows_avx2(a: &Csc, inv: Option<&[usize]>, x: &RowBlock, y: &mut RowBlock) {
    sym_mul_rows_impl(a, inv, x, y)
}

std::thread_local! {
    /// Scratch of the sparse products, kept between calls: fresh large
    /// allocations are mapped lazily and every first touch of a page faults.
    static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
    /// Reusable block buffers (see [`RowBlock::take`]).
    static POOL: std::cell::RefCell<Vec<AlignedVec>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Free this thread's scratch of the sparse products and its block pool.
pub(crate) fn release_scratch() {
    SCRATCH.with(|cell| *cell.borrow_mut() = Vec::new());
    POOL.with(|cell| cell.borrow_mut().clear());
}

/// Columns of the right-hand side processed together in a sparse product:
/// the rows touched by neighbouring matrix columns then stay in L2.
const CW: usize = 16;

#[inline(always)]
fn sym_mul_rows_impl(a: &Csc, inv: Option<&[usize]>, x: &RowBlock, y: &mut RowBlock) {
    let n = a.ncols;
    let k = x.k;
    debug_assert_eq!(x.n, n);
    debug_assert_eq!(y.n, n);
    debug_assert_eq!(y.k, k);
    if k == 0 {
        return;
    }
    let map = |i: usize| inv.map(|v| v[i]).unwrap_or(i);
    SCRATCH.with(|cell| {
        let mut scratch = cell.borrow_mut();
        if scratch.len() < 2 * n * CW {
            scratch.resize(2 * n * CW, 0.0);
        }
        let (xt, yt) = scratch.split_at_mut(n * CW);
        let yt = &mut yt[..n * CW];
        for c0 in (0..k).step_by(CW) {
            let w = CW.min(k - c0);
            for i in 0..n {
                let src = &x.row(map(i))[c0..c0 + w];
                let dst = &mut xt[i * CW..(i + 1) * CW];
                dst[..w].copy_from_slice(src);
                dst[w..].fill(0.0);
            }
            yt.fill(0.0);
            let mut acc = [0.0f64; CW];
            for j in 0..n {
                let (rows, vals) = a.col(j);
                acc = [0.0; CW];
                let xj: &[f64; CW] = xt[j * CW..(j + 1) * CW].try_into().expect("CW");
                let xj = *xj;
                for (&i, &v) in rows.iter().zip(vals) {
                    if i == j {
                        for q in 0..CW {
                            acc[q] += v * xj[q];
                        }
                        continue;
                    }
                    let xi: &[f64; CW] = xt[i * CW..(i + 1) * CW].try_into().expect("CW");
                    let yi: &mut [f64; CW] =
                        (&mut yt[i * CW..(i + 1) * CW]).try_into().expect("CW");
                    for q in 0..CW {
                        yi[q] += v * xj[q];
                        acc[q] += v * xi[q];
                    }
                }
                let yj: &mut [f64; CW] = (&mut yt[j * CW..(j + 1) * CW]).try_into().expect("CW");
                for q in 0..CW {
                    yj[q] += acc[q];
                }
            }
            let _ = acc;
            for i in 0..n {
                y.row_mut(map(i))[c0..c0 + w].copy_from_slice(&yt[i * CW..i * CW + w]);
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn views_are_row_major() {
        let a = Mat::from_fn(5, 3, |i, j| (10 * i + j) as f64);
        let b = RowBlock::from_mat(a.as_ref());
        assert_eq!(b.row(2), &[20.0, 21.0, 22.0]);
        assert_eq!(b.view()[(4, 1)], 41.0);
    }
}
