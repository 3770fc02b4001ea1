//! One solved case: the continuation of the case's frequency response (retried with other
//! steps when it fails or stops early), its resonance peak, and how it ended
//! ([`CurveStatus`]): a case that does not cover the range keeps the points it finished.

use crate::analysis::frf::{self, FrfObserver, FrfPoint, Jump};
use crate::model::Problem;

use super::case::LimitCase;
use super::error::LimitError;
use super::peak::{refine_peak, Peak};

/// How the continuation of one case ended.
#[derive(Debug, Clone, PartialEq)]
pub enum CurveStatus {
    /// The path reached the end frequency.
    Complete,
    /// The path ended before the end frequency (point budget used up, left the range below the
    /// start, no progress), or left a stretch of the range uncovered, or abandoned a branch
    /// inside the range (the response beyond the point given up is missing, see
    /// `frf::BranchEnd::Abandoned`), with every step setting tried; `reason` says where and
    /// why.
    Incomplete {
        /// Why the range was not covered (see `FrfRun::incomplete_reason`).
        reason: String,
    },
    /// The continuation failed (no solution at the start, a stall), or the curve cannot be
    /// used (no converged point in the peak window, its grid solves could not be set up).
    Failed {
        /// Cause.
        error: LimitError,
    },
}

/// Serialised as its [`CurveStatus::text`].
impl serde::Serialize for CurveStatus {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.text())
    }
}

impl CurveStatus {
    /// Whether the case covered the range.
    pub fn is_complete(&self) -> bool {
        matches!(self, CurveStatus::Complete)
    }

    /// `complete`, `incomplete: <reason>` or `failed: <cause>` (the text of `limits.json`).
    pub fn text(&self) -> String {
        match self {
            CurveStatus::Complete => "complete".to_string(),
            CurveStatus::Incomplete { reason } => format!("incomplete: {reason}"),
            CurveStatus::Failed { error } => format!("failed: {}", error.cause()),
        }
    }
}

/// One attempted case: the points its continuation finished (all of them when complete), its
/// resonance peak and how it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseCurve {
    /// The case.
    pub case: LimitCase,
    /// Converged points in path order: the whole path of a complete case, the points finished
    /// before the path stopped or failed otherwise (empty when it failed at its first point).
    pub points: Vec<FrfPoint>,
    /// Turning-point frequencies of the path (Hz).
    pub turning_points: Vec<f64>,
    /// Jumps of the path to other branches, with how the branch before each ended
    /// ([`Jump`]; `first_point` indexes `points`).
    pub jumps: Vec<Jump>,
    /// Resonance peak of the first output DOF in the peak window; `None` when no finished point
    /// lies in it.
    pub peak: Option<Peak>,
    /// How the case ended.
    pub status: CurveStatus,
}

impl CaseCurve {
    /// `curve <name> incomplete: <reason>` or `curve <name> failed: <cause>` when the case
    /// did not cover the range; `None` when it did.
    pub fn unfinished_reason(&self) -> Option<String> {
        (!self.status.is_complete())
            .then(|| format!("curve `{}` {}", self.case.name, self.status.text()))
    }
}

/// Collects the path as it comes, so that the points of a continuation that fails are kept.
#[derive(Default)]
struct Collect {
    points: Vec<FrfPoint>,
    turning_points: Vec<f64>,
    jumps: Vec<Jump>,
}

impl FrfObserver for Collect {
    fn point(&mut self, point: &FrfPoint) {
        self.points.push(point.clone());
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.turning_points.push(freq_hz);
    }
    fn jump(&mut self, jump: &Jump) {
        self.jumps.push(*jump);
    }
}

/// Solves the FRF of one case and locates its peak (first output DOF) in `window` (Hz).
/// Never fails: how the case ended is in [`CaseCurve::status`].
///
/// A continuation that fails, or ends before the end of the range (an incomplete run: the
/// curve would not cover the range the limits are asked for), keeps its finished points with
/// its status (`Incomplete` or `Failed`). A path that covers the range but has no point in the
/// peak window is `Failed` with [`LimitError::NoPeak`] (its points are kept).
pub fn attempt_case(problem: &Problem, case: &LimitCase, window: Option<(f64, f64)>) -> CaseCurve {
    let p = case.apply(problem);
    let mut collect = Collect::default();
    let (points, turning_points, jumps, mut status) = match frf::solve(&p, &mut collect) {
        Ok(run) => {
            let status = match run.incomplete_reason() {
                None => CurveStatus::Complete,
                Some(reason) => CurveStatus::Incomplete { reason },
            };
            (run.points, run.turning_points, run.jumps, status)
        }
        Err(source) => (
            collect.points,
            collect.turning_points,
            collect.jumps,
            CurveStatus::Failed {
                error: LimitError::Curve {
                    case: case.name.clone(),
                    source,
                },
            },
        ),
    };
    let peak = match refine_peak(&p, &points, 0, window) {
        Ok(peak) => peak,
        Err(source) => {
            if status.is_complete() {
                status = CurveStatus::Failed {
                    error: LimitError::Curve {
                        case: case.name.clone(),
                        source,
                    },
                };
            }
            None
        }
    };
    if peak.is_none() && status.is_complete() {
        let (lo_hz, hi_hz) = window.unwrap_or((f64::NAN, f64::NAN));
        status = CurveStatus::Failed {
            error: LimitError::NoPeak {
                case: case.name.clone(),
                lo_hz,
                hi_hz,
            },
        };
    }
    CaseCurve {
        case: case.clone(),
        points,
        turning_points,
        jumps,
        peak,
        status,
    }
}

/// As [`attempt_case`], for callers that need the whole curve: the curve when it covered the
/// range (its peak is then `Some`), otherwise the error of its status ([`LimitError::Incomplete`]
/// or the failure).
pub fn solve_case(
    problem: &Problem,
    case: &LimitCase,
    window: Option<(f64, f64)>,
) -> Result<CaseCurve, LimitError> {
    let curve = attempt_case(problem, case, window);
    match curve.status {
        CurveStatus::Complete => Ok(curve),
        CurveStatus::Incomplete { reason } => Err(LimitError::Incomplete {
            case: case.name.clone(),
            reason,
        }),
        CurveStatus::Failed { error } => Err(error),
    }
}
