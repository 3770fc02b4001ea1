//! The contact-count benchmark (`fricbound bench contacts`): what one limit curve of the
//! reduced 2D blade pair costs as the contact faces are refined, per formulation and linear
//! solver.
//!
//! Each case is the blade pair of [`scaling::reduced_problem`] (generator refinement 2, 20
//! fixed-interface modes) with its contact faces refined `contact_refine` times (4, 8, 16, 32
//! give 25, 49, 97 and 193 pairs per side), solved at harmonics 0..H as one limit curve
//! (m = +1 on every contact point) of at most `max_points` continuation points, the case that
//! `examples/limit_curve_timing` times. A case reports its unknowns, the formulation and linear
//! solver, the Newton iterations, factorisations, Krylov iterations and preconditioner builds
//! ([`crate::numerics::work`]), the wall time per curve and per Newton iteration and where it
//! went (factorisations, solves, preconditioner builds, residual and Jacobian evaluations),
//! the peak resident memory of the curve, and the refined resonance peaks of the curve (to
//! compare formulations).
//!
//! Peak memory: the cases run in one process, so before each curve the process's resident
//! high-water mark is reset (`5` written to `/proc/self/clear_refs`, Linux) and `VmHWM` of
//! `/proc/self/status` is read after it: the figure is the peak while that curve ran, the model
//! and the allocator's retained memory included. Where the reset is refused the figure is the
//! process's peak so far, and the measure says so (`memory_reset = false`).

use std::path::Path;
use std::time::Instant;

use crate::analysis::{frf, peaks};
use crate::contact::ContactState;
use crate::model::{Formulation, JacobianStrategy};
use crate::numerics::work;
use crate::study::scaling::{self, ModelSize, ScalingError, SolverConfig};

/// Generator refinement of the blade pair of every case.
pub const REFINE: usize = 2;

/// Fixed-interface modes of the reduction.
pub const MODES: usize = 20;

/// One case: contact refinement, highest harmonic, formulation, continuation points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactCase {
    /// Extra refinement of the contact faces and the damper.
    pub contact_refine: usize,
    /// Highest harmonic H.
    pub harmonics: usize,
    /// Formulation (`auto` resolved per case).
    pub formulation: Formulation,
    /// Most continuation points of the curve.
    pub max_points: usize,
}

/// What one case measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ContactMeasure {
    /// Extra refinement of the contact faces.
    pub contact_refine: usize,
    /// Contact pairs per damper side.
    pub pairs_per_side: usize,
    /// Highest harmonic H.
    pub harmonics: usize,
    /// Unknowns of Newton's iteration.
    pub unknowns: usize,
    /// Formulation solved (`auto` resolved).
    pub formulation: String,
    /// Its linear solver.
    pub linear_solver: String,
    /// Continuation points of the curve.
    pub points: usize,
    /// Whether the curve covered its window within the points allowed.
    pub complete: bool,
    /// Newton iterations (as the continuation counts them: three chord steps are one).
    pub newton_iterations: usize,
    /// Linear-algebra work and its time during the curve.
    pub work: work::WorkReading,
    /// Wall time of the curve (s).
    pub curve_s: f64,
    /// Wall time per Newton iteration (ms).
    pub per_iteration_ms: f64,
    /// Peak resident memory during the curve (bytes), where known.
    pub peak_memory_bytes: Option<u64>,
    /// Whether the high-water mark was reset before the curve (else the process's peak).
    pub memory_reset: bool,
    /// Refined resonance peaks of the first output: (frequency Hz, amplitude m).
    pub peaks: Vec<(f64, f64)>,
    /// Mean over the curve's points of the fraction of contact points that slip or lift off
    /// for part of the period (neither stuck nor open throughout): the contacts whose
    /// Jacobian couples harmonics, which the Krylov preconditioner leaves out.
    pub slipping_fraction: f64,
}

/// Resets the process's resident high-water mark; false where Linux's `clear_refs` is absent
/// or refused.
fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The process's resident high-water mark `VmHWM` (bytes), where known.
pub fn peak_memory_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Runs one case, its mesh written into `dir`; with `refine_peaks` the curve's resonance
/// peaks are refined after it (not timed).
pub fn measure_case(
    case: &ContactCase,
    dir: &Path,
    refine_peaks: bool,
) -> Result<ContactMeasure, ScalingError> {
    let size = ModelSize {
        three_d: false,
        refine: REFINE,
        contact_refine: case.contact_refine,
        contact_pairs: None,
    };
    let reduced = scaling::reduced_problem(size, MODES, dir)?;
    let config = SolverConfig {
        harmonics: case.harmonics,
        formulation: case.formulation,
        jacobian: JacobianStrategy::Analytic,
        m: 1.0,
    };
    let mut p = config.apply(&reduced);
    p.analysis.continuation.max_points = case.max_points;
    let formulation = p.formulation();
    let memory_reset = reset_peak_memory();
    let before = work::reading();
    let started = Instant::now();
    let mut points = Vec::new();
    let outcome = frf::solve(&p, &mut Collect(&mut points));
    let curve_s = started.elapsed().as_secs_f64();
    let done = work::reading().since(&before);
    let peak_memory_bytes = peak_memory_bytes();
    let newton_iterations: usize = points.iter().map(|q| q.newton_iterations).sum();
    let slipping_fraction = points
        .iter()
        .map(|q| {
            let slipping = q
                .states
                .iter()
                .filter(|s| !matches!(s, ContactState::Stuck | ContactState::Open))
                .count();
            slipping as f64 / q.states.len().max(1) as f64
        })
        .sum::<f64>()
        / points.len().max(1) as f64;
    let peaks = if refine_peaks && !points.is_empty() {
        peaks::path_peaks(&p, &points)
            .map_err(|e| ScalingError::Setup(e.to_string()))?
            .first()
            .map(|list| list.iter().map(|k| (k.freq_hz, k.amplitude)).collect())
            .unwrap_or_default()
    } else {
        Vec::new()
    };
    Ok(ContactMeasure {
        contact_refine: case.contact_refine,
        pairs_per_side: p.contacts.len() / p.sides.len().max(1),
        harmonics: case.harmonics,
        unknowns: scaling::unknowns(&p),
        formulation: scaling::formulation_name(formulation).to_string(),
        linear_solver: crate::hbm::cost::linear_solver_description(&p, formulation),
        points: points.len(),
        complete: outcome.as_ref().is_ok_and(|run| run.is_complete()),
        newton_iterations,
        work: done,
        curve_s,
        per_iteration_ms: 1e3 * curve_s / newton_iterations.max(1) as f64,
        peak_memory_bytes,
        memory_reset,
        peaks,
        slipping_fraction,
    })
}

/// The exponent a of time per Newton iteration ∝ (contact pairs per side)^a, fitted by least
/// squares in log-log over the measures of one H and formulation with at least `min_pairs`
/// pairs per side; None with fewer than two such measures.
pub fn fitted_exponent(
    measures: &[ContactMeasure],
    harmonics: usize,
    formulation: &str,
    min_pairs: usize,
) -> Option<f64> {
    let xy: Vec<(f64, f64)> = measures
        .iter()
        .filter(|m| {
            m.harmonics == harmonics
                && m.formulation == formulation
                && m.pairs_per_side >= min_pairs
                && m.newton_iterations > 0
        })
        .map(|m| ((m.pairs_per_side as f64).ln(), m.per_iteration_ms.ln()))
        .collect();
    if xy.len() < 2 {
        return None;
    }
    let k = xy.len() as f64;
    let (mx, my) = (
        xy.iter().map(|p| p.0).sum::<f64>() / k,
        xy.iter().map(|p| p.1).sum::<f64>() / k,
    );
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Collects FRF points (also when the run fails part-way).
struct Collect<'a>(&'a mut Vec<frf::FrfPoint>);

impl frf::FrfObserver for Collect<'_> {
    fn point(&mut self, point: &frf::FrfPoint) {
        self.0.push(point.clone());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measure(pairs: usize, ms: f64) -> ContactMeasure {
        ContactMeasure {
            contact_refine: 1,
            pairs_per_side: pairs,
            harmonics: 5,
            unknowns: 0,
            formulation: "schur".into(),
            linear_solver: String::new(),
            points: 1,
            complete: true,
            newton_iterations: 1,
            work: Default::default(),
            curve_s: 0.0,
            per_iteration_ms: ms,
            peak_memory_bytes: None,
            memory_reset: false,
            peaks: Vec::new(),
            slipping_fraction: 0.0,
        }
    }

    #[test]
    fn the_fitted_exponent_recovers_a_power_law() {
        let m: Vec<ContactMeasure> = [25, 49, 97, 193]
            .iter()
            .map(|&p| measure(p, 3.0 * (p as f64).powf(2.4)))
            .collect();
        let a = fitted_exponent(&m, 5, "schur", 49).unwrap();
        assert!((a - 2.4).abs() < 1e-12, "{a}");
        assert!(fitted_exponent(&m, 3, "schur", 49).is_none());
        assert!(fitted_exponent(&m, 5, "schur", 150).is_none());
    }
}
