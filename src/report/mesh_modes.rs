//! Mode shapes of an FE problem with its contacts stuck (replaced by their kt, kn springs), on
//! the mesh as VTU for ParaView: one vector field per mode, named with its frequency.
//!
//! The modes are those of the problem as solved: for a reduced problem the eigenpairs of the
//! dense reduced pencil (K_r + K_contact, M_r), mapped back to every node through the kept
//! Craig-Bampton basis; for an unreduced problem of at most [`MAX_DENSE_DOFS`] DOFs the dense
//! pencil of the full model. Larger unreduced problems are skipped (the sparse Lanczos solver
//! of the reduction crate serves the fixed-interface modes there).

use std::path::{Path, PathBuf};

use crate::fe::{write_vtu, PointField};
use crate::model::Problem;

/// Largest unreduced problem whose modes are computed densely.
pub const MAX_DENSE_DOFS: usize = 3000;

/// Modes written.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshModes {
    /// File written.
    pub path: PathBuf,
    /// Natural frequencies (Hz), ascending.
    pub frequencies_hz: Vec<f64>,
}

/// Errors of the mode computation or the file.
#[derive(Debug, thiserror::Error)]
pub enum MeshModesError {
    /// The eigen solve failed.
    #[error("stuck-contact modes: {0}")]
    Eigen(#[from] fricbound_reduction::ReductionError),
    /// The file could not be written.
    #[error(transparent)]
    Vtu(#[from] crate::fe::VtuError),
}

/// Writes the lowest `count` stuck-contact modes of `problem` to `<dir>/modes_stuck.vtu`;
/// None when the problem has no mesh, no kept basis, or is too large to solve densely.
pub fn write_stuck_modes(
    dir: &Path,
    problem: &Problem,
    count: usize,
) -> Result<Option<MeshModes>, MeshModesError> {
    let Some(fe) = &problem.fe else {
        return Ok(None);
    };
    let n = problem.model.n_dofs();
    if (fe.reduced && fe.recovery.is_none()) || (!fe.reduced && n > MAX_DENSE_DOFS) {
        return Ok(None);
    }
    let mut k = problem.model.stiffness.to_dense();
    for (i, j, v) in crate::analysis::linear::contact_stiffness(problem) {
        k[(i, j)] += v;
    }
    let m = problem.model.mass.to_dense();
    let (values, vectors) =
        fricbound_reduction::dense_generalized_eigenvalues(k.as_ref(), m.as_ref())?;
    let index = fe.mesh.node_index_map();
    let mut fields = Vec::new();
    let mut frequencies_hz = Vec::new();
    for (mode, &lambda) in values.iter().enumerate().take(count) {
        let f = lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI);
        let shape: Vec<f64> = (0..n).map(|i| vectors[(i, mode)]).collect();
        let Some(full) = fe.full_values(&shape) else {
            return Ok(None);
        };
        let mut nodal = vec![[0.0; 3]; fe.mesh.nodes.len()];
        for (row, dof) in fe.dofs.dofs().iter().enumerate() {
            if let (Some(&i), true) = (index.get(&dof.node), dof.direction.is_translation()) {
                nodal[i][dof.direction.axis()] = full[row];
            }
        }
        fields.push(PointField::vectors(
            &format!("mode_{:02}_{:.1}Hz", mode + 1, f),
            nodal,
        ));
        frequencies_hz.push(f);
    }
    let path = dir.join("modes_stuck.vtu");
    write_vtu(&path, &fe.mesh, &fields)?;
    Ok(Some(MeshModes {
        path,
        frequencies_hz,
    }))
}
