//! The error estimate of a nonlinear-mode point: how much its frequency, modal damping ratio
//! and first-harmonic amplitude at the mode's DOF change when the harmonic set is raised.
//!
//! The point (ψ, ω, ξ) at modal amplitude a is padded with zero coefficients for the harmonics
//! H+1 … 2H+1 ([`extended_harmonic`], as the forced response's truncation estimate,
//! [`crate::analysis::error_estimate`]) and solved by Newton on the EPMC system of the extended
//! set at the same a (the same normalisation and phase condition, the same
//! static state at rest, and at least 2(2H+1)+1 samples per period). The estimate of each
//! property is its relative change, |ω' − ω| / ω, |D' − D| / |D| and |A' − A| / A: what a run
//! at 2H + 1 gives at the same modal amplitude. On the 1-DOF Jenkins oscillator at H = 1 and 3
//! it equals the change to an independent run at 2H + 1 within 1 % at every point (the ratio
//! 1.000 to three digits); against a run at H = 15 it is 0.15-16 times the true change point by
//! point at H = 1 (near the slip onset the harmonics above 3 still matter) and 0.01-2.9 at
//! H = 3 (`tests/it/nonlinear_modes/checks.rs`). Where several contacts slip and lift off
//! (the paper's 2nd mode) the extended system may have several solutions near the point and
//! Newton may not reach one: 2 of 63 points at H = 1 and 47 of 317 at H = 3 are not sized
//! there.
//!
//! The extended system is solved by Newton from the padded point, and from the previous
//! point's extended solution where that fails (ψ is normalised, so it changes little from
//! point to point; where a contact's regime changes with the harmonics the padded point can
//! lie outside Newton's reach). Unlike the forced response's estimate, no point is sized from
//! its first Newton steps: ω and D change only through the contacts' response to the new
//! harmonics while the residual is dominated by those harmonics' own rows, so a step within
//! the forced response's linear range gave 0.07-5.4 times the converged change of the
//! frequency on the 1-DOF Jenkins oscillator, and two steps kept where the second changed
//! little sized a third of that oscillator's points and almost none of the paper's modes, with
//! no run time saved. Where the padded point already solves the extended system within the
//! run's residual tolerance (every contact stuck or open all period, the forces linear in the
//! motion) the estimate is 0 without a solve, so that the round-off of a vanishing damping
//! ratio is not read as a relative change. Where the solve does not converge the estimate is
//! NaN and reported as not sized. Sampling is not estimated: the extended set is solved at
//! enough samples for its own harmonics, and with the event-resolved laws the samples only
//! bracket the transitions. How many points took which way is counted ([`EstimateCounts`],
//! `estimate_counts` in `modes_nl.json`).
//!
//! Cost per point: a Newton solve of the dense EPMC system on 2H + 1 harmonics (about
//! (2H + 1)/H times the unknowns of the run); one that does not converge takes up to three
//! times the run's iteration limit (less where its residual stagnates), twice where the second
//! start fails too. Measured run times: docs/src/nonlinear-modes.md, "Accuracy of each
//! point".

use std::f64::consts::TAU;

use super::operator::{EpmcOperator, LogAmplitude};
use crate::analysis::error_estimate::extended_harmonic;
use crate::contact::harmonic::HarmonicSet;
use crate::model::Problem;
use crate::numerics::continuation::StagnationExit;
use crate::numerics::{Continuation, ParametricResidual};

/// The error estimate of a mode point (relative changes when the harmonics are raised to
/// 2H + 1; NaN where the extended system could not be solved).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ModeAccuracy {
    /// |ω' − ω| / ω (–).
    pub frequency: f64,
    /// |D' − D| / |D| (–).
    pub damping_ratio: f64,
    /// |A' − A| / A, A the first-harmonic amplitude at the mode's DOF (–).
    pub dof_amplitude: f64,
    /// Highest harmonic of the set compared with (2H + 1).
    pub harmonic: usize,
}

impl ModeAccuracy {
    /// The three estimates in the order frequency, damping ratio, amplitude at the DOF.
    pub fn values(&self) -> [f64; 3] {
        [self.frequency, self.damping_ratio, self.dof_amplitude]
    }

    /// Whether the estimate could be formed.
    pub fn is_sized(&self) -> bool {
        self.values().iter().all(|v| v.is_finite())
    }
}

/// What the estimate compares of a point: its modal amplitude a (kg^½·m), ω (rad/s), ξ (1/s),
/// damping ratio and first-harmonic amplitude at the DOF (m).
pub(super) struct PointValues {
    pub(super) modal_amplitude: f64,
    pub(super) omega: f64,
    pub(super) xi: f64,
    pub(super) damping_ratio: f64,
    pub(super) dof_amplitude: f64,
}

/// What the estimator needs of the run: the extended EPMC system and a Newton driver for it.
pub(super) struct ModeEstimator<'p> {
    op: EpmcOperator<'p>,
    newton: Continuation,
    /// For each block of the run's set, its index in the extended set.
    block_index: Vec<usize>,
    n: usize,
    /// The run's residual tolerance (relative to the residual scale).
    tolerance: f64,
    dof: usize,
    harmonic: usize,
    /// The last extended solution (ψ', ω', ξ'), the second start of the next point's solve.
    last: Option<Vec<f64>>,
    /// How the estimates so far were formed.
    pub(super) counts: EstimateCounts,
}

/// The autonomous problem `free` on the harmonic set extended to 2H + 1, with at least
/// 2(2H + 1) + 1 samples per period (the scene's count doubled until it resolves them).
pub fn extended_problem(free: &Problem) -> Problem {
    let h = free.harmonics.iter().copied().max().unwrap_or(1);
    let top = extended_harmonic(h);
    let mut extended = free.clone();
    extended.harmonics = free.harmonics.iter().copied().chain(h + 1..=top).collect();
    extended.harmonics.sort_unstable();
    extended.harmonics.dedup();
    while extended.samples <= 2 * top {
        extended.samples *= 2;
    }
    extended
}

impl<'p> ModeEstimator<'p> {
    /// The estimator of a run on `extended` ([`extended_problem`] of the run's autonomous
    /// problem `free`), about the static state `statics`, with the run's phase DOF, amplitude
    /// map, row weight and Newton driver (`newton`, whose scale is per unknown of the run: it
    /// is spread over the extended blocks by harmonic). A solve gets the run's iterations, and
    /// further ones (up to three times as many) only while its residual keeps falling
    /// ([`StagnationExit`], as the forced response's estimate).
    pub(super) fn new(
        free: &Problem,
        extended: &'p Problem,
        (statics, dof): (Vec<f64>, usize),
        (map, row_scale): (LogAmplitude, f64),
        newton: &Continuation,
    ) -> Result<Self, crate::hbm::HbmError> {
        let op = EpmcOperator::new(extended, statics, dof, map, row_scale)?;
        let run_set = free.unknown_harmonics();
        let ext_set = op.unknowns().clone();
        let n = free.model.n_dofs();
        let block_index: Vec<usize> = run_set
            .blocks()
            .iter()
            .map(|b| {
                ext_set
                    .blocks()
                    .iter()
                    .position(|c| c == b)
                    .expect("the extended set holds the run's harmonics")
            })
            .collect();
        let scale = spread_scale(&newton.x_scale, &run_set, &ext_set, n);
        Ok(Self {
            op,
            newton: Continuation::new(newton.settings, scale).with_stagnation_exit(
                StagnationExit {
                    after: newton.settings.max_iterations,
                },
            ),
            block_index,
            n,
            tolerance: newton.settings.residual_tolerance,
            dof,
            harmonic: ext_set.max_harmonic(),
            last: None,
            counts: EstimateCounts::default(),
        })
    }

    /// The estimate of the point `point`, whose normalised harmonics are `psi` (the run's
    /// layout): the extended system solved from the padded point, else from the previous
    /// point's extended solution.
    pub(super) fn estimate(&mut self, point: &PointValues, psi: &[f64]) -> ModeAccuracy {
        let n = self.n;
        let dim_h = self.op.harmonic_dim();
        let mut y = vec![0.0; dim_h + 2];
        for (j, &e) in self.block_index.iter().enumerate() {
            y[e * n..(e + 1) * n].copy_from_slice(&psi[j * n..(j + 1) * n]);
        }
        y[dim_h] = point.omega;
        y[dim_h + 1] = point.xi;
        let map = self.op.map();
        let lambda = TAU * map.decade(point.modal_amplitude);
        let not_sized = ModeAccuracy {
            frequency: f64::NAN,
            damping_ratio: f64::NAN,
            dof_amplitude: f64::NAN,
            harmonic: self.harmonic,
        };
        let mut r = vec![0.0; y.len()];
        if self.op.residual(&y, lambda, &mut r).is_err() {
            return not_sized;
        }
        let padded = crate::numerics::linalg::norm(&r) / self.op.residual_scale();
        if padded <= self.tolerance {
            self.counts.converged += 1;
            return ModeAccuracy {
                frequency: 0.0,
                damping_ratio: 0.0,
                dof_amplitude: 0.0,
                harmonic: self.harmonic,
            };
        }
        let Some(solution) = self.solve(&y, lambda) else {
            self.counts.not_sized += 1;
            return not_sized;
        };
        self.counts.solved += 1;
        let [omega, damping_ratio, amplitude] = self.values(&solution, point.modal_amplitude);
        self.last = Some(solution);
        ModeAccuracy {
            frequency: relative_change(omega, point.omega),
            damping_ratio: relative_change(damping_ratio, point.damping_ratio),
            dof_amplitude: relative_change(amplitude, point.dof_amplitude),
            harmonic: self.harmonic,
        }
    }

    /// (ω, D, A) of the extended unknowns `y` at modal amplitude `a`: A the first-harmonic
    /// amplitude at the DOF (m).
    fn values(&self, y: &[f64], a: f64) -> [f64; 3] {
        let dim_h = self.op.harmonic_dim();
        let (omega, xi) = (y[dim_h], y[dim_h + 1]);
        let (cos1, sin1) = self.op.first_harmonic();
        let at = |block: usize| y[block * self.n + self.dof];
        [omega, xi / (2.0 * omega), a * at(cos1).hypot(at(sin1))]
    }

    /// The extended system solved to convergence at λ from `from`, else from the previous
    /// point's extended solution.
    fn solve(&mut self, from: &[f64], lambda: f64) -> Option<Vec<f64>> {
        if let Ok(p) = self.newton.solve_fixed(&mut self.op, from, lambda) {
            return Some(p.x);
        }
        let last = self.last.clone()?;
        self.newton
            .solve_fixed(&mut self.op, &last, lambda)
            .ok()
            .map(|p| p.x)
    }
}

/// How the estimates of a run were formed: points whose padded point already solved the
/// extension, points solved to convergence, points not sized.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct EstimateCounts {
    /// The padded point solves the extended system (estimate 0).
    pub converged: usize,
    /// Solved to convergence.
    pub solved: usize,
    /// The extended system could not be solved.
    pub not_sized: usize,
}

/// |new − old| / |old|; 0 where they are equal (also both 0).
fn relative_change(new: f64, old: f64) -> f64 {
    if new == old {
        0.0
    } else {
        (new - old).abs() / old.abs()
    }
}

/// The run's arc-length scale (per unknown of `run`, then ω and ξ) on the extended set: each
/// new block takes the scale of the run's first-harmonic cosine block (the run's scale is the
/// same for every block of harmonic h ≥ 1).
fn spread_scale(scale: &[f64], run: &HarmonicSet, ext: &HarmonicSet, n: usize) -> Vec<f64> {
    let reference = run.cos_block(1).unwrap_or(0);
    let mut out = Vec::with_capacity(ext.n_blocks() * n + 2);
    for b in ext.blocks() {
        let j = run
            .blocks()
            .iter()
            .position(|c| c == b)
            .unwrap_or(reference);
        out.extend_from_slice(&scale[j * n..(j + 1) * n]);
    }
    out.extend_from_slice(&scale[run.n_blocks() * n..]);
    out
}
