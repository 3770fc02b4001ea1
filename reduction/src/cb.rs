//! The Craig-Bampton reduction itself.

use crate::constraint::constraint_blocks;
use crate::csc::{canonical_symmetric, split, Blocks, Part, SymView};
use crate::eigen::{lambda_to_hz, lowest_modes, Eigen, LanczosOptions};
use crate::factor::{fill_reducing_order, PivotContext, SpdFactor};
use crate::ordering::Ordering;
use crate::report::{peak_memory_bytes, process_cpu_seconds, CpuClock, CpuPhases, ReductionReport};
use crate::ReductionError;
use faer::sparse::SparseColMatRef;
use faer::{Mat, Par};
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
    let cons = constraint_blocks(
        &kb,
        &mb,
        &inv,
        &factor,
        &phi,
        &part,
        recover,
        (options.block_size, options.threads),
    )?;
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
