//! The relative contact coordinates: the contact rows B of every contact point, the basis
//! (P, N) that makes q = B x unknowns, and the change of coordinates both ways.

use faer::prelude::Solve;
use faer::Mat;

use super::elimination::EliminationCache;
use super::modal::ModalBasis;
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::hbm::formulation::{check_relative_coordinates, RelativeCoordinatesError};
use crate::model::{DofSplit, Problem};
use crate::numerics::linalg::checked_lu;

/// One contact's rows over the DOFs, in force order: tangential (, second tangential of a 2D
/// point), normal.
type ContactRows = Vec<Vec<(usize, f64)>>;

/// Unknown blocks of one harmonic: (cos or constant, sin).
#[derive(Debug, Clone, Copy)]
pub(super) struct HarmonicBlocks {
    pub(super) harmonic: usize,
    pub(super) first: usize,
    pub(super) second: Option<usize>,
}

/// The change to relative contact coordinates of one problem and its structural matrices in
/// those coordinates, built once per scene and shared by every Jacobian.
#[derive(Debug)]
pub struct RelativeCoordinates {
    pub(super) n: usize,
    pub(super) n_q: usize,
    other_dofs: Vec<usize>,
    /// T on the contact DOFs, block-diagonal over groups of contacts that share DOFs.
    components: Vec<ContactComponent>,
    /// K, M, C in y = (q, w, x_o) coordinates (TᵀKT, …).
    pub(super) k_y: Mat<f64>,
    pub(super) m_y: Mat<f64>,
    pub(super) c_y: Mat<f64>,
    /// K, M, C in the problem's coordinates (residual products, entries for checks).
    pub(super) k: Mat<f64>,
    pub(super) m: Mat<f64>,
    pub(super) c: Mat<f64>,
    /// Per contact, its rows (2 for a 1D point, 3 for a 2D point).
    pub(super) rows: Vec<ContactRows>,
    /// Per contact, the relative coordinate of each of its rows (None for a zero row, which
    /// carries no coordinate).
    pub(super) coordinate: Vec<Vec<Option<usize>>>,
    /// Per contact, the offset of its (k·blocks)² block of Jacobian values (k = its rows), and
    /// the total at the end.
    pub(super) value_offsets: Vec<usize>,
    /// Per DOF, the contacts whose rows touch it.
    pub(super) dof_contacts: Vec<Vec<usize>>,
    /// Per unknown block: its harmonic and damping partner (block, sign).
    pub(super) blocks: Vec<(usize, Option<(usize, f64)>)>,
    /// Unknown blocks grouped by harmonic.
    pub(super) harmonics: Vec<HarmonicBlocks>,
    /// The per-harmonic elimination of the last factorisation, with its ω.
    pub(super) last_elimination: EliminationCache,
    /// The glued structure's modes for the modal elimination ([`super::modal`]), computed at
    /// the first factorisation that asks for them; None where the scene does not allow it.
    pub(super) modal: std::sync::OnceLock<Option<ModalBasis>>,
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
    pub(super) block: Mat<f64>,
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
            modal: std::sync::OnceLock::new(),
        };
        coords.k_y = coords.congruence(&coords.k);
        coords.m_y = coords.congruence(&coords.m);
        coords.c_y = coords.congruence(&coords.c);
        Ok(coords)
    }

    /// The glued structure's modes (computed once, at the first call): None when K, M, C in
    /// relative coordinates are not symmetric, M_zz is not positive definite, or the damping is
    /// not of low rank ([`ModalBasis::new`]).
    pub(super) fn modal_basis(&self) -> Option<&ModalBasis> {
        self.modal
            .get_or_init(|| ModalBasis::new(&self.k_y, &self.m_y, &self.c_y, self.n_q))
            .as_ref()
    }

    /// Whether the per-harmonic elimination can use the glued structure's modes (builds them at
    /// the first call): the `schur-lowrank` formulation's elimination where this holds, else the
    /// LU elimination of every harmonic.
    pub fn has_modal_elimination(&self) -> bool {
        self.modal_basis().is_some()
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
    pub(super) fn to_relative_coordinates(&self, x: &Mat<f64>) -> Mat<f64> {
        self.change_coordinates(x, true)
    }

    /// T Y for Y with n rows.
    pub(super) fn to_problem_coordinates(&self, y: &Mat<f64>) -> Mat<f64> {
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
}
