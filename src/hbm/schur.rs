//! The `schur` formulation: Newton on all DOFs, each linear solve reduced to the relative
//! contact coordinates by eliminating everything else per harmonic.
//!
//! A contact point acts on the structure only through its relative displacements u = aₜ·x and
//! v = aₙ·x (and u₂ = aₜ₂·x for a 2D-friction point, [`crate::contact`]). Stack those rows into
//! B (n_q = 2 per 1D contact, 3 per 2D contact, ×
//! n DOFs, nonzero on the contact DOFs c only) and change coordinates on c:
//!
//! ```text
//! x_c = P q + N w,   B P = I,  B N = 0        (P = Bᵀ(BBᵀ)⁻¹, N an orthonormal basis of ker B)
//! ```
//!
//! so that y = (q, w, x_o) with x = T y and q = B x are the relative displacements themselves.
//! In these coordinates the contact forces act on the q rows only, Tᵀ J T = Ã(ω) + [N_c 0; 0 0],
//! with Ã = Tᵀ A T the linear harmonic-balance operator (block-diagonal over harmonics, real
//! 2-block form per harmonic h ≥ 1) and N_c the contact Jacobian, one (k·blocks)² block per
//! contact point (k = 2, or 3 for a 2D point). Per harmonic the z = (w, x_o) coordinates are eliminated exactly,
//!
//! ```text
//! S_h = Ã_qq − Ã_qz Ã_zz⁻¹ Ã_zq       (dynamic Schur complement on the relative coordinates)
//! ```
//!
//! and Newton's linear system becomes (blockdiag_h S_h + N_c) y_q = r_q on n_q · blocks
//! unknowns (n_q = 2 per contact point, 3 per 2D point; 1 fewer for a contact whose normal row is zero, a
//! Jenkins element to ground with a constant normal load, whose v moves with no DOF and whose
//! normal rows of N_c therefore act on nothing): with node-to-node pairs that is half the contact DOFs (4 per pair in 2D),
//! an eighth of the dense LU work of the condensed formulation. Ã_zz is the structure with
//! every contact glued (q = 0), which is regular even when a body (the damper) is held only by
//! its contacts; the 0th harmonic therefore needs no regularisation.
//!
//! Unlike [`crate::hbm::condensed`], the residual stays the full one (cheap: a dense product per
//! block), so a frequency change costs nothing until the next factorisation, and chord steps
//! of the corrector re-use the eliminated blocks. The complex dynamic stiffness is
//! complex-symmetric, not Hermitian: each Ã_zz is factored by dense LU with partial pivoting
//! in the real 2n form, as is the reduced Newton matrix (friction makes it unsymmetric).
//! faer offers dense LU but no block elimination over a coordinate change, hence this module.

use std::sync::Arc;

use faer::prelude::Solve;
use faer::{c64, Mat};

use crate::contact::harmonic::{Block, HarmonicSet};
use crate::hbm::formulation::{check_relative_coordinates, RelativeCoordinatesError};
use crate::model::{DofSplit, Problem};
use crate::numerics::jacobian::{ImplicitFactor, ImplicitJacobian};
use crate::numerics::linalg::{
    checked_lu, packed_complex_lu, packed_lu, LinearSolveError, PackedLu,
};

/// One contact's rows over the DOFs, in force order: tangential (, second tangential of a 2D
/// point), normal.
type ContactRows = Vec<Vec<(usize, f64)>>;

/// Unknown blocks of one harmonic: (cos or constant, sin).
#[derive(Debug, Clone, Copy)]
struct HarmonicBlocks {
    harmonic: usize,
    first: usize,
    second: Option<usize>,
}

/// The change to relative contact coordinates of one problem and its structural matrices in
/// those coordinates, built once per scene and shared by every Jacobian.
#[derive(Debug)]
pub struct RelativeCoordinates {
    n: usize,
    n_q: usize,
    other_dofs: Vec<usize>,
    /// T on the contact DOFs, block-diagonal over groups of contacts that share DOFs.
    components: Vec<ContactComponent>,
    /// K, M, C in y = (q, w, x_o) coordinates (TᵀKT, …).
    k_y: Mat<f64>,
    m_y: Mat<f64>,
    c_y: Mat<f64>,
    /// K, M, C in the problem's coordinates (residual products, entries for checks).
    k: Mat<f64>,
    m: Mat<f64>,
    c: Mat<f64>,
    /// Per contact, its rows (2 for a 1D point, 3 for a 2D point).
    rows: Vec<ContactRows>,
    /// Per contact, the relative coordinate of each of its rows (None for a zero row, which
    /// carries no coordinate).
    coordinate: Vec<Vec<Option<usize>>>,
    /// Per contact, the offset of its (k·blocks)² block of Jacobian values (k = its rows), and
    /// the total at the end.
    value_offsets: Vec<usize>,
    /// Per DOF, the contacts whose rows touch it.
    dof_contacts: Vec<Vec<usize>>,
    /// Per unknown block: its harmonic and damping partner (block, sign).
    blocks: Vec<(usize, Option<(usize, f64)>)>,
    /// Unknown blocks grouped by harmonic.
    harmonics: Vec<HarmonicBlocks>,
    /// The per-harmonic elimination of the last factorisation, with its ω.
    last_elimination: EliminationCache,
}

/// The per-harmonic elimination (LU of Ã_zz, W = Ã_zz⁻¹ Ã_zq and S_h) depends on ω alone, not
/// on the contact blocks: a factorisation at the ω of the previous one (every Newton iteration
/// of a fixed-frequency solve: limit-curve grids, refined peaks, the envelope) reuses it: on
/// the 3D blade pair a factorisation then takes 6.3 ms of CPU instead of 15 ms (benches/README.md,
/// "Where a 3D Newton iteration spends its time"). A continuation step changes ω at every
/// iteration and gains nothing. Holds the last ω's elimination (ω as bits: the same ω
/// exactly) and is shared by every factorisation of the coordinates, whatever thread makes it.
#[derive(Default)]
struct EliminationCache(std::sync::Mutex<Option<(u64, Arc<Vec<EliminatedHarmonic>>)>>);

impl std::fmt::Debug for EliminationCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("EliminationCache")
    }
}

/// The coordinate change on one group of contact points that share DOFs (contacts of
/// different groups touch disjoint DOFs, so T is block-diagonal over the groups: a node-to-node
/// pair is a group of its own, with a 4 × 4 block in 2D).
#[derive(Debug)]
struct ContactComponent {
    /// The group's DOFs (problem indices, sorted).
    dofs: Vec<usize>,
    /// For each column of `block`, its y coordinate: the group's relative coordinates
    /// (those of its contacts' non-zero rows) first, then its share of the null-space
    /// coordinates w.
    y_rows: Vec<usize>,
    /// [P N] on the group's DOFs: P = Bᵀ(BBᵀ)⁻¹, N an orthonormal basis of ker B.
    block: Mat<f64>,
}

/// Groups the contacts by shared DOFs (union-find) and builds each group's block; `coordinate`
/// gives each contact row's relative coordinate (None for a zero row), numbered 0..n_q.
fn contact_components(
    problem: &Problem,
    rows: &[ContactRows],
    coordinate: &[Vec<Option<usize>>],
    split: &DofSplit,
) -> Result<Vec<ContactComponent>, RelativeCoordinatesError> {
    let n_contacts = rows.len();
    let n_q = coordinate.iter().flatten().flatten().count();
    let mut parent: Vec<usize> = (0..n_contacts).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    // The contact that first touched each contact DOF.
    let mut owner: Vec<Option<usize>> = vec![None; split.contact.len()];
    for (p, contact_rows) in rows.iter().enumerate() {
        for &(d, _) in contact_rows.iter().flatten() {
            let Some(l) = split.local[d] else {
                continue; // every DOF of a contact row is a contact DOF
            };
            match owner[l] {
                None => owner[l] = Some(p),
                Some(first) => {
                    let (a, b) = (find(&mut parent, first), find(&mut parent, p));
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of = vec![usize::MAX; n_contacts];
    for p in 0..n_contacts {
        let root = find(&mut parent, p);
        if group_of[root] == usize::MAX {
            group_of[root] = groups.len();
            groups.push(Vec::new());
        }
        groups[group_of[root]].push(p);
    }
    let mut w_next = n_q;
    let mut components = Vec::with_capacity(groups.len());
    for contacts in groups {
        let mut dofs: Vec<usize> = contacts
            .iter()
            .flat_map(|&p| rows[p].iter().flatten().map(|&(d, _)| d))
            .collect();
        dofs.sort_unstable();
        dofs.dedup();
        // The group's non-zero rows: (contact, row index, coordinate).
        let active: Vec<(usize, usize, usize)> = contacts
            .iter()
            .flat_map(|&p| {
                (0..rows[p].len()).filter_map(move |a| coordinate[p][a].map(|q| (p, a, q)))
            })
            .collect();
        let (m, d) = (active.len(), dofs.len());
        if m > d {
            return Err(RelativeCoordinatesError::Dependent {
                contact: problem.contacts[contacts[0]].name.clone(),
                ratio: 0.0,
            });
        }
        let mut b = Mat::<f64>::zeros(m, d);
        for (row, &(p, a, _)) in active.iter().enumerate() {
            for &(dof, v) in rows[p][a].iter() {
                let col = dofs.binary_search(&dof).expect("listed above");
                b[(row, col)] += v;
            }
        }
        let gram = &b * b.transpose();
        let gram_lu = checked_lu(&gram).map_err(|_| RelativeCoordinatesError::Dependent {
            contact: problem.contacts[contacts[0]].name.clone(),
            ratio: 0.0,
        })?;
        let p = gram_lu.solve(&b).transpose().to_owned();
        let q_full = b.transpose().to_owned().qr().compute_Q();
        let block = Mat::from_fn(d, d, |i, j| if j < m { p[(i, j)] } else { q_full[(i, j)] });
        let mut y_rows: Vec<usize> = active.iter().map(|&(_, _, q)| q).collect();
        y_rows.extend(w_next..w_next + (d - m));
        w_next += d - m;
        components.push(ContactComponent {
            dofs,
            y_rows,
            block,
        });
    }
    Ok(components)
}

impl RelativeCoordinates {
    /// The coordinates of `problem` for unknown harmonics `set`.
    pub fn new(problem: &Problem, set: &HarmonicSet) -> Result<Self, RelativeCoordinatesError> {
        check_relative_coordinates(problem)?;
        let n = problem.model.n_dofs();
        let split = problem.dof_split();
        let rows: Vec<ContactRows> = problem
            .contacts
            .iter()
            .map(|c| c.rows().map(|r| r.to_vec()).collect())
            .collect();
        let mut n_q = 0;
        let coordinate: Vec<Vec<Option<usize>>> = problem
            .nonzero_contact_rows()
            .iter()
            .map(|on| {
                on.iter()
                    .map(|&on| {
                        on.then(|| {
                            n_q += 1;
                            n_q - 1
                        })
                    })
                    .collect()
            })
            .collect();
        let nb = set.n_blocks();
        let mut value_offsets = vec![0];
        for r in &rows {
            let k = r.len() * nb;
            value_offsets.push(value_offsets.last().expect("starts at 0") + k * k);
        }
        let components = contact_components(problem, &rows, &coordinate, &split)?;
        let dense = |m: &crate::model::matrix::StructuralMatrix| m.to_dense();
        let (k, m, c) = (
            dense(&problem.model.stiffness),
            dense(&problem.model.mass),
            dense(&problem.model.damping),
        );
        let mut dof_contacts: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (p, contact_rows) in rows.iter().enumerate() {
            for &(d, _) in contact_rows.iter().flatten() {
                if dof_contacts[d].last() != Some(&p) {
                    dof_contacts[d].push(p);
                }
            }
        }
        let blocks = set
            .blocks()
            .iter()
            .map(|b| {
                let partner = match b {
                    Block::Cos(h) => set.sin_block(*h).map(|j| (j, 1.0)),
                    Block::Sin(h) => set.cos_block(*h).map(|j| (j, -1.0)),
                    Block::Constant => None,
                };
                (b.harmonic(), partner)
            })
            .collect();
        let harmonics = set
            .harmonics()
            .iter()
            .map(|&h| {
                if h == 0 {
                    HarmonicBlocks {
                        harmonic: 0,
                        first: set.constant_block().expect("h = 0 is in the set"),
                        second: None,
                    }
                } else {
                    let (first, second) = match (set.cos_block(h), set.sin_block(h)) {
                        (Some(c), s) => (c, s),
                        (None, Some(s)) => (s, None),
                        (None, None) => unreachable!("harmonic {h} of the set has a block"),
                    };
                    HarmonicBlocks {
                        harmonic: h,
                        first,
                        second,
                    }
                }
            })
            .collect();
        let mut coords = Self {
            n,
            n_q,
            other_dofs: split.linear,
            components,
            k_y: Mat::zeros(0, 0),
            m_y: Mat::zeros(0, 0),
            c_y: Mat::zeros(0, 0),
            k,
            m,
            c,
            rows,
            coordinate,
            value_offsets,
            dof_contacts,
            blocks,
            harmonics,
            last_elimination: EliminationCache::default(),
        };
        coords.k_y = coords.congruence(&coords.k);
        coords.m_y = coords.congruence(&coords.m);
        coords.c_y = coords.congruence(&coords.c);
        Ok(coords)
    }

    /// Number of DOFs n of the problem.
    pub fn n_dofs(&self) -> usize {
        self.n
    }

    /// Offsets of each contact's block of Jacobian values (see [`Self::factor`]), one per
    /// contact plus the total at the end.
    pub fn value_offsets(&self) -> &[usize] {
        &self.value_offsets
    }

    /// Number of rows (relative coordinates, zero rows included) of contact `p`: 2 for a 1D
    /// point, 3 for a 2D point.
    pub fn contact_rows(&self, p: usize) -> usize {
        self.rows[p].len()
    }

    /// Number of relative coordinates n_q (2 per 1D point, 3 per 2D point, fewer where a row
    /// is zero).
    pub fn n_relative(&self) -> usize {
        self.n_q
    }

    /// Number of contact points.
    pub fn n_contacts(&self) -> usize {
        self.rows.len()
    }

    /// Number of unknown blocks.
    pub fn n_blocks(&self) -> usize {
        self.blocks.len()
    }

    /// Tᵀ X for X with n rows (columns transformed independently).
    fn to_relative_coordinates(&self, x: &Mat<f64>) -> Mat<f64> {
        self.change_coordinates(x, true)
    }

    /// T Y for Y with n rows.
    fn to_problem_coordinates(&self, y: &Mat<f64>) -> Mat<f64> {
        self.change_coordinates(y, false)
    }

    /// Tᵀ X (`to_relative`) or T X: each component's block maps its DOFs to its y rows (or
    /// back), the other DOFs are copied to the last rows (or back).
    fn change_coordinates(&self, x: &Mat<f64>, to_relative: bool) -> Mat<f64> {
        let k = x.ncols();
        let n_c = self.n - self.other_dofs.len();
        let mut out = Mat::zeros(self.n, k);
        for c in &self.components {
            for (il, &d) in c.dofs.iter().enumerate() {
                for (jl, &row) in c.y_rows.iter().enumerate() {
                    let (from, to) = if to_relative { (d, row) } else { (row, d) };
                    let w = c.block[(il, jl)];
                    for col in 0..k {
                        out[(to, col)] += w * x[(from, col)];
                    }
                }
            }
        }
        for (i, &d) in self.other_dofs.iter().enumerate() {
            let (from, to) = if to_relative {
                (d, n_c + i)
            } else {
                (n_c + i, d)
            };
            for col in 0..k {
                out[(to, col)] = x[(from, col)];
            }
        }
        out
    }

    /// Tᵀ A T.
    fn congruence(&self, a: &Mat<f64>) -> Mat<f64> {
        let left = self.to_relative_coordinates(a);
        self.to_relative_coordinates(&left.transpose().to_owned())
            .transpose()
            .to_owned()
    }

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

    /// Eliminates the z coordinates of one harmonic at ω.
    fn eliminate(
        &self,
        hb: &HarmonicBlocks,
        omega: f64,
    ) -> Result<EliminatedHarmonic, LinearSolveError> {
        let (n, n_q) = (self.n, self.n_q);
        let blocks: Vec<usize> = std::iter::once(hb.first).chain(hb.second).collect();
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

    /// Every harmonic's elimination at ω: the last factorisation's when it was at this ω
    /// exactly ([`EliminationCache`]), else computed (without holding the cache meanwhile) and
    /// kept.
    fn eliminated_at(&self, omega: f64) -> Result<Arc<Vec<EliminatedHarmonic>>, LinearSolveError> {
        let cache = || {
            self.last_elimination
                .0
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        };
        if let Some((bits, eliminated)) = cache().as_ref() {
            if *bits == omega.to_bits() {
                return Ok(Arc::clone(eliminated));
            }
        }
        let eliminated = Arc::new(
            self.harmonics
                .iter()
                .map(|hb| self.eliminate(hb, omega))
                .collect::<Result<Vec<_>, _>>()?,
        );
        *cache() = Some((omega.to_bits(), Arc::clone(&eliminated)));
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
    ) -> Result<SchurFactor, LinearSolveError> {
        if !omega.is_finite() || contact_values.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolveError::NonFinite);
        }
        let (n_q, nb) = (self.n_q, self.blocks.len());
        let dim_q = n_q * nb;
        let mut s = Mat::<f64>::zeros(dim_q, dim_q);
        let eliminated = self.eliminated_at(omega)?;
        for eh in eliminated.iter() {
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
        let lu_q = packed_lu(s)?;
        let lu_q_single = lu_q.to_single();
        Ok(SchurFactor {
            coords: Arc::clone(self),
            harmonics: eliminated,
            lu_q,
            lu_q_single,
        })
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

/// One harmonic's elimination of the z coordinates: W = Ã_zz⁻¹ Ã_zq, Ã_qz and the Schur
/// complement S_h, real for a single block, complex (on x_cos − i x_sin) for a cosine/sine
/// pair, where it costs half the real 2n form.
enum Elimination {
    /// One block (h = 0).
    Real {
        lu_zz: Option<PackedLu<f64>>,
        w: Mat<f64>,
        a_qz: Mat<f64>,
        schur: Mat<f64>,
    },
    /// Cosine and sine blocks.
    Complex {
        lu_zz: Option<PackedLu<c64>>,
        w: Mat<c64>,
        a_qz: Mat<c64>,
        schur: Mat<c64>,
    },
}

/// The elimination of one harmonic and its unknown blocks (one, or cosine and sine).
struct EliminatedHarmonic {
    blocks: Vec<usize>,
    elimination: Elimination,
}

impl EliminatedHarmonic {
    /// Writes S_h into the reduced Newton matrix `s` (real form: S = Sr + i Si acts on the
    /// cosine/sine blocks as [[Sr, Si], [−Si, Sr]]).
    fn add_schur_complement(&self, s: &mut Mat<f64>, n_q: usize) {
        match &self.elimination {
            Elimination::Real { schur, .. } => {
                let jb = self.blocks[0] * n_q;
                for k in 0..n_q {
                    for i in 0..n_q {
                        s[(jb + i, jb + k)] += schur[(i, k)];
                    }
                }
            }
            Elimination::Complex { schur, .. } => {
                let (jc, js) = (self.blocks[0] * n_q, self.blocks[1] * n_q);
                for k in 0..n_q {
                    for i in 0..n_q {
                        let v = schur[(i, k)];
                        s[(jc + i, jc + k)] += v.re;
                        s[(jc + i, js + k)] += v.im;
                        s[(js + i, jc + k)] -= v.im;
                        s[(js + i, js + k)] += v.re;
                    }
                }
            }
        }
    }
}

/// The z part of a right-hand side, kept between the two passes of a solve.
enum ZPart {
    Real(Option<Mat<f64>>),
    Complex(Option<Mat<c64>>),
}

/// The schur formulation's Jacobian storage for [`AssembledJacobian::implicit`]: the values
/// are one (k·blocks)² block per contact point (k = 2 rows, 3 for a 2D point) (see [`RelativeCoordinates::factor`]); the
/// linear part is formed from the structural matrices at ω.
///
/// [`AssembledJacobian::implicit`]: crate::numerics::jacobian::AssembledJacobian::implicit
#[derive(Debug)]
pub struct SchurJacobian(pub Arc<RelativeCoordinates>);

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
        Ok(Box::new(self.0.factor(omega, values)?))
    }
}

/// A factorised Jacobian of the schur formulation (see the module docs).
pub struct SchurFactor {
    coords: Arc<RelativeCoordinates>,
    harmonics: Arc<Vec<EliminatedHarmonic>>,
    /// LU of blockdiag_h S_h + N_c.
    lu_q: PackedLu<f64>,
    /// The same LU rounded to single precision, for approximate solves.
    lu_q_single: PackedLu<f32>,
}

impl ImplicitFactor for SchurFactor {
    /// Solves J x = b (problem coordinates, harmonic-major, length n·blocks). With `single`,
    /// the reduced system is solved with the factors rounded to single precision: twice as
    /// fast on large factors, with a relative error of about 10⁻⁷ times the condition number
    /// (for the chord steps of a corrector, whose convergence is judged on the true residual).
    fn solve(&self, b: &[f64], single: bool) -> Vec<f64> {
        let co = &self.coords;
        let (n, n_q, nb) = (co.n, co.n_q, co.blocks.len());
        let bm = Mat::from_fn(n, nb, |i, j| b[j * n + i]);
        let by = co.to_relative_coordinates(&bm);
        let mut r_q = Mat::<f64>::zeros(n_q * nb, 1);
        let mut kept: Vec<ZPart> = Vec::with_capacity(self.harmonics.len());
        for eh in self.harmonics.iter() {
            match &eh.elimination {
                Elimination::Real { lu_zz, a_qz, .. } => {
                    let j = eh.blocks[0];
                    let mut rq = Mat::from_fn(n_q, 1, |i, _| by[(i, j)]);
                    let g = lu_zz.as_ref().map(|lu| {
                        let g = lu.solve(&Mat::from_fn(n - n_q, 1, |i, _| by[(n_q + i, j)]));
                        rq -= a_qz * &g;
                        g
                    });
                    for i in 0..n_q {
                        r_q[(j * n_q + i, 0)] = rq[(i, 0)];
                    }
                    kept.push(ZPart::Real(g));
                }
                Elimination::Complex { lu_zz, a_qz, .. } => {
                    let (jc, js) = (eh.blocks[0], eh.blocks[1]);
                    let packed = |i: usize| c64::new(by[(i, jc)], -by[(i, js)]);
                    let mut rq = Mat::from_fn(n_q, 1, |i, _| packed(i));
                    let g = lu_zz.as_ref().map(|lu| {
                        let g = lu.solve(&Mat::from_fn(n - n_q, 1, |i, _| packed(n_q + i)));
                        rq -= a_qz * &g;
                        g
                    });
                    for i in 0..n_q {
                        r_q[(jc * n_q + i, 0)] = rq[(i, 0)].re;
                        r_q[(js * n_q + i, 0)] = -rq[(i, 0)].im;
                    }
                    kept.push(ZPart::Complex(g));
                }
            }
        }
        let y_q = if single {
            let mut y = Mat::from_fn(r_q.nrows(), 1, |i, _| r_q[(i, 0)] as f32);
            self.lu_q_single.solve_in_place(&mut y);
            Mat::from_fn(y.nrows(), 1, |i, _| y[(i, 0)] as f64)
        } else {
            let mut y_q = r_q;
            self.lu_q.solve_in_place(&mut y_q);
            y_q
        };
        let mut y = Mat::<f64>::zeros(n, nb);
        for (eh, g) in self.harmonics.iter().zip(kept) {
            match (&eh.elimination, g) {
                (Elimination::Real { w, .. }, ZPart::Real(g)) => {
                    let j = eh.blocks[0];
                    let yq = Mat::from_fn(n_q, 1, |i, _| y_q[(j * n_q + i, 0)]);
                    for i in 0..n_q {
                        y[(i, j)] = yq[(i, 0)];
                    }
                    if let Some(g) = g {
                        let yz = g - w * &yq;
                        for i in 0..n - n_q {
                            y[(n_q + i, j)] = yz[(i, 0)];
                        }
                    }
                }
                (Elimination::Complex { w, .. }, ZPart::Complex(g)) => {
                    let (jc, js) = (eh.blocks[0], eh.blocks[1]);
                    let yq = Mat::from_fn(n_q, 1, |i, _| {
                        c64::new(y_q[(jc * n_q + i, 0)], -y_q[(js * n_q + i, 0)])
                    });
                    for i in 0..n_q {
                        y[(i, jc)] = yq[(i, 0)].re;
                        y[(i, js)] = -yq[(i, 0)].im;
                    }
                    if let Some(g) = g {
                        let yz = g - w * &yq;
                        for i in 0..n - n_q {
                            y[(n_q + i, jc)] = yz[(i, 0)].re;
                            y[(n_q + i, js)] = -yz[(i, 0)].im;
                        }
                    }
                }
                _ => unreachable!("z parts are kept in the order of the eliminations"),
            }
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
}
