//! What an FRF run reports: its points, its jumps between branches, and whether the run is
//! complete (the status line's reason), for files, messages and callers.

use crate::analysis::error_estimate::PointAccuracy;
use crate::analysis::estimate_pool::EstimateTicket;
use crate::analysis::stability::PointStability;
use crate::contact::{ContactState, TimeResolution};
use crate::hbm::HbmError;
use crate::model::Problem;
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
/// left the range below the start, the run goes on, as a stepped-sine test sweeping up would,
/// on a branch found just past the highest frequency reached, first followed back down toward
/// that frequency (those points come first, in rising frequency).
///
/// Serialised in `solution.json`'s `jumps`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Jump {
    /// Highest frequency of the path before the jump (Hz).
    pub from_hz: f64,
    /// Lowest frequency of the branch after the jump (Hz), followed back down toward
    /// `from_hz` as far as it goes. Frequencies between the two were not computed on any
    /// branch (none when `to_hz` ≤ `from_hz`).
    pub to_hz: f64,
    /// Index of the next branch's first point in the run's points.
    pub first_point: usize,
}

impl Jump {
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

    /// Whether the run is complete: it reached the end frequency and every stretch it jumped
    /// over at a fold was computed on some branch ([`Self::incomplete_reason`]).
    pub fn is_complete(&self) -> bool {
        self.incomplete_reason().is_none()
    }

    /// Why the run did not cover the range (None when it did), for the run's status line
    /// (`incomplete: <reason>`).
    pub fn incomplete_reason(&self) -> Option<String> {
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
                         the branch found past it did not reach back to those frequencies",
                        gaps.join(", ")
                    )
                })
            }
            PathEnd::LeftRangeBelow => Some(format!(
                "the path turned back and left the range below the start frequency at \
                 {last:.4} Hz, and no branch was found past {highest:.4} Hz; frequencies above \
                 were never reached"
            )),
            PathEnd::MaxPoints => Some(format!(
                "the point budget (analysis.max_points = {}) was used up at {last:.4} Hz; \
                 frequencies above {highest:.4} Hz were never reached",
                self.points.len()
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
    Continuation(ContinuationError),
    /// Continuation stalled on a problem with a contact on a sampled law: the message adds
    /// the likely cause and its remedy (a residual that stagnates just above the tolerance
    /// where a contact transition falls between two time samples, whose kink Newton cannot
    /// converge across).
    #[error("{source}; {SAMPLED_LAW_STALL}")]
    StalledOnSampledLaw {
        /// The continuation's error.
        source: ContinuationError,
    },
}

/// What a stall on a sampled contact law usually means, and what gets past it.
const SAMPLED_LAW_STALL: &str = "with a sampled contact law (`jenkins-1d-sampled`, \
    `jenkins-2d-sampled`) a residual stagnating just above tolerance means a contact \
    transition falls between time samples: the event-resolved law (`jenkins-1d`, \
    `jenkins-2d`) or more samples ([harmonics] samples) get past it";

impl FrfError {
    /// The error of a continuation run on `problem`: a stall on a problem with a contact on a
    /// sampled law names that law's remedy, any other error is passed on as it is.
    pub fn from_continuation(error: ContinuationError, problem: &Problem) -> Self {
        let sampled = problem
            .contacts
            .iter()
            .any(|c| c.resolution == TimeResolution::Samples);
        match error {
            ContinuationError::Stalled { .. } if sampled => {
                FrfError::StalledOnSampledLaw { source: error }
            }
            other => FrfError::Continuation(other),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_with_jumps(jumps: Vec<Jump>) -> FrfRun {
        FrfRun {
            points: Vec::new(),
            turning_points: Vec::new(),
            rejected_steps: 0,
            jumps,
            end: PathEnd::EndFrequency,
            elapsed_s: 0.0,
        }
    }

    /// A stall names the sampled law's remedy only when a contact of the problem is on a
    /// sampled law; other continuation errors pass unchanged.
    #[test]
    fn a_stall_advises_the_sampled_law_remedy_only_on_a_sampled_law() {
        const SCENE: &str = include_str!("../../../tests/data/two-dof-grounded.toml");
        let problem = |law: &str| {
            let set = format!("contacts.0.law={law}");
            crate::scene::parse(SCENE, "two-dof", &[set])
                .and_then(|s| s.validate("two-dof"))
                .expect("the two-DOF scene is valid")
        };
        let stall = || ContinuationError::Stalled {
            freq_hz: 12.0,
            step: 1e-9,
            reason: crate::numerics::NewtonFailure::Evaluation("kink".into()),
        };
        let on_sampled = FrfError::from_continuation(stall(), &problem("jenkins-1d-sampled"));
        assert!(matches!(on_sampled, FrfError::StalledOnSampledLaw { .. }));
        assert!(
            on_sampled.to_string().contains("event-resolved law"),
            "{on_sampled}"
        );
        let on_events = FrfError::from_continuation(stall(), &problem("jenkins-1d"));
        assert_eq!(on_events, FrfError::Continuation(stall()));
        assert!(!on_events.to_string().contains("sampled"), "{on_events}");
        let interrupted = ContinuationError::Interrupted { freq_hz: 12.0 };
        assert_eq!(
            FrfError::from_continuation(interrupted.clone(), &problem("jenkins-1d-sampled")),
            FrfError::Continuation(interrupted)
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
        };
        assert!(run_with_jumps(vec![jump(66.0, 66.0)]).is_complete());
        assert!(run_with_jumps(vec![jump(66.0, 66.0 + 1e-12)]).is_complete());
        let gap = run_with_jumps(vec![jump(66.0, 66.0), jump(151.84, 152.14)]);
        assert!(!gap.is_complete());
        let reason = gap.incomplete_reason().unwrap();
        assert!(reason.contains("151.8400-152.1400 Hz"), "{reason}");
    }
}
