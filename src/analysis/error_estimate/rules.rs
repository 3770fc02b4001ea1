//! How far an estimate goes at a point: the solve budget per extended set, the tail test and
//! widen gate of the wider set, and the linear range of the Newton step.

use super::problems::{extended_harmonic, wider_harmonic, EstimateProblems};
use super::report::EstimateMethod;
use crate::hbm::operator::HbmOperator;
use crate::model::{BeyondLinearRange, Problem};
use crate::numerics::ParametricResidual;

/// What the estimate may spend on one point under `accuracy.beyond_linear_range = "auto"` (the
/// default), in continuation points of the run ("run points", [`crate::hbm::cost`]): the
/// cost model's time of one Newton iteration (a factorisation and an evaluation) on each
/// extended set, against two budgets that bound the worst case of one point, whatever the
/// number of points that reach it.
///
/// - **Solves** ([`Self::SOLVE_RUN_POINTS`]): a point whose step leaves its linear range
///   ([`LinearRange`]) is solved on its set only where a solve at the continuation's iteration
///   limit (`max_iterations`, 12 by default; most converging solves take 4-12 iterations, and a
///   solve goes on beyond only while its residual keeps falling,
///   [`extended_newton`](super::estimator::extended_newton)) is estimated within the budget;
///   elsewhere it is flagged ([`EstimateMethod::Unsolved`]). With `"solve"` every set is solved,
///   with `"flag"` none.
/// - **The wider set** ([`Self::STEP_RUN_POINTS`]): a point [`TailTest`] sends there takes a
///   step on 2H + 1 and one on 4H + 3; where the two together are estimated beyond the budget
///   the wider set is not stepped on under `"auto"` ([`SetBudget::steps`]) and those points
///   are flagged with their 2H + 1 estimate. Its steps apply to every such point, and on a 3D
///   FE model with many contact points that is nearly every point: 38-45 of the 3D blade pair's
///   56 points stay stuck all period.
///
/// Measured, before these budgets (when every set whose single iteration was estimated at most
/// 50 run points was stepped on and solved): the 3D blade pair at H = 1 over 880-890 Hz (H = 3
/// at 1.8 run points per iteration, H = 7 at 14.7) sent all of its points to H = 7, where a
/// step costs about 3 s of CPU and the fixed-frequency solves up to 36 iterations; the run,
/// 2.5 minutes without the estimate, had estimated 217 of its 1174 points after 33 minutes.
/// The sets measured fall apart on either side: at most 6.2 run points per iteration (a solve
/// at most 74) and at most 7.1 for the two steps (the paper case up to H = 31; the small and
/// the larger 2D blade pair at H = 1, the small one at H = 3) against at least 12.2 per
/// iteration (146 per solve) and 13.8 for the two steps (the larger 2D blade pair at H = 3,
/// the 3D one at H = 1, the 2D one at H = 11 with H = 23 at 17.9 and H = 47 at 144.7, the
/// paper case at H = 15 with H = 63 at 14.5: `tests/it/cli_run.rs` compares that run with
/// `"solve"`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveBudget {
    /// The first extension (2H + 1).
    pub truncation: SetBudget,
    /// The wider set (4H + 3).
    pub wider: SetBudget,
    /// The Newton iterations a solve is costed at (the continuation's `max_iterations`).
    pub solve_iterations: usize,
}

/// The budget decision for one extended set ([`SolveBudget`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetBudget {
    /// Its highest harmonic.
    pub harmonic: usize,
    /// Estimated time of one Newton iteration on it, in continuation points of the run.
    pub run_points: f64,
    /// Whether points beyond the step's linear range are solved on it.
    pub solves: bool,
    /// Whether points are stepped on it at all (the wider set: the points [`TailTest`] sends
    /// there; the first extension is always stepped on).
    pub steps: bool,
}

impl SolveBudget {
    /// Under `"auto"` a set is solved on where a solve at the iteration limit is estimated at
    /// most this many run points.
    pub const SOLVE_RUN_POINTS: f64 = 100.0;
    /// Under `"auto"` the wider set is stepped on where the steps of a point sent there (on
    /// 2H + 1 and on 4H + 3) are estimated at most this many run points.
    pub const STEP_RUN_POINTS: f64 = 10.0;

    /// The decision for `problem`'s refined problems `refined`.
    pub fn new(problem: &Problem, refined: &EstimateProblems) -> Self {
        let run_point = crate::hbm::cost::estimate(problem).seconds_per_point();
        let h = problem.harmonics.iter().copied().max().unwrap_or(1);
        let mode = problem.analysis.error_estimate.beyond_linear_range;
        let solve_iterations = problem.analysis.continuation.max_iterations.max(1);
        let per_iteration = |extended: &Problem| {
            crate::hbm::cost::estimate(extended).seconds_per_iteration() / run_point
        };
        let (first, wider) = (
            per_iteration(&refined.truncation),
            per_iteration(&refined.wider),
        );
        let set = |harmonic: usize, run_points: f64, steps: bool| SetBudget {
            harmonic,
            run_points,
            solves: match mode {
                BeyondLinearRange::Solve => true,
                BeyondLinearRange::Flag => false,
                BeyondLinearRange::Auto => {
                    Self::within(run_points * solve_iterations as f64, Self::SOLVE_RUN_POINTS)
                }
            },
            steps,
        };
        let wider_steps =
            mode != BeyondLinearRange::Auto || Self::within(first + wider, Self::STEP_RUN_POINTS);
        Self {
            truncation: set(extended_harmonic(h), first, true),
            wider: set(wider_harmonic(h), wider, wider_steps),
            solve_iterations,
        }
    }

    /// Whether an estimated cost of `run_points` run points is within `budget` (NaN, a cost
    /// that could not be estimated, is not).
    pub fn within(run_points: f64, budget: f64) -> bool {
        run_points <= budget
    }

    /// What `fricbound check` says of it: "solved on H = 3 (1.8 run points per iteration),
    /// not stepped, its points flagged, on H = 7 (14.7 …) […]".
    pub fn summary(&self, mode: BeyondLinearRange) -> String {
        let how = |s: &SetBudget| {
            format!(
                "{} on H = {} ({:.1} run points per iteration)",
                match (s.solves, s.steps) {
                    (_, false) => "not stepped, its points flagged,",
                    (true, true) => "solved",
                    (false, true) => "flagged",
                },
                s.harmonic,
                s.run_points
            )
        };
        let why = match mode {
            BeyondLinearRange::Auto => format!(
                "auto: solved where {} iterations are estimated at most {} run points, the \
                 wider set stepped on where a point's two steps are at most {}",
                self.solve_iterations,
                Self::SOLVE_RUN_POINTS,
                Self::STEP_RUN_POINTS
            ),
            BeyondLinearRange::Solve => "solve".to_string(),
            BeyondLinearRange::Flag => "flag".to_string(),
        };
        format!("{}, {} [{why}]", how(&self.truncation), how(&self.wider))
    }
}

/// Whether the estimate on 2H + 1 may be missing what lies beyond 2H + 1, so that the point is
/// estimated again on the wider set (4H + 3), which it then reports. Two reasons, either
/// suffices (and neither where the estimate is negligible, [`Self::NEGLIGIBLE`]):
///
/// - **A contact stuck all period.** Its tangential force keeps the march's initial condition
///   T(0) = m μ N(0), so its mean force is kₜ (ū − u(0)) + m μ N(0): it holds u and N at τ = 0,
///   sums of every cosine harmonic with weight one. The harmonic content such a contact feeds
///   back does not decay with the harmonic number as slip-driven forces do, and the error can
///   sit far above 2H + 1 (on the small blade pair's upper branch at H = 1 it sits in the
///   harmonics 6-7: docs/accuracy.md). Where every contact is stuck the model is linear and
///   the estimate negligible, so only points mixing stuck and moving contacts pay.
/// - **The extension has not converged in its own harmonics.** Two estimates come from the
///   same factorisation: the step from the residual on the lower half of the new harmonics
///   alone (H+1 … ⌈3H/2⌉) changes the amplitude by d₁, the step from all of them by
///   d₁ + d₂. If each further half of harmonics changes it by r = |d₂|/|d₁| times the previous
///   one (a geometric tail), the harmonics above 2H + 1 add at most |d₂| r/(1 − r) (unbounded
///   for r ≥ 1). Where that exceeds [`Self::FRACTION`] of the estimate |d₁ + d₂|, the point is
///   extended.
///
/// The fraction: the criterion holds an estimate to a factor 3 of the true error; a
/// tail of at most half the estimate leaves the reported value within a factor 1.5 of the
/// extension's limit, half of the allowed band (in log scale), the other half left for the
/// first-order step itself.
pub struct TailTest;

impl TailTest {
    /// Largest projected tail, relative to the estimate, that the 2H + 1 estimate is kept with.
    pub const FRACTION: f64 = 0.5;
    /// Relative estimates below this are kept without testing their tail (round-off of the
    /// amplitude, far below the no-warning level 1e-4 of the issue).
    pub const NEGLIGIBLE: f64 = 1e-7;

    /// True when the estimate needs the wider set: `base` the point's amplitude, `low` and
    /// `full` the amplitudes after the lower-half and the full steps, `stuck_contact` whether
    /// a contact of the point is stuck all period.
    pub fn extend(base: f64, low: f64, full: f64, stuck_contact: bool) -> bool {
        let d1 = (low - base).abs();
        let d2 = (full - low).abs();
        let estimate = (full - base).abs();
        if estimate.partial_cmp(&(Self::NEGLIGIBLE * base.abs()))
            != Some(std::cmp::Ordering::Greater)
        {
            // Negligible, or not a number (then the wider set cannot do better).
            return false;
        }
        if stuck_contact || d2 >= d1 {
            return true;
        }
        let r = d2 / d1;
        d2 * r / (1.0 - r) > Self::FRACTION * estimate
    }
}

/// Which of the points [`TailTest`] sends to the wider set (4H + 3) are widened: those whose
/// estimate on 2H + 1 is not below [`Self::FRACTION`] of the scene's warning threshold, and
/// every one whose step on 2H + 1 leaves its linear range ([`LinearRange`]), since such a
/// step's estimate does not bound the wider one (it exceeded it by up to 868× there).
///
/// The fraction is derived from the criteria and one measured ratio: on every point
/// measured whose 2H + 1 step is within its linear range and whose widened estimate is at least
/// 10⁻³/3 (the larger blade pair at H = 1, the paper case's 2nd resonance at H = 1, 3, 5, 7, the
/// paper case at a low pre-load at H = 1, 3; docs/accuracy.md), the widened estimate exceeded
/// the 2H + 1 one by at most X = 37.3 (the low pre-load at H = 3, 23.43 Hz: 1.8 × 10⁻⁵ on
/// 2H + 1, 6.8 × 10⁻⁴ on 4H + 3; at most 2.6 on the other scenes). A point kept below
/// 8 × 10⁻⁴ of the default 1 % threshold (8 × 10⁻⁶) would have had a widened estimate below
/// 37.3 × 8 × 10⁻⁶ = 3 × 10⁻⁴ < 10⁻³/3: it neither warns after widening nor sizes a true error
/// above 10⁻³ within a factor 3, so the gate changes no outcome of the criteria on what was
/// measured. A gate at 2.5 % of the threshold did: on the small blade pair
/// (`tests/it/error_estimate_fe.rs`) it kept 4 points at H = 1 next to the fold (933.45 Hz) whose
/// 2H + 1 estimates of 1.7-2.3 × 10⁻⁴ are 5-7× below their true errors of 1.1-1.3 × 10⁻³.
pub struct WidenGate;

impl WidenGate {
    /// Fraction of the warning threshold below which a 2H + 1 estimate within its linear
    /// range is kept without widening (8 × 10⁻⁶ at the default 1 %).
    pub const FRACTION: f64 = 8e-4;

    /// True when the point is widened: `truncation` its 2H + 1 estimate per output (NaN
    /// counts as above the gate), `in_range` whether the 2H + 1 step is within its linear
    /// range ([`LinearRange::holds`]), `threshold` the scene's warning threshold (relative).
    pub fn widens(truncation: &[f64], in_range: bool, threshold: f64) -> bool {
        let gate = Self::FRACTION * threshold;
        !in_range || truncation.iter().any(|&e| e > gate || e.is_nan())
    }
}

/// Whether the point padded with zero harmonics already solves an extended system within the
/// Newton tolerance of the run (`analysis.residual_tolerance`, relative to the operator's
/// residual scale), `r_norm` being the norm of the extended residual there: the contact
/// forces' harmonics beyond the kept set are then below what the run itself counts as
/// converged, and the padded point is a converged solution of the extended system by the
/// run's own criterion. Its step moves within that tolerance, the residual after it is of the
/// same size (round-off), and the step's contraction ([`LinearRange`]) is no test of
/// linearity: the point keeps the step (its change is the size of the tolerance) and is not
/// solved again. Measured on the blade pair at H = 11 over 700-720 Hz: every one of the 53
/// points had a step estimate below 10⁻¹² and a contraction above 5 %, and its converged
/// solve changed the estimate by less than 1.5 × 10⁻¹² (docs/accuracy.md).
pub(super) fn solves_padded(problem: &Problem, operator: &HbmOperator<'_>, r_norm: f64) -> bool {
    let scale = operator.residual_scale();
    scale > 0.0 && r_norm / scale <= problem.analysis.continuation.residual_tolerance
}

/// The method of a point that [`TailTest`] sends to the wider set where the scene's budget
/// does not step on it ([`SetBudget::steps`]): its 2H + 1 estimate is no size of the error
/// (the extension has not converged in its own harmonics), so it is flagged
/// ([`EstimateMethod::Unsolved`]), or not formed where that estimate is not a number.
pub(super) fn beyond_budget(truncation: &[f64]) -> EstimateMethod {
    if truncation.iter().any(|v| v.is_nan()) {
        EstimateMethod::None
    } else {
        EstimateMethod::Unsolved
    }
}

/// Whether the one Newton step of the extended system stays in the range where its
/// linearisation holds: its contraction, the norm of the extended residual after the step
/// relative to the norm before it (the residual on the new harmonics), is at most
/// [`Self::MAX_CONTRACTION`]. Within its linear range a Newton step leaves a residual of
/// second order in the step, far below the first.
///
/// Measured on the small blade pair (`examples/estimate_misses.rs`, docs/accuracy.md, "Why
/// the estimate missed on the small blade pair"): below 929.5 Hz a stuck contact of the point
/// sits at its friction limit at an instant of the period (it slipped by a hair, so its mean
/// force is set by that slip), while on the extended set it stays stuck from the march's
/// initial condition with a margin of 1-3 % of μN; the step linearised on the first regime
/// lands far from the extended solution (at H = 1, 928.77 Hz: step 0.27 %, converged extended
/// solution 6.4 %, true error 6.6 %), and its estimate jumps by factors 3-50 between
/// neighbouring points while the converged extended solutions change smoothly. Where the
/// contraction exceeds the bound the point is solved on the extended set to convergence at
/// its frequency, or across the path where it reports the across-path step
/// ([`EstimateMethod::Solved`]), or, where that fails, reported as not sizeable
/// ([`EstimateMethod::Unsized`]).
pub struct LinearRange;

impl LinearRange {
    /// Largest contraction of the residual by the estimate's Newton step that keeps the step.
    pub const MAX_CONTRACTION: f64 = 0.05;

    /// Whether a step is kept: its `contraction` is at most [`Self::MAX_CONTRACTION`] (NaN,
    /// the residual after the step not formed, counts as beyond), or the padded point it
    /// starts from already solves the extended system within the Newton tolerance
    /// (`padded_converged`, see `solves_padded`), where the contraction of a step within
    /// round-off tells nothing.
    pub fn holds(contraction: f64, padded_converged: bool) -> bool {
        padded_converged || contraction <= Self::MAX_CONTRACTION
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_test_extends_slow_tails_and_stuck_contacts_only() {
        // Lower half changes the amplitude by 1e-2, the upper half by 1e-3: r = 0.1, tail
        // 1.1e-4, far below half of the 1.1e-2 estimate.
        assert!(!TailTest::extend(1.0, 1.01, 1.011, false));
        // The upper half changes it by as much as the lower one: r = 1, unbounded tail.
        assert!(TailTest::extend(1.0, 1.01, 1.02, false));
        // r = 0.6: tail 0.6/0.4 · 6e-3 = 9e-3 > half of 1.6e-2.
        assert!(TailTest::extend(1.0, 1.01, 1.016, false));
        // A stuck contact extends any estimate that is not negligible ...
        assert!(TailTest::extend(1.0, 1.01, 1.011, true));
        // ... and none that is (all stuck: linear, no truncation error), nor a NaN.
        assert!(!TailTest::extend(1.0, 1.0, 1.0 + 1e-9, true));
        assert!(!TailTest::extend(1.0, f64::NAN, f64::NAN, true));
    }

    #[test]
    fn the_solve_budget_is_a_number_of_run_points() {
        let solve = SolveBudget::SOLVE_RUN_POINTS;
        assert!(SolveBudget::within(solve, solve));
        // The paper case at H = 7 solves on H = 31 (6.2 run points per iteration, 12
        // iterations), the 2D blade pair at H = 3 does not on H = 15 (12.2).
        assert!(SolveBudget::within(6.2 * 12.0, solve));
        assert!(!SolveBudget::within(12.2 * 12.0, solve));
        // A cost that could not be estimated is not within the budget.
        assert!(!SolveBudget::within(f64::NAN, solve));
        let budget = SolveBudget {
            truncation: SetBudget {
                harmonic: 3,
                run_points: 1.8,
                solves: true,
                steps: true,
            },
            wider: SetBudget {
                harmonic: 7,
                run_points: 14.7,
                solves: false,
                steps: false,
            },
            solve_iterations: 12,
        };
        let text = budget.summary(BeyondLinearRange::Auto);
        assert!(
            text.starts_with(
                "solved on H = 3 (1.8 run points per iteration), not stepped, its points \
                 flagged, on H = 7 (14.7 run points per iteration) [auto: solved where 12 \
                 iterations are estimated at most 100 run points"
            ),
            "{text}"
        );
        // With "solve" a wider set is solved and stepped on whatever it costs.
        let solved = SetBudget {
            solves: true,
            steps: true,
            ..budget.wider
        };
        let text = SolveBudget {
            wider: solved,
            ..budget
        }
        .summary(BeyondLinearRange::Solve);
        assert!(
            text.ends_with("solved on H = 7 (14.7 run points per iteration) [solve]"),
            "{text}"
        );
    }

    #[test]
    fn points_sent_beyond_the_budget_are_flagged_with_their_first_extension() {
        assert_eq!(beyond_budget(&[0.02, 1e-9]), EstimateMethod::Unsolved);
        assert_eq!(beyond_budget(&[0.02, f64::NAN]), EstimateMethod::None);
        // Under "auto" the wider set is stepped on only within the budget; "solve" and
        // "flag" step on it whatever it costs.
        let problem = crate::scene::parse(crate::scene::paper_wedge_scene(), "paper", &[])
            .unwrap()
            .validate("paper")
            .unwrap();
        let refined = EstimateProblems::new(&problem).expect("the estimate is on");
        let budget = SolveBudget::new(&problem, &refined);
        assert!(budget.truncation.steps && budget.wider.steps, "{budget:?}");
    }

    #[test]
    fn widen_gate_keeps_small_estimates_within_their_linear_range() {
        let threshold = 0.01;
        let gate = WidenGate::FRACTION * threshold;
        // Below the gate, within the linear range: kept on 2H + 1.
        let within = |contraction: f64| LinearRange::holds(contraction, false);
        assert!(!WidenGate::widens(&[0.5 * gate], within(0.01), threshold));
        // Above it (any output), or not a number: widened.
        assert!(WidenGate::widens(
            &[0.5 * gate, 2.0 * gate],
            within(0.01),
            threshold
        ));
        assert!(WidenGate::widens(&[f64::NAN], within(0.01), threshold));
        // A step beyond its linear range (or whose contraction is not known) is widened
        // whatever its size: its estimate does not bound the wider one.
        assert!(WidenGate::widens(&[0.5 * gate], within(0.2), threshold));
        assert!(WidenGate::widens(
            &[0.5 * gate],
            within(f64::NAN),
            threshold
        ));
        // A step from a point that already solves the extension within the Newton tolerance
        // is within range whatever its contraction.
        assert!(!WidenGate::widens(
            &[0.5 * gate],
            LinearRange::holds(0.9, true),
            threshold
        ));
    }
}
