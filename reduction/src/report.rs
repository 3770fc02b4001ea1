//! What a reduction reports: sizes, cut-off frequency, factor size, ordering, CPU seconds per
//! phase, and the process's CPU time and peak memory.

use crate::ordering::Ordering;

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
pub(crate) struct CpuClock {
    pub(crate) last: Option<f64>,
}

impl CpuClock {
    pub(crate) fn new() -> Self {
        CpuClock {
            last: thread_cpu_seconds(),
        }
    }
    /// CPU seconds since the previous mark.
    pub(crate) fn lap(&mut self) -> f64 {
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
