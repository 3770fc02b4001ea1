//! A direct solve of the schur formulation's reduced matrix Q = blockdiag_h S_h + N_c that uses
//! its structure: a per-harmonic baseline and a low-rank update for the contacts whose Jacobian
//! couples harmonics.
//!
//! The linear part S_h is block-diagonal over harmonics; the contact Jacobian N_c is
//! block-diagonal over contact points, each point coupling its own harmonics. Split N_c into its
//! harmonic-diagonal part N̄ (per contact and harmonic h, the mean stiffness R + iI of its cos/sin
//! block pattern [[R, I], [−I, R]]) and the rest E = N_c − N̄. A contact stuck or open over the
//! whole period has a constant tangent stiffness, so E vanishes on it except, for a stuck point
//! that keeps its initial condition T(0) = mμN(0), in the rows of the constant harmonic; only a
//! point that slips or lifts off for part of the period fills its rows of E. With U selecting
//! the r rows where E is not zero and M those rows of E,
//!
//! ```text
//! Q = P + U M,   P = blockdiag_h (S_h + N̄_h)   (one dense LU per harmonic, n_q rows, complex)
//! Q⁻¹ = P⁻¹ − P⁻¹U C⁻¹ M P⁻¹,   C = I_r + M P⁻¹ U   (Sherman-Morrison-Woodbury, C dense r × r)
//! ```
//!
//! Factorising costs per harmonic (8/3)·n_q³ for P, 8·n_q² per column of U for P⁻¹U and (2/3)·r³
//! for C, against (2/3)·(n_q·blocks)³ for the dense LU of Q: [`LowRankFactor::new`] is asked only
//! when that estimate is lower, that is when few enough contacts slip
//! ([`crate::hbm::cost::low_rank_flops`]). The
//! solve is exact up to rounding, like the dense LU's.

use faer::{c64, Mat};

use super::coordinates::RelativeCoordinates;
use super::elimination::{EliminatedHarmonic, SchurRef};
use crate::numerics::linalg::{packed_complex_lu, packed_lu, LinearSolveError, PackedLu};

/// A row of E is kept when one of its entries exceeds this fraction of the largest entry of
/// its contact's block (below it the entry is rounding in the AFT's Jacobian).
pub const DROP_TOLERANCE: f64 = 1e-12;

/// The per-harmonic LU of S_h + N̄_h.
pub(super) enum HarmonicLu {
    /// One real block (h = 0, or a harmonic with a single coefficient block).
    Real { block: usize, lu: PackedLu<f64> },
    /// Cosine and sine blocks, on x_cos − i x_sin.
    Complex {
        cos: usize,
        sin: usize,
        lu: PackedLu<c64>,
    },
}

impl HarmonicLu {
    /// Coefficient blocks of this harmonic.
    fn blocks(&self) -> Vec<usize> {
        match self {
            HarmonicLu::Real { block, .. } => vec![*block],
            HarmonicLu::Complex { cos, sin, .. } => vec![*cos, *sin],
        }
    }
}

impl RelativeCoordinates {
    /// Contact `p`'s Jacobian value for force a of block j and coordinate b of block i (see
    /// [`RelativeCoordinates::factor`] for the layout).
    pub(super) fn contact_value(
        &self,
        values: &[f64],
        p: usize,
        (j, i): (usize, usize),
        (a, b): (usize, usize),
    ) -> f64 {
        let (nb, k) = (self.blocks.len(), self.rows[p].len());
        values[self.value_offsets[p] + ((j * nb + i) * k + a) * k + b]
    }

    /// The harmonic-diagonal part N̄ of contact `p`'s entry (j, a) × (i, b): its value where
    /// blocks j and i belong to one harmonic (the mean of the cos/sin pattern), else zero.
    fn mean_contact_value(
        &self,
        values: &[f64],
        p: usize,
        (j, i): (usize, usize),
        (a, b): (usize, usize),
    ) -> f64 {
        let v = |j, i| self.contact_value(values, p, (j, i), (a, b));
        let (hj, pj) = self.blocks[j];
        let (hi, _) = self.blocks[i];
        if hj != hi {
            return 0.0;
        }
        match pj {
            None => v(j, i),
            Some((partner, sign)) => {
                // sign +1: j is the cosine block and the partner the sine block.
                let (c, s) = if sign > 0.0 {
                    (j, partner)
                } else {
                    (partner, j)
                };
                let mean = 0.5 * (v(c, c) + v(s, s));
                let skew = 0.5 * (v(c, s) - v(s, c));
                match (j == c, i == c) {
                    (true, true) | (false, false) => mean,
                    (true, false) => skew,
                    (false, true) => -skew,
                }
            }
        }
    }

    /// Calls `f(p, (a, q_a), (b, q_b))` for every pair of non-zero rows a, b of every contact
    /// p, with their relative coordinates.
    pub(super) fn for_each_contact_entry(
        &self,
        mut f: impl FnMut(usize, (usize, usize), (usize, usize)),
    ) {
        for (p, coordinate) in self.coordinate.iter().enumerate() {
            for (a, qa) in coordinate.iter().enumerate() {
                let Some(qa) = *qa else { continue };
                for (b, qb) in coordinate.iter().enumerate() {
                    let Some(qb) = *qb else { continue };
                    f(p, (a, qa), (b, qb));
                }
            }
        }
    }

    /// Per harmonic, the LU of S_h + N̄_h from the eliminated harmonics and the contact blocks
    /// `values`.
    pub(super) fn harmonic_lus(
        &self,
        harmonics: &[EliminatedHarmonic],
        values: &[f64],
    ) -> Result<Vec<HarmonicLu>, LinearSolveError> {
        let mut lus = Vec::with_capacity(harmonics.len());
        for eh in harmonics {
            lus.push(match eh.schur() {
                SchurRef::Real(schur) => {
                    let block = eh.blocks[0];
                    let mut s = schur.clone();
                    self.for_each_contact_entry(|p, (a, qa), (b, qb)| {
                        s[(qa, qb)] += self.contact_value(values, p, (block, block), (a, b));
                    });
                    HarmonicLu::Real {
                        block,
                        lu: packed_lu(s)?,
                    }
                }
                SchurRef::Complex(schur) => {
                    let (cos, sin) = (eh.blocks[0], eh.blocks[1]);
                    let mut s = schur.clone();
                    self.for_each_contact_entry(|p, (a, qa), (b, qb)| {
                        let re = self.mean_contact_value(values, p, (cos, cos), (a, b));
                        let im = self.mean_contact_value(values, p, (cos, sin), (a, b));
                        s[(qa, qb)] += c64::new(re, im);
                    });
                    HarmonicLu::Complex {
                        cos,
                        sin,
                        lu: packed_complex_lu(s)?,
                    }
                }
            });
        }
        Ok(lus)
    }

    /// The rows of E = N_c − N̄ (see the module docs) that are not zero: per row its reduced
    /// index j·n_q + q_a and its entries (reduced index, value) over its contact's coordinates.
    pub(super) fn coupling_rows(&self, values: &[f64]) -> Vec<(usize, Vec<(usize, f64)>)> {
        let (n_q, nb) = (self.n_q, self.blocks.len());
        let mut rows = Vec::new();
        for (p, coordinate) in self.coordinate.iter().enumerate() {
            let block = &values[self.value_offsets[p]..self.value_offsets[p + 1]];
            let largest = block.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let threshold = DROP_TOLERANCE * largest;
            for j in 0..nb {
                for (a, qa) in coordinate.iter().enumerate() {
                    let Some(qa) = *qa else { continue };
                    let mut entries = Vec::new();
                    let mut keep = false;
                    for i in 0..nb {
                        for (b, qb) in coordinate.iter().enumerate() {
                            let Some(qb) = *qb else { continue };
                            let e = self.contact_value(values, p, (j, i), (a, b))
                                - self.mean_contact_value(values, p, (j, i), (a, b));
                            keep |= e.abs() > threshold;
                            entries.push((i * n_q + qb, e));
                        }
                    }
                    if keep {
                        rows.push((j * n_q + qa, entries));
                    }
                }
            }
        }
        rows
    }
}

/// Applies P⁻¹ (the per-harmonic LUs `lus`) in place to the columns of `r` (reduced
/// coordinates, n_q rows per block).
pub(super) fn apply_harmonic_lus(lus: &[HarmonicLu], n_q: usize, r: &mut Mat<f64>) {
    let k = r.ncols();
    for lu in lus {
        match lu {
            HarmonicLu::Real { block, lu } => {
                let mut x = Mat::from_fn(n_q, k, |i, c| r[(block * n_q + i, c)]);
                lu.solve_in_place(&mut x);
                for c in 0..k {
                    for i in 0..n_q {
                        r[(block * n_q + i, c)] = x[(i, c)];
                    }
                }
            }
            HarmonicLu::Complex { cos, sin, lu } => {
                let mut x = Mat::from_fn(n_q, k, |i, c| {
                    c64::new(r[(cos * n_q + i, c)], -r[(sin * n_q + i, c)])
                });
                lu.solve_in_place(&mut x);
                for c in 0..k {
                    for i in 0..n_q {
                        r[(cos * n_q + i, c)] = x[(i, c)].re;
                        r[(sin * n_q + i, c)] = -x[(i, c)].im;
                    }
                }
            }
        }
    }
}

/// P_h⁻¹ e for the unit vectors e at the reduced indices `at` (all in harmonic `lu`'s blocks),
/// on that harmonic's blocks only (n_q rows per block, in the order of [`HarmonicLu::blocks`]).
fn inverse_columns(lu: &HarmonicLu, n_q: usize, at: impl Iterator<Item = usize>) -> Mat<f64> {
    let at: Vec<usize> = at.collect();
    match lu {
        HarmonicLu::Real { lu, .. } => {
            let mut x = Mat::<f64>::zeros(n_q, at.len());
            for (c, &idx) in at.iter().enumerate() {
                x[(idx % n_q, c)] = 1.0;
            }
            lu.solve_in_place(&mut x);
            x
        }
        HarmonicLu::Complex { cos, lu, .. } => {
            // A unit cosine entry is e_q on x_cos − i x_sin, a unit sine entry −i e_q.
            let mut z = Mat::<c64>::zeros(n_q, at.len());
            for (c, &idx) in at.iter().enumerate() {
                z[(idx % n_q, c)] = if idx / n_q == *cos {
                    c64::new(1.0, 0.0)
                } else {
                    c64::new(0.0, -1.0)
                };
            }
            lu.solve_in_place(&mut z);
            Mat::from_fn(2 * n_q, at.len(), |i, c| {
                if i < n_q {
                    z[(i, c)].re
                } else {
                    -z[(i - n_q, c)].im
                }
            })
        }
    }
}

/// The factorised reduced matrix Q = P + U M (see the module docs).
pub(super) struct LowRankFactor {
    n_q: usize,
    lus: Vec<HarmonicLu>,
    /// Rows of M: (reduced index, entries).
    rows: Vec<(usize, Vec<(usize, f64)>)>,
    /// Per harmonic (in the order of `lus`): the columns of U in it (positions in `rows`) and
    /// P⁻¹U on that harmonic's blocks (blocks · n_q rows, one column each).
    inverse_u: Vec<(Vec<usize>, Mat<f64>)>,
    /// LU of C = I + M P⁻¹U.
    capacitance: PackedLu<f64>,
}

impl LowRankFactor {
    /// Factorises Q from the per-harmonic LUs `lus` and the coupling rows `rows`
    /// ([`RelativeCoordinates::coupling_rows`]).
    pub(super) fn new(
        n_q: usize,
        lus: Vec<HarmonicLu>,
        rows: Vec<(usize, Vec<(usize, f64)>)>,
    ) -> Result<Self, LinearSolveError> {
        let r = rows.len();
        let mut inverse_u = Vec::with_capacity(lus.len());
        let mut capacitance = Mat::<f64>::identity(r, r);
        for lu in &lus {
            let blocks = lu.blocks();
            let columns: Vec<usize> = (0..r)
                .filter(|&c| blocks.contains(&(rows[c].0 / n_q)))
                .collect();
            // P_h⁻¹ applied to U's columns of this harmonic, on its blocks.
            let local = inverse_columns(lu, n_q, columns.iter().map(|&c| rows[c].0));
            // C += M P⁻¹U on these columns: each row of M meets this harmonic's blocks.
            for (rho, (_, entries)) in rows.iter().enumerate() {
                for &(idx, v) in entries {
                    let Some(l) = blocks.iter().position(|&b| b == idx / n_q) else {
                        continue;
                    };
                    if v == 0.0 {
                        continue;
                    }
                    let li = l * n_q + idx % n_q;
                    for (c, &col) in columns.iter().enumerate() {
                        capacitance[(rho, col)] += v * local[(li, c)];
                    }
                }
            }
            inverse_u.push((columns, local));
        }
        Ok(Self {
            n_q,
            lus,
            rows,
            inverse_u,
            capacitance: packed_lu(capacitance)?,
        })
    }

    /// Rows r of the update.
    pub(super) fn rank(&self) -> usize {
        self.rows.len()
    }

    /// The sign of det Q (±1), as the dense LU of Q gives it: det Q = det P · det C (the matrix
    /// determinant lemma for P + U M). A harmonic with cosine and sine blocks contributes
    /// det [[A, B], [−B, A]] = |det(A − iB)|² ≥ 0 to det P (its blocks are the cosine-sine form
    /// of the complex matrix its LU factorises), so only the real blocks' LUs and C's count.
    pub(super) fn det_sign(&self) -> f64 {
        let baseline: f64 = self
            .lus
            .iter()
            .map(|h| match h {
                HarmonicLu::Real { lu, .. } => lu.det_sign(),
                HarmonicLu::Complex { .. } => 1.0,
            })
            .product();
        baseline * self.capacitance.det_sign()
    }

    /// Q⁻¹ r for the columns of `r` (reduced coordinates).
    pub(super) fn solve(&self, mut r: Mat<f64>) -> Mat<f64> {
        let n_q = self.n_q;
        apply_harmonic_lus(&self.lus, n_q, &mut r);
        let k = r.ncols();
        let mut t = Mat::from_fn(self.rows.len(), k, |rho, c| {
            self.rows[rho]
                .1
                .iter()
                .map(|&(idx, v)| v * r[(idx, c)])
                .sum::<f64>()
        });
        self.capacitance.solve_in_place(&mut t);
        for (lu, (columns, local)) in self.lus.iter().zip(&self.inverse_u) {
            let t_h = Mat::from_fn(columns.len(), k, |m, c| t[(columns[m], c)]);
            let update = local * &t_h;
            for (l, &block) in lu.blocks().iter().enumerate() {
                for c in 0..k {
                    for i in 0..n_q {
                        r[(block * n_q + i, c)] -= update[(l * n_q + i, c)];
                    }
                }
            }
        }
        r
    }
}
