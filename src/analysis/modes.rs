//! Natural frequencies and mode shapes of a problem's linear structure, with its contacts open
//! (removed) or stuck (replaced by their springs kₜ aₜaₜᵀ + kₙ aₙaₙᵀ), and the damped
//! eigenvalues with their modal damping ratios: the check an FE analyst makes of the linear
//! model before any friction analysis.
//!
//! Undamped modes solve K φ = λ M φ, λ = ω² (rad²/s²), f = ω/2π (Hz). Problems of at most
//! [`DENSE_MAX_DOFS`] DOFs are solved densely (all eigenvalues, faer); larger ones by the
//! reduction crate's shift-invert block Lanczos with the shift
//! σ = −max((2π·1 Hz)², 10⁻⁶ λ_scale) (K − σM is then positive definite, and well conditioned,
//! even where a body is free), and the result is checked by a Sturm count
//! of the full model between the last mode kept and the next one: a missed mode is an error.
//!
//! Rigid-body modes: with contacts open a wedge damper is a free body, K is singular and the
//! lowest eigenvalues are zero up to round-off. A mode is reported as rigid
//! ([`Mode::rigid`]) when λ < [`RIGID_TOLERANCE`] · λ_scale, λ_scale = max K_ii / M_ii; its
//! frequency is then 0 Hz.
//!
//! Repeated eigenvalues: the modes kept are extended past `count` while the next eigenvalue
//! equals the last kept one within [`CLUSTER_RTOL`], so every copy of a repeated frequency is
//! reported (a symmetric structure's pairs are not cut in half).
//!
//! Damped modes (state space, dense, at most [`DAMPED_MAX_DOFS`] DOFs): the eigenvalues s of
//! [[0, I], [−M⁻¹K, −M⁻¹C]] (formed balanced, see [`damped_modes`]) with Im s ≥ 0, rigid-body
//! ones (two real eigenvalues per rigid-body mode) counted apart, the others ordered by |s|; natural frequency |s|/2π, damped
//! frequency Im s/2π, damping ratio ζ = −Re s/|s|. For Rayleigh damping C = αM + βK this is
//! ζ = α/(2ω) + βω/2 per mode (the check of the tests). A real s (an overdamped motion, or a
//! free body's motion damped by αM) has ζ = 1.

use std::time::Instant;

use faer::{c64, Mat};
use fricbound_reduction::{Ordering, ReductionError};

use crate::analysis::linear::{contact_stiffness, LinearCase};
use crate::model::matrix::StructuralMatrix;
use crate::model::Problem;

/// Largest problem whose undamped modes are solved densely; larger ones use Lanczos.
pub const DENSE_MAX_DOFS: usize = 2000;

/// Largest problem whose damped eigenvalues are computed (dense state space of 2n).
pub const DAMPED_MAX_DOFS: usize = 800;

/// Relative size (of max K_ii/M_ii) below which an eigenvalue is a rigid-body mode.
pub const RIGID_TOLERANCE: f64 = 1e-9;

/// Relative distance within which two eigenvalues are copies of a repeated one.
pub const CLUSTER_RTOL: f64 = 1e-6;

/// Smallest magnitude of the Lanczos shift, (2π·1 Hz)² (rad²/s²).
const LANCZOS_SHIFT_MIN: f64 = (2.0 * std::f64::consts::PI) * (2.0 * std::f64::consts::PI);

/// Magnitude of the Lanczos shift relative to λ_scale: with a free body, K − σM has pivots
/// of about |σ|/λ_scale relative to its diagonal, which must stay far above the factorisation's
/// singularity threshold (10⁻¹¹).
const LANCZOS_SHIFT_RELATIVE: f64 = 1e-6;

/// Extra eigenpairs asked of Lanczos beyond `count` (to find the end of a repeated cluster
/// and the next distinct eigenvalue for the Sturm check).
const LANCZOS_EXTRA: usize = 4;

/// One undamped mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// Eigenvalue λ = ω² (rad²/s²).
    pub eigenvalue: f64,
    /// Natural frequency (Hz), 0 for a rigid-body mode.
    pub frequency_hz: f64,
    /// Rigid-body mode (λ ≈ 0, see the module docs).
    pub rigid: bool,
}

/// How the eigenvalues were found.
#[derive(Debug, Clone, PartialEq)]
pub enum EigenMethod {
    /// Dense symmetric solve of the whole pencil.
    Dense,
    /// Shift-invert block Lanczos, checked by a Sturm count.
    Lanczos {
        /// Eigenvalues of the full model below `sturm_shift_hz` by the Sturm count (equals the
        /// number of modes kept).
        sturm_count: Option<usize>,
        /// Frequency of the Sturm check's shift (Hz).
        sturm_shift_hz: f64,
        /// Largest relative residual ‖Kφ − λMφ‖ / ‖Kφ‖ of the pairs.
        max_residual: f64,
    },
}

/// The lowest undamped modes of a problem in one contact case.
#[derive(Debug, Clone)]
pub struct NaturalModes {
    /// Contact case.
    pub case: LinearCase,
    /// Modes, ascending.
    pub modes: Vec<Mode>,
    /// Mass-normalised shapes, one column per mode, in the problem's coordinates.
    pub shapes: Mat<f64>,
    /// Solver used.
    pub method: EigenMethod,
    /// Wall-clock time (s).
    pub seconds: f64,
}

/// One damped mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedMode {
    /// Eigenvalue s of the state-space matrix (1/s), Im s ≥ 0.
    pub eigenvalue: c64,
    /// Natural frequency |s|/2π (Hz).
    pub natural_hz: f64,
    /// Damped frequency Im s/2π (Hz).
    pub damped_hz: f64,
    /// Modal damping ratio −Re s/|s| (–).
    pub damping_ratio: f64,
}

/// Why modes could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum ModesError {
    /// The eigen solve failed.
    #[error("eigen solve ({case}): {source}")]
    Eigen {
        /// Contact case.
        case: &'static str,
        /// Cause.
        source: ReductionError,
    },
    /// The Sturm count found more eigenvalues below its shift than modes were computed.
    #[error(
        "eigen solve ({case}): the Sturm count finds {found} eigenvalues below {shift_hz:.6} Hz \
         but {computed} modes were computed: Lanczos missed a mode (ask for more with --count)"
    )]
    MissedModes {
        /// Contact case.
        case: &'static str,
        /// Modes computed below the shift.
        computed: usize,
        /// Sturm count.
        found: usize,
        /// Shift (Hz).
        shift_hz: f64,
    },
    /// The mass matrix is singular (massless DOFs): the damped state-space form needs M⁻¹.
    #[error("damped modes: the mass matrix is not positive definite (massless DOFs?)")]
    MassSingular,
    /// The damped eigenvalue solve failed.
    #[error("damped modes: the eigenvalue solve did not converge")]
    DampedEigen,
}

/// Name of a contact case in files and messages.
pub fn case_name(case: LinearCase) -> &'static str {
    match case {
        LinearCase::Open => "open",
        LinearCase::Stuck => "stuck",
    }
}

/// K of the structure in a contact case, as triplets (stuck: with the contact springs).
fn case_stiffness(problem: &Problem, case: LinearCase) -> Vec<(usize, usize, f64)> {
    let mut k = problem.model.stiffness.triplets();
    if case == LinearCase::Stuck {
        k.extend(contact_stiffness(problem));
    }
    k
}

/// max K_ii / M_ii over the DOFs with mass (rad²/s²): the scale of rigid-body round-off.
fn eigenvalue_scale(k: &[(usize, usize, f64)], m: &StructuralMatrix) -> f64 {
    let n = m.n();
    let (mut kd, mut md) = (vec![0.0; n], vec![0.0; n]);
    for &(i, j, v) in k {
        if i == j {
            kd[i] += v;
        }
    }
    m.for_each_nonzero(|i, j, v| {
        if i == j {
            md[i] += v;
        }
    });
    (0..n)
        .filter(|&i| md[i] > 0.0)
        .map(|i| kd[i].abs() / md[i])
        .fold(0.0, f64::max)
}

fn hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// How many of the ascending `values` to keep for `count` asked: extended over every copy of
/// the last kept eigenvalue.
fn kept_count(values: &[f64], count: usize, scale: f64) -> usize {
    let mut kept = count.min(values.len());
    while kept > 0 && kept < values.len() {
        let (last, next) = (values[kept - 1], values[kept]);
        let tol = CLUSTER_RTOL * last.abs().max(RIGID_TOLERANCE * scale);
        if next - last <= tol {
            kept += 1;
        } else {
            break;
        }
    }
    kept
}

/// The lowest `count` undamped modes (and every copy of the last one's eigenvalue) of the
/// problem's structure in a contact case; dense or Lanczos by size (module docs).
pub fn natural_modes(
    problem: &Problem,
    case: LinearCase,
    count: usize,
) -> Result<NaturalModes, ModesError> {
    let start = Instant::now();
    let n = problem.model.n_dofs();
    let name = case_name(case);
    let eigen = |source| ModesError::Eigen { case: name, source };
    let k = case_stiffness(problem, case);
    let scale = eigenvalue_scale(&k, &problem.model.mass);
    let count = count.min(n);
    let (values, vectors, method) = if n <= DENSE_MAX_DOFS {
        let mut kd = Mat::<f64>::zeros(n, n);
        for &(i, j, v) in &k {
            kd[(i, j)] += v;
        }
        let md = problem.model.mass.to_dense();
        let (values, vectors) =
            fricbound_reduction::dense_generalized_eigenvalues(kd.as_ref(), md.as_ref())
                .map_err(eigen)?;
        (values, vectors, EigenMethod::Dense)
    } else {
        let ks = sparse(n, &k);
        let ms = sparse(n, &problem.model.mass.triplets());
        let asked = (count + LANCZOS_EXTRA).min(n);
        let shift = -(LANCZOS_SHIFT_RELATIVE * scale).max(LANCZOS_SHIFT_MIN);
        let eig = fricbound_reduction::lowest_eigenpairs(ks.as_ref(), ms.as_ref(), asked, shift)
            .map_err(eigen)?;
        let kept = kept_count(&eig.values, count, scale);
        let last = eig.values[kept - 1];
        let sigma = match eig.values.get(kept) {
            Some(&next) => 0.5 * (last + next),
            None => last + (last.abs() * 1e-3).max(RIGID_TOLERANCE * scale),
        };
        let sturm = fricbound_reduction::count_eigenvalues_below(
            ks.as_ref(),
            ms.as_ref(),
            sigma,
            Ordering::Metis,
        )
        .map_err(eigen)?;
        if let Some(found) = sturm {
            if found != kept {
                return Err(ModesError::MissedModes {
                    case: name,
                    computed: kept,
                    found,
                    shift_hz: hz(sigma),
                });
            }
        }
        let method = EigenMethod::Lanczos {
            sturm_count: sturm,
            sturm_shift_hz: hz(sigma),
            max_residual: eig.max_residual,
        };
        (eig.values, eig.vectors, method)
    };
    let kept = kept_count(&values, count, scale);
    let modes = values[..kept]
        .iter()
        .map(|&lambda| {
            let rigid = lambda < RIGID_TOLERANCE * scale;
            Mode {
                eigenvalue: lambda,
                frequency_hz: if rigid { 0.0 } else { hz(lambda) },
                rigid,
            }
        })
        .collect();
    let shapes = Mat::from_fn(n, kept, |i, j| vectors[(i, j)]);
    Ok(NaturalModes {
        case,
        modes,
        shapes,
        method,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Sparse CSC matrix of size n from triplets (duplicates summed).
fn sparse(n: usize, t: &[(usize, usize, f64)]) -> faer::sparse::SparseColMat<usize, f64> {
    match StructuralMatrix::sparse_from_triplets(n, t) {
        StructuralMatrix::Sparse(s) => s,
        StructuralMatrix::Dense(_) => unreachable!("sparse_from_triplets builds sparse storage"),
    }
}

/// Whether the problem's damping matrix has a non-zero entry.
pub fn is_damped(problem: &Problem) -> bool {
    let mut any = false;
    problem
        .model
        .damping
        .for_each_nonzero(|_, _, v| any |= v != 0.0);
    any
}

/// The damped modes of a problem in one contact case.
#[derive(Debug, Clone, PartialEq)]
pub struct DampedModes {
    /// The lowest elastic damped modes, by natural frequency.
    pub modes: Vec<DampedMode>,
    /// Rigid-body eigenvalues left out of `modes`: two real ones per rigid-body mode of the
    /// undamped problem (s = 0, and 0 or −α under Rayleigh damping).
    pub rigid: usize,
}

/// The lowest `count` elastic damped modes of the problem in a contact case (module docs);
/// `None` when the problem is undamped or larger than [`DAMPED_MAX_DOFS`].
///
/// The state-space matrix is formed in the undamped modal coordinates, scaled so that it is
/// balanced: with K Φ = M Φ Λ (Φᵀ M Φ = I), Ω = Λ^½, C̃ = Φᵀ C Φ and the states z₁ = Ω η,
/// z₂ = η̇ (q = Φ η), ż = [[0, Ω], [−Ω, −C̃]] z. Its eigenvalues are those of
/// [[0, I], [−M⁻¹K, −M⁻¹C]], but every entry is of the size of a frequency, where the
/// unscaled form mixes 1 with K/M (10¹³ for a steel mesh) and loses digits.
pub fn damped_modes(
    problem: &Problem,
    case: LinearCase,
    count: usize,
) -> Result<Option<DampedModes>, ModesError> {
    let n = problem.model.n_dofs();
    if n > DAMPED_MAX_DOFS || !is_damped(problem) {
        return Ok(None);
    }
    let triplets = case_stiffness(problem, case);
    let scale = eigenvalue_scale(&triplets, &problem.model.mass);
    let mut k = Mat::<f64>::zeros(n, n);
    for (i, j, v) in triplets {
        k[(i, j)] += v;
    }
    let m = problem.model.mass.to_dense();
    let (lambda, phi) = fricbound_reduction::dense_generalized_eigenvalues(k.as_ref(), m.as_ref())
        .map_err(|_| ModesError::MassSingular)?;
    // Rigid-body modes at exactly ω = 0, as in the undamped report.
    let rigid_bound = RIGID_TOLERANCE * scale;
    let omega: Vec<f64> = lambda
        .iter()
        .map(|&l| if l < rigid_bound { 0.0 } else { l.sqrt() })
        .collect();
    let c = problem.model.damping.to_dense();
    let c_modal = phi.transpose() * &c * &phi;
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => {
            if j - n == i {
                omega[i]
            } else {
                0.0
            }
        }
        (false, true) => {
            if i - n == j {
                -omega[j]
            } else {
                0.0
            }
        }
        (false, false) => -c_modal[(i - n, j - n)],
    });
    let mut values = a.eigenvalues().map_err(|_| ModesError::DampedEigen)?;
    // Each rigid-body mode (ω_i ≈ 0) gives two real eigenvalues: 0 (its z₁ row is zero) and
    // the decay of its velocity under C (0, or −α under Rayleigh damping). They are the
    // 2·n_rigid real eigenvalues of smallest |s|, counted apart.
    let n_rigid = lambda.iter().filter(|&&l| l < rigid_bound).count();
    let norm_max = values.iter().map(|s| s.norm()).fold(0.0, f64::max);
    let is_real = |s: &c64| s.im.abs() <= 1e-9 * norm_max.max(f64::MIN_POSITIVE);
    let mut real: Vec<usize> = (0..values.len()).filter(|&i| is_real(&values[i])).collect();
    real.sort_by(|&a, &b| values[a].norm().total_cmp(&values[b].norm()));
    let mut drop: Vec<usize> = real.into_iter().take(2 * n_rigid).collect();
    let rigid = drop.len();
    drop.sort_unstable();
    for &i in drop.iter().rev() {
        values.remove(i);
    }
    let mut modes: Vec<DampedMode> = values
        .into_iter()
        .filter(|s| s.im >= -1e-9 * norm_max)
        .map(|s| {
            let norm = s.norm();
            DampedMode {
                eigenvalue: s,
                natural_hz: norm / (2.0 * std::f64::consts::PI),
                damped_hz: s.im.max(0.0) / (2.0 * std::f64::consts::PI),
                damping_ratio: if norm > 0.0 { -s.re / norm } else { 0.0 },
            }
        })
        .collect();
    modes.sort_by(|a, b| a.natural_hz.total_cmp(&b.natural_hz));
    modes.truncate(count);
    Ok(Some(DampedModes { modes, rigid }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_eigenvalues_extend_the_kept_count() {
        let v = [0.0, 1.0, 4.0, 4.0 * (1.0 + 1e-9), 4.0 * (1.0 + 2e-9), 9.0];
        assert_eq!(kept_count(&v, 3, 9.0), 5);
        assert_eq!(kept_count(&v, 2, 9.0), 2);
        assert_eq!(kept_count(&v, 6, 9.0), 6);
    }
}
