//! Craig-Bampton reduction of a problem on a large (sparse) FE model to a small dense one.
//!
//! The boundary set ([`boundary`]) is every DOF the friction problem needs as a physical
//! coordinate: the contact DOFs, completed to every direction the model has at each contact
//! node, the output DOFs, and the extra DOFs a scene asks for (`[reduction.boundary]`).
//! A contact's rows may use fewer directions than its node has (a grounded contact with a
//! zero normal component, a 3D patch whose frame has no z component); the node is kept
//! physical in every direction all the same, so the reduced model does not depend on which
//! components of a contact frame happen to be zero (a model reported with such nodes left
//! partly interior had 58 boundary DOFs instead of 102 and its 10th mode 4 % off). Everything
//! else is condensed into constraint modes and the
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
    /// Full-model DOFs kept physical beyond the contact and output DOFs.
    pub boundary: Vec<usize>,
}

/// How many boundary DOFs each origin adds, each DOF counted once, at its first origin in
/// this order: contact rows, the other directions of contact nodes, outputs, extra.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BoundaryMakeup {
    /// DOFs with a non-zero coefficient in a contact's tangential or normal row.
    pub contacts: usize,
    /// Other directions of the contact nodes (see the module docs).
    pub contact_nodes: usize,
    /// Output DOFs.
    pub outputs: usize,
    /// DOFs of `[reduction.boundary]`.
    pub extra: usize,
    /// Loaded DOFs: not in the boundary (their loads are projected on the basis), counted
    /// for the report.
    pub loaded: usize,
}

/// A contact node whose contact rows use fewer directions than the model has there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartialContactNode {
    /// Contact point.
    pub contact: String,
    /// Node (the DOF name's part before the direction, e.g. `42`).
    pub node: String,
    /// Directions the contact's rows use at that node.
    pub used: Vec<String>,
    /// Directions the model has at that node.
    pub model: Vec<String>,
}

/// The boundary DOF set of a reduction, sorted, with its make-up.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Boundary {
    /// Full-model DOFs kept physical, sorted.
    pub dofs: Vec<usize>,
    /// Count per origin.
    pub makeup: BoundaryMakeup,
    /// Contact nodes completed to every direction.
    pub partial_contact_nodes: Vec<PartialContactNode>,
}

/// Splits a DOF name `<node>.<dir>` into node and direction; `None` for names without a
/// direction suffix (inline models name DOFs freely).
fn node_and_direction(name: &str) -> Option<(&str, &str)> {
    let (node, dir) = name.rsplit_once('.')?;
    crate::fe::Direction::parse(dir).map(|_| (node, dir))
}

/// The boundary of a problem: contact DOFs completed to every direction of their nodes,
/// outputs, then `extra` (full-model DOFs), with the make-up by origin.
pub fn boundary(problem: &Problem, extra: &[usize]) -> Boundary {
    use std::collections::{BTreeMap, BTreeSet, HashMap};
    let names = &problem.model.dof_names;
    let mut origin: BTreeMap<usize, usize> = BTreeMap::new();
    let mut add = |d: usize, o: usize| {
        origin.entry(d).or_insert(o);
    };
    let contact = problem.contact_dofs();
    // Directions each contact uses per node.
    let mut used: Vec<(String, BTreeMap<&str, BTreeSet<&str>>)> = Vec::new();
    for c in &problem.contacts {
        let mut per_node: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for &(d, _) in c.row_entries() {
            if let Some((node, dir)) = node_and_direction(&names[d]) {
                per_node.entry(node).or_default().insert(dir);
            }
        }
        used.push((c.name.clone(), per_node));
    }
    let nodes: BTreeSet<&str> = used.iter().flat_map(|(_, m)| m.keys().copied()).collect();
    let mut node_dofs: HashMap<&str, Vec<usize>> = HashMap::new();
    if !nodes.is_empty() {
        for (d, name) in names.iter().enumerate() {
            if let Some((node, _)) = node_and_direction(name) {
                if nodes.contains(node) {
                    node_dofs.entry(node).or_default().push(d);
                }
            }
        }
    }
    for &d in &contact {
        add(d, 0);
    }
    let mut partial = Vec::new();
    for (contact_name, per_node) in &used {
        for (node, dirs) in per_node {
            let all = node_dofs.get(node).map(Vec::as_slice).unwrap_or(&[]);
            for &d in all {
                add(d, 1);
            }
            if all.len() > dirs.len() {
                partial.push(PartialContactNode {
                    contact: contact_name.clone(),
                    node: node.to_string(),
                    used: dirs.iter().map(|s| s.to_string()).collect(),
                    model: all
                        .iter()
                        .filter_map(|&d| node_and_direction(&names[d]).map(|(_, r)| r.to_string()))
                        .collect(),
                });
            }
        }
    }
    for &d in &problem.outputs {
        add(d, 2);
    }
    for &d in extra {
        add(d, 3);
    }
    let mut makeup = BoundaryMakeup {
        loaded: loaded_dofs(problem).len(),
        ..Default::default()
    };
    for &o in origin.values() {
        match o {
            0 => makeup.contacts += 1,
            1 => makeup.contact_nodes += 1,
            2 => makeup.outputs += 1,
            _ => makeup.extra += 1,
        }
    }
    Boundary {
        dofs: origin.into_keys().collect(),
        makeup,
        partial_contact_nodes: partial,
    }
}

/// A reduced problem and what is needed to go back to the full model.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// The reduced problem (dense).
    pub problem: Problem,
    /// The reduced model with its recovery rows (of `settings.recover`, in that order) and
    /// report.
    pub model: ReducedModel,
    /// The boundary kept physical and its make-up.
    pub boundary: Boundary,
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
    let kept = boundary(problem, &settings.boundary);
    let boundary = kept.dofs.clone();
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
        if let Some(second) = &mut c.second_tangent {
            second.row = remap(&second.row);
        }
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
        boundary: kept,
    })
}
