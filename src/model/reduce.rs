//! Craig-Bampton reduction of a problem on a large (sparse) FE model to a small dense one.
//!
//! The boundary set is every DOF the friction problem needs as a physical coordinate: the
//! contact DOFs and the output DOFs. Everything else is condensed into constraint modes and the
//! lowest fixed-interface modes by the `fricbound-reduction` crate, so the reduced coordinates
//! are q = [u_B; η]: the boundary displacements (named as in the full model) then the modal
//! amplitudes (`mode1`, `mode2`, ...). Contacts and outputs keep their meaning on u_B exactly,
//! since Craig-Bampton keeps boundary DOFs as physical coordinates.
//!
//! Loads on other DOFs (a pre-load spread over the damper's body, an excitation at a blade tip)
//! do not enlarge the boundary: they are projected on the reduced basis, f_r = Tᵀf, with the
//! recovery rows of the loaded DOFs (row d of T). The projection does the same virtual work as
//! f on every displacement of the basis; in particular the rigid-body motions of a free damper
//! are in the basis, so the resultant of its pre-load, which the contacts must balance (paper
//! Eq. 11), is kept exactly.
//!
//! Damping: Rayleigh damping C = αM + βK of the full model reduces exactly to αM_r + βK_r
//! (the Craig-Bampton basis T is applied congruently, TᵀCT); modal damping ratios ζ act on the
//! fixed-interface modes, C_r[η_i, η_i] += 2ζω_i.

use fricbound_reduction::{craig_bampton, CbOptions, Ordering, ReducedModel, ReductionError};

use crate::model::matrix::StructuralMatrix;
use crate::model::{HarmonicLoad, LinearModel, Problem};

/// Most entries of the Craig-Bampton basis kept for results on the mesh (8 bytes each).
pub const MAX_BASIS_ENTRIES: usize = 20_000_000;

/// Settings of a reduction.
#[derive(Debug, Clone, PartialEq)]
pub struct ReductionSettings {
    /// Fixed-interface modes kept.
    pub modes: usize,
    /// Modal damping ratio ζ of the fixed-interface modes (–).
    pub modal_damping: f64,
    /// Rayleigh coefficients (α in 1/s, β in s) of the full model's damping.
    pub rayleigh: (f64, f64),
    /// Fill-reducing ordering of the interior Cholesky factorisation.
    pub ordering: Ordering,
    /// Full-model DOFs whose recovery rows are kept (response output on the mesh).
    pub recover: Vec<usize>,
}

/// A reduced problem and what is needed to go back to the full model.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// The reduced problem (dense).
    pub problem: Problem,
    /// The reduced model with its recovery rows and report.
    pub model: ReducedModel,
}

/// The boundary DOFs of a problem: contact and output DOFs, sorted.
pub fn boundary_dofs(problem: &Problem) -> Vec<usize> {
    let mut b = problem.contact_dofs();
    b.extend(problem.outputs.iter().copied());
    b.sort_unstable();
    b.dedup();
    b
}

/// The DOFs carrying a static or harmonic load, sorted.
fn loaded_dofs(problem: &Problem) -> Vec<usize> {
    let mut d: Vec<usize> = problem
        .static_load
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(d, _)| d)
        .collect();
    d.extend(problem.harmonic_loads.iter().map(|l| l.dof));
    d.sort_unstable();
    d.dedup();
    d
}

/// Reduces a problem whose structural matrices are sparse. The problem's damping matrix is
/// ignored: damping of the reduced model comes from `settings` (see the module docs).
pub fn reduce(
    problem: &Problem,
    settings: &ReductionSettings,
) -> Result<Reduction, ReductionError> {
    let to_sparse = |m: &StructuralMatrix| match m {
        StructuralMatrix::Sparse(s) => s.clone(),
        StructuralMatrix::Dense(_) => {
            match StructuralMatrix::sparse_from_triplets(m.n(), &m.triplets()) {
                StructuralMatrix::Sparse(s) => s,
                StructuralMatrix::Dense(_) => {
                    unreachable!("sparse_from_triplets builds sparse storage")
                }
            }
        }
    };
    let k = to_sparse(&problem.model.stiffness);
    let m = to_sparse(&problem.model.mass);
    let boundary = boundary_dofs(problem);
    let loaded = loaded_dofs(problem);
    let mut recover = loaded.clone();
    recover.extend_from_slice(&settings.recover);
    // Results on the mesh need the whole basis: kept while it stays small.
    let n = problem.model.n_dofs();
    let recover_all =
        problem.fe.is_some() && n * (boundary.len() + settings.modes) <= MAX_BASIS_ENTRIES;
    let first_all = recover.len();
    if recover_all {
        recover.extend(0..n);
    }
    let mut options = CbOptions::with_modes(settings.modes);
    options.ordering = settings.ordering;
    let mut reduced = craig_bampton(k.as_ref(), m.as_ref(), &boundary, &recover, &options)?;
    // Rows of T of the loaded DOFs (the first `loaded.len()` recovery rows).
    let load_rows: Vec<Vec<f64>> = reduced
        .recovery
        .drain(..loaded.len())
        .map(|r| r.row)
        .collect();
    let row_of = |d: usize| &load_rows[loaded.binary_search(&d).expect("listed as loaded")];
    let basis: Option<Vec<Vec<f64>>> = recover_all.then(|| {
        reduced
            .recovery
            .drain(first_all - loaded.len()..)
            .map(|r| r.row)
            .collect()
    });
    let nb = boundary.len();
    let nr = reduced.size();
    let mut position = vec![usize::MAX; problem.model.n_dofs()];
    for (i, &d) in boundary.iter().enumerate() {
        position[d] = i;
    }
    let remap = |row: &[(usize, f64)]| -> Vec<(usize, f64)> {
        row.iter().map(|&(d, a)| (position[d], a)).collect()
    };
    let mut names: Vec<String> = boundary
        .iter()
        .map(|&d| problem.model.dof_names[d].clone())
        .collect();
    names.extend((1..=reduced.n_modes).map(|i| format!("mode{i}")));
    let (alpha, beta) = settings.rayleigh;
    let mut damping = reduced.modal_damping(settings.modal_damping);
    for j in 0..nr {
        for i in 0..nr {
            damping[(i, j)] += alpha * reduced.mass[(i, j)] + beta * reduced.stiffness[(i, j)];
        }
    }
    let mut static_load = vec![0.0; nr];
    for (d, &f) in problem.static_load.iter().enumerate() {
        if f != 0.0 {
            for (i, t) in row_of(d).iter().enumerate() {
                static_load[i] += t * f;
            }
        }
    }
    let mut out = problem.clone();
    out.model = LinearModel {
        dof_names: names,
        mass: StructuralMatrix::Dense(reduced.mass.clone()),
        damping: StructuralMatrix::Dense(damping),
        stiffness: StructuralMatrix::Dense(reduced.stiffness.clone()),
    };
    for c in &mut out.contacts {
        c.tangential = remap(&c.tangential);
        c.normal = remap(&c.normal);
    }
    out.static_load = static_load;
    // f_r = Tᵀ f per harmonic load, merged per (coordinate, harmonic).
    let mut harmonic: std::collections::BTreeMap<(usize, usize), (f64, f64)> = Default::default();
    for l in &problem.harmonic_loads {
        for (i, t) in row_of(l.dof).iter().enumerate() {
            if *t != 0.0 {
                let e = harmonic.entry((l.harmonic, i)).or_insert((0.0, 0.0));
                e.0 += t * l.cos;
                e.1 += t * l.sin;
            }
        }
    }
    out.harmonic_loads = harmonic
        .into_iter()
        .map(|((harmonic, dof), (cos, sin))| HarmonicLoad {
            dof,
            harmonic,
            cos,
            sin,
        })
        .collect();
    out.outputs = problem.outputs.iter().map(|&d| position[d]).collect();
    out.fe = problem.fe.as_ref().map(|fe| {
        std::sync::Arc::new(crate::model::FeOrigin {
            mesh: fe.mesh.clone(),
            dofs: fe.dofs.clone(),
            recovery: basis,
            reduced: true,
        })
    });
    debug_assert!(nb <= nr);
    Ok(Reduction {
        problem: out,
        model: reduced,
    })
}
