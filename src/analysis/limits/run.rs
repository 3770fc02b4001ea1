//! The limit analysis itself: its settings, the run (limit, intermediate and scanned curves,
//! grid classification, bound check, hysteresis loops) and the size of the variability found.

use rayon::prelude::*;

use crate::model::Problem;

use super::bounds::{check_bounds, BoundCheck};
use super::case::{scan_cases, two_point_cases, CaseSpec, LimitCase};
use super::curve::{solve_case, CaseCurve};
use super::error::LimitError;
use super::grid::{classify, on_grid, GridPoint};
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

/// Everything a limit analysis computes.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitAnalysis {
    /// The two limit curves (m = +1, m = −1 on every side).
    pub limits: Vec<CaseCurve>,
    /// Intermediate curves.
    pub intermediate: Vec<CaseCurve>,
    /// Common grid with classification and band.
    pub grid: Vec<GridPoint>,
    /// Bound check of the scan (None when no scan was asked for).
    pub bounds: Option<BoundCheck>,
    /// Scanned cases with their peaks.
    pub scan_peaks: Vec<(LimitCase, Peak)>,
    /// Requested hysteresis loops.
    pub loops: Vec<LoopSet>,
    /// Requested loops that could not be computed (no solution of the curve there), as text.
    pub loops_missing: Vec<String>,
}

/// Size of the variability of one limit analysis (first output DOF).
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
    /// Widest band, max over the grid of upper − lower limit (m).
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
        let (a, b) = (&self.limits[0].peak, &self.limits[1].peak);
        let (upper_peak, lower_peak) = (a.amplitude.max(b.amplitude), a.amplitude.min(b.amplitude));
        let (f_hi, f_lo) = (a.freq_hz.max(b.freq_hz), a.freq_hz.min(b.freq_hz));
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
}

/// Runs the two-point limit analysis, intermediate curves, the bound scan and the requested
/// hysteresis loops. Curves are solved in parallel (rayon); results do not depend on the
/// thread count.
///
/// `on_curve` is called as each limit, intermediate or scanned curve is solved (from worker
/// threads), so callers can write results as they come.
pub fn analyse<F>(
    problem: &Problem,
    settings: &LimitSettings,
    on_curve: F,
) -> Result<LimitAnalysis, LimitError>
where
    F: Fn(&CaseCurve) + Sync,
{
    let a = &problem.analysis.continuation;
    let n = settings.grid_points.max(2);
    let grid: Vec<f64> = (0..n)
        .map(|i| a.freq_start_hz + (a.freq_end_hz - a.freq_start_hz) * i as f64 / (n - 1) as f64)
        .collect();
    let window = settings.peak_window_hz;
    let limit_cases = two_point_cases(problem);
    let intermediate_cases = settings.intermediate_cases(problem);
    let scanned_cases = scan_cases(problem, &settings.bound_scan);

    // Solves one case and hands the curve to `on_curve` at once.
    let solve = |c: &LimitCase| -> Result<CaseCurve, LimitError> {
        let curve = solve_case(problem, c, window)?;
        on_curve(&curve);
        Ok(curve)
    };
    let solve_all = |cases: &[LimitCase]| -> Result<Vec<CaseCurve>, LimitError> {
        cases.par_iter().map(solve).collect()
    };
    let limits = solve_all(&limit_cases)?;
    let intermediate = solve_all(&intermediate_cases)?;
    let limits_on_grid: Vec<_> = limits
        .par_iter()
        .map(|c| on_grid(problem, &c.case, &c.run.points, &grid))
        .collect::<Result<_, _>>()?;
    let grid_points = classify(problem, &grid, &limits_on_grid);

    let (bounds, scan_peaks) = if scanned_cases.is_empty() {
        (None, Vec::new())
    } else {
        let scanned: Vec<_> = scanned_cases
            .par_iter()
            .map(|c| {
                let curve = solve(c)?;
                let sols = on_grid(problem, c, &curve.run.points, &grid)?;
                Ok((c.clone(), sols, curve.peak))
            })
            .collect::<Result<_, LimitError>>()?;
        let limit_peaks: Vec<f64> = limits.iter().map(|c| c.peak.amplitude).collect();
        let check = check_bounds(&grid_points, &limit_peaks, &scanned);
        (
            Some(check),
            scanned.into_iter().map(|(c, _, p)| (c, p)).collect(),
        )
    };
    let per_curve: Vec<(Vec<LoopSet>, Vec<String>)> = limits
        .par_iter()
        .chain(intermediate.par_iter())
        .map(|c| curve_loops(problem, c, &settings.hysteresis))
        .collect::<Result<_, _>>()?;
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
        scan_peaks,
        loops,
        loops_missing,
    })
}
