//! The branch past a fold the path did not come back from: a point solved just past the highest
//! frequency reached, and the branch through it followed back down toward that frequency.

use std::f64::consts::PI;

use super::observer::{Adapter, Silent};
use super::status::{FrfError, FrfPoint};
use crate::analysis::estimate_pool::EstimatePool;
use crate::analysis::linear;
use crate::contact::harmonic::HarmonicSet;
use crate::hbm::operator::HbmOperator;
use crate::model::Problem;
use crate::numerics::continuation::AdaptiveScale;
use crate::numerics::{Continuation, ContinuationSettings, PathSummary};

/// How far past the highest frequency a path reached a jump lands, as fractions of the range,
/// tried in turn until a point converges there.
const JUMP_FRACTIONS: &[f64] = &[0.0005, 0.002, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2];

/// What the branches of one run share: the settings, the arc-length scale (each branch starts
/// with the one the branch before grew to), how it grows and which amplitudes the steps follow.
pub(super) struct Branching {
    pub(super) settings: ContinuationSettings,
    pub(super) x_scale: Vec<f64>,
    pub(super) adaptive: AdaptiveScale,
    pub(super) amplitude_groups: Vec<Vec<usize>>,
}

impl Branching {
    /// The continuation of a branch from `from_hz` toward `to_hz` (Hz, below or above) with at
    /// most `max_points` points.
    pub(super) fn continuation(&self, from_hz: f64, to_hz: f64, max_points: usize) -> Continuation {
        let settings = ContinuationSettings {
            freq_start_hz: from_hz,
            freq_end_hz: to_hz,
            max_points,
            ..self.settings
        };
        Continuation::new(settings, self.x_scale.clone())
            .with_adaptive_scale(self.adaptive.clone())
            .with_amplitude_steps(self.amplitude_groups.clone())
    }

    /// Follows the path silently from `x` (the operator's unknowns, converged at `from_hz`)
    /// toward `to_hz` (below or above) with at most `max_points` points. Returns the points in
    /// path order (the first is the start point) and the summary, None when the continuation
    /// failed (its points up to the failure are kept). With `estimates`, each point gets
    /// its error estimate across the path as it is accepted (or, formed on a worker, pending
    /// until the run reports the point).
    pub(super) fn follow(
        &self,
        system: &mut HbmOperator<'_>,
        x: &[f64],
        from_hz: f64,
        to_hz: f64,
        max_points: usize,
        estimates: Option<&EstimatePool<'_>>,
    ) -> (Vec<FrfPoint>, Option<PathSummary>) {
        let mut silent = Silent;
        let mut collect = Adapter::new(&mut silent, estimates, false);
        let mut continuation = self.continuation(from_hz, to_hz, max_points);
        let summary = continuation.run(system, x, &mut collect).ok();
        (std::mem::take(&mut collect.points), summary)
    }
}

/// A converged point just past `highest` (Hz) on whatever branch Newton finds there, for the
/// path to go on from after a fold it did not come back from: at each of [`JUMP_FRACTIONS`] of
/// the range past `highest` (capped at the end frequency), from the stuck linear guess there,
/// the open-contact one (harmonics of the open structure on the stuck static state), then from
/// the highest point solved so far. Returns the frequency and the operator's
/// unknowns, or None when no guess converges.
pub(super) fn jump_target(
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
