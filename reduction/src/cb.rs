//! The Craig-Bampton reduction itself.

use crate::block::{sym_mul_rows, RowBlock};
use crate::csc::{canonical_symmetric, split, Blocks, Part, SymView};
use crate::eigen::{lambda_to_hz, lowest_modes, Eigen, LanczosOptions};
use crate::factor::{fill_reducing_order, PivotContext, SpdFactor};
use crate::ordering::Ordering;
use crate::ReductionError;
use faer::linalg::matmul::matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, Par};
use rayon::prelude::*;
use std::time::Instant;

/// Options of [`craig_bampton`].
#[derive(Clone, Debug)]
pub struct CbOptions {
    /// Number of fixed-interface modes kept (may grow by a few to keep a
    /// repeated eigenvalue whole, see `complete_clusters`).
    pub n_modes: usize,
    /// Fill-reducing ordering of the Cholesky factorisation of `K_II`.
    pub ordering: Ordering,
    /// Number of constraint modes computed at once (columns of a block of Ψ).
    /// Memory of a block: about `2 × n_I × block_size × 8` bytes (Ψ_a and
    /// M_II Ψ_a), plus the products' scratch `2 × n_I × 16 × 8` bytes.
    pub block_size: usize,
    /// Worker threads for the constraint-mode blocks (1: sequential). Each
    /// block is computed sequentially and written to its own rows/columns,
    /// so results do not depend on this number (beyond round-off).
    pub threads: usize,
    /// Settings of the block Lanczos eigen solver.
    pub lanczos: LanczosOptions,
    /// Extra fixed-interface modes computed beyond `n_modes` (convergence
    /// safety and cluster detection); `None`: `max(4, n_modes / 10)`.
    pub extra_modes: Option<usize>,
    /// If the `n_modes`-th eigenvalue is repeated (relative gap below
    /// `cluster_rtol`), keep all its copies.
    pub complete_clusters: bool,
    /// Relative tolerance defining a repeated eigenvalue.
    pub cluster_rtol: f64,
    /// Largest accepted relative residual `‖Kφ − λMφ‖/‖Kφ‖` of a
    /// fixed-interface mode.
    pub max_residual: f64,
    /// Check with a Sturm-sequence count that no fixed-interface mode below
    /// the cut-off was missed: the inertia of `K_II − σ M_II`, σ halfway
    /// between the last kept and the next computed eigenvalue, from one more
    /// (indefinite, supernodal `LDLᵀ`) factorisation. Costs about one
    /// numeric factorisation; an error if modes were missed.
    pub sturm_check: bool,
}

impl Default for CbOptions {
    fn default() -> Self {
        CbOptions {
            n_modes: 20,
            ordering: Ordering::Metis,
            block_size: 64,
            threads: 1,
            lanczos: LanczosOptions::default(),
            extra_modes: None,
            complete_clusters: true,
            cluster_rtol: 1e-6,
            max_residual: 1e-6,
            sturm_check: true,
        }
    }
}

impl CbOptions {
    /// Default options with `n_modes` fixed-interface modes.
    pub fn with_modes(n_modes: usize) -> Self {
        CbOptions {
            n_modes,
            ..Default::default()
        }
    }
}

/// Recovery row of one full-model DOF: `u[dof] = row · q` with `q` the
/// reduced coordinates (boundary displacements then modal amplitudes).
#[derive(Clone, Debug, PartialEq)]
pub struct RecoveryRow {
    /// full-model index
    pub dof: usize,
    /// length `n_boundary + n_modes`
    pub row: Vec<f64>,
}

/// CPU seconds of the calling thread per phase of a reduction.
#[derive(Clone, Copy, Debug, Default)]
pub struct CpuPhases {
    /// validation, canonicalisation, partition
    pub validate: f64,
    /// ordering, symbolic and numeric Cholesky
    pub factor: f64,
    /// fixed-interface modes
    pub eigen: f64,
    /// constraint modes and reduced matrices
    pub constraint: f64,
    /// Sturm-sequence check
    pub sturm: f64,
}

/// CPU time of the calling thread, seconds (`/proc/thread-self/schedstat`).
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Marks phase boundaries on the calling thread's CPU clock.
struct CpuClock {
    last: Option<f64>,
}

impl CpuClock {
    fn new() -> Self {
        CpuClock {
            last: thread_cpu_seconds(),
        }
    }
    /// CPU seconds since the previous mark.
    fn lap(&mut self) -> f64 {
        let now = thread_cpu_seconds();
        let d = match (self.last, now) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        self.last = now;
        d
    }
}

/// Sizes, times and memory of a reduction.
#[derive(Clone, Debug, Default)]
pub struct ReductionReport {
    /// DOFs of the full model
    pub n_full: usize,
    /// boundary DOFs kept as physical coordinates
    pub n_boundary: usize,
    /// interior DOFs condensed
    pub n_interior: usize,
    /// fixed-interface modes kept
    pub n_modes: usize,
    /// fixed-interface modes computed (kept + extra)
    pub n_modes_computed: usize,
    /// highest kept fixed-interface eigenfrequency, Hz (0 if no mode)
    pub cutoff_hz: f64,
    /// lowest computed but not kept fixed-interface frequency, Hz
    pub next_hz: Option<f64>,
    /// ordering used for `K_II`
    pub ordering: Ordering,
    /// stored entries of the lower triangle of `K_II`
    pub k_ii_nnz: usize,
    /// stored entries of the Cholesky factor of `K_II` (supernodal storage)
    pub factor_nnz: usize,
    /// largest relative residual of the fixed-interface modes
    pub eigen_max_residual: f64,
    /// thick restarts of the Lanczos solver
    pub eigen_restarts: usize,
    /// block solves of the Lanczos solver
    pub eigen_solves: usize,
    /// where the eigen solve spent its time
    pub eigen_timings: crate::eigen::EigenTimings,
    /// seconds of the constraint-mode phase in solves with the factor
    /// (summed over blocks; with several threads, over threads)
    pub t_constraint_solve: f64,
    /// seconds of the constraint-mode phase in products with M_II
    pub t_constraint_mass: f64,
    /// block Lanczos block size
    pub lanczos_block: usize,
    /// constraint-mode block size
    pub block_size: usize,
    /// worker threads of the constraint-mode phase
    pub threads: usize,
    /// seconds: validation and canonicalisation of K, M
    pub t_validate: f64,
    /// seconds: interior/boundary split
    pub t_partition: f64,
    /// seconds: METIS ordering (0 for AMD, counted in `t_symbolic`)
    pub t_ordering: f64,
    /// seconds: symbolic Cholesky (with AMD when chosen)
    pub t_symbolic: f64,
    /// seconds: numeric Cholesky
    pub t_numeric: f64,
    /// seconds: fixed-interface eigen solve
    pub t_eigen: f64,
    /// seconds: constraint modes and reduced matrices
    pub t_constraint: f64,
    /// Sturm count: fixed-interface eigenvalues below the check shift
    /// (should equal `n_modes`); `None` if not done
    pub sturm_count: Option<usize>,
    /// seconds: Sturm-sequence check
    pub t_sturm: f64,
    /// seconds in all (wall clock)
    pub t_total: f64,
    /// CPU seconds of the process during the reduction (user + system, all
    /// threads; from /proc/self/stat, `None` elsewhere). Compared with
    /// `t_total` it shows how much the machine was shared.
    pub cpu_seconds: Option<f64>,
    /// CPU seconds of the calling thread per phase (Linux), independent of
    /// how busy the machine is; with `threads > 1` the constraint-mode
    /// blocks run on other threads and are not counted here
    pub cpu_phases: Option<CpuPhases>,
    /// peak resident memory of the process (VmHWM of /proc/self/status),
    /// bytes; `None` where it cannot be read
    pub peak_memory_bytes: Option<u64>,
}

impl std::fmt::Display for ReductionReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "Craig-Bampton: {} DOFs -> {} boundary + {} modes ({} interior)",
            self.n_full, self.n_boundary, self.n_modes, self.n_interior
        )?;
        writeln!(
            f,
            "  cut-off {:.4} Hz{}",
            self.cutoff_hz,
            self.next_hz
                .map(|h| format!(", next fixed-interface mode {h:.4} Hz"))
                .unwrap_or_default()
        )?;
        writeln!(
            f,
            "  K_II lower nnz {}, Cholesky factor entries {} ({} ordering)",
            self.k_ii_nnz, self.factor_nnz, self.ordering
        )?;
        writeln!(
            f,
            "  eigen: max residual {:.2e}, {} restarts, {} block solves (block {})",
            self.eigen_max_residual, self.eigen_restarts, self.eigen_solves, self.lanczos_block
        )?;
        let e = &self.eigen_timings;
        writeln!(
            f,
            "  eigen seconds: solves {:.2}, M products {:.2}, orthogonalisation {:.2}, Rayleigh-Ritz/restart {:.2}, check {:.2}",
            e.solve, e.mass, e.orthogonalise, e.restart, e.check
        )?;
        writeln!(
            f,
            "  constraint-mode seconds: solves {:.2}, M products {:.2}",
            self.t_constraint_solve, self.t_constraint_mass
        )?;
        if let Some(c) = self.sturm_count {
            writeln!(
                f,
                "  Sturm check: {c} eigenvalues below the check shift ({:.2} s)",
                self.t_sturm
            )?;
        }
        writeln!(
            f,
            "  seconds: validate {:.2}, partition {:.2}, ordering {:.2}, symbolic {:.2}, numeric {:.2}, eigen {:.2}, constraint modes {:.2}, total {:.2} (CPU {})",
            self.t_validate,
            self.t_partition,
            self.t_ordering,
            self.t_symbolic,
            self.t_numeric,
            self.t_eigen,
            self.t_constraint,
            self.t_total,
            self.cpu_seconds
                .map(|c| format!("{c:.2}"))
                .unwrap_or_else(|| "n/a".into())
        )?;
        if let Some(c) = &self.cpu_phases {
            writeln!(
                f,
                "  CPU seconds (calling thread): validate {:.2}, factor {:.2}, eigen {:.2}, constraint modes {:.2}, Sturm {:.2}",
                c.validate, c.factor, c.eigen, c.constraint, c.sturm
            )?;
        }
        match self.peak_memory_bytes {
            Some(b) => write!(f, "  peak memory {:.2} GiB", b as f64 / (1u64 << 30) as f64),
            None => write!(f, "  peak memory unknown"),
        }
    }
}

/// A Craig-Bampton reduced model.
///
/// Coordinates `q = [u_B; η]`: the boundary displacements in the order given
/// to [`craig_bampton`], then the amplitudes of the mass-normalised
/// fixed-interface modes.
#[derive(Clone, Debug)]
pub struct ReducedModel {
    /// full-model indices of the boundary DOFs = first `nb` reduced coordinates
    pub boundary: Vec<usize>,
    /// number of fixed-interface modal coordinates (after the boundary ones)
    pub n_modes: usize,
    /// `K_r = [K_BB + K_BI Ψ, 0; 0, Λ]`, symmetric `(nb + nm)²`
    pub stiffness: Mat<f64>,
    /// `M_r = [M̂_BB, (M_BI + Ψᵀ M_II) Φ; sym, I]`, symmetric
    pub mass: Mat<f64>,
    /// fixed-interface eigenfrequencies in Hz, ascending (`√λ / 2π`)
    pub modal_frequencies_hz: Vec<f64>,
    /// fixed-interface eigenvalues `λ = ω²` (rad²/s²), ascending
    pub modal_eigenvalues: Vec<f64>,
    /// recovery rows of the DOFs asked for, in the order asked
    pub recovery: Vec<RecoveryRow>,
    /// sizes, times, memory
    pub report: ReductionReport,
}

impl ReducedModel {
    /// Size of the reduced model, `nb + nm`.
    pub fn size(&self) -> usize {
        self.boundary.len() + self.n_modes
    }

    /// Modal damping matrix with one ratio `zeta` for every fixed-interface
    /// mode: `C_r[nb+i, nb+i] = 2 ζ ωᵢ` (ωᵢ in rad/s; the modes are
    /// mass-normalised), zero elsewhere, in particular on the boundary
    /// coordinates, whose damping (joints, contacts) belongs to the scene.
    pub fn modal_damping(&self, zeta: f64) -> Mat<f64> {
        let z = vec![zeta; self.n_modes];
        self.build_damping(&z)
    }

    /// Modal damping with one ratio per fixed-interface mode (`zeta.len()`
    /// must equal `n_modes`, or be 1 for a uniform ratio).
    pub fn modal_damping_per_mode(&self, zeta: &[f64]) -> Result<Mat<f64>, ReductionError> {
        if zeta.len() == 1 {
            return Ok(self.modal_damping(zeta[0]));
        }
        if zeta.len() != self.n_modes {
            return Err(ReductionError::InvalidArgument(format!(
                "{} modal damping ratios given for {} fixed-interface modes",
                zeta.len(),
                self.n_modes
            )));
        }
        if let Some((i, z)) = zeta
            .iter()
            .enumerate()
            .find(|(_, z)| !z.is_finite() || **z < 0.0)
        {
            return Err(ReductionError::InvalidArgument(format!(
                "modal damping ratio {i} is {z}: it must be finite and non-negative"
            )));
        }
        Ok(self.build_damping(zeta))
    }

    fn build_damping(&self, zeta: &[f64]) -> Mat<f64> {
        let nb = self.boundary.len();
        let mut c = Mat::zeros(self.size(), self.size());
        for (i, &z) in zeta.iter().enumerate() {
            let omega = self.modal_eigenvalues[i].max(0.0).sqrt();
            c[(nb + i, nb + i)] = 2.0 * z * omega;
        }
        c
    }

    /// Full-model displacements of the recovered DOFs for reduced
    /// coordinates `q`, in the order of `recovery`.
    pub fn recover(&self, q: &[f64]) -> Result<Vec<f64>, ReductionError> {
        if q.len() != self.size() {
            return Err(ReductionError::InvalidArgument(format!(
                "reduced vector has length {}, the model has {} coordinates",
                q.len(),
                self.size()
            )));
        }
        Ok(self
            .recovery
            .iter()
            .map(|r| r.row.iter().zip(q).map(|(a, b)| a * b).sum())
            .collect())
    }
}

/// CPU time (user + system) of this process so far, seconds; `None` off Linux.
pub fn process_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // fields after the command name (which is in parentheses)
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    // clock ticks: 100 per second on Linux
    Some((utime + stime) / 100.0)
}

/// Peak resident memory of this process (VmHWM), bytes; `None` off Linux.
pub fn peak_memory_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

pub(crate) fn check_indices(
    n: usize,
    boundary: &[usize],
    recover: &[usize],
) -> Result<Vec<Part>, ReductionError> {
    let mut first_pos = vec![usize::MAX; n];
    for (pos, &b) in boundary.iter().enumerate() {
        if b >= n {
            return Err(ReductionError::IndexOutOfRange {
                list: "boundary",
                index: b,
                position: pos,
                n,
            });
        }
        if first_pos[b] != usize::MAX {
            return Err(ReductionError::RepeatedBoundary {
                index: b,
                first: first_pos[b],
                second: pos,
            });
        }
        first_pos[b] = pos;
    }
    for (pos, &r) in recover.iter().enumerate() {
        if r >= n {
            return Err(ReductionError::IndexOutOfRange {
                list: "recover",
                index: r,
                position: pos,
                n,
            });
        }
    }
    let mut part = Vec::with_capacity(n);
    let mut n_i = 0;
    for &fp in &first_pos {
        if fp == usize::MAX {
            part.push(Part::Interior(n_i));
            n_i += 1;
        } else {
            part.push(Part::Boundary(fp));
        }
    }
    Ok(part)
}

/// Craig-Bampton reduction of the symmetric model `(K, M)`.
///
/// * `k`, `m`: `n × n`, both triangles stored, finite; `K_II` (the stiffness
///   with the boundary DOFs held) must be positive definite, `K` itself may
///   be singular (free bodies held only through boundary DOFs).
/// * `boundary`: full indices of the DOFs kept as physical coordinates
///   (contact, excitation, response), distinct, in the order of the reduced
///   coordinates.
/// * `recover`: full indices whose recovery rows are returned (boundary or
///   interior, any order, repeats allowed).
pub fn craig_bampton(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    boundary: &[usize],
    recover: &[usize],
    options: &CbOptions,
) -> Result<ReducedModel, ReductionError> {
    let t_start = Instant::now();
    let cpu_start = process_cpu_seconds();
    let mut clock = CpuClock::new();
    let mut cpu = CpuPhases::default();
    let n = k.nrows();
    if options.block_size == 0 {
        return Err(ReductionError::InvalidArgument(
            "block_size must be at least 1".into(),
        ));
    }
    if options.lanczos.block == 0 {
        return Err(ReductionError::InvalidArgument(
            "the Lanczos block size must be at least 1".into(),
        ));
    }
    if k.ncols() != n {
        return Err(ReductionError::BadShape {
            matrix: "K",
            rows: k.nrows(),
            cols: k.ncols(),
            expected: n,
        });
    }
    if m.nrows() != n || m.ncols() != n {
        return Err(ReductionError::BadShape {
            matrix: "M",
            rows: m.nrows(),
            cols: m.ncols(),
            expected: n,
        });
    }
    let part = check_indices(n, boundary, recover)?;
    let nb = boundary.len();
    let n_i = n - nb;
    if options.n_modes > n_i {
        return Err(ReductionError::TooManyModes {
            asked: options.n_modes,
            available: n_i,
            what: "interior (fixed-interface) model",
        });
    }
    let kc = canonical_symmetric(k, "K", n)?;
    let mc = canonical_symmetric(m, "M", n)?;
    let t_validate = t_start.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let kb = split(&kc, &part, n_i, nb);
    drop(kc);
    let mb = split(&mc, &part, n_i, nb);
    drop(mc);
    let interior_full: Vec<usize> = (0..n)
        .filter(|&d| matches!(part[d], Part::Interior(_)))
        .collect();
    let t_partition = t0.elapsed().as_secs_f64();
    cpu.validate = clock.lap();

    let mut report = ReductionReport {
        n_full: n,
        n_boundary: nb,
        n_interior: n_i,
        ordering: options.ordering,
        k_ii_nnz: kb.ii_lower.nnz(),
        lanczos_block: options.lanczos.block,
        block_size: options.block_size,
        threads: options.threads.max(1),
        t_validate,
        t_partition,
        ..Default::default()
    };

    if n_i == 0 {
        // nothing to condense
        let model = ReducedModel {
            boundary: boundary.to_vec(),
            n_modes: 0,
            stiffness: symmetric_part(&kb.bb),
            mass: symmetric_part(&mb.bb),
            modal_frequencies_hz: Vec::new(),
            modal_eigenvalues: Vec::new(),
            recovery: recovery_rows(recover, &part, nb, 0, &[], &[]),
            report: finish_report(report, t_start, cpu_start),
        };
        return Ok(model);
    }

    // elimination order of K_II; the interior DOFs are renumbered in it so
    // that the factor solves in place without permutation copies
    let (fwd, inv, t_ordering) = fill_reducing_order(&kb.ii_lower, options.ordering)?;
    // K_II and M_II stay in mesh order for cache-friendly products; only
    // the coupling blocks and the factored copy of K_II are renumbered
    let kb = permute_coupling(kb, &inv);
    let mb = permute_coupling(mb, &inv);
    let part: Vec<Part> = part
        .into_iter()
        .map(|p| match p {
            Part::Interior(i) => Part::Interior(inv[i]),
            b => b,
        })
        .collect();
    let local_index = |i: usize| fwd[i];
    let full_index = |i: usize| interior_full[fwd[i]];
    let k_ii_perm = kb.ii_lower.permute_sym_lower(&inv);
    let factor = SpdFactor::new(
        &k_ii_perm,
        &PivotContext {
            matrix: "K_II",
            context: "interior",
            local_index: &local_index,
            full_index: &full_index,
        },
    )?;
    drop(k_ii_perm);
    report.t_ordering = t_ordering;
    report.t_symbolic = factor.symbolic_seconds;
    report.t_numeric = factor.numeric_seconds;
    cpu.factor = clock.lap();
    report.factor_nnz = factor.factor_entries();

    // fixed-interface modes
    let t0 = Instant::now();
    let extra = options.extra_modes.unwrap_or((options.n_modes / 10).max(4));
    let n_comp = if options.n_modes == 0 {
        0
    } else {
        (options.n_modes + extra).min(n_i)
    };
    let eig = lowest_modes(
        SymView {
            lower: &kb.ii_lower,
            inv: Some(&inv),
        },
        SymView {
            lower: &mb.ii_lower,
            inv: Some(&inv),
        },
        &factor,
        0.0,
        n_comp,
        &options.lanczos,
        Par::Seq,
    )?;
    if eig.max_residual > options.max_residual {
        return Err(ReductionError::EigenNotConverged {
            wanted: n_comp,
            converged: 0,
            restarts: eig.restarts,
            residual: eig.max_residual,
        });
    }
    let mut nm = options.n_modes;
    if options.complete_clusters && nm > 0 {
        while nm < eig.values.len() {
            let a = eig.values[nm - 1];
            let b = eig.values[nm];
            if (b - a).abs() <= options.cluster_rtol * a.abs().max(b.abs()) {
                nm += 1;
            } else {
                break;
            }
        }
    }
    let Eigen {
        values,
        vectors,
        max_residual,
        restarts,
        solves,
        timings,
    } = eig;
    let next_lambda = values.get(nm).copied();
    let next_hz = next_lambda.map(lambda_to_hz);
    let lambdas: Vec<f64> = values[..nm].to_vec();
    let phi = vectors.subcols(0, nm).to_owned();
    drop(vectors);
    report.n_modes = nm;
    report.n_modes_computed = n_comp;
    report.cutoff_hz = lambdas.last().map(|&l| lambda_to_hz(l)).unwrap_or(0.0);
    report.next_hz = next_hz;
    report.eigen_max_residual = max_residual;
    report.eigen_restarts = restarts;
    report.eigen_solves = solves;
    report.eigen_timings = timings;
    report.t_eigen = t0.elapsed().as_secs_f64();
    cpu.eigen = clock.lap();

    // constraint modes, block by block
    let t0 = Instant::now();
    let cons = constraint_blocks(&kb, &mb, &inv, &factor, &phi, &part, recover, options)?;
    report.t_constraint = t0.elapsed().as_secs_f64();
    cpu.constraint = clock.lap();
    report.t_constraint_solve = cons.t_solve;
    report.t_constraint_mass = cons.t_mass;

    drop(factor);
    if options.sturm_check && nm > 0 {
        let t0 = Instant::now();
        let last = lambdas[nm - 1];
        let sigma = match next_lambda {
            Some(next) if next > last => 0.5 * (last + next),
            _ => last * (1.0 + 1e-3),
        };
        let shifted =
            crate::csc::add_scaled(&kb.ii_lower, &mb.ii_lower, -sigma).permute_sym_lower(&inv);
        let count = crate::factor::negative_pivots(&shifted)?;
        drop(shifted);
        report.t_sturm = t0.elapsed().as_secs_f64();
        cpu.sturm = clock.lap();
        report.sturm_count = count;
        if let Some(c) = count {
            if c > nm {
                return Err(ReductionError::MissedEigenvalues {
                    computed: nm,
                    found: c,
                    shift_hz: lambda_to_hz(sigma),
                });
            }
        }
    }

    if clock.last.is_some() {
        report.cpu_phases = Some(cpu);
    }

    let size = nb + nm;
    let mut kr = Mat::zeros(size, size);
    let mut mr = Mat::zeros(size, size);
    for j in 0..nb {
        for i in 0..nb {
            kr[(i, j)] = 0.5 * (cons.k_bb[(i, j)] + cons.k_bb[(j, i)]);
            mr[(i, j)] = 0.5 * (cons.m_bb[(i, j)] + cons.m_bb[(j, i)]);
        }
    }
    for (a, &l) in lambdas.iter().enumerate() {
        kr[(nb + a, nb + a)] = l;
        mr[(nb + a, nb + a)] = 1.0;
        for i in 0..nb {
            mr[(i, nb + a)] = cons.coupling[(i, a)];
            mr[(nb + a, i)] = cons.coupling[(i, a)];
        }
    }
    let recovery = recovery_rows(
        recover,
        &part,
        nb,
        nm,
        &cons.psi_rows,
        &phi_rows(&phi, &part, recover),
    );
    Ok(ReducedModel {
        boundary: boundary.to_vec(),
        n_modes: nm,
        stiffness: kr,
        mass: mr,
        modal_frequencies_hz: lambdas.iter().map(|&l| lambda_to_hz(l)).collect(),
        modal_eigenvalues: lambdas,
        recovery,
        report: finish_report(report, t_start, cpu_start),
    })
}

fn permute_coupling(b: Blocks, inv: &[usize]) -> Blocks {
    Blocks {
        ii_lower: b.ii_lower,
        ib: b.ib.permute_rows(inv),
        bb: b.bb,
    }
}

fn finish_report(
    mut r: ReductionReport,
    t_start: Instant,
    cpu_start: Option<f64>,
) -> ReductionReport {
    crate::block::release_scratch();
    r.t_total = t_start.elapsed().as_secs_f64();
    r.cpu_seconds = match (cpu_start, process_cpu_seconds()) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    r.peak_memory_bytes = peak_memory_bytes();
    r
}

fn symmetric_part(a: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// Φ rows of the recovered interior DOFs (empty vec for boundary ones).
fn phi_rows(phi: &Mat<f64>, part: &[Part], recover: &[usize]) -> Vec<Vec<f64>> {
    recover
        .iter()
        .map(|&d| match part[d] {
            Part::Interior(i) => (0..phi.ncols()).map(|c| phi[(i, c)]).collect(),
            Part::Boundary(_) => Vec::new(),
        })
        .collect()
}

fn recovery_rows(
    recover: &[usize],
    part: &[Part],
    nb: usize,
    nm: usize,
    psi_rows: &[Vec<f64>],
    phi_rows: &[Vec<f64>],
) -> Vec<RecoveryRow> {
    recover
        .iter()
        .enumerate()
        .map(|(pos, &d)| {
            let mut row = vec![0.0; nb + nm];
            match part[d] {
                Part::Boundary(b) => row[b] = 1.0,
                Part::Interior(_) => {
                    row[..nb].copy_from_slice(&psi_rows[pos]);
                    row[nb..].copy_from_slice(&phi_rows[pos]);
                }
            }
            RecoveryRow { dof: d, row }
        })
        .collect()
}

struct ConstraintResult {
    /// K_BB + K_BI Ψ
    k_bb: Mat<f64>,
    /// M_BB + M_BI Ψ + Ψᵀ M_IB + Ψᵀ M_II Ψ
    m_bb: Mat<f64>,
    /// (M_BI + Ψᵀ M_II) Φ, nb × nm
    coupling: Mat<f64>,
    /// Ψ rows (length nb) of the recovered DOFs (empty for boundary ones)
    psi_rows: Vec<Vec<f64>>,
    t_solve: f64,
    t_mass: f64,
}

/// Output of one column block `a` of Ψ.
struct BlockOut {
    start: usize,
    /// (K_BB + K_BI Ψ)[:, a], nb × w
    k_cols: Mat<f64>,
    /// M_BI Ψ_a, nb × w
    p_cols: Mat<f64>,
    /// −K_BI K_II⁻¹ M_II Ψ_a = Ψᵀ M_II Ψ_a, nb × w (columns a of Ψᵀ M_II Ψ)
    g_cols: Mat<f64>,
    /// (M_II Ψ_a)ᵀ Φ, w × nm
    coupling_rows: Mat<f64>,
    /// Ψ_a rows of the recovered interior DOFs: (position in recover, values)
    psi: Vec<(usize, Vec<f64>)>,
    t_solve: f64,
    t_mass: f64,
}

#[allow(clippy::too_many_arguments)]
/// Ψ = −K_II⁻¹ K_IB computed `block_size` columns at a time; only the block
/// in hand is held (3 dense `n_I × block_size` arrays). The term Ψᵀ M_II Ψ,
/// which pairs every block with every other, is obtained without holding Ψ
/// through `Ψ_bᵀ M_II Ψ_a = −K_BI_b (K_II⁻¹ M_II Ψ_a)`: one more solve per
/// block.
fn constraint_blocks(
    kb: &Blocks,
    mb: &Blocks,
    inv: &[usize],
    factor: &SpdFactor,
    phi: &Mat<f64>,
    part: &[Part],
    recover: &[usize],
    options: &CbOptions,
) -> Result<ConstraintResult, ReductionError> {
    let n_i = kb.ii_lower.ncols;
    let nb = kb.ib.ncols;
    let nm = phi.ncols();
    let bs = options.block_size;
    // recovered interior DOFs: (position in recover, interior index)
    let rec_int: Vec<(usize, usize)> = recover
        .iter()
        .enumerate()
        .filter_map(|(pos, &d)| match part[d] {
            Part::Interior(i) => Some((pos, i)),
            Part::Boundary(_) => None,
        })
        .collect();
    // M_BI Φ (nb × nm)
    let mbi_phi = mb.ib.transpose_mul_rows(&RowBlock::from_mat(phi.as_ref()));

    let starts: Vec<usize> = (0..nb).step_by(bs).collect();
    let run_block = |start: usize| -> BlockOut {
        let w = bs.min(nb - start);
        // Ψ_a = −K_II⁻¹ K_IB[:, a]   (row-major n_I × w)
        let mut psi = RowBlock::take(n_i, w);
        psi.data.fill(0.0);
        for c in 0..w {
            let (rows, vals) = kb.ib.col(start + c);
            for (&i, &v) in rows.iter().zip(vals) {
                psi.row_mut(i)[c] = -v;
            }
        }
        let t = Instant::now();
        factor.solve_rows(&mut psi);
        let mut t_solve = t.elapsed().as_secs_f64();
        let mut k_cols = kb.ib.transpose_mul_rows(&psi);
        let p_cols = mb.ib.transpose_mul_rows(&psi);
        for c in 0..w {
            for i in 0..nb {
                k_cols[(i, c)] += kb.bb[(i, start + c)];
            }
        }
        let psi_rec: Vec<(usize, Vec<f64>)> = rec_int
            .iter()
            .map(|&(pos, i)| (pos, psi.row(i).to_vec()))
            .collect();
        // Z = M_II Ψ_a
        let mut z = RowBlock::take(n_i, w);
        let t = Instant::now();
        sym_mul_rows(&mb.ii_lower, Some(inv), &psi, &mut z);
        let t_mass = t.elapsed().as_secs_f64();
        psi.give_back();
        let mut coupling_rows = Mat::zeros(w, nm);
        matmul(
            coupling_rows.as_mut(),
            Accum::Replace,
            z.view().transpose(),
            phi.as_ref(),
            1.0,
            Par::Seq,
        );
        for c in 0..w {
            for a in 0..nm {
                coupling_rows[(c, a)] += mbi_phi[(start + c, a)];
            }
        }
        // Y = K_II⁻¹ Z; Ψᵀ M_II Ψ_a = −K_BI Y
        let t = Instant::now();
        factor.solve_rows(&mut z);
        t_solve += t.elapsed().as_secs_f64();
        let mut g_cols = kb.ib.transpose_mul_rows(&z);
        z.give_back();
        for c in 0..w {
            for i in 0..nb {
                g_cols[(i, c)] = -g_cols[(i, c)];
            }
        }
        BlockOut {
            start,
            k_cols,
            p_cols,
            g_cols,
            coupling_rows,
            psi: psi_rec,
            t_solve,
            t_mass,
        }
    };
    let threads = options.threads.max(1);
    let outs: Vec<BlockOut> = if threads == 1 {
        starts.iter().map(|&s| run_block(s)).collect()
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| ReductionError::InvalidArgument(format!("thread pool: {e}")))?;
        pool.install(|| starts.par_iter().map(|&s| run_block(s)).collect())
    };
    let mut k_bb = Mat::zeros(nb, nb);
    let mut p = Mat::zeros(nb, nb);
    let mut g = Mat::zeros(nb, nb);
    let mut coupling = Mat::zeros(nb, nm);
    let mut psi_rows: Vec<Vec<f64>> = recover.iter().map(|_| Vec::new()).collect();
    for &(pos, _) in &rec_int {
        psi_rows[pos] = vec![0.0; nb];
    }
    let (mut t_solve, mut t_mass) = (0.0, 0.0);
    for o in outs {
        t_solve += o.t_solve;
        t_mass += o.t_mass;
        let w = o.k_cols.ncols();
        k_bb.as_mut().subcols_mut(o.start, w).copy_from(&o.k_cols);
        p.as_mut().subcols_mut(o.start, w).copy_from(&o.p_cols);
        g.as_mut().subcols_mut(o.start, w).copy_from(&o.g_cols);
        coupling
            .as_mut()
            .subrows_mut(o.start, w)
            .copy_from(&o.coupling_rows);
        for (pos, vals) in o.psi {
            psi_rows[pos][o.start..o.start + w].copy_from_slice(&vals);
        }
    }
    // M̂_BB = M_BB + P + Pᵀ + G
    let m_bb = Mat::from_fn(nb, nb, |i, j| {
        mb.bb[(i, j)] + p[(i, j)] + p[(j, i)] + 0.5 * (g[(i, j)] + g[(j, i)])
    });
    Ok(ConstraintResult {
        k_bb,
        m_bb,
        coupling,
        psi_rows,
        t_solve,
        t_mass,
    })
}
