//! The limit analysis itself: its settings, the run (limit, intermediate and scanned curves,
//! each attempted whatever the others do; grid classification, bound check, hysteresis loops)
//! and the size of the variability found.

use rayon::prelude::*;

use crate::model::Problem;

use crate::hbm::HbmSystem;

use super::bounds::{check_bounds, BoundCheck};
use super::case::{scan_cases, two_point_cases, CaseSpec, LimitCase};
use super::curve::{attempt_case, CaseCurve, CurveStatus};
use super::envelope::{envelope, search_settings, Envelope, EnvelopeInputs, EnvelopeMode};
use super::error::LimitError;
use super::grid::{classify, on_grid, GridPoint, GridSolution};
use super::loops::{curve_loops, HysteresisRequest, LoopSet};
use super::peak::Peak;
use super::side::Regime;

/// Settings of a limit analysis.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LimitSettings {
    /// m values of uniform intermediate curves (the same m on every point).
    pub intermediate: Vec<f64>,
    /// Intermediate cases given per damper side or per contact point.
    pub cases: Vec<CaseSpec>,
    /// Points of the common frequency grid.
    pub grid_points: usize,
    /// m values scanned per side (all combinations) to test the bounds; empty disables.
    pub bound_scan: Vec<f64>,
    /// Frequency window (Hz) in which each curve's resonance peak is sought; `None`: the range.
    pub peak_window_hz: Option<(f64, f64)>,
    /// Hysteresis loops to compute.
    pub hysteresis: HysteresisRequest,
    /// The response envelope over the initial states, one m per side or per point; `None`:
    /// not computed.
    pub envelope: Option<EnvelopeMode>,
}

impl Default for LimitSettings {
    fn default() -> Self {
        Self {
            intermediate: Vec::new(),
            cases: Vec::new(),
            grid_points: 201,
            bound_scan: Vec::new(),
            peak_window_hz: None,
            hysteresis: HysteresisRequest::default(),
            envelope: None,
        }
    }
}

impl LimitSettings {
    /// The intermediate cases: uniform ones first, then those given per side or point.
    pub fn intermediate_cases(&self, problem: &Problem) -> Vec<LimitCase> {
        self.intermediate
            .iter()
            .map(|&m| LimitCase::uniform(problem, m))
            .chain(self.cases.iter().map(|c| LimitCase::from_spec(problem, c)))
            .collect()
    }
}

/// One case of the bound scan as it ended: its peak (where its finished path has one) and
/// status; the path itself is not kept.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ScannedCase {
    /// The case.
    pub case: LimitCase,
    /// Resonance peak of the first output DOF in the peak window, if the path has a point there.
    pub peak: Option<Peak>,
    /// How the case ended (`complete`, `incomplete: …`, `failed: …` in JSON).
    pub status: CurveStatus,
}

/// Everything a limit analysis computes. Every case is attempted whatever the others do: a
/// case that fails or stops early keeps its finished points and says so in its status, and the
/// grid, band and bound check use what exists (the band only where both limit curves were
/// solved, NaN elsewhere).
#[derive(Debug, Clone, PartialEq)]
pub struct LimitAnalysis {
    /// The two limit curves (m = +1, m = −1 on every side), in that order, whatever their status.
    pub limits: Vec<CaseCurve>,
    /// Intermediate curves, in the order of [`LimitSettings::intermediate_cases`].
    pub intermediate: Vec<CaseCurve>,
    /// Common grid with classification and band.
    pub grid: Vec<GridPoint>,
    /// Bound check of the scan (None when no scan was asked for).
    pub bounds: Option<BoundCheck>,
    /// Scanned cases with their peaks and status, in scan order.
    pub scanned: Vec<ScannedCase>,
    /// Requested hysteresis loops.
    pub loops: Vec<LoopSet>,
    /// Requested loops that could not be computed (no solution of the curve there), as text.
    pub loops_missing: Vec<String>,
    /// The response envelope, when asked for.
    pub envelope: Option<Envelope>,
}

/// Size of the variability of one limit analysis (first output DOF). Values that need a limit
/// curve's peak are NaN when that curve has none.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Variability {
    /// Larger resonance-peak amplitude of the two limit curves (m).
    pub upper_peak: f64,
    /// Smaller resonance-peak amplitude of the two limit curves (m).
    pub lower_peak: f64,
    /// `upper_peak / lower_peak`.
    pub peak_ratio: f64,
    /// 100·(higher − lower)/lower resonance frequency of the two limit curves (%).
    pub peak_freq_change_pct: f64,
    /// Widest band, max over the grid of upper − lower limit (m; over the grid points where the
    /// band exists).
    pub widest_band: f64,
    /// Frequency of the widest band (Hz).
    pub widest_band_hz: f64,
    /// Grid frequencies in the multiple-solution regime.
    pub multiple_points: usize,
    /// Grid frequencies.
    pub grid_points: usize,
}

impl LimitAnalysis {
    /// The size of the variability: limit peaks, their ratio and frequency change, widest band.
    pub fn variability(&self) -> Variability {
        let peak = |i: usize| {
            self.limits
                .get(i)
                .and_then(|c| c.peak.as_ref())
                .map_or((f64::NAN, f64::NAN), |p| (p.amplitude, p.freq_hz))
        };
        let (a, b) = (peak(0), peak(1));
        let both = |x: f64, y: f64, f: fn(f64, f64) -> f64| {
            if x.is_nan() || y.is_nan() {
                f64::NAN
            } else {
                f(x, y)
            }
        };
        let (upper_peak, lower_peak) = (both(a.0, b.0, f64::max), both(a.0, b.0, f64::min));
        let (f_hi, f_lo) = (both(a.1, b.1, f64::max), both(a.1, b.1, f64::min));
        let (widest_band, widest_band_hz) = self
            .grid
            .iter()
            .filter(|g| g.upper.is_finite() && g.lower.is_finite())
            .map(|g| (g.upper - g.lower, g.freq_hz))
            .fold((0.0, f64::NAN), |acc, x| if x.0 > acc.0 { x } else { acc });
        Variability {
            upper_peak,
            lower_peak,
            peak_ratio: upper_peak / lower_peak,
            peak_freq_change_pct: 100.0 * (f_hi - f_lo) / f_lo,
            widest_band,
            widest_band_hz,
            multiple_points: self
                .grid
                .iter()
                .filter(|g| matches!(g.regime, Regime::Multiple { .. }))
                .count(),
            grid_points: self.grid.len(),
        }
    }

    /// Grid frequencies where the band exists (both limit curves solved there).
    pub fn band_points(&self) -> usize {
        self.grid
            .iter()
            .filter(|g| g.lower.is_finite() && g.upper.is_finite())
            .count()
    }

    /// Whether every case (limit, intermediate, scanned) covered the range.
    pub fn is_complete(&self) -> bool {
        self.limits
            .iter()
            .chain(&self.intermediate)
            .all(|c| c.status.is_complete())
            && self.scanned.iter().all(|c| c.status.is_complete())
            && self.envelope.as_ref().is_none_or(|e| e.unsolved == 0)
    }

    /// "curve `<name>` incomplete: …" / "curve `<name>` failed: …" of every case that did not
    /// cover the range, limit curves first, then intermediate and scanned ones; empty when the
    /// analysis is complete.
    pub fn unfinished(&self) -> Vec<String> {
        self.limits
            .iter()
            .chain(&self.intermediate)
            .filter_map(CaseCurve::unfinished_reason)
            .chain(
                self.scanned
                    .iter()
                    .filter(|c| !c.status.is_complete())
                    .map(|c| format!("curve `{}` {}", c.case.name, c.status.text())),
            )
            .chain(self.envelope.as_ref().filter(|e| e.unsolved > 0).map(|e| {
                format!(
                    "envelope: no state solved at {} of {} grid frequencies",
                    e.unsolved,
                    e.points.len()
                )
            }))
            .collect()
    }
}

/// Runs the two-point limit analysis, intermediate curves, the bound scan, the response
/// envelope (when [`LimitSettings::envelope`] asks for it) and the requested hysteresis loops. Curves are solved in parallel (rayon); results do not depend on the
/// thread count.
///
/// Every case is attempted ([`attempt_case`]), whatever the others do: a case that fails or
/// stops before the end frequency keeps its finished points and its status, the grid is solved
/// on whatever path each limit curve has (the band and regime are NaN / `unknown` where one of
/// them has no solution), the bound check compares what exists, and loops that cannot be
/// computed are listed in [`LimitAnalysis::loops_missing`]. See [`LimitAnalysis::unfinished`].
///
/// `on_curve` is called as each limit, intermediate or scanned case ends (from worker
/// threads), so callers can write results as they come.
///
/// # Errors
/// [`LimitError::Setup`] when the problem's harmonic-balance system cannot be built (checked
/// once, before any curve: no case could be solved).
pub fn analyse<F>(
    problem: &Problem,
    settings: &LimitSettings,
    on_curve: F,
) -> Result<LimitAnalysis, LimitError>
where
    F: Fn(&CaseCurve) + Sync,
{
    HbmSystem::new(problem).map_err(LimitError::Setup)?;
    let a = &problem.analysis.continuation;
    let n = settings.grid_points.max(2);
    let grid: Vec<f64> = (0..n)
        .map(|i| a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / (n - 1) as f64)
        .collect();
    let window = settings.peak_window_hz;
    let limit_cases = two_point_cases(problem);
    let n_limits = limit_cases.len();
    let mut curve_cases = limit_cases;
    curve_cases.extend(settings.intermediate_cases(problem));
    let scanned_cases = scan_cases(problem, &settings.bound_scan);

    // Attempts one case and hands the curve to `on_curve` at once.
    let attempt = |c: &LimitCase| -> CaseCurve {
        let curve = attempt_case(problem, c, window);
        on_curve(&curve);
        curve
    };
    let mut limits: Vec<CaseCurve> = curve_cases.par_iter().map(attempt).collect();
    let intermediate = limits.split_off(n_limits);
    // Each limit curve on the grid, where its (possibly unfinished) path brackets the grid
    // frequency; a curve whose grid solves cannot be set up is unsolved everywhere and failed.
    let limits_on_grid: Vec<Vec<GridSolution>> = limits
        .par_iter_mut()
        .map(|c| match on_grid(problem, &c.case, &c.points, &grid) {
            Ok(sols) => sols,
            Err(error) => {
                if c.status.is_complete() {
                    c.status = CurveStatus::Failed { error };
                }
                vec![None; grid.len()]
            }
        })
        .collect();
    let grid_points = classify(problem, &grid, &limits_on_grid);

    let (bounds, scanned, scanned_on_grid) = if scanned_cases.is_empty() {
        (None, Vec::new(), Vec::new())
    } else {
        let results: Vec<(ScannedCase, Vec<GridSolution>)> = scanned_cases
            .par_iter()
            .map(|c| {
                let mut curve = attempt(c);
                let sols = match on_grid(problem, c, &curve.points, &grid) {
                    Ok(sols) => sols,
                    Err(error) => {
                        if curve.status.is_complete() {
                            curve.status = CurveStatus::Failed { error };
                        }
                        vec![None; grid.len()]
                    }
                };
                let scanned = ScannedCase {
                    case: curve.case,
                    peak: curve.peak,
                    status: curve.status,
                };
                (scanned, sols)
            })
            .collect();
        let limit_peaks: Vec<f64> = limits
            .iter()
            .filter_map(|c| c.peak.as_ref().map(|p| p.amplitude))
            .collect();
        let compared: Vec<(LimitCase, Vec<GridSolution>, Option<Peak>)> = results
            .iter()
            .map(|(s, sols)| (s.case.clone(), sols.clone(), s.peak.clone()))
            .collect();
        let check = check_bounds(&grid_points, &limit_peaks, &compared);
        let (scanned, sols): (Vec<ScannedCase>, Vec<Vec<GridSolution>>) =
            results.into_iter().unzip();
        (Some(check), scanned, sols)
    };
    let envelope = settings.envelope.map(|mode| {
        let inputs = EnvelopeInputs {
            limits: limits
                .iter()
                .zip(&limits_on_grid)
                .map(|(c, s)| (&c.case, s.as_slice()))
                .collect(),
            scanned: scanned
                .iter()
                .zip(&scanned_on_grid)
                .map(|(c, s)| (&c.case, s.as_slice()))
                .collect(),
            peaks: limits
                .iter()
                .filter_map(|c| c.peak.as_ref().map(|p| (&c.case, p)))
                .collect(),
        };
        envelope(problem, mode, &grid_points, &inputs, &search_settings())
    });
    let per_curve: Vec<(Vec<LoopSet>, Vec<String>)> = limits
        .par_iter()
        .chain(intermediate.par_iter())
        .map(|c| curve_loops(problem, c, &settings.hysteresis))
        .collect();
    let (mut loops, mut loops_missing) = (Vec::new(), Vec::new());
    for (l, m) in per_curve {
        loops.extend(l);
        loops_missing.extend(m);
    }
    Ok(LimitAnalysis {
        limits,
        intermediate,
        grid: grid_points,
        bounds,
        scanned,
        loops,
        loops_missing,
        envelope,
    })
}
