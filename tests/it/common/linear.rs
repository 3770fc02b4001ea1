//! Linear references of a problem's structure.

use faer::c64;
use fricbound::model::Problem;

/// The damped eigenvalues λ of λ²M + λC + K (first-order form; rad/s) of the problem's
/// structural matrices, contacts left out.
pub fn damped_eigenvalues(problem: &Problem) -> Vec<c64> {
    let (m, c, k) = (
        problem.model.mass.to_dense(),
        problem.model.damping.to_dense(),
        problem.model.stiffness.to_dense(),
    );
    fricbound::analysis::stability::damped_eigenvalues(m.as_ref(), c.as_ref(), k.as_ref()).unwrap()
}
