//! The pattern of the harmonic-balance Jacobian and the slot tables that fill it.
//!
//! The Jacobian ∂R/∂x has, per coefficient block j (harmonic-major unknowns, see
//! [`crate::contact::harmonic`]): the block-diagonal linear part K − (hω)²M on (j, j), the damping
//! coupling ±hωC on (j, partner(j)), and, per contact, a dense coupling of all its DOFs across
//! all blocks (the AFT mixes harmonics). That pattern is fixed for a scene, so the slot of
//! every entry is computed once here and Newton iterations only add values at known slots —
//! the same code fills dense and sparse storage.

use crate::contact::harmonic::{Block, HarmonicSet};
use crate::model::Problem;
use crate::numerics::jacobian::{AssembledJacobian, Storage};

/// Slots of one contact's coupling: for each pair of unknown blocks (j, i), a dense d × d
/// table over the contact's DOFs.
#[derive(Debug, Clone)]
pub struct ContactSlots {
    /// Number of distinct DOFs the contact touches.
    pub dofs: usize,
    /// Tangential row as (local DOF index, coefficient).
    pub tangential: Vec<(usize, f64)>,
    /// Second tangential row of a 2D-friction point (empty for a 1D point).
    pub tangential2: Vec<(usize, f64)>,
    /// Normal row as (local DOF index, coefficient).
    pub normal: Vec<(usize, f64)>,
    /// Slots, indexed ((j · n_blocks + i) · d + a) · d + b.
    pub slots: Vec<usize>,
}

/// A contact's DOFs (sorted, unique) and its rows on them.
struct LocalRows {
    dofs: Vec<usize>,
    tangential: Vec<(usize, f64)>,
    tangential2: Vec<(usize, f64)>,
    normal: Vec<(usize, f64)>,
}

impl LocalRows {
    fn of(c: &crate::contact::ContactPoint) -> Self {
        let mut dofs: Vec<usize> = c.row_entries().map(|&(d, _)| d).collect();
        dofs.sort_unstable();
        dofs.dedup();
        let to_local = |row: &[(usize, f64)]| -> Vec<(usize, f64)> {
            row.iter()
                .map(|&(d, a)| (dofs.binary_search(&d).expect("listed above"), a))
                .collect()
        };
        let tangential = to_local(&c.tangential);
        let tangential2 = c
            .second_tangent
            .as_ref()
            .map_or_else(Vec::new, |s| to_local(&s.row));
        let normal = to_local(&c.normal);
        Self {
            dofs,
            tangential,
            tangential2,
            normal,
        }
    }
}

/// Slot tables of the harmonic-balance Jacobian of one problem.
#[derive(Debug, Clone)]
pub struct JacobianLayout {
    /// Storage used.
    pub storage: Storage,
    /// Unknowns n_dofs × n_blocks.
    pub dim: usize,
    /// Per block: (slot, k_pq, m_pq) of the union pattern of K and M.
    pub stiffness: Vec<Vec<(usize, f64, f64)>>,
    /// Per block: (slot, c_pq) of C on the partner block's columns.
    pub damping: Vec<Vec<(usize, f64)>>,
    /// Per contact.
    pub contacts: Vec<ContactSlots>,
    /// The empty Jacobian with the pattern, cloned for each new Jacobian.
    template: AssembledJacobian,
}

impl JacobianLayout {
    /// Builds the pattern and slots for `problem` with unknowns `set`, in `storage`.
    ///
    /// `Storage::Schur` needs the relative coordinates ([`Self::relative`]); asked here it
    /// gives the dense layout.
    pub fn new(problem: &Problem, set: &HarmonicSet, storage: Storage) -> Self {
        let storage = match storage {
            Storage::Schur => Storage::Dense,
            s => s,
        };
        let model = &problem.model;
        let n = model.n_dofs();
        let nb = set.n_blocks();
        let dim = n * nb;
        // K ∪ M entries (p, q, k, m), and C entries.
        let mut km: Vec<(usize, usize, f64, f64)> = Vec::new();
        model
            .stiffness
            .for_each_nonzero(|p, q, k| km.push((p, q, k, 0.0)));
        model
            .mass
            .for_each_nonzero(|p, q, m| km.push((p, q, 0.0, m)));
        km.sort_by_key(|e| (e.1, e.0));
        let mut merged: Vec<(usize, usize, f64, f64)> = Vec::with_capacity(km.len());
        for e in km {
            match merged.last_mut() {
                Some(last) if last.0 == e.0 && last.1 == e.1 => {
                    last.2 += e.2;
                    last.3 += e.3;
                }
                _ => merged.push(e),
            }
        }
        let damping = model.damping.triplets();
        let partner = |b: Block| match b {
            Block::Cos(h) => set.sin_block(h),
            Block::Sin(h) => set.cos_block(h),
            Block::Constant => None,
        };
        let local: Vec<LocalRows> = problem.contacts.iter().map(LocalRows::of).collect();

        let template = match storage {
            Storage::Dense | Storage::Schur => AssembledJacobian::dense(dim),
            Storage::Sparse => {
                let mut entries: Vec<(usize, usize)> = Vec::new();
                for (j, b) in set.blocks().iter().enumerate() {
                    entries.extend(merged.iter().map(|e| (j * n + e.0, j * n + e.1)));
                    if let Some(pj) = partner(*b) {
                        entries.extend(damping.iter().map(|e| (j * n + e.0, pj * n + e.1)));
                    }
                }
                for LocalRows { dofs, .. } in &local {
                    for j in 0..nb {
                        for i in 0..nb {
                            for &p in dofs {
                                for &q in dofs {
                                    entries.push((j * n + p, i * n + q));
                                }
                            }
                        }
                    }
                }
                AssembledJacobian::sparse(dim, entries)
            }
        };
        let stiffness = (0..nb)
            .map(|j| {
                merged
                    .iter()
                    .map(|e| (template.slot(j * n + e.0, j * n + e.1), e.2, e.3))
                    .collect()
            })
            .collect();
        let damping = set
            .blocks()
            .iter()
            .enumerate()
            .map(|(j, b)| match partner(*b) {
                Some(pj) => damping
                    .iter()
                    .map(|e| (template.slot(j * n + e.0, pj * n + e.1), e.2))
                    .collect(),
                None => Vec::new(),
            })
            .collect();
        let contacts = local
            .into_iter()
            .map(
                |LocalRows {
                     dofs,
                     tangential,
                     tangential2,
                     normal,
                 }| {
                    let d = dofs.len();
                    let mut slots = Vec::with_capacity(nb * nb * d * d);
                    for j in 0..nb {
                        for i in 0..nb {
                            for &p in &dofs {
                                for &q in &dofs {
                                    slots.push(template.slot(j * n + p, i * n + q));
                                }
                            }
                        }
                    }
                    ContactSlots {
                        dofs: d,
                        tangential,
                        tangential2,
                        normal,
                        slots,
                    }
                },
            )
            .collect();
        Self {
            storage,
            dim,
            stiffness,
            damping,
            contacts,
            template,
        }
    }

    /// A dense layout over a subset of the DOFs holding only the contact couplings: DOF p of
    /// the problem is row/column `local[p]` of each block of size `n_local` (None for DOFs
    /// outside the subset, which no contact may touch). Used by the condensed
    /// formulation, whose unknowns are the contact DOFs.
    ///
    /// # Panics
    /// If a contact touches a DOF outside the subset (a programming error).
    pub fn contacts_only(
        problem: &Problem,
        set: &HarmonicSet,
        local: &[Option<usize>],
        n_local: usize,
    ) -> Self {
        let nb = set.n_blocks();
        let dim = n_local * nb;
        let template = AssembledJacobian::dense(dim);
        let contacts = problem
            .contacts
            .iter()
            .map(|c| {
                let LocalRows {
                    dofs,
                    tangential,
                    tangential2,
                    normal,
                } = LocalRows::of(c);
                let d = dofs.len();
                let mut slots = Vec::with_capacity(nb * nb * d * d);
                for j in 0..nb {
                    for i in 0..nb {
                        for &p in &dofs {
                            for &q in &dofs {
                                let (Some(lp), Some(lq)) = (local[p], local[q]) else {
                                    panic!("contact DOF {p} or {q} outside the subset");
                                };
                                slots.push(template.slot(j * n_local + lp, i * n_local + lq));
                            }
                        }
                    }
                }
                ContactSlots {
                    dofs: d,
                    tangential,
                    tangential2,
                    normal,
                    slots,
                }
            })
            .collect();
        Self {
            storage: Storage::Dense,
            dim,
            stiffness: vec![Vec::new(); nb],
            damping: vec![Vec::new(); nb],
            contacts,
            template,
        }
    }

    /// The layout of the schur formulation ([`crate::hbm::schur`]): no linear slots (the linear
    /// part is formed from ω when the Jacobian is factorised) and, per contact, its block on
    /// the contact's own k relative coordinates (u, v; or u₁, u₂, v for a 2D point), slot
    /// offset + ((j·blocks + i)·k + a)·k + b. Its reduced matrix is factorised by a dense LU, or
    /// by structure when the problem's formulation is `schur-lowrank`.
    pub fn relative(
        problem: &Problem,
        set: &HarmonicSet,
        coords: std::sync::Arc<crate::hbm::schur::RelativeCoordinates>,
    ) -> Self {
        let nb = set.n_blocks();
        let dim = problem.model.n_dofs() * nb;
        let offsets = coords.value_offsets().to_vec();
        let rows: Vec<usize> = (0..problem.contacts.len())
            .map(|p| coords.contact_rows(p))
            .collect();
        let solver = if problem.formulation() == crate::model::Formulation::SchurLowRank {
            crate::hbm::schur::ReducedSolver::Structured
        } else {
            crate::hbm::schur::ReducedSolver::Dense
        };
        let template = AssembledJacobian::implicit(std::sync::Arc::new(
            crate::hbm::schur::SchurJacobian(coords, solver),
        ));
        let contacts = (0..problem.contacts.len())
            .map(|p| {
                let k = rows[p];
                ContactSlots {
                    dofs: k,
                    tangential: vec![(0, 1.0)],
                    tangential2: if k == 3 { vec![(1, 1.0)] } else { Vec::new() },
                    normal: vec![(k - 1, 1.0)],
                    slots: (offsets[p]..offsets[p + 1]).collect(),
                }
            })
            .collect();
        Self {
            storage: Storage::Schur,
            dim,
            stiffness: vec![Vec::new(); nb],
            damping: vec![Vec::new(); nb],
            contacts,
            template,
        }
    }

    /// An empty Jacobian with this layout's pattern (the symbolic factorisation, computed on
    /// its first solve, is kept by that Jacobian).
    pub fn new_jacobian(&self) -> AssembledJacobian {
        self.template.clone()
    }
}
