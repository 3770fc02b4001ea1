//! The bound check: how far scanned intermediate curves, and their peaks, go outside the band
//! of the two limit curves.

use crate::contact::ContactState;

use super::case::LimitCase;
use super::grid::{GridPoint, GridSolution};
use super::peak::Peak;

/// How well the limit curves bound a set of other curves.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BoundCheck {
    /// Largest amplitude above the upper limit, relative to the upper limit there.
    pub max_excess_above: f64,
    /// Where (frequency in Hz, case name), if any excess.
    pub above_at: Option<(f64, String)>,
    /// Largest amplitude below the lower limit, relative to the lower limit there.
    pub max_excess_below: f64,
    /// Where (frequency in Hz, case name), if any excess.
    pub below_at: Option<(f64, String)>,
    /// Largest refined peak of a scanned curve above the largest limit peak (relative; over
    /// the scanned curves and limit curves that have a peak).
    pub peak_excess_above: f64,
    /// Smallest refined peak of a scanned curve below the smallest limit peak (relative).
    pub peak_excess_below: f64,
    /// Grid points compared: those where the scanned curve and both limit curves were solved
    /// (unfinished curves are compared where they exist).
    pub compared: usize,
    /// Contact states where the excess above the upper limit is largest.
    pub above_states: Option<ExcessStates>,
    /// Contact states where the excess below the lower limit is largest.
    pub below_states: Option<ExcessStates>,
}

/// Contact states at the point of a largest excess: they tell why the limits do not bound
/// there (e.g. a limit curve fully stuck while the scanned state slips).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ExcessStates {
    /// States of the scanned curve.
    pub scanned: Vec<ContactState>,
    /// States of each limit curve at that grid frequency.
    pub limits: Vec<Vec<ContactState>>,
}

/// Compares scanned curves (on the grid) and their peaks with the limits: pointwise where the
/// band and the scanned curve exist, peaks where the scanned curve has one (`limit_peaks`: the
/// peak amplitudes of the limit curves that have one, m; the peak check is skipped when empty).
pub fn check_bounds(
    grid: &[GridPoint],
    limit_peaks: &[f64],
    scanned: &[(LimitCase, Vec<GridSolution>, Option<Peak>)],
) -> BoundCheck {
    let mut b = BoundCheck {
        max_excess_above: 0.0,
        above_at: None,
        max_excess_below: 0.0,
        below_at: None,
        peak_excess_above: 0.0,
        peak_excess_below: 0.0,
        compared: 0,
        above_states: None,
        below_states: None,
    };
    let peak_hi = limit_peaks
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    let peak_lo = limit_peaks.iter().cloned().fold(f64::INFINITY, f64::min);
    for (case, sols, peak) in scanned {
        for (g, s) in grid.iter().zip(sols) {
            let Some((p, _)) = s else { continue };
            if !(g.upper.is_finite() && g.lower.is_finite()) {
                continue;
            }
            b.compared += 1;
            let a = p.amplitudes[0];
            let above = (a - g.upper) / g.upper;
            let states = || ExcessStates {
                scanned: p.states.clone(),
                limits: g.states.clone(),
            };
            if above > b.max_excess_above {
                b.max_excess_above = above;
                b.above_at = Some((g.freq_hz, case.name.clone()));
                b.above_states = Some(states());
            }
            let below = (g.lower - a) / g.lower;
            if below > b.max_excess_below {
                b.max_excess_below = below;
                b.below_at = Some((g.freq_hz, case.name.clone()));
                b.below_states = Some(states());
            }
        }
        let Some(peak) = peak.as_ref().filter(|_| !limit_peaks.is_empty()) else {
            continue;
        };
        b.peak_excess_above = b
            .peak_excess_above
            .max((peak.amplitude - peak_hi) / peak_hi);
        b.peak_excess_below = b
            .peak_excess_below
            .max((peak_lo - peak.amplitude) / peak_lo);
    }
    b
}
