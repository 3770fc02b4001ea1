//! The limits of a nonlinear mode among the multiple steady states friction allows: the mode
//! per initial tangential state (the paper's two-point idea applied to modes, Ferhatoglu &
//! Zucca 2021, §3: m = ±1 on each damper side, and the intermediate cases of `[limits]`), and
//! the band of frequency and damping ratio they span at each amplitude.
//!
//! A contact stuck all period keeps the tangential force its initial state gave it, so the
//! static state, the contact's stiffness and the slip onset depend on m: each case is its own
//! problem ([`LimitCase::apply`]), with its own static state at rest, linear mode and path.

use rayon::prelude::*;

use super::run::{solve, NonlinearModeError, NonlinearModeRun, NonlinearModeSettings};
use crate::analysis::limits::{LimitCase, LimitSettings};
use crate::model::Problem;

/// Most damper sides whose 2^k sign combinations are all solved; above it only the uniform
/// pair m = ±1 is.
pub const MAX_COMBINED_SIDES: usize = 4;

/// Relative width (max − min)/max of the frequency band above which the band is reported as
/// wide.
pub const WIDE_FREQUENCY: f64 = 1e-3;

/// Relative width of the damping-ratio band above which the band is reported as wide.
pub const WIDE_DAMPING: f64 = 0.1;

/// The cases of a mode's limits: every combination of m = ±1 per damper side (the uniform pair
/// first; only that pair above [`MAX_COMBINED_SIDES`] sides), then the intermediate cases of
/// the settings.
pub fn mode_cases(problem: &Problem, settings: &LimitSettings) -> Vec<LimitCase> {
    let k = problem.sides.len();
    let mut cases = vec![
        LimitCase::uniform(problem, 1.0),
        LimitCase::uniform(problem, -1.0),
    ];
    if (2..=MAX_COMBINED_SIDES).contains(&k) {
        for bits in 1..(1usize << k) - 1 {
            let states: Vec<f64> = (0..k)
                .map(|s| if bits >> s & 1 == 1 { -1.0 } else { 1.0 })
                .collect();
            cases.push(LimitCase::per_side(problem, &states));
        }
    }
    cases.extend(settings.intermediate_cases(problem));
    cases
}

/// One case's nonlinear mode, or why it could not be computed.
#[derive(Debug, Clone)]
pub struct ModeCase {
    /// The case.
    pub case: LimitCase,
    /// Its mode.
    pub run: Result<NonlinearModeRun, NonlinearModeError>,
}

/// The band of the cases' modes on a grid of amplitudes at the settings' DOF.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct ModeBand {
    /// First-harmonic amplitude at the DOF (m), log-spaced over the range.
    pub amplitude: Vec<f64>,
    /// Lowest and highest frequency (Hz) over the cases' points at that amplitude (NaN where
    /// no case reaches it).
    pub freq_hz: Vec<[f64; 2]>,
    /// Lowest and highest modal damping ratio.
    pub damping_ratio: Vec<[f64; 2]>,
    /// Cases that reach each amplitude.
    pub cases: Vec<usize>,
    /// Amplitude stretches [from, to] (m) where the band is wide ([`WIDE_FREQUENCY`],
    /// [`WIDE_DAMPING`]).
    pub wide: Vec<[f64; 2]>,
}

/// The modes of every case and their band.
#[derive(Debug, Clone)]
pub struct ModeLimits {
    /// The cases' modes, in [`mode_cases`] order.
    pub cases: Vec<ModeCase>,
    /// Their band.
    pub band: ModeBand,
}

impl ModeLimits {
    /// Why the analysis is incomplete (a case failed or did not reach the range's end).
    pub fn incomplete_reason(&self) -> Option<String> {
        let reasons: Vec<String> = self
            .cases
            .iter()
            .filter_map(|c| match &c.run {
                Ok(r) => r
                    .incomplete_reason()
                    .map(|why| format!("{}: {why}", c.case.name)),
                Err(e) => Some(format!("{}: {e}", c.case.name)),
            })
            .collect();
        (!reasons.is_empty()).then(|| reasons.join("; "))
    }
}

/// Points of the band's amplitude grid.
pub const BAND_POINTS: usize = 101;

/// The nonlinear mode of every case of [`mode_cases`] (in parallel) and their band.
pub fn mode_limits(
    problem: &Problem,
    settings: &NonlinearModeSettings,
    limits: &LimitSettings,
) -> ModeLimits {
    let cases: Vec<ModeCase> = mode_cases(problem, limits)
        .into_par_iter()
        .map(|case| {
            let run = solve(&case.apply(problem), settings);
            ModeCase { case, run }
        })
        .collect();
    let band = band(&cases, settings.amplitude);
    ModeLimits { cases, band }
}

/// The scene's modes: per case of [`mode_limits`] with `[limits]`, else the one mode from the
/// contacts' own initial states (a single case named `scene`), with the band either way.
pub fn scene_modes(
    problem: &Problem,
    settings: &NonlinearModeSettings,
    limits: Option<&LimitSettings>,
) -> ModeLimits {
    if let Some(l) = limits {
        return mode_limits(problem, settings, l);
    }
    let case = LimitCase {
        name: "scene".to_string(),
        contact_states: problem
            .contacts
            .iter()
            .map(|c| c.law.initial_state)
            .collect(),
        second_states: None,
    };
    let cases = vec![ModeCase {
        case,
        run: solve(problem, settings),
    }];
    let band = band(&cases, settings.amplitude);
    ModeLimits { cases, band }
}

/// Values of `y` where the path (log A, y) crosses log A = `at`, linearly interpolated on each
/// segment (a path that folds back in amplitude crosses more than once).
fn crossings(log_a: &[f64], y: &[f64], at: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..log_a.len() {
        let (a0, a1) = (log_a[i - 1], log_a[i]);
        if (a0 - at) * (a1 - at) <= 0.0 && a0 != a1 {
            let t = (at - a0) / (a1 - a0);
            out.push(y[i - 1] + t * (y[i] - y[i - 1]));
        } else if a0 == at {
            out.push(y[i - 1]);
        }
    }
    out
}

/// The band of the cases' modes on [`BAND_POINTS`] log-spaced amplitudes over `range` (m).
pub fn band(cases: &[ModeCase], range: [f64; 2]) -> ModeBand {
    let runs: Vec<&NonlinearModeRun> = cases.iter().filter_map(|c| c.run.as_ref().ok()).collect();
    let paths: Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> = runs
        .iter()
        .map(|r| {
            (
                r.points.iter().map(|p| p.dof_amplitude.log10()).collect(),
                r.points.iter().map(|p| p.freq_hz).collect(),
                r.points.iter().map(|p| p.damping_ratio).collect(),
            )
        })
        .collect();
    let (lo, hi) = (range[0].log10(), range[1].log10());
    let mut out = ModeBand::default();
    let mut wide_from: Option<f64> = None;
    for i in 0..BAND_POINTS {
        let at = lo + (hi - lo) * i as f64 / (BAND_POINTS - 1) as f64;
        let (mut f, mut d, mut count) = (
            [f64::INFINITY, f64::NEG_INFINITY],
            [f64::INFINITY, f64::NEG_INFINITY],
            0,
        );
        for (log_a, freq, damping) in &paths {
            let fs = crossings(log_a, freq, at);
            if fs.is_empty() {
                continue;
            }
            count += 1;
            for v in fs {
                f = [f[0].min(v), f[1].max(v)];
            }
            for v in crossings(log_a, damping, at) {
                d = [d[0].min(v), d[1].max(v)];
            }
        }
        if count == 0 {
            f = [f64::NAN; 2];
            d = [f64::NAN; 2];
        }
        let amplitude = 10f64.powf(at);
        let wide = count > 0
            && ((f[1] - f[0]) > WIDE_FREQUENCY * f[1].abs()
                || (d[1] - d[0]) > WIDE_DAMPING * d[1].abs());
        match (wide, wide_from) {
            (true, None) => wide_from = Some(amplitude),
            (false, Some(from)) => {
                out.wide
                    .push([from, out.amplitude.last().copied().unwrap_or(from)]);
                wide_from = None;
            }
            _ => {}
        }
        out.amplitude.push(amplitude);
        out.freq_hz.push(f);
        out.damping_ratio.push(d);
        out.cases.push(count);
    }
    if let (Some(from), Some(&to)) = (wide_from, out.amplitude.last()) {
        out.wide.push([from, to]);
    }
    out
}
