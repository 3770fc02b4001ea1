//! What an FRF run reports: its points, jumps between branches and how each branch ended, and
//! whether the run is complete (the status line's reasons), for files, messages and callers.

use super::checks::{CutCheck, CutVerdict, LeapCheck};
use crate::analysis::error_estimate::PointAccuracy;
use crate::analysis::estimate_pool::EstimateTicket;
use crate::analysis::stability::PointStability;
use crate::contact::ContactState;
use crate::hbm::HbmError;
use crate::numerics::linalg::LinearSolveError;
use crate::numerics::{ContinuationError, PathEnd};

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
    /// Where the branch after the jump (the fill, followed back down toward the fold, or a bridge,
    /// followed toward the edges of its stretch) was left off every stretch followed before (see
    /// [`fill_cut`](super::cuts::fill_cut)): at its edge after turning back at a fold of its own,
    /// or given up before its edge (a dead end, no progress, its point budget used up); for a
    /// bridge cut both ways, its way down's ([`Jump::second_cut`]). That branch may go on beyond
    /// the point, not followed. It does not count in [`Jump::abandons_branch`] (which is about the
    /// branch before the jump); whether it counts in the run's status is decided by
    /// [`Jump::cut_check`], once the branches solved after it are known. None otherwise.
    pub fill_cut: Option<GivenUp>,
    /// How [`Jump::fill_cut`] was judged once the run was over ([`CutCheck`]): by a Newton
    /// solve just past it, whose landing either lies on a stretch of the run (the cut is
    /// covered; past the cut stretch's fold when the landing is its own other side) or not
    /// (the branch given up there goes on, unfollowed: the run is incomplete).
    /// None without a cut, and for jumps reported before the judgement (see
    /// [`FrfObserver::cut_judged`](super::FrfObserver::cut_judged)).
    pub cut_check: Option<CutCheck>,
    /// The cut of a bridge's way up when its way down was cut too (then [`Jump::fill_cut`] is
    /// the way down's): a bridge, followed toward both edges of its stretch, can be left off
    /// the run at both, and each may leave its branch unfollowed beyond. None otherwise.
    pub second_cut: Option<GivenUp>,
    /// How [`Jump::second_cut`] was judged, as [`Jump::cut_check`] for [`Jump::fill_cut`].
    pub second_cut_check: Option<CutCheck>,
    /// How the branch before the jump, given up inside the range off every stretch followed
    /// ([`BranchEnd::Abandoned`]), was judged once the run was over: as a cut is
    /// ([`judge_cuts`](super::judge::judge_cuts)), by Newton just past its last point, the way the
    /// path was going. A landing on a stretch of the run covers it (the branch beyond the point
    /// given up is one the run has: nothing is missing, [`Jump::abandons_branch`] is false); a
    /// landing on no stretch, or no landing, leaves it abandoned. None for other branch ends, and
    /// for jumps reported before the judgement.
    pub end_check: Option<CutCheck>,
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
    /// The path could not be followed on from its last point, but that point lies on a stretch the
    /// run had already followed, within [`RETRACE_TOLERANCE`](super::RETRACE_TOLERANCE) at the same
    /// frequency: the path was retracing itself, and nothing was abandoned.
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
    /// The judgement of each leap, in the order of [`FrfRun::leaps`]
    /// ([`judge_leaps`](super::judge::judge_leaps)).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::frf::fixtures::run_with_jumps;

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
}
