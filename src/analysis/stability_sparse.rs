//! Hill stability for models above the dense limit ([`super::stability::MAX_HILL_UNKNOWNS`],
//! or on request): the Floquet exponents near estimates of them, by a shift-invert Arnoldi
//! iteration on the companion form of the Hill quadratic eigenvalue problem, with the sparse
//! harmonic-balance Jacobian and a complex sparse LU (faer 0.24) per shift. Runs use it through
//! the scene field `analysis.hill_solver` (`auto`: above the dense limit; `shift-invert`:
//! always); its verdicts carry `stability_method = hill-sparse`.
//!
//! # The operator
//!
//! In the non-dimensional exponent s = λ/ω the Hill problem of [`super::stability`] reads
//! Q(s) p = (s² A₂ + s A₁ + J) p = 0 with A₂ = ω² (I ⊗ M), A₁ = ω (I ⊗ C) + 2ω² (∇ ⊗ M)
//! (all sparse: block-diagonal or partner-block couplings of M and C). Its first companion
//! form L = [[0, I], [−A₂⁻¹J, −A₂⁻¹A₁]] has the eigenvalues s; shift-invert with a complex
//! shift σ makes those nearest σ dominant: μ = 1/(s − σ). Applying (L − σI)⁻¹ to [x; y] needs
//! no inverse of M, only one solve with Q(σ):
//!
//! ```text
//! u = Q(σ)⁻¹ [ −A₂ y − (A₁ + σA₂) x ],   w = x + σ u,   (L − σI)⁻¹ [x; y] = [u; w].
//! ```
//!
//! Q(σ) = J + σA₁ + σ²A₂ is complex, factored once per shift by faer's sparse LU; each Arnoldi
//! step is one forward/back solve. No well-kept Rust crate offered a shift-invert Arnoldi
//! (ARPACK-style) over faer's complex sparse LU at the time of writing (the reduction crate's
//! block Lanczos is for the symmetric K, M pencil), hence this one.
//!
//! # Where the shifts go
//!
//! Every exponent λ appears 2H + 1 times in the Hill spectrum, as λ + ikω; the dense path keeps
//! the **most centred** copy (content centroid k̄ ≈ 0, [`super::stability`]), and that copy
//! sits near the physical frequencies of the linearised structure (e.g. 490 Hz on the paper
//! system excited at 150 Hz), not in the strip Im λ ∈ (−ω/2, ω/2]. A first version put its
//! shifts in that strip: it found copies shifted by several harmonics toward the truncation
//! edge, poorly resolved in the truncated Hill matrix, and reported −0.148 1/s where the
//! dense path gives −0.175 1/s. So the shifts are placed at **estimates** of the centred
//! exponents ([`exponent_estimates`]): the damped eigenvalues of λ²M + λC + K̄ with K̄ = J₀₀, the
//! Jacobian's 0th-harmonic block (the structure's stiffness plus the period-mean contact
//! stiffness at the point), a dense 2·DOFs eigen solve ((2H + 1)³ times cheaper than the dense
//! Hill solve). For a linear system, and at points where every contact is stuck or open, these
//! estimates are the exponents themselves; at stick-slip points they are nearby. The shifts
//! start at s = 0.01i (a fold's real exponent near 0, whatever the estimates say) and then go
//! to the first estimate (by frequency) that no earlier shift's disc covers, just off it
//! (σ = ŝ + 10⁻⁴(1 + |ŝ|)i, since at an exact eigenvalue Q(σ) is singular), until every
//! estimate up to [`ShiftInvertSettings::max_freq_hz`] (default: all) is covered.
//!
//! # Convergence, selection and coverage
//!
//! Per shift, a Krylov space of [`ShiftInvertSettings::krylov`] vectors (classical
//! Gram-Schmidt twice, no restart) and the Ritz pairs of its Hessenberg matrix (faer's dense
//! complex eigen solve), walked from the nearest to the shift outwards while each is
//! converged: Arnoldi's residual β|y_m|/‖y‖ ≤ [`ShiftInvertSettings::tolerance`]·|μ| (so the
//! eigenvalue's error is about tolerance·|s − σ|), plus a backward error on the quadratic
//! problem below 10⁻⁸ of (‖J‖ + |s|‖A₁‖ + |s|²‖A₂‖)‖p‖ as a guard. The walk stops at the first
//! unconverged pair: the shift's disc |s − σ| ≤ r, r the distance of the farthest converged
//! pair, is taken to hold every Hill eigenvalue in it (up to the usual Krylov caveat: an
//! eigenvector with no component in the start vector is never seen).
//!
//! Candidates are the found eigenvalues with |k̄| ≤ 1/2 (conjugates merged, kept with
//! Im ≥ 0); then the dense rule: as many as the estimates count (2·DOFs with conjugates,
//! without a frequency limit), those with the smallest |k̄|. The count matters: at a stuck
//! point the initial slider state (T(τ_ini) = mμN(τ_ini)) couples every harmonic into the
//! 0th-harmonic force, and the Hill matrix has further eigenvalues with k̄ between 0 and 1/2
//! that are not exponents of the stuck system (measured on the paper system at 150 Hz: five
//! such, e.g. −0.148 1/s at 1603 Hz, k̄ = 0.26, while the stuck system's six exponents come
//! with k̄ below 10⁻²²).
//!
//! **Coverage statement.** The solve guarantees (up to the Krylov caveat) the centred
//! exponents inside the union of the discs; [`ShiftInvertExponents::complete`] says whether
//! that union covers s = 0 and every estimate. The verdict is marked not reliable
//! (`stability_reliable = false`) when it does not ([`point_stability_with`]), as well as on
//! stick-slip points (as the dense path). The exponents that decide the verdict are the least
//! damped: for Rayleigh or modal damping the lowest modes, which the estimates list first, so
//! the first shifts target them; an exponent that contact nonlinearity moves far from every
//! estimate (beyond the disc of the nearest shift) is not guaranteed to be found.
//!
//! # Checks and cost
//!
//! `tests/it/stability_sparse.rs`: on a 12-mass linear chain the 12 exponent pairs are the damped
//! eigenvalues of M, C, K to 10⁻⁹ at 8, 17.3 and 30 Hz; on the paper system (H = 3) the leading
//! exponent, its frequency and the verdict are the dense path's at 13 points of 150-235 Hz,
//! stuck and stick-slip (to 10⁻⁶ relative; the printed digits agree); above the dense limit (90
//! masses, 630 unknowns) the dense path's at a point and a run fills every point's verdict. The
//! cost is one complex sparse LU of the Hill size per shift, and the shifts grow with the
//! number of modes to cover: a table per point against the dense solve is printed by
//! `cargo run --release --example hill_sparse_cost` (README, section Stability).

use faer::prelude::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{c64, Mat};

use super::stability::{
    content_profile, damped_eigenvalues, harmonics_supported, hill_reliable, point_stability,
    verdict, PointStability, StabilityError, VerdictSource, MAX_HILL_UNKNOWNS,
};
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::hbm::HbmSystem;
use crate::model::{HillSolve, LinearModel};

/// Shifts and sizes of the shift-invert solve.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftInvertSettings {
    /// Explicit shifts σ = i·f as fractions f of the excitation frequency (s = λ/ω; a shift at
    /// f = 2.5 sits at 2.5 times the excitation frequency on the imaginary axis), replacing
    /// the automatic placement at the estimated exponents ([`exponent_estimates`]); coverage
    /// is then judged against the same estimates.
    pub shifts: Option<Vec<f64>>,
    /// Highest frequency (Hz) of the estimated exponents that must be covered; `None`: all of
    /// them (every mode of the model).
    pub max_freq_hz: Option<f64>,
    /// Krylov space dimension per shift (capped at 2·unknowns).
    pub krylov: usize,
    /// Arnoldi's residual of a Ritz pair of the shift-invert operator, relative to its
    /// eigenvalue μ = 1/(s − σ), below which the pair counts as converged: the eigenvalue's
    /// error is then about tolerance·|s − σ| (times its condition number). A backward error
    /// on the quadratic problem relative to ‖J‖ was tried first: with contact springs
    /// dominating ‖J‖ it let through unconverged Ritz values of mixed harmonic content.
    pub tolerance: f64,
}

impl Default for ShiftInvertSettings {
    fn default() -> Self {
        Self {
            shifts: None,
            max_freq_hz: None,
            krylov: 60,
            tolerance: 1e-10,
        }
    }
}

/// Backward error of an accepted eigenpair on the quadratic problem itself, a guard against
/// a Krylov basis that lost orthogonality (the convergence test proper is Arnoldi's residual,
/// [`ShiftInvertSettings::tolerance`]).
const QUADRATIC_BACKWARD_ERROR: f64 = 1e-8;

/// A sparse real matrix as (row, col, value) triplets.
type Triplets = Vec<(usize, usize, f64)>;

/// The found exponents and what the solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftInvertExponents {
    /// Floquet exponents λ (1/s) with Im λ ≥ 0 (the conjugates are exponents too): the centred
    /// Hill eigenvalues (|k̄| ≤ 1/2) inside the covered discs.
    pub exponents: Vec<c64>,
    /// Per exponent: its eigenvector's content centroid k̄ and the fraction of its content at
    /// the truncation edge |k| = H ([`super::stability::content_profile`]).
    pub content: Vec<(f64, f64)>,
    /// Ritz pairs dropped by the residual check.
    pub rejected: usize,
    /// Shifts used, in s = λ/ω (complex: placed at the estimates).
    pub shifts: Vec<c64>,
    /// Radii (in s) of the discs around the shifts inside which every Hill eigenvalue was
    /// found: the distance of the farthest of the consecutive nearest Ritz values that passed
    /// the residual check (0 when the nearest one failed).
    pub radii: Vec<f64>,
    /// The estimated exponents (1/s, Im ≥ 0, up to the frequency limit) that had to be
    /// covered, and how many of them no disc covers.
    pub estimates: Vec<c64>,
    /// Estimates outside every disc.
    pub uncovered: usize,
    /// Whether some disc covers every estimate (and s = 0): only then is the leading
    /// exponent taken as known.
    pub complete: bool,
}

/// Exponents an eigenvalue with Im ≥ 0 stands for: 1 if real, 2 with its conjugate.
fn pair_count(e: c64) -> usize {
    if e.im.abs() > 1e-9 * e.norm() {
        2
    } else {
        1
    }
}

/// Most DOFs for the dense estimate of the exponents ([`exponent_estimates`]), a 2·DOFs
/// nonsymmetric eigen solve: (2H + 1)³ times cheaper than the dense Hill solve it replaces,
/// still about 30·(2·DOFs)³ flops.
pub const MAX_ESTIMATE_DOFS: usize = 1000;

/// Estimates of the Floquet exponents (1/s) with Im ≥ 0: the damped eigenvalues of
/// λ²M + λC + K̄, K̄ = J₀₀ the harmonic-balance Jacobian's 0th-harmonic block (the structure's
/// stiffness plus the period-mean contact stiffness at the point: kt for a stuck contact, 0
/// for an open one). For a linear system these are the exponents themselves; with contacts
/// they sit near them. `jacobian`: triplets, harmonic-major (the 0th harmonic block first).
pub fn exponent_estimates(
    model: &LinearModel,
    jacobian: &[(usize, usize, f64)],
) -> Result<Vec<c64>, StabilityError> {
    let n = model.n_dofs();
    let mut k = Mat::<f64>::zeros(n, n);
    for &(i, j, v) in jacobian {
        if i < n && j < n {
            k[(i, j)] += v;
        }
    }
    let values = damped_eigenvalues(
        model.mass.to_dense().as_ref(),
        model.damping.to_dense().as_ref(),
        k.as_ref(),
    )?;
    let mut upper: Vec<c64> = values
        .into_iter()
        .filter(|v| v.re.is_finite() && v.im.is_finite() && v.im >= 0.0)
        .collect();
    upper.sort_by(|a, b| a.im.total_cmp(&b.im));
    Ok(upper)
}

/// The Floquet exponents of a point with harmonic-balance Jacobian `jacobian` (triplets,
/// duplicates summed, harmonic-major, all DOFs of `model`, blocks of `set`) at ω (rad/s), by
/// shift-invert Arnoldi with shifts placed at the estimated exponents (see the module doc).
pub fn floquet_exponents_shift_invert(
    model: &LinearModel,
    set: &HarmonicSet,
    jacobian: &[(usize, usize, f64)],
    omega: f64,
    settings: &ShiftInvertSettings,
) -> Result<ShiftInvertExponents, StabilityError> {
    if !harmonics_supported(set) {
        return Err(StabilityError::Harmonics(set.harmonics().to_vec()));
    }
    let n = model.n_dofs();
    let nb = set.n_blocks();
    let dim = n * nb;
    let (a2, a1) = hill_blocks(model, set, omega);
    let norm = |t: &[(usize, usize, f64)]| {
        let mut rows = vec![0.0; dim];
        for &(i, _, v) in t {
            rows[i] += v.abs();
        }
        rows.into_iter().fold(0.0, f64::max)
    };
    let (nj, n1, n2) = (norm(jacobian), norm(&a1), norm(&a2));
    let limit = settings
        .max_freq_hz
        .map_or(f64::INFINITY, |f| 2.0 * std::f64::consts::PI * f);
    let estimates: Vec<c64> = exponent_estimates(model, jacobian)?
        .into_iter()
        .filter(|e| e.im <= limit)
        .collect();
    // Targets in s = λ/ω: s = 0 first (a fold's real exponent, whatever the estimates say;
    // a little off the axis so that Q(σ) = J stays regular at the fold itself), then the
    // estimates in order of frequency.
    let mut targets: Vec<c64> = vec![c64::new(0.0, 1e-2)];
    targets.extend(estimates.iter().map(|e| e / omega));
    let explicit: Option<Vec<c64>> = settings
        .shifts
        .as_ref()
        .map(|f| f.iter().map(|&f| c64::new(0.0, f)).collect());
    let mut found: Vec<c64> = Vec::new();
    let mut content: Vec<(f64, f64)> = Vec::new();
    let (mut shifts, mut radii) = (Vec::new(), Vec::new());
    let mut rejected = 0;
    let mut covered = vec![false; targets.len()];
    let mut next = 0;
    loop {
        // The next shift: the explicit list, or the first target no disc covers yet.
        let sigma = match &explicit {
            Some(list) => match list.get(shifts.len()) {
                Some(s) => *s,
                None => break,
            },
            None => {
                while next < targets.len() && covered[next] {
                    next += 1;
                }
                if next == targets.len() {
                    break;
                }
                next += 1;
                // Just off the estimate: for a linear system the estimate is an exact
                // eigenvalue, where Q(σ) would be singular.
                let t = targets[next - 1];
                c64::new(t.re, t.im + 1e-4 * (1.0 + t.norm()))
            }
        };
        let q = complex_pencil(dim, jacobian, &a1, &a2, sigma)?;
        let lu = q
            .sp_lu()
            .map_err(|_| StabilityError::EigenSolve { size: 2 * dim })?;
        let apply = |v: &[c64]| -> Vec<c64> {
            let (x, y) = v.split_at(dim);
            // rhs = −A₂ y − (A₁ + σA₂) x
            let mut rhs = vec![c64::new(0.0, 0.0); dim];
            for &(i, j, a) in &a2 {
                rhs[i] -= (y[j] + sigma * x[j]) * a;
            }
            for &(i, j, a) in &a1 {
                rhs[i] -= x[j] * a;
            }
            let u = lu.solve(Mat::from_fn(dim, 1, |i, _| rhs[i]));
            let mut out = Vec::with_capacity(2 * dim);
            out.extend((0..dim).map(|i| u[(i, 0)]));
            out.extend((0..dim).map(|i| x[i] + sigma * u[(i, 0)]));
            out
        };
        let m = settings.krylov.max(2).min(2 * dim);
        // The space is doubled once when the nearest Ritz pairs did not converge far enough
        // to cover the shift's own target (clustered modes).
        for attempt in 0..2 {
            let m = if attempt == 0 {
                m
            } else {
                (2 * m).min(2 * dim)
            };
            let (basis, hess, beta) = arnoldi(&apply, 2 * dim, m);
            let k = hess.ncols();
            let small = Mat::from_fn(k, k, |i, j| hess[(i, j)]);
            let eig = small
                .eigen()
                .map_err(|_| StabilityError::EigenSolve { size: 2 * dim })?;
            let (vals, vecs) = (eig.S(), eig.U());
            let mut order: Vec<usize> = (0..k).filter(|&j| vals[j].norm() > 0.0).collect();
            order.sort_by(|&a, &b| vals[b].norm().total_cmp(&vals[a].norm()));
            // Walk the Ritz values from the nearest to the shift outwards while they pass the
            // residual check: the disc up to the last one holds every Hill eigenvalue found.
            let mut radius = 0.0;
            for &j in &order {
                let s = sigma + c64::new(1.0, 0.0) / vals[j];
                // Ritz vector's upper half p = V[..dim] y.
                let mut p = vec![c64::new(0.0, 0.0); dim];
                for (c, col) in basis.iter().enumerate().take(k) {
                    let yc = vecs[(c, j)];
                    for i in 0..dim {
                        p[i] += col[i] * yc;
                    }
                }
                let pn = p.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
                if !(s.re.is_finite() && s.im.is_finite()) || pn == 0.0 {
                    rejected += 1;
                    break;
                }
                // Arnoldi's residual of the Ritz pair of the shift-invert operator,
                // ‖(L − σI)⁻¹z − μz‖ = β·|y_last| / ‖y‖: converged when below tol·|μ|.
                let y_norm = (0..k).map(|c| vecs[(c, j)].norm_sqr()).sum::<f64>().sqrt();
                let ritz_residual = beta * vecs[(k - 1, j)].norm() / y_norm;
                if ritz_residual > settings.tolerance * vals[j].norm() {
                    rejected += 1;
                    break;
                }
                let mut r = vec![c64::new(0.0, 0.0); dim];
                for &(i, jj, a) in jacobian {
                    r[i] += p[jj] * a;
                }
                for &(i, jj, a) in &a1 {
                    r[i] += p[jj] * (s * a);
                }
                for &(i, jj, a) in &a2 {
                    r[i] += p[jj] * (s * s * a);
                }
                let rn = r.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
                let scale = (nj + s.norm() * n1 + s.norm_sqr() * n2) * pn;
                if rn > QUADRATIC_BACKWARD_ERROR * scale {
                    rejected += 1;
                    break;
                }
                radius = (s - sigma).norm();
                let pm = Mat::from_fn(dim, 1, |i, _| p[i]);
                let (centroid, edge) = content_profile(set, n, pm.col(0));
                if centroid.abs() > 0.5 {
                    continue;
                }
                // Exponents are kept with Im ≥ 0 (their conjugates are exponents too).
                let lambda = if s.im < 0.0 { s.conj() } else { s } * omega;
                let same = |a: &c64| (a - lambda).norm() <= 1e-8 * (lambda.norm() + omega);
                if !found.iter().any(same) {
                    found.push(lambda);
                    content.push((centroid, edge));
                }
            }
            for (t, c) in targets.iter().zip(covered.iter_mut()) {
                // A disc covers a target, or its conjugate (the spectrum is symmetric).
                *c |= (t - sigma).norm() < radius || (t.conj() - sigma).norm() < radius;
            }
            let own_covered = explicit.is_some() || covered[next - 1];
            if own_covered || attempt == 1 || m == 2 * dim {
                shifts.push(sigma);
                radii.push(radius);
                break;
            }
        }
    }
    if found.is_empty() {
        return Err(StabilityError::NoFiniteExponent);
    }
    // The dense rule on what was found: as many exponents as the estimates count (2·DOFs
    // without a frequency limit, conjugates counted), those with the most centred content.
    // Candidates beyond that count mix the 0th harmonic with others (at a stuck point the
    // initial slider state couples every harmonic into the 0th-harmonic force).
    let wanted: usize = estimates.iter().map(|e| pair_count(*e)).sum();
    let mut order: Vec<usize> = (0..found.len()).collect();
    order.sort_by(|&a, &b| content[a].0.abs().total_cmp(&content[b].0.abs()));
    let mut kept = Vec::new();
    let mut counted = 0;
    for i in order {
        if counted >= wanted {
            break;
        }
        counted += pair_count(found[i]);
        kept.push(i);
    }
    kept.sort_unstable();
    let found: Vec<c64> = kept.iter().map(|&i| found[i]).collect();
    let content: Vec<(f64, f64)> = kept.iter().map(|&i| content[i]).collect();
    let uncovered = covered.iter().filter(|c| !**c).count();
    Ok(ShiftInvertExponents {
        exponents: found,
        content,
        rejected,
        shifts,
        radii,
        estimates,
        uncovered,
        complete: uncovered == 0,
    })
}

/// How the Hill eigenvalue problem of a point is solved.
#[derive(Debug, Clone, PartialEq)]
pub enum HillSolver {
    /// The whole spectrum by the dense eigen solve ([`super::stability`]), for at most
    /// [`MAX_HILL_UNKNOWNS`] unknowns in the scenes' automatic choice.
    Dense,
    /// The exponents nearest a few shifts on the imaginary axis by the sparse shift-invert
    /// Arnoldi solve (this module).
    ShiftInvert(ShiftInvertSettings),
}

/// Whether the scene's choice `analysis.hill_solver` runs the shift-invert solve for a problem
/// of `unknowns` harmonic-balance unknowns (`auto`: above [`MAX_HILL_UNKNOWNS`]).
pub fn uses_shift_invert(choice: HillSolve, unknowns: usize) -> bool {
    match choice {
        HillSolve::Auto => unknowns > MAX_HILL_UNKNOWNS,
        HillSolve::Dense => false,
        HillSolve::ShiftInvert => true,
    }
}

/// The Hill solver of a problem with the scene's choice `analysis.hill_solver` (default
/// settings for the shift-invert solve, with the coverage limit `analysis.hill_max_freq_hz`
/// in Hz, `None` for every mode).
pub fn hill_solver_for(choice: HillSolve, unknowns: usize, max_freq_hz: Option<f64>) -> HillSolver {
    if uses_shift_invert(choice, unknowns) {
        HillSolver::ShiftInvert(ShiftInvertSettings {
            max_freq_hz,
            ..ShiftInvertSettings::default()
        })
    } else {
        HillSolver::Dense
    }
}

/// [`super::stability::point_stability`] with the Hill solver chosen by the caller. The shift-invert solve
/// takes the Jacobian's entries in the system's storage (a schur-storage system is switched to
/// sparse storage for the evaluation and back); when it did not find every exponent
/// ([`ShiftInvertExponents::complete`]) the verdict is
/// marked not reliable.
pub fn point_stability_with(
    system: &mut HbmSystem<'_>,
    x: &[f64],
    omega: f64,
    solver: &HillSolver,
) -> Result<PointStability, StabilityError> {
    let settings = match solver {
        HillSolver::Dense => return point_stability(system, x, omega),
        HillSolver::ShiftInvert(settings) => settings,
    };
    let dim = system.dim();
    let storage = system.storage();
    let switch = storage == crate::numerics::jacobian::Storage::Schur;
    if switch {
        system.set_storage(crate::numerics::jacobian::Storage::Sparse)?;
    }
    let mut jacobian = system.new_jacobian();
    let (mut r, mut dr) = (vec![0.0; dim], vec![0.0; dim]);
    let states = system.states.clone();
    let evaluated = system.residual_and_jacobian(x, omega, &mut r, &mut jacobian, &mut dr);
    let reliable = hill_reliable(system.problem(), &system.states);
    system.states = states;
    if switch {
        system.set_storage(storage)?;
    }
    evaluated?;
    let found = floquet_exponents_shift_invert(
        &system.problem().model,
        system.unknowns(),
        &jacobian.triplets(),
        omega,
        settings,
    )?;
    Ok(PointStability {
        reliable: reliable && found.complete,
        method: VerdictSource::HillSparse,
        ..verdict(&found.exponents, omega)
    })
}

/// A₂ = ω² (I ⊗ M) and A₁ = ω (I ⊗ C) + 2ω² (∇ ⊗ M) as triplets (harmonic-major blocks).
fn hill_blocks(model: &LinearModel, set: &HarmonicSet, omega: f64) -> (Triplets, Triplets) {
    let n = model.n_dofs();
    let (mass, damping) = (model.mass.triplets(), model.damping.triplets());
    let (mut a2, mut a1) = (Vec::new(), Vec::new());
    for (jb, block) in set.blocks().iter().enumerate() {
        let h = block.harmonic() as f64;
        // (∇ ⊗ M) couples a cos block's rows to its sine partner's columns and back.
        let partner = match block {
            Block::Cos(hh) => set.sin_block(*hh).map(|k| (k, h)),
            Block::Sin(hh) => set.cos_block(*hh).map(|k| (k, -h)),
            Block::Constant => None,
        };
        for &(r, c, m) in &mass {
            a2.push((jb * n + r, jb * n + c, omega * omega * m));
            if let Some((kb, sign)) = partner {
                a1.push((jb * n + r, kb * n + c, 2.0 * omega * omega * sign * m));
            }
        }
        for &(r, c, d) in &damping {
            a1.push((jb * n + r, jb * n + c, omega * d));
        }
    }
    (a2, a1)
}

/// Q(σ) = J + σA₁ + σ²A₂ as a complex sparse matrix.
fn complex_pencil(
    dim: usize,
    jacobian: &[(usize, usize, f64)],
    a1: &[(usize, usize, f64)],
    a2: &[(usize, usize, f64)],
    sigma: c64,
) -> Result<SparseColMat<usize, c64>, StabilityError> {
    let mut t: Vec<Triplet<usize, usize, c64>> =
        Vec::with_capacity(jacobian.len() + a1.len() + a2.len());
    t.extend(
        jacobian
            .iter()
            .map(|&(i, j, v)| Triplet::new(i, j, c64::new(v, 0.0))),
    );
    t.extend(a1.iter().map(|&(i, j, v)| Triplet::new(i, j, sigma * v)));
    t.extend(
        a2.iter()
            .map(|&(i, j, v)| Triplet::new(i, j, sigma * sigma * v)),
    );
    if t.iter()
        .any(|e| !(e.val.re.is_finite() && e.val.im.is_finite()))
    {
        return Err(StabilityError::NoFiniteExponent);
    }
    SparseColMat::try_new_from_triplets(dim, dim, &t)
        .map_err(|_| StabilityError::EigenSolve { size: 2 * dim })
}

/// m steps of Arnoldi on `apply` (size `size`) from a fixed start vector: the orthonormal
/// basis (m vectors, fewer on a lucky breakdown) and the square Hessenberg matrix of the
/// steps taken. Gram-Schmidt is applied twice per step.
fn arnoldi(
    apply: &dyn Fn(&[c64]) -> Vec<c64>,
    size: usize,
    m: usize,
) -> (Vec<Vec<c64>>, Mat<c64>, f64) {
    // A fixed start with every component non-zero and no structure the harmonics share.
    let mut v0: Vec<c64> = (0..size)
        .map(|i| {
            let t = i as f64;
            c64::new(1.0 + 0.5 * (0.7 * t).sin(), 0.3 * (1.3 * t).cos())
        })
        .collect();
    let nrm = v0.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
    v0.iter_mut().for_each(|v| *v /= nrm);
    let mut basis = vec![v0];
    let mut hess = Mat::<c64>::zeros(m + 1, m);
    let mut steps = m;
    let mut last_beta = 0.0;
    for j in 0..m {
        let mut w = apply(&basis[j]);
        for _pass in 0..2 {
            for (i, q) in basis.iter().enumerate() {
                let h: c64 = q.iter().zip(&w).map(|(a, b)| a.conj() * b).sum();
                hess[(i, j)] += h;
                w.iter_mut().zip(q).for_each(|(wv, qv)| *wv -= h * qv);
            }
        }
        let beta = w.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
        hess[(j + 1, j)] = c64::new(beta, 0.0);
        last_beta = beta;
        if beta <= 1e-14 * (0..=j).map(|i| hess[(i, j)].norm()).fold(0.0, f64::max) {
            steps = j + 1;
            last_beta = 0.0;
            break;
        }
        if j + 1 < m {
            w.iter_mut().for_each(|v| *v /= beta);
            basis.push(w);
        }
    }
    basis.truncate(steps);
    let h = Mat::from_fn(steps, steps, |i, j| hess[(i, j)]);
    (basis, h, last_beta)
}
