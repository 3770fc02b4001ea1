//! The judgements of a run's cuts, dead ends and leaps (Newton past a point, compared with the
//! run) and the words they are told in: what a verdict means is defined here, once.

use crate::numerics::continuation::SAME_SOLUTION_TOLERANCE;

/// The judgement of a cut ([`Jump::fill_cut`](super::Jump::fill_cut)): Newton at a fixed frequency
/// just past the cut, in the direction the stretch was going at its last step, from the cut point's
/// coefficients (at most five solves, the first that converges is kept, see
/// [`judge_cuts`](super::judge::judge_cuts)), the crossings of that frequency by the run's points
/// within a branch, compared on the coefficients, and Newton at that frequency from each crossing
/// within [`RETRACE_TOLERANCE`], which tells whether the landing is that crossing's solution
/// (`cut_check` in `solution.json`'s jumps).
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
    /// [`judge_cuts`](super::judge::judge_cuts)).
    pub own_side: bool,
    /// Newton iterations of the converged solve (0 without one): with the solves that did not
    /// converge (at most five in all, see [`judge_cuts`](super::judge::judge_cuts)), the
    /// judgement's cost.
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
/// stretch, see [`judge_cuts`](super::judge::judge_cuts)), compared with the run: the fields shared
/// by [`CutCheck`] and [`FoldCheck`].
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
    /// ‖c − c_N‖ / ‖c‖ between the landing c and Newton's solution c_N at the landing's frequency
    /// started from the crossing of [`Landing::distance`] (see
    /// [`judge_cuts`](super::judge::judge_cuts)): at most [`SAME_SOLUTION_TOLERANCE`], the landing
    /// is that stretch's solution (covered); above, it is another solution. None when no crossing
    /// lies within [`RETRACE_TOLERANCE`] of the landing, or Newton from it converged nowhere.
    pub resolved_distance: Option<f64>,
}

impl Landing {
    /// No solve converged; `freq_hz` (Hz) is the frequency of the last one tried.
    pub(super) fn nowhere(freq_hz: f64) -> Self {
        Self {
            freq_hz,
            amplitude: None,
            distance: None,
            resolved_distance: None,
        }
    }
}

/// The judgement past the fold of a cut stretch that came back along its own other side
/// ([`CutCheck::beyond_fold`]): Newton past the fold, from the fold point's coefficients, at the
/// offsets of [`judge_cuts`](super::judge::judge_cuts), compared with the run as the landing past
/// the cut is.
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
    /// for a [`Jump::end_check`](super::Jump::end_check)).
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
            // The other side of a fold at the dead end
            // ([`judge_round_dead_end`](super::landing::judge_round_dead_end)).
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

/// Relative tolerance on every output's first-harmonic amplitude within which the last point of a
/// branch given up counts as lying on a stretch already followed
/// ([`BranchEnd::Retrace`](super::BranchEnd::Retrace)): another segment of the run's points
/// crossing the same frequency, interpolated linearly, must match each amplitude to 1 % of it. The
/// sampled contact law makes the solution curve a chain of pieces meeting at corners, and converged
/// points of neighbouring pieces at one frequency differ by the sampling: on the paper's system at
/// F0 = 1 N a branch given up at 151.8405 Hz (3.2333e-4 m) is passed there by the branch solved
/// past it at 3.2285e-4 m (0.15 %), and Newton from the point given up, just above it, lands on
/// that branch.
pub const RETRACE_TOLERANCE: f64 = 1e-2;

/// The judgement of a leap of the path ([`FrfRun::leaps`](super::FrfRun::leaps)): where the
/// corrector failed at every step and no corner was found, the path went on from a point predicted
/// further ahead along its tangent, which may have landed on another solution curve, past a fold it
/// never met (measured on the 3D blade pair over 845-900 Hz: a leap from 886.848 to 887.41 Hz over
/// the lower branch's fold, the resonance peak left out, the run otherwise `complete`). After the
/// run the path is followed back from the leap's landing to the frequency of the point before the
/// leap, and the solution it reaches there is compared with that point
/// ([`judge_leaps`](super::judge::judge_leaps)): the same solution, and the leap stayed on one
/// solution curve.
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
    /// `covered`: the path followed back from the landing reaches the point before the leap, or a
    /// solution within [`RETRACE_TOLERANCE`] of it on the coefficients (at a low pre-load of the
    /// paper's system the sampled contact law's solution curve is a chain of short pieces meeting
    /// at corners: at F0 = 1 N the leap from 19.0467 to 19.2388 Hz lands on the piece next to the
    /// one it left, 0.89 % from it at 19.0467 Hz), so the response the run gives over the leap is
    /// the one there to that tolerance; `abandoned`: it reaches a solution further off, so the leap
    /// crossed onto another branch and the branch through the point before it goes on beyond it
    /// unfollowed (possibly to a fold and a resonance peak); `unjudged`: it did not get back to
    /// that frequency within [`LEAP_CHECK_POINTS`](super::LEAP_CHECK_POINTS) points. The last two
    /// make the run incomplete. A leap onto another branch is `covered` after all when
    /// [`Self::past`] finds the branch through the point before it on the run.
    pub verdict: CutVerdict,
    /// For a leap onto another branch: the branch through the point before the leap judged as a
    /// branch given up at a dead end is ([`judge_cuts`](super::judge::judge_cuts)): Newton at a
    /// fixed frequency past that point, the way the path was going, compared with the run, or,
    /// where it converges nowhere, the other side of a fold there
    /// ([`judge_round_dead_end`](super::landing::judge_round_dead_end)). Its verdict is the leap's.
    /// None otherwise.
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
