//! Newton's matrix in the schur formulation: the elimination of z per harmonic, then
//! blockdiag S_h + N_c on the relative coordinates, factored, with its products and entries.

use std::sync::Arc;

use faer::{c64, Mat};

use super::coordinates::{HarmonicBlocks, RelativeCoordinates};
use super::elimination::{EliminatedHarmonic, Elimination, ZPart};
use super::lowrank::LowRankFactor;
use crate::hbm::cost::low_rank_flops;
use crate::numerics::jacobian::{ImplicitFactor, ImplicitJacobian};
use crate::numerics::linalg::{packed_complex_lu, packed_lu, LinearSolveError, PackedLu};
use crate::numerics::work::{self, Work};

impl RelativeCoordinates {
    /// K − (hω)²M on y-coordinate ranges `rows` × `cols` (real: h = 0, or a harmonic without
    /// its sine block, whose damping term has no partner).
    fn real_block(
        &self,
        hb: &HarmonicBlocks,
        omega: f64,
        rows: std::ops::Range<usize>,
        cols: std::ops::Range<usize>,
    ) -> Mat<f64> {
        let hw = hb.harmonic as f64 * omega;
        let (r0, c0) = (rows.start, cols.start);
        Mat::from_fn(rows.len(), cols.len(), |i, j| {
            self.k_y[(r0 + i, c0 + j)] - hw * hw * self.m_y[(r0 + i, c0 + j)]
        })
    }

    /// K − (hω)²M + i hωC on y-coordinate ranges `rows` × `cols`: the complex dynamic
    /// stiffness, acting on x_cos − i x_sin and giving r_cos − i r_sin.
    fn complex_block(
        &self,
        hb: &HarmonicBlocks,
        omega: f64,
        rows: std::ops::Range<usize>,
        cols: std::ops::Range<usize>,
    ) -> Mat<c64> {
        let hw = hb.harmonic as f64 * omega;
        let (r0, c0) = (rows.start, cols.start);
        Mat::from_fn(rows.len(), cols.len(), |i, j| {
            let (p, q) = (r0 + i, c0 + j);
            c64::new(
                self.k_y[(p, q)] - hw * hw * self.m_y[(p, q)],
                hw * self.c_y[(p, q)],
            )
        })
    }

    /// Eliminates the z coordinates of one harmonic at ω: from the glued structure's modes
    /// when `modal` and they exist ([`super::modal`], unless ω is too close to a glued mode),
    /// else by LU.
    fn eliminate(
        &self,
        hb: &HarmonicBlocks,
        omega: f64,
        modal: bool,
    ) -> Result<EliminatedHarmonic, LinearSolveError> {
        let (n, n_q) = (self.n, self.n_q);
        let blocks: Vec<usize> = std::iter::once(hb.first).chain(hb.second).collect();
        if let Some(basis) = modal.then(|| self.modal_basis()).flatten() {
            let s = hb.harmonic as f64 * omega;
            if let Some(m) = basis.harmonic(s, hb.second.is_some())? {
                work::add(Work::ModalElimination, 1);
                return Ok(EliminatedHarmonic {
                    blocks,
                    elimination: Elimination::Modal(m),
                });
            }
        }
        let elimination = if hb.second.is_none() {
            let a_qq = self.real_block(hb, omega, 0..n_q, 0..n_q);
            if n == n_q {
                Elimination::Real {
                    lu_zz: None,
                    w: Mat::zeros(0, n_q),
                    a_qz: Mat::zeros(n_q, 0),
                    schur: a_qq,
                }
            } else {
                let lu = packed_lu(self.real_block(hb, omega, n_q..n, n_q..n))?;
                let mut w = self.real_block(hb, omega, n_q..n, 0..n_q);
                lu.solve_in_place(&mut w);
                let a_qz = self.real_block(hb, omega, 0..n_q, n_q..n);
                let schur = &a_qq - &a_qz * &w;
                Elimination::Real {
                    lu_zz: Some(lu),
                    w,
                    a_qz,
                    schur,
                }
            }
        } else {
            let a_qq = self.complex_block(hb, omega, 0..n_q, 0..n_q);
            if n == n_q {
                Elimination::Complex {
                    lu_zz: None,
                    w: Mat::zeros(0, n_q),
                    a_qz: Mat::zeros(n_q, 0),
                    schur: a_qq,
                }
            } else {
                let a_zz = self.complex_block(hb, omega, n_q..n, n_q..n);
                let lu = packed_complex_lu(a_zz)?;
                let mut w = self.complex_block(hb, omega, n_q..n, 0..n_q);
                lu.solve_in_place(&mut w);
                let a_qz = self.complex_block(hb, omega, 0..n_q, n_q..n);
                let schur = &a_qq - &a_qz * &w;
                Elimination::Complex {
                    lu_zz: Some(lu),
                    w,
                    a_qz,
                    schur,
                }
            }
        };
        Ok(EliminatedHarmonic {
            blocks,
            elimination,
        })
    }

    /// Every harmonic's elimination at ω: the last factorisation's when it was at this ω exactly
    /// ([`EliminationCache`](super::elimination::EliminationCache)), else computed (without holding
    /// the cache meanwhile) and kept.
    pub(super) fn eliminated_at(
        &self,
        omega: f64,
        modal: bool,
    ) -> Result<Arc<Vec<EliminatedHarmonic>>, LinearSolveError> {
        let cache = || {
            self.last_elimination
                .0
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        };
        if let Some((bits, cached_modal, eliminated)) = cache().as_ref() {
            if *bits == omega.to_bits() && *cached_modal == modal {
                return Ok(Arc::clone(eliminated));
            }
        }
        let eliminated = Arc::new(
            self.harmonics
                .iter()
                .map(|hb| self.eliminate(hb, omega, modal))
                .collect::<Result<Vec<_>, _>>()?,
        );
        *cache() = Some((omega.to_bits(), modal, Arc::clone(&eliminated)));
        Ok(eliminated)
    }

    /// Factorises J at ω with the contact blocks `contact_values` (one (k·blocks)² block per
    /// contact from [`Self::value_offsets`], k = 2 rows for a 1D point and 3 for a 2D point,
    /// indexed ((j·blocks + i)·k + a)·k + b for force a ∈ {T, (T₂,) N} of block j and
    /// coordinate b ∈ {u, (u₂,) v} of block i).
    pub fn factor(
        self: &Arc<Self>,
        omega: f64,
        contact_values: &[f64],
        solver: ReducedSolver,
    ) -> Result<SchurFactor, LinearSolveError> {
        if !omega.is_finite() || contact_values.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let modal = solver == ReducedSolver::Structured;
        let eliminated = self.eliminated_at(omega, modal)?;
        let reduced = self.reduced_factor(&eliminated, contact_values, solver)?;
        Ok(SchurFactor {
            coords: Arc::clone(self),
            harmonics: eliminated,
            reduced,
        })
    }

    /// The factorised reduced matrix blockdiag_h S_h + N_c of the eliminated `harmonics` with
    /// the contact blocks `contact_values`: with [`ReducedSolver::Structured`], by the low-rank
    /// update of a per-harmonic baseline ([`super::lowrank`]) when its estimated flops are below
    /// the dense LU's (and the baseline can be factorised); else by the dense LU.
    pub(super) fn reduced_factor(
        &self,
        harmonics: &[EliminatedHarmonic],
        contact_values: &[f64],
        solver: ReducedSolver,
    ) -> Result<ReducedFactor, LinearSolveError> {
        let (n_q, nb) = (self.n_q, self.blocks.len());
        if solver == ReducedSolver::Structured {
            let rows = self.coupling_rows(contact_values);
            let dense = 2.0 / 3.0 * ((n_q * nb) as f64).powi(3);
            if low_rank_flops(n_q, harmonics.len(), rows.len()) < dense {
                let factor = self
                    .harmonic_lus(harmonics, contact_values)
                    .and_then(|lus| LowRankFactor::new(n_q, lus, rows));
                if let Ok(f) = factor {
                    work::add(Work::LowRankFactorisation, 1);
                    work::add(Work::LowRankRows, f.rank() as u64);
                    return Ok(ReducedFactor::LowRank(f));
                }
            }
        }
        let mut s = Mat::<f64>::zeros(n_q * nb, n_q * nb);
        for eh in harmonics.iter() {
            eh.add_schur_complement(&mut s, n_q);
        }
        for p in 0..self.rows.len() {
            let values = &contact_values[self.value_offsets[p]..self.value_offsets[p + 1]];
            // Entries on a zero row or column act on nothing (that row of B is zero).
            let coordinate = &self.coordinate[p];
            let k = coordinate.len();
            for j in 0..nb {
                for i in 0..nb {
                    for a in 0..k {
                        let Some(qa) = coordinate[a] else { continue };
                        for b in 0..k {
                            let Some(qb) = coordinate[b] else { continue };
                            let v = values[((j * nb + i) * k + a) * k + b];
                            s[(j * n_q + qa, i * n_q + qb)] += v;
                        }
                    }
                }
            }
        }
        let lu = packed_lu(s)?;
        let single = lu.to_single();
        Ok(ReducedFactor::Dense { lu, single })
    }

    /// y += s·J x with J at ω and contact blocks `contact_values` (x, y of length n·blocks).
    pub fn mul_add(
        &self,
        omega: f64,
        contact_values: &[f64],
        scale: f64,
        x: &[f64],
        y: &mut [f64],
    ) {
        let (n, nb) = (self.n, self.blocks.len());
        let xm = Mat::from_fn(n, nb, |i, j| x[j * n + i]);
        let kx = &self.k * &xm;
        let mx = &self.m * &xm;
        let cx = &self.c * &xm;
        for (j, &(h, partner)) in self.blocks.iter().enumerate() {
            let hw = h as f64 * omega;
            for i in 0..n {
                let mut v = kx[(i, j)] - hw * hw * mx[(i, j)];
                if let Some((pj, sign)) = partner {
                    v += sign * hw * cx[(i, pj)];
                }
                y[j * n + i] += scale * v;
            }
        }
        let dot = |row: &[(usize, f64)], block: usize| -> f64 {
            row.iter().map(|&(d, a)| a * x[block * n + d]).sum()
        };
        for (p, rows) in self.rows.iter().enumerate() {
            let values = &contact_values[self.value_offsets[p]..self.value_offsets[p + 1]];
            let k = rows.len();
            let coords: Vec<Vec<f64>> = (0..nb)
                .map(|i| rows.iter().map(|r| dot(r, i)).collect())
                .collect();
            let mut force = vec![0.0; k];
            for j in 0..nb {
                force.iter_mut().for_each(|f| *f = 0.0);
                for (i, c) in coords.iter().enumerate() {
                    for a in 0..k {
                        for b in 0..k {
                            force[a] += values[((j * nb + i) * k + a) * k + b] * c[b];
                        }
                    }
                }
                for (row, f) in rows.iter().zip(&force) {
                    for &(d, a) in row {
                        y[j * n + d] += scale * a * f;
                    }
                }
            }
        }
    }

    /// Entry (row, col) of J (problem coordinates, harmonic-major), for checks.
    pub fn entry(&self, omega: f64, contact_values: &[f64], row: usize, col: usize) -> f64 {
        let (n, nb) = (self.n, self.blocks.len());
        let (jb, p) = (row / n, row % n);
        let (ib, q) = (col / n, col % n);
        let (h, partner) = self.blocks[jb];
        let hw = h as f64 * omega;
        let mut v = 0.0;
        if jb == ib {
            v += self.k[(p, q)] - hw * hw * self.m[(p, q)];
        }
        if let Some((pj, sign)) = partner {
            if pj == ib {
                v += sign * hw * self.c[(p, q)];
            }
        }
        let coef = |row: &[(usize, f64)], d: usize| -> f64 {
            row.iter().filter(|e| e.0 == d).map(|e| e.1).sum()
        };
        for &c in &self.dof_contacts[p] {
            let rows = &self.rows[c];
            let k = rows.len();
            let rows_p: Vec<f64> = rows.iter().map(|r| coef(r, p)).collect();
            let cols_q: Vec<f64> = rows.iter().map(|r| coef(r, q)).collect();
            let values = &contact_values[self.value_offsets[c]..self.value_offsets[c + 1]];
            for a in 0..k {
                for b in 0..k {
                    v += rows_p[a] * values[((jb * nb + ib) * k + a) * k + b] * cols_q[b];
                }
            }
        }
        v
    }
}

/// How the reduced matrix blockdiag_h S_h + N_c is factorised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReducedSolver {
    /// Dense LU (the `schur` formulation).
    Dense,
    /// Per-harmonic baseline and low-rank update where that is estimated cheaper, else dense
    /// LU (the `schur-lowrank` formulation, [`super::lowrank`]).
    Structured,
}

/// The schur formulation's Jacobian storage for [`AssembledJacobian::implicit`]: the values
/// are one (k·blocks)² block per contact point (k = 2 rows, 3 for a 2D point) (see [`RelativeCoordinates::factor`]); the
/// linear part is formed from the structural matrices at ω; the reduced matrix is factorised
/// by the [`ReducedSolver`].
///
/// [`AssembledJacobian::implicit`]: crate::numerics::jacobian::AssembledJacobian::implicit
#[derive(Debug)]
pub struct SchurJacobian(pub Arc<RelativeCoordinates>, pub ReducedSolver);

impl ImplicitJacobian for SchurJacobian {
    fn dim(&self) -> usize {
        self.0.n_dofs() * self.0.n_blocks()
    }
    fn values_len(&self) -> usize {
        *self
            .0
            .value_offsets()
            .last()
            .expect("one offset per contact plus the total")
    }
    fn entry(&self, omega: f64, values: &[f64], i: usize, j: usize) -> f64 {
        self.0.entry(omega, values, i, j)
    }
    fn mul_add(&self, omega: f64, values: &[f64], col_scale: f64, x: &[f64], y: &mut [f64]) {
        self.0.mul_add(omega, values, col_scale, x, y)
    }
    fn factor(
        &self,
        omega: f64,
        values: &[f64],
    ) -> Result<Box<dyn ImplicitFactor>, LinearSolveError> {
        Ok(Box::new(self.0.factor(omega, values, self.1)?))
    }
}

/// A factorised Jacobian of the schur formulation (see the module docs).
pub struct SchurFactor {
    coords: Arc<RelativeCoordinates>,
    pub(super) harmonics: Arc<Vec<EliminatedHarmonic>>,
    /// blockdiag_h S_h + N_c factorised.
    reduced: ReducedFactor,
}

/// The reduced matrix blockdiag_h S_h + N_c factorised.
pub(super) enum ReducedFactor {
    /// Dense LU, and the same LU rounded to single precision for approximate solves.
    Dense {
        lu: PackedLu<f64>,
        single: PackedLu<f32>,
    },
    /// Per-harmonic baseline and low-rank update ([`super::lowrank`]).
    LowRank(LowRankFactor),
}

impl SchurFactor {
    /// The rank of the low-rank update when the reduced matrix was factorised by structure
    /// ([`super::lowrank`]); None for the dense LU.
    pub fn low_rank(&self) -> Option<usize> {
        match &self.reduced {
            ReducedFactor::LowRank(f) => Some(f.rank()),
            ReducedFactor::Dense { .. } => None,
        }
    }
}

impl ReducedFactor {
    /// The reduced matrix's inverse applied to `r` (with `single`, the dense LU's
    /// single-precision factors).
    pub(super) fn solve(&self, r: Mat<f64>, single: bool) -> Mat<f64> {
        match self {
            ReducedFactor::Dense { lu, single: lu32 } if single => {
                let mut y = Mat::from_fn(r.nrows(), r.ncols(), |i, j| r[(i, j)] as f32);
                lu32.solve_in_place(&mut y);
                Mat::from_fn(y.nrows(), y.ncols(), |i, j| y[(i, j)] as f64)
            }
            ReducedFactor::Dense { lu, .. } => {
                let mut y = r;
                lu.solve_in_place(&mut y);
                y
            }
            ReducedFactor::LowRank(f) => f.solve(r),
        }
    }
}

impl ImplicitFactor for SchurFactor {
    /// Solves J x = b (problem coordinates, harmonic-major, length n·blocks). With `single`,
    /// the reduced system is solved with the factors rounded to single precision: twice as
    /// fast on large factors, with a relative error of about 10⁻⁷ times the condition number
    /// (for the chord steps of a corrector, whose convergence is judged on the true residual).
    fn solve(&self, b: &[f64], single: bool) -> Vec<f64> {
        solve_eliminated(&self.coords, &self.harmonics, b, |r_q| {
            self.reduced.solve(r_q, single)
        })
    }

    /// The sign of det J up to a fixed factor: that of the reduced matrix's dense LU. The
    /// eliminated part adds only det of each harmonic's linear dynamic stiffness on the
    /// eliminated coordinates, in cosine-sine form |det(K − k²ω²M + ikωC)|² ≥ 0 (the static
    /// stiffness for k = 0), and the change to relative coordinates is fixed. The low-rank
    /// factorisation gives the same sign by the matrix determinant lemma
    /// ([`LowRankFactor::det_sign`]).
    fn det_sign(&self) -> Option<f64> {
        match &self.reduced {
            ReducedFactor::Dense { lu, .. } => Some(lu.det_sign()),
            ReducedFactor::LowRank(f) => Some(f.det_sign()),
        }
    }
}

/// Solves (Ã + [R 0; 0 0]) y = Tᵀ b by the per-harmonic elimination `harmonics` and returns
/// x = T y (problem coordinates, harmonic-major, length n·blocks): `reduced` solves the reduced
/// system on the relative coordinates, blockdiag_h S_h + R, for its right-hand side (n_q·blocks
/// rows, block-major): the dense LU of the whole reduced matrix, or its structured factorisation
/// ([`super::lowrank`]).
pub(super) fn solve_eliminated(
    co: &RelativeCoordinates,
    harmonics: &[EliminatedHarmonic],
    b: &[f64],
    reduced: impl FnOnce(Mat<f64>) -> Mat<f64>,
) -> Vec<f64> {
    let (n, n_q, nb) = (co.n, co.n_q, co.blocks.len());
    let bm = Mat::from_fn(n, nb, |i, j| b[j * n + i]);
    let by = co.to_relative_coordinates(&bm);
    let basis = co.modal.get().and_then(Option::as_ref);
    let mut r_q = Mat::<f64>::zeros(n_q * nb, 1);
    let kept: Vec<ZPart> = harmonics
        .iter()
        .map(|eh| eh.reduce_rhs(basis, &by, n_q, &mut r_q))
        .collect();
    let y_q = reduced(r_q);
    let mut y = Mat::<f64>::zeros(n, nb);
    for (eh, z) in harmonics.iter().zip(kept) {
        eh.back_substitute(basis, &y_q, z, n_q, &mut y);
    }
    let x = co.to_problem_coordinates(&y);
    let mut out = vec![0.0; n * nb];
    for j in 0..nb {
        for i in 0..n {
            out[j * n + i] = x[(i, j)];
        }
    }
    out
}
