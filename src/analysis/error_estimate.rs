//! A-posteriori error estimate of a converged harmonic-balance point: how much each output's
//! first-harmonic amplitude would change if the harmonic set were larger (truncation) or the
//! AFT sampled the period more finely (sampling).
//!
//! # Truncation
//!
//! A converged point x (harmonics 0..H, or the scene's set) is padded with zero coefficients
//! for the harmonics H+1 … 2H+1 ([`extended_harmonic`]) and put into the harmonic balance on the
//! extended set (paper Eq. 7 with more harmonics), at the same frequency and the same number of
//! samples per period (doubled only where the scene's count does not resolve 2H+1). With the
//! same samples the displacement samples, the march and the kept force harmonics are those of
//! the converged point, so the residual is zero on the kept harmonics and holds on the new ones
//! exactly what the truncation threw away: the contact forces' harmonics H+1 … 2H+1. One Newton step of the extended system, δ = −J⁻¹R, pushes these forces
//! through the dynamic stiffness of the new harmonics (with the contacts' linearisation) and
//! carries their effect back onto the kept harmonics through the contact Jacobian. The
//! estimate of an output is |A(x + δ) − A(x)| / A(x), A the first-harmonic amplitude
//! √(c₁² + s₁²).
//!
//! Where the harmonics beyond 2H + 1 may matter ([`TailTest`]: a contact stuck all period,
//! whose mean force holds every harmonic of u(τ = 0), or an extension whose upper half of
//! harmonics still changes the estimate as much as its lower half) the point is estimated
//! again in the same way on the wider set H+1 … 4H+3 ([`wider_harmonic`]) and reports that
//! estimate ([`PointAccuracy::estimate_harmonic`] says which), unless its step on 2H + 1 is
//! within its linear range and its estimate below a gate ([`WidenGate`], 8 × 10⁻⁶ at the
//! default 1 % threshold, derived from the largest measured ratio of the widened estimate to
//! the 2H + 1 one).
//!
//! # Where the step leaves its linear range
//!
//! The extended residual is evaluated once more at the stepped point. Where it is more than
//! [`LinearRange::MAX_CONTRACTION`] of the residual before the step, the step is outside the
//! range where its linearisation holds (a contact whose regime differs between the point and
//! the extended solution: docs/accuracy.md, "Why the estimate missed on the small blade
//! pair"), and the point is solved on the extended set to convergence, which it then reports
//! ([`EstimateMethod::Solved`]): at its frequency where it reports the fixed-frequency step,
//! across the path where it reports the across-path step (Newton on the extended system
//! bordered with the path's hyperplane through the point, normal · (x − x₀, ω − ω₀) = 0, the
//! normal the step was bordered with; the amplitude change across the path). Where that
//! solve does not converge the point is not sizeable ([`EstimateMethod::Unsized`], warned in
//! a band of its own). Against the true error across the path the converged across-path
//! estimate is within 0.91-1.05 of it on the paper case (H = 1, 3; 208 points above 10⁻³) and
//! 0.78-1.82 on the small blade pair (H = 1, 3; 129 points), formed at every point by the
//! tests (`tests/error_estimate.rs`, `tests/error_estimate_fe.rs`).
//!
//! # Points that already solve the extension
//!
//! Where the padded point already solves the extended system, and the point the harmonic
//! balance at twice the samples, within the run's Newton tolerance (`solves_padded`: e.g.
//! every contact stuck or open all period, where the contact forces are linear in the motion
//! and hold no harmonic the point lacks), the point is a converged solution of both by the
//! run's own criterion: both estimates are 0, formed from those two residuals without a
//! Jacobian ([`EstimateMethod::Converged`]). A step from such a point moves within round-off,
//! and its contraction says nothing of linearity; it was taken for a step beyond its linear
//! range before, and solved again at a cost: on the blade pair at H = 11 every point over
//! 700-720 Hz (step estimates below 10⁻¹¹, their converged solves 1.5 × 10⁻¹² at most), at
//! 5.1 s of CPU for a run of 0.38 s (now 0.42 s with the estimate). Where the sampling residual
//! is above the tolerance the point takes the full estimate, and its truncation step counts
//! as within its linear range ([`LinearRange::holds`]).
//!
//! # Sampling
//!
//! The same point put into the harmonic balance of the same harmonic set at twice the samples
//! per period: the residual is what the coarser sampling of the march misses (stick-slip and
//! lift-off transitions located to a sample). It is pushed through the Jacobian already
//! factorised for the truncation step (the extended system's; the residual on the kept
//! harmonics, zero on the new ones): one Newton step as above, at the cost of one residual
//! at twice the samples and one more solve with the same factors.
//!
//! # Across the path or at a fixed frequency
//!
//! On a continuation path (every point of an FRF run, limit and intermediate curves) the
//! extended system is factorised bordered with the path's arc-length row, normal · (δx, δω)
//! = 0, the normal being the path's tangent at the point in the continuation's scaled metric
//! (paper Eq. 9; see [`crate::numerics::Observer::accepted`]). Its solutions give two steps
//! from one factorisation: the step *across the path* (it may change the frequency and stays
//! in the hyperplane orthogonal to the path: it moves the point onto the refined path at the
//! same place along it), and, with one more solve for the path's direction z, the step *at the
//! fixed frequency* (the across-path step slid along z back onto the point's frequency). The
//! fixed-frequency Jacobian is singular at a fold of the path (a turning point), where the
//! slide, hence the fixed-frequency estimate, grows without bound (806 % at H = 1, 395 at
//! H = 3 on the reduced blade pair next to its fold); the bordered matrix is regular there.
//! The point reports the fixed-frequency estimate unless the slide exceeds
//! [`PathSwitch::SLIDE_STEPS`] continuation steps ([`PointAccuracy::across_path`] says
//! which one it reports; both truncation estimates are kept in
//! [`PointAccuracy::both_truncation`]). Away from folds the two differ where the path is
//! steep: the across-path step measures the error across the path, the fixed-frequency one
//! the (larger) error at a fixed frequency, which is what an FRF is read at. Points solved at
//! a fixed frequency (the end frequency of a path, the bridge points between branches,
//! refined peaks) take the plain fixed-frequency step. An estimate that cannot be formed (an
//! AFT march that does not settle, a singular matrix) is NaN.
//!
//! Cost per point: one residual, Jacobian and factorisation of the system on 2H+1 harmonics
//! (in the formulation the cost model picks for that system, see `extended_formulation`),
//! one residual at twice the samples, and two solves with the same factors (three with the
//! path's direction on a path point; before the sampling step reused the factors, it took a
//! Jacobian and a factorisation of its own). The bordered factorisation adds one row and
//! column (dense storage) or one solve for the border column (storages that eliminate the
//! border by blocks). A point whose step leaves its linear range ([`LinearRange`]) adds a
//! Newton solve of the extended system: a Jacobian, a factorisation and the line search's
//! residuals per iteration; at its frequency up to three times the continuation's iteration
//! limit, across the path up to that limit (the corrector's own, one row and column more)
//! where it does not converge. It starts from the stepped point where the step lowers the
//! residual (the iterate Newton from the padded point reaches first), so it repeats no work of
//! the step. A point sent to the wider set but kept on 2H + 1 by [`WidenGate`] saves the
//! wider set's residual, Jacobian and factorisation. On the larger blade pair at H = 1
//! (855-895 Hz, 1076 points) these solves take most of the estimate's time (the failing ones
//! 46 %, the converging ones 40 %, the steps 14 %): 23-26 s of user CPU with the estimate
//! against 3.2-3.4 s without (6.8-8.2×; 15 s, about 5×, before the solve across the path,
//! which sizes 285 of its 607 points next to the small folds); the gate keeps none of its
//! points on 2H + 1, since 417 of its 450 widened points have 2H + 1 estimates above the 1 %
//! threshold itself (docs/accuracy.md, "What the estimate costs, and where the time goes").
//!
//! Which extended sets a point beyond its step's linear range is solved on, and whether the
//! wider set is stepped on at all, is the scene's choice (`accuracy.beyond_linear_range`): by
//! default ([`SolveBudget`]) a set is solved on only where the cost model puts a solve at the
//! iteration limit at most 100 run points, and the wider set stepped on only where a point's
//! two steps cost at most 10; beyond that the point is flagged ([`EstimateMethod::Unsolved`];
//! a point sent to a wider set that is not stepped on is flagged with its 2H + 1 estimate). On
//! the 3D blade pair at H = 1 the steps and solves on H = 7 at every point (38-45 of its 56
//! contact points stay stuck all period, so every point is widened) had a 2.5-minute run past
//! 33 minutes at 217 of its 1174 points; with the budget the run takes 1.03× its wall time
//! without the estimate, every point flagged.
//!
//! Every estimate runs on a pool of one thread of the estimator's own
//! (`ErrorEstimator::on_one_thread`): faer then factorises the extended systems (2-5× the
//! run's) on that one thread instead of splitting each factorisation over rayon's threads,
//! which on a loaded machine mostly wait for each other (on the blade pair above 28-43 s of
//! user and 2-18 s of system CPU before, with the same results).
//!
//! An FRF run hands its points to estimators on worker threads of their own
//! ([`crate::analysis::estimate_pool`]), one per thread of rayon's global pool, and goes on
//! with the continuation meanwhile: the CPU is the same, the wall time shared over the cores
//! (on the blade pair above 9.7-10.9 s of wall time against 20.7-22.2 s inline on two cores).
//! Runs inside a rayon job (the limit curves, the accuracy study's settings) estimate inline.

use crate::contact::harmonic::HarmonicSet;
use crate::contact::point::ContactState;
use crate::hbm::operator::HbmOperator;
use crate::hbm::HbmError;
use crate::model::{BeyondLinearRange, Formulation, Problem};
use crate::numerics::continuation::{Continuation, StagnationExit};
use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::ParametricResidual;

/// The error estimate of one converged point, per output DOF (relative to its first-harmonic
/// amplitude; NaN where the estimate could not be formed).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PointAccuracy {
    /// Harmonic-truncation estimate per output DOF (relative).
    pub truncation: Vec<f64>,
    /// AFT-sampling estimate per output DOF (relative).
    pub sampling: Vec<f64>,
    /// True when the reported estimates are the steps across the path (bordered with the
    /// path's normal), false when at a fixed frequency (see the module docs and
    /// [`PathSwitch`]).
    pub across_path: bool,
    /// The hyperplane the across-path steps stay in (on a path point): the covector on the
    /// point's full coefficients (harmonic-major, as `FrfPoint::coefficients`) followed by
    /// the one on ω (rad/s); zero on coefficients the run's formulation eliminates. A
    /// reference path crossing this hyperplane gives the true error at the same place along
    /// the path (`crate::analysis::frf::amplitude_across_path`).
    #[serde(skip)]
    pub path_normal: Option<Vec<f64>>,
    /// On a path point, both truncation estimates per output: at the fixed frequency and
    /// across the path (the reported one is chosen by [`PathSwitch`]); empty elsewhere.
    #[serde(skip)]
    pub both_truncation: Option<(Vec<f64>, Vec<f64>)>,
    /// On a path point, the arc length (scaled, Hz-equivalent, as the continuation's steps)
    /// that the fixed-frequency truncation step slides along the path beyond the step across
    /// it, and the continuation step that reached the point; NaN elsewhere.
    #[serde(skip)]
    pub slide_and_step: (f64, f64),
    /// Highest harmonic of the extended set the reported truncation estimate comes from:
    /// 2H + 1, or the wider set's 4H + 3 where the first extension had not converged in its
    /// own harmonics ([`TailTest`]); 0 where no estimate was formed.
    pub estimate_harmonic: usize,
    /// Whether a contact's regime at the point moved by the reported truncation step (on the
    /// first extension) differs from the point's own: the step crosses a stick-slip or
    /// lift-off transition, outside the range where its linearisation holds.
    pub step_changes_regime: bool,
    /// The reported truncation step's contraction of the extended residual
    /// ([`LinearRange`]); NaN where not formed.
    #[serde(skip)]
    pub contraction: f64,
    /// How the truncation estimate was formed: one Newton step, the extended system solved to
    /// convergence, or not sizeable ([`EstimateMethod`]).
    pub method: EstimateMethod,
}

impl PointAccuracy {
    /// The estimate of a point where none could be formed: NaN for each of `outputs` output
    /// DOFs, no method.
    pub fn not_formed(outputs: usize) -> Self {
        Self {
            truncation: vec![f64::NAN; outputs],
            sampling: vec![f64::NAN; outputs],
            across_path: false,
            path_normal: None,
            both_truncation: None,
            slide_and_step: (f64::NAN, f64::NAN),
            estimate_harmonic: 0,
            step_changes_regime: false,
            contraction: f64::NAN,
            method: EstimateMethod::None,
        }
    }
}

/// Where the path is at a converged point, for the estimate across it: the hyperplane normal
/// to the path (see [`crate::numerics::Observer::accepted`]) and the arc-length step
/// (Hz-equivalent) that reached the point.
#[derive(Debug, Clone, Copy)]
pub struct PathPlace<'a> {
    /// Covector on the run operator's unknowns, then on ω (rad/s).
    pub normal: &'a [f64],
    /// The continuation step that reached the point (scaled arc length).
    pub step: f64,
}

/// Which step a path point reports: the fixed-frequency one, unless it slides along the path
/// (beyond the step across it) by more than [`Self::SLIDE_STEPS`] continuation steps. The
/// fixed-frequency step is the across-path one plus a slide along the path's tangent back onto
/// the point's frequency; next to a fold the tangent's frequency component vanishes, the
/// fixed-frequency Jacobian is singular and the slide unbounded, far beyond the stretch of path
/// where the tangent holds (the continuation turns its tangent by about 10° per step).
///
/// The threshold is set from measurements: on the paper case's steep flank below its 2nd
/// resonance (H = 1, `zoom-2nd.toml`) the slide reaches 21 steps while the fixed-frequency
/// estimate still tracks the error at a fixed frequency (within the criteria, see
/// `tests/error_estimate.rs`), so the switch sits above that.
pub struct PathSwitch;

impl PathSwitch {
    /// Continuation steps the fixed-frequency step may slide along the path.
    pub const SLIDE_STEPS: f64 = 32.0;

    /// True when the across-path step is reported (not at a path's first point, solved at a
    /// fixed frequency, whose `step` is 0).
    pub fn across(slide: f64, step: f64) -> bool {
        // A slide that is not a number (the path's direction has no frequency component: at
        // the fold itself) counts as beyond.
        step > 0.0 && (slide.is_nan() || slide > Self::SLIDE_STEPS * step)
    }
}

/// The two refined problems the estimate puts a point into: the harmonic set extended to 2H,
/// and the same set at twice the samples. Built once per run (see [`ErrorEstimator`]).
#[derive(Debug, Clone)]
pub struct EstimateProblems {
    /// The problem on the extended harmonic set (up to 2H + 1).
    pub truncation: Problem,
    /// The problem on the wider set (up to [`wider_harmonic`], 4H + 3), for the points whose
    /// first extension has not converged in its own harmonics ([`TailTest`]).
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

/// What the estimate may spend on one point under `accuracy.beyond_linear_range = "auto"` (the
/// default), in continuation points of the run ("run points", [`crate::hbm::cost`]): the
/// cost model's time of one Newton iteration (a factorisation and an evaluation) on each
/// extended set, against two budgets that bound the worst case of one point, whatever the
/// number of points that reach it.
///
/// - **Solves** ([`Self::SOLVE_RUN_POINTS`]): a point whose step leaves its linear range
///   ([`LinearRange`]) is solved on its set only where a solve at the continuation's
///   iteration limit (`max_iterations`, 12 by default; most converging solves take 4-12
///   iterations, and a solve goes on beyond only while its residual keeps falling,
///   [`extended_newton`]) is estimated within the budget; elsewhere it
///   is flagged ([`EstimateMethod::Unsolved`]). With `"solve"` every set is solved, with
///   `"flag"` none.
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
/// paper case at H = 15 with H = 63 at 14.5: `tests/cli_run.rs` compares that run with
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
/// (`tests/error_estimate_fe.rs`) it kept 4 points at H = 1 next to the fold (933.45 Hz) whose
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

/// One refined operator and a Jacobian in its storage (pattern built once).
struct Refined<'p> {
    operator: HbmOperator<'p>,
    jacobian: AssembledJacobian,
    /// For each block of the base unknowns, its index among the refined operator's blocks.
    block_of: Vec<usize>,
}

impl<'p> Refined<'p> {
    fn new(problem: &'p Problem, base: &HarmonicSet) -> Result<Self, HbmError> {
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
    fn padded(&self, n: usize, x: &[f64]) -> Vec<f64> {
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
    fn on_kept_blocks(&self, r: &[f64], base_blocks: usize) -> Option<Vec<f64>> {
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
    fn lower_half(&self, r: &[f64], h: usize) -> Vec<f64> {
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
    fn after_step(
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
    fn stepped(&mut self, xr: &[f64], delta: &[f64], omega: f64) -> Option<Vec<f64>> {
        let stepped: Vec<f64> = xr.iter().zip(delta).map(|(a, d)| a - d).collect();
        let full = self.operator.expand(&stepped, omega).ok()?;
        full.iter().all(|v| v.is_finite()).then_some(full)
    }
}

/// First-harmonic amplitude √(c₁² + s₁²) of each output DOF from full coefficients on `set`.
fn amplitudes(problem: &Problem, set: &HarmonicSet, x: &[f64]) -> Vec<f64> {
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
fn relative_changes(refined: &[f64], base: &[f64]) -> Vec<f64> {
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
fn solves_padded(problem: &Problem, operator: &HbmOperator<'_>, r_norm: f64) -> bool {
    let scale = operator.residual_scale();
    scale > 0.0 && r_norm / scale <= problem.analysis.continuation.residual_tolerance
}

/// The method of a point that [`TailTest`] sends to the wider set where the scene's budget
/// does not step on it ([`SetBudget::steps`]): its 2H + 1 estimate is no size of the error
/// (the extension has not converged in its own harmonics), so it is flagged
/// ([`EstimateMethod::Unsolved`]), or not formed where that estimate is not a number.
fn beyond_budget(truncation: &[f64]) -> EstimateMethod {
    if truncation.iter().any(|v| v.is_nan()) {
        EstimateMethod::None
    } else {
        EstimateMethod::Unsolved
    }
}

/// The truncation estimate on the wider set (4H + 3).
struct Wider {
    /// Whether the padded point already solves the wider system within the Newton tolerance
    /// ([`solves_padded`]).
    padded_converged: bool,
    /// At the fixed frequency, per output.
    fixed: Vec<f64>,
    /// The fixed-frequency step's contraction ([`LinearRange`]).
    fixed_contraction: f64,
    /// Across the path (per output) and that step's contraction, where the path's normal was
    /// given and the bordered matrix factorised.
    across: Option<(Vec<f64>, f64)>,
    /// The fixed-frequency step (wider unknowns), for the start of a converged solve.
    fixed_step: Vec<f64>,
    /// The across-path step (wider unknowns, then δω in rad/s), where formed, for the start of
    /// a converged solve across the path.
    across_step: Option<Vec<f64>>,
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

/// How a point's truncation estimate was formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EstimateMethod {
    /// One Newton step of the extended system (the default, within its linear range).
    Step,
    /// The extended system solved to convergence at the point's frequency, or across the path
    /// where the point reports the across-path step (the step left its linear range,
    /// [`LinearRange`]).
    Solved,
    /// Not sizeable: the step left its linear range and the extended system has no converged
    /// solution at the point's frequency (or, where the point reports the across-path step,
    /// across the path). The estimate is the step's and is not to be read as a size: the run
    /// warns.
    Unsized,
    /// Not sized: the step left its linear range and the scene asked not to solve the
    /// extended system there (`accuracy.beyond_linear_range = "flag"`). The estimate is the
    /// step's and is not to be read as a size: the run warns, as for [`Self::Unsized`].
    Unsolved,
    /// The point padded with zero harmonics already solves the extended system, and the
    /// harmonic balance at twice the samples, within the run's Newton tolerance
    /// (`solves_padded`): both estimates are 0 (below what the run resolves), formed from
    /// two residuals without a Newton step (e.g. every contact stuck or open all period,
    /// where the contact forces hold no harmonic the point lacks).
    Converged,
    /// No estimate formed (NaN).
    None,
}

impl EstimateMethod {
    /// The label written in the output files.
    pub fn label(self) -> &'static str {
        match self {
            Self::Step => "step",
            Self::Solved => "solved",
            Self::Unsized => "unsized",
            Self::Unsolved => "unsolved",
            Self::Converged => "converged",
            Self::None => "none",
        }
    }
}

/// What one set of Newton steps (across the path or at the fixed frequency) gives on the
/// first extension.
struct Assessed {
    /// Truncation estimate per output.
    truncation: Vec<f64>,
    /// Whether [`TailTest`] sends the point to the wider set.
    needs_wider: bool,
    /// Whether the truncation step changes a contact's regime.
    changes_regime: bool,
    /// The truncation step's contraction ([`LinearRange`]).
    contraction: f64,
    /// Sampling estimate per output.
    sampling: Vec<f64>,
}

/// Estimates the truncation and sampling errors of converged points of one problem, reusing
/// the refined operators (and their Jacobian patterns) from point to point.
pub struct ErrorEstimator<'p> {
    problem: &'p Problem,
    set: HarmonicSet,
    truncation: Refined<'p>,
    /// The wider set (4H + 3), for points whose first extension has not converged.
    wider: Refined<'p>,
    /// The problem's highest harmonic H.
    h_max: usize,
    /// The operator at twice the samples (residuals only).
    sampling: HbmOperator<'p>,
    /// For each of the run's unknowns, its index among the full coefficients (the run's
    /// operator restricts by selection).
    full_index: Vec<usize>,
    /// A pool of one thread that every estimate runs on ([`Self::on_one_thread`]); None where
    /// the thread could not be started (the estimate then runs on the caller's thread).
    one_thread: Option<rayon::ThreadPool>,
    /// On which extended sets a point whose step leaves its linear range is solved, and
    /// whether the points [`TailTest`] and [`WidenGate`] send to the wider set are stepped on
    /// it (where not, they are flagged with their 2H + 1 estimate).
    budget: SolveBudget,
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

    /// Runs `work` on the estimator's pool of one thread, so that the dense factorisations of
    /// the extended systems (faer, whose default parallelism spreads a factorisation over
    /// rayon's threads, the pool's own there) run sequentially. The extended systems are 2-5×
    /// the run's, large enough for faer to split their factorisations; on the larger blade pair
    /// at H = 1 the split factorisations cost 30 s of user and 9 s of system CPU against 24 s
    /// and 0.1 s on one thread, with the same wall time and identical results, on the 2-core
    /// machine shared with other jobs (docs/accuracy.md, "What the estimate costs, and where
    /// the time goes"). Where the pool could not be started, `work` runs on the caller's thread.
    fn on_one_thread<R: Send>(&mut self, work: impl FnOnce(&mut Self) -> R + Send) -> R {
        match self.one_thread.take() {
            Some(pool) => {
                let out = pool.install(|| work(self));
                self.one_thread = Some(pool);
                out
            }
            None => work(self),
        }
    }

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
        let mut assess = |steps: &[Vec<f64>]| {
            let (full, moved) = amplitudes_after(&steps[0], true);
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
        let first = assess(&deltas);
        let step = path.map_or(f64::NAN, |p| p.step);
        let Some(fixed_steps) = fixed_deltas else {
            let mut truncation = first.truncation.clone();
            let mut estimate_harmonic = top;
            let mut contraction = first.contraction;
            let mut reported_step = deltas[0][..dim].to_vec();
            let widens = first.needs_wider
                && self.widens(&first.truncation, first.contraction, padded_converged);
            if widens && self.budget.wider.steps {
                if let Some(w) = self.wider_truncation(x, omega, None, &base) {
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
        let fixed = assess(&fixed_steps);
        let across = PathSwitch::across(slide, step);
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
            if let Some(w) = self.wider_truncation(x, omega, normal, &base) {
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

    /// How the reported truncation estimate stands ([`LinearRange`]): `truncation` (per
    /// output, replaced by the converged extended solution's change where that is solved),
    /// the extension it comes from, its step's contraction, and whether the padded point
    /// already solves that extension within the Newton tolerance ([`solves_padded`]: then the
    /// point is the extension's converged solution, its step a move within round-off whose
    /// contraction says nothing, and the step is kept); `beyond_the_budget` when the point was
    /// sent to a wider set the scene's budget does not step on ([`SetBudget::steps`]: then it
    /// is flagged). `across` is the path's normal
    /// (run unknowns, then ω) when the point reports the step across the path, `step` the
    /// reported step on the extension (with its δω last when across the path).
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

    /// The extended system solved to convergence across the path at the converged point `x`
    /// (full coefficients) at ω = `omega` (rad/s), from the point padded with zeros, on the
    /// hyperplane `path_normal` (as [`PointAccuracy::path_normal`]: a covector on the full
    /// coefficients, then on ω): the relative change of each output's amplitude, None where
    /// Newton does not converge. The set is the wider one (4H + 3) when `harmonic` (as
    /// [`PointAccuracy::estimate_harmonic`]) is its top, else 2H + 1. The estimate a point next
    /// to a fold reports where its across-path step leaves its linear range; here for any path
    /// point, to compare it with the true error across the path where no point reports it.
    pub fn solved_across(
        &mut self,
        x: &[f64],
        omega: f64,
        path_normal: &[f64],
        harmonic: usize,
    ) -> Option<Vec<f64>> {
        let (on_omega, on_full) = path_normal.split_last()?;
        if on_full.len() != x.len() {
            return None;
        }
        let mut normal: Vec<f64> = self.full_index.iter().map(|&i| on_full[i]).collect();
        normal.push(*on_omega);
        let base = amplitudes(self.problem, &self.set, x);
        let wider = harmonic == wider_harmonic(self.h_max);
        self.on_one_thread(|e| {
            e.converged_across(x, omega, wider, &base, &normal, (&[], f64::INFINITY))
        })
    }

    /// Whether a point that [`TailTest`] sends to the wider set is widened ([`WidenGate`]).
    fn widens(&self, truncation: &[f64], contraction: f64, padded_converged: bool) -> bool {
        WidenGate::widens(
            truncation,
            LinearRange::holds(contraction, padded_converged),
            self.problem.analysis.error_estimate.warn_threshold,
        )
    }

    /// The border row on the unknowns of `refined` for the path normal `normal` (the run's
    /// unknowns, then ω in rad/s); None when it does not fit or is not finite.
    fn row_on(&self, refined: &Refined, normal: &[f64]) -> Option<Vec<f64>> {
        let (on_omega, on_x) = normal.split_last()?;
        if on_x.len() != self.full_index.len() || normal.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut row = refined.on_kept_blocks(on_x, self.set.n_blocks())?;
        row.push(*on_omega);
        Some(row)
    }

    /// The converged solution of the extended system (the wider one when `wider`) across the
    /// path: Newton on the extended residual bordered with the path's hyperplane through the
    /// point, `normal` · (x − x₀, ω − ω₀) = 0 (`normal` on the run's unknowns, then ω in
    /// rad/s; zero on the new harmonics), as the relative change of each output's amplitude
    /// from `base`; None when Newton does not converge. What the across-path step of
    /// [`Self::estimate`] approximates, for the points next to a fold whose step leaves its
    /// linear range ([`LinearRange`]).
    ///
    /// `step` is that across-path step on the same set (its unknowns, then δω), `contraction`
    /// its contraction: where it lowers the residual the solve starts from the stepped point
    /// (in the hyperplane, since the step is), as [`Self::converged_truncation`] does. The
    /// Newton iterations are the continuation's corrector ([`Continuation::correct`]) with the
    /// hyperplane as its arc-length row, with three times the path's `max_iterations` as its
    /// limit, as the fixed-frequency solve, the iterations beyond the path's own only while
    /// the residual keeps falling ([`extended_newton`]). Three times the limit without that
    /// exit had sized 382 instead of 285 of the 607 such points of the larger blade pair at
    /// H = 1 over 855-895 Hz for 10 s more user CPU (38 s against 28 s); with it the estimate
    /// costs less than with the path's limit alone (docs/accuracy.md, "What the estimate
    /// costs").
    fn converged_across(
        &mut self,
        x: &[f64],
        omega: f64,
        wider: bool,
        base: &[f64],
        normal: &[f64],
        (step, contraction): (&[f64], f64),
    ) -> Option<Vec<f64>> {
        let n = self.problem.model.n_dofs();
        let row = self.row_on(if wider { &self.wider } else { &self.truncation }, normal)?;
        let refined = if wider {
            &mut self.wider
        } else {
            &mut self.truncation
        };
        let xr = refined.padded(n, x);
        let dim = xr.len();
        if row.len() != dim + 1 {
            return None;
        }
        // Scaled space of the corrector: x in units of the point's largest coefficient (as
        // the fixed-frequency solve's step tolerance), ω in Hz.
        let scale = xr.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
        let hz = 2.0 * std::f64::consts::PI;
        let (start, omega_start) = if contraction < 1.0 && step.len() == dim + 1 {
            (
                xr.iter()
                    .zip(step)
                    .map(|(a, d)| a - d)
                    .collect::<Vec<f64>>(),
                omega - step[dim],
            )
        } else {
            (xr.clone(), omega)
        };
        let mut predicted: Vec<f64> = start.iter().map(|v| v / scale).collect();
        predicted.push(omega_start / hz);
        // The hyperplane's normal in the scaled space, as a unit vector.
        let mut tangent: Vec<f64> = row[..dim].iter().map(|w| w * scale).collect();
        tangent.push(row[dim] * hz);
        let length = crate::numerics::linalg::norm(&tangent);
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        tangent.iter_mut().for_each(|v| *v /= length);
        let newton = extended_newton(self.problem, vec![scale; dim], 3);
        let (y, _, _) = newton
            .correct(&mut refined.operator, &predicted, &tangent)
            .ok()?;
        let solved: Vec<f64> = y[..dim].iter().map(|v| v * scale).collect();
        let ext = refined.operator.unknowns().clone();
        let full = refined.operator.expand(&solved, y[dim] * hz).ok()?;
        full.iter()
            .all(|v| v.is_finite())
            .then(|| relative_changes(&amplitudes(self.problem, &ext, &full), base))
    }

    /// The truncation estimate of the point `x` at `omega` on the wider set (4H + 3): at the
    /// fixed frequency, and across the path when the path's `normal` (run unknowns, then ω) is
    /// given and the bordered matrix factorises; None when the estimate cannot be formed.
    fn wider_truncation(
        &mut self,
        x: &[f64],
        omega: f64,
        normal: Option<&[f64]>,
        base: &[f64],
    ) -> Option<Wider> {
        let n = self.problem.model.n_dofs();
        let row = normal.and_then(|normal| self.row_on(&self.wider, normal));
        let wider = &mut self.wider;
        let xr = wider.padded(n, x);
        let dim = xr.len();
        let mut r = vec![0.0; dim];
        let mut dr = vec![0.0; dim];
        wider
            .operator
            .residual_and_jacobian(&xr, omega, &mut r, &mut wider.jacobian, &mut dr)
            .ok()?;
        let ext = wider.operator.unknowns().clone();
        let problem = self.problem;
        let r_norm = crate::numerics::linalg::norm(&r);
        let padded_converged = solves_padded(problem, &wider.operator, r_norm);
        // The change of each output and the step's contraction ([`LinearRange`]).
        let change = |w: &mut Refined, delta: &[f64], d_omega: f64| {
            let contraction = w
                .after_step(&xr, delta, omega - d_omega)
                .map_or(f64::NAN, |(_, after)| after / r_norm);
            w.stepped(&xr, delta, omega - d_omega).map(|full| {
                (
                    relative_changes(&amplitudes(problem, &ext, &full), base),
                    contraction,
                )
            })
        };
        if let Some(row) = row {
            let ones = vec![1.0; dim];
            if let Ok(factor) = wider.jacobian.factor_bordered(&ones, &dr, &row) {
                let mut b = r.clone();
                b.push(0.0);
                let mut along = vec![0.0; dim];
                along.push(1.0);
                if let (Ok(step), Ok(z)) = (factor.solve(&b), factor.solve(&along)) {
                    let (d_omega, z_omega) = (step[dim], z[dim]);
                    let s = d_omega / z_omega;
                    let fixed: Vec<f64> = step.iter().zip(&z).map(|(a, b)| a - s * b).collect();
                    let across = change(wider, &step[..dim], d_omega);
                    let fixed_change = change(wider, &fixed[..dim], fixed[dim]);
                    if let (Some(f), Some(a)) = (fixed_change, across) {
                        return Some(Wider {
                            padded_converged,
                            fixed: f.0,
                            fixed_contraction: f.1,
                            across: Some(a),
                            fixed_step: fixed[..dim].to_vec(),
                            across_step: Some(step),
                        });
                    }
                }
            }
        }
        let step = wider.jacobian.solve_many(&[&r]).ok()?.pop()?;
        change(wider, &step, 0.0).map(|f| Wider {
            padded_converged,
            fixed: f.0,
            fixed_contraction: f.1,
            across: None,
            fixed_step: step.clone(),
            across_step: None,
        })
    }

    /// The converged solution of the extended system (the wider one when `wider`) at the
    /// fixed ω (rad/s), by Newton from the point `x` padded with zeros, as the relative change
    /// of each output's amplitude from `base`; None when Newton does not converge. What the
    /// one Newton step of [`Self::estimate`] approximates, for the points where that step
    /// leaves its linear range ([`LinearRange`]).
    ///
    /// `step` is that Newton step at the fixed frequency on the same set (its unknowns), and
    /// `contraction` the residual after it relative to the residual before it. Where the step
    /// lowers the residual (contraction below 1), Newton from the padded point would take it
    /// in full as its first iteration (same Jacobian, full step accepted by the line search),
    /// so the solve starts from the stepped point instead: the same iterates, one Jacobian and
    /// factorisation fewer. Other starts that were measured change the solution some points
    /// converge to (docs/accuracy.md, "What the estimate costs").
    fn converged_truncation(
        &mut self,
        x: &[f64],
        omega: f64,
        wider: bool,
        base: &[f64],
        (step, contraction): (&[f64], f64),
    ) -> Option<Vec<f64>> {
        let n = self.problem.model.n_dofs();
        let refined = if wider {
            &mut self.wider
        } else {
            &mut self.truncation
        };
        let xr = refined.padded(n, x);
        // The step tolerance is relative to the point's largest coefficient.
        let scale = xr.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
        let start: Vec<f64> = if contraction < 1.0 && step.len() == xr.len() {
            xr.iter().zip(step).map(|(a, d)| a - d).collect()
        } else {
            xr.clone()
        };
        let newton = extended_newton(self.problem, vec![scale; xr.len()], 1);
        let solved = newton
            .solve_fixed(&mut refined.operator, &start, omega)
            .ok()?;
        let ext = refined.operator.unknowns().clone();
        let full = refined.operator.expand(&solved.x, omega).ok()?;
        full.iter()
            .all(|v| v.is_finite())
            .then(|| relative_changes(&amplitudes(self.problem, &ext, &full), base))
    }

    /// The bordered Newton steps (δx, δω) of [[J, ∂R/∂ω], [row]] (δx, δω) = (r, 0) for each
    /// residual r of `rhs`, with one factorisation (the Jacobian last evaluated by the
    /// truncation operator, `dr` its ∂R/∂ω).
    /// The last right-hand side takes 1 in the border row instead of 0: its solution is the
    /// path's direction.
    fn bordered_steps(
        &mut self,
        dr: &[f64],
        row: &[f64],
        rhs: &[&[f64]],
    ) -> Result<Vec<Vec<f64>>, LinearSolveError> {
        let ones = vec![1.0; dr.len()];
        let factor = self.truncation.jacobian.factor_bordered(&ones, dr, row)?;
        let last = rhs.len() - 1;
        rhs.iter()
            .enumerate()
            .map(|(k, r)| {
                let mut b = r.to_vec();
                b.push(if k == last { 1.0 } else { 0.0 });
                let step = factor.solve(&b)?;
                if step.iter().all(|v| v.is_finite()) {
                    Ok(step)
                } else {
                    Err(LinearSolveError::NonFinite)
                }
            })
            .collect()
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
fn extended_newton(problem: &Problem, x_scale: Vec<f64>, limit_factor: usize) -> Continuation {
    let mut settings = problem.analysis.continuation;
    let after = settings.max_iterations;
    settings.max_iterations *= limit_factor;
    Continuation::new(settings, x_scale).with_stagnation_exit(StagnationExit { after })
}

/// A frequency band where an estimate exceeds the scene's threshold, for the end-of-run warning.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyWarning {
    /// `truncation` or `sampling`.
    pub kind: EstimateKind,
    /// Output DOF index (into the problem's outputs).
    pub output: usize,
    /// Lowest and highest frequency of the points above the threshold (Hz).
    pub from_hz: f64,
    /// See `from_hz`.
    pub to_hz: f64,
    /// Largest estimate in the band (relative).
    pub largest: f64,
}

/// Which estimate a warning is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EstimateKind {
    /// Harmonic truncation.
    Truncation,
    /// AFT sampling.
    Sampling,
    /// Points whose truncation error could not be sized ([`EstimateMethod::Unsized`]): the
    /// band holds them whatever their estimate.
    Unsized,
    /// Points whose truncation error was not sized because the scene skips the solve beyond
    /// the step's linear range ([`EstimateMethod::Unsolved`]).
    Unsolved,
}

/// Bands of consecutive points (in path order) where an estimate exceeds `threshold`, per
/// output and kind; NaN estimates (not formed) count as above. Bands less than
/// [`MERGE_FRACTION`] of the points' frequency span apart are reported as one.
pub fn warnings(
    points: &[(f64, &PointAccuracy)],
    outputs: usize,
    threshold: f64,
) -> Vec<AccuracyWarning> {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    let gap = MERGE_FRACTION * (hi - lo).max(0.0);
    let mut merged: Vec<AccuracyWarning> = Vec::new();
    for w in bands(points, outputs, threshold) {
        match merged.last_mut() {
            Some(last)
                if last.kind == w.kind
                    && last.output == w.output
                    && w.from_hz - last.to_hz <= gap
                    && last.from_hz - w.to_hz <= gap =>
            {
                last.from_hz = last.from_hz.min(w.from_hz);
                last.to_hz = last.to_hz.max(w.to_hz);
                if w.largest > last.largest || w.largest.is_nan() {
                    last.largest = w.largest;
                }
            }
            _ => merged.push(w),
        }
    }
    merged
}

/// Fraction of the frequency span under which two warning bands are merged.
pub const MERGE_FRACTION: f64 = 0.02;

/// The bands of [`warnings`] before merging.
fn bands(points: &[(f64, &PointAccuracy)], outputs: usize, threshold: f64) -> Vec<AccuracyWarning> {
    let mut found = Vec::new();
    for kind in [
        EstimateKind::Truncation,
        EstimateKind::Sampling,
        EstimateKind::Unsized,
        EstimateKind::Unsolved,
    ] {
        for output in 0..outputs {
            let mut band: Option<AccuracyWarning> = None;
            for &(freq_hz, acc) in points {
                let values = match kind {
                    EstimateKind::Truncation | EstimateKind::Unsized | EstimateKind::Unsolved => {
                        &acc.truncation
                    }
                    EstimateKind::Sampling => &acc.sampling,
                };
                let e = values.get(output).copied().unwrap_or(f64::NAN);
                let not_sized = matches!(
                    acc.method,
                    EstimateMethod::Unsized | EstimateMethod::Unsolved
                );
                let inside = match kind {
                    // Points not sized warn in their own bands, not as a size.
                    EstimateKind::Truncation => !not_sized && (e > threshold || e.is_nan()),
                    EstimateKind::Sampling => e > threshold || e.is_nan(),
                    EstimateKind::Unsized => acc.method == EstimateMethod::Unsized,
                    EstimateKind::Unsolved => acc.method == EstimateMethod::Unsolved,
                };
                if inside {
                    let b = band.get_or_insert(AccuracyWarning {
                        kind,
                        output,
                        from_hz: freq_hz,
                        to_hz: freq_hz,
                        largest: e,
                    });
                    b.from_hz = b.from_hz.min(freq_hz);
                    b.to_hz = b.to_hz.max(freq_hz);
                    if e > b.largest || e.is_nan() {
                        b.largest = e;
                    }
                } else if let Some(b) = band.take() {
                    found.push(b);
                }
            }
            found.extend(band);
        }
    }
    found
}

/// The relative truncation estimate above which a warning says the size is not to be read:
/// the estimate is one Newton step of the extended system, and a step that changes the
/// amplitude by more than the amplitude itself is outside the reach of the linearisation it
/// comes from. Measured on the reduced blade pair at H = 1 (docs/accuracy.md, "The larger
/// blade pair at H = 1, on its small folds"): its points with estimates of 560-8907 % have no
/// state nearby at H = 3, 5 or 7 (Newton from the padded point does not converge at the
/// point's frequency), and the nearest one across the path is 33-39 % away.
pub const BEYOND_LINEAR: f64 = 1.0;

/// The warning line of a band: where, how large, and which field to raise. `h_max` is the
/// highest balanced harmonic, `samples` the samples per period, `output` the DOF's name.
pub fn warning_text(w: &AccuracyWarning, output: &str, h_max: usize, samples: usize) -> String {
    let size = if w.largest.is_nan() {
        "could not be estimated".to_string()
    } else {
        format!("is estimated at up to {:.2} %", 100.0 * w.largest)
    };
    let (what, advice) = match w.kind {
        EstimateKind::Truncation if w.largest > BEYOND_LINEAR => (
            "harmonic truncation",
            format!(
                "harmonics.max > {h_max} needed; an estimate above {:.0} % is beyond what a \
                 first-order step can size: these points may lie on a branch of the truncated \
                 model that has no counterpart at H = {} (read them as wrong, not as off by that \
                 much, and solve the band at the higher H)",
                100.0 * BEYOND_LINEAR,
                extended_harmonic(h_max)
            ),
        ),
        EstimateKind::Truncation => (
            "harmonic truncation",
            format!(
                "harmonics.max > {h_max} needed (the estimate compares with H = {}, or {} where \
                 contacts stay stuck or the harmonics decay slowly)",
                extended_harmonic(h_max),
                wider_harmonic(h_max)
            ),
        ),
        EstimateKind::Sampling => (
            "AFT sampling",
            format!("harmonics.samples > {samples} needed (try {})", 2 * samples),
        ),
        EstimateKind::Unsolved => {
            return format!(
                "accuracy: the harmonic truncation error of {output}'s amplitude was not sized \
                 between {:.4} and {:.4} Hz: the estimate's Newton step leaves its linear range \
                 there (a contact changes regime with more harmonics), or the error lies beyond \
                 H = {} (a contact stuck all period), and the solve on H = {} (or {}) or the step \
                 on H = {} that sizes it was skipped (accuracy.beyond_linear_range = \"flag\", \
                 or \"auto\" where it costs more than its budget: `fricbound check` says which \
                 and how much); set it to \"solve\", or solve the band at harmonics.max > \
                 {h_max} and compare",
                w.from_hz,
                w.to_hz,
                extended_harmonic(h_max),
                extended_harmonic(h_max),
                wider_harmonic(h_max),
                wider_harmonic(h_max)
            );
        }
        EstimateKind::Unsized => {
            return format!(
                "accuracy: the harmonic truncation error of {output}'s amplitude could not be \
                 sized between {:.4} and {:.4} Hz: the estimate's Newton step leaves its linear \
                 range there (a contact changes regime with more harmonics) and the system on \
                 H = {} (or {}) has no converged solution there (at those frequencies, or \
                 across the path next to a fold); solve the band \
                 at harmonics.max > {h_max} and compare",
                w.from_hz,
                w.to_hz,
                extended_harmonic(h_max),
                wider_harmonic(h_max)
            );
        }
    };
    format!(
        "accuracy: the {what} error of {output}'s amplitude {size} between {:.4} and {:.4} Hz: \
         {advice}",
        w.from_hz, w.to_hz
    )
}

/// The largest estimate per output over `points` (NaN ignored; 0 for no points), truncation
/// then sampling.
pub fn largest(points: &[&PointAccuracy], outputs: usize) -> (Vec<f64>, Vec<f64>) {
    let mut trunc = vec![0.0_f64; outputs];
    let mut samp = vec![0.0_f64; outputs];
    for p in points {
        for (m, v) in trunc.iter_mut().zip(&p.truncation) {
            if v.is_finite() {
                *m = m.max(*v);
            }
        }
        for (m, v) in samp.iter_mut().zip(&p.sampling) {
            if v.is_finite() {
                *m = m.max(*v);
            }
        }
    }
    (trunc, samp)
}

/// The end-of-run warning lines of a run's estimates (frequency in Hz and estimate of each
/// point that has one, in path order; see `crate::analysis::frf::accuracy_of`): one per band
/// where an estimate exceeds the scene's threshold ([`warnings`], [`warning_text`]); empty when
/// the estimate is off or everything is below the threshold.
pub fn run_warnings(problem: &Problem, with: &[(f64, &PointAccuracy)]) -> Vec<String> {
    let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
    warnings(
        with,
        problem.outputs.len(),
        problem.analysis.error_estimate.warn_threshold,
    )
    .iter()
    .map(|w| {
        let name = &problem.model.dof_names[problem.outputs[w.output]];
        warning_text(w, name, h_max, problem.samples)
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn acc(t: f64, s: f64) -> PointAccuracy {
        PointAccuracy {
            truncation: vec![t],
            sampling: vec![s],
            across_path: false,
            path_normal: None,
            both_truncation: None,
            slide_and_step: (f64::NAN, f64::NAN),
            estimate_harmonic: 3,
            step_changes_regime: false,
            contraction: 0.0,
            method: EstimateMethod::Step,
        }
    }

    #[test]
    fn warning_bands_join_consecutive_points() {
        let a = [
            acc(0.001, 0.0),
            acc(0.05, 0.0),
            acc(0.02, 0.0),
            acc(0.001, 0.2),
            acc(0.03, 0.0),
            acc(0.001, 0.0),
            acc(0.001, 0.0),
            acc(0.04, 0.0),
        ];
        let points: Vec<(f64, &PointAccuracy)> =
            [100.0, 101.0, 102.0, 103.0, 104.0, 120.0, 150.0, 200.0]
                .into_iter()
                .zip(&a)
                .collect();
        let w = warnings(&points, 1, 0.01);
        assert_eq!(w.len(), 3, "{w:?}");
        // 101-102 and 104 are 2 Hz apart, under 2 % of the 100 Hz span: one band.
        assert_eq!(w[0].kind, EstimateKind::Truncation);
        assert_eq!(
            (w[0].from_hz, w[0].to_hz, w[0].largest),
            (101.0, 104.0, 0.05)
        );
        assert_eq!((w[1].from_hz, w[1].to_hz), (200.0, 200.0));
        assert_eq!(w[2].kind, EstimateKind::Sampling);
        assert_eq!((w[2].from_hz, w[2].to_hz), (103.0, 103.0));
        let text = warning_text(&w[0], "y2", 1, 256);
        assert!(text.contains("harmonics.max > 1"), "{text}");
        assert!(text.contains("101.0000 and 104.0000 Hz"), "{text}");
        assert!(!text.contains("no counterpart"), "{text}");
        // Above 100 % the size is beyond a first-order step: the warning says so.
        let huge = AccuracyWarning {
            largest: 89.07,
            ..w[0].clone()
        };
        let text = warning_text(&huge, "y2", 1, 256);
        assert!(text.contains("8907.00 %"), "{text}");
        assert!(text.contains("no counterpart at H = 3"), "{text}");
    }

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

    /// Points with the truncation estimates `truncation` (sampling 0) and, at the indices
    /// given, the methods given.
    fn marked(truncation: &[f64], methods: &[(usize, EstimateMethod)]) -> Vec<PointAccuracy> {
        let mut a: Vec<PointAccuracy> = truncation.iter().map(|&t| acc(t, 0.0)).collect();
        for &(i, method) in methods {
            a[i].method = method;
        }
        a
    }

    #[test]
    fn unsized_points_warn_in_their_own_band() {
        // Two points not sizeable with small estimates between sized ones, one of them above
        // the threshold: the unsized ones form their own band and do not count as a size.
        let a = marked(
            &[0.001, 0.002, 0.003, 0.05],
            &[(1, EstimateMethod::Unsized), (2, EstimateMethod::Unsized)],
        );
        let points: Vec<(f64, &PointAccuracy)> =
            [100.0, 110.0, 120.0, 200.0].into_iter().zip(&a).collect();
        let w = warnings(&points, 1, 0.01);
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(w[0].kind, EstimateKind::Truncation);
        assert_eq!((w[0].from_hz, w[0].to_hz), (200.0, 200.0));
        assert_eq!(w[1].kind, EstimateKind::Unsized);
        assert_eq!((w[1].from_hz, w[1].to_hz), (110.0, 120.0));
        let text = warning_text(&w[1], "y2", 3, 256);
        assert!(
            text.contains("could not be sized between 110.0000 and 120.0000 Hz"),
            "{text}"
        );
        assert!(text.contains("H = 7 (or 15)"), "{text}");
        assert!(text.contains("harmonics.max > 3"), "{text}");
        assert_eq!(EstimateMethod::Unsized.label(), "unsized");
    }

    #[test]
    fn unsolved_points_warn_in_a_band_of_their_own() {
        // Points flagged because the scene skips the solve (`beyond_linear_range = "flag"`)
        // next to points whose solve failed: two bands, each with its own advice.
        let a = marked(
            &[0.001, 0.002, 0.003, 0.004],
            &[
                (0, EstimateMethod::Unsized),
                (2, EstimateMethod::Unsolved),
                (3, EstimateMethod::Unsolved),
            ],
        );
        let points: Vec<(f64, &PointAccuracy)> =
            [100.0, 150.0, 180.0, 200.0].into_iter().zip(&a).collect();
        let w = warnings(&points, 1, 0.01);
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(w[0].kind, EstimateKind::Unsized);
        assert_eq!((w[0].from_hz, w[0].to_hz), (100.0, 100.0));
        assert_eq!(w[1].kind, EstimateKind::Unsolved);
        assert_eq!((w[1].from_hz, w[1].to_hz), (180.0, 200.0));
        let text = warning_text(&w[1], "y2", 3, 256);
        assert!(
            text.contains("was not sized between 180.0000 and 200.0000 Hz")
                && text.contains("accuracy.beyond_linear_range = \"flag\"")
                && text.contains("set it to \"solve\""),
            "{text}"
        );
        assert_eq!(EstimateMethod::Unsolved.label(), "unsolved");
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

    #[test]
    fn largest_ignores_unformed_estimates() {
        let a = [acc(0.01, f64::NAN), acc(0.03, 0.002)];
        let refs: Vec<&PointAccuracy> = a.iter().collect();
        assert_eq!(largest(&refs, 1), (vec![0.03], vec![0.002]));
    }
}
