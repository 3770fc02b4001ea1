//! Validation of the linear structure: the `[model]` table built into a [`LinearModel`]
//! (inline dense matrices, or an FE model through [`crate::scene::fe_input`]), the optional
//! Craig-Bampton `[reduction]`, the model's stiffness scale that bounds contact stiffnesses,
//! and the check that the structure with all contacts stuck can carry static loads.

use faer::Mat;

use crate::analysis::linear::contact_stiffness;
use crate::model::matrix::StructuralMatrix;
use crate::model::reduce::{self, ReductionSettings};
use crate::model::{LinearModel, Problem};
use crate::scene::checker::{Checker, DofNames};
use crate::scene::error::SceneError;
use crate::scene::fe_input::{self, FeStructure, ReductionSpec};
use crate::scene::schema::ModelSpec;

/// The diagonal of a structural matrix (one pass over its stored entries).
pub(super) fn diagonal(m: &StructuralMatrix) -> Vec<f64> {
    let mut d = vec![0.0; m.n()];
    m.for_each_nonzero(|i, j, v| {
        if i == j {
            d[i] += v;
        }
    });
    d
}

/// The model's stiffness scale (N/m): the largest diagonal entry of K, 0 for a model without
/// stiffness. It bounds the contact stiffnesses (a spring far stiffer than the structure
/// swamps it in round-off) and sets the tolerance of rigid-body modes.
pub(super) fn stiffness_scale(model: &LinearModel) -> f64 {
    diagonal(&model.stiffness)
        .into_iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()))
}

/// The linear structure: inline dense matrices, or an FE model (mesh or Matrix Market).
pub(super) fn build_model(
    m: &ModelSpec,
    ck: &Checker,
) -> Result<(LinearModel, Option<FeStructure>), SceneError> {
    if m.is_fe() {
        if !m.dofs.is_empty()
            || !m.mass.is_empty()
            || !m.stiffness.is_empty()
            || m.damping.is_some()
        {
            return Err(ck.err(
                "model",
                "give inline matrices (`dofs`, `mass`, `stiffness`, `damping`) or an FE model \
                 (`mesh` or `matrix_market`), not both",
            ));
        }
        let [alpha, beta] = m.rayleigh.unwrap_or([0.0, 0.0]);
        for (i, v) in [alpha, beta].iter().enumerate() {
            ck.non_negative(&format!("model.rayleigh[{i}]"), *v)?;
        }
        let fe = fe_input::build_structure(
            ck.file,
            m.mesh.as_deref(),
            &m.materials,
            m.plane,
            &m.clamp,
            m.matrix_market.as_ref(),
            (alpha, beta),
        )?;
        return Ok((fe.model.clone(), Some(fe)));
    }
    for (field, set) in [
        ("model.materials", !m.materials.is_empty()),
        ("model.clamp", !m.clamp.is_empty()),
        ("model.rayleigh", m.rayleigh.is_some()),
    ] {
        if set {
            return Err(ck.err(
                field,
                "applies to FE models only (`mesh` or `matrix_market`)",
            ));
        }
    }
    let dofs = &m.dofs;
    let n = dofs.len();
    if n == 0 {
        return Err(ck.err("model.dofs", "must name at least one DOF"));
    }
    for (i, d) in dofs.iter().enumerate() {
        ck.name(&format!("model.dofs[{i}]"), d)?;
        if dofs[..i].contains(d) {
            return Err(ck.err(format!("model.dofs[{i}]"), format!("duplicate DOF `{d}`")));
        }
    }
    let mass = ck.matrix("model.mass", &m.mass, n)?;
    let stiffness = ck.matrix("model.stiffness", &m.stiffness, n)?;
    let damping = match &m.damping {
        Some(c) => ck.matrix("model.damping", c, n)?,
        None => Mat::zeros(n, n),
    };
    ck.semidefinite("model.mass", &mass)?;
    mass_spread(ck, &mass)?;
    ck.semidefinite("model.stiffness", &stiffness)?;
    ck.semidefinite("model.damping", &damping)?;
    Ok((
        LinearModel {
            dof_names: dofs.clone(),
            mass: StructuralMatrix::Dense(mass),
            damping: StructuralMatrix::Dense(damping),
            stiffness: StructuralMatrix::Dense(stiffness),
        },
        None,
    ))
}

/// The reduction settings of a `[reduction]` table (with the model's Rayleigh damping, α 1/s
/// and β s, and the `[reduction.boundary]` DOFs resolved to full-model rows); `None` without
/// the table. No recovery rows are asked for here (the `reduce` command adds the outputs').
pub(super) fn reduction_settings(
    reduction: Option<&ReductionSpec>,
    model: &ModelSpec,
    ck: &Checker,
    dofs: &DofNames,
    fe: Option<&FeStructure>,
) -> Result<Option<ReductionSettings>, SceneError> {
    let Some(r) = reduction else {
        return Ok(None);
    };
    if r.modes == 0 {
        return Err(ck.err("reduction.modes", "must be ≥ 1"));
    }
    let zeta = ck.non_negative("reduction.modal_damping", r.modal_damping)?;
    let [alpha, beta] = model.rayleigh.unwrap_or([0.0, 0.0]);
    let mut boundary = r
        .boundary
        .dofs
        .iter()
        .enumerate()
        .map(|(i, d)| ck.dof(&format!("reduction.boundary.dofs[{i}]"), d, dofs))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, g) in r.boundary.groups.iter().enumerate() {
        let field = format!("reduction.boundary.groups[{i}]");
        let Some(fe) = fe else {
            return Err(ck.err(
                field,
                "groups need an FE mesh (`model.mesh`); name DOFs in reduction.boundary.dofs",
            ));
        };
        boundary.extend(fe_input::group_dofs(ck.file, &field, fe, g)?);
    }
    Ok(Some(ReductionSettings {
        modes: r.modes,
        modal_damping: zeta,
        rayleigh: (alpha, beta),
        ordering: r.ordering.ordering(),
        recover: Vec::new(),
        boundary,
    }))
}

/// The problem reduced by Craig-Bampton with `settings`; unchanged without them.
pub(super) fn reduce_problem(
    settings: Option<&ReductionSettings>,
    ck: &Checker,
    problem: Problem,
) -> Result<Problem, SceneError> {
    let Some(settings) = settings else {
        return Ok(problem);
    };
    Ok(reduce::reduce(&problem, settings)
        .map_err(|e| ck.err("reduction", e.to_string()))?
        .problem)
}

/// The structure with all contacts stuck must carry static loads: K + contact springs must be
/// positive definite (a free body, or an indefinite K, is refused). Dense models: eigenvalues;
/// sparse ones: a sparse Cholesky factorisation.
pub(super) fn check_stuck_structure(ck: &Checker, problem: &Problem) -> Result<(), SceneError> {
    let singular = || {
        ck.err(
            "model.stiffness",
            "the structure is singular or indefinite even with all contacts stuck (a body is \
             free, or K has a negative eigenvalue: ground the body or connect it through a \
             contact, and check K)",
        )
    };
    match &problem.model.stiffness {
        StructuralMatrix::Dense(k) => {
            let mut k = k.clone();
            for (i, j, v) in contact_stiffness(problem) {
                k[(i, j)] += v;
            }
            let (min, max) = ck.eigen_range("model.stiffness", &k)?;
            if min <= 1e-12 * max {
                return Err(singular());
            }
        }
        StructuralMatrix::Sparse(_) => {
            let mut t = problem.model.stiffness.triplets();
            t.extend(contact_stiffness(problem));
            let StructuralMatrix::Sparse(k) =
                StructuralMatrix::sparse_from_triplets(problem.model.n_dofs(), &t)
            else {
                unreachable!("sparse_from_triplets builds sparse storage")
            };
            k.sp_cholesky(faer::Side::Lower).map_err(|_| singular())?;
        }
    }
    Ok(())
}

/// Largest ratio of two positive diagonal entries of an inline mass matrix: beyond it the
/// light DOFs are lost in the round-off of the heavy ones (a mass of 1e40 kg beside 0.1 kg
/// makes the structure's dynamics meaningless).
pub const MAX_MASS_RATIO: f64 = 1e12;

/// Refuses an inline mass matrix whose positive diagonal entries span more than
/// [`MAX_MASS_RATIO`], naming the largest entry.
fn mass_spread(ck: &Checker, mass: &Mat<f64>) -> Result<(), SceneError> {
    let diag: Vec<f64> = (0..mass.nrows()).map(|i| mass[(i, i)]).collect();
    let positive = diag.iter().copied().filter(|&m| m > 0.0);
    let min = positive.clone().fold(f64::INFINITY, f64::min);
    let Some((i, &max)) = diag
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .filter(|(_, &m)| m > 0.0)
    else {
        return Ok(());
    };
    if max > MAX_MASS_RATIO * min {
        return Err(ck.err(
            format!("model.mass[{i}][{i}]"),
            format!(
                "{max:e} kg is more than {MAX_MASS_RATIO:e} times the lightest DOF's mass \
                 ({min:e} kg): the light DOFs would be lost in round-off; check the units (kg)"
            ),
        ));
    }
    Ok(())
}
