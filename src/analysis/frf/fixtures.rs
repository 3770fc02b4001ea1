//! Test fixtures shared by the unit tests of the FRF run's files: hand-made runs, points and
//! judgements, so that each file's tests build the paths they judge in one way.

use crate::numerics::PathEnd;

use super::checks::{CutCheck, CutVerdict, Landing};
use super::status::{FrfPoint, FrfRun, Jump};

/// A judgement that covers its cut or point: Newton landed at `freq_hz` (Hz) with the first
/// output's amplitude `amplitude` (m), `distance` from the nearest stretch and
/// `resolved_distance` from Newton's solution from it, in `newton_iterations`.
pub(super) fn covered_check(
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

pub(super) fn run_with_jumps(jumps: Vec<Jump>) -> FrfRun {
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

pub(super) fn line_point(freq_hz: f64, c1: f64, c3: f64) -> FrfPoint {
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

/// The synthetic path of a branch rising along A = 1 + 0.1 (f − 100) from 100 to 110 Hz
/// (one point per Hz), then turned back at the fold at 110 Hz onto `back`: (Hz, amplitude)
/// points followed down.
pub(super) fn folded_path(back: &[(f64, f64)]) -> Vec<FrfPoint> {
    (0..=10)
        .map(|k| {
            let f = 100.0 + k as f64;
            line_point(f, 1.0 + 0.1 * (f - 100.0), 0.0)
        })
        .chain(back.iter().map(|&(f, a)| line_point(f, a, 0.0)))
        .collect()
}
