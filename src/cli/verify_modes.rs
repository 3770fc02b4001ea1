//! `fricbound verify` on a nonlinear-mode scene (`analysis.kind = "nonlinear-modes"`): the mode
//! is computed as `fricbound run` computes it (per case with `[limits]`, without the error
//! estimate), and at each amplitude of `--amplitudes` the point nearest it (first-harmonic
//! amplitude at the mode's DOF, nearest on a log scale) is integrated in time from its state
//! with the artificial damping applied, M q̈ + (C − ξ M) q̇ + K q + f_c = F_static
//! ([`crate::analysis::nonlinear_modes::verify_mode_point`]), over a few periods 2π/ω.
//!
//! A point passes when the motion keeps the mode's first-harmonic amplitudes within
//! [`MODE_TOLERANCE`] and its energy within the harmonics 1..H ([`MODE_NONHARMONIC`]): the
//! motion is then periodic with the mode's period and amplitude. Only a few periods
//! ([`MODE_PERIODS`] by default): −ξ M q̇ also feeds the structure's other, less damped modes,
//! which grow from what the truncated start leaves in them, so the extended periodic motion is
//! periodic but not stable, and an autonomous orbit keeps no phase (its state is not compared
//! period to period). Writes `verify_modes.csv` and `verify_modes.json`; a point that fails
//! the check or cannot be integrated makes the run incomplete (exit 3).

use rayon::prelude::*;

use crate::analysis::limits::LimitSettings;
use crate::analysis::nonlinear_modes::{
    scene_modes, verify_mode_point, NonlinearModePoint, NonlinearModeSettings,
};
use crate::analysis::verify::{PointVerification, VerifySettings};
use crate::model::Problem;
use crate::report::files::write_atomic;

use super::context::{create_dir, CommandError};

/// Largest relative difference of the integrated first-harmonic amplitudes (last period, dt/2)
/// from the mode point's for the point to pass.
pub const MODE_TOLERANCE: f64 = 1e-2;

/// Largest energy of the integrated motion outside the harmonics 1..H, relative to its dynamic
/// part, for the point to pass.
pub const MODE_NONHARMONIC: f64 = 1e-3;

/// Periods integrated by default (`--max-periods` sets another count).
pub const MODE_PERIODS: usize = 4;

/// One verified mode point.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModeVerifyCase {
    /// The case of the mode (`scene`, or the `[limits]` case's name).
    pub case: String,
    /// The amplitude asked at the DOF (m).
    pub amplitude_asked: f64,
    /// The point's first-harmonic amplitude at the DOF (m).
    pub dof_amplitude: f64,
    /// The point's frequency (Hz).
    pub freq_hz: f64,
    /// Its modal damping ratio (–).
    pub damping_ratio: f64,
    /// Its artificial damping ξ (1/s), applied in the integration.
    pub xi: f64,
    /// The time integration (None when it failed or the mode has no point).
    pub verification: Option<PointVerification>,
    /// Whether the point passed ([`MODE_TOLERANCE`], [`MODE_NONHARMONIC`]).
    pub passed: bool,
    /// Why the case failed, if it did.
    pub error: Option<String>,
}

/// What `fricbound verify` did on a nonlinear-mode scene.
#[derive(Debug, Clone)]
pub struct ModeVerifyReport {
    /// Printed table.
    pub text: String,
    /// Why the check is incomplete (a point failed it or could not be integrated).
    pub incomplete: Option<String>,
    /// The cases, per mode case then amplitude.
    pub cases: Vec<ModeVerifyCase>,
}

/// The point of `points` whose amplitude at the DOF is nearest `amplitude` on a log scale.
fn nearest(points: &[NonlinearModePoint], amplitude: f64) -> Option<&NonlinearModePoint> {
    points.iter().min_by(|a, b| {
        let d = |p: &NonlinearModePoint| (p.dof_amplitude / amplitude).ln().abs();
        d(a).total_cmp(&d(b))
    })
}

/// What `fricbound verify` takes on a nonlinear-mode scene.
#[derive(Debug, Clone, Default)]
pub struct ModeVerifyOptions {
    /// First-harmonic amplitudes at the mode's DOF (m) whose nearest points are checked.
    pub amplitudes: Vec<f64>,
    /// Steps per period (default 256·H).
    pub steps_per_period: Option<usize>,
    /// Periods integrated (default [`MODE_PERIODS`]).
    pub periods: Option<usize>,
}

/// Runs `fricbound verify` on the nonlinear-mode scene `problem` (`label` names it).
pub fn run(
    options: &ModeVerifyOptions,
    label: &str,
    problem: &Problem,
    limits: Option<&LimitSettings>,
    dir: &std::path::Path,
) -> Result<ModeVerifyReport, CommandError> {
    if options.amplitudes.is_empty() {
        return Err(CommandError::Study {
            scene: label.to_string(),
            reason: "a nonlinear-mode scene is verified at --amplitudes (first-harmonic \
                     amplitudes at analysis.dof, m, comma separated)"
                .to_string(),
        });
    }
    if let Some(a) = options
        .amplitudes
        .iter()
        .find(|a| !(**a > 0.0 && a.is_finite()))
    {
        return Err(CommandError::Study {
            scene: label.to_string(),
            reason: format!("--amplitudes: {a} is not a positive amplitude (m)"),
        });
    }
    let mode_settings =
        NonlinearModeSettings::of_problem(problem).ok_or_else(|| CommandError::Study {
            scene: label.to_string(),
            reason: "the scene asks for no nonlinear mode".to_string(),
        })?;
    create_dir(dir)?;
    let mut quiet = problem.clone();
    quiet.analysis.error_estimate.enabled = false;
    let modes = scene_modes(&quiet, &mode_settings, limits);
    if limits.is_none() {
        if let Err(source) = &modes.cases[0].run {
            return Err(CommandError::NonlinearMode {
                scene: label.to_string(),
                source: source.clone(),
            });
        }
    }
    let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
    let mut settings = VerifySettings {
        min_periods: MODE_PERIODS,
        max_periods: MODE_PERIODS,
        ..VerifySettings::for_harmonics(h_max)
    };
    if let Some(s) = options.steps_per_period {
        settings.steps_per_period = s;
    }
    if let Some(p) = options.periods {
        settings.max_periods = p;
        settings.min_periods = p;
    }
    let jobs: Vec<(usize, f64)> = (0..modes.cases.len())
        .flat_map(|c| options.amplitudes.iter().map(move |&a| (c, a)))
        .collect();
    let cases: Vec<ModeVerifyCase> = jobs
        .par_iter()
        .map(|&(c, asked)| {
            let case = &modes.cases[c];
            let case_problem = if limits.is_some() {
                case.case.apply(problem)
            } else {
                problem.clone()
            };
            one_point(&case_problem, &case.case.name, &case.run, asked, &settings)
        })
        .collect();
    let dof_name = &problem.model.dof_names[mode_settings.dof];
    let text = table(label, dof_name, &settings, &cases, dir);
    write_atomic(
        &dir.join("verify_modes.csv"),
        csv(dof_name, &cases).as_bytes(),
    )?;
    let json = serde_json::to_string_pretty(&cases).unwrap_or_default();
    write_atomic(&dir.join("verify_modes.json"), json.as_bytes())?;
    let failed: Vec<String> = cases
        .iter()
        .filter(|c| !c.passed)
        .map(|c| {
            let what = match (&c.verification, &c.error) {
                (Some(v), _) => format!(
                    "first harmonic {:.2e} from the mode's, energy outside 1..H {:.1e} \
                     (tolerances {MODE_TOLERANCE:.0e}, {MODE_NONHARMONIC:.0e})",
                    v.hbm_difference, v.fine.nonharmonic_energy
                ),
                (None, Some(e)) => format!("failed: {e}"),
                (None, None) => "failed".to_string(),
            };
            format!("{} at {:.3e} m: {what}", c.case, c.amplitude_asked)
        })
        .collect();
    Ok(ModeVerifyReport {
        text,
        incomplete: (!failed.is_empty()).then(|| format!("mode check: {}", failed.join("; "))),
        cases,
    })
}

/// The check of the point of `run` nearest `asked` (m at the DOF).
fn one_point(
    problem: &Problem,
    case: &str,
    run: &Result<
        crate::analysis::nonlinear_modes::NonlinearModeRun,
        crate::analysis::nonlinear_modes::NonlinearModeError,
    >,
    asked: f64,
    settings: &VerifySettings,
) -> ModeVerifyCase {
    let mut out = ModeVerifyCase {
        case: case.to_string(),
        amplitude_asked: asked,
        dof_amplitude: f64::NAN,
        freq_hz: f64::NAN,
        damping_ratio: f64::NAN,
        xi: f64::NAN,
        verification: None,
        passed: false,
        error: None,
    };
    let point = match run {
        Ok(r) => nearest(&r.points, asked),
        Err(e) => {
            out.error = Some(format!("the mode: {e}"));
            return out;
        }
    };
    let Some(p) = point else {
        out.error = Some("the mode has no point".to_string());
        return out;
    };
    out.dof_amplitude = p.dof_amplitude;
    out.freq_hz = p.freq_hz;
    out.damping_ratio = p.damping_ratio;
    out.xi = p.xi;
    match verify_mode_point(problem, p, settings) {
        Ok(v) => {
            out.passed =
                v.hbm_difference <= MODE_TOLERANCE && v.fine.nonharmonic_energy <= MODE_NONHARMONIC;
            out.verification = Some(v);
        }
        Err(e) => out.error = Some(e.to_string()),
    }
    out
}

/// `verify_modes.csv`: `case`, `amplitude_asked`, `<dof>_amp`, `freq_hz`, `damping_ratio`,
/// `xi_per_s`, `periods`, `rel_diff` (first harmonic from the mode's), `dt_change`,
/// `nonharmonic_energy`, `passed`, `error`.
fn csv(dof_name: &str, cases: &[ModeVerifyCase]) -> String {
    let mut s = format!(
        "case,amplitude_asked,{dof_name}_amp,freq_hz,damping_ratio,xi_per_s,periods,rel_diff,dt_change,nonharmonic_energy,passed,error\n"
    );
    for c in cases {
        let v = c.verification.as_ref();
        let opt = |x: Option<f64>| x.map(|x| format!("{x:.6e}")).unwrap_or_default();
        s.push_str(&format!(
            "{},{:e},{:e},{},{:e},{:e},{},{},{},{},{},{}\n",
            c.case,
            c.amplitude_asked,
            c.dof_amplitude,
            c.freq_hz,
            c.damping_ratio,
            c.xi,
            v.map(|v| v.fine.periods.to_string()).unwrap_or_default(),
            opt(v.map(|v| v.hbm_difference)),
            opt(v.map(|v| v.dt_change)),
            opt(v.map(|v| v.fine.nonharmonic_energy)),
            c.passed,
            c.error.clone().unwrap_or_default().replace(',', ";"),
        ));
    }
    s
}

/// The printed table.
fn table(
    label: &str,
    dof_name: &str,
    settings: &VerifySettings,
    cases: &[ModeVerifyCase],
    dir: &std::path::Path,
) -> String {
    let mut text = format!(
        "{label}: nonlinear-mode points by time integration with the artificial damping \
         applied (Newmark average acceleration, {} steps/period and twice that, {} periods)\n",
        settings.steps_per_period, settings.max_periods
    );
    text.push_str(&format!(
        "case             {dof_name}_amp      freq_hz      D           rel_diff   dt_change  outside_1..H passed\n"
    ));
    for c in cases {
        match &c.verification {
            Some(v) => text.push_str(&format!(
                "{:<16} {:<12.4e} {:<12.4} {:<11.4e} {:<10.3e} {:<10.3e} {:<12.1e} {}\n",
                c.case,
                c.dof_amplitude,
                c.freq_hz,
                c.damping_ratio,
                v.hbm_difference,
                v.dt_change,
                v.fine.nonharmonic_energy,
                c.passed
            )),
            None => text.push_str(&format!(
                "{:<16} {:<12.4e} failed: {}\n",
                c.case,
                c.amplitude_asked,
                c.error.clone().unwrap_or_default()
            )),
        }
    }
    text.push_str(&format!("written to {}\n", dir.display()));
    text
}
