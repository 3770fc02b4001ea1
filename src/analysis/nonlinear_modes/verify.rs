//! A point of a nonlinear mode checked by time integration: the autonomous structure with the
//! artificial damping applied, M q̈ + (C − ξ M) q̇ + K q + f_c = F_static, integrated from the
//! point's state by [`crate::analysis::verify`] over periods 2π/ω. The motion is periodic and
//! its first harmonic is the mode's where the harmonic balance resolves it; it stays on the
//! orbit where the orbit is stable (the damping ratio rising with the amplitude there: a little
//! more amplitude dissipates more than ξ feeds in).

use super::run::NonlinearModePoint;
use crate::analysis::verify::{verify_point, PointVerification, VerifyError, VerifySettings};
use crate::model::matrix::StructuralMatrix;
use crate::model::Problem;

/// The autonomous problem of `problem` (harmonic loads left out) with the damping C − ξ M.
pub fn negatively_damped(problem: &Problem, xi: f64) -> Problem {
    let mut p = super::run::autonomous(problem);
    let n = p.model.n_dofs();
    let mut entries = p.model.damping.triplets();
    entries.extend(
        p.model
            .mass
            .triplets()
            .into_iter()
            .map(|(i, j, m)| (i, j, -xi * m)),
    );
    p.model.damping = match &p.model.damping {
        StructuralMatrix::Dense(_) => {
            let mut c = faer::Mat::<f64>::zeros(n, n);
            for (i, j, v) in entries {
                c[(i, j)] += v;
            }
            StructuralMatrix::Dense(c)
        }
        StructuralMatrix::Sparse(_) => StructuralMatrix::sparse_from_triplets(n, &entries),
    };
    p
}

/// Integrates the negatively damped structure from the mode point `point` (of a mode of
/// `problem`) and compares the output amplitudes with the point's.
pub fn verify_mode_point(
    problem: &Problem,
    point: &NonlinearModePoint,
    settings: &VerifySettings,
) -> Result<PointVerification, VerifyError> {
    let damped = negatively_damped(problem, point.xi);
    let set = damped.unknown_harmonics();
    let n = damped.model.n_dofs();
    let (Some(c1), Some(s1)) = (set.cos_block(1), set.sin_block(1)) else {
        return Err(VerifyError::Unsupported {
            reason: "a nonlinear mode needs the first harmonic".to_string(),
        });
    };
    let amplitudes: Vec<f64> = damped
        .outputs
        .iter()
        .map(|&d| point.coefficients[c1 * n + d].hypot(point.coefficients[s1 * n + d]))
        .collect();
    verify_point(
        &damped,
        &set,
        &point.coefficients,
        &amplitudes,
        point.freq_hz,
        settings,
    )
}
