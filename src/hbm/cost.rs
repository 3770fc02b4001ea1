//! Size and cost of a problem's harmonic balance, estimated before anything is allocated: the
//! unknowns of Newton's iteration, the rows of the matrix it factorises, the memory one Newton
//! iteration holds (Jacobian storage and factorisation, the formulation's eliminated blocks,
//! the AFT buffers) and a rough time per continuation point.
//!
//! It belongs to the harmonic-balance layer because only this layer knows how each formulation
//! ([`Formulation`], chosen by [`Problem::formulation`]) stores and factorises its matrices.
//! `fricbound check` prints the estimate and `fricbound run` refuses a problem whose estimate
//! exceeds the machine's available memory, instead of aborting on an allocation later.
//!
//! Everything here is counted from the problem's sizes (DOFs, coefficient blocks, AFT samples,
//! contact points, non-zeros of the structural matrices); nothing is allocated in proportion
//! to them, so a problem that would need terabytes is estimated in microseconds.
//!
//! **Memory model** (bytes, f64 = 8, complex = 16; m = unknowns, b = unknown coefficient
//! blocks, b_f = AFT coefficient blocks (0th harmonic always included), N = samples per period,
//! n = DOFs, c = contact points, d = DOFs touched by one contact point):
//!
//! - AFT workspace (one per operator, shared by all contact points): the sampled basis and its
//!   projection (2·N·b_f values, the inverse-DFT and DFT matrices), the three derivative
//!   matrices ∂T̂/∂û, ∂T̂/∂v̂, ∂N̂/∂v̂ (3·b_f²) and about 16 sample buffers of N values;
//! - contact Jacobian blocks: d²·b² slots (index and value) per contact point (schur: one
//!   (2·b)² block of values per contact point);
//! - `dense`: the Jacobian, the bordered copy handed to the LU and its L and U factors,
//!   4·m² values;
//! - `sparse`: the Jacobian's non-zeros (b·nnz(K ∪ M) + 2·H·nnz(C) + c·d²·b², value and row
//!   index each, at most m²) and an LU factor assumed [`SPARSE_FILL`] times as large, at most
//!   m² (the fill-in depends on the ordering and is not known before the symbolic
//!   factorisation);
//! - `condensed`: dense K, M, C (3·n²), per harmonic the kept LU of the linear DOFs' block in
//!   the real 2n form and the coupling blocks (about 8·n_l² + 8·n_l·n_c + 4·n_c² values for
//!   h ≥ 1, a quarter for h = 0) plus one such block in construction, and the dense Jacobian
//!   on the m = n_c·b contact unknowns (4·m²);
//! - `schur`: dense K, M, C and their congruences (6·n²), per dynamic harmonic the complex
//!   elimination of everything but the n_q ≤ 2c relative coordinates (one per non-zero contact row; n² complex values:
//!   LU, coupling blocks and the Schur complement; n² real for h = 0), and the reduced matrix
//!   of (n_q·b)² values with its single-precision copy; twice all of the factor part, since
//!   the continuation keeps the previous factorisation while it builds the next one;
//! - `schur-lowrank`: as schur, with the reduced matrix's structured factorisation in place of
//!   its dense LU where that is cheaper: per harmonic a complex LU of n_q rows, P⁻¹U on each
//!   harmonic's rows, M and the r × r capacitance matrix, r assumed [`LOW_RANK_ROW_FRACTION`] of
//!   the reduced rows ([`low_rank_flops`]); and where the damping is of low rank
//!   ([`modal_elimination_expected`]) the elimination from the glued modes instead of the LU
//!   elimination: the modes (n_z² + 2·n_q·n_z real values, once) and per harmonic G (n_q·n_z
//!   real) and S_h (n_q² complex), 2·n_q²·n_z flops.
//!
//! **Time model** (an estimate, good to a factor of a few): per Newton iteration, the
//! factorisation's floating-point operations (dense LU (2/3)·m³; complex LU 4× a real one;
//! sparse LU 2·nnz(LU)²/m with nnz(LU) ≤ m²) at [`FACTOR_FLOPS_PER_S`], plus the scalar work (the AFT march of
//! every contact point over [`MARCH_PERIODS`] periods with its FFTs and Gram matrices, the
//! contact blocks, the assembly of the linear part) at [`SCALAR_FLOPS_PER_S`], plus
//! [`OVERHEAD_S`]; times [`ITERATIONS_PER_POINT`] iterations per continuation point, or, when
//! the corrector takes chord iterations, [`CHORD_FACTORISATIONS_PER_POINT`] factorisations and
//! [`CHORD_EVALUATIONS_PER_POINT`] evaluations per point. The rates were calibrated on the
//! 2-core development machine against measured runs of the paper scene (H = 1 to 600, dense
//! and schur), the reduced blade pair (dense) and the unreduced one (sparse); README's Outputs
//! section gives the comparison.

use crate::model::{Formulation, Problem};

/// Bytes of one f64.
const F64: f64 = 8.0;
/// Bytes of one complex f64.
const C64: f64 = 16.0;
/// Bytes of one stored index (usize).
const INDEX: f64 = 8.0;

/// Assumed ratio of the sparse LU factor's non-zeros to the Jacobian's (the fill-in). The
/// time per point of the unreduced 5 000-DOF 2D blade pair fits 4-5; the Cholesky factors of
/// the Craig-Bampton study (`reduction/README.md`, K alone) fill 6-7 times in 2D and about 16
/// times in 3D, so 3D meshes may need more than this estimate.
pub const SPARSE_FILL: f64 = 5.0;

/// Factorisation rate assumed for the time estimate (flop/s): measured runs of the paper scene
/// with 250-800 factorised rows (dense and schur) give 3.5-4.5 Gflop/s on the development
/// machine, the copies into the bordered matrix included.
pub const FACTOR_FLOPS_PER_S: f64 = 4.0e9;

/// Rate of the scalar work (AFT march, FFTs, Jacobian assembly) assumed for the time estimate
/// (flop/s, calibrated on the paper scene at H = 1 and 5, where it dominates).
pub const SCALAR_FLOPS_PER_S: f64 = 2.0e9;

/// Fixed cost of one Newton iteration (s): residual bookkeeping, small allocations.
pub const OVERHEAD_S: f64 = 5.0e-6;

/// Newton iterations per continuation point assumed for the time estimate, cut steps included
/// (the paper scene averages 2.9-3.4 converged iterations per point; chord iterations of large
/// problems make fewer factorisations).
pub const ITERATIONS_PER_POINT: f64 = 3.5;

/// Factorisations per continuation point with chord iterations (problems of at least the
/// continuation's `chord_min_unknowns` unknowns carry a factorisation over several points;
/// measured 0.2-0.25 on the paper scene with 2 400-4 800 factorised rows).
pub const CHORD_FACTORISATIONS_PER_POINT: f64 = 0.25;

/// Residual and contact-force evaluations per continuation point with chord iterations (three
/// chord steps count as one Newton iteration; the paper scene averages about 2.2 such
/// iterations per point).
pub const CHORD_EVALUATIONS_PER_POINT: f64 = 7.0;

/// Periods of the AFT march assumed per evaluation (the march repeats until the slider state
/// repeats, usually after the second period).
pub const MARCH_PERIODS: f64 = 2.0;

/// Unknowns of Newton's iteration on `p`: all DOFs per coefficient block, or the contact DOFs
/// per block for the condensed formulation.
pub fn unknowns(p: &Problem) -> usize {
    unknowns_for(p, p.formulation())
}

/// [`unknowns`] of `p` solved in `formulation`.
pub fn unknowns_for(p: &Problem, formulation: Formulation) -> usize {
    let blocks = p.unknown_harmonics().n_blocks();
    match formulation {
        Formulation::Condensed => p.contact_dofs().len() * blocks,
        _ => p.model.n_dofs() * blocks,
    }
}

/// Rows of the matrix factorised per Newton iteration on `p`: the unknowns, except for the
/// schur formulation (2 relative coordinates per contact point, 3 per 2D-friction point, 1
/// fewer where a direction is zero, and coefficient block) (the schur-lowrank formulation
/// factorises the same reduced matrix, by structure where that is cheaper).
pub fn factored_size(p: &Problem) -> usize {
    factored_size_for(p, p.formulation())
}

/// [`factored_size`] of `p` solved in `formulation`.
pub fn factored_size_for(p: &Problem, formulation: Formulation) -> usize {
    match formulation {
        Formulation::Schur | Formulation::SchurLowRank => {
            p.relative_coordinate_count() * p.unknown_harmonics().n_blocks()
        }
        _ => unknowns_for(p, formulation),
    }
}

/// Name of a formulation as written in scenes (`analysis.formulation`).
pub fn formulation_name(f: Formulation) -> &'static str {
    match f {
        Formulation::Auto => "auto",
        Formulation::Dense => "dense",
        Formulation::Sparse => "sparse",
        Formulation::Condensed => "condensed",
        Formulation::Schur => "schur",
        Formulation::SchurLowRank => "schur-lowrank",
    }
}

/// The formulation written `name` in scenes ([`formulation_name`]), if any.
pub fn formulation_from_name(name: &str) -> Option<Formulation> {
    [
        Formulation::Auto,
        Formulation::Dense,
        Formulation::Sparse,
        Formulation::Condensed,
        Formulation::Schur,
        Formulation::SchurLowRank,
    ]
    .into_iter()
    .find(|&f| formulation_name(f) == name)
}

/// The linear solver of a formulation, as `fricbound check` and the benches name it.
pub fn linear_solver_name(f: Formulation) -> &'static str {
    match f {
        Formulation::Auto | Formulation::Dense | Formulation::Condensed => "dense LU",
        Formulation::Sparse => "sparse LU",
        Formulation::Schur => "dense LU on the relative coordinates",
        Formulation::SchurLowRank => {
            "per-harmonic LU + low-rank update of the slipping contacts (dense LU where cheaper)"
        }
    }
}

/// The linear solver of a formulation on problem `p`: [`linear_solver_name`], and for
/// schur-lowrank how the rest of the model is eliminated per harmonic (from the glued
/// structure's modes, or by LU where the damping is not of low rank,
/// [`modal_elimination_expected`]).
pub fn linear_solver_description(p: &Problem, f: Formulation) -> String {
    let name = linear_solver_name(f);
    if f != Formulation::SchurLowRank {
        return name.to_string();
    }
    if modal_elimination_expected(p) {
        format!("{name}; other coordinates eliminated from the glued structure's modes")
    } else {
        format!(
            "{name}; other coordinates eliminated by LU per harmonic (the damping is not of low \
             rank)"
        )
    }
}

/// The estimated size and cost of one problem's harmonic balance (see the module docs for the
/// model behind each number).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CostEstimate {
    /// The formulation solved (the scene's choice, or what `auto` picks).
    pub formulation: Formulation,
    /// DOFs of the model.
    pub dofs: usize,
    /// Unknown coefficient blocks (0th harmonic when coupled, cos and sin per harmonic).
    pub blocks: usize,
    /// Coefficient blocks of the AFT (the 0th harmonic always included).
    pub force_blocks: usize,
    /// AFT samples per period.
    pub samples: usize,
    /// Contact points.
    pub contacts: usize,
    /// Unknowns of Newton's iteration ([`unknowns`]).
    pub unknowns: usize,
    /// Rows of the matrix factorised per Newton iteration ([`factored_size`]).
    pub factored: usize,
    /// Jacobian storage and its factorisation, with the formulation's eliminated blocks and
    /// dense structural matrices (bytes).
    pub solver_bytes: f64,
    /// AFT workspace: sampled basis and projection, derivative matrices, sample buffers
    /// (bytes).
    pub aft_bytes: f64,
    /// Contact Jacobian blocks and their slots in the Jacobian (bytes).
    pub contact_bytes: f64,
    /// Floating-point operations of the factorisation per Newton iteration.
    pub factor_flops: f64,
    /// Floating-point operations of the rest of a Newton iteration or chord step (AFT, contact
    /// blocks, assembly of the linear part, one solve with the factors).
    pub scalar_flops: f64,
    /// Whether the corrector takes chord iterations (at least the continuation's
    /// `chord_min_unknowns` unknowns): factorisations are then carried over points.
    pub chord: bool,
}

impl CostEstimate {
    /// Memory of one Newton iteration (bytes): solver, AFT and contact blocks.
    pub fn bytes(&self) -> f64 {
        self.solver_bytes + self.aft_bytes + self.contact_bytes
    }

    /// Estimated time of one factorisation (s).
    pub fn seconds_per_factorisation(&self) -> f64 {
        self.factor_flops / FACTOR_FLOPS_PER_S
    }

    /// Estimated time of one evaluation without factorisation (s): residual, contact forces
    /// and their Jacobian, one solve.
    pub fn seconds_per_evaluation(&self) -> f64 {
        self.scalar_flops / SCALAR_FLOPS_PER_S + OVERHEAD_S
    }

    /// Factorisations and evaluations per continuation point: [`ITERATIONS_PER_POINT`] of each,
    /// or with chord iterations [`CHORD_FACTORISATIONS_PER_POINT`] and
    /// [`CHORD_EVALUATIONS_PER_POINT`].
    pub fn per_point(&self) -> (f64, f64) {
        if self.chord {
            (CHORD_FACTORISATIONS_PER_POINT, CHORD_EVALUATIONS_PER_POINT)
        } else {
            (ITERATIONS_PER_POINT, ITERATIONS_PER_POINT)
        }
    }

    /// Estimated time of one Newton iteration with a factorisation (s).
    pub fn seconds_per_iteration(&self) -> f64 {
        self.seconds_per_factorisation() + self.seconds_per_evaluation()
    }

    /// Estimated time of one continuation point (s), see [`Self::per_point`].
    pub fn seconds_per_point(&self) -> f64 {
        let (factorisations, evaluations) = self.per_point();
        factorisations * self.seconds_per_factorisation()
            + evaluations * self.seconds_per_evaluation()
    }

    /// One line for `fricbound check`: "memory per Newton iteration ≈ … MiB (…), time per
    /// point ≈ … (estimate: … factorisations of …, … evaluations of …)".
    pub fn summary(&self) -> String {
        let (factorisations, evaluations) = self.per_point();
        format!(
            "memory per Newton iteration ≈ {} (solver {}, AFT {}, contact blocks {}), \
             time per point ≈ {} (estimate: {factorisations} factorisations of {}, \
             {evaluations} evaluations of {})",
            format_bytes(self.bytes()),
            format_bytes(self.solver_bytes),
            format_bytes(self.aft_bytes),
            format_bytes(self.contact_bytes),
            format_seconds(self.seconds_per_point()),
            format_seconds(self.seconds_per_factorisation()),
            format_seconds(self.seconds_per_evaluation()),
        )
    }
}

/// Estimates the size and cost of `p`'s harmonic balance without allocating in proportion to
/// it (see the module docs for the model).
pub fn estimate(p: &Problem) -> CostEstimate {
    estimate_for(p, p.formulation())
}

/// [`estimate`] of `p` solved in `formulation` (what `auto` compares, see
/// `Problem::formulation`).
pub fn estimate_for(p: &Problem, formulation: Formulation) -> CostEstimate {
    let n = p.model.n_dofs() as f64;
    let set = p.unknown_harmonics();
    let b = set.n_blocks() as f64;
    let force_blocks = p.force_harmonics().n_blocks();
    let bf = force_blocks as f64;
    let samples = p.samples as f64;
    let c = p.contacts.len() as f64;
    // Dynamic harmonics (h ≥ 1) of the unknowns, and whether the 0th is among them.
    let dynamic = set.harmonics().iter().filter(|&&h| h > 0).count() as f64;
    let has_static = set.constant_block().is_some();
    let unknowns = unknowns_for(p, formulation);
    let factored = factored_size_for(p, formulation);
    let m = unknowns as f64;

    // AFT: basis and projection, derivative matrices, sample buffers.
    let aft_bytes = F64 * (2.0 * samples * bf + 3.0 * bf * bf + 16.0 * samples);
    // Contact blocks: d² b² slots and values per contact point.
    let d2: f64 = p
        .contacts
        .iter()
        .map(|cp| {
            let mut dofs: Vec<usize> = cp.row_entries().map(|&(d, _)| d).collect();
            dofs.sort_unstable();
            dofs.dedup();
            (dofs.len() * dofs.len()) as f64
        })
        .sum();
    let contact_bytes = match formulation {
        // The schur Jacobian keeps each contact's (k·b)² block on its k relative coordinates
        // (k = 2, or 3 for a 2D-friction point).
        Formulation::Schur | Formulation::SchurLowRank => {
            let k2: f64 = p
                .contacts
                .iter()
                .map(|cp| cp.rows().count().pow(2) as f64)
                .sum();
            F64 * k2 * b * b
        }
        _ => (F64 + INDEX) * d2 * b * b,
    };

    let log2 = |x: f64| x.max(2.0).log2();
    // The march (synthesis by inverse FFT, the law per sample, forward FFT) over a few
    // periods per contact point, the Gram matrices of the analytic Jacobian (3 FFTs and b_f²
    // reads each), and scattering the contact blocks into the Jacobian.
    let aft_flops = c
        * (MARCH_PERIODS * (10.0 * samples * log2(samples) + 20.0 * samples)
            + 3.0 * (5.0 * samples * log2(samples) + bf * bf))
        + d2 * b * b;

    // Per formulation: memory, factorisation flops, and the flops of assembling the linear
    // part and of one solve with the factors (each evaluation makes one).
    let (solver_bytes, factor_flops, assembly_flops) = match formulation {
        Formulation::Sparse => {
            let nnz_km = p.model.stiffness.nnz().max(p.model.mass.nnz()) as f64;
            let nnz_c = p.model.damping.nnz() as f64;
            // The pattern's blocks overlap where contacts touch DOFs the structure couples,
            // and neither the matrix nor its LU factors can hold more than the m² entries of a
            // dense one: without this bound a model whose DOFs are all coupled (the paper's 6
            // DOFs) was estimated at up to 50 times the measured factorisation (H = 15).
            let nnz = (b * nnz_km + 2.0 * dynamic * nnz_c + d2 * b * b).min(m * m);
            let factor_nnz = (SPARSE_FILL * nnz).min(m * m);
            (
                (F64 + INDEX) * (nnz + factor_nnz),
                2.0 * factor_nnz * factor_nnz / m.max(1.0),
                4.0 * nnz + 2.0 * factor_nnz,
            )
        }
        Formulation::Condensed => {
            let n_c = p.contact_dofs().len() as f64;
            let n_l = n - n_c;
            let per_dynamic = 8.0 * n_l * n_l + 8.0 * n_l * n_c + 4.0 * n_c * n_c;
            let kept = dynamic * per_dynamic + if has_static { per_dynamic / 4.0 } else { 0.0 };
            let bytes = F64 * (3.0 * n * n + kept + per_dynamic + 4.0 * m * m);
            // Per iteration (ω moves in arc-length continuation): per harmonic the LU of the
            // real 2n_l block, the solves for A_ll⁻¹ A_lc and the Schur product; then the
            // dense LU on the contact unknowns.
            let per_harmonic = |k: f64| {
                let (l, cc) = (k * n_l, k * n_c);
                2.0 / 3.0 * l * l * l + 2.0 * l * l * cc + 2.0 * cc * cc * l
            };
            let flops = dynamic * per_harmonic(2.0)
                + if has_static { per_harmonic(1.0) } else { 0.0 }
                + 2.0 / 3.0 * m * m * m;
            (bytes, flops, 4.0 * m * m)
        }
        Formulation::Schur | Formulation::SchurLowRank => {
            let q = factored as f64;
            let low_rank = formulation == Formulation::SchurLowRank;
            let (bytes, flops) = schur_cost(p, (n, q), (dynamic, has_static), low_rank);
            // The residual: a dense product per block with K, M, C; a solve: the reduced
            // factors and the eliminated blocks of every harmonic.
            (
                bytes,
                flops,
                6.0 * n * n * b + 2.0 * q * q + 8.0 * dynamic * n * n,
            )
        }
        Formulation::Dense | Formulation::Auto => {
            (F64 * 4.0 * m * m, 2.0 / 3.0 * m * m * m, 4.0 * m * m)
        }
    };
    CostEstimate {
        formulation,
        dofs: p.model.n_dofs(),
        blocks: set.n_blocks(),
        force_blocks,
        samples: p.samples,
        contacts: p.contacts.len(),
        unknowns,
        factored,
        solver_bytes,
        aft_bytes,
        contact_bytes,
        factor_flops,
        scalar_flops: aft_flops + assembly_flops,
        chord: unknowns >= p.analysis.continuation.chord_min_unknowns,
    }
}

/// Fraction of the reduced rows (n_q·blocks) that the schur-lowrank formulation's update is
/// assumed to hold for its estimates: the rows of the contacts that slip or lift off, and the
/// constant-harmonic rows of those stuck with their initial condition. Measured: 0.36 on average
/// over a limit curve of the reduced blade pair with 49 pairs per side at H = 3 (39 % of its
/// contacts slipping), `fricbound bench contacts`.
pub const LOW_RANK_ROW_FRACTION: f64 = 0.4;

/// Memory and factorisation flops of the schur and schur-lowrank formulations on `p` (n DOFs,
/// n_q relative coordinates, q = n_q·b reduced rows; `dynamic` harmonics h ≥ 1 and the 0th
/// when `has_static`): per harmonic the complex elimination of the n_z = n − n_q other
/// coordinates, then the dense LU of the reduced matrix (schur), or for schur-lowrank whichever
/// of it and the structured factorisation with [`LOW_RANK_ROW_FRACTION`]·q update rows
/// ([`low_rank_flops`]) is cheaper, as the formulation chooses.
fn schur_cost(
    p: &Problem,
    (n, q): (f64, f64),
    (dynamic, has_static): (f64, bool),
    low_rank: bool,
) -> (f64, f64) {
    let n_q = p.relative_coordinate_count() as f64;
    let n_z = (n - n_q).max(0.0);
    let modal = low_rank && modal_elimination_expected(p);
    let (per_harmonic, elimination) = if modal {
        // Per harmonic G (n_q·n_z real) and S_h (n_q² complex), S₀ = A₀_qq − G Δ⁻¹ Gᵀ in
        // 2·n_q²·n_z real flops; the modes, once per system, are not counted per factorisation.
        let per = C64 * n_q * n_q + F64 * n_q * n_z;
        let harmonics = dynamic + if has_static { 1.0 } else { 0.0 };
        (harmonics * per, harmonics * 2.0 * n_q * n_q * n_z)
    } else {
        let real = 2.0 / 3.0 * n_z * n_z * n_z + 2.0 * n_z * n_z * n_q + 2.0 * n_q * n_q * n_z;
        (
            dynamic * C64 * n * n + if has_static { F64 * n * n } else { 0.0 },
            dynamic * 4.0 * real + if has_static { real } else { 0.0 },
        )
    };
    // The modes Φ and K_qzΦ, M_qzΦ, kept once.
    let modes = if modal {
        F64 * (n_z * n_z + 2.0 * n_q * n_z)
    } else {
        0.0
    };
    let dense_flops = 2.0 / 3.0 * q * q * q;
    let dense_bytes = (F64 + 4.0) * q * q;
    let harmonics = dynamic as usize + usize::from(has_static);
    let r = (LOW_RANK_ROW_FRACTION * q).round();
    let structured = low_rank_flops(n_q as usize, harmonics, r as usize);
    let (reduced_bytes, reduced_flops) = if low_rank && structured < dense_flops {
        // Per harmonic LU (complex n_q²), P⁻¹U on its harmonic's 2·n_q rows, M and C.
        let bytes = C64 * harmonics as f64 * n_q * n_q + F64 * (2.0 * n_q * r + q * r + r * r);
        (bytes, structured)
    } else {
        (dense_bytes, dense_flops)
    };
    (
        F64 * 6.0 * n * n + modes + 2.0 * (per_harmonic + reduced_bytes),
        elimination + reduced_flops,
    )
}

/// Whether the schur-lowrank formulation is expected to eliminate the harmonics from the glued
/// structure's modes ([`crate::hbm::schur::modal`]): when the DOFs that the damping matrix
/// touches (a bound on its rank) are at most
/// [`MAX_DAMPING_RANK_FRACTION`](crate::hbm::schur::modal::MAX_DAMPING_RANK_FRACTION) of the
/// relative coordinates. The other conditions (symmetric matrices, M_zz positive definite) hold
/// for structural models and are checked when the modes are computed.
pub fn modal_elimination_expected(p: &Problem) -> bool {
    let mut touched = vec![false; p.model.n_dofs()];
    p.model.damping.for_each_nonzero(|i, j, v| {
        if v != 0.0 {
            touched[i] = true;
            touched[j] = true;
        }
    });
    let rank_bound = touched.iter().filter(|&&t| t).count() as f64;
    rank_bound
        <= crate::hbm::schur::modal::MAX_DAMPING_RANK_FRACTION
            * p.relative_coordinate_count() as f64
}

/// Estimated flops of the schur-lowrank factorisation of the reduced matrix
/// ([`crate::hbm::schur::lowrank`]) with n_q relative coordinates, `harmonics` harmonics and `r`
/// update rows, against the dense LU's (2/3)·(n_q·blocks)³: per harmonic the LU of n_q complex
/// rows (4× a real LU), P⁻¹U (8·n_q² per complex column) and the LU of the r × r capacitance
/// matrix.
pub fn low_rank_flops(n_q: usize, harmonics: usize, r: usize) -> f64 {
    let (n_q, r) = (n_q as f64, r as f64);
    harmonics as f64 * 8.0 / 3.0 * n_q.powi(3) + 8.0 * n_q * n_q * r + 2.0 / 3.0 * r.powi(3)
}

/// Bytes as MiB (or GiB from 10 GiB), e.g. "1.3 MiB", "51.2 GiB".
pub fn format_bytes(bytes: f64) -> String {
    const MIB: f64 = 1024.0 * 1024.0;
    let mib = bytes / MIB;
    if mib >= 10.0 * 1024.0 {
        format!("{:.1} GiB", mib / 1024.0)
    } else if mib >= 10.0 {
        format!("{mib:.0} MiB")
    } else {
        format!("{mib:.2} MiB")
    }
}

/// Seconds in a readable unit: "0.12 ms", "3.4 s", "2.1 h".
pub fn format_seconds(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.3} ms", s * 1e3)
    } else if s < 1.0 {
        format!("{:.1} ms", s * 1e3)
    } else if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// Where the available memory was read, for messages.
pub const MEMINFO: &str = "/proc/meminfo";

/// The memory available to a new process (bytes): `MemAvailable` of `/proc/meminfo`, lowered
/// to the room left under the cgroup's limit (`/sys/fs/cgroup/memory.max` minus
/// `memory.current`) when the process runs in a limited cgroup (a container). `None` when
/// `/proc/meminfo` cannot be read or has no `MemAvailable` line (not Linux): the caller then
/// skips the refusal.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string(MEMINFO).ok()?;
    let available = parse_mem_available(&meminfo)?;
    let read = |f: &str| -> Option<u64> {
        std::fs::read_to_string(std::path::Path::new("/sys/fs/cgroup").join(f))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let cgroup_room =
        read("memory.max").map(|max| max.saturating_sub(read("memory.current").unwrap_or(0)));
    Some(cgroup_room.map_or(available, |room| room.min(available)))
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes (the file gives kB).
pub fn parse_mem_available(meminfo: &str) -> Option<u64> {
    meminfo.lines().find_map(|line| {
        let rest = line.strip_prefix("MemAvailable:")?;
        let mut parts = rest.split_whitespace();
        let value: u64 = parts.next()?.parse().ok()?;
        match parts.next() {
            Some("kB") | None => Some(value * 1024),
            Some(_) => None,
        }
    })
}

/// A problem refused before anything proportional to it is allocated: its estimated memory
/// exceeds what the machine has available ([`check_memory`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{reason}")]
pub struct TooLarge {
    /// The estimate, the memory available and the fields to lower ([`memory_refusal`]).
    pub reason: String,
}

/// Refuses a problem whose estimated memory, one Newton iteration ([`estimate`]) times the
/// solves that run at the same time, exceeds the memory available ([`available_memory`]);
/// nothing is allocated in proportion to the problem before this check. When the available
/// memory cannot be read the check is skipped.
pub fn check_memory(problem: &Problem, parallel: usize) -> Result<(), TooLarge> {
    let Some(available) = available_memory() else {
        return Ok(());
    };
    let cost = estimate(problem);
    match memory_refusal(problem, &cost, parallel, available as f64) {
        Some(reason) => Err(TooLarge { reason }),
        None => Ok(()),
    }
}

/// Why a problem of estimate `cost`, solved `parallel` times at once, does not fit in
/// `available` bytes; `None` when it fits. Names the fields to lower.
pub fn memory_refusal(
    problem: &Problem,
    cost: &CostEstimate,
    parallel: usize,
    available: f64,
) -> Option<String> {
    let needed = cost.bytes() * parallel.max(1) as f64;
    if needed <= available {
        return None;
    }
    let max_h = problem.harmonics.iter().copied().max().unwrap_or(0);
    Some(format!(
        "refused: one Newton iteration is estimated to need {}{} ({} formulation: {} unknowns, \
         factorised matrix of {} rows; AFT {} samples x {} coefficient blocks), more than the {} \
         available ({MEMINFO}); lower harmonics.max (highest harmonic {max_h}, {} blocks), \
         harmonics.samples ({}) or the model size ({} DOFs, {} contact points: coarser mesh, \
         [reduction], fewer contact pairs){}{}",
        format_bytes(needed),
        if parallel > 1 {
            format!(" for {parallel} curves solved at once")
        } else {
            String::new()
        },
        formulation_name(cost.formulation),
        cost.unknowns,
        cost.factored,
        cost.samples,
        cost.force_blocks,
        format_bytes(available),
        cost.blocks,
        cost.samples,
        cost.dofs,
        cost.contacts,
        if parallel > 1 {
            ", or the curves solved at once (RAYON_NUM_THREADS)"
        } else {
            ""
        },
        if cost.formulation == Formulation::Condensed && problem.model.stiffness.is_sparse() {
            ", or change analysis.formulation: `condensed` holds K, M and C of the whole model \
             dense, `sparse` (or `auto`) keeps them sparse"
        } else {
            ""
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_mem_available() {
        let text = "MemTotal:       24585944 kB\nMemFree:         1000000 kB\n\
                    MemAvailable:   20000000 kB\nBuffers:          100 kB\n";
        assert_eq!(parse_mem_available(text), Some(20_000_000 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 1 kB\n"), None);
        assert_eq!(parse_mem_available("MemAvailable: lots\n"), None);
    }

    /// The refusal compares the estimate (times the solves at once) with the memory given and
    /// names the fields to lower.
    #[test]
    fn refuses_what_does_not_fit() {
        let problem = crate::scene::parse(crate::scene::PAPER_DEFAULT_SCENE, "paper", &[])
            .and_then(|s| s.validate("paper"))
            .unwrap();
        let cost = estimate(&problem);
        assert!(memory_refusal(&problem, &cost, 1, 2.0 * cost.bytes()).is_none());
        let why = memory_refusal(&problem, &cost, 1, 0.5 * cost.bytes()).unwrap();
        for field in [
            "harmonics.max",
            "harmonics.samples",
            "model size",
            "dense formulation",
        ] {
            assert!(why.contains(field), "{field}: {why}");
        }
        // Four curves at once need four times the memory.
        assert!(memory_refusal(&problem, &cost, 4, 2.0 * cost.bytes())
            .unwrap()
            .contains("RAYON_NUM_THREADS"));
        assert!(!why.contains("analysis.formulation"), "{why}");
    }

    /// A sparse FE model asked to run `condensed` (which holds K, M and C dense: the 18 574-DOF
    /// blade pair needs 54 GiB) is also told that another formulation keeps them sparse.
    #[test]
    fn a_condensed_fe_model_is_pointed_to_a_sparse_formulation() {
        let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("meshes/blade-pair/blade-pair-2d.toml");
        let overrides = [
            "reduction=".to_string(),
            "analysis.formulation=condensed".to_string(),
        ];
        let (_, problem) = crate::scene::load_problem(&scene, &overrides).unwrap();
        let cost = estimate(&problem);
        let why = memory_refusal(&problem, &cost, 1, 0.5 * cost.bytes()).unwrap();
        assert!(why.contains("analysis.formulation"), "{why}");
    }
    use crate::contact::harmonic::SampleBasis;
    use crate::hbm::operator::HbmOperator;
    use crate::numerics::ParametricResidual;

    fn paper(overrides: &[&str]) -> Problem {
        let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        crate::scene::parse(crate::scene::PAPER_DEFAULT_SCENE, "paper", &o)
            .and_then(|s| s.validate("paper"))
            .expect("valid scene")
    }

    /// The counts agree with the operator actually built, and the AFT part with the sampled
    /// basis the AFT allocates.
    #[test]
    fn counts_match_the_operator_and_the_aft() {
        for overrides in [
            &["harmonics.max=1"][..],
            &["harmonics.max=5"][..],
            &["harmonics.max=5", "analysis.formulation=condensed"][..],
            &["harmonics.max=5", "analysis.formulation=schur"][..],
            &["harmonics.max=5", "analysis.formulation=sparse"][..],
        ] {
            let p = paper(overrides);
            let c = estimate(&p);
            let op = HbmOperator::new(&p).expect("operator");
            assert_eq!(c.unknowns, op.dim(), "{overrides:?}");
            let basis = SampleBasis::new(&p.force_harmonics(), p.samples);
            let basis_bytes = 8.0 * (basis.synthesis.len() + basis.projection.len()) as f64;
            assert!(c.aft_bytes >= basis_bytes, "{overrides:?}");
            assert!(c.aft_bytes < 2.0 * basis_bytes + 1e6, "{overrides:?}");
            assert!(c.bytes() > 0.0 && c.seconds_per_point() > 0.0);
        }
    }

    /// The default scene: a dense Jacobian of 18 unknowns, 4·18² values for the solver.
    #[test]
    fn dense_default_scene() {
        let c = estimate(&paper(&[]));
        assert_eq!(c.formulation, Formulation::Dense);
        assert_eq!((c.unknowns, c.factored, c.blocks), (18, 18, 3));
        assert_eq!(c.solver_bytes, 8.0 * 4.0 * 18.0 * 18.0);
        assert!(!c.chord);
        // About a tenth to a few tenths of a millisecond per point on a current machine.
        assert!((1e-5..1e-2).contains(&c.seconds_per_point()), "{c:?}");
    }

    /// The case is estimated in microseconds (nothing is allocated in proportion to
    /// it) and at tens of gigabytes: the schur matrix of 80 004 rows alone holds 51 GB.
    #[test]
    fn huge_harmonic_count_is_estimated_without_allocating() {
        let p = paper(&["harmonics.max=10000", "harmonics.samples=32768"]);
        let started = std::time::Instant::now();
        let c = estimate(&p);
        assert!(started.elapsed().as_secs_f64() < 0.5);
        assert_eq!(c.formulation, Formulation::Schur);
        assert_eq!(
            (c.unknowns, c.factored, c.force_blocks),
            (120_006, 80_004, 20_001)
        );
        assert!(c.solver_bytes > 8.0 * 80_004.0 * 80_004.0);
        assert!(c.aft_bytes > 2.0 * 8.0 * 32768.0 * 20_001.0);
        assert!(c.chord);
        assert!(c.summary().contains("GiB"), "{}", c.summary());
    }

    /// More harmonics cost more memory and time.
    #[test]
    fn cost_grows_with_the_harmonics() {
        let small = estimate(&paper(&["harmonics.max=5"]));
        let large = estimate(&paper(&["harmonics.max=50", "harmonics.samples=1024"]));
        assert!(large.bytes() > small.bytes());
        assert!(large.seconds_per_point() > small.seconds_per_point());
    }

    #[test]
    fn formats() {
        assert_eq!(format_bytes(1.5 * 1024.0 * 1024.0), "1.50 MiB");
        assert_eq!(format_bytes(300.0 * 1024.0 * 1024.0), "300 MiB");
        assert_eq!(format_bytes(51.0 * 1024.0 * 1024.0 * 1024.0), "51.0 GiB");
        assert_eq!(format_seconds(2.5e-4), "0.250 ms");
        assert_eq!(format_seconds(0.0123), "12.3 ms");
        assert_eq!(format_seconds(3.45), "3.5 s");
        assert_eq!(format_seconds(600.0), "10 min");
        assert_eq!(format_seconds(36_000.0), "10.0 h");
    }
}
