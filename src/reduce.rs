//! Craig-Bampton reduction of a problem on a large (sparse) FE model to a small dense one.
//!
//! The boundary set is every DOF the friction problem needs as a physical coordinate: the
//! contact DOFs, the DOFs carrying static or harmonic loads and the output DOFs. Everything
//! else is condensed into constraint modes and the lowest fixed-interface modes by the
//! `fricbound-reduction` crate, so the reduced coordinates are q = [u_B; η]: the boundary
//! displacements (named as in the full model) then the modal amplitudes (`mode1`, `mode2`, ...).
//! Contacts, loads and outputs keep their meaning on u_B exactly, since Craig-Bampton keeps
//! boundary DOFs as physical coordinates.
//!
//! Damping: Rayleigh damping C = αM + βK of the full model reduces exactly to αM_r + βK_r
//! (the Craig-Bampton basis T is applied congruently, TᵀCT); modal damping ratios ζ act on the
//! fixed-interface modes, C_r[η_i, η_i] += 2ζω_i.

use fricbound_reduction::{craig_bampton, CbOptions, Ordering, ReducedModel, ReductionError};

use crate::matrix::StructuralMatrix;
use crate::model::{HarmonicLoad, LinearModel, Problem};

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

/// The boundary DOFs of a problem: contact, loaded and output DOFs, sorted.
pub fn boundary_dofs(problem: &Problem) -> Vec<usize> {
    let mut b = problem.contact_dofs();
    b.extend(
        problem
            .static_load
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(d, _)| d),
    );
    b.extend(problem.harmonic_loads.iter().map(|l| l.dof));
    b.extend(problem.outputs.iter().copied());
    b.sort_unstable();
    b.dedup();
    b
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
    let mut options = CbOptions::with_modes(settings.modes);
    options.ordering = settings.ordering;
    let reduced = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &boundary,
        &settings.recover,
        &options,
    )?;
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
    for (i, &d) in boundary.iter().enumerate() {
        static_load[i] = problem.static_load[d];
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
    out.harmonic_loads = problem
        .harmonic_loads
        .iter()
        .map(|l| HarmonicLoad {
            dof: position[l.dof],
            ..*l
        })
        .collect();
    out.outputs = problem.outputs.iter().map(|&d| position[d]).collect();
    debug_assert!(nb <= nr);
    Ok(Reduction {
        problem: out,
        model: reduced,
    })
}
