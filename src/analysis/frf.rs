//! Frequency-response runs: continuation of the harmonic balance over the scene's range, with
//! per-point outputs (amplitudes, peaks, contact states) handed to an observer as they come.

use std::collections::VecDeque;
use std::f64::consts::PI;
use std::thread::Scope;
use std::time::Instant;

use crate::analysis::error_estimate::{EstimateProblems, PathPlace, PointAccuracy};
use crate::analysis::estimate_pool::{EstimatePool, EstimateTicket, Submitted};
use crate::analysis::linear;
use crate::analysis::monodromy::point_monodromy;
use crate::analysis::stability::{PointStability, StabilityError};
use crate::analysis::stability_sparse::{hill_solver_for, point_stability_with};
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::ContactState;
use crate::hbm::operator::HbmOperator;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::{Problem, StabilityMethod};
use crate::numerics::continuation::AdaptiveScale;
use crate::numerics::golden;
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::path::NoObserver;
use crate::numerics::{
    Continuation, ContinuationError, ContinuationSettings, NewtonFailure, Observer,
    ParametricResidual, PathEnd, PathPoint, PathSummary,
};

/// One converged point of a nonlinear frequency response.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrfPoint {
    /// Excitation frequency (Hz).
    pub freq_hz: f64,
    /// First-harmonic amplitude √(c₁² + s₁²) of each output DOF (m).
    pub amplitudes: Vec<f64>,
    /// Peak |q(τ)| over the period of each output DOF, static part included (m).
    pub peaks: Vec<f64>,
    /// Contact state of each contact over the period.
    pub states: Vec<ContactState>,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Final residual relative to the load norm.
    pub residual: f64,
    /// All Fourier coefficients, harmonic-major (m).
    pub coefficients: Vec<f64>,
    /// A-posteriori error estimate of the amplitudes (continuation points of a run whose
    /// scene asks for it; None for points solved on their own, such as refined peaks).
    pub accuracy: Option<PointAccuracy>,
    /// The estimate a worker is still forming for this point, inside a run
    /// ([`crate::analysis::estimate_pool`]); None on every point a run reports, whose
    /// `accuracy` is filled by then.
    #[serde(skip)]
    pub pending_estimate: Option<EstimateTicket>,
    /// Hill stability of the point, when the scene asks for it (`analysis.stability`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<PointStability>,
}

/// The frequency (Hz) and error estimate of every point of `points` that has one, in order
/// (for [`crate::analysis::error_estimate::run_warnings`]).
pub fn accuracy_of(points: &[FrfPoint]) -> Vec<(f64, &PointAccuracy)> {
    points
        .iter()
        .filter_map(|p| p.accuracy.as_ref().map(|a| (p.freq_hz, a)))
        .collect()
}

/// A jump of an FRF run from one branch to another: where the path turned back at a fold and
/// did not come back, the run goes on on a branch found past the highest frequency reached, and
/// solves further branches inside any stretch that neither branch reached.
///
/// Serialised (`solution.json`'s `jumps`) with its fields and `abandoned`
/// ([`Jump::abandons_branch`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// Highest frequency of the branch before the jump (Hz).
    pub from_hz: f64,
    /// Lowest frequency of the branch after the jump (Hz): a branch found past a fold is
    /// followed back down toward `from_hz` as far as it goes. Frequencies between the two were
    /// not computed on any branch (none when `to_hz` ≤ `from_hz`).
    pub to_hz: f64,
    /// Index of the next branch's first point in the run's points.
    pub first_point: usize,
    /// Why the run changed branch.
    pub kind: JumpKind,
    /// How the branch before the jump ended: followed until it left the range, or given up
    /// inside it (where and why). [`BranchEnd::Bridge`] for a bridge branch.
    pub before: BranchEnd,
    /// Where the branch after the jump (the fill, followed back down toward the fold, or a
    /// bridge, followed toward the edges of its stretch) was left off every stretch followed
    /// before (see [`fill_cut`]): at its edge after turning back at a fold of its own, or
    /// given up before its edge (a dead end, no progress, its point budget used up); for a
    /// bridge cut both ways, its way down's ([`Jump::second_cut`]). That branch may go on beyond the
    /// point, not followed. It does not count in [`Jump::abandons_branch`] (which is about the
    /// branch before the jump); whether it counts in the run's status is decided by
    /// [`Jump::cut_check`], once the branches solved after it are known. None otherwise.
    pub fill_cut: Option<GivenUp>,
    /// How [`Jump::fill_cut`] was judged once the run was over ([`CutCheck`]): by a Newton
    /// solve just past it, whose landing either lies on a stretch of the run (the cut is
    /// covered; past the cut stretch's fold when the landing is its own other side) or not
    /// (the branch given up there goes on, unfollowed: the run is incomplete).
    /// None without a cut, and for jumps reported before the judgement (see
    /// [`FrfObserver::cut_judged`]).
    pub cut_check: Option<CutCheck>,
    /// The cut of a bridge's way up when its way down was cut too (then [`Jump::fill_cut`] is
    /// the way down's): a bridge, followed toward both edges of its stretch, can be left off
    /// the run at both, and each may leave its branch unfollowed beyond. None otherwise.
    pub second_cut: Option<GivenUp>,
    /// How [`Jump::second_cut`] was judged, as [`Jump::cut_check`] for [`Jump::fill_cut`].
    pub second_cut_check: Option<CutCheck>,
    /// How the branch before the jump, given up inside the range off every stretch followed
    /// ([`BranchEnd::Abandoned`]), was judged once the run was over: as a cut is
    /// ([`judge_cuts`]), by Newton just past its last point, the way the path was going. A
    /// landing on a stretch of the run covers it (the branch beyond the point given up is one
    /// the run has: nothing is missing, [`Jump::abandons_branch`] is false); a landing on no
    /// stretch, or no landing, leaves it abandoned. None for other branch ends, and for jumps
    /// reported before the judgement.
    pub end_check: Option<CutCheck>,
}

/// The judgement of a cut ([`Jump::fill_cut`]): Newton at a fixed frequency just past the cut,
/// in the direction the stretch was going at its last step, from the cut point's coefficients
/// (at most five solves, the first that converges is kept, see [`judge_cuts`]), the crossings
/// of that frequency by the run's points within a branch, compared on the coefficients, and
/// Newton at that frequency from each crossing within [`RETRACE_TOLERANCE`], which tells
/// whether the landing is that crossing's solution (`cut_check` in `solution.json`'s jumps).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CutCheck {
    /// Where Newton landed just past the cut and how that landing compares with the run
    /// (flattened into `cut_check` in `solution.json`).
    #[serde(flatten)]
    pub landing: Landing,
    /// Whether the crossing of [`Landing::distance`] lies on the cut's own branch, on the
    /// stretch into the cut or the other side of the fold before it: next to a fold the two
    /// sides lie within [`RETRACE_TOLERANCE`] of each other, and only Newton from that side
    /// ([`Landing::resolved_distance`]) tells whether the landing is on it (see
    /// [`judge_cuts`]).
    pub own_side: bool,
    /// Newton iterations of the converged solve (0 without one): with the solves that did
    /// not converge (at most five in all, see [`judge_cuts`]), the judgement's cost.
    pub newton_iterations: usize,
    /// When the landing is the cut's own other side ([`CutCheck::own_side`], the same
    /// solution: the stretch came back along the side it had followed into its fold, so the
    /// path reversed there on one solution curve), the same judgement past that fold, the way
    /// that side was heading: the branch goes on there. The cut's verdict is then its verdict.
    /// None otherwise.
    pub beyond_fold: Option<FoldCheck>,
    /// What the judgement says.
    pub verdict: CutVerdict,
}

/// A Newton landing at a fixed frequency past a point of the run (a cut, or the fold of a cut
/// stretch, see [`judge_cuts`]), compared with the run: the fields shared by [`CutCheck`] and
/// [`FoldCheck`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Landing {
    /// Frequency of the last solve tried, the converged one if any (Hz).
    pub freq_hz: f64,
    /// First output's first-harmonic amplitude where Newton landed (m); None when no solve
    /// converged.
    pub amplitude: Option<f64>,
    /// ‖c − c_run‖ / ‖c‖ over all Fourier coefficients between the landing c and the crossing
    /// c_run of its frequency by the run (linear along a segment within a branch) that the
    /// verdict rests on: the one Newton found the landing on when covered, else the nearest;
    /// None without a landing or a crossing.
    pub distance: Option<f64>,
    /// ‖c − c_N‖ / ‖c‖ between the landing c and Newton's solution c_N at the landing's
    /// frequency started from the crossing of [`Landing::distance`] (see [`judge_cuts`]): at
    /// most [`SAME_SOLUTION_TOLERANCE`], the landing is that stretch's solution (covered);
    /// above, it is another solution. None when no crossing lies within
    /// [`RETRACE_TOLERANCE`] of the landing, or Newton from it converged nowhere.
    pub resolved_distance: Option<f64>,
}

impl Landing {
    /// No solve converged; `freq_hz` (Hz) is the frequency of the last one tried.
    fn nowhere(freq_hz: f64) -> Self {
        Self {
            freq_hz,
            amplitude: None,
            distance: None,
            resolved_distance: None,
        }
    }
}

/// The judgement past the fold of a cut stretch that came back along its own other side
/// ([`CutCheck::beyond_fold`]): Newton past the fold, from the fold point's coefficients, at
/// the offsets of [`judge_cuts`], compared with the run as the landing past the cut is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FoldCheck {
    /// Frequency of the fold: the turning point of the cut's stretch (Hz).
    pub fold_hz: f64,
    /// Where Newton landed past the fold and how that landing compares with the run
    /// (flattened into `beyond_fold` in `solution.json`).
    #[serde(flatten)]
    pub landing: Landing,
    /// The largest first-output amplitude of the run where it crosses the landing's
    /// frequency [`Landing::freq_hz`] (m); None when it does not.
    pub run_amplitude: Option<f64>,
    /// `covered` when Newton from a stretch of the run finds the landing, or when the landing
    /// lies below the run's largest amplitude there (a lower branch beside the response the
    /// run has, which the run does not follow anywhere, as below the end of a fill);
    /// `abandoned` when it lies on no stretch and above everything the run has there: the
    /// branch beyond the fold, not followed, carries a larger response (possibly the resonance
    /// peak); `unjudged` when no solve converged.
    pub verdict: CutVerdict,
}

impl FoldCheck {
    /// `past` (where Newton landed beyond the fold) followed by how that landing compares with
    /// the run and the verdict; `fold` names the fold for an abandoned landing.
    fn describe_landing(&self, past: &str, fold: &str) -> String {
        let run = self.run_amplitude.map_or(
            "no stretch of the run crosses that frequency".to_string(),
            |m| format!("the run's largest amplitude there is {m:.3e} m"),
        );
        let on_run = self
            .landing
            .resolved_distance
            .is_some_and(|d| d <= SAME_SOLUTION_TOLERANCE);
        match self.verdict {
            CutVerdict::Covered if on_run => format!("{past}, on a stretch of the run: covered"),
            CutVerdict::Covered => format!(
                "{past}, on no stretch of the run but below it ({run}): a lower branch beside \
                 the response the run has, covered"
            ),
            _ => format!(
                "{past}, on no stretch of the run and above it ({run}): a branch beyond {fold}, \
                 not followed"
            ),
        }
    }
}

/// What a [`CutCheck`] says (`verdict` in `solution.json`: `covered`, `abandoned`,
/// `unjudged`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CutVerdict {
    /// Newton past the cut landed on a stretch of the run: within [`RETRACE_TOLERANCE`] of it
    /// on the coefficients, and Newton from that stretch at the landing's frequency converges
    /// to the landing (within [`SAME_SOLUTION_TOLERANCE`]): the branch beyond the cut is the
    /// one the run has there.
    Covered,
    /// Newton past the cut landed on no stretch of the run: none crosses its frequency within
    /// [`RETRACE_TOLERANCE`], or Newton from each that does converges to another solution (a
    /// landing beyond a fold of the cut's own stretch, next to its other side) or nowhere.
    /// The branch given up at the cut goes on beyond it, not followed (possibly to a resonance
    /// peak). The run is incomplete.
    Abandoned,
    /// Newton past the cut converged at none of the offsets tried: whether the branch goes on
    /// there is not known. Counted as not covered (the run is incomplete and says why), since
    /// a cut nobody checked may hide the response beyond it.
    Unjudged,
}

impl CutCheck {
    /// Whether the cut leaves response missing or unknown ([`CutVerdict::Abandoned`],
    /// [`CutVerdict::Unjudged`]): counted in the run's status.
    pub fn uncovered(&self) -> bool {
        !matches!(self.verdict, CutVerdict::Covered)
    }

    /// "Newton just past the cut, at 886.8496 Hz, lands at 1.772e-5 m (first output), 0.02 %
    /// (on the coefficients) from the nearest stretch of the run (the cut branch's own side of
    /// its fold), but Newton from that stretch at the same frequency converges to another
    /// solution …: the landing lies on a branch beyond the fold …, not followed", for status
    /// lines and messages.
    pub fn describe(&self) -> String {
        self.describe_past("the cut")
    }

    /// [`CutCheck::describe`] for a judgement past `what` ("the cut", "the point given up"
    /// for a [`Jump::end_check`]).
    pub fn describe_past(&self, what: &str) -> String {
        let Some(a) = self
            .landing
            .amplitude
            .filter(|_| self.verdict != CutVerdict::Unjudged || self.beyond_fold.is_some())
        else {
            let nowhere = format!(
                "Newton just past {what} converged at none of the frequencies tried (the last \
                 {:.4} Hz)",
                self.landing.freq_hz
            );
            let Some(fold) = &self.beyond_fold else {
                return format!("{nowhere}: whether the branch goes on there is not known");
            };
            // The other side of a fold at the dead end ([`judge_round_dead_end`]).
            let Some(b) = fold.landing.amplitude else {
                return format!("{nowhere}: whether the branch goes on there is not known");
            };
            let past = format!(
                "{nowhere}, and with the frequency free, on the stretch's chord in the unknowns \
                 past the point, Newton lands behind it at {:.4} Hz, {b:.3e} m: the branch \
                 turns back there at a fold",
                fold.landing.freq_hz
            );
            return fold.describe_landing(&past, "that fold");
        };
        let landing = format!(
            "Newton just past {what}, at {:.4} Hz, lands at {a:.3e} m (first output)",
            self.landing.freq_hz
        );
        let Some(d) = self.landing.distance else {
            return format!(
                "{landing}; no stretch of the run crosses that frequency: on no branch of the run"
            );
        };
        let stretch = if self.own_side {
            "the branch's own side of its fold"
        } else {
            "another stretch of the run"
        };
        let place = format!(
            "{landing}, {:.2} % (on the coefficients) from the nearest stretch of the run \
             checked, {stretch}",
            100.0 * d
        );
        if let (Some(fold), Some(r)) = (&self.beyond_fold, self.landing.resolved_distance) {
            let back = format!(
                "{place}, and Newton from that side at the same frequency converges to the \
                 landing ({r:.1e} apart): the stretch came back along the side it had followed \
                 into its fold at {:.4} Hz, so the branch goes on beyond that fold",
                fold.fold_hz
            );
            let Some(b) = fold.landing.amplitude else {
                return format!(
                    "{back}; Newton past the fold converged at none of the frequencies tried \
                     (the last {:.4} Hz): whether the response there is on the run is not known",
                    fold.landing.freq_hz
                );
            };
            let past = format!(
                "{back}; Newton past the fold, at {:.4} Hz, lands at {b:.3e} m",
                fold.landing.freq_hz
            );
            return fold.describe_landing(&past, "the fold of that branch");
        }
        match (self.verdict, self.landing.resolved_distance) {
            (CutVerdict::Covered, Some(r)) => format!(
                "{place}, and Newton from that stretch at the same frequency converges to the \
                 landing ({r:.1e} apart): covered"
            ),
            (CutVerdict::Covered, None) => format!("{place}: covered"),
            (_, Some(r)) if self.own_side => format!(
                "{place}, but Newton from that side at the same frequency converges to another \
                 solution ({r:.1e} apart): the landing lies on a branch beyond the fold of \
                 that branch, not followed"
            ),
            (_, Some(r)) => format!(
                "{place}, but Newton from that stretch at the same frequency converges to \
                 another solution ({r:.1e} apart): the landing lies on a branch the run does \
                 not have"
            ),
            (_, None) if d <= RETRACE_TOLERANCE => format!(
                "{place}, but Newton from that stretch at the same frequency does not converge: \
                 whether the landing lies on it is not known"
            ),
            (_, None) => format!("{place}: on no branch of the run"),
        }
    }
}

impl serde::Serialize for Jump {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut record = serializer.serialize_struct("Jump", 11)?;
        record.serialize_field("from_hz", &self.from_hz)?;
        record.serialize_field("to_hz", &self.to_hz)?;
        record.serialize_field("first_point", &self.first_point)?;
        record.serialize_field("kind", &self.kind)?;
        record.serialize_field("abandoned", &self.abandons_branch())?;
        record.serialize_field("before", &self.before)?;
        record.serialize_field("fill_cut", &self.fill_cut)?;
        record.serialize_field("cut_check", &self.cut_check)?;
        record.serialize_field("second_cut", &self.second_cut)?;
        record.serialize_field("second_cut_check", &self.second_cut_check)?;
        record.serialize_field("end_check", &self.end_check)?;
        record.end()
    }
}

/// How the branch before a [`Jump`] ended (`before` in `solution.json`'s jumps, with `how`
/// one of `left-range`, `abandoned`, `retrace`, `outside-range`, `bridge`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case", tag = "how")]
pub enum BranchEnd {
    /// The branch was followed until it left the range below the start frequency
    /// ([`PathEnd::LeftRangeBelow`]): nothing inside the range was given up on it.
    LeftRange,
    /// The path could not be followed on from its last point (a dead end or no progress), and
    /// that point does not lie on a stretch already followed: the branch beyond it, possibly
    /// with a resonance peak, was not computed. The run is incomplete.
    Abandoned(GivenUp),
    /// The path could not be followed on from its last point, but that point lies on a stretch
    /// the run had already followed, within [`RETRACE_TOLERANCE`] at the same frequency: the
    /// path was retracing itself, and nothing was abandoned.
    Retrace(GivenUp),
    /// The path could not be followed on from its last point, which lies below the start
    /// frequency: the branch had run out of the range (as one that left it, but before the
    /// continuation counted it as gone), so nothing inside the range was abandoned.
    OutsideRange(GivenUp),
    /// A bridge branch solved inside an uncovered stretch: the branch before it was not ended
    /// by the path (see [`JumpKind::Bridge`]).
    Bridge,
}

impl BranchEnd {
    /// How the branch ended, in words following "the branch before the jump was" (None for a
    /// branch followed out of the range and for a bridge, which end nothing): the one wording
    /// of the run's status line ([`FrfRun::incomplete_reason`]) and of the message at the jump.
    pub fn words(&self) -> Option<String> {
        match self {
            BranchEnd::Abandoned(g) => Some(format!(
                "abandoned {}: the response beyond that point on that branch (possibly the \
                 resonance peak) was not computed",
                g.describe()
            )),
            BranchEnd::Retrace(g) => Some(format!(
                "given up {}, on a stretch already followed (a retrace): nothing is missing there",
                g.describe()
            )),
            BranchEnd::OutsideRange(g) => Some(format!(
                "given up {}, below the start frequency: nothing inside the range is missing \
                 there",
                g.describe()
            )),
            BranchEnd::LeftRange | BranchEnd::Bridge => None,
        }
    }
}

/// Where and why a branch was given up ([`BranchEnd::Abandoned`], [`BranchEnd::Retrace`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GivenUp {
    /// Frequency of the branch's last point (Hz).
    pub freq_hz: f64,
    /// First-harmonic amplitude of the first output there (m).
    pub amplitude: f64,
    /// Whether that amplitude was rising along the path into the last point (toward a
    /// resonance peak the path did not reach).
    pub amplitude_rising: bool,
    /// The last fold the path had turned back at on that branch before the point (Hz); None
    /// when it had not turned back on that branch.
    pub fold_hz: Option<f64>,
    /// Why the path could not be followed on.
    pub cause: GiveUpCause,
}

/// Why a branch was given up ([`GivenUp`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GiveUpCause {
    /// [`PathEnd::DeadEnd`]: the corrector failed at every step down to the minimum, and the
    /// only way on found led back along the path already followed, or behind a fold.
    DeadEnd,
    /// [`PathEnd::NoProgress`]: the path wandered back and forth over ground it had covered
    /// (frequency and response) for a fifth of the point budget.
    NoProgress,
    /// The fill of a branch past a jump, followed down toward the highest frequency of the
    /// branch before, turned back up at a fold of its own and stopped on reaching that
    /// frequency (its end): the branch it was on goes on above ([`Jump::fill_cut`]).
    FillEnd,
    /// A fill or bridge branch used up the points allowed for it ([`PathEnd::MaxPoints`])
    /// before reaching the edge of its stretch: the branch goes on beyond its last point,
    /// not followed ([`Jump::fill_cut`]).
    PointBudget,
}

impl GiveUpCause {
    /// Plain words for a status line.
    fn words(self) -> &'static str {
        match self {
            GiveUpCause::DeadEnd => {
                "a dead end: the only way on found led back along the path already followed"
            }
            GiveUpCause::FillEnd => {
                "the end of a fill or bridge: the branch, followed toward the edge of the \
                 stretch it was solved for, turned back at a fold of its own and was followed \
                 no further"
            }
            GiveUpCause::NoProgress => {
                "no progress: the path wandered back and forth over ground it had covered \
                 already"
            }
            GiveUpCause::PointBudget => {
                "its point budget: the fill or bridge used up the points allowed for it before \
                 reaching the edge of the stretch it was solved for"
            }
        }
    }
}

/// Relative tolerance on every output's first-harmonic amplitude within which the last point
/// of a branch given up counts as lying on a stretch already followed ([`BranchEnd::Retrace`]):
/// another segment of the run's points crossing the same frequency, interpolated linearly,
/// must match each amplitude to 1 % of it. The sampled contact law makes the solution curve a
/// chain of pieces meeting at corners, and converged points of neighbouring pieces at one
/// frequency differ by the sampling: on the paper's system at F0 = 1 N a branch given up at
/// 151.8405 Hz (3.2333e-4 m) is passed there by the branch solved past it at 3.2285e-4 m
/// (0.15 %), and Newton from the point given up, just above it, lands on that branch.
pub const RETRACE_TOLERANCE: f64 = 1e-2;

/// Relative distance ‖c − c'‖ / ‖c‖ over all Fourier coefficients within which two solutions
/// converged by Newton at one frequency are the same solution ([`Landing::resolved_distance`]):
/// the continuation's own, which tells a sharp fold's other side from the path already
/// followed with it (measurements there).
pub use crate::numerics::continuation::SAME_SOLUTION_TOLERANCE;

impl GivenUp {
    /// "at 886.8455 Hz (first output's amplitude 1.770e-5 m, rising), below the fold at
    /// 886.8500 Hz where the path had turned back down, by a dead end: …", for status lines
    /// and messages.
    pub fn describe(&self) -> String {
        let trend = if self.amplitude_rising {
            "rising"
        } else {
            "falling"
        };
        let side = match self.fold_hz {
            Some(fold) if fold >= self.freq_hz => {
                format!(", below the fold at {fold:.4} Hz where the path had turned back down")
            }
            Some(fold) => {
                format!(", above the fold at {fold:.4} Hz where the path had turned back up")
            }
            None => String::new(),
        };
        format!(
            "at {:.4} Hz (first output's amplitude {:.3e} m, {trend}){side}, by {}",
            self.freq_hz,
            self.amplitude,
            self.cause.words()
        )
    }
}

/// Why an FRF run changed branch (see [`Jump`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum JumpKind {
    /// The path turned back at a fold and did not come back; the run went on on a branch
    /// solved just past the highest frequency reached.
    PastFold,
    /// The path met a spot it could not pass where the only way on found led back along the
    /// path already followed, or behind a fold ([`PathEnd::DeadEnd`]); the run went on on a
    /// branch solved just past the highest frequency reached.
    PastDeadEnd,
    /// A branch solved inside a stretch that the branches on either side of it did not reach
    /// (Newton from blends of the two ends' coefficients, then followed both ways).
    Bridge,
}

impl Jump {
    /// Whether the branch before the jump was abandoned inside the range
    /// ([`BranchEnd::Abandoned`]): the response beyond its last point is missing. A
    /// [`Jump::fill_cut`] does not count here (see [`Jump::cut_uncovered`]).
    pub fn abandons_branch(&self) -> bool {
        matches!(self.before, BranchEnd::Abandoned(_))
            && self.end_check.is_none_or(|c| c.uncovered())
    }

    /// The cuts of the branch after the jump ([`Jump::fill_cut`], then [`Jump::second_cut`]),
    /// each with its judgement once there is one.
    pub fn cuts(&self) -> impl Iterator<Item = (&GivenUp, Option<&CutCheck>)> {
        [
            (&self.fill_cut, &self.cut_check),
            (&self.second_cut, &self.second_cut_check),
        ]
        .into_iter()
        .filter_map(|(g, c)| g.as_ref().map(|g| (g, c.as_ref())))
    }

    /// The cuts of the branch after the jump whose judgement leaves the response beyond them
    /// missing or unknown ([`CutCheck::uncovered`]), each with that judgement. A cut not
    /// judged (a jump reported during the run) does not count.
    pub fn cuts_uncovered(&self) -> impl Iterator<Item = (&GivenUp, &CutCheck)> {
        self.cuts()
            .filter_map(|(g, c)| c.filter(|c| c.uncovered()).map(|c| (g, c)))
    }

    /// The first of [`Jump::cuts_uncovered`]: a cut of the branch after the jump and its
    /// judgement, when that judgement leaves the response beyond the cut missing or unknown.
    pub fn cut_uncovered(&self) -> Option<(&GivenUp, &CutCheck)> {
        self.cuts_uncovered().next()
    }

    /// Width of the stretch not computed on any branch (Hz); stretches narrower than 10⁻⁹ of
    /// the frequency (round-off of a branch followed onto an end frequency) count as none.
    pub fn uncovered_hz(&self) -> f64 {
        let gap = self.to_hz - self.from_hz;
        if gap > 1e-9 * self.to_hz.abs() {
            gap
        } else {
            0.0
        }
    }
}

/// Receives the events of an FRF run.
pub trait FrfObserver {
    /// A point converged.
    fn point(&mut self, _point: &FrfPoint) {}
    /// A step was cut (frequency of the last converged point, Hz).
    fn step_cut(&mut self, _freq_hz: f64, _step: f64, _new_step: f64, _reason: &NewtonFailure) {}
    /// A turning point was passed (Hz).
    fn turning_point(&mut self, _freq_hz: f64) {}
    /// The path could not be followed from `from_hz` and was resumed at `to_hz` (Hz).
    fn leap(&mut self, _from_hz: f64, _to_hz: f64) {}
    /// The path stalled after `from_hz` and was taken on over a narrow window around it up to
    /// `to_hz` (Hz; see `Continuation::run`).
    fn narrow_pass(&mut self, _from_hz: f64, _to_hz: f64) {}
    /// The path turned back at a fold and did not return; it goes on on another branch, whose
    /// points come next (see [`Jump`]).
    fn jump(&mut self, _jump: &Jump) {}
    /// After the run, the cut of the `index`-th jump (in the order reported) was judged:
    /// `jump` is that jump with its [`Jump::cut_check`] set.
    fn cut_judged(&mut self, _index: usize, _jump: &Jump) {}
    /// After the run, a leap was judged ([`judge_leaps`]).
    fn leap_judged(&mut self, _check: &LeapCheck) {}
}

/// Observer that ignores everything.
pub struct Silent;
impl FrfObserver for Silent {}

/// The judgement of a leap of the path ([`FrfRun::leaps`]): where the corrector failed at
/// every step and no corner was found, the path went on from a point predicted further ahead
/// along its tangent, which may have landed on another solution curve, past a fold it never
/// met (measured on the 3D blade pair over 845-900 Hz: a leap from 886.848 to 887.41 Hz over
/// the lower branch's fold, the resonance peak left out, the run otherwise `complete`).
/// After the run the path is followed back from the leap's landing to the frequency of the
/// point before the leap, and the solution it reaches there is compared with that point
/// ([`judge_leaps`]): the same solution, and the leap stayed on one solution curve.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LeapCheck {
    /// Frequency of the last point before the leap (Hz).
    pub from_hz: f64,
    /// Frequency of the first point after it, the landing (Hz).
    pub to_hz: f64,
    /// First output's first-harmonic amplitude of the point before the leap (m).
    pub before_amplitude: Option<f64>,
    /// The same where the path followed back from the landing reached `from_hz` (m); None
    /// when it did not reach it.
    pub back_amplitude: Option<f64>,
    /// ‖c − c_before‖ / ‖c‖ over all Fourier coefficients between Newton's solution c at
    /// `from_hz` started from the point before the leap and the solution the path followed
    /// back reached there; None when it did not reach it. At most
    /// [`SAME_SOLUTION_TOLERANCE`]: one solution; at most [`RETRACE_TOLERANCE`]: a
    /// neighbouring piece of the solution curve, as close as the run's comparisons tell.
    pub distance: Option<f64>,
    /// Points of the path followed back.
    pub points: usize,
    /// `covered`: the path followed back from the landing reaches the point before the leap,
    /// or a solution within [`RETRACE_TOLERANCE`] of it on the coefficients (at a low
    /// pre-load of the paper's system the sampled contact law's solution curve is a chain of
    /// short pieces meeting at corners: at F0 = 1 N the leap from 19.0467 to 19.2388 Hz lands
    /// on the piece next to the one it left, 0.89 % from it at 19.0467 Hz), so the response
    /// the run gives over the leap is the one there to that tolerance; `abandoned`: it reaches
    /// a solution further off, so the leap crossed onto another branch and the branch through the point before
    /// it goes on beyond it unfollowed (possibly to a fold and a resonance peak); `unjudged`:
    /// it did not get back to that frequency within [`LEAP_CHECK_POINTS`] points. The last
    /// two make the run incomplete. A leap onto another branch is `covered` after all when
    /// [`Self::past`] finds the branch through the point before it on the run.
    pub verdict: CutVerdict,
    /// For a leap onto another branch: the branch through the point before the leap judged as
    /// a branch given up at a dead end is ([`judge_cuts`]): Newton at a fixed frequency past
    /// that point, the way the path was going, compared with the run, or, where it converges
    /// nowhere, the other side of a fold there ([`judge_round_dead_end`]). Its verdict is the
    /// leap's. None otherwise.
    pub past: Option<CutCheck>,
}

impl LeapCheck {
    /// Whether the leap may have left response out ([`CutVerdict::Abandoned`],
    /// [`CutVerdict::Unjudged`]): counted in the run's status.
    pub fn uncovered(&self) -> bool {
        !matches!(self.verdict, CutVerdict::Covered)
    }

    /// "the path leapt from 886.8480 to 887.4100 Hz …", for status lines and messages.
    pub fn describe(&self) -> String {
        let leapt = format!(
            "the path leapt from {:.4} to {:.4} Hz over a spot the corrector could not pass",
            self.from_hz, self.to_hz
        );
        let before = self
            .before_amplitude
            .map_or(String::new(), |a| format!(" ({a:.3e} m)"));
        if let (Some(past), Some(a), Some(d)) = (&self.past, self.back_amplitude, self.distance) {
            return format!(
                "{leapt}, onto another branch: followed back from {:.4} Hz the path reaches \
                 {:.4} Hz at {a:.3e} m (first output), {:.1} % from the point before the \
                 leap{before} on the coefficients; for the branch through that point, {}",
                self.to_hz,
                self.from_hz,
                100.0 * d,
                past.describe_past("the point before the leap")
            );
        }
        match (self.verdict, self.back_amplitude, self.distance) {
            (CutVerdict::Covered, _, Some(d)) if d <= SAME_SOLUTION_TOLERANCE => format!(
                "{leapt}; followed back from {:.4} Hz the path reaches the point before the leap \
                 ({d:.1e} apart on the coefficients): one solution curve",
                self.to_hz
            ),
            (CutVerdict::Covered, _, Some(d)) => format!(
                "{leapt}; followed back from {:.4} Hz the path reaches {:.4} Hz on a neighbouring \
                 piece of the solution curve, {:.2} % from the point before the leap on the \
                 coefficients (within the 1 % the run's comparisons allow)",
                self.to_hz,
                self.from_hz,
                100.0 * d
            ),
            (CutVerdict::Abandoned, Some(a), Some(d)) => format!(
                "{leapt}, onto another branch: followed back from {:.4} Hz the path reaches \
                 {:.4} Hz at {a:.3e} m (first output), {:.1} % from the point before the \
                 leap{before} on the coefficients, so the branch through that point beyond \
                 {:.4} Hz (possibly to a fold and a resonance peak) was not computed",
                self.to_hz,
                self.from_hz,
                100.0 * d,
                self.from_hz
            ),
            _ => format!(
                "{leapt}; followed back from {:.4} Hz the path did not get back to {:.4} Hz \
                 ({} points), so whether the leap skipped a fold, and the response beyond it, is \
                 not known",
                self.to_hz, self.from_hz, self.points
            ),
        }
    }
}

/// Result of an FRF run.
#[derive(Debug, Clone, PartialEq)]
pub struct FrfRun {
    /// Converged points in path order.
    pub points: Vec<FrfPoint>,
    /// Turning-point frequencies (Hz).
    pub turning_points: Vec<f64>,
    /// Number of cut steps.
    pub rejected_steps: usize,
    /// Stretches leapt over: (last point before, first point after), Hz, in the direction the
    /// continuation travelled; on every path of the run: the main path's branches, the fills
    /// after its jumps and the bridges (whose ways down, and the fills, are reported in
    /// reverse, the landing before the point before it).
    pub leaps: Vec<(f64, f64)>,
    /// The indices in [`FrfRun::points`] of each leap's point before and landing, in the order
    /// of [`FrfRun::leaps`] (the landing before the point before it on a way reported in
    /// reverse), as the continuation recorded the landing and the run placed the path's
    /// points in its report.
    pub leap_points: Vec<Option<(usize, usize)>>,
    /// The judgement of each leap, in the order of [`FrfRun::leaps`] ([`judge_leaps`]).
    pub leap_checks: Vec<LeapCheck>,
    /// Jumps to another branch after a fold the path did not come back from.
    pub jumps: Vec<Jump>,
    /// Why the run ended.
    pub end: PathEnd,
    /// Wall time of the run (s).
    pub elapsed_s: f64,
}

/// One crossing of a frequency by a path ([`FrfRun::crossings`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathCrossing {
    /// Amplitude of the output there, interpolated along the segment (m).
    pub amplitude: f64,
    /// Index of the segment's first point.
    pub segment: usize,
    /// Index of the segment's point nearer in frequency.
    pub nearest_point: usize,
}

impl FrfRun {
    /// Indices of the points where a branch reached by a jump starts.
    pub fn branch_starts(&self) -> Vec<usize> {
        self.jumps.iter().map(|j| j.first_point).collect()
    }

    /// Every place where the path crosses `freq_hz` (Hz) within a branch (a segment between
    /// consecutive points bracketing it, not across a jump), in path order: the linearly
    /// interpolated amplitude of output `output` there (m), the segment's first point index,
    /// and the index of its point nearer in frequency. A folded path crosses a frequency more
    /// than once, which is why a comparison between paths picks among these.
    pub fn crossings(&self, freq_hz: f64, output: usize) -> Vec<PathCrossing> {
        let starts = self.branch_starts();
        let mut out = Vec::new();
        for k in 0..self.points.len().saturating_sub(1) {
            if starts.contains(&(k + 1)) {
                continue;
            }
            let (p, q) = (&self.points[k], &self.points[k + 1]);
            if (p.freq_hz - freq_hz) * (q.freq_hz - freq_hz) > 0.0 || p.freq_hz == q.freq_hz {
                continue;
            }
            let t = (freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
            out.push(PathCrossing {
                amplitude: p.amplitudes[output] + t * (q.amplitudes[output] - p.amplitudes[output]),
                segment: k,
                nearest_point: if t < 0.5 { k } else { k + 1 },
            });
        }
        out
    }

    /// The crossing of `freq_hz` (Hz) by the path ([`FrfRun::crossings`]) whose amplitude of
    /// output `output` is nearest to `near` (m): where a folded path crosses a frequency more
    /// than once, the one to compare a point of amplitude `near` with. None when the path does
    /// not cross the frequency.
    pub fn crossing_nearest(&self, freq_hz: f64, output: usize, near: f64) -> Option<PathCrossing> {
        self.crossings(freq_hz, output).into_iter().min_by(|x, y| {
            (x.amplitude - near)
                .abs()
                .total_cmp(&(y.amplitude - near).abs())
        })
    }

    /// Whether the run is complete: it covers the range ([`Self::covers_range`]), no branch
    /// was abandoned inside it and no cut of a fill or bridge is judged uncovered
    /// ([`Self::incomplete_reason`]).
    pub fn is_complete(&self) -> bool {
        self.incomplete_reason().is_none()
    }

    /// Whether the run covers the range, abandoned branches and cuts aside: the path reached
    /// the end frequency, and every stretch it jumped over at a fold was computed on some
    /// branch.
    pub fn covers_range(&self) -> bool {
        self.coverage_reason().is_none()
    }

    /// The jumps whose branch before was abandoned inside the range ([`BranchEnd::Abandoned`]):
    /// the response beyond each such point on its branch is missing.
    pub fn abandoned(&self) -> impl Iterator<Item = (&Jump, &GivenUp)> {
        self.jumps.iter().filter_map(|j| match &j.before {
            BranchEnd::Abandoned(g) => Some((j, g)),
            _ => None,
        })
    }

    /// Why the run did not cover the range (None when it did), for the run's status line
    /// (`incomplete: <reason>`): the range not reached, the stretches no branch reached,
    /// every branch abandoned inside the range ([`BranchEnd::Abandoned`]), whose response
    /// beyond the point given up (possibly a resonance peak) is missing even though the run
    /// went on past it, and every cut of a fill or bridge judged not covered
    /// ([`Jump::cut_uncovered`]).
    pub fn incomplete_reason(&self) -> Option<String> {
        let abandoned: Vec<String> = self
            .jumps
            .iter()
            .filter(|j| j.abandons_branch())
            .filter_map(|j| {
                let judged = j.end_check.map_or(String::new(), |c| {
                    format!("; {}", c.describe_past("the point given up"))
                });
                j.before.words().map(|words| {
                    format!(
                        "a branch was {words}{judged} (the run went on on a branch found past \
                         {:.4} Hz)",
                        j.from_hz
                    )
                })
            })
            .collect();

        let cuts = self.jumps.iter().flat_map(|j| {
            j.cuts_uncovered().map(move |(g, c)| {
                format!(
                    "a branch solved past the jump at {:.4} Hz was left {}; {}, so the response \
                     beyond that point on that branch (possibly the resonance peak) {}",
                    j.from_hz,
                    g.describe(),
                    c.describe(),
                    if c.verdict == CutVerdict::Unjudged {
                        "may be missing"
                    } else {
                        "was not computed"
                    }
                )
            })
        });
        let leaps = self
            .leap_checks
            .iter()
            .filter(|c| c.uncovered())
            .map(LeapCheck::describe);
        let coverage = self.coverage_reason();
        let reasons: Vec<String> = coverage
            .into_iter()
            .chain(abandoned)
            .chain(cuts)
            .chain(leaps)
            .collect();
        (!reasons.is_empty()).then(|| reasons.join("; "))
    }

    /// Why the run did not reach every frequency of the range (None when it did).
    fn coverage_reason(&self) -> Option<String> {
        let last = self.points.last().map_or(f64::NAN, |p| p.freq_hz);
        let highest = self
            .points
            .iter()
            .map(|p| p.freq_hz)
            .fold(f64::NEG_INFINITY, f64::max);
        match self.end {
            PathEnd::EndFrequency => {
                let gaps: Vec<String> = self
                    .jumps
                    .iter()
                    .filter(|j| j.uncovered_hz() > 0.0)
                    .map(|j| format!("{:.4}-{:.4} Hz", j.from_hz, j.to_hz))
                    .collect();
                (!gaps.is_empty()).then(|| {
                    format!(
                        "no solution was found at {}: the path turned back at a fold there and \
                         neither the branch found past it nor a branch solved inside reached \
                         those frequencies",
                        gaps.join(", ")
                    )
                })
            }
            PathEnd::LeftRangeBelow => Some(format!(
                "the path turned back and left the range below the start frequency at \
                 {last:.4} Hz; frequencies above {highest:.4} Hz were never reached"
            )),
            PathEnd::MaxPoints => Some(format!(
                "the point budget (analysis.max_points = {}) was used up at {last:.4} Hz; \
                 frequencies above {highest:.4} Hz were never reached",
                self.points.len()
            )),
            PathEnd::NoProgress => Some(format!(
                "the path wandered back and forth below {highest:.4} Hz without getting \
                 higher (last point at {last:.4} Hz); frequencies above were never reached"
            )),
            PathEnd::DeadEnd => Some(format!(
                "the path could not be followed past {last:.4} Hz (the only way on found led \
                 back along the path already followed, or the path had turned back at a fold \
                 below {highest:.4} Hz); frequencies above {highest:.4} Hz were never reached"
            )),
        }
    }
}

/// Errors of an FRF run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrfError {
    /// Building the operator failed.
    #[error("{0}")]
    Setup(#[from] HbmError),
    /// The linear starting guess failed.
    #[error("linear starting guess: {0}")]
    Guess(#[from] LinearSolveError),
    /// Continuation failed.
    #[error("{0}")]
    Continuation(#[from] ContinuationError),
}

/// The largest |offset + q(τ)| over a period of the trigonometric polynomial q with
/// coefficients `coef` on `set` (m): the time-domain peak of a DOF. The maximum is located on a
/// fine grid (16 points per period of the highest harmonic, at least 64), then refined by a
/// golden-section search between the neighbours of the best grid point, down to 10⁻¹² rad:
/// the value is exact to round-off, so at one harmonic it equals the first-harmonic
/// amplitude, and it does not depend on the AFT sampling.
pub fn time_peak(set: &HarmonicSet, coef: &[f64], offset: f64) -> f64 {
    let h_max = set.harmonics().iter().copied().max().unwrap_or(0);
    let grid = (16 * h_max).max(64);
    let value = |tau: f64| (offset + set.evaluate(coef, tau)).abs();
    let dt = 2.0 * PI / grid as f64;
    let (best, _) =
        (0..grid)
            .map(|k| (k, value(k as f64 * dt)))
            .fold(
                (0, f64::NEG_INFINITY),
                |acc, (k, v)| if v > acc.1 { (k, v) } else { acc },
            );
    let search = golden::maximise(
        (best as f64 - 1.0) * dt,
        (best as f64 + 1.0) * dt,
        1e-12,
        |tau| Some((value(tau), ())),
    );
    search
        .best
        .map_or(f64::NEG_INFINITY, |(_, v, _)| v)
        .max(value(best as f64 * dt))
}

/// Output quantities of a converged point.
pub fn point_outputs(
    problem: &Problem,
    set: &HarmonicSet,
    static_offset: &[f64],
    x: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let n = problem.model.n_dofs();
    let c1 = set.cos_block(1);
    let s1 = set.sin_block(1);
    let mut amplitudes = Vec::with_capacity(problem.outputs.len());
    let mut peaks = Vec::with_capacity(problem.outputs.len());
    let mut coef = vec![0.0; set.n_blocks()];
    for &d in &problem.outputs {
        let c = c1.map(|j| x[j * n + d]).unwrap_or(0.0);
        let s = s1.map(|j| x[j * n + d]).unwrap_or(0.0);
        amplitudes.push(c.hypot(s));
        for (j, v) in coef.iter_mut().enumerate() {
            *v = x[j * n + d];
        }
        let offset = if set.has_constant() {
            0.0
        } else {
            static_offset[d]
        };
        peaks.push(time_peak(set, &coef, offset));
    }
    (amplitudes, peaks)
}

/// Scale of each unknown in the arc length (m), in the operator's layout: per coefficient
/// block, the largest stuck-linear response norm of that kind of block over the range (the
/// static block's norm for the 0th harmonic, the dynamic blocks' for the others), divided so
/// that climbing to it costs a quarter of the range in arc length.
///
/// One scale for all unknowns would let a large static part (a high pre-load) dominate the
/// arc length: the dynamic response would then hardly count, steps would grow to the largest
/// one and cross resonance peaks. Each kind of block gets its own scale, with a floor of 10⁻³
/// of the other so that a block without load (no static load) does not get a zero scale.
fn arc_length_x_scale(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> Result<Vec<f64>, LinearSolveError> {
    let a = &problem.analysis.continuation;
    // The 0th harmonic of the guess does not depend on ω: solved once, the dynamic harmonics
    // on the grid.
    let dynamic = HarmonicSet::new(
        set.harmonics()
            .iter()
            .copied()
            .filter(|&h| h != 0)
            .collect(),
    );
    let static_norm = if set.has_constant() {
        crate::numerics::linalg::norm(&linear::stuck_guess(
            problem,
            &HarmonicSet::new(vec![0]),
            0.0,
        )?)
    } else {
        0.0
    };
    let mut dynamic_norm = 0.0_f64;
    for i in 0..=40 {
        let f = a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / 40.0;
        let x = linear::stuck_guess(problem, &dynamic, 2.0 * PI * f)?;
        dynamic_norm = dynamic_norm.max(crate::numerics::linalg::norm(&x));
    }
    let x_ref = static_norm.hypot(dynamic_norm);
    let range = a.freq_end_hz - a.freq_start_hz;
    let to_scale =
        |block_norm: f64| (block_norm.max(1e-3 * x_ref) / (0.25 * range)).max(f64::MIN_POSITIVE);
    let (static_scale, dynamic_scale) = (to_scale(static_norm), to_scale(dynamic_norm));
    let n = problem.model.n_dofs();
    let full: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let s = match b {
                Block::Constant => static_scale,
                _ => dynamic_scale,
            };
            std::iter::repeat_n(s, n)
        })
        .collect();
    Ok(system.restrict(&full))
}

/// The groups of [`arc_length_x_scale`] (static block, dynamic blocks) as an adaptive scale:
/// each grows with its block's norm along the path, at the same climb (a quarter of the range).
fn adaptive_scale(problem: &Problem, set: &HarmonicSet, system: &HbmOperator<'_>) -> AdaptiveScale {
    let a = &problem.analysis.continuation;
    let n = problem.model.n_dofs();
    let full: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let g = if *b == Block::Constant { 0.0 } else { 1.0 };
            std::iter::repeat_n(g, n)
        })
        .collect();
    AdaptiveScale {
        group_of: system.restrict(&full).iter().map(|&g| g as usize).collect(),
        climb: 0.25 * (a.freq_end_hz - a.freq_start_hz),
    }
}

/// For each output DOF, the indices of its first-harmonic cosine and sine among the operator's
/// unknowns (outputs the operator does not carry are left out), for the step length to follow
/// the output amplitudes ([`Continuation::with_amplitude_steps`]).
fn output_amplitude_groups(
    problem: &Problem,
    set: &HarmonicSet,
    system: &HbmOperator<'_>,
) -> Vec<Vec<usize>> {
    let n = problem.model.n_dofs();
    let blocks: Vec<usize> = [set.cos_block(1), set.sin_block(1)]
        .into_iter()
        .flatten()
        .collect();
    problem
        .outputs
        .iter()
        .filter_map(|&d| {
            let mut marker = vec![0.0; n * set.n_blocks()];
            for &j in &blocks {
                marker[j * n + d] = 1.0;
            }
            let group: Vec<usize> = system
                .restrict(&marker)
                .iter()
                .enumerate()
                .filter(|(_, &v)| v == 1.0)
                .map(|(i, _)| i)
                .collect();
            (!group.is_empty()).then_some(group)
        })
        .collect()
}

struct Adapter<'o, 'p, 'e, O: FrfObserver> {
    observer: &'o mut O,
    points: Vec<FrfPoint>,
    /// A converged point whose full coefficients could not be recovered.
    failure: Option<HbmError>,
    /// The error estimate of every accepted point, when the scene asks for it.
    estimates: Option<&'p EstimatePool<'e>>,
    /// Whether the observer's events keep their order behind points whose estimates are still
    /// being formed (the run's own observer); a branch followed silently passes them on at once,
    /// its points keeping their pending estimates until the run reports them.
    in_order: bool,
    /// Events held back behind a point whose estimate has not come in yet, in order.
    held: VecDeque<Held>,
}

/// An observer event of [`Adapter`], held back until the estimates of the points before it
/// have come in.
enum Held {
    /// The point at this index of [`Adapter::points`].
    Point(usize),
    StepCut(f64, f64, f64, NewtonFailure),
    TurningPoint(f64),
    Leap(f64, f64),
    NarrowPass(f64, f64),
    /// Boxed: a jump is ten times the size of the other events.
    Jump(Box<Jump>),
}

impl<O: FrfObserver> Adapter<'_, '_, '_, O> {
    /// Gives `point` its error estimate at ω = `omega` (rad/s), at once or pending on a
    /// worker, when the run estimates.
    fn estimate(&self, point: &mut FrfPoint, omega: f64, place: Option<PathPlace>) {
        let Some(pool) = self.estimates else { return };
        match pool.submit(&point.coefficients, omega, place, &point.states) {
            Submitted::Ready(accuracy) => point.accuracy = Some(accuracy),
            Submitted::Pending(ticket) => point.pending_estimate = Some(ticket),
        }
    }

    /// Appends `point` to the run's points and reports it (in order).
    fn push_point(&mut self, point: FrfPoint) {
        self.points.push(point);
        self.report(Held::Point(self.points.len() - 1));
    }

    /// Reports `event` to the observer, after the events held back before it.
    fn report(&mut self, event: Held) {
        self.held.push_back(event);
        self.flush(false);
    }

    /// Passes the held events on in order, each point with its estimate, up to the first point
    /// whose estimate has not come in (or, with `wait`, waiting for every one).
    fn flush(&mut self, wait: bool) {
        while let Some(front) = self.held.front() {
            if let (&Held::Point(i), true) = (front, self.in_order) {
                if let (Some(ticket), Some(pool)) =
                    (self.points[i].pending_estimate, self.estimates)
                {
                    let accuracy = if wait {
                        pool.wait(ticket)
                    } else {
                        match pool.get(ticket) {
                            Some(accuracy) => Some(accuracy),
                            None => break,
                        }
                    };
                    // None with `wait`: the workers stopped, the point goes without.
                    self.points[i].accuracy = accuracy;
                    self.points[i].pending_estimate = None;
                }
            }
            let Some(event) = self.held.pop_front() else {
                break;
            };
            match event {
                Held::Point(i) => self.observer.point(&self.points[i]),
                Held::StepCut(freq_hz, step, new_step, reason) => {
                    self.observer.step_cut(freq_hz, step, new_step, &reason)
                }
                Held::TurningPoint(freq_hz) => self.observer.turning_point(freq_hz),
                Held::Leap(from_hz, to_hz) => self.observer.leap(from_hz, to_hz),
                Held::NarrowPass(from_hz, to_hz) => self.observer.narrow_pass(from_hz, to_hz),
                Held::Jump(jump) => self.observer.jump(&jump),
            }
        }
    }

    /// The points, every estimate in (the events all passed on).
    fn take_points(&mut self) -> Vec<FrfPoint> {
        self.flush(true);
        std::mem::take(&mut self.points)
    }
}

impl<O: FrfObserver> Drop for Adapter<'_, '_, '_, O> {
    /// A run that ends early (an error) still reports every point it accepted.
    fn drop(&mut self) {
        if self.in_order {
            self.flush(true);
        }
    }
}

/// The outputs of a converged path point, on full coefficients.
fn full_point(system: &mut HbmOperator<'_>, p: &PathPoint) -> Result<FrfPoint, HbmError> {
    let coefficients = system.expand(&p.x, p.omega)?;
    let full = system.full_ref();
    let (amplitudes, peaks) = point_outputs(
        full.problem(),
        full.unknowns(),
        full.static_offset(),
        &coefficients,
    );
    // A point solved at the start or end frequency (ω = 2π f) is reported at exactly f, not at
    // ω / 2π rounded an ulp away (the last row of a range must be its end).
    let range = &full.problem().analysis.continuation;
    let freq_hz = [range.freq_start_hz, range.freq_end_hz]
        .into_iter()
        .find(|f| (p.freq_hz() - f).abs() <= 8.0 * f64::EPSILON * f)
        .unwrap_or_else(|| p.freq_hz());
    let states = system.states().to_vec();
    Ok(FrfPoint {
        freq_hz,
        amplitudes,
        peaks,
        states,
        newton_iterations: p.iterations,
        residual: p.residual,
        coefficients,
        accuracy: None,
        pending_estimate: None,
        stability: None,
    })
}

/// The point with its stability at ω (rad/s) when the problem asks for it
/// (`analysis.stability`): computed for the points of a continuation path (FRF runs and every
/// limit, intermediate and scanned curve), not for the extra solves of peak refinements and
/// common grids. The method is `analysis.stability_method`: Hill's verdict (marked unreliable
/// on stick-slip points, [`crate::analysis::stability::hill_reliable`]), the monodromy's
/// ([`point_monodromy`]), or Hill's replaced by the monodromy's where Hill is unreliable. A
/// monodromy that fails (a time step whose Newton does not converge) leaves Hill's verdict
/// (marked unreliable) or, with the monodromy alone, no verdict: empty cells.
fn with_stability(
    system: &mut HbmOperator<'_>,
    mut point: FrfPoint,
    omega: f64,
) -> Result<FrfPoint, HbmError> {
    let analysis = system.full_ref().problem().analysis;
    if !analysis.stability {
        return Ok(point);
    }
    let method = analysis.stability_method;
    let mut verdict = None;
    if method.uses_hill() {
        verdict = Some(
            {
                let full = system.full();
                let unknowns = full.problem().model.n_dofs() * full.unknowns().n_blocks();
                let solver =
                    hill_solver_for(analysis.hill_solver, unknowns, analysis.hill_max_freq_hz);
                point_stability_with(full, &point.coefficients, omega, &solver)
            }
            .map_err(|e| match e {
                StabilityError::Hbm(e) => e,
                other => HbmError::Stability(other.to_string()),
            })?,
        );
    }
    let monodromy_needed = match method {
        StabilityMethod::Hill => false,
        StabilityMethod::Monodromy => true,
        StabilityMethod::HillMonodromy => verdict.is_some_and(|v| !v.reliable),
    };
    if monodromy_needed {
        let full = system.full_ref();
        match point_monodromy(
            full.problem(),
            full.unknowns(),
            &point.coefficients,
            point.freq_hz,
            analysis.monodromy_steps_per_period,
        ) {
            Ok(m) => verdict = Some(m.point_stability()),
            Err(_) => match &mut verdict {
                Some(v) => v.reliable = false,
                None => verdict = Some(PointStability::failed()),
            },
        }
    }
    point.stability = verdict;
    Ok(point)
}

impl<O: FrfObserver> Observer<HbmOperator<'_>> for Adapter<'_, '_, '_, O> {
    fn accepted(&mut self, system: &mut HbmOperator<'_>, p: &PathPoint, normal: Option<&[f64]>) {
        let mut point =
            match full_point(system, p).and_then(|point| with_stability(system, point, p.omega)) {
                Ok(point) => point,
                Err(e) => {
                    self.failure.get_or_insert(e);
                    return;
                }
            };
        let place = normal.map(|normal| PathPlace {
            normal,
            step: p.step,
        });
        self.estimate(&mut point, p.omega, place);
        self.push_point(point);
    }
    fn rejected(&mut self, freq_hz: f64, step: f64, new_step: f64, reason: &NewtonFailure) {
        self.report(Held::StepCut(freq_hz, step, new_step, reason.clone()));
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.report(Held::TurningPoint(freq_hz));
    }
    fn leap(&mut self, from_hz: f64, to_hz: f64) {
        self.report(Held::Leap(from_hz, to_hz));
    }
    fn narrow_pass(&mut self, from_hz: f64, to_hz: f64) {
        self.report(Held::NarrowPass(from_hz, to_hz));
    }
}

/// Point budget of the fill of a branch back toward the fold (see [`solve`]).
const FILL_POINTS: usize = 500;
/// Most jumps to another branch in one run (see [`solve`]).
const MAX_JUMPS: usize = 8;
/// How far past the highest frequency a path reached a jump lands, as fractions of the range,
/// tried in turn until a point converges there.
const JUMP_FRACTIONS: &[f64] = &[0.0005, 0.002, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2];

/// Solves the nonlinear frequency response of a problem over its analysis range.
///
/// The path is followed from the start frequency. A path that turns back at a fold and does not
/// come back toward the end (it leaves the range below the start, or wanders without reaching
/// a higher frequency) is not the whole answer: as in a stepped-sine test sweeping
/// up, the response then jumps to another branch. The run solves a point just past the highest
/// frequency reached (see [`jump_target`]) and
/// follows the path on from it, up to [`MAX_JUMPS`] times. The new branch is first followed
/// back down toward the highest frequency reached, to fill the gap (those points come first,
/// in rising frequency). Each jump is reported ([`FrfRun::jumps`], [`FrfObserver::jump`]) with
/// the frequencies its ends reached: the stretch between them was not computed on any branch
/// (empty when the fill got back to the highest frequency).
///
/// The points' error estimates (when the scene asks for them) are formed on worker threads
/// while the path goes on ([`crate::analysis::estimate_pool`]); the observer still receives
/// every event in the order of the run, each point with its estimate.
pub fn solve<O: FrfObserver>(problem: &Problem, observer: &mut O) -> Result<FrfRun, FrfError> {
    let started = Instant::now();
    let refined = EstimateProblems::new(problem);
    std::thread::scope(|scope| solve_in(scope, problem, refined.as_ref(), observer, started))
}

/// [`solve`], its estimates' workers (if any) scoped to `scope`.
fn solve_in<'scope, 'p, O: FrfObserver>(
    scope: &'scope Scope<'scope, 'p>,
    problem: &'p Problem,
    refined: Option<&'p EstimateProblems>,
    observer: &mut O,
    started: Instant,
) -> Result<FrfRun, FrfError> {
    let mut system = HbmOperator::new(problem)?;
    let set = system.unknowns().clone();
    let settings = problem.analysis.continuation;
    let omega0 = 2.0 * PI * settings.freq_start_hz;
    let mut x_scale = arc_length_x_scale(problem, &set, &system)?;
    let mut guess = start_guess(problem, &set, &mut system, &x_scale, omega0)?;
    // How the scale grows and which amplitudes the steps follow: the same on every branch.
    let adaptive = adaptive_scale(problem, &set, &system);
    let amplitude_groups = output_amplitude_groups(problem, &set, &system);
    let pool = refined
        .map(|r| EstimatePool::start(scope, problem, r, EstimatePool::default_workers()))
        .transpose()?;
    let mut adapter = Adapter {
        observer,
        points: Vec::new(),
        failure: None,
        estimates: pool.as_ref(),
        in_order: true,
        held: VecDeque::new(),
    };
    let mut run = FrfRun {
        points: Vec::new(),
        turning_points: Vec::new(),
        rejected_steps: 0,
        leaps: Vec::new(),
        leap_points: Vec::new(),
        leap_checks: Vec::new(),
        jumps: Vec::new(),
        end: PathEnd::MaxPoints,
        elapsed_s: 0.0,
    };
    let mut start_hz = settings.freq_start_hz;
    loop {
        let segment_start = adapter.points.len();
        let segment_fold: Option<f64>;
        let segment = ContinuationSettings {
            freq_start_hz: start_hz,
            max_points: settings.max_points.saturating_sub(adapter.points.len()),
            ..settings
        };
        let mut continuation = Continuation::new(segment, x_scale.clone())
            .with_adaptive_scale(adaptive.clone())
            .with_amplitude_steps(amplitude_groups.clone());
        // Where this branch's points go in the report (one per point of its path).
        let offset = adapter.points.len();
        let outcome = continuation.run(&mut system, &guess, &mut adapter);
        // The next branch starts with the scale this one grew to.
        x_scale.clone_from(&continuation.x_scale);
        if let Some(e) = adapter.failure.take() {
            return Err(FrfError::Setup(e));
        }
        match outcome {
            Ok(summary) => {
                segment_fold = summary.turning_points.last().copied();
                run.turning_points.extend(summary.turning_points);
                run.rejected_steps += summary.rejected_steps;
                run.leaps.extend(summary.leaps);
                run.leap_points
                    .extend(forward_leaps(&summary.leap_landings, 0, offset));
                run.end = summary.end;
            }
            // A stall is not a fold: the path goes on past it, but could not be followed. (A
            // spot past which only the way back was found ends the summary as
            // `PathEnd::DeadEnd` and is jumped past below.)
            Err(e) => return Err(e.into()),
        }
        let turned_back = matches!(
            run.end,
            PathEnd::LeftRangeBelow | PathEnd::NoProgress | PathEnd::DeadEnd
        );
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        let past_folds = run
            .jumps
            .iter()
            .filter(|j| matches!(j.kind, JumpKind::PastFold | JumpKind::PastDeadEnd))
            .count();
        if !turned_back || past_folds >= MAX_JUMPS || budget < 2 {
            break;
        }
        let highest = adapter
            .points
            .iter()
            .map(|p| p.freq_hz)
            .fold(f64::NEG_INFINITY, f64::max);
        let Some((freq_hz, x)) = jump_target(
            problem,
            &set,
            &mut system,
            &continuation,
            &adapter.points,
            highest,
        )?
        else {
            break;
        };
        let branching = Branching {
            settings,
            x_scale: &x_scale,
            adaptive: &adaptive,
            amplitude_groups: &amplitude_groups,
        };
        // Fill the gap on the new branch, back down toward the highest frequency reached, and
        // report those points first (in rising frequency) so that the path reads on from the
        // jump. The fill's first point (at the jump target) is solved again by the branch's
        // own run.
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        let (mut fill, summary) = branching.follow(
            &mut system,
            &x,
            freq_hz,
            highest,
            (budget / 2).min(FILL_POINTS),
            adapter.estimates,
        );
        let cut = summary.as_ref().and_then(|summary| {
            fill_cut(
                &adapter.points,
                &run.branch_starts(),
                &fill,
                true,
                summary.end,
                summary.turning_points.last().copied(),
            )
        });
        // A stretch neither branch reached: solve branches inside it, between the highest
        // point before the jump and the lowest point of the new branch.
        let top = adapter
            .points
            .iter()
            .rev()
            .find(|p| p.freq_hz == highest)
            .cloned();
        let bottom = fill
            .iter()
            .min_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz))
            .cloned();
        // The fill as followed, from the jump target: a branch given up at the point where
        // the fill ends (its end frequency) lies on the fill's segment into the jump target.
        let followed_fill = fill.clone();
        fill.reverse();
        fill.pop();
        let bridges = match (top, bottom) {
            (Some(top), Some(bottom)) if bottom.freq_hz > highest => {
                let budget = settings
                    .max_points
                    .saturating_sub(adapter.points.len() + fill.len())
                    / 2;
                branching.bridge(
                    &mut system,
                    &top,
                    &bottom,
                    budget,
                    adapter.estimates,
                    (&adapter.points, &run.branch_starts()),
                )
            }
            _ => Vec::new(),
        };
        // What the bridges and the fill met, in the order they are reported (bridges first);
        // their turning points and leaps go to the observer too (`solution.json` lists them),
        // its leaps in the order of `run.leaps`, which the leaps' judgements follow.
        // The fill's leaps as placed in its report: followed down from the jump target and
        // reported in reverse without that first point, which the next branch solves again
        // and reports right after the fill.
        let fill_leaps = summary.as_ref().map_or(Vec::new(), |s| {
            reversed_leaps(&s.leap_landings, followed_fill.len())
        });
        let met = bridges
            .iter()
            .map(|b| {
                (
                    &b.turning_points,
                    b.rejected_steps,
                    &b.leaps,
                    &b.leap_points,
                    b.points.len(),
                )
            })
            .chain(summary.as_ref().map(|s| {
                (
                    &s.turning_points,
                    s.rejected_steps,
                    &s.leaps,
                    &fill_leaps,
                    fill.len(),
                )
            }));
        let mut offset = adapter.points.len();
        for (turning_points, rejected_steps, leaps, places, length) in met {
            for &freq_hz in turning_points {
                run.turning_points.push(freq_hz);
                adapter.report(Held::TurningPoint(freq_hz));
            }
            run.rejected_steps += rejected_steps;
            for (&(from_hz, to_hz), place) in leaps.iter().zip(places) {
                run.leaps.push((from_hz, to_hz));
                run.leap_points
                    .push(place.map(|(before, landing)| (offset + before, offset + landing)));
                adapter.report(Held::Leap(from_hz, to_hz));
            }
            offset += length;
        }
        // How the branch before ended, now that the branches solved past it are known (a
        // branch given up whose last point one of them passes through abandoned nothing).
        let later: Vec<&[FrfPoint]> = bridges
            .iter()
            .map(|b| b.points.as_slice())
            .chain([followed_fill.as_slice()])
            .collect();
        let branch_end = branch_end(
            &adapter.points,
            &run.branch_starts(),
            segment_start,
            segment_fold,
            run.end,
            &later,
            settings.freq_start_hz,
        );
        let mut reached = highest;
        let mut kind = if run.end == PathEnd::DeadEnd {
            JumpKind::PastDeadEnd
        } else {
            JumpKind::PastFold
        };
        let mut before = branch_end;
        // A bridge's cuts: its way down's, then its way up's.
        let cuts: Vec<[Option<GivenUp>; 2]> = bridges
            .iter()
            .map(|b| b.cuts)
            .chain([[cut, None]])
            .collect();
        let branches = bridges.into_iter().map(|b| b.points).chain([fill]);
        for (branch, cuts) in branches.zip(cuts) {
            let (cut, second_cut) = bridge_cuts(cuts);
            let lowest = branch
                .iter()
                .map(|p| p.freq_hz)
                .fold(f64::INFINITY, f64::min);
            let jump = Jump {
                from_hz: reached,
                // A fill that solved nothing below the jump target starts there.
                to_hz: if lowest.is_finite() { lowest } else { freq_hz },
                first_point: adapter.points.len(),
                kind,
                before,
                fill_cut: cut,
                cut_check: None,
                second_cut,
                second_cut_check: None,
                end_check: None,
            };
            adapter.report(Held::Jump(Box::new(jump)));
            run.jumps.push(jump);
            for mut p in branch {
                reached = reached.max(p.freq_hz);
                // Points followed on a branch have their estimate (across the path) already,
                // or pending; the others (solved at a fixed frequency) take it at their
                // frequency.
                if p.accuracy.is_none() && p.pending_estimate.is_none() {
                    let omega = 2.0 * PI * p.freq_hz;
                    adapter.estimate(&mut p, omega, None);
                }
                adapter.push_point(p);
            }
            kind = JumpKind::Bridge;
            before = BranchEnd::Bridge;
        }
        start_hz = freq_hz;
        guess = x;
    }
    run.points = adapter.take_points();
    // Every branch is known now: judge the cuts of the fills and bridges against all of them.
    let newton = Continuation::new(settings, x_scale.clone());
    judge_cuts(&mut system, &newton, &mut run, &mut *adapter.observer);
    let branching = Branching {
        settings,
        x_scale: &x_scale,
        adaptive: &adaptive,
        amplitude_groups: &amplitude_groups,
    };
    judge_leaps(
        &mut system,
        &newton,
        &branching,
        &mut run,
        &mut *adapter.observer,
    );
    run.elapsed_s = started.elapsed().as_secs_f64();
    Ok(run)
}

/// The cuts of a bridge's way down and way up ([`fill_cut`]) as its jump's
/// ([`Jump::fill_cut`], [`Jump::second_cut`]): the way down's first, and a single cut, either
/// way's, as `fill_cut`.
fn bridge_cuts([down, up]: [Option<GivenUp>; 2]) -> (Option<GivenUp>, Option<GivenUp>) {
    match down {
        Some(down) => (Some(down), up),
        None => (up, None),
    }
}

/// How the branch of `points[segment_start..]` ended, for the jump past it: [`PathEnd`] `end`
/// of its continuation (a turned-back end: left the range, dead end or no progress), and
/// `fold_hz`, the last turning point of that continuation. A branch given up (dead end, no
/// progress) is [`BranchEnd::OutsideRange`] when its last point lies below `freq_start_hz`,
/// [`BranchEnd::Retrace`] when it lies on a stretch already followed
/// or on one of the branches solved past it (`later`, each a path without jumps; see
/// [`on_followed_stretch`]), else [`BranchEnd::Abandoned`].
fn branch_end(
    points: &[FrfPoint],
    branch_starts: &[usize],
    segment_start: usize,
    fold_hz: Option<f64>,
    end: PathEnd,
    later: &[&[FrfPoint]],
    freq_start_hz: f64,
) -> BranchEnd {
    let cause = match end {
        PathEnd::DeadEnd => GiveUpCause::DeadEnd,
        PathEnd::NoProgress => GiveUpCause::NoProgress,
        _ => return BranchEnd::LeftRange,
    };
    let Some(last) = points.len().checked_sub(1) else {
        return BranchEnd::LeftRange;
    };
    let amplitude = points[last].amplitudes.first().copied().unwrap_or(f64::NAN);
    let amplitude_rising = last > segment_start
        && points[last - 1]
            .amplitudes
            .first()
            .is_some_and(|&a| amplitude > a);
    let given_up = GivenUp {
        freq_hz: points[last].freq_hz,
        amplitude,
        amplitude_rising,
        fold_hz,
        cause,
    };
    if given_up.freq_hz < freq_start_hz {
        BranchEnd::OutsideRange(given_up)
    } else if on_followed_stretch(points, branch_starts, last, later) {
        BranchEnd::Retrace(given_up)
    } else {
        BranchEnd::Abandoned(given_up)
    }
}

/// Whether point `last` of `points` (the last point of a branch given up) lies on a stretch of
/// path followed elsewhere: some segment between consecutive points, within a branch (not
/// across a jump at `branch_starts`) and before the last monotone stretch that leads into
/// `last` (which crosses its frequency trivially), or within one of the paths `later`,
/// brackets its frequency with every output's linearly interpolated amplitude within
/// [`RETRACE_TOLERANCE`] of the point's.
fn on_followed_stretch(
    points: &[FrfPoint],
    branch_starts: &[usize],
    last: usize,
    later: &[&[FrfPoint]],
) -> bool {
    // The monotone stretch into `last`: back while the frequency keeps moving the same way.
    let mut stretch_start = last;
    if last > 0 {
        let direction = (points[last].freq_hz - points[last - 1].freq_hz).signum();
        stretch_start = last - 1;
        while stretch_start > 0
            && !branch_starts.contains(&stretch_start)
            && (points[stretch_start].freq_hz - points[stretch_start - 1].freq_hz).signum()
                == direction
        {
            stretch_start -= 1;
        }
    }
    // The run's points up to the start of that stretch, cut at the branch starts.
    let mut cuts: Vec<usize> = branch_starts
        .iter()
        .copied()
        .filter(|&b| b > 0 && b <= stretch_start)
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut paths: Vec<&[FrfPoint]> = Vec::new();
    let mut from = 0;
    for cut in cuts {
        paths.push(&points[from..cut]);
        from = cut;
    }
    paths.push(&points[from..=stretch_start]);
    paths.extend_from_slice(later);
    passes_through(&paths, &points[last])
}

/// Whether some segment between consecutive points of one of `paths` brackets `target`'s
/// frequency with every output's linearly interpolated amplitude within
/// [`RETRACE_TOLERANCE`] of `target`'s.
fn passes_through(paths: &[&[FrfPoint]], target: &FrfPoint) -> bool {
    paths.iter().any(|path| {
        path.windows(2).any(|w| {
            let (p, q) = (&w[0], &w[1]);
            if (p.freq_hz - target.freq_hz) * (q.freq_hz - target.freq_hz) > 0.0
                || p.freq_hz == q.freq_hz
            {
                return false;
            }
            let t = (target.freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
            target.amplitudes.iter().enumerate().all(|(o, &a)| {
                let on_segment = p.amplitudes[o] + t * (q.amplitudes[o] - p.amplitudes[o]);
                (on_segment - a).abs() <= RETRACE_TOLERANCE * a.abs()
            })
        })
    })
}

/// Where the fill of a branch past a jump (`fill`, in path order from the jump target down
/// toward the highest frequency of the branch before) was left on a branch that may go on:
/// when its last step heads up (it turned back at a fold of its own, the last at `fold_hz`,
/// and stopped on reaching its end frequency: `end`), the branch goes on above its last
/// point, which no continuation follows; when it was given up before its edge (`end` a dead
/// end or no progress, heading either way) or stopped there for its point budget (`end`
/// [`PathEnd::MaxPoints`]), the branch goes on beyond its last point. None when it reached
/// its end frequency heading down, or left its range, or when its last point lies on the
/// run's `points` before the jump (within a
/// branch at `branch_starts`, see [`passes_through`]). Whether a cut leaves response missing
/// is judged once the run is over ([`judge_cuts`]): the branch followed on from the jump
/// target may pass it.
///
/// A bridge branch is followed the same way from inside a stretch toward each of its edges
/// (`travel_down` false for the way up: then a last step heading down is the cut).
fn fill_cut(
    points: &[FrfPoint],
    branch_starts: &[usize],
    fill: &[FrfPoint],
    travel_down: bool,
    end: PathEnd,
    fold_hz: Option<f64>,
) -> Option<GivenUp> {
    let [.., before, last] = fill else {
        return None;
    };
    let heading_up = last.freq_hz > before.freq_hz;
    let turned_back = last.freq_hz != before.freq_hz && heading_up == travel_down;
    let cause = match end {
        PathEnd::EndFrequency if turned_back => GiveUpCause::FillEnd,
        PathEnd::DeadEnd => GiveUpCause::DeadEnd,
        PathEnd::NoProgress => GiveUpCause::NoProgress,
        PathEnd::MaxPoints => GiveUpCause::PointBudget,
        PathEnd::EndFrequency | PathEnd::LeftRangeBelow => return None,
    };
    let mut cuts: Vec<usize> = branch_starts
        .iter()
        .copied()
        .filter(|&b| b > 0 && b < points.len())
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut paths: Vec<&[FrfPoint]> = Vec::new();
    let mut from = 0;
    for cut in cuts {
        paths.push(&points[from..cut]);
        from = cut;
    }
    paths.push(&points[from..]);
    if passes_through(&paths, last) {
        return None;
    }
    let amplitude = last.amplitudes.first().copied().unwrap_or(f64::NAN);
    Some(GivenUp {
        freq_hz: last.freq_hz,
        amplitude,
        amplitude_rising: before.amplitudes.first().is_some_and(|&a| amplitude > a),
        fold_hz,
        cause,
    })
}

/// Offsets past a cut at which [`judge_cuts`] tries Newton, in units of the cut's last
/// frequency step (clamped to [10⁻⁷, 5·10⁻⁴] of the cut's frequency), in the order tried: the
/// first that converges is the landing. Then [`CUT_CHECK_FALLBACKS`].
pub const CUT_CHECK_OFFSETS: &[f64] = &[1.0, 0.25, 0.0625];
/// Offsets past a cut, relative to its frequency, tried when none of [`CUT_CHECK_OFFSETS`]
/// converges: at a dead end Newton at a fixed frequency can fail close past the point (at
/// F0 = 1 N on the paper's system a bridge given up at 152.2176 Hz: no convergence from 10⁻⁷
/// to 5·10⁻⁴ past it, a landing on the run at 10⁻³).
pub const CUT_CHECK_FALLBACKS: &[f64] = &[1e-4, 1e-3];
/// The step, relative to the frequency, of which [`CUT_CHECK_OFFSETS`] are taken past a point
/// given up at a dead end ([`GiveUpCause::DeadEnd`]; see [`judge_cut`]): the largest a cut's
/// last step is clamped to. On the paper's system at F0 = 2 N Newton from the dead end at
/// 153.0743 Hz converges 6·10⁻⁹ of the frequency past it (the branch's own next bit, 2 Newton
/// iterations), at none of 10⁻⁷ to 5·10⁻⁴, and on the run 10⁻³ past it.
pub const DEAD_END_CHECK_STEP: f64 = 5e-4;

/// Judges the cuts of every jump of `run` ([`Jump::fill_cut`], [`Jump::second_cut`]), and the
/// last point of every branch abandoned before a jump ([`BranchEnd::Abandoned`]), now that
/// every branch of the run is known, sets their [`Jump::cut_check`],
/// [`Jump::second_cut_check`] and [`Jump::end_check`] and tells `observer`
/// ([`FrfObserver::cut_judged`]). A branch given up at a dead end or for want of progress
/// off every stretch followed is judged as a cut is: the point given up, like a cut, is where
/// the run stopped following a branch, and only Newton past it tells whether that branch goes
/// on off the run (on the paper's system at F0 = 2 N the dead end at 153.0743 Hz: Newton 10⁻³
/// of the frequency past it lands 0.24 % from the nearest stretch of the run, and Newton from
/// that stretch's nearer point converges to the landing: covered). Past a dead end the
/// offsets are taken of [`DEAD_END_CHECK_STEP`]; where Newton converges at none of them, the
/// other side of a fold at the dead end is sought with the frequency free
/// ([`judge_round_dead_end`]: on the 3D blade pair's m = −1 limit curve the dead end at
/// 869.0841 Hz turns back there, its other side at 869.0661 Hz below the run: covered; on the
/// 2D blade pair's m = +1 limit curve at 5 N neither converges past the dead end at 875.5021
/// Hz: unjudged).
///
/// Newton at a fixed frequency just past the cut, in the direction its stretch was going at
/// its last step (away from the point before it on the branch; by its fold when the branch
/// holds the cut point alone), from the cut point's coefficients, at the offsets
/// [`CUT_CHECK_OFFSETS`] then [`CUT_CHECK_FALLBACKS`] until one converges: at most five
/// fixed-frequency solves per cut, one where Newton converges just past it.
/// The landing is compared, over all its Fourier coefficients, with every crossing of its
/// frequency by the run's points (linear along a segment within a branch, not across a jump),
/// the cut's own branch included (a crossing on the other side of the cut's fold is recorded
/// as [`CutCheck::own_side`]). Each crossing within [`RETRACE_TOLERANCE`], nearest first, is
/// then solved again by Newton at the landing's frequency, from its interpolated coefficients
/// (else from the segment's nearer point): the first whose solution is the landing (within
/// [`SAME_SOLUTION_TOLERANCE`]) covers the cut. When none does the branch goes on beyond the
/// cut unfollowed ([`CutVerdict::Abandoned`]): next to a fold of the cut's own stretch its two
/// sides lie within the tolerance of each other, so a landing on the branch beyond the cut is
/// that close to the side already followed, and only Newton from that side tells them apart.
/// When no solve past the cut converges the cut is [`CutVerdict::Unjudged`]; the status
/// counts both as not covered.
fn judge_cuts<O: FrfObserver>(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    run: &mut FrfRun,
    observer: &mut O,
) {
    let starts = run.branch_starts();
    for k in 0..run.jumps.len() {
        let jump = run.jumps[k];
        // The branch before the jump, given up off every stretch followed: its last point is
        // the last of the branch that ends at the jump.
        let end_check = match &jump.before {
            BranchEnd::Abandoned(given_up) => {
                let branch = k.checked_sub(1).map_or(0, |j| starts[j])..jump.first_point;
                Some(judge_cut(
                    system,
                    newton,
                    &run.points,
                    &starts,
                    branch,
                    given_up,
                ))
            }
            _ => None,
        };
        run.jumps[k].end_check = end_check;
        if jump.fill_cut.is_none() && jump.second_cut.is_none() {
            if end_check.is_some() {
                observer.cut_judged(k, &run.jumps[k]);
            }
            continue;
        }
        let first = jump.first_point;
        let end = starts
            .get(k + 1)
            .copied()
            .unwrap_or(run.points.len())
            .max(first);
        let mut judge =
            |cut: &GivenUp| judge_cut(system, newton, &run.points, &starts, first..end, cut);
        let checks = (
            jump.fill_cut.as_ref().map(&mut judge),
            jump.second_cut.as_ref().map(&mut judge),
        );
        run.jumps[k].cut_check = checks.0;
        run.jumps[k].second_cut_check = checks.1;
        observer.cut_judged(k, &run.jumps[k]);
    }
}

/// Most points of the path followed back from a leap's landing ([`judge_leaps`]).
pub const LEAP_CHECK_POINTS: usize = 300;

/// Judges every leap of the run ([`LeapCheck`]): from the leap's landing (the first point
/// after it) the path is followed back to the frequency of the point before it, with the
/// run's continuation settings and scales and at most [`LEAP_CHECK_POINTS`] points, and the
/// solution it reaches there is compared with Newton's solution at that frequency started
/// from the point before the leap. On one solution curve the path followed back comes round
/// to that point (through whatever the leap passed over); where the leap crossed a fold onto
/// another curve, the path back reaches the frequency on that other curve first.
fn judge_leaps<O: FrfObserver>(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    branching: &Branching<'_>,
    run: &mut FrfRun,
    observer: &mut O,
) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    let starts = run.branch_starts();
    for k in 0..run.leaps.len() {
        let (from_hz, to_hz) = run.leaps[k];
        // (before, landing) as recorded, checked against the leap's frequencies.
        let at = run.leap_points.get(k).copied().flatten().filter(|&(b, l)| {
            match (run.points.get(b), run.points.get(l)) {
                (Some(b), Some(l)) => close(b.freq_hz, from_hz) && close(l.freq_hz, to_hz),
                _ => false,
            }
        });
        let mut check = LeapCheck {
            from_hz,
            to_hz,
            before_amplitude: None,
            back_amplitude: None,
            distance: None,
            points: 0,
            verdict: CutVerdict::Unjudged,
            past: None,
        };
        if let Some((b, l)) = at {
            let (before, landing) = (&run.points[b], &run.points[l]);
            check.before_amplitude = before.amplitudes.first().copied();
            let x = system.restrict(&landing.coefficients);
            let (back, summary) =
                branching.follow(system, &x, to_hz, from_hz, LEAP_CHECK_POINTS, None);
            check.points = back.len();
            let reached = summary.is_some_and(|s| s.end == PathEnd::EndFrequency);
            if let (true, Some(end)) = (reached, back.last()) {
                check.back_amplitude = end.amplitudes.first().copied();
                let omega = 2.0 * PI * end.freq_hz;
                if let Some(own) = newton_at(system, newton, &before.coefficients, omega) {
                    let d = relative_distance(&end.coefficients, &own);
                    check.distance = Some(d);
                    check.verdict = if d <= RETRACE_TOLERANCE {
                        CutVerdict::Covered
                    } else {
                        CutVerdict::Abandoned
                    };
                }
            }
            if check.verdict == CutVerdict::Abandoned {
                let past = judge_past_leap(system, newton, &run.points, &starts, (b, l));
                if let Some(past) = past {
                    check.verdict = past.verdict;
                    check.past = Some(past);
                }
            }
        }
        observer.leap_judged(&check);
        run.leap_checks.push(check);
    }
}

/// The branch through the point before a leap onto another branch (`before`, `landing`:
/// indices of the point before the leap and of the landing in `points`), judged as a branch
/// given up at a dead end ([`judge_cut`]): the corrector failed at every step past that point,
/// as at a dead end. None when the point is the first of its stretch (no direction to go on
/// in).
fn judge_past_leap(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    (before, landing): (usize, usize),
) -> Option<CutCheck> {
    // The stretch into the point before the leap, within its branch: the point before it
    // along the path is on the side away from the landing.
    let branch_start = starts
        .iter()
        .copied()
        .filter(|&s| s <= before)
        .max()
        .unwrap_or(0);
    let branch_end = starts
        .iter()
        .copied()
        .filter(|&s| s > before)
        .min()
        .unwrap_or(points.len());
    let stretch = if landing > before {
        branch_start..before + 1
    } else {
        before..branch_end
    };
    if stretch.len() < 2 {
        return None;
    }
    let given_up = GivenUp {
        freq_hz: points[before].freq_hz,
        amplitude: points[before]
            .amplitudes
            .first()
            .copied()
            .unwrap_or(f64::NAN),
        amplitude_rising: false,
        fold_hz: None,
        cause: GiveUpCause::DeadEnd,
    };
    Some(judge_cut(
        system, newton, points, starts, stretch, &given_up,
    ))
}

/// The judgement of one cut `cut` of the branch `points[branch]` (see [`judge_cuts`]).
fn judge_cut(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    branch: std::ops::Range<usize>,
    cut: &GivenUp,
) -> CutCheck {
    let unjudged = |freq_hz: f64, newton_iterations: usize| CutCheck {
        landing: Landing::nowhere(freq_hz),
        own_side: false,
        newton_iterations,
        beyond_fold: None,
        verdict: CutVerdict::Unjudged,
    };
    let is_cut = |p: &FrfPoint| {
        p.freq_hz == cut.freq_hz
            && p.amplitudes
                .first()
                .map_or(cut.amplitude.is_nan(), |&a| a == cut.amplitude)
    };
    // The cut point is the first or the last of its branch (the fill is reported from the
    // cut up; a bridge from its lower end, cut or not, to its upper end).
    let Some(i) = [branch.start, branch.end.saturating_sub(1)]
        .into_iter()
        .find(|&i| branch.contains(&i) && is_cut(&points[i]))
    else {
        return unjudged(cut.freq_hz, 0);
    };
    let f = cut.freq_hz;
    // The point before the cut along the stretch, skipping points at the same frequency.
    let before = if i == branch.start {
        points[i + 1..branch.end]
            .iter()
            .find(|p| p.freq_hz != f)
            .map(|p| p.freq_hz)
    } else {
        points[branch.start..i]
            .iter()
            .rev()
            .find(|p| p.freq_hz != f)
            .map(|p| p.freq_hz)
    };
    let (direction, step) = match before {
        Some(b) => ((f - b).signum(), (f - b).abs()),
        None => {
            let down = cut.fold_hz.is_some_and(|fold| fold >= f);
            (if down { -1.0 } else { 1.0 }, 1e-4 * f)
        }
    };
    // At a dead end the corrector failed at every step down to the minimum, so the last
    // step is tiny, and a landing that close past the point is the branch's own next bit,
    // which no stretch holds by construction: there the judgement steps as far as a cut's
    // largest step.
    let step = if cut.cause == GiveUpCause::DeadEnd {
        DEAD_END_CHECK_STEP * f
    } else {
        step
    };
    let (freq_hz, landing) = land_past(system, newton, &points[i].coefficients, f, direction, step);
    let Some(landing) = landing else {
        // Nothing past a dead end: the branch may turn back there, at a fold whose other side
        // runs back beside the stretch into it.
        if cut.cause == GiveUpCause::DeadEnd {
            if let Some(check) =
                judge_round_dead_end(system, newton, (points, starts), branch, i, freq_hz)
            {
                return check;
            }
        }
        return unjudged(freq_hz, 0);
    };
    // The cut's own stretch and the one before it on its branch (the other side of the fold
    // it turned back at): next to a fold its two sides lie within the tolerance of each
    // other, so the comparison by interpolation does not tell the branch beyond the cut from
    // the side already followed; nor can that side be left out (at F0 = 5 N on the paper's
    // system the landings 10⁻⁷ to 2·10⁻³ past the cut at 80.4161 Hz follow that side within
    // 0.002-0.18 %, as close as its linear interpolation over a 0.75 Hz segment allows, and
    // no other stretch crosses there). Newton from the crossing tells them apart.
    let away: Vec<usize> = if i == branch.start {
        (i..branch.end).collect()
    } else {
        (branch.start..=i).rev().collect()
    };
    let mut turns = 0;
    let mut heading = 0.0;
    let mut reach = 0;
    // The fold the cut's stretch turned back at: the point where the way back from the cut
    // first turns.
    let mut fold = None;
    for w in 1..away.len() {
        let d = (points[away[w]].freq_hz - points[away[w - 1]].freq_hz).signum();
        if d != 0.0 && heading != 0.0 && d != heading {
            turns += 1;
            fold.get_or_insert(w - 1);
            if turns == 2 {
                break;
            }
        }
        if d != 0.0 {
            heading = d;
        }
        reach = w;
    }
    let own = away.get(reach).map_or(i..=i, |&j| i.min(j)..=i.max(j));
    let compared = compare_with_run(system, newton, points, starts, &own, &landing);
    // Landed on the cut's own other side, the same solution: the stretch came back along
    // the side it had followed into its fold, so that fold is where the path reversed on one
    // solution curve, and the branch goes on beyond it, the way that side was heading.
    let beyond_fold = match (compared.covered, compared.own_side, fold) {
        (true, true, Some(w)) => {
            let j = away[w];
            let fold_hz = points[j].freq_hz;
            let into = away[w + 1..]
                .iter()
                .map(|&k| points[k].freq_hz)
                .find(|&g| g != fold_hz);
            into.map(|g| {
                let (freq_hz, landing) = land_past(
                    system,
                    newton,
                    &points[j].coefficients,
                    fold_hz,
                    (fold_hz - g).signum(),
                    (fold_hz - g).abs(),
                );
                judge_beyond_fold(
                    system, newton, points, starts, &own, fold_hz, freq_hz, landing,
                )
            })
        }
        _ => None,
    };
    let verdict = match (&beyond_fold, compared.covered) {
        (Some(b), _) => b.verdict,
        (None, true) => CutVerdict::Covered,
        (None, false) => CutVerdict::Abandoned,
    };
    CutCheck {
        landing: compared.landing,
        own_side: compared.own_side,
        newton_iterations: landing.newton_iterations,
        beyond_fold,
        verdict,
    }
}

/// How far back along the stretch into a dead end, relative to its frequency, the chord of
/// [`judge_round_dead_end`] reaches: the first point at least this far from the dead end in
/// frequency (or the stretch's first point). On the 3D blade pair's m = −1 curve the stretch
/// reaches its dead end at 869.0841 Hz in halving steps (the last ones 10⁻⁸ Hz apart): the
/// chord reaches back to 869.0123 Hz, and a quarter of it past the dead end lands on the other
/// side of its fold at 869.0661 Hz; on the paper's system at −5 N and H = 3 a fill's dead end
/// at 92.0992 Hz, reached the same way, turns back a few 10⁻⁵ Hz behind it
/// (`tests/frf_abandoned.rs`).
pub const ROUND_FOLD_CHORD: f64 = 5e-5;
/// Steps past a dead end along the chord of [`judge_round_dead_end`], in chord lengths, in
/// the order tried.
pub const ROUND_FOLD_STEPS: &[f64] = &[0.25, 1.0, 0.0625];

/// The judgement of a dead end past which Newton at a fixed frequency converges nowhere
/// (`past_hz` the last frequency tried): the stretch may have met a fold of the sampled
/// contact law, a corner where the branch turns back, whose other side the path could not
/// turn onto. That side is sought by Newton with the frequency free on the hyperplane normal
/// to the stretch's chord in the unknowns alone ([`ROUND_FOLD_CHORD`] back, stepped
/// [`ROUND_FOLD_STEPS`] past the dead end): where the unknowns go on past the dead-end point,
/// a branch that turned back at a fold lies at a lower frequency (higher on a stretch running
/// down). A landing behind the dead end is judged as the landing past a cut stretch's fold
/// ([`judge_beyond_fold`]: on the run, or below the run's largest amplitude there, is
/// covered). Recorded as a [`CutCheck`] whose own landing is nowhere and whose
/// [`CutCheck::beyond_fold`] is that judgement, the fold at the dead end. None where no such
/// landing converges.
fn judge_round_dead_end(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    (points, starts): (&[FrfPoint], &[usize]),
    branch: std::ops::Range<usize>,
    i: usize,
    past_hz: f64,
) -> Option<CutCheck> {
    let f = points[i].freq_hz;
    let into: Vec<usize> = if i == branch.start {
        (i + 1..branch.end).collect()
    } else {
        (branch.start..i).rev().collect()
    };
    let a = into
        .iter()
        .copied()
        .find(|&k| (points[k].freq_hz - f).abs() >= ROUND_FOLD_CHORD * f)
        .or_else(|| into.last().copied())?;
    let landing = land_round_fold(system, newton.settings, &points[a], &points[i])?;
    let own = a.min(i)..=a.max(i);
    let compared = compare_with_run(system, newton, points, starts, &own, &landing);
    // A landing on the stretch into the dead end itself (the chord's hyperplane crossing it
    // again behind the point) is no other side: no fold was found.
    if compared.covered && compared.own_side {
        return None;
    }
    let fold = fold_check(f, &compared);
    Some(CutCheck {
        landing: Landing::nowhere(past_hz),
        own_side: false,
        newton_iterations: 0,
        beyond_fold: Some(fold),
        verdict: fold.verdict,
    })
}

/// The other side of a fold at the point `b`, reached from the point `a` before it on the
/// same stretch: Newton with the frequency free (the corrector of `settings`) on the
/// hyperplane normal to the chord from `a` to `b` in the unknowns alone, through `b` plus
/// [`ROUND_FOLD_STEPS`] chord lengths along it; the first landing behind `b` in frequency (on
/// the side of `a`) is returned. The unknowns are Fourier coefficients of displacements, all in
/// metres, and the chord is taken in that metric (one scale for all of them, the largest
/// coefficient of `b`), not in the run's arc-length scales, which grow along the run: the
/// landing depends on the two points only ([`PointSolver::solve_round_fold`] finds it again).
fn land_round_fold(
    system: &mut HbmOperator<'_>,
    settings: ContinuationSettings,
    a: &FrfPoint,
    b: &FrfPoint,
) -> Option<FrfPoint> {
    let size = system
        .restrict(&b.coefficients)
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let newton = Continuation::new(settings, vec![size; system.dim()]);
    let scale = &newton.x_scale;
    let scaled = |p: &FrfPoint, system: &HbmOperator<'_>| -> Vec<f64> {
        system
            .restrict(&p.coefficients)
            .iter()
            .zip(scale)
            .map(|(v, s)| v / s)
            .collect()
    };
    let (ya, yb) = (scaled(a, system), scaled(b, system));
    let mut chord: Vec<f64> = yb.iter().zip(&ya).map(|(q, p)| q - p).collect();
    let length = crate::numerics::linalg::norm(&chord);
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    chord.iter_mut().for_each(|v| *v /= length);
    // The frequency is free: the hyperplane's normal has no component on it.
    chord.push(0.0);
    let back = (a.freq_hz - b.freq_hz).signum();
    for &steps in ROUND_FOLD_STEPS {
        let mut predicted: Vec<f64> = yb
            .iter()
            .zip(&chord)
            .map(|(y, c)| y + steps * length * c)
            .collect();
        predicted.push(b.freq_hz);
        let Ok(point) = correct_on_hyperplane(system, &newton, &predicted, &chord) else {
            continue;
        };
        if (point.freq_hz - b.freq_hz) * back > 0.0 {
            return Some(point);
        }
    }
    None
}

/// The point on the hyperplane through `predicted` normal to `normal` (both in the scaled
/// space of `newton`: unknowns over its `x_scale`, then the frequency in Hz), by its corrector
/// from `predicted`, with the operator left evaluated at it (its contact states those of the
/// point).
fn correct_on_hyperplane(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    predicted: &[f64],
    normal: &[f64],
) -> Result<FrfPoint, NewtonFailure> {
    let (y, iterations, residual) = newton.correct(system, predicted, normal)?;
    let n = y.len() - 1;
    let x: Vec<f64> = y[..n]
        .iter()
        .zip(&newton.x_scale)
        .map(|(v, s)| v * s)
        .collect();
    let omega = 2.0 * PI * y[n];
    let mut r = vec![0.0; n];
    system
        .residual(&x, omega, &mut r)
        .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
    let path_point = PathPoint {
        omega,
        x,
        iterations,
        residual,
        step: 0.0,
    };
    let mut point =
        full_point(system, &path_point).map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
    point.freq_hz = y[n];
    Ok(point)
}

/// Newton at fixed frequencies past `f` (Hz) in `direction` (±1) from the coefficients
/// `start`, at the offsets [`CUT_CHECK_OFFSETS`] of `step` (Hz, the last frequency step into
/// `f`, clamped to [10⁻⁷, 5·10⁻⁴] of `f`), then [`CUT_CHECK_FALLBACKS`]: the frequency of the
/// last solve tried (Hz) and the first point that converged, if any.
fn land_past(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    start: &[f64],
    f: f64,
    direction: f64,
    step: f64,
) -> (f64, Option<FrfPoint>) {
    let guess = system.restrict(start);
    let step = step.clamp(1e-7 * f, 5e-4 * f);
    let mut freq_hz = f;
    let offsets = CUT_CHECK_OFFSETS
        .iter()
        .map(|m| m * step)
        .chain(CUT_CHECK_FALLBACKS.iter().map(|r| r * f));
    for offset in offsets {
        freq_hz = f + direction * offset;
        let Ok(p) = newton.solve_fixed(system, &guess, 2.0 * PI * freq_hz) else {
            continue;
        };
        if let Ok(mut point) = full_point(system, &p) {
            point.freq_hz = freq_hz;
            return (freq_hz, Some(point));
        }
    }
    (freq_hz, None)
}

/// The judgement past the fold at `fold_hz` (Hz) of a cut stretch that came back along its
/// own other side ([`CutCheck::beyond_fold`]): `landing`, solved at `freq_hz` (Hz) past the
/// fold, compared with the run ([`compare_with_run`]).
#[allow(clippy::too_many_arguments)]
fn judge_beyond_fold(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    own: &std::ops::RangeInclusive<usize>,
    fold_hz: f64,
    freq_hz: f64,
    landing: Option<FrfPoint>,
) -> FoldCheck {
    let Some(landing) = landing else {
        return FoldCheck {
            fold_hz,
            landing: Landing::nowhere(freq_hz),
            run_amplitude: None,
            verdict: CutVerdict::Unjudged,
        };
    };
    let compared = compare_with_run(system, newton, points, starts, own, &landing);
    fold_check(fold_hz, &compared)
}

/// The judgement past the fold at `fold_hz` (Hz) of a landing `compared` with the run: on a
/// stretch, or below the run's largest amplitude there, covered; else abandoned.
fn fold_check(fold_hz: f64, compared: &Comparison) -> FoldCheck {
    let below_run = |run: f64| compared.landing.amplitude.is_some_and(|a| a <= run);
    let verdict = match compared.run_amplitude {
        _ if compared.covered => CutVerdict::Covered,
        Some(run) if below_run(run) => CutVerdict::Covered,
        _ => CutVerdict::Abandoned,
    };
    FoldCheck {
        fold_hz,
        landing: compared.landing,
        run_amplitude: compared.run_amplitude,
        verdict,
    }
}

/// How a landing compares with the run ([`compare_with_run`]).
struct Comparison {
    /// The landing, at its frequency, with [`Landing::distance`] and
    /// [`Landing::resolved_distance`] from this comparison.
    landing: Landing,
    /// [`CutCheck::own_side`].
    own_side: bool,
    /// Whether Newton from a crossing within [`RETRACE_TOLERANCE`] found the landing.
    covered: bool,
    /// The largest first-output amplitude of the run's crossings of the landing's frequency
    /// (m); None without a crossing.
    run_amplitude: Option<f64>,
}

/// Compares `landing` with every crossing of its frequency by the run's `points` within a
/// branch (not across a jump at `starts`), those inside `own` marked as the cut's own side:
/// each crossing within [`RETRACE_TOLERANCE`] on the coefficients, nearest first, is solved
/// again by Newton at the landing's frequency ([`resolve_crossing`]), and the first whose
/// solution is the landing (within [`SAME_SOLUTION_TOLERANCE`]) covers it.
fn compare_with_run(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    starts: &[usize],
    own: &std::ops::RangeInclusive<usize>,
    landing: &FrfPoint,
) -> Comparison {
    let freq_hz = landing.freq_hz;
    let norm = crate::numerics::linalg::norm(&landing.coefficients);
    let mut run_amplitude: Option<f64> = None;
    // Every crossing of the landing's frequency within a branch, nearest first.
    let mut crossings: Vec<Crossing> = (0..points.len().saturating_sub(1))
        .filter(|&k| !starts.contains(&(k + 1)))
        .filter_map(|k| {
            let (p, q) = (&points[k], &points[k + 1]);
            if (p.freq_hz - freq_hz) * (q.freq_hz - freq_hz) > 0.0 || p.freq_hz == q.freq_hz {
                return None;
            }
            let t = (freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
            if let (Some(a), Some(b)) = (p.amplitudes.first(), q.amplitudes.first()) {
                let on = a + t * (b - a);
                run_amplitude = Some(run_amplitude.map_or(on, |r| r.max(on)));
            }
            let squared: f64 = landing
                .coefficients
                .iter()
                .zip(p.coefficients.iter().zip(&q.coefficients))
                .map(|(c, (a, b))| (c - (a + t * (b - a))).powi(2))
                .sum();
            Some(Crossing {
                segment: k,
                t,
                distance: squared.sqrt() / norm,
                own_side: own.contains(&k) && own.contains(&(k + 1)),
            })
        })
        .collect();
    crossings.sort_by(|a, b| a.distance.total_cmp(&b.distance));
    let omega = 2.0 * PI * freq_hz;
    let mut covered = false;
    let mut resolved: Option<(&Crossing, Option<f64>)> = None;
    for crossing in crossings
        .iter()
        .take_while(|c| c.distance <= RETRACE_TOLERANCE)
    {
        let apart = resolve_crossing(system, newton, points, crossing, omega, landing);
        let covers = apart.is_some_and(|d| d <= SAME_SOLUTION_TOLERANCE);
        if resolved.is_none() || covers {
            resolved = Some((crossing, apart));
        }
        if covers {
            covered = true;
            break;
        }
    }
    let shown = resolved.map(|(c, _)| c).or(crossings.first());
    Comparison {
        landing: Landing {
            freq_hz,
            amplitude: Some(landing.amplitudes.first().copied().unwrap_or(f64::NAN)),
            distance: shown.map(|c| c.distance),
            resolved_distance: resolved.and_then(|(_, d)| d),
        },
        own_side: shown.is_some_and(|c| c.own_side),
        covered,
        run_amplitude,
    }
}

/// A crossing of a frequency by a segment of the run's points (see [`judge_cut`]).
struct Crossing {
    /// Index of the segment's first point.
    segment: usize,
    /// Where along the segment, from its first point (0) to its second (1).
    t: f64,
    /// ‖c − c_run‖ / ‖c‖ between the landing and the linear interpolation along the segment.
    distance: f64,
    /// Whether the segment lies on the cut's own side of its fold ([`CutCheck::own_side`]).
    own_side: bool,
}

/// ‖c − c_N‖ / ‖c‖ between `landing` (converged at ω = `omega`, rad/s) and Newton's solution
/// c_N at the same ω from `crossing`: from its coefficients interpolated along the segment,
/// and, unless that solution is the landing, from those of the segment's nearer point; the
/// smaller of the two. The same solution to solver precision when at most
/// [`SAME_SOLUTION_TOLERANCE`]: where neighbouring pieces of the sampled contact law lie a few
/// 10⁻³ apart, the two starts can reach different ones (on the paper's system at F0 = 2 N, at
/// 153.2274 Hz, the interpolated start a solution 3.2·10⁻³ from the landing, the nearer point
/// the landing itself). None when Newton converges from neither.
fn resolve_crossing(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    points: &[FrfPoint],
    crossing: &Crossing,
    omega: f64,
    landing: &FrfPoint,
) -> Option<f64> {
    let (p, q) = (&points[crossing.segment], &points[crossing.segment + 1]);
    let t = crossing.t;
    let interpolated: Vec<f64> = p
        .coefficients
        .iter()
        .zip(&q.coefficients)
        .map(|(a, b)| a + t * (b - a))
        .collect();
    let nearer = if t < 0.5 { p } else { q };
    let mut apart: Option<f64> = None;
    for start in [interpolated.as_slice(), nearer.coefficients.as_slice()] {
        if let Some(c) = newton_at(system, newton, start, omega) {
            let d = relative_distance(&c, &landing.coefficients);
            apart = Some(apart.map_or(d, |a| a.min(d)));
            if d <= SAME_SOLUTION_TOLERANCE {
                break;
            }
        }
    }
    apart
}

/// Newton's solution at ω = `omega` (rad/s) from the full coefficients `start`, on full
/// coefficients; None when it does not converge.
fn newton_at(
    system: &mut HbmOperator<'_>,
    newton: &Continuation,
    start: &[f64],
    omega: f64,
) -> Option<Vec<f64>> {
    let guess = system.restrict(start);
    let solved = newton.solve_fixed(system, &guess, omega).ok()?;
    system.expand(&solved.x, omega).ok()
}

/// ‖a − reference‖ / ‖reference‖ over all coefficients.
fn relative_distance(a: &[f64], reference: &[f64]) -> f64 {
    let squared: f64 = a.iter().zip(reference).map(|(u, v)| (u - v).powi(2)).sum();
    squared.sqrt() / crate::numerics::linalg::norm(reference)
}

/// Point budget of each direction of a bridge branch (see [`Branching::bridge`]).
const BRIDGE_POINTS: usize = 300;
/// Most branches solved inside the stretches left uncovered by one jump.
const MAX_BRIDGES: usize = 8;
/// Where in an uncovered stretch a bridge branch is sought, as fractions of the stretch, in
/// the order tried.
const BRIDGE_FRACTIONS: &[f64] = &[0.5, 0.25, 0.75, 0.1, 0.9];
/// Weights w of the blends (1 − w)·lower end + w·upper end of the stretch's end points'
/// coefficients tried as Newton guesses, in the order tried.
const BRIDGE_BLENDS: &[f64] = &[0.5, 0.25, 0.75, 0.0, 1.0];

/// What the branches of one run share: the settings, the arc-length scale, how it grows and
/// which amplitudes the steps follow.
struct Branching<'a> {
    settings: ContinuationSettings,
    x_scale: &'a [f64],
    adaptive: &'a AdaptiveScale,
    amplitude_groups: &'a [Vec<usize>],
}

impl Branching<'_> {
    /// Follows the path silently from `x` (the operator's unknowns, converged at `from_hz`)
    /// toward `to_hz` (below or above) with at most `max_points` points. Returns the points in
    /// path order (the first is the start point) and the summary, None when the continuation
    /// failed (its points up to the failure are kept). With `estimates`, each point gets
    /// its error estimate across the path as it is accepted (or, formed on a worker, pending
    /// until the run reports the point).
    fn follow(
        &self,
        system: &mut HbmOperator<'_>,
        x: &[f64],
        from_hz: f64,
        to_hz: f64,
        max_points: usize,
        estimates: Option<&EstimatePool<'_>>,
    ) -> (Vec<FrfPoint>, Option<PathSummary>) {
        let settings = ContinuationSettings {
            freq_start_hz: from_hz,
            freq_end_hz: to_hz,
            max_points,
            ..self.settings
        };
        let mut collect = Adapter {
            observer: &mut Silent,
            points: Vec::new(),
            failure: None,
            estimates,
            in_order: false,
            held: VecDeque::new(),
        };
        let mut continuation = Continuation::new(settings, self.x_scale.to_vec())
            .with_adaptive_scale(self.adaptive.clone())
            .with_amplitude_steps(self.amplitude_groups.to_vec());
        let summary = continuation.run(system, x, &mut collect).ok();
        (std::mem::take(&mut collect.points), summary)
    }

    /// Branches inside the stretch between `below` (the highest point of the branch before a
    /// jump) and `above` (the lowest point of the branch after it), which neither reached.
    ///
    /// At a fold of the sampled contact law's solution curve, two branches can fold away from
    /// each other with solutions between them on neither (a damper bouncing at a low
    /// pre-load). Newton from blends of the two ends' coefficients ([`BRIDGE_BLENDS`]) at
    /// points inside the stretch ([`BRIDGE_FRACTIONS`]) finds such solutions; each is followed
    /// down toward `below` and up toward `above`, and what is still uncovered on either side
    /// is bridged in turn, up to [`MAX_BRIDGES`] branches and `budget` points. Returns the
    /// branches found, each in path order from its lowest point up, sorted by their lowest
    /// frequency, with the cuts of its way down and of its way up (see [`fill_cut`]).
    fn bridge(
        &self,
        system: &mut HbmOperator<'_>,
        below: &FrfPoint,
        above: &FrfPoint,
        budget: usize,
        estimates: Option<&EstimatePool<'_>>,
        (followed, branch_starts): (&[FrfPoint], &[usize]),
    ) -> Vec<BridgeBranch> {
        let mut branches: Vec<BridgeBranch> = Vec::new();
        let mut gaps = vec![(below.clone(), above.clone())];
        let mut used = 0;
        let solver = Continuation::new(self.settings, self.x_scale.to_vec());
        while let Some((lo, hi)) = gaps.pop() {
            if branches.len() >= MAX_BRIDGES || used + 2 > budget {
                break;
            }
            let Some((freq_hz, x)) = solve_between(system, &solver, &lo, &hi) else {
                continue;
            };
            let per_side = BRIDGE_POINTS.min((budget - used) / 2);
            let (mut down, down_end) =
                self.follow(system, &x, freq_hz, lo.freq_hz, per_side, estimates);
            let (up, up_end) = self.follow(system, &x, freq_hz, hi.freq_hz, per_side, estimates);
            // Either way turned back at a fold of its own before its edge, or was given up or
            // ran out of points before it: cut there (both ways may be).
            let cut_of = |side: &[FrfPoint], travel_down: bool, end: &Option<PathSummary>| {
                end.as_ref().and_then(|summary| {
                    fill_cut(
                        followed,
                        branch_starts,
                        side,
                        travel_down,
                        summary.end,
                        summary.turning_points.last().copied(),
                    )
                })
            };
            let cuts = [cut_of(&down, true, &down_end), cut_of(&up, false, &up_end)];
            // The leaps of both ways as placed in the branch: the way down reversed, then the
            // way up without its first point (the way down's first).
            let down_len = down.len();
            let mut leap_points = down_end
                .as_ref()
                .map_or(Vec::new(), |s| reversed_leaps(&s.leap_landings, down_len));
            leap_points.extend(
                up_end
                    .as_ref()
                    .map_or(Vec::new(), |s| forward_leaps(&s.leap_landings, 1, down_len)),
            );
            down.reverse();
            // Both directions start with the point at `freq_hz`: keep one.
            let branch: Vec<FrfPoint> = down.into_iter().chain(up.into_iter().skip(1)).collect();
            used += branch.len();
            let by_freq = |a: &&FrfPoint, b: &&FrfPoint| a.freq_hz.total_cmp(&b.freq_hz);
            let (Some(low), Some(high)) =
                (branch.iter().min_by(by_freq), branch.iter().max_by(by_freq))
            else {
                continue;
            };
            let gap_below = Jump {
                from_hz: lo.freq_hz,
                to_hz: low.freq_hz,
                first_point: 0,
                kind: JumpKind::Bridge,
                before: BranchEnd::Bridge,
                fill_cut: None,
                cut_check: None,
                second_cut: None,
                second_cut_check: None,
                end_check: None,
            };
            if gap_below.uncovered_hz() > 0.0 {
                gaps.push((lo.clone(), low.clone()));
            }
            let gap_above = Jump {
                from_hz: high.freq_hz,
                to_hz: hi.freq_hz,
                ..gap_below
            };
            if gap_above.uncovered_hz() > 0.0 {
                gaps.push((high.clone(), hi.clone()));
            }
            let ways = [&down_end, &up_end];
            let summaries = || ways.iter().filter_map(|w| w.as_ref());
            branches.push(BridgeBranch {
                points: branch,
                cuts,
                turning_points: summaries()
                    .flat_map(|s| s.turning_points.iter().copied())
                    .collect(),
                rejected_steps: summaries().map(|s| s.rejected_steps).sum(),
                leaps: summaries().flat_map(|s| s.leaps.iter().copied()).collect(),
                leap_points,
            });
        }
        branches.sort_by(|a, b| a.points[0].freq_hz.total_cmp(&b.points[0].freq_hz));
        branches
    }
}

/// One branch solved inside a stretch no branch reached ([`Branching::bridge`]): its points
/// from its lowest up, the cuts of its way down and of its way up ([`fill_cut`]), and what the
/// continuation met on the two ways: turning points (Hz), rejected steps and leaps (each as
/// (last point before, first point after) in the way's own direction of travel, Hz).
struct BridgeBranch {
    points: Vec<FrfPoint>,
    cuts: [Option<GivenUp>; 2],
    turning_points: Vec<f64>,
    rejected_steps: usize,
    leaps: Vec<(f64, f64)>,
    /// The indices in `points` of each leap's point before and landing, in the order of
    /// `leaps`.
    leap_points: Vec<Option<(usize, usize)>>,
}

/// The (point before, landing) indices of the leaps of a path of `len` points, whose landings
/// are the path's points `landings` ([`PathSummary::leap_landings`]), in a report that lists
/// the path in reverse: path point k at `len − 1 − k` (the path's first point last; where the
/// report leaves that point out, the index `len − 1` is the point reported right after).
fn reversed_leaps(landings: &[usize], len: usize) -> Vec<Option<(usize, usize)>> {
    landings
        .iter()
        .map(|&l| Some((len.checked_sub(l)?, len.checked_sub(l + 1)?)))
        .collect()
}

/// The (point before, landing) indices of the leaps of a path whose landings are its points
/// `landings`, in a report that lists the path in order from its point `first` at index
/// `offset` (the points before `first` left out).
fn forward_leaps(landings: &[usize], first: usize, offset: usize) -> Vec<Option<(usize, usize)>> {
    landings
        .iter()
        .map(|&l| {
            Some((
                (l.checked_sub(1)? + offset).checked_sub(first)?,
                (l + offset).checked_sub(first)?,
            ))
        })
        .collect()
}

/// A converged point strictly between `lo` and `hi` (Hz and operator unknowns), by Newton at
/// fixed frequency from blends of their coefficients (see [`Branching::bridge`]).
fn solve_between(
    system: &mut HbmOperator<'_>,
    solver: &Continuation,
    lo: &FrfPoint,
    hi: &FrfPoint,
) -> Option<(f64, Vec<f64>)> {
    for fraction in BRIDGE_FRACTIONS {
        let freq_hz = lo.freq_hz + fraction * (hi.freq_hz - lo.freq_hz);
        let omega = 2.0 * PI * freq_hz;
        for w in BRIDGE_BLENDS {
            let blend: Vec<f64> = lo
                .coefficients
                .iter()
                .zip(&hi.coefficients)
                .map(|(a, b)| (1.0 - w) * a + w * b)
                .collect();
            let guess = system.restrict(&blend);
            if let Ok(p) = solver.solve_fixed(system, &guess, omega) {
                return Some((freq_hz, p.x));
            }
        }
    }
    None
}

/// The starting guess at ω0 (rad/s): the stuck linear solution, or where Newton does not
/// converge from it (a low pre-load: the contacts open for most of the period) the solution
/// converged from the open-contact guess ([`linear::open_guess`]), else from either on the
/// static state with the contacts ([`contact_statics`]), else the end of a short
/// continuation onto ω0 from a point solved a little off it ([`START_OFFSETS`]). When none converges the
/// stuck guess is returned and the run reports its failure at the start.
fn start_guess(
    problem: &Problem,
    set: &HarmonicSet,
    system: &mut HbmOperator<'_>,
    x_scale: &[f64],
    omega0: f64,
) -> Result<Vec<f64>, FrfError> {
    let stuck = system.restrict(&linear::stuck_guess(problem, set, omega0)?);
    let newton = Continuation::new(problem.analysis.continuation, x_scale.to_vec());
    if newton.solve_fixed(system, &stuck, omega0).is_ok() {
        return Ok(stuck);
    }
    let open = system.restrict(&linear::open_guess(problem, set, omega0)?);
    if let Ok(p) = newton.solve_fixed(system, &open, omega0) {
        return Ok(p.x);
    }
    // Contacts open at rest (gaps the pre-load must close): the linear guesses leave the
    // damper where it hangs free. Solve the statics with the contacts first, then the linear
    // harmonics on that static state.
    if let Some(statics) = contact_statics(problem, set)? {
        for dynamic in [
            linear::stuck_guess(problem, set, omega0)?,
            linear::open_guess(problem, set, omega0)?,
        ] {
            let n = problem.model.n_dofs();
            let mut guess = dynamic;
            if let Some(j) = set.constant_block() {
                guess[j * n..(j + 1) * n].copy_from_slice(&statics);
            }
            let guess = system.restrict(&guess);
            if let Ok(p) = newton.solve_fixed(system, &guess, omega0) {
                return Ok(p.x);
            }
        }
    }
    // On (or next to) a resonance of the stuck structure the stuck guess is near-singular:
    // start a little off it, where the guess is sound, and follow the path onto ω0 (from
    // below, then from above).
    for offset in START_OFFSETS {
        for sign in [-1.0, 1.0] {
            let f0 = omega0 / (2.0 * PI);
            let from_hz = f0 * (1.0 + sign * offset);
            let near = system.restrict(&linear::stuck_guess(problem, set, 2.0 * PI * from_hz)?);
            let settings = ContinuationSettings {
                freq_start_hz: from_hz,
                freq_end_hz: f0,
                max_points: START_APPROACH_POINTS,
                ..problem.analysis.continuation
            };
            let mut approach = Continuation::new(settings, x_scale.to_vec());
            if let Ok(summary) = approach.run(system, &near, &mut NoObserver) {
                if summary.end == PathEnd::EndFrequency {
                    if let Some(p) = summary.points.last() {
                        return Ok(p.x.clone());
                    }
                }
            }
        }
    }
    Ok(stuck)
}

/// The static state with the contacts (m), when the unknowns include the 0th harmonic: the
/// harmonic balance of the 0th harmonic alone (normal springs with lift-off, and the
/// tangential force m μ N of each contact's initial state, since nothing moves), solved by
/// Newton from the sliding static state ([`linear::sliding_static`]), else from the stuck
/// static guess. None when neither converges.
fn contact_statics(problem: &Problem, set: &HarmonicSet) -> Result<Option<Vec<f64>>, FrfError> {
    if !set.has_constant() {
        return Ok(None);
    }
    let mut statics = problem.clone();
    statics.harmonics = Vec::new();
    let static_set = HarmonicSet::new(vec![0]);
    let mut system = HbmOperator::new(&statics)?;
    let mut guesses = Vec::new();
    if let Ok(q) = linear::sliding_static(&statics) {
        guesses.push(system.restrict(&q));
    }
    guesses.push(system.restrict(&linear::stuck_guess(&statics, &static_set, 0.0)?));
    let scale = vec![1.0; guesses[0].len()];
    let newton = Continuation::new(statics.analysis.continuation, scale);
    let omega = 2.0 * PI * statics.analysis.continuation.freq_start_hz;
    for guess in guesses {
        if let Ok(p) = newton.solve_fixed(&mut system, &guess, omega) {
            return Ok(Some(system.expand(&p.x, omega)?));
        }
    }
    Ok(None)
}

/// Relative frequency offsets at which a start on a resonance of the stuck structure is first
/// solved (see [`start_guess`]).
const START_OFFSETS: &[f64] = &[1e-2, 5e-2];
/// Point budget of the approach onto the start frequency (see [`start_guess`]).
const START_APPROACH_POINTS: usize = 200;

/// A converged point just past `highest` (Hz) on whatever branch Newton finds there, for the
/// path to go on from after a fold it did not come back from: at each of [`JUMP_FRACTIONS`] of
/// the range past `highest` (capped at the end frequency), from the stuck linear guess there,
/// the open-contact one (harmonics of the open structure on the stuck static state), then from
/// the highest point solved so far. Returns the frequency and the operator's
/// unknowns, or None when no guess converges.
fn jump_target(
    problem: &Problem,
    set: &HarmonicSet,
    system: &mut HbmOperator<'_>,
    continuation: &Continuation,
    points: &[FrfPoint],
    highest: f64,
) -> Result<Option<(f64, Vec<f64>)>, FrfError> {
    let settings = &problem.analysis.continuation;
    let range = settings.freq_end_hz - settings.freq_start_hz;
    let top = points.iter().find(|p| p.freq_hz == highest);
    for fraction in JUMP_FRACTIONS {
        let freq_hz = (highest + fraction * range).min(settings.freq_end_hz);
        if freq_hz <= highest {
            return Ok(None);
        }
        let omega = 2.0 * PI * freq_hz;
        let mut guesses = vec![
            system.restrict(&linear::stuck_guess(problem, set, omega)?),
            system.restrict(&linear::open_guess(problem, set, omega)?),
        ];
        if let Some(p) = top {
            guesses.push(system.restrict(&p.coefficients));
        }
        for g in guesses {
            if let Ok(p) = continuation.solve_fixed(system, &g, omega) {
                return Ok(Some((freq_hz, p.x)));
            }
        }
    }
    Ok(None)
}

/// Solves single points of a problem at fixed frequencies (Newton from a given guess), reusing
/// one harmonic-balance operator. Used to put curves on a common grid and to refine peaks.
pub struct PointSolver<'p> {
    system: HbmOperator<'p>,
    continuation: Continuation,
}

impl<'p> PointSolver<'p> {
    /// A solver for `problem`.
    pub fn new(problem: &'p Problem) -> Result<Self, FrfError> {
        let system = HbmOperator::new(problem)?;
        let set = system.unknowns().clone();
        let continuation = Continuation::new(
            problem.analysis.continuation,
            arc_length_x_scale(problem, &set, &system)?,
        );
        Ok(Self {
            system,
            continuation,
        })
    }

    /// The full operator (for contact time histories after a solve).
    pub fn system(&mut self) -> &mut HbmSystem<'p> {
        self.system.full()
    }

    /// Solves at `freq_hz` from the full-coefficient guess `x0`.
    pub fn solve(&mut self, x0: &[f64], freq_hz: f64) -> Result<FrfPoint, NewtonFailure> {
        let guess = self.system.restrict(x0);
        let p = self
            .continuation
            .solve_fixed(&mut self.system, &guess, 2.0 * PI * freq_hz)?;
        let mut point = full_point(&mut self.system, &p)
            .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
        point.freq_hz = freq_hz;
        Ok(point)
    }

    /// The other side of a fold at `b`, as the judgement of a dead end seeks it from the point
    /// `a` before it on the stretch into it (see `judge_round_dead_end`): None where no landing
    /// behind `b` converges.
    pub fn solve_round_fold(&mut self, a: &FrfPoint, b: &FrfPoint) -> Option<FrfPoint> {
        land_round_fold(&mut self.system, self.continuation.settings, a, b)
    }

    /// Solves the path point on the hyperplane through `a + t (b − a)` normal to the chord
    /// from `a` to `b` (two nearby points of a path; t ∈ [0, 1] moves along the chord), in the
    /// continuation's scaled space. Unlike [`Self::solve`] it does not fix the frequency, so it
    /// stays on the branch of the chord at folds (turning points) of the path.
    pub fn solve_on_chord(
        &mut self,
        a: &FrfPoint,
        b: &FrfPoint,
        t: f64,
    ) -> Result<FrfPoint, NewtonFailure> {
        let scale = self.continuation.x_scale.clone();
        let system = &self.system;
        let scaled = |p: &FrfPoint| -> Vec<f64> {
            system
                .restrict(&p.coefficients)
                .iter()
                .zip(&scale)
                .map(|(v, s)| v / s)
                .chain(std::iter::once(p.freq_hz))
                .collect()
        };
        let (ya, yb) = (scaled(a), scaled(b));
        let mut chord: Vec<f64> = ya.iter().zip(&yb).map(|(p, q)| q - p).collect();
        let length = crate::numerics::linalg::norm(&chord);
        if length == 0.0 {
            return self.solve(&a.coefficients, a.freq_hz);
        }
        chord.iter_mut().for_each(|v| *v /= length);
        let predicted: Vec<f64> = ya.iter().zip(&yb).map(|(p, q)| p + t * (q - p)).collect();
        correct_on_hyperplane(&mut self.system, &self.continuation, &predicted, &chord)
    }
}

/// The first path segment bracketing `freq_hz`: its lower and upper end (by frequency) and
/// the fraction t ∈ [0, 1] of the way from the lower one (0 on a segment of zero width).
pub fn bracket_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<(&FrfPoint, &FrfPoint, f64)> {
    points.windows(2).find_map(|w| {
        let (lo, hi) = if w[0].freq_hz <= w[1].freq_hz {
            (&w[0], &w[1])
        } else {
            (&w[1], &w[0])
        };
        if freq_hz < lo.freq_hz || freq_hz > hi.freq_hz {
            return None;
        }
        let span = hi.freq_hz - lo.freq_hz;
        let t = if span > 0.0 {
            (freq_hz - lo.freq_hz) / span
        } else {
            0.0
        };
        Some((lo, hi, t))
    })
}

/// The linearly interpolated coefficients on the first path segment bracketing `freq_hz`.
pub fn interpolate_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<Vec<f64>> {
    let (lo, hi, t) = bracket_on_path(points, freq_hz)?;
    Some(
        lo.coefficients
            .iter()
            .zip(&hi.coefficients)
            .map(|(p, q)| p + t * (q - p))
            .collect(),
    )
}

/// The first output's first-harmonic amplitude (m), linear on the first path segment
/// bracketing `freq_hz`.
pub fn amplitude_on_path(points: &[FrfPoint], freq_hz: f64) -> Option<f64> {
    let (lo, hi, t) = bracket_on_path(points, freq_hz)?;
    Some(lo.amplitudes[0] + t * (hi.amplitudes[0] - lo.amplitudes[0]))
}

/// The first-harmonic amplitude of output `output` (index into the problem's outputs) on a
/// reference path where it crosses the hyperplane through `point` normal to `point`'s own path,
/// and the frequency there (Hz): the reference's counterpart of the point at the same place
/// along the path, against which a bordered error estimate (see
/// [`crate::analysis::error_estimate`]) is compared. `normal` is the hyperplane as
/// [`PointAccuracy::path_normal`] holds it (a covector on `point`'s full coefficients on
/// `set`, then on ω in rad/s); the reference's coefficients on `reference_set` enter on the
/// blocks of `set` (the hyperplane does not see the others). Each segment of the reference
/// within a branch (not across a jump) whose ends lie on either side is a crossing,
/// interpolated linearly; the one nearest the point in relative frequency and amplitude is
/// returned. None when the reference does not cross the hyperplane.
pub fn amplitude_across_path(
    reference: &FrfRun,
    reference_set: &HarmonicSet,
    point: &FrfPoint,
    set: &HarmonicSet,
    normal: &[f64],
    output: usize,
) -> Option<(f64, f64)> {
    let blocks = set.n_blocks();
    let n = point.coefficients.len() / blocks.max(1);
    if normal.len() != n * blocks + 1 {
        return None;
    }
    let block_in_reference: Vec<Option<usize>> = set
        .blocks()
        .iter()
        .map(|b| reference_set.blocks().iter().position(|c| c == b))
        .collect();
    let side = |q: &FrfPoint| -> f64 {
        let mut g = normal[n * blocks] * 2.0 * PI * (q.freq_hz - point.freq_hz);
        for (j, jr) in block_in_reference.iter().enumerate() {
            for i in 0..n {
                let on_reference = jr.map_or(0.0, |jr| q.coefficients[jr * n + i]);
                g += normal[j * n + i] * (on_reference - point.coefficients[j * n + i]);
            }
        }
        g
    };
    let sides: Vec<f64> = reference.points.iter().map(side).collect();
    let starts = reference.branch_starts();
    let a0 = point.amplitudes[output];
    let mut best: Option<(f64, (f64, f64))> = None;
    for k in 0..reference.points.len().saturating_sub(1) {
        let (ga, gb) = (sides[k], sides[k + 1]);
        if starts.contains(&(k + 1)) || ga * gb > 0.0 || (ga == 0.0 && gb == 0.0) {
            continue;
        }
        let t = ga / (ga - gb);
        let (p, q) = (&reference.points[k], &reference.points[k + 1]);
        let freq_hz = p.freq_hz + t * (q.freq_hz - p.freq_hz);
        let amplitude = p.amplitudes[output] + t * (q.amplitudes[output] - p.amplitudes[output]);
        let distance =
            ((freq_hz - point.freq_hz) / point.freq_hz).powi(2) + ((amplitude - a0) / a0).powi(2);
        if best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, (amplitude, freq_hz)));
        }
    }
    best.map(|(_, found)| found)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A judgement that covers its cut or point: Newton landed at `freq_hz` (Hz) with the first
    /// output's amplitude `amplitude` (m), `distance` from the nearest stretch and
    /// `resolved_distance` from Newton's solution from it, in `newton_iterations`.
    fn covered_check(
        freq_hz: f64,
        amplitude: f64,
        distance: f64,
        resolved_distance: f64,
        newton_iterations: usize,
    ) -> CutCheck {
        CutCheck {
            landing: Landing {
                freq_hz,
                amplitude: Some(amplitude),
                distance: Some(distance),
                resolved_distance: Some(resolved_distance),
            },
            own_side: false,
            newton_iterations,
            beyond_fold: None,
            verdict: CutVerdict::Covered,
        }
    }

    /// A leap's recorded landing placed in the report: a path reported in order from its
    /// point `first` at `offset`, or in reverse (its first point last, or left out with the
    /// point reported after the path in its place); a point before that the report does not
    /// hold gives none.
    #[test]
    fn leap_landings_are_placed_where_the_report_puts_the_path() {
        // The main path at offset 10: landing 1 and 3 (before 0 and 2).
        assert_eq!(
            forward_leaps(&[1, 3], 0, 10),
            vec![Some((10, 11)), Some((12, 13))]
        );
        // A bridge's way up after its way down of 4 points, its first point (the way down's
        // first) not repeated: path point k at 4 − 1 + k.
        assert_eq!(
            forward_leaps(&[1, 3], 1, 4),
            vec![Some((3, 4)), Some((5, 6))]
        );
        // A way up with no way down before it: the point before its first leap is not there.
        assert_eq!(forward_leaps(&[1, 2], 1, 0), vec![None, Some((0, 1))]);
        // A path of 5 points in reverse: path point k at 4 − k.
        assert_eq!(reversed_leaps(&[1, 3], 5), vec![Some((4, 3)), Some((2, 1))]);
    }

    fn run_with_jumps(jumps: Vec<Jump>) -> FrfRun {
        FrfRun {
            points: Vec::new(),
            turning_points: Vec::new(),
            rejected_steps: 0,
            leaps: Vec::new(),
            leap_points: Vec::new(),
            leap_checks: Vec::new(),
            jumps,
            end: PathEnd::EndFrequency,
            elapsed_s: 0.0,
        }
    }

    fn line_point(freq_hz: f64, c1: f64, c3: f64) -> FrfPoint {
        FrfPoint {
            freq_hz,
            amplitudes: vec![c1.abs()],
            peaks: vec![0.0],
            states: Vec::new(),
            newton_iterations: 1,
            residual: 0.0,
            coefficients: vec![c1, 0.0, c3, 0.0],
            accuracy: None,
            pending_estimate: None,
            stability: None,
        }
    }

    /// The reference path c₁ = 1 + (f − 100) (one DOF, harmonics 1 and 3) crosses the
    /// hyperplane through (100.5 Hz, c₁ = 1.3) normal to the direction (1 Hz, 1) at 100.4 Hz,
    /// c₁ = 1.4 (the 3rd harmonic, which the point's set lacks, does not enter); the segment
    /// across a jump to another branch, which crosses it too, is not a crossing.
    #[test]
    fn the_reference_is_read_where_it_crosses_the_hyperplane_normal_to_the_path() {
        let mut points: Vec<FrfPoint> = (0..=10)
            .map(|k| {
                let f = 100.0 + 0.1 * k as f64;
                line_point(f, 1.0 + (f - 100.0), 7.0)
            })
            .collect();
        // The far branch: c1 = −5 at 99 Hz and 97 Hz, on one side of the hyperplane; the
        // jump's segment from (101 Hz, 2) to (99 Hz, −5) crosses it.
        points.push(line_point(99.0, -5.0, 0.0));
        points.push(line_point(97.0, -5.0, 0.0));
        let mut reference = run_with_jumps(vec![Jump {
            from_hz: 101.0,
            to_hz: 97.0,
            first_point: 11,
            kind: JumpKind::PastFold,
            before: BranchEnd::LeftRange,
            fill_cut: None,
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        reference.points = points;
        let point = FrfPoint {
            coefficients: vec![1.3, 0.0],
            ..line_point(100.5, 1.3, 0.0)
        };
        let set = HarmonicSet::new(vec![1]);
        let reference_set = HarmonicSet::new(vec![1, 3]);
        // Unit weight per Hz of frequency (ω in rad/s) and per unit of c1.
        let normal = [1.0, 0.0, 1.0 / (2.0 * PI)];
        let (amplitude, freq_hz) =
            amplitude_across_path(&reference, &reference_set, &point, &set, &normal, 0).unwrap();
        assert!((amplitude - 1.4).abs() < 1e-12, "{amplitude}");
        assert!((freq_hz - 100.4).abs() < 1e-12, "{freq_hz}");
        // Without the line but its last point, only the jump's segment crosses: none.
        reference.points.drain(..10);
        reference.jumps[0].first_point = 1;
        assert_eq!(
            amplitude_across_path(&reference, &reference_set, &point, &set, &normal, 0),
            None
        );
    }

    /// A path that reached the end frequency but jumped over a stretch at a fold that no branch
    /// reached does not cover the range; one whose jumps left nothing uncovered (or only the
    /// round-off of a branch followed onto an end frequency) does.
    #[test]
    fn an_uncovered_stretch_makes_the_run_incomplete() {
        let jump = |from_hz: f64, to_hz: f64| Jump {
            from_hz,
            to_hz,
            first_point: 0,
            kind: JumpKind::PastFold,
            before: BranchEnd::LeftRange,
            fill_cut: None,
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        };
        assert!(run_with_jumps(vec![jump(66.0, 66.0)]).is_complete());
        assert!(run_with_jumps(vec![jump(66.0, 66.0 + 1e-12)]).is_complete());
        let gap = run_with_jumps(vec![jump(66.0, 66.0), jump(151.84, 152.14)]);
        assert!(!gap.is_complete());
        let reason = gap.incomplete_reason().unwrap();
        assert!(reason.contains("151.8400-152.1400 Hz"), "{reason}");
    }

    /// The synthetic path of a branch rising along A = 1 + 0.1 (f − 100) from 100 to 110 Hz
    /// (one point per Hz), then turned back at the fold at 110 Hz onto `back`: (Hz, amplitude)
    /// points followed down.
    fn folded_path(back: &[(f64, f64)]) -> Vec<FrfPoint> {
        (0..=10)
            .map(|k| {
                let f = 100.0 + k as f64;
                line_point(f, 1.0 + 0.1 * (f - 100.0), 0.0)
            })
            .chain(back.iter().map(|&(f, a)| line_point(f, a, 0.0)))
            .collect()
    }

    /// A branch given up by a dead end on the middle branch past a fold, its amplitude rising
    /// away from the upper branch it turned back from, is abandoned: the jump records where
    /// (last point, first output's amplitude, the fold) and why, and the run that went on to the
    /// end frequency past it is incomplete, saying so; its JSON record says `abandoned`.
    #[test]
    fn a_branch_abandoned_past_a_fold_makes_the_run_incomplete() {
        let points = folded_path(&[(109.5, 2.5), (109.0, 3.0)]);
        let end = branch_end(&points, &[], 0, Some(110.0), PathEnd::DeadEnd, &[], 0.0);
        let BranchEnd::Abandoned(given_up) = end else {
            panic!("{end:?}");
        };
        assert_eq!(given_up.freq_hz, 109.0);
        assert_eq!(given_up.amplitude, 3.0);
        assert!(given_up.amplitude_rising);
        assert_eq!(given_up.fold_hz, Some(110.0));
        assert_eq!(given_up.cause, GiveUpCause::DeadEnd);
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 110.0,
            to_hz: 110.0,
            first_point: points.len(),
            kind: JumpKind::PastDeadEnd,
            before: end,
            fill_cut: None,
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        run.points = points;
        assert!(!run.is_complete());
        let reason = run.incomplete_reason().unwrap();
        for words in [
            "abandoned at 109.0000 Hz",
            "amplitude 3.000e0 m, rising",
            "below the fold at 110.0000 Hz",
            "dead end",
            "possibly the resonance peak",
            "past 110.0000 Hz",
        ] {
            assert!(reason.contains(words), "{words:?} not in {reason}");
        }
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], true);
        assert_eq!(json["before"]["how"], "abandoned");
        assert_eq!(json["before"]["freq_hz"], 109.0);
        assert_eq!(json["before"]["cause"], "dead-end");
        // An uncovered stretch is reported with it.
        run.jumps[0].to_hz = 111.0;
        let reason = run.incomplete_reason().unwrap();
        assert!(reason.contains("110.0000-111.0000 Hz") && reason.contains("abandoned at"));
        run.jumps[0].to_hz = 110.0;
        // Judged once the run is over (`end_check`): Newton past the point landing on a
        // stretch of the run covers it, the run is complete; landing off the run, or nowhere,
        // it stays abandoned and the reason says where Newton landed.
        let covered = covered_check(108.9, 3.1, 1e-4, 1e-12, 2);
        run.jumps[0].end_check = Some(covered);
        assert!(!run.jumps[0].abandons_branch());
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], false);
        assert_eq!(json["end_check"]["verdict"], "covered");
        for verdict in [CutVerdict::Abandoned, CutVerdict::Unjudged] {
            run.jumps[0].end_check = Some(CutCheck {
                landing: Landing {
                    distance: Some(3e-2),
                    resolved_distance: None,
                    ..covered.landing
                },
                verdict,
                ..covered
            });
            assert!(run.jumps[0].abandons_branch());
            let reason = run.incomplete_reason().unwrap();
            assert!(
                reason.contains("abandoned at 109.0000 Hz")
                    && reason.contains("Newton just past the point given up"),
                "{reason}"
            );
        }
    }

    /// A branch given up where it was retracing the stretch already followed (the points
    /// after the fold lie back on the rising branch, within 1 % of its amplitude) abandoned
    /// nothing: the run stays complete. Just outside the tolerance it is abandoned.
    #[test]
    fn a_branch_given_up_on_a_stretch_already_followed_is_a_retrace() {
        for cause in [PathEnd::DeadEnd, PathEnd::NoProgress] {
            let on_line = |f: f64| 1.0 + 0.1 * (f - 100.0);
            let points = folded_path(&[(109.5, on_line(109.5)), (108.5, on_line(108.5) * 1.009)]);
            let end = branch_end(&points, &[], 0, Some(110.0), cause, &[], 0.0);
            assert!(matches!(end, BranchEnd::Retrace(_)), "{end:?}");
            let mut run = run_with_jumps(vec![Jump {
                from_hz: 110.0,
                to_hz: 110.0,
                first_point: points.len(),
                kind: JumpKind::PastFold,
                before: end,
                fill_cut: None,
                cut_check: None,
                second_cut: None,
                second_cut_check: None,
                end_check: None,
            }]);
            run.points = points;
            assert!(run.is_complete(), "{:?}", run.incomplete_reason());
            assert!(!run.jumps[0].abandons_branch());

            let off = folded_path(&[(109.5, on_line(109.5)), (108.5, on_line(108.5) * 1.011)]);
            let end = branch_end(&off, &[], 0, Some(110.0), cause, &[], 0.0);
            assert!(matches!(end, BranchEnd::Abandoned(_)), "{end:?}");
        }
    }

    /// The stretch followed on another branch counts too, but not a segment across a jump; a
    /// branch given up while still rising (no fold) is abandoned with no fold named, one that
    /// left the range below the start abandoned nothing.
    #[test]
    fn retraces_are_sought_within_branches_and_a_left_range_abandons_nothing() {
        // Branch 1: 100..110 Hz on the line; branch 2 (from index 11): 112 Hz down to
        // 105 Hz on a line with amplitude 5, then up again to 106 Hz at the first line's
        // amplitude: the segment across the jump (110 Hz, 2) to (112 Hz, 5) does not count.
        // How branch 2, given up at its last point after the fold at 105 Hz, ended.
        let end_of_branch_2 = |points: &[FrfPoint]| {
            branch_end(
                points,
                &[11],
                11,
                Some(105.0),
                PathEnd::NoProgress,
                &[],
                0.0,
            )
        };
        let mut points = folded_path(&[]);
        points.push(line_point(112.0, 5.0, 0.0));
        points.push(line_point(105.0, 5.0, 0.0));
        points.push(line_point(106.0, 1.6, 0.0));
        let end = end_of_branch_2(&points);
        let BranchEnd::Retrace(g) = end else {
            panic!("{end:?}")
        };
        assert_eq!(g.cause, GiveUpCause::NoProgress);
        assert!(g.describe().contains("above the fold at 105.0000 Hz"));
        // At 111 Hz only the segment across the jump, (110 Hz, 2) to (112 Hz, 5), passes
        // through the point's amplitude 3.5: not a stretch followed.
        points.pop();
        points.push(line_point(111.0, 3.5, 0.0));
        let end = end_of_branch_2(&points);
        assert!(matches!(end, BranchEnd::Abandoned(_)), "{end:?}");

        let rising = folded_path(&[]);
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[], 0.0);
        let BranchEnd::Abandoned(g) = end else {
            panic!("{end:?}")
        };
        assert_eq!((g.freq_hz, g.fold_hz), (110.0, None));
        assert!(!g.describe().contains("fold"));
        // A branch solved past it (here a fill from 109 to 111 Hz) passing through the point
        // within the tolerance: the branch goes on there, nothing was abandoned.
        let fill = [line_point(109.0, 1.9, 0.0), line_point(111.0, 2.1, 0.0)];
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[&fill], 0.0);
        assert!(matches!(end, BranchEnd::Retrace(_)), "{end:?}");
        let fill = [line_point(109.0, 1.9, 0.0), line_point(111.0, 2.2, 0.0)];
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[&fill], 0.0);
        assert!(matches!(end, BranchEnd::Abandoned(_)), "{end:?}");
        // Given up below the start frequency: outside the range, nothing in it abandoned.
        let end = branch_end(&rising, &[], 0, None, PathEnd::DeadEnd, &[], 110.5);
        assert!(matches!(end, BranchEnd::OutsideRange(_)), "{end:?}");
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 110.0,
            to_hz: 110.0,
            first_point: rising.len(),
            kind: JumpKind::PastDeadEnd,
            before: end,
            fill_cut: None,
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        run.points = rising.clone();
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        assert_eq!(
            branch_end(
                &rising,
                &[],
                0,
                Some(110.0),
                PathEnd::LeftRangeBelow,
                &[],
                0.0
            ),
            BranchEnd::LeftRange
        );
    }

    /// The fill of the branch past a jump, followed from 115 Hz down toward 110 Hz (the highest
    /// frequency of the branch before, on A = 1 + 0.1 (f − 100)), turns back up at a fold of its
    /// own at 109.5 Hz and stops on reaching 110 Hz at amplitude 3.5, off the branch before: cut
    /// (recorded in the jump, not in the status). Heading down at its end, or ending on the
    /// branch before, it is not.
    #[test]
    fn a_fill_that_turned_back_up_off_the_path_followed_is_cut() {
        let points = folded_path(&[]);
        let fill = [
            line_point(115.0, 3.0, 0.0),
            line_point(112.0, 3.3, 0.0),
            line_point(109.5, 3.6, 0.0),
            line_point(110.0, 3.5, 0.0),
        ];
        let cut = fill_cut(
            &points,
            &[],
            &fill,
            true,
            PathEnd::EndFrequency,
            Some(109.5),
        )
        .unwrap();
        assert_eq!((cut.freq_hz, cut.amplitude), (110.0, 3.5));
        assert!(!cut.amplitude_rising);
        assert_eq!(cut.cause, GiveUpCause::FillEnd);
        assert!(cut.describe().contains("above the fold at 109.5000 Hz"));
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 110.0,
            to_hz: 109.5,
            first_point: points.len(),
            kind: JumpKind::PastFold,
            before: BranchEnd::LeftRange,
            fill_cut: Some(cut),
            cut_check: None,
            second_cut: None,
            second_cut_check: None,
            end_check: None,
        }]);
        run.points = points.clone();
        // Not judged yet (a jump as reported during the run): not counted in the status.
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], false);
        assert_eq!(json["fill_cut"]["freq_hz"], 110.0);
        assert_eq!(json["fill_cut"]["cause"], "fill-end");
        assert!(json["cut_check"].is_null());
        // Judged covered: still complete; judged abandoned or unjudged: incomplete, and the
        // status says where and what Newton found.
        let check = covered_check(110.01, 3.6, 2e-3, 1e-9, 3);
        run.jumps[0].cut_check = Some(check);
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        assert!(!run.jumps[0].abandons_branch());
        run.jumps[0].cut_check = Some(CutCheck {
            landing: Landing {
                distance: Some(0.4),
                resolved_distance: None,
                ..check.landing
            },
            verdict: CutVerdict::Abandoned,
            ..check
        });
        let reason = run.incomplete_reason().unwrap();
        assert!(
            reason.contains("was left at 110.0000 Hz")
                && reason.contains("at 110.0100 Hz, lands at 3.600e0 m")
                && reason.contains("40.00 %")
                && reason.contains("was not computed"),
            "{reason}"
        );
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["abandoned"], false);
        assert_eq!(json["cut_check"]["verdict"], "abandoned");
        assert_eq!(json["cut_check"]["freq_hz"], 110.01);
        run.jumps[0].cut_check = Some(CutCheck {
            landing: Landing {
                amplitude: None,
                distance: None,
                ..check.landing
            },
            newton_iterations: 0,
            verdict: CutVerdict::Unjudged,
            ..check
        });
        let reason = run.incomplete_reason().unwrap();
        assert!(
            reason.contains("converged at none") && reason.contains("may be missing"),
            "{reason}"
        );
        // Heading down at its end: the fill reached the fold's frequency from above.
        assert_eq!(
            fill_cut(&points, &[], &fill[..3], true, PathEnd::EndFrequency, None),
            None
        );
        // Back on the branch before (A = 2 at 110 Hz): nothing cut.
        let mut onto = fill.clone();
        onto[3] = line_point(110.0, 2.0, 0.0);
        assert_eq!(
            fill_cut(
                &points,
                &[],
                &onto,
                true,
                PathEnd::EndFrequency,
                Some(109.5)
            ),
            None
        );
        // A bridge's way up that turned back down at a fold of its own before its edge.
        let up = [
            line_point(104.0, 3.0, 0.0),
            line_point(106.0, 3.2, 0.0),
            line_point(105.5, 3.3, 0.0),
        ];
        let cut = fill_cut(&points, &[], &up, false, PathEnd::EndFrequency, Some(106.0));
        assert!(cut.is_some_and(|g| g.freq_hz == 105.5 && g.amplitude_rising));
        assert_eq!(
            fill_cut(&points, &[], &up[..2], false, PathEnd::EndFrequency, None),
            None
        );
        // Left the range: not a cut.
        assert_eq!(
            fill_cut(
                &points,
                &[],
                &fill,
                true,
                PathEnd::LeftRangeBelow,
                Some(109.5)
            ),
            None
        );
        // Given up before its edge (a dead end, no progress), heading either way and off the
        // path followed: a cut, with its cause.
        for (end, cause) in [
            (PathEnd::DeadEnd, GiveUpCause::DeadEnd),
            (PathEnd::NoProgress, GiveUpCause::NoProgress),
        ] {
            for side in [&fill[..3], &fill[..]] {
                let cut = fill_cut(&points, &[], side, true, end, None).unwrap();
                assert_eq!(cut.cause, cause);
                assert_eq!(cut.freq_hz, side[side.len() - 1].freq_hz);
            }
            assert_eq!(fill_cut(&points, &[], &onto, true, end, None), None);
        }
    }

    /// A fill or bridge that used up its point budget before the edge of its stretch, heading
    /// either way and off the path followed, leaves its branch unfollowed beyond its last
    /// point: a cut (`point-budget`), judged like the others; the status names the cause. On
    /// the path followed, nothing is cut.
    #[test]
    fn a_fill_or_bridge_out_of_points_is_cut() {
        let points = folded_path(&[]);
        // A fill from 115 Hz heading down toward 110 Hz, stopped at 112 Hz; a bridge's way up
        // stopped at 106 Hz.
        let down = [line_point(115.0, 3.0, 0.0), line_point(112.0, 3.3, 0.0)];
        let up = [line_point(104.0, 3.0, 0.0), line_point(106.0, 3.2, 0.0)];
        for (side, travel_down) in [(&down[..], true), (&up[..], false)] {
            let cut = fill_cut(&points, &[], side, travel_down, PathEnd::MaxPoints, None)
                .expect("a stretch out of points off the path is cut");
            assert_eq!(cut.cause, GiveUpCause::PointBudget);
            assert_eq!(cut.freq_hz, side[1].freq_hz);
            assert!(
                cut.describe().contains("point budget"),
                "{}",
                cut.describe()
            );
            let json = serde_json::to_value(cut).unwrap();
            assert_eq!(json["cause"], "point-budget");
        }
        // Stopped on the branch before (A = 1.6 at 106 Hz): nothing left unfollowed.
        let on = [line_point(104.0, 3.0, 0.0), line_point(106.0, 1.6, 0.0)];
        assert_eq!(
            fill_cut(&points, &[], &on, false, PathEnd::MaxPoints, None),
            None
        );
    }

    /// A bridge followed toward both edges of its stretch and left at both (its way down
    /// turned back up at a fold of its own, its way up was given up by a dead end) keeps both
    /// cuts: `fill_cut` the way down's, `second_cut` the way up's; both are judged, and the
    /// second alone not covered makes the run incomplete, naming it. Its JSON record has both.
    #[test]
    fn a_bridge_cut_on_both_sides_keeps_and_counts_both_cuts() {
        let points = folded_path(&[]);
        let way_down = [
            line_point(107.0, 3.0, 0.0),
            line_point(104.5, 3.3, 0.0),
            line_point(104.8, 3.4, 0.0),
        ];
        let way_up = [line_point(107.0, 3.0, 0.0), line_point(108.5, 3.1, 0.0)];
        let cuts = [
            fill_cut(
                &points,
                &[],
                &way_down,
                true,
                PathEnd::EndFrequency,
                Some(104.5),
            ),
            fill_cut(&points, &[], &way_up, false, PathEnd::DeadEnd, None),
        ];
        let (cut, second_cut) = bridge_cuts(cuts);
        let (cut, second_cut) = (cut.unwrap(), second_cut.unwrap());
        assert_eq!((cut.freq_hz, cut.cause), (104.8, GiveUpCause::FillEnd));
        assert_eq!(
            (second_cut.freq_hz, second_cut.cause),
            (108.5, GiveUpCause::DeadEnd)
        );
        // One way cut: it is the jump's `fill_cut`, whichever way.
        assert_eq!(bridge_cuts([None, cuts[1]]), (cuts[1], None));
        assert_eq!(bridge_cuts([cuts[0], None]), (cuts[0], None));
        let covered = covered_check(104.9, 3.41, 1e-4, 1e-12, 2);
        let abandoned = CutCheck {
            landing: Landing {
                amplitude: Some(3.11),
                ..Landing::nowhere(108.6)
            },
            verdict: CutVerdict::Abandoned,
            ..covered
        };
        let mut run = run_with_jumps(vec![Jump {
            from_hz: 104.0,
            to_hz: 104.0,
            first_point: points.len(),
            kind: JumpKind::Bridge,
            before: BranchEnd::Bridge,
            fill_cut: Some(cut),
            cut_check: Some(covered),
            second_cut: Some(second_cut),
            second_cut_check: Some(covered),
            end_check: None,
        }]);
        run.points = points;
        assert!(run.is_complete(), "{:?}", run.incomplete_reason());
        assert_eq!(run.jumps[0].cuts().count(), 2);
        run.jumps[0].second_cut_check = Some(abandoned);
        let reason = run
            .incomplete_reason()
            .expect("the way up's cut is not covered");
        assert!(
            reason.contains("was left at 108.5000 Hz") && !reason.contains("left at 104.8000"),
            "{reason}"
        );
        assert_eq!(
            run.jumps[0].cut_uncovered().map(|(g, _)| g.freq_hz),
            Some(108.5)
        );
        let json = serde_json::to_value(run.jumps[0]).unwrap();
        assert_eq!(json["fill_cut"]["freq_hz"], 104.8);
        assert_eq!(json["cut_check"]["verdict"], "covered");
        assert_eq!(json["cut_check"]["resolved_distance"], 1e-12);
        assert_eq!(json["second_cut"]["freq_hz"], 108.5);
        assert_eq!(json["second_cut_check"]["verdict"], "abandoned");
    }

    /// The paper's system at F0 = 1 N, for [`judge_cut`] at its real folds.
    fn paper_at_1n() -> Problem {
        crate::scene::parse(
            crate::scene::PAPER_DEFAULT_SCENE,
            "paper",
            &["static_loads.0.value=-1".to_string()],
        )
        .and_then(|s| s.validate("paper"))
        .expect("the built-in scene is valid")
    }

    /// At the real folds of the paper's system at F0 = 1 N: a stretch followed into a fold
    /// and one point back out of it, cut there (as a fill or bridge stopping at its edge).
    /// Newton one step past the cut lands on the branch beyond it. Where the other side of the
    /// fold (the cut stretch's own side) crosses that frequency within 1 % of the landing,
    /// linear interpolation cannot tell them apart, but Newton at that frequency from the
    /// other side converges to another solution: the cut is not covered. With the branch
    /// beyond the cut in the run (the points the FRF followed there, as another branch), the
    /// same landing is covered, Newton from that branch converging to it.
    #[test]
    fn a_landing_beyond_a_fold_of_its_own_stretch_is_told_from_the_other_side_by_newton() {
        let problem = paper_at_1n();
        let run = solve(&problem, &mut Silent).unwrap();
        let starts = run.branch_starts();
        let mut system = HbmOperator::new(&problem).unwrap();
        let set = system.unknowns().clone();
        let x_scale = arc_length_x_scale(&problem, &set, &system).unwrap();
        let newton = Continuation::new(problem.analysis.continuation, x_scale);
        let p = &run.points;
        let direction = |k: usize| (p[k + 1].freq_hz - p[k].freq_hz).signum();
        let same_branch = |a: usize, b: usize| !starts.iter().any(|&s| s > a && s <= b);
        let mut told = 0;
        for k in 1..p.len().saturating_sub(2) {
            // A fold at point k: the stretch into it and the one out of it in one branch.
            if !same_branch(k - 1, k + 2) || direction(k - 1) * direction(k) >= 0.0 {
                continue;
            }
            let mut a = k - 1;
            while a > 0 && same_branch(a - 1, k) && direction(a - 1) == direction(k - 1) {
                a -= 1;
            }
            let mut b = k + 1;
            while b + 1 < p.len()
                && same_branch(k, b + 1)
                && direction(b) == direction(k)
                && b < k + 20
            {
                b += 1;
            }
            // The stretch into the fold and one point out: cut at point k + 1.
            let stretch: Vec<FrfPoint> = p[a..=k + 1].to_vec();
            let cut = GivenUp {
                freq_hz: p[k + 1].freq_hz,
                amplitude: p[k + 1].amplitudes[0],
                amplitude_rising: p[k + 1].amplitudes[0] > p[k].amplitudes[0],
                fold_hz: Some(p[k].freq_hz),
                cause: GiveUpCause::FillEnd,
            };
            let alone = judge_cut(&mut system, &newton, &stretch, &[], 0..stretch.len(), &cut);
            let (Some(d), true) = (alone.landing.distance, alone.own_side) else {
                continue;
            };
            if d > RETRACE_TOLERANCE || alone.verdict == CutVerdict::Unjudged {
                continue;
            }
            // The branch beyond the cut, as the run followed it, as another branch.
            let mut with_beyond = stretch.clone();
            with_beyond.extend_from_slice(&p[k + 1..=b]);
            let beyond = judge_cut(
                &mut system,
                &newton,
                &with_beyond,
                &[stretch.len()],
                0..stretch.len(),
                &cut,
            );
            eprintln!(
                "fold at {:.4} Hz, cut at {:.4} Hz: alone {alone:?}; with the branch beyond \
                 {beyond:?}",
                p[k].freq_hz, cut.freq_hz
            );
            assert_eq!(beyond.landing.freq_hz, alone.landing.freq_hz);
            if beyond.verdict != CutVerdict::Covered || beyond.own_side {
                // The run's branch beyond the cut does not cross the landing's frequency.
                continue;
            }
            assert!(beyond.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE);
            // Where Newton from the other side finds the landing itself, the stretch came
            // back along that side (a reversal on one solution curve, a corner of the sampled
            // law): judged beyond the fold instead. Elsewhere the two sides are two solutions.
            if alone.beyond_fold.is_some() {
                assert!(alone.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE);
                continue;
            }
            assert_eq!(alone.verdict, CutVerdict::Abandoned, "{alone:?}");
            let apart = alone
                .landing
                .resolved_distance
                .expect("Newton from the other side");
            assert!(apart > SAME_SOLUTION_TOLERANCE, "{alone:?}");
            let words = alone.describe();
            assert!(words.contains("beyond the fold"), "{words}");
            told += 1;
        }
        assert!(told > 0, "no fold within 1 % told apart by Newton");
    }

    /// A stretch that came back along the side it had followed into its fold (the paper's
    /// system at F0 = 1 N: a monotone stretch of the run above 100 Hz, then its last points
    /// again in reverse, as a fill or bridge reversing on one solution curve), cut there. Newton
    /// past the cut lands on that side, the same solution (covered by interpolation before
    /// Newton was asked); the branch goes on beyond the fold, where the run, without the
    /// points it followed there, has nothing: not covered, the status naming a branch beyond
    /// the fold not followed. With those points in the run (as another branch) it is covered.
    #[test]
    fn a_stretch_back_along_its_own_side_is_judged_beyond_its_fold() {
        let problem = paper_at_1n();
        let run = solve(&problem, &mut Silent).unwrap();
        let starts = run.branch_starts();
        let mut system = HbmOperator::new(&problem).unwrap();
        let set = system.unknowns().clone();
        let x_scale = arc_length_x_scale(&problem, &set, &system).unwrap();
        let newton = Continuation::new(problem.analysis.continuation, x_scale);
        let p = &run.points;
        let direction = |k: usize| (p[k + 1].freq_hz - p[k].freq_hz).signum();
        // Ten points of one branch above 100 Hz, the frequency moving one way throughout.
        let a = (0..p.len().saturating_sub(10))
            .find(|&a| {
                p[a].freq_hz > 100.0
                    && !starts.iter().any(|&s| s > a && s <= a + 9)
                    && (a..a + 9).all(|k| direction(k) == direction(a) && direction(k) != 0.0)
            })
            .expect("a monotone stretch");
        let mut back: Vec<FrfPoint> = p[a..=a + 5].to_vec();
        back.push(p[a + 4].clone());
        back.push(p[a + 3].clone());
        let last = &p[a + 3];
        let cut = GivenUp {
            freq_hz: last.freq_hz,
            amplitude: last.amplitudes[0],
            amplitude_rising: last.amplitudes[0] > p[a + 4].amplitudes[0],
            fold_hz: Some(p[a + 5].freq_hz),
            cause: GiveUpCause::FillEnd,
        };
        let alone = judge_cut(&mut system, &newton, &back, &[], 0..back.len(), &cut);
        eprintln!("stretch from {:.4} Hz: {alone:?}", p[a].freq_hz);
        assert!(alone.own_side, "{alone:?}");
        assert!(
            alone.landing.distance.unwrap() <= RETRACE_TOLERANCE,
            "{alone:?}"
        );
        assert!(
            alone.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE,
            "{alone:?}"
        );
        let fold = alone.beyond_fold.expect("judged beyond the fold");
        assert_eq!(fold.fold_hz, p[a + 5].freq_hz);
        assert_eq!(fold.run_amplitude, None, "{fold:?}");
        assert_eq!(alone.verdict, CutVerdict::Abandoned, "{alone:?}");
        let words = alone.describe();
        assert!(
            words.contains("came back along the side") && words.contains("not followed"),
            "{words}"
        );
        let mut with_beyond = back.clone();
        with_beyond.extend_from_slice(&p[a + 5..=a + 9]);
        let beyond = judge_cut(
            &mut system,
            &newton,
            &with_beyond,
            &[back.len()],
            0..back.len(),
            &cut,
        );
        eprintln!("with the points beyond: {beyond:?}");
        let fold = beyond.beyond_fold.expect("judged beyond the fold");
        assert!(
            fold.landing.resolved_distance.unwrap() <= SAME_SOLUTION_TOLERANCE,
            "{fold:?}"
        );
        assert_eq!(beyond.verdict, CutVerdict::Covered, "{beyond:?}");
    }
}
