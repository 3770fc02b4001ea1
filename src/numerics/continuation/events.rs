//! Events of a path that end it or turn it: leaving the range behind the start, passing the
//! end frequency, the direction of travel, and the stagnation exit of Newton.

use super::corrector::CHORD_STEPS_PER_ITERATION;
use super::settings::Continuation;
use crate::numerics::path::PathPoint;

impl Continuation {
    /// Whether the solve with relative residuals `history` (one per step) is to be given up for
    /// stagnation. With `chord` steps [`CHORD_STEPS_PER_ITERATION`] of them count as one iteration
    /// of [`StagnationExit::after`](super::StagnationExit::after) and of its window, as of the
    /// iteration limit.
    pub(super) fn stagnates(&self, history: &[f64], chord: bool) -> bool {
        self.stagnation.is_some_and(|exit| {
            if chord {
                // Every third step back from the current one.
                let iterations: Vec<f64> = history
                    .iter()
                    .rev()
                    .step_by(CHORD_STEPS_PER_ITERATION)
                    .rev()
                    .copied()
                    .collect();
                exit.stagnated(&iterations)
            } else {
                exit.stagnated(history)
            }
        })
    }

    /// Whether the path has left the range for good behind the start frequency. A path that
    /// turns back behind the start (a fold: the response overhangs) is followed on, within the
    /// point budget, since it usually turns again and comes back; only one that runs on to
    /// half the range behind the start (or, running up, to a tenth of the start frequency) is
    /// given up.
    pub(super) fn left_range(&self, point: &PathPoint) -> bool {
        let a = &self.settings;
        let behind = self.direction() * (a.freq_start_hz - point.freq_hz());
        let range = (a.freq_end_hz - a.freq_start_hz).abs();
        behind > 0.5 * range || (self.direction() > 0.0 && point.freq_hz() < 0.1 * a.freq_start_hz)
    }

    /// +1 when the path runs up in frequency (end above start), −1 when it runs down.
    pub(super) fn direction(&self) -> f64 {
        if self.settings.freq_end_hz < self.settings.freq_start_hz {
            -1.0
        } else {
            1.0
        }
    }

    /// Whether a predicted y (scaled, ω last) lands at or past the end frequency in the
    /// direction of travel.
    pub(super) fn past_end(&self, predicted: &[f64]) -> bool {
        let n = predicted.len() - 1;
        self.direction() * (predicted[n] - self.settings.freq_end_hz) >= 0.0
    }
}
