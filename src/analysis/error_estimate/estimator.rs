//! The estimate of one converged point: the padded residual, the Newton step on the extended
//! set (fixed frequency or across the path), the sampling step, and the wider set where needed.

use super::problems::{
    amplitudes, extended_harmonic, relative_changes, wider_harmonic, EstimateProblems, Refined,
};
use super::report::{EstimateMethod, PathPlace, PathSwitch, PointAccuracy};
use super::rules::{beyond_budget, solves_padded, LinearRange, SolveBudget, TailTest};
use crate::contact::harmonic::HarmonicSet;
use crate::contact::point::ContactState;
use crate::hbm::operator::HbmOperator;
use crate::hbm::HbmError;
use crate::model::Problem;
use crate::numerics::continuation::{Continuation, StagnationExit};
use crate::numerics::ParametricResidual;

/// The truncation estimate on the wider set (4H + 3).
pub(super) struct Wider {
    /// Whether the padded point already solves the wider system within the Newton tolerance
    /// ([`solves_padded`]).
    pub(super) padded_converged: bool,
    /// At the fixed frequency, per output.
    pub(super) fixed: Vec<f64>,
    /// The fixed-frequency step's contraction ([`LinearRange`]); NaN where the point reports
    /// the step across the path (not evaluated).
    pub(super) fixed_contraction: f64,
    /// Across the path (per output) and that step's contraction (NaN where the point reports
    /// the fixed-frequency step), where the path's normal was given and the bordered matrix
    /// factorised.
    pub(super) across: Option<(Vec<f64>, f64)>,
    /// The fixed-frequency step (wider unknowns), for the start of a converged solve.
    pub(super) fixed_step: Vec<f64>,
    /// The across-path step (wider unknowns, then δω in rad/s), where formed, for the start of
    /// a converged solve across the path.
    pub(super) across_step: Option<Vec<f64>>,
}

/// What one set of Newton steps (across the path or at the fixed frequency) gives on the
/// first extension. The contraction and the regime change are evaluated for the set the point
/// reports only (one residual at the stepped point); the other set's are NaN and false.
struct Assessed {
    /// Truncation estimate per output.
    pub(super) truncation: Vec<f64>,
    /// Whether [`TailTest`] sends the point to the wider set.
    needs_wider: bool,
    /// Whether the truncation step changes a contact's regime.
    changes_regime: bool,
    /// The truncation step's contraction ([`LinearRange`]).
    pub(super) contraction: f64,
    /// Sampling estimate per output.
    pub(super) sampling: Vec<f64>,
}

/// Estimates the truncation and sampling errors of converged points of one problem, reusing
/// the refined operators (and their Jacobian patterns) from point to point.
pub struct ErrorEstimator<'p> {
    pub(super) problem: &'p Problem,
    pub(super) set: HarmonicSet,
    pub(super) truncation: Refined<'p>,
    /// The wider set (4H + 3), for points whose first extension has not converged.
    pub(super) wider: Refined<'p>,
    /// The problem's highest harmonic H.
    pub(super) h_max: usize,
    /// The operator at twice the samples (residuals only).
    pub(super) sampling: HbmOperator<'p>,
    /// For each of the run's unknowns, its index among the full coefficients (the run's
    /// operator restricts by selection).
    pub(super) full_index: Vec<usize>,
    /// A pool of one thread that every estimate runs on ([`Self::on_one_thread`]); None where
    /// the thread could not be started (the estimate then runs on the caller's thread).
    one_thread: Option<rayon::ThreadPool>,
    /// On which extended sets a point whose step leaves its linear range is solved, and whether the
    /// points [`TailTest`] and [`WidenGate`](super::WidenGate) send to the wider set are stepped on
    /// it (where not, they are flagged with their 2H + 1 estimate).
    pub(super) budget: SolveBudget,
}

impl<'p> ErrorEstimator<'p> {
    /// An estimator for converged points of `problem` (full coefficients on its unknown
    /// harmonics), on the refined problems `refined` built from it.
    pub fn new(problem: &'p Problem, refined: &'p EstimateProblems) -> Result<Self, HbmError> {
        let set = problem.unknown_harmonics();
        let sampling = HbmOperator::new(&refined.sampling)?;
        let positions: Vec<f64> = (0..problem.model.n_dofs() * set.n_blocks())
            .map(|i| i as f64)
            .collect();
        let full_index = sampling
            .restrict(&positions)
            .iter()
            .map(|&i| i as usize)
            .collect();
        Ok(Self {
            problem,
            budget: SolveBudget::new(problem, refined),
            truncation: Refined::new(&refined.truncation, &set)?,
            wider: Refined::new(&refined.wider, &set)?,
            h_max: problem.harmonics.iter().copied().max().unwrap_or(1),
            sampling,
            set,
            full_index,
            one_thread: rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .thread_name(|_| "error-estimate".to_string())
                .build()
                .ok(),
        })
    }
}

impl<'p> ErrorEstimator<'p> {
    /// Runs `work` on the estimator's pool of one thread, so that the dense factorisations of
    /// the extended systems (faer, whose default parallelism spreads a factorisation over
    /// rayon's threads, the pool's own there) run sequentially. The extended systems are 2-5×
    /// the run's, large enough for faer to split their factorisations; on the larger blade pair
    /// at H = 1 the split factorisations cost 30 s of user and 9 s of system CPU against 24 s
    /// and 0.1 s on one thread, with the same wall time and identical results, on the 2-core
    /// machine shared with other jobs (docs/accuracy.md, "What the estimate costs, and where
    /// the time goes"). Where the pool could not be started, `work` runs on the caller's thread.
    pub(super) fn on_one_thread<R: Send>(&mut self, work: impl FnOnce(&mut Self) -> R + Send) -> R {
        match self.one_thread.take() {
            Some(pool) => {
                let out = pool.install(|| work(self));
                self.one_thread = Some(pool);
                out
            }
            None => work(self),
        }
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The border row on the extended unknowns for the path normal `normal` (the run's
    /// unknowns, then ω), and the same normal on the full coefficients; None when it does not
    /// fit or is not finite.
    fn border(&self, normal: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let row = self.row_on(&self.truncation, normal)?;
        let (&on_omega, on_x) = normal.split_last()?;
        let mut full = vec![0.0; self.problem.model.n_dofs() * self.set.n_blocks() + 1];
        for (&i, &w) in self.full_index.iter().zip(on_x) {
            full[i] = w;
        }
        *full.last_mut()? = on_omega;
        Some((row, full))
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The estimate at the converged point `x` (full coefficients, harmonic-major) solved at
    /// ω = `omega` (rad/s): one residual and Jacobian of the extended system, factorised once
    /// for both Newton steps (truncation: its own residual; sampling: the residual at twice
    /// the samples on the kept harmonics). With the path's `normal` (in the run operator's
    /// unknowns then ω, as [`crate::numerics::Observer::accepted`] gives it) the steps are
    /// bordered with it (across the path), else at the fixed frequency; a bordered matrix
    /// that cannot be factorised falls back to the fixed frequency.
    ///
    /// `states` are the point's contact states: a contact stuck all period sends the point on
    /// to the wider set when its estimate is not negligible ([`TailTest`]).
    ///
    /// Runs on the estimator's own thread ([`Self::on_one_thread`]).
    pub fn estimate(
        &mut self,
        x: &[f64],
        omega: f64,
        path: Option<PathPlace>,
        states: &[ContactState],
    ) -> PointAccuracy {
        self.on_one_thread(|e| e.estimate_here(x, omega, path, states))
    }
}

impl<'p> ErrorEstimator<'p> {
    /// The estimate of a point whose padding `xr` (the point `x` with zero harmonics
    /// H+1 … 2H+1) already solves the extended system, and whose coefficients already solve
    /// the harmonic balance at twice the samples, within the run's Newton tolerance
    /// ([`solves_padded`]): both estimates are 0, below what the run itself resolves, and
    /// the point costs two residuals instead of a Jacobian and its factorisation
    /// ([`EstimateMethod::Converged`]). None for any other point (or where a residual cannot be
    /// formed: the full estimate then says so).
    fn padding_converges(
        &mut self,
        xr: &[f64],
        x: &[f64],
        omega: f64,
        path: Option<PathPlace>,
        outputs: usize,
    ) -> Option<PointAccuracy> {
        let norm = crate::numerics::linalg::norm;
        let mut r = vec![0.0; xr.len()];
        self.truncation.operator.residual(xr, omega, &mut r).ok()?;
        if !solves_padded(self.problem, &self.truncation.operator, norm(&r)) {
            return None;
        }
        let xs = self.sampling.restrict(x);
        let mut rs = vec![0.0; xs.len()];
        self.sampling.residual(&xs, omega, &mut rs).ok()?;
        if !solves_padded(self.problem, &self.sampling, norm(&rs)) {
            return None;
        }
        let zeros = vec![0.0; outputs];
        let path_normal = path
            .and_then(|p| self.border(p.normal))
            .map(|(_, full)| full);
        Some(PointAccuracy {
            truncation: zeros.clone(),
            sampling: zeros.clone(),
            across_path: false,
            both_truncation: path_normal.as_ref().map(|_| (zeros.clone(), zeros)),
            path_normal,
            slide_and_step: (f64::NAN, path.map_or(f64::NAN, |p| p.step)),
            estimate_harmonic: extended_harmonic(self.h_max),
            step_changes_regime: false,
            contraction: f64::NAN,
            method: EstimateMethod::Converged,
        })
    }
}

impl<'p> ErrorEstimator<'p> {
    /// [`Self::estimate`] on the calling thread.
    fn estimate_here(
        &mut self,
        x: &[f64],
        omega: f64,
        path: Option<PathPlace>,
        states: &[ContactState],
    ) -> PointAccuracy {
        let stuck_contact = states.contains(&ContactState::Stuck);
        let n = self.problem.model.n_dofs();
        let base = amplitudes(self.problem, &self.set, x);
        let nan = || PointAccuracy::not_formed(base.len());
        let xr = self.truncation.padded(n, x);
        // The padded point's residual alone first: a point that already solves the extension
        // costs two residuals and no Jacobian. Any other point marches the extended set again
        // below, with the Jacobian (the operator evaluates both in one march and has no
        // Jacobian-only evaluation): one residual more per such point, against a Jacobian per
        // converged point were the two evaluated together (200 of the paper case's 350 points
        // of `zoom-2nd.toml` are converged, 94 of the 2D blade pair's 3114).
        if let Some(converged) = self.padding_converges(&xr, x, omega, path, base.len()) {
            return converged;
        }
        let dim = xr.len();
        let mut r = vec![0.0; dim];
        let mut dr = vec![0.0; dim];
        if self
            .truncation
            .operator
            .residual_and_jacobian(&xr, omega, &mut r, &mut self.truncation.jacobian, &mut dr)
            .is_err()
        {
            return nan();
        }
        // The sampling residual on the base set, moved onto the extended unknowns.
        let xs = self.sampling.restrict(x);
        let mut rs = vec![0.0; xs.len()];
        let sampling_rhs = self
            .sampling
            .residual(&xs, omega, &mut rs)
            .ok()
            .and_then(|()| self.truncation.on_kept_blocks(&rs, self.set.n_blocks()));
        // The truncation residual on the lower half of the new harmonics alone, for the
        // extension's own convergence ([`TailTest`]).
        let r_low = self.truncation.lower_half(&r, self.h_max);
        let mut rhs: Vec<&[f64]> = vec![&r, &r_low];
        if let Some(s) = &sampling_rhs {
            rhs.push(s);
        }
        let border = path.and_then(|p| self.border(p.normal));
        let mut path_normal = None;
        let mut deltas = None;
        let mut fixed_deltas = None;
        let mut slide = f64::NAN;
        if let Some((row, full)) = border {
            // The path's direction of the extended system, z with row · z = 1: the
            // fixed-frequency steps are the across-path ones slid along z back onto ω.
            let dim_x = dr.len();
            let mut along = vec![0.0; dim_x];
            along.push(1.0);
            let mut with_along = rhs.clone();
            let along_x = along[..dim_x].to_vec();
            with_along.push(&along_x);
            if let Ok(mut d) = self.bordered_steps(&dr, &row, &with_along) {
                let z = d.pop().expect("the path direction was solved");
                let z_omega = z[dim_x];
                let fixed: Vec<Vec<f64>> = d
                    .iter()
                    .map(|step| {
                        let s = step[dim_x] / z_omega;
                        step.iter().zip(&z).map(|(a, b)| a - s * b).collect()
                    })
                    .collect();
                // z has a unit component along the unit tangent of the scaled space, so the
                // slide is an arc length of that space.
                slide = (d[0][dim_x] / z_omega).abs();
                deltas = Some(d);
                fixed_deltas = Some(fixed);
                path_normal = Some(full);
            }
        }
        let deltas = match deltas {
            Some(d) => d,
            None => match self.truncation.jacobian.solve_many(&rhs) {
                // At a fixed frequency: δω = 0.
                Ok(d) => d
                    .into_iter()
                    .map(|mut v| {
                        v.push(0.0);
                        v
                    })
                    .collect(),
                Err(_) => return nan(),
            },
        };
        let ext = self.truncation.operator.unknowns().clone();
        let nan_values = vec![f64::NAN; base.len()];
        let r_norm = crate::numerics::linalg::norm(&r);
        let mut padded_converged = solves_padded(self.problem, &self.truncation.operator, r_norm);
        let mut amplitudes_after = |delta: &[f64], with_states: bool| {
            let (d_omega, d_x) = delta.split_last().expect("a step has a frequency part");
            let values = match self.truncation.stepped(&xr, d_x, omega - d_omega) {
                Some(full) => amplitudes(self.problem, &ext, &full),
                None => nan_values.clone(),
            };
            let moved = with_states
                .then(|| self.truncation.after_step(&xr, d_x, omega - d_omega))
                .flatten();
            (values, moved)
        };
        // Per reported step set (across the path or at the fixed frequency): the truncation
        // estimate, whether its tail needs the wider set, whether the step changes a contact's
        // regime, and the sampling estimate.
        let mut assess = |steps: &[Vec<f64>], reported: bool| {
            let (full, moved) = amplitudes_after(&steps[0], reported);
            let (low, _) = amplitudes_after(&steps[1], false);
            let needs_wider = base
                .iter()
                .zip(&low)
                .zip(&full)
                .any(|((&b, &l), &f)| TailTest::extend(b, l, f, stuck_contact));
            let changes_regime = moved.as_ref().is_some_and(|m| m.0.as_slice() != states);
            let contraction = moved.map_or(f64::NAN, |m| m.1 / r_norm);
            let sampling = match steps.get(2) {
                Some(d) => relative_changes(&amplitudes_after(d, false).0, &base),
                None => nan_values.clone(),
            };
            Assessed {
                truncation: relative_changes(&full, &base),
                needs_wider,
                changes_regime,
                contraction,
                sampling,
            }
        };
        let top = extended_harmonic(self.h_max);
        let step = path.map_or(f64::NAN, |p| p.step);
        // Whether a path point reports the step across the path; a point at a fixed frequency
        // (no path direction) reports its only step set.
        let across = fixed_deltas.is_some() && PathSwitch::across(slide, step);
        let first = assess(&deltas, fixed_deltas.is_none() || across);
        let Some(fixed_steps) = fixed_deltas else {
            let mut truncation = first.truncation.clone();
            let mut estimate_harmonic = top;
            let mut contraction = first.contraction;
            let mut reported_step = deltas[0][..dim].to_vec();
            let widens = first.needs_wider
                && self.widens(&first.truncation, first.contraction, padded_converged);
            if widens && self.budget.wider.steps {
                if let Some(w) = self.wider_truncation(x, omega, None, &base, false) {
                    padded_converged = w.padded_converged;
                    truncation = w.fixed;
                    contraction = w.fixed_contraction;
                    estimate_harmonic = wider_harmonic(self.h_max);
                    reported_step = w.fixed_step;
                }
            }
            let method = self.settle(
                x,
                omega,
                &base,
                (
                    &mut truncation,
                    estimate_harmonic,
                    contraction,
                    padded_converged,
                ),
                (None, &reported_step),
                widens && !self.budget.wider.steps,
            );
            return PointAccuracy {
                truncation,
                sampling: first.sampling,
                across_path: false,
                path_normal: None,
                both_truncation: None,
                slide_and_step: (f64::NAN, step),
                estimate_harmonic,
                step_changes_regime: first.changes_regime,
                contraction,
                method,
            };
        };
        let fixed = assess(&fixed_steps, !across);
        let reported = if across { &first } else { &fixed };
        let mut both = (fixed.truncation.clone(), first.truncation.clone());
        let mut contractions = (fixed.contraction, first.contraction);
        let mut estimate_harmonic = top;
        let mut reported_step = fixed_steps[0][..dim].to_vec();
        // The across-path step with its δω (rad/s), for a converged solve across the path.
        let mut across_step = deltas[0].clone();
        let normal = path.map(|p| p.normal);
        let widens = reported.needs_wider
            && self.widens(&reported.truncation, reported.contraction, padded_converged);
        if widens && self.budget.wider.steps {
            if let Some(w) = self.wider_truncation(x, omega, normal, &base, across) {
                let wider_converged = w.padded_converged;
                if let (Some((a, a_contraction)), Some(a_step)) = (w.across, w.across_step) {
                    padded_converged = wider_converged;
                    both = (w.fixed, a);
                    contractions = (w.fixed_contraction, a_contraction);
                    estimate_harmonic = wider_harmonic(self.h_max);
                    reported_step = w.fixed_step;
                    across_step = a_step;
                } else if !across {
                    padded_converged = wider_converged;
                    both.0 = w.fixed;
                    contractions.0 = w.fixed_contraction;
                    estimate_harmonic = wider_harmonic(self.h_max);
                    reported_step = w.fixed_step;
                }
            }
        }
        let contraction = if across {
            contractions.1
        } else {
            contractions.0
        };
        let mut truncation = if across {
            both.1.clone()
        } else {
            both.0.clone()
        };
        let (normal, settled_step) = if across {
            (normal, &across_step)
        } else {
            (None, &reported_step)
        };
        let method = self.settle(
            x,
            omega,
            &base,
            (
                &mut truncation,
                estimate_harmonic,
                contraction,
                padded_converged,
            ),
            (normal, settled_step),
            widens && !self.budget.wider.steps,
        );
        if method == EstimateMethod::Solved {
            if across {
                both.1 = truncation.clone();
            } else {
                both.0 = truncation.clone();
            }
        }
        PointAccuracy {
            truncation,
            sampling: if across {
                first.sampling.clone()
            } else {
                fixed.sampling.clone()
            },
            across_path: across,
            path_normal,
            both_truncation: Some(both),
            slide_and_step: (slide, step),
            estimate_harmonic,
            step_changes_regime: reported.changes_regime,
            contraction,
            method,
        }
    }
}

impl<'p> ErrorEstimator<'p> {
    /// How the reported truncation estimate stands ([`LinearRange`]): `truncation` (per output,
    /// replaced by the converged extended solution's change where that is solved), the extension it
    /// comes from, its step's contraction, and whether the padded point already solves that
    /// extension within the Newton tolerance ([`solves_padded`]: then the point is the extension's
    /// converged solution, its step a move within round-off whose contraction says nothing, and the
    /// step is kept); `beyond_the_budget` when the point was sent to a wider set the scene's budget
    /// does not step on ([`SetBudget::steps`](super::SetBudget::steps): then it is flagged).
    /// `across` is the path's normal (run unknowns, then ω) when the point reports the step across
    /// the path, `step` the reported step on the extension (with its δω last when across the path).
    fn settle(
        &mut self,
        x: &[f64],
        omega: f64,
        base: &[f64],
        (truncation, estimate_harmonic, contraction, padded_converged): (
            &mut Vec<f64>,
            usize,
            f64,
            bool,
        ),
        (across, step): (Option<&[f64]>, &[f64]),
        beyond_the_budget: bool,
    ) -> EstimateMethod {
        if truncation.iter().any(|v| v.is_nan()) {
            return EstimateMethod::None;
        }
        if beyond_the_budget {
            return beyond_budget(truncation);
        }
        let wider = estimate_harmonic == wider_harmonic(self.h_max);
        // A contraction that is not a number (the residual after the step failed) counts as
        // beyond the linear range.
        if LinearRange::holds(contraction, padded_converged) {
            return EstimateMethod::Step;
        }
        let set = if wider {
            &self.budget.wider
        } else {
            &self.budget.truncation
        };
        if !set.solves {
            return EstimateMethod::Unsolved;
        }
        let solved = match across {
            Some(normal) => {
                self.converged_across(x, omega, wider, base, normal, (step, contraction))
            }
            None => self.converged_truncation(x, omega, wider, base, (step, contraction)),
        };
        match solved {
            Some(solved) => {
                *truncation = solved;
                EstimateMethod::Solved
            }
            None => EstimateMethod::Unsized,
        }
    }
}

/// Newton for the solves on an extended set ([`ErrorEstimator::converged_truncation`],
/// [`ErrorEstimator::converged_across`]), in the scaled space `x_scale`: the run's continuation
/// settings with `limit_factor` times its iteration limit for the corrector (the
/// fixed-frequency solve takes three times the limit of its own), and the exit on a stagnating
/// residual ([`StagnationExit`]) from the run's limit on. A solve gets the iterations a
/// continuation point gets, and the further ones only while its residual keeps falling.
///
/// Measured on the larger blade pair at H = 1 (700-1100 Hz, 3114 points; docs/accuracy.md,
/// "What the estimate costs"): with the across-path solves at the run's 12 iterations and the
/// fixed-frequency ones at 36 without the exit, 2057 points were solved and 787 not sizeable;
/// the failing fixed-frequency solves spent their 36 iterations at a residual of 0.07-0.2.
pub(super) fn extended_newton(
    problem: &Problem,
    x_scale: Vec<f64>,
    limit_factor: usize,
) -> Continuation {
    let mut settings = problem.analysis.continuation;
    let after = settings.max_iterations;
    settings.max_iterations *= limit_factor;
    Continuation::new(settings, x_scale).with_stagnation_exit(StagnationExit { after })
}
