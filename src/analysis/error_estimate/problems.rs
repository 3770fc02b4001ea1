//! The refined problems an estimate puts a point into (the harmonic set extended to 2H + 1 or
//! 4H + 3, twice the samples) and their operators, built once per run.

use crate::contact::harmonic::HarmonicSet;
use crate::contact::point::ContactState;
use crate::hbm::operator::HbmOperator;
use crate::hbm::HbmError;
use crate::model::{Formulation, Problem};
use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::ParametricResidual;

/// The two refined problems the estimate puts a point into: the harmonic set extended to 2H, and
/// the same set at twice the samples. Built once per run (see
/// [`ErrorEstimator`](super::ErrorEstimator)).
#[derive(Debug, Clone)]
pub struct EstimateProblems {
    /// The problem on the extended harmonic set (up to 2H + 1).
    pub truncation: Problem,
    /// The problem on the wider set (up to [`wider_harmonic`], 4H + 3), for the points whose
    /// first extension has not converged in its own harmonics ([`TailTest`](super::TailTest)).
    pub wider: Problem,
    /// The problem at twice the samples per period.
    pub sampling: Problem,
}

impl EstimateProblems {
    /// The refined problems of `problem`, or None when its scene switched the estimate off.
    pub fn new(problem: &Problem) -> Option<Self> {
        if !problem.analysis.error_estimate.enabled {
            return None;
        }
        let h = problem.harmonics.iter().copied().max().unwrap_or(1);
        let extended_to = |top: usize| {
            let mut extended = problem.clone();
            extended.harmonics = problem
                .harmonics
                .iter()
                .copied()
                .chain(h + 1..=top)
                .collect();
            extended.harmonics.sort_unstable();
            extended.harmonics.dedup();
            while extended.samples <= 2 * top {
                extended.samples *= 2;
            }
            extended.analysis.formulation = extended_formulation(problem, &extended);
            extended
        };
        let mut sampling = problem.clone();
        sampling.samples = 2 * problem.samples;
        Some(Self {
            truncation: extended_to(extended_harmonic(h)),
            wider: extended_to(wider_harmonic(h)),
            sampling,
        })
    }
}

/// The formulation of the extended system: the one the cost model picks for the extended
/// problem (`auto`, for its own size, which at 2H + 1 harmonics is often another than the
/// run's: on the reduced blade pair schur factorises 196 rows where dense factorises 539), as
/// long as it has the run's unknowns (every DOF per block, or the contact DOFs alone for the
/// condensed formulation), since the sampling step moves the run's residual onto the extended
/// unknowns; otherwise the run's formulation. The Newton step, hence the estimate, is the same
/// in every formulation up to round-off.
fn extended_formulation(problem: &Problem, extended: &Problem) -> Formulation {
    let run = problem.formulation();
    let mut auto = extended.clone();
    auto.analysis.formulation = Formulation::Auto;
    let picked = auto.formulation();
    if (picked == Formulation::Condensed) == (run == Formulation::Condensed) {
        picked
    } else {
        run
    }
}

/// The highest harmonic of the truncation estimate's extended set for a scene whose highest
/// harmonic is `h`: 2H + 1. A first-harmonic motion through a Jenkins element gives odd
/// harmonics first (the slip reversals are symmetric over the period), so at H = 1 the set must
/// reach the 3rd harmonic for the estimate to see what matters.
pub fn extended_harmonic(h: usize) -> usize {
    2 * h + 1
}

/// The highest harmonic of the wider set, the cap of the adaptive extension: the first
/// extension applied twice, 2(2H + 1) + 1 = 4H + 3 (7 at H = 1, where the upper branch of the
/// blade pair holds its error in harmonics 6-7: docs/accuracy.md).
pub fn wider_harmonic(h: usize) -> usize {
    extended_harmonic(extended_harmonic(h))
}

/// One refined operator and a Jacobian in its storage (pattern built once).
pub(super) struct Refined<'p> {
    pub(super) operator: HbmOperator<'p>,
    pub(super) jacobian: AssembledJacobian,
    /// For each block of the base unknowns, its index among the refined operator's blocks.
    block_of: Vec<usize>,
}

impl<'p> Refined<'p> {
    pub(super) fn new(problem: &'p Problem, base: &HarmonicSet) -> Result<Self, HbmError> {
        let mut operator = HbmOperator::new(problem)?;
        let jacobian = operator.new_jacobian();
        let refined = operator.unknowns().clone();
        let block_of = base
            .blocks()
            .iter()
            .map(|b| {
                refined
                    .blocks()
                    .iter()
                    .position(|c| c == b)
                    .expect("the refined set holds the base set")
            })
            .collect();
        Ok(Self {
            operator,
            jacobian,
            block_of,
        })
    }

    /// The base point `x` (full coefficients on the base set, `n` DOFs) padded with zeros on
    /// the refined set, in the refined operator's unknowns.
    pub(super) fn padded(&self, n: usize, x: &[f64]) -> Vec<f64> {
        let set = self.operator.unknowns();
        let mut padded = vec![0.0; n * set.n_blocks()];
        for (j, &jr) in self.block_of.iter().enumerate() {
            padded[jr * n..(jr + 1) * n].copy_from_slice(&x[j * n..(j + 1) * n]);
        }
        self.operator.restrict(&padded)
    }

    /// `r` (a residual in the unknowns of an operator on the base set, `base_blocks` blocks)
    /// placed on the kept blocks of this operator's unknowns, zero on the others; None when
    /// the block sizes differ.
    pub(super) fn on_kept_blocks(&self, r: &[f64], base_blocks: usize) -> Option<Vec<f64>> {
        let blocks = self.operator.unknowns().n_blocks();
        let dim = self.operator.dim();
        let size = dim / blocks.max(1);
        if r.len() != size * base_blocks || self.block_of.len() != base_blocks {
            return None;
        }
        let mut out = vec![0.0; dim];
        for (j, &jr) in self.block_of.iter().enumerate() {
            out[jr * size..(jr + 1) * size].copy_from_slice(&r[j * size..(j + 1) * size]);
        }
        Some(out)
    }

    /// `r` (in this operator's unknowns) with the blocks of the upper half of the harmonics
    /// above `h` (above ⌈3h/2⌉) set to zero.
    pub(super) fn lower_half(&self, r: &[f64], h: usize) -> Vec<f64> {
        let set = self.operator.unknowns();
        let size = r.len() / set.n_blocks().max(1);
        let split = (3 * h).div_ceil(2);
        let mut low = r.to_vec();
        for (j, block) in set.blocks().iter().enumerate() {
            if block.harmonic() > split {
                low[j * size..(j + 1) * size].fill(0.0);
            }
        }
        low
    }

    /// The contact states of `xr − δ` at ω and the norm of the residual there (one residual
    /// evaluation); None when it fails.
    pub(super) fn after_step(
        &mut self,
        xr: &[f64],
        delta: &[f64],
        omega: f64,
    ) -> Option<(Vec<ContactState>, f64)> {
        let stepped: Vec<f64> = xr.iter().zip(delta).map(|(a, d)| a - d).collect();
        let mut r = vec![0.0; stepped.len()];
        self.operator.residual(&stepped, omega, &mut r).ok()?;
        Some((
            self.operator.states().to_vec(),
            crate::numerics::linalg::norm(&r),
        ))
    }

    /// Full coefficients of `xr − δ` (refined unknowns); None when not finite.
    pub(super) fn stepped(&mut self, xr: &[f64], delta: &[f64], omega: f64) -> Option<Vec<f64>> {
        let stepped: Vec<f64> = xr.iter().zip(delta).map(|(a, d)| a - d).collect();
        let full = self.operator.expand(&stepped, omega).ok()?;
        full.iter().all(|v| v.is_finite()).then_some(full)
    }
}

/// First-harmonic amplitude √(c₁² + s₁²) of each output DOF from full coefficients on `set`.
pub(super) fn amplitudes(problem: &Problem, set: &HarmonicSet, x: &[f64]) -> Vec<f64> {
    let n = problem.model.n_dofs();
    let (c1, s1) = (set.cos_block(1), set.sin_block(1));
    problem
        .outputs
        .iter()
        .map(|&d| {
            let c = c1.map_or(0.0, |j| x[j * n + d]);
            let s = s1.map_or(0.0, |j| x[j * n + d]);
            c.hypot(s)
        })
        .collect()
}

/// |a − b| / b per output (0 where both are 0, infinite where only b is).
pub(super) fn relative_changes(refined: &[f64], base: &[f64]) -> Vec<f64> {
    refined
        .iter()
        .zip(base)
        .map(|(&a, &b)| {
            let change = (a - b).abs();
            if change == 0.0 {
                0.0
            } else {
                change / b.abs()
            }
        })
        .collect()
}
