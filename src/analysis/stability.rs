//! Hill stability of a converged harmonic-balance point: the Floquet exponents of the
//! periodic solution from the Hill eigenvalue problem, and the verdict `stable` / unstable.
//!
//! # The Hill problem
//!
//! The equations of motion are M q̈ + C q̇ + K q + f_c(q) = f_ex(t). A perturbation of the
//! periodic solution q*(τ), τ = ωt, is sought as e^{λt} p(τ) with p periodic and written in the
//! same real Fourier coefficients as q (harmonic-major blocks, see
//! [`crate::contact::harmonic`]). With d/dt = ω d/dτ and ∇ the derivative d/dτ acting on
//! coefficients ((∇p)_ch = h p_sh, (∇p)_sh = −h p_ch, (∇p)₀ = 0), linearising gives the
//! quadratic eigenvalue problem
//!
//! ```text
//! ( λ² Δ₂ + λ Δ₁ + J ) p = 0,   Δ₂ = I ⊗ M,   Δ₁ = I ⊗ C + 2ω ∇ ⊗ M,
//! ```
//!
//! where J = ∂R/∂x is the harmonic-balance Jacobian at the point (paper Eq. 7: the linear
//! part K − (hω)²M, ±hωC per harmonic, plus the analytic AFT Jacobian of the contact forces).
//! The contact part of the linearisation is the AFT Jacobian, i.e. the derivative of the
//! steady-state periodic contact forces: the usual approximation of Hill's method for
//! hysteretic (Jenkins) contacts, exact for smooth laws.
//!
//! It is solved through its companion linearisation in the non-dimensional exponent s = λ/ω
//! (so that J, ωΔ₁ and ω²Δ₂ have comparable entries): since Δ₂ is block-diagonal with M on
//! every block, M is inverted once and the first-order matrix
//!
//! ```text
//! ⎡ 0               I             ⎤ ⎡p ⎤     ⎡p ⎤
//! ⎣ −(ω²Δ₂)⁻¹J   −(ω²Δ₂)⁻¹ωΔ₁  ⎦ ⎣sp⎦ = s ⎣sp⎦
//! ```
//!
//! goes to faer's dense nonsymmetric eigen solver (`faer::linalg::evd::evd_real`, on the calling
//! thread; the QZ of the pencil
//! was tried first: on the paper system at H = 3 it took seconds per point against milliseconds). A singular mass matrix is
//! refused. The cost grows as (2·unknowns)³: models with more than [`MAX_HILL_UNKNOWNS`]
//! unknowns use the sparse shift-invert solve of [`crate::analysis::stability_sparse`]
//! instead (scene field `analysis.hill_solver`, default `auto`).
//!
//! # Picking the Floquet exponents
//!
//! Every Floquet exponent λ of the truncated problem appears 2H + 1 times, as λ + ikω
//! (k = −H..H), with the eigenvector's content shifted by k harmonics. The rule used here:
//! write p in complex exponentials, p(τ) = Σₖ cₖ e^{ikτ} (c₀ = p₀, c_{±h} = (p_ch ∓ i p_sh)/2),
//! and keep the eigenvalues whose eigenvector content is **most centred**: the smallest
//! |k̄|, k̄ = Σ k‖cₖ‖² / Σ ‖cₖ‖² (the symmetric-eigenvector criterion of Lazarus & Thomas,
//! 2010), as many as there are exponents (finite eigenvalues / (2H + 1)). Shifting a copy by
//! one harmonic moves k̄ by one, so one copy of each exponent has |k̄| ≤ 1/2. The centroid
//! rather than the largest component matters at a fold: there the unstable mode is real and
//! its eigenvector is the path's tangent, mostly first harmonic, split evenly between k = ±1
//! (k̄ = 0), while its copies λ ± iω have content at {0, ±2} (k̄ = ±1). For a linear system the
//! Hill matrix is block-diagonal and the kept exponents are exactly the damped eigenvalues of
//! M, C, K (checked in the tests); with contacts, eigenvalues whose content piles up at the
//! truncation edge |k| ≈ H (spurious ones) are not the kept copies. This needs the 0th harmonic among the unknowns and the
//! harmonics 0..H without gaps (a coupled scene with `harmonics.max`), checked at the door.
//!
//! # The verdict
//!
//! The leading exponent is the kept one with the largest real part; the point is `stable`
//! when that real part is at most [`STABILITY_TOLERANCE`]·ω (a growth time over 10⁶ periods/2π
//! is taken as neutral, above the eigen solver's round-off). `floquet_re` (1/s) is that real
//! part and `floquet_freq_hz` = |Im λ|/2π the frequency of the mode that grows (or decays
//! slowest): 0 for a real exponent (a fold: the saddle-node branch between two turning points),
//! a mode's frequency for a flutter-like (Neimark-Sacker) loss of stability.

use faer::linalg::solvers::DenseSolveCore;
use faer::{c64, Mat, MatRef};
use serde::Serialize;

use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::ContactState;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::LinearModel;

/// Most harmonic-balance unknowns (DOFs × coefficient blocks) solved by the dense eigen solve
/// of the 2·unknowns companion matrix, about 30·(2·unknowns)³ flops; above it runs use the
/// sparse shift-invert solve ([`crate::analysis::stability_sparse`]) unless the scene asks for
/// `analysis.hill_solver = "dense"`, which is then refused.
pub const MAX_HILL_UNKNOWNS: usize = 600;

/// Largest real part of the leading Floquet exponent, relative to ω, of a point still
/// called stable (neutral within round-off).
pub const STABILITY_TOLERANCE: f64 = 1e-6;

/// The method that gave a point its verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum VerdictSource {
    /// Hill's method (this module), the whole spectrum by the dense eigen solve.
    Hill,
    /// Hill's method by the sparse shift-invert solve of the exponents near the estimated
    /// ones ([`crate::analysis::stability_sparse`]).
    HillSparse,
    /// The monodromy of the time integration's periodic orbit
    /// ([`crate::analysis::monodromy`]).
    Monodromy,
    /// No verdict: the monodromy was asked for and failed (a time step whose Newton did not
    /// converge) and Hill's method was not run ([`PointStability::failed`]).
    Failed,
}

impl VerdictSource {
    /// The label written in `frf.csv`, `curve_*.csv` and the JSON files.
    pub fn label(self) -> &'static str {
        match self {
            VerdictSource::Hill => "hill",
            VerdictSource::HillSparse => "hill-sparse",
            VerdictSource::Monodromy => "monodromy",
            VerdictSource::Failed => "failed",
        }
    }
}

/// The stability of one converged point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointStability {
    /// Leading Floquet exponent's real part at most [`STABILITY_TOLERANCE`]·ω (written null
    /// in JSON when there is no verdict, [`VerdictSource::Failed`]).
    pub stable: bool,
    /// Real part of the leading Floquet exponent (1/s): > 0 grows, < 0 decays.
    pub floquet_re: f64,
    /// |Im λ|/2π of the leading exponent (Hz): the frequency of the mode that destabilises
    /// the point (0 for a real exponent, e.g. past a fold). A perturbation holds every
    /// λ + ikω, so this frequency is defined modulo the excitation frequency; the kept copy is
    /// the one whose content is most centred.
    pub floquet_freq_hz: f64,
    /// Which method gave the verdict.
    pub method: VerdictSource,
    /// Whether the verdict can be trusted: Hill's on points where every contact with friction
    /// is stuck or open all period ([`hill_reliable`]), the monodromy's where its shooting
    /// converged to the periodic orbit.
    pub reliable: bool,
}

/// As the fields `stable` (null without a verdict), `floquet_re`, `floquet_freq_hz`,
/// `stability_method` and `stability_reliable`.
impl Serialize for PointStability {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = serializer.serialize_struct("PointStability", 5)?;
        st.serialize_field("stable", &self.has_verdict().then_some(self.stable))?;
        st.serialize_field("floquet_re", &self.floquet_re)?;
        st.serialize_field("floquet_freq_hz", &self.floquet_freq_hz)?;
        st.serialize_field("stability_method", &self.method)?;
        st.serialize_field("stability_reliable", &self.reliable)?;
        st.end()
    }
}

impl PointStability {
    /// No verdict: the monodromy failed at the point and Hill's method was not asked for.
    pub fn failed() -> Self {
        Self {
            stable: false,
            floquet_re: f64::NAN,
            floquet_freq_hz: f64::NAN,
            method: VerdictSource::Failed,
            reliable: false,
        }
    }

    /// Whether the point has a verdict and it is unstable (what figures dash and stretches
    /// count).
    pub fn is_unstable(&self) -> bool {
        self.method != VerdictSource::Failed && !self.stable
    }

    /// Whether the point has a verdict at all.
    pub fn has_verdict(&self) -> bool {
        self.method != VerdictSource::Failed
    }
}

/// Which methods gave the verdicts `verdicts` (e.g. the points of a curve), for legends and
/// summaries: `Hill`, `Hill, unreliable on stick-slip` when some Hill verdict is not
/// reliable, `monodromy`, or `monodromy on stick-slip, Hill elsewhere` when both gave
/// verdicts.
pub fn methods_text<'a>(verdicts: impl IntoIterator<Item = &'a PointStability>) -> &'static str {
    let (mut hill, mut hill_unreliable, mut monodromy) = (false, false, false);
    for v in verdicts {
        match v.method {
            VerdictSource::Hill | VerdictSource::HillSparse => {
                hill = true;
                hill_unreliable |= !v.reliable;
            }
            VerdictSource::Monodromy => monodromy = true,
            VerdictSource::Failed => {}
        }
    }
    match (hill, monodromy) {
        (true, true) => "monodromy on stick-slip, Hill elsewhere",
        (false, true) => "monodromy",
        _ if hill_unreliable => "Hill, unreliable on stick-slip",
        _ => "Hill",
    }
}

/// Whether Hill's verdict can be trusted at a point with these contact states: every contact
/// is stuck or open over the whole period, or has no friction (μ = 0: a one-sided spring,
/// such as the lift-off fold of `tests/data/liftoff-fold.toml`, where Hill agrees with the
/// monodromy). On stick-slip points the AFT Jacobian linearises the steady-state force map,
/// not the slider's dynamics, and Hill's growth rates were measured 20-55 times the
/// monodromy's on the paper case (README, section Stability).
pub fn hill_reliable(problem: &crate::model::Problem, states: &[ContactState]) -> bool {
    problem
        .contacts
        .iter()
        .zip(states)
        .all(|(c, s)| c.law.mu == 0.0 || matches!(s, ContactState::Stuck | ContactState::Open))
}

/// Why the Floquet exponents of a point could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StabilityError {
    /// The Jacobian at the point could not be evaluated.
    #[error("Jacobian at the point: {0}")]
    Hbm(#[from] HbmError),
    /// The dense eigen solve did not converge.
    #[error("the Hill eigenvalue problem ({size} × {size}) did not converge")]
    EigenSolve {
        /// Size of the companion pencil.
        size: usize,
    },
    /// The harmonic set lacks the 0th harmonic or has gaps.
    #[error("Hill stability needs the harmonics 0, 1, …, H without gaps (got {0:?})")]
    Harmonics(Vec<usize>),
    /// Every eigenvalue was non-finite.
    #[error("no finite Floquet exponent")]
    NoFiniteExponent,
    /// The mass matrix is singular (a DOF without mass).
    #[error("Hill stability needs a non-singular mass matrix (every DOF with mass)")]
    SingularMass,
}

/// Whether the harmonic set suits Hill's method here: 0, 1, …, H without gaps.
pub fn harmonics_supported(set: &HarmonicSet) -> bool {
    set.harmonics().iter().enumerate().all(|(i, &h)| i == h)
}

/// The Floquet exponents λ (1/s) picked from the Hill spectrum (see the module doc) of a
/// point with harmonic-balance Jacobian `jacobian` (dense, harmonic-major, all DOFs of
/// `model`, blocks of `set`) at ω (rad/s), in no particular order.
pub fn floquet_exponents(
    model: &LinearModel,
    set: &HarmonicSet,
    jacobian: MatRef<'_, f64>,
    omega: f64,
) -> Result<Vec<c64>, StabilityError> {
    if !harmonics_supported(set) {
        return Err(StabilityError::Harmonics(set.harmonics().to_vec()));
    }
    let n = model.n_dofs();
    let blocks = set.blocks();
    let nb = blocks.len();
    let dim = n * nb;
    assert_eq!(jacobian.nrows(), dim, "Jacobian rows = DOFs × blocks");
    let mass = model.mass.to_dense();
    let damping = model.damping.to_dense();
    // ω²Δ₂ is block-diagonal with ω²M on every block: invert M once (refused when singular).
    let lu = mass.as_ref().partial_piv_lu();
    let mass_inverse = lu.inverse();
    if !mass_inverse.as_ref().is_all_finite() {
        return Err(StabilityError::SingularMass);
    }
    // The first-order matrix of the companion form in s = λ/ω:
    // [[0, I], [−(ω²Δ₂)⁻¹ J, −(ω²Δ₂)⁻¹ ωΔ₁]].
    let size = 2 * dim;
    let mut lower = Mat::<f64>::zeros(dim, size);
    for j in 0..dim {
        for i in 0..dim {
            lower[(i, j)] = jacobian[(i, j)];
        }
    }
    for (jb, block) in blocks.iter().enumerate() {
        let h = block.harmonic() as f64;
        // (∇ ⊗ M) couples a cos block's rows to its sine partner's columns and back.
        let partner = match block {
            Block::Cos(hh) => set.sin_block(*hh).map(|k| (k, h)),
            Block::Sin(hh) => set.cos_block(*hh).map(|k| (k, -h)),
            Block::Constant => None,
        };
        for r in 0..n {
            for c in 0..n {
                lower[(jb * n + r, dim + jb * n + c)] = omega * damping[(r, c)];
                if let Some((kb, sign)) = partner {
                    lower[(jb * n + r, dim + kb * n + c)] =
                        2.0 * omega * omega * sign * mass[(r, c)];
                }
            }
        }
    }
    let scale = -1.0 / (omega * omega);
    let mut a = Mat::<f64>::zeros(size, size);
    for i in 0..dim {
        a[(i, dim + i)] = 1.0;
    }
    for jb in 0..nb {
        let rows = lower.as_ref().subrows(jb * n, n);
        let solved = &mass_inverse * rows;
        for r in 0..n {
            for c in 0..size {
                a[(dim + jb * n + r, c)] = scale * solved[(r, c)];
            }
        }
    }
    let (values, vectors) =
        sequential_eigen(a.as_ref()).map_err(|_| StabilityError::EigenSolve { size })?;
    // Eigenvalues λ = ω s with the centroid k̄ of their eigenvector's content.
    let mut finite: Vec<(c64, f64)> = Vec::new();
    for (k, s) in values.iter().enumerate() {
        if !(s.re.is_finite() && s.im.is_finite()) {
            continue;
        }
        let centroid = content_centroid(set, n, vectors.col(k).subrows(0, dim));
        finite.push((*s * omega, centroid));
    }
    if finite.is_empty() {
        return Err(StabilityError::NoFiniteExponent);
    }
    // Each exponent appears once per coefficient block (2H + 1 copies): keep that many
    // exponents, those with the most centred content.
    let keep = ((finite.len() as f64 / nb as f64).round() as usize).max(1);
    finite.sort_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
    Ok(finite.into_iter().take(keep).map(|(l, _)| l).collect())
}

/// Eigenvalues and right eigenvectors of a real square matrix, solved on the calling thread
/// (faer's default parallelism spreads these small solves over rayon's threads, which on a
/// loaded machine cost more in waiting than the solve itself, and the limit analysis already
/// runs its curves in parallel). Complex pairs come as (λ, v), (λ̄, v̄).
fn sequential_eigen(
    a: MatRef<'_, f64>,
) -> Result<(Vec<c64>, Mat<c64>), faer::linalg::evd::EvdError> {
    use faer::diag::Diag;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{evd_real, evd_scratch, ComputeEigenvectors};
    use faer::Par;
    let n = a.nrows();
    let mut s_re = Diag::<f64>::zeros(n);
    let mut s_im = Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    let mut buffer = MemBuffer::new(evd_scratch::<f64>(
        n,
        ComputeEigenvectors::No,
        ComputeEigenvectors::Yes,
        Par::Seq,
        Default::default(),
    ));
    evd_real(
        a,
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut buffer),
        Default::default(),
    )?;
    let mut values = vec![c64::new(0.0, 0.0); n];
    let mut vectors = Mat::<c64>::zeros(n, n);
    let mut j = 0;
    while j < n {
        if s_im[j] == 0.0 || j + 1 == n {
            values[j] = c64::new(s_re[j], s_im[j]);
            for i in 0..n {
                vectors[(i, j)] = c64::new(u[(i, j)], 0.0);
            }
            j += 1;
        } else {
            values[j] = c64::new(s_re[j], s_im[j]);
            values[j + 1] = c64::new(s_re[j], -s_im[j]);
            for i in 0..n {
                vectors[(i, j)] = c64::new(u[(i, j)], u[(i, j + 1)]);
                vectors[(i, j + 1)] = c64::new(u[(i, j)], -u[(i, j + 1)]);
            }
            j += 2;
        }
    }
    Ok((values, vectors))
}

/// The centroid k̄ = Σ k‖cₖ‖² / Σ ‖cₖ‖² of the complex-exponential content cₖ (k = −H..H) of
/// the eigenvector p (harmonic-major real-coefficient blocks of `n` DOFs): 0 for content
/// centred on the 0th component (including a real mode split evenly between k = ±1, the
/// saddle-node mode at a fold), ±1 for its copies shifted by one harmonic.
pub(crate) fn content_centroid(set: &HarmonicSet, n: usize, p: faer::ColRef<'_, c64>) -> f64 {
    content_profile(set, n, p).0
}

/// The centroid k̄ of [`content_centroid`] and the fraction of the content at the truncation
/// edge |k| = H (0 when H = 0). A spurious eigenvalue of the truncated Hill matrix can have
/// its content split between k = +H and k = −H, hence k̄ ≈ 0: the edge fraction tells it apart
/// from a centred copy.
pub fn content_profile(set: &HarmonicSet, n: usize, p: faer::ColRef<'_, c64>) -> (f64, f64) {
    let h_max = set.harmonics().last().copied().unwrap_or(0);
    let i = c64::new(0.0, 1.0);
    let (mut moment, mut total, mut edge) = (0.0, 0.0, 0.0);
    for (jb, block) in set.blocks().iter().enumerate() {
        match block {
            Block::Constant => {
                total += (0..n).map(|r| p[jb * n + r].norm_sqr()).sum::<f64>();
            }
            Block::Cos(h) => {
                let Some(js) = set.sin_block(*h) else {
                    continue;
                };
                let (mut plus, mut minus) = (0.0, 0.0);
                for r in 0..n {
                    let (pc, ps) = (p[jb * n + r], p[js * n + r]);
                    plus += (pc - i * ps).norm_sqr() / 4.0;
                    minus += (pc + i * ps).norm_sqr() / 4.0;
                }
                moment += *h as f64 * (plus - minus);
                total += plus + minus;
                if *h == h_max {
                    edge += plus + minus;
                }
            }
            Block::Sin(_) => {}
        }
    }
    if total > 0.0 {
        (moment / total, edge / total)
    } else {
        (0.0, 0.0)
    }
}

/// The verdict from the picked exponents at ω (rad/s): the leading exponent (largest real
/// part) and whether it is within [`STABILITY_TOLERANCE`]·ω of the imaginary axis or left of
/// it.
pub fn verdict(exponents: &[c64], omega: f64) -> PointStability {
    let lead = exponents
        .iter()
        .copied()
        .fold(c64::new(f64::NEG_INFINITY, 0.0), |a, b| {
            if b.re > a.re {
                b
            } else {
                a
            }
        });
    PointStability {
        stable: lead.re <= STABILITY_TOLERANCE * omega,
        floquet_re: lead.re,
        floquet_freq_hz: lead.im.abs() / (2.0 * std::f64::consts::PI),
        method: VerdictSource::Hill,
        reliable: true,
    }
}

/// The stability of the converged point with full coefficients `x` at ω (rad/s) of `system`:
/// its Jacobian (the system's strategy, analytic by default) in dense form, the Floquet
/// exponents and the verdict, `reliable` from the contact states at the point
/// ([`hill_reliable`]). The system's contact states are left as they were. The whole Hill
/// spectrum is solved densely; [`crate::analysis::stability_sparse::point_stability_with`]
/// can use the sparse shift-invert solve instead (what runs do above the dense limit).
pub fn point_stability(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    omega: f64,
) -> Result<PointStability, StabilityError> {
    let dim = system.dim();
    let mut jacobian = system.new_jacobian();
    let (mut r, mut dr) = (vec![0.0; dim], vec![0.0; dim]);
    let states = system.states.clone();
    let evaluated = system.residual_and_jacobian(x, omega, &mut r, &mut jacobian, &mut dr);
    let reliable = hill_reliable(system.problem(), &system.states);
    system.states = states;
    evaluated?;
    let dense = jacobian.to_dense();
    let exponents = floquet_exponents(
        &system.problem().model,
        system.unknowns(),
        dense.as_ref(),
        omega,
    )?;
    Ok(PointStability {
        reliable,
        ..verdict(&exponents, omega)
    })
}

/// The stretches of a path (frequencies in Hz, `[from, to]` with from ≤ to) over which
/// consecutive points are unstable, in path order, from each point's frequency and stability;
/// a single unstable point gives a stretch of zero width. Points without stability (not
/// computed) count as stable.
pub fn unstable_stretches(
    points: impl IntoIterator<Item = (f64, Option<PointStability>)>,
) -> Vec<[f64; 2]> {
    let mut stretches = Vec::new();
    let mut current: Option<[f64; 2]> = None;
    for (freq_hz, stability) in points {
        if stability.is_some_and(|s| s.is_unstable()) {
            let span = current.get_or_insert([freq_hz, freq_hz]);
            span[0] = span[0].min(freq_hz);
            span[1] = span[1].max(freq_hz);
        } else if let Some(span) = current.take() {
            stretches.push(span);
        }
    }
    stretches.extend(current);
    stretches
}

/// `unstable_stretches` as text, e.g. `220.10-221.34 Hz, 228.00 Hz`; `stable throughout`
/// when there are none.
pub fn stretches_text(stretches: &[[f64; 2]]) -> String {
    if stretches.is_empty() {
        return "stable throughout".to_string();
    }
    stretches
        .iter()
        .map(|[a, b]| {
            if a == b {
                format!("{a:.2} Hz")
            } else {
                format!("{a:.2}-{b:.2} Hz")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The damped eigenvalues λ (1/s) of λ²M + λC + K (all 2n, conjugate pairs included), by the
/// eigen solve of the first-order matrix [[0, I], [−M⁻¹K, −M⁻¹C]]: for a linear system these are
/// its Floquet exponents, and the shift-invert solve places its shifts at them
/// ([`super::stability_sparse::exponent_estimates`]). A singular M is refused.
pub fn damped_eigenvalues(
    mass: MatRef<'_, f64>,
    damping: MatRef<'_, f64>,
    stiffness: MatRef<'_, f64>,
) -> Result<Vec<c64>, StabilityError> {
    let n = mass.nrows();
    let minv = mass.partial_piv_lu().inverse();
    if !minv.as_ref().is_all_finite() {
        return Err(StabilityError::SingularMass);
    }
    let (mk, mc) = (&minv * stiffness, &minv * damping);
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - n == i)),
        (false, true) => -mk[(i - n, j)],
        (false, false) => -mc[(i - n, j - n)],
    });
    a.eigenvalues()
        .map_err(|_| StabilityError::EigenSolve { size: 2 * n })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::matrix::StructuralMatrix;

    /// A 3-DOF chain with non-proportional damping.
    fn chain() -> LinearModel {
        let m = Mat::from_fn(3, 3, |i, j| if i == j { [1.0, 0.5, 2.0][i] } else { 0.0 });
        let k = Mat::from_fn(3, 3, |i, j| match (i, j) {
            (0, 0) => 3.0e4,
            (1, 1) => 2.5e4,
            (2, 2) => 1.0e4,
            (0, 1) | (1, 0) => -1.0e4,
            (1, 2) | (2, 1) => -0.5e4,
            _ => 0.0,
        });
        let c = Mat::from_fn(3, 3, |i, j| match (i, j) {
            (0, 0) => 4.0,
            (1, 1) => 0.5,
            (2, 2) => 1.0,
            (0, 1) | (1, 0) => -0.3,
            _ => 0.0,
        });
        LinearModel {
            dof_names: vec!["a".into(), "b".into(), "c".into()],
            mass: StructuralMatrix::Dense(m),
            damping: StructuralMatrix::Dense(c),
            stiffness: StructuralMatrix::Dense(k),
        }
    }

    /// The linear harmonic-balance Jacobian of `model` (paper Eq. 7 without contacts).
    fn linear_jacobian(model: &LinearModel, set: &HarmonicSet, omega: f64) -> Mat<f64> {
        let n = model.n_dofs();
        let (m, c, k) = (
            model.mass.to_dense(),
            model.damping.to_dense(),
            model.stiffness.to_dense(),
        );
        let nb = set.n_blocks();
        let mut j = Mat::zeros(n * nb, n * nb);
        for (jb, block) in set.blocks().iter().enumerate() {
            let hw = block.harmonic() as f64 * omega;
            for r in 0..n {
                for q in 0..n {
                    j[(jb * n + r, jb * n + q)] = k[(r, q)] - hw * hw * m[(r, q)];
                }
            }
            let partner = match block {
                Block::Cos(h) => set.sin_block(*h).map(|s| (s, 1.0)),
                Block::Sin(h) => set.cos_block(*h).map(|s| (s, -1.0)),
                Block::Constant => None,
            };
            if let Some((pb, sign)) = partner {
                for r in 0..n {
                    for q in 0..n {
                        j[(jb * n + r, pb * n + q)] = sign * hw * c[(r, q)];
                    }
                }
            }
        }
        j
    }

    fn damped_eigenvalues(model: &LinearModel) -> Vec<c64> {
        let (m, c, k) = (
            model.mass.to_dense(),
            model.damping.to_dense(),
            model.stiffness.to_dense(),
        );
        super::damped_eigenvalues(m.as_ref(), c.as_ref(), k.as_ref())
            .expect("a small eigen solve converges")
    }

    fn sorted(mut v: Vec<c64>) -> Vec<c64> {
        v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        v
    }

    #[test]
    fn linear_exponents_are_the_damped_eigenvalues() {
        let model = chain();
        let expected = sorted(damped_eigenvalues(&model));
        for (h_max, freq_hz) in [(1, 10.0), (3, 17.3), (5, 40.0)] {
            let set = HarmonicSet::up_to(h_max);
            let omega = 2.0 * std::f64::consts::PI * freq_hz;
            let j = linear_jacobian(&model, &set, omega);
            let got = sorted(floquet_exponents(&model, &set, j.as_ref(), omega).unwrap());
            assert_eq!(got.len(), expected.len(), "H = {h_max}: {got:?}");
            for (g, e) in got.iter().zip(&expected) {
                assert!(
                    (g - e).norm() <= 1e-7 * e.norm(),
                    "H = {h_max}, f = {freq_hz}: {g} vs {e}"
                );
            }
            let v = verdict(&got, omega);
            assert!(v.stable && v.floquet_re < 0.0);
            let lead = expected.last().unwrap();
            assert!((v.floquet_re - lead.re).abs() <= 1e-7 * lead.norm());
        }
    }

    #[test]
    fn negative_damping_is_unstable_at_the_mode_frequency() {
        let mut model = chain();
        // A negative damper on DOF b (alone, to keep the others damped).
        if let StructuralMatrix::Dense(c) = &mut model.damping {
            c[(1, 1)] = -0.8;
        }
        let expected = sorted(damped_eigenvalues(&model));
        let lead = *expected.last().unwrap();
        assert!(lead.re > 0.0, "the fixture must be unstable");
        let set = HarmonicSet::up_to(3);
        let omega = 2.0 * std::f64::consts::PI * 25.0;
        let j = linear_jacobian(&model, &set, omega);
        let v = verdict(
            &floquet_exponents(&model, &set, j.as_ref(), omega).unwrap(),
            omega,
        );
        assert!(!v.stable);
        assert!((v.floquet_re - lead.re).abs() <= 1e-7 * lead.norm());
        let f = lead.im.abs() / (2.0 * std::f64::consts::PI);
        assert!((v.floquet_freq_hz - f).abs() <= 1e-6 * f, "{v:?} vs {f}");
    }

    #[test]
    fn gaps_in_the_harmonics_are_refused() {
        let model = chain();
        let set = HarmonicSet::new(vec![0, 1, 3]);
        let j = Mat::zeros(3 * set.n_blocks(), 3 * set.n_blocks());
        assert!(matches!(
            floquet_exponents(&model, &set, j.as_ref(), 10.0),
            Err(StabilityError::Harmonics(_))
        ));
    }
}
