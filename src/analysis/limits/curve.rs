//! One solved case: the continuation of the case's frequency response (retried with other
//! steps when it fails) and its resonance peak.

use crate::analysis::frf::{self, FrfRun, Silent};
use crate::model::Problem;

use super::case::LimitCase;
use super::error::LimitError;
use super::peak::{refine_peak, Peak};

/// One solved curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseCurve {
    /// The case.
    pub case: LimitCase,
    /// The continuation run.
    pub run: FrfRun,
    /// Resonance peak of the first output DOF in the peak window.
    pub peak: Peak,
    /// Continuation retries with other step settings before the run succeeded (0: none).
    pub retries: usize,
}

/// Factors on the scene's continuation steps (initial and largest) tried in turn when a curve
/// fails: a continuation that stalls at a corner of the piecewise-smooth path (a contact
/// changing state) usually passes it when the corner is approached with other steps.
const STEP_RETRIES: [f64; 4] = [1.0, 0.5, 0.25, 2.0];

/// Solves the FRF of one case and locates its peak (first output DOF) in `window` (Hz).
///
/// If the continuation fails, or ends before the end of the range (an incomplete run: the
/// curve would not cover the range the limits are asked for), it is repeated with the scene's
/// initial and largest steps scaled by the factors 0.5, 0.25 and 2 in turn; the number of
/// retries is recorded, and the first failure is returned when every attempt fails.
pub fn solve_case(
    problem: &Problem,
    case: &LimitCase,
    window: Option<(f64, f64)>,
) -> Result<CaseCurve, LimitError> {
    let p = case.apply(problem);
    let err = |source| LimitError::Curve {
        case: case.name.clone(),
        source,
    };
    let mut first_error: Option<LimitError> = None;
    for (retries, factor) in STEP_RETRIES.iter().enumerate() {
        let mut attempt = p.clone();
        let a = &mut attempt.analysis.continuation;
        a.max_step = (a.max_step * factor).max(a.min_step);
        a.initial_step = (a.initial_step * factor).clamp(a.min_step, a.max_step);
        match frf::solve(&attempt, &mut Silent) {
            Ok(run) if !run.is_complete() => {
                first_error.get_or_insert(LimitError::Incomplete {
                    case: case.name.clone(),
                    reason: run.incomplete_reason().unwrap_or_default(),
                });
            }
            Ok(run) => {
                let peak = refine_peak(&p, &run.points, 0, window)
                    .map_err(err)?
                    .ok_or_else(|| {
                        let (lo_hz, hi_hz) = window.unwrap_or((f64::NAN, f64::NAN));
                        LimitError::NoPeak {
                            case: case.name.clone(),
                            lo_hz,
                            hi_hz,
                        }
                    })?;
                return Ok(CaseCurve {
                    case: case.clone(),
                    run,
                    peak,
                    retries,
                });
            }
            Err(e) => {
                first_error.get_or_insert(err(e));
            }
        }
    }
    Err(first_error.expect("at least one attempt"))
}
