//! Results on the FE mesh, as VTU for ParaView: at one converged point, the static displacement
//! (0th harmonic), the first harmonic per direction at every node (its amplitude, and its
//! cosine and sine parts, which hold the phase: the motion is c cos ωt + s sin ωt, so a
//! travelling or complex shape shows by animating c cos φ + s sin φ over φ), and the contact
//! state at the contact nodes.
//!
//! Reduced problems are mapped back to the mesh through the Craig-Bampton basis kept with the
//! problem ([`crate::model::FeOrigin`]); when it was too large to keep, nothing is written.

use std::path::{Path, PathBuf};

use crate::contact::harmonic::HarmonicSet;
use crate::contact::ContactState;
use crate::fe::{write_vtu, PointField, VtuError};
use crate::model::Problem;

/// Numeric code of a contact state in the `contact_state` field (−1 at nodes without contact).
pub fn state_code(state: ContactState) -> f64 {
    match state {
        ContactState::Stuck => 0.0,
        ContactState::StickSlip => 1.0,
        ContactState::StickSlipLiftoff => 2.0,
        ContactState::Open => 3.0,
    }
}

/// Writes `<dir>/<name>.vtu` for the point with full coefficients `x` (harmonic-major on the
/// problem's DOFs) and contact states `states`. Returns the file written, or None when the
/// problem has no mesh or its reduction basis was not kept.
pub fn write_point(
    dir: &Path,
    name: &str,
    problem: &Problem,
    x: &[f64],
    states: &[ContactState],
) -> Result<Option<PathBuf>, VtuError> {
    let Some(fe) = &problem.fe else {
        return Ok(None);
    };
    let n = problem.model.n_dofs();
    let set: HarmonicSet = problem.unknown_harmonics();
    let block = |j: Option<usize>| -> Option<Vec<f64>> {
        match j {
            Some(j) => fe.full_values(&x[j * n..(j + 1) * n]),
            None => Some(vec![0.0; fe.dofs.len()]),
        }
    };
    let (Some(q0), Some(c1), Some(s1)) = (
        block(set.constant_block()),
        block(set.cos_block(1)),
        block(set.sin_block(1)),
    ) else {
        return Ok(None);
    };
    let index = fe.mesh.node_index_map();
    let mut statics = vec![[0.0; 3]; fe.mesh.nodes.len()];
    let mut amplitude = vec![[0.0; 3]; fe.mesh.nodes.len()];
    let (mut cosine, mut sine) = (amplitude.clone(), amplitude.clone());
    for (row, dof) in fe.dofs.dofs().iter().enumerate() {
        if let (Some(&i), true) = (index.get(&dof.node), dof.direction.is_translation()) {
            let a = dof.direction.axis();
            statics[i][a] = q0[row];
            amplitude[i][a] = c1[row].hypot(s1[row]);
            cosine[i][a] = c1[row];
            sine[i][a] = s1[row];
        }
    }
    // Contact nodes: the nodes named by each contact's DOFs (`<node>.<direction>`).
    let mut state = vec![-1.0; fe.mesh.nodes.len()];
    for (c, contact) in problem.contacts.iter().enumerate() {
        for &(d, _) in contact.row_entries() {
            let node = problem.model.dof_names[d]
                .split('.')
                .next()
                .and_then(|s| s.parse::<u64>().ok());
            if let (Some(node), Some(s)) = (node, states.get(c)) {
                if let Some(&i) = index.get(&node) {
                    state[i] = state_code(*s);
                }
            }
        }
    }
    let path = dir.join(format!("{name}.vtu"));
    write_vtu(
        &path,
        &fe.mesh,
        &[
            PointField::vectors("static_displacement", statics),
            PointField::vectors("first_harmonic_amplitude", amplitude),
            PointField::vectors("first_harmonic_cos", cosine),
            PointField::vectors("first_harmonic_sin", sine),
            PointField::scalars("contact_state", state),
        ],
    )?;
    Ok(Some(path))
}
