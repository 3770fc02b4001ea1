//! Process-wide counters of the linear-algebra work done so far: factorisations (and how many
//! were structured low-rank ones, with their rank) and solves, with the wall time spent in each,
//! plus the time spent evaluating residuals and Jacobians. Benchmarks (`fricbound bench contacts`) read them
//! before and after a run to say where its time went; nothing in the solvers depends on them.
//!
//! The counters are plain relaxed atomics shared by every thread: two runs in one process at
//! the same time add into the same counters, so a reading is meaningful only when one run is
//! measured at a time (as the bench does).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// What a counter counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Work {
    /// Numeric factorisations of a Newton matrix (dense, sparse or the schur formulation's
    /// reduced LU), with their wall time.
    Factorisation,
    /// Solves with a factorisation (each right-hand side), with their wall time.
    Solve,
    /// Residual and Jacobian evaluations (contact forces by AFT, their Jacobian, the linear
    /// part), with their wall time.
    Evaluation,
    /// Factorisations of a reduced matrix by a low-rank update of a per-harmonic baseline
    /// (the schur formulation where few contacts slip).
    LowRankFactorisation,
    /// Rows of those low-rank updates, summed.
    LowRankRows,
    /// Harmonics eliminated from the glued structure's modes (the schur formulation's
    /// per-harmonic elimination without an LU, [`crate::hbm::schur::modal`]).
    ModalElimination,
}

const KINDS: usize = 6;

static COUNTS: [AtomicU64; KINDS] = [const { AtomicU64::new(0) }; KINDS];
static NANOS: [AtomicU64; KINDS] = [const { AtomicU64::new(0) }; KINDS];

fn index(w: Work) -> usize {
    match w {
        Work::Factorisation => 0,
        Work::Solve => 1,
        Work::Evaluation => 2,
        Work::LowRankFactorisation => 3,
        Work::LowRankRows => 4,
        Work::ModalElimination => 5,
    }
}

/// Adds `count` to the counter of `w`.
pub fn add(w: Work, count: u64) {
    COUNTS[index(w)].fetch_add(count, Ordering::Relaxed);
}

/// Adds one to the counter of `w` and the wall time since `started` to its time.
pub fn record(w: Work, started: Instant) {
    let nanos = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
    COUNTS[index(w)].fetch_add(1, Ordering::Relaxed);
    NANOS[index(w)].fetch_add(nanos, Ordering::Relaxed);
}

/// The counters at one moment; the difference of two readings is the work done between them.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct WorkReading {
    /// Numeric factorisations.
    pub factorisations: u64,
    /// Wall time in factorisations (s).
    pub factorisation_s: f64,
    /// Solves (right-hand sides).
    pub solves: u64,
    /// Wall time in solves (s).
    pub solve_s: f64,
    /// Residual (and Jacobian) evaluations.
    pub evaluations: u64,
    /// Wall time in evaluations (s).
    pub evaluation_s: f64,
    /// Reduced matrices factorised by a low-rank update.
    pub low_rank_factorisations: u64,
    /// Rows of those updates, summed.
    pub low_rank_rows: u64,
    /// Harmonics eliminated from the glued structure's modes.
    pub modal_eliminations: u64,
}

/// The counters now.
pub fn reading() -> WorkReading {
    let count = |w: Work| COUNTS[index(w)].load(Ordering::Relaxed);
    let seconds = |w: Work| NANOS[index(w)].load(Ordering::Relaxed) as f64 * 1e-9;
    WorkReading {
        factorisations: count(Work::Factorisation),
        factorisation_s: seconds(Work::Factorisation),
        solves: count(Work::Solve),
        solve_s: seconds(Work::Solve),
        evaluations: count(Work::Evaluation),
        evaluation_s: seconds(Work::Evaluation),
        low_rank_factorisations: count(Work::LowRankFactorisation),
        low_rank_rows: count(Work::LowRankRows),
        modal_eliminations: count(Work::ModalElimination),
    }
}

impl WorkReading {
    /// The work done from `before` to `self`.
    pub fn since(&self, before: &WorkReading) -> WorkReading {
        WorkReading {
            factorisations: self.factorisations - before.factorisations,
            factorisation_s: self.factorisation_s - before.factorisation_s,
            solves: self.solves - before.solves,
            solve_s: self.solve_s - before.solve_s,
            evaluations: self.evaluations - before.evaluations,
            evaluation_s: self.evaluation_s - before.evaluation_s,
            low_rank_factorisations: self.low_rank_factorisations - before.low_rank_factorisations,
            low_rank_rows: self.low_rank_rows - before.low_rank_rows,
            modal_eliminations: self.modal_eliminations - before.modal_eliminations,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_difference_counts_what_was_recorded() {
        let before = reading();
        add(Work::LowRankRows, 3);
        record(Work::Solve, Instant::now());
        let done = reading().since(&before);
        // Other tests may add work meanwhile: at least what this one recorded.
        assert!(done.low_rank_rows >= 3);
        assert!(done.solves >= 1);
        assert!(done.solve_s >= 0.0);
    }
}
