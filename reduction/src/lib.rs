//! # fricbound-reduction: Craig-Bampton reduction of large sparse FE models
//!
//! The nonlinear (harmonic balance) solver of fricbound works on a few
//! hundred coordinates; FE models of blades and dampers have 10⁴–10⁶ DOFs.
//! This crate condenses a sparse symmetric model `(K, M)` (SI units: N/m,
//! kg; eigenvalues in rad²/s², frequencies in Hz) onto a chosen set of
//! boundary DOFs `B` (contact, excitation and response DOFs) plus the lowest
//! fixed-interface modes of the interior `I`:
//!
//! ```text
//! u = [u_B; u_I] ≈ T q,   T = [ I   0 ],   q = [u_B; η]
//!                             [ Ψ   Φ ]
//! Ψ = −K_II⁻¹ K_IB                       (static constraint modes)
//! K_II Φ = M_II Φ Λ,  Φᵀ M_II Φ = I      (fixed-interface modes, lowest n_modes)
//! K_r = Tᵀ K T = [ K_BB + K_BI Ψ   0 ]
//!                [ 0               Λ ]
//! M_r = Tᵀ M T = [ M_BB + M_BI Ψ + Ψᵀ M_IB + Ψᵀ M_II Ψ   (M_BI + Ψᵀ M_II) Φ ]
//!                [ sym                                    I                  ]
//! ```
//!
//! What is computed and why:
//!
//! * **Validation** ([`ReductionError`]): shapes, finite values, symmetry of
//!   both matrices (both triangles stored), boundary/recovery indices in
//!   range, boundary without repeats. No panic on user data.
//! * **Factorisation of `K_II`**: faer's low-level supernodal sparse
//!   Cholesky (symbolic once, numeric once) with a METIS nested-dissection
//!   ordering ([`Ordering::Metis`], through `metis-sys`, which vendors METIS
//!   and builds it with gcc) or AMD. Cholesky, not LU: `K_II` is SPD and LU
//!   is several times slower. A non-positive or round-off-sized pivot
//!   (`L_jj² / K_jj < 1e-11`) is reported with the interior and full index:
//!   usually a body held by no boundary DOF. `K` itself may be singular
//!   (the damper is free and held only through its contact DOFs).
//! * **Fixed-interface modes**: shift-invert block Lanczos in the
//!   M-inner product with full re-orthogonalisation and thick restarts,
//!   written by hand in [`eigen`] (see there); a few more modes than asked
//!   are computed, and a repeated eigenvalue cut by `n_modes` is kept whole.
//!   Residuals `‖Kφ − λMφ‖/‖Kφ‖` are checked.
//! * **Sturm check** ([`CbOptions::sturm_check`], on by default): the
//!   inertia of `K_II − σ M_II` (σ between the last kept and the next
//!   fixed-interface eigenvalue, from a supernodal `LDLᵀ`) must count the
//!   kept modes; a larger count means a missed mode
//!   ([`ReductionError::MissedEigenvalues`]). One more numeric factorisation.
//! * **Constraint modes, block by block**: Ψ is never held whole (for 10⁶
//!   DOFs and 400 boundary DOFs it would be 3.2 GB): `block_size` columns
//!   are solved at a time and folded into `K_r`, `M_r`. The term `Ψᵀ M_II Ψ`
//!   couples every block with every other; it is obtained from
//!   `Ψ_bᵀ M_II Ψ_a = −K_BI,b (K_II⁻¹ M_II Ψ_a)`, one extra solve per block
//!   and no second copy of Ψ. Rows of `T` are kept only for the DOFs in
//!   `recover` ([`RecoveryRow`]).
//! * **Modal damping** ([`ReducedModel::modal_damping`]): `2ζωᵢ` on the
//!   modal diagonal, zero on the boundary coordinates.
//! * **Report** ([`ReductionReport`]): sizes, cut-off frequency, factor size,
//!   ordering, seconds per phase, peak memory (VmHWM).
//!
//! Statics are exact: with loads on boundary DOFs only, `K_r q = f` gives
//! `η = 0`, `u_B` and `u_I = Ψ u_B` equal to the full static solution.
//!
//! Results do not depend on the number of threads beyond round-off: faer
//! runs sequentially (`Par::Seq`), only whole constraint-mode blocks run in
//! parallel ([`CbOptions::threads`]), each written to its own columns, and
//! the factor and block vectors live in 64-byte aligned buffers. (Last-bit
//! differences between runs were still seen inside faer's kernels; where
//! fixed-interface eigenvalues are repeated, the modal basis inside the
//! eigenspace is arbitrary anyway.)

mod block;
mod cb;
mod constraint;
mod csc;
pub mod eigen;
mod error;
mod factor;
mod ordering;
mod report;
pub mod testmodels;

pub use cb::{craig_bampton, CbOptions, RecoveryRow, ReducedModel};
pub use eigen::{dense_generalized_eigenvalues, Eigen, LanczosOptions};
pub use error::ReductionError;
pub use ordering::Ordering;
pub use report::{peak_memory_bytes, process_cpu_seconds, CpuPhases, ReductionReport};

use faer::sparse::SparseColMatRef;
use faer::Par;

/// The `n` lowest eigenpairs of the full model `K φ = λ M φ` by shift-invert
/// block Lanczos with the shift `shift` (σ): `K − σM` must be positive
/// definite, i.e. σ below the lowest eigenvalue. For a model with free
/// bodies (singular K) use a negative shift, e.g. `−(2π·1 Hz)²`.
/// METIS ordering and default Lanczos settings.
pub fn lowest_eigenpairs(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    n: usize,
    shift: f64,
) -> Result<Eigen, ReductionError> {
    lowest_eigenpairs_with(k, m, n, shift, Ordering::Metis, &LanczosOptions::default())
}

/// Sturm-sequence count of the full model: how many eigenvalues of `K φ = λ M φ` lie below
/// `sigma` (rad²/s²), from the negative pivots of an `L D Lᵀ` factorisation of `K − σM`
/// (Sylvester's law of inertia). It checks that an eigen solve missed no mode below `sigma`.
/// `None` when a zero pivot occurred (σ on an eigenvalue: move it).
pub fn count_eigenvalues_below(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    sigma: f64,
    ordering: Ordering,
) -> Result<Option<usize>, ReductionError> {
    if !sigma.is_finite() {
        return Err(ReductionError::InvalidArgument(format!(
            "shift {sigma} is not finite"
        )));
    }
    let size = k.nrows();
    let kl = csc::lower(&csc::canonical_symmetric(k, "K", size)?);
    let ml = csc::lower(&csc::canonical_symmetric(m, "M", size)?);
    let a = csc::add_scaled(&kl, &ml, -sigma);
    drop((kl, ml));
    let (_, inv, _) = factor::fill_reducing_order(&a, ordering)?;
    let count = factor::negative_pivots(&a.permute_sym_lower(&inv));
    block::release_scratch();
    count
}

/// [`lowest_eigenpairs`] with a chosen ordering and Lanczos settings.
pub fn lowest_eigenpairs_with(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    n: usize,
    shift: f64,
    ordering: Ordering,
    options: &LanczosOptions,
) -> Result<Eigen, ReductionError> {
    if !shift.is_finite() {
        return Err(ReductionError::InvalidArgument(format!(
            "shift {shift} is not finite"
        )));
    }
    if options.block == 0 {
        return Err(ReductionError::InvalidArgument(
            "the Lanczos block size must be at least 1".into(),
        ));
    }
    let size = k.nrows();
    let kc = csc::canonical_symmetric(k, "K", size)?;
    let mc = csc::canonical_symmetric(m, "M", size)?;
    if n > size {
        return Err(ReductionError::TooManyModes {
            asked: n,
            available: size,
            what: "model",
        });
    }
    let kl = csc::lower(&kc);
    drop(kc);
    let ml = csc::lower(&mc);
    drop(mc);
    let a = if shift != 0.0 {
        csc::add_scaled(&kl, &ml, -shift)
    } else {
        kl.clone()
    };
    let (fwd, inv, _) = factor::fill_reducing_order(&a, ordering)?;
    let a = a.permute_sym_lower(&inv);
    let orig = |i: usize| fwd[i];
    let factor = factor::SpdFactor::new(
        &a,
        &factor::PivotContext {
            matrix: "K − σM",
            context: "model",
            local_index: &orig,
            full_index: &orig,
        },
    )?;
    drop(a);
    let view = |lower| csc::SymView {
        lower,
        inv: Some(&inv),
    };
    let mut eig = eigen::lowest_modes(view(&kl), view(&ml), &factor, shift, n, options, Par::Seq)?;
    let q = eig.values.len();
    eig.vectors = faer::Mat::from_fn(size, q, |old, c| eig.vectors[(inv[old], c)]);
    block::release_scratch();
    Ok(eig)
}
