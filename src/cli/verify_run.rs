//! `fricbound verify`: the time-integration check of harmonic-balance points.
//!
//! For each frequency: the HBM point is solved by Newton from the stuck linear guess (the
//! open-contact guess if that fails), its Hill stability computed, and the equations of motion
//! integrated from it ([`crate::analysis::verify::verify_point`], at dt and dt/2). Cases run in
//! parallel (rayon) with a progress bar. Writes `verify.csv`, `verify.json` and one time-history
//! figure per frequency (`verify_<freq>Hz.png/.svg`: the output DOFs over the last integrated
//! period against the HBM's periodic motion). A nonlinear-mode scene is verified at mode points
//! instead ([`super::verify_modes`]).

use std::f64::consts::PI;
use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use crate::analysis::frf::PointSolver;
use crate::analysis::linear;
use crate::analysis::monodromy::{self, MonodromySettings, MonodromyStability};
use crate::analysis::stability;
use crate::analysis::verify::{self, PointVerification, VerifySettings};
use crate::report::files::write_atomic;
use crate::report::plot::{self, figure_files, palette, Curve};

use super::context::{create_dir, default_out_dir, load_scene, CommandError};

/// Relative first-harmonic difference from the HBM point (last integrated period, dt/2) below
/// which a motion started on the HBM point counts as having stayed on it, settled or not (a
/// stable point with a slowly decaying mode, e.g. −0.17 1/s, need not settle within the budget).
pub const STAY_TOLERANCE: f64 = 1e-3;

/// Where each time integration starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StartFrom {
    /// On the harmonic-balance solution at τ = 0 (sliders from the AFT's march).
    #[default]
    Hbm,
    /// At rest at the static equilibrium in which every contact carries T = m μ N
    /// ([`crate::analysis::verify::static_state`]).
    Static,
}

/// Options of `fricbound verify`.
#[derive(Debug, Clone, Default)]
pub struct VerifyOptions {
    /// Scene file (the built-in paper scene when None).
    pub scene: Option<PathBuf>,
    /// Excitation frequencies (Hz).
    pub freqs: Vec<f64>,
    /// Output folder (default: `out/<scene>/verify`).
    pub out: Option<PathBuf>,
    /// Scene overrides.
    pub overrides: Vec<String>,
    /// Steps per period (default 256·H).
    pub steps_per_period: Option<usize>,
    /// Period budget (default 300).
    pub max_periods: Option<usize>,
    /// No progress bar.
    pub quiet: bool,
    /// Where the integrations start.
    pub from: StartFrom,
    /// Initial tangential states m ∈ [−1, 1], each applied to every contact (one case per
    /// frequency and state); empty: the scene's own `initial_state` per contact.
    pub initial_states: Vec<f64>,
    /// Nonlinear-mode scenes: first-harmonic amplitudes at the mode's DOF (m) whose nearest
    /// points are checked ([`super::verify_modes`]).
    pub amplitudes: Vec<f64>,
}

/// One verified frequency.
#[derive(Debug, Clone, serde::Serialize)]
pub struct VerifyCase {
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Initial tangential state m of every contact (None: the scene's).
    pub initial_state: Option<f64>,
    /// Where the integration started.
    pub from: StartFrom,
    /// HBM first-harmonic amplitude of each output (m).
    pub hbm_amplitudes: Vec<f64>,
    /// Hill's verdict at the HBM point (None if it could not be computed).
    pub hill_stable: Option<bool>,
    /// Leading Floquet exponent's real part (1/s).
    pub floquet_re: Option<f64>,
    /// The time integration (None when the case failed; see `error`).
    pub verification: Option<PointVerification>,
    /// Whether the motion stayed within [`STAY_TOLERANCE`] of the HBM point.
    pub stays: Option<bool>,
    /// Whether Hill's verdict agrees (stable ⇔ stays).
    pub hill_agrees: Option<bool>,
    /// Floquet multipliers of the time integration's periodic orbit through the HBM point
    /// (shooting from its state, monodromy matrix of the period map; whatever `from` is).
    pub monodromy: Option<MonodromyStability>,
    /// Whether Hill's verdict equals the monodromy's.
    pub hill_monodromy_agree: Option<bool>,
    /// Why the monodromy could not be computed, if it could not.
    pub monodromy_error: Option<String>,
    /// `--from static`: the curve (m = −1, +1, the scene's uniform intermediate m, as
    /// `m=<value>`, and its `[[limits.cases]]`, by name) whose HBM point at this frequency is
    /// nearest to the motion at the end of the integration.
    pub reached_curve: Option<String>,
    /// `--from static`: the largest relative difference of the output amplitudes (last
    /// period, dt/2) from that curve's HBM point.
    pub reached_distance: Option<f64>,
    /// `--from static`: the relative difference from every compared curve's HBM point, as
    /// (label, difference).
    pub curve_distances: Vec<(String, f64)>,
    /// Why the case failed, if it did.
    pub error: Option<String>,
}

/// What `fricbound verify` did.
#[derive(Debug, Clone)]
pub struct VerifyReport {
    /// Printed table.
    pub text: String,
    /// Why the run is incomplete (a case failed or did not settle).
    pub incomplete: Option<String>,
    /// The cases in frequency order (forced-response scenes).
    pub cases: Vec<VerifyCase>,
    /// The checked mode points (nonlinear-mode scenes).
    pub mode_cases: Vec<super::verify_modes::ModeVerifyCase>,
}

/// The HBM point at `freq` (Hz) by Newton from the stuck linear guess, or from the
/// open-contact guess if that fails.
fn hbm_point(
    problem: &crate::model::Problem,
    freq: f64,
) -> Option<(PointSolver<'_>, crate::analysis::frf::FrfPoint)> {
    let mut solver = PointSolver::new(problem).ok()?;
    let set = solver.system().unknowns().clone();
    let omega = 2.0 * PI * freq;
    let point = [linear::stuck_guess, linear::open_guess]
        .iter()
        .filter_map(|g| g(problem, &set, omega).ok())
        .find_map(|guess| solver.solve(&guess, freq).ok())?;
    Some((solver, point))
}

/// Relative distance of `time` amplitudes from `hbm` ones: the largest over outputs.
fn relative_distance(time: &[f64], hbm: &[f64]) -> f64 {
    time.iter()
        .zip(hbm)
        .map(|(t, h)| (t - h).abs() / h.abs().max(1e-300))
        .fold(0.0_f64, f64::max)
}

/// A curve a `--from static` case is compared with: its label in `reached_curve` (`m=<value>`
/// for a uniform m, the case's name for a per-side or per-point `[[limits.cases]]` entry) and
/// the initial state of every contact.
#[derive(Debug, Clone)]
pub struct ComparedCurve {
    /// `m=<value>` or the case name.
    pub label: String,
    /// m of each contact point, in the problem's contact order.
    pub contact_states: Vec<f64>,
}

/// For each curve of `curves`, the distance of `time` amplitudes from that curve's HBM point
/// at `freq` (curves whose point does not converge are left out).
fn curve_distances(
    problem: &crate::model::Problem,
    freq: f64,
    curves: &[ComparedCurve],
    time: &[f64],
) -> Vec<(String, f64)> {
    curves
        .iter()
        .filter_map(|curve| {
            let mut pm = problem.clone();
            pm.contacts
                .iter_mut()
                .zip(&curve.contact_states)
                .for_each(|(c, m)| c.law.initial_state = *m);
            let (_, point) = hbm_point(&pm, freq)?;
            Some((
                curve.label.clone(),
                relative_distance(time, &point.amplitudes),
            ))
        })
        .collect()
}

/// The curves a `--from static` case is compared with: the two limits (m = ±1), the scene's
/// uniform intermediate states (m = 0 too when the scene has no limit analysis) and its
/// per-side or per-point `[[limits.cases]]`.
pub fn compared_curves(
    problem: &crate::model::Problem,
    limits: Option<&crate::analysis::limits::run::LimitSettings>,
) -> Vec<ComparedCurve> {
    let mut ms: Vec<f64> = vec![-1.0, 1.0];
    match limits {
        Some(l) => ms.extend(l.intermediate.iter().copied()),
        None => ms.push(0.0),
    }
    ms.sort_by(f64::total_cmp);
    ms.dedup();
    let mut curves: Vec<ComparedCurve> = ms
        .into_iter()
        .map(|m| ComparedCurve {
            label: format!("m={m}"),
            contact_states: vec![m; problem.contacts.len()],
        })
        .collect();
    if let Some(l) = limits {
        for spec in &l.cases {
            let case = crate::analysis::limits::case::LimitCase::from_spec(problem, spec);
            curves.push(ComparedCurve {
                label: case.name,
                contact_states: case.contact_states,
            });
        }
    }
    curves
}

fn one_case(
    scene_problem: &crate::model::Problem,
    freq: f64,
    initial_state: Option<f64>,
    from: StartFrom,
    settings: &VerifySettings,
    fig_dir: &std::path::Path,
    curves: &[ComparedCurve],
) -> VerifyCase {
    let mut problem_m = scene_problem.clone();
    if let Some(m) = initial_state {
        for c in &mut problem_m.contacts {
            c.law.initial_state = m;
        }
    }
    let problem = &problem_m;
    let mut case = VerifyCase {
        freq_hz: freq,
        initial_state,
        from,
        hbm_amplitudes: Vec::new(),
        hill_stable: None,
        floquet_re: None,
        verification: None,
        stays: None,
        hill_agrees: None,
        monodromy: None,
        hill_monodromy_agree: None,
        monodromy_error: None,
        reached_curve: None,
        reached_distance: None,
        curve_distances: Vec::new(),
        error: None,
    };
    let omega = 2.0 * PI * freq;
    if let Err(e) = PointSolver::new(problem) {
        case.error = Some(e.to_string());
        return case;
    }
    let Some((mut solver, point)) = hbm_point(problem, freq) else {
        case.error = Some(format!("harmonic balance did not converge at {freq} Hz"));
        return case;
    };
    let set = solver.system().unknowns().clone();
    case.hbm_amplitudes = point.amplitudes.clone();
    if let Ok(s) = stability::point_stability(solver.system(), &point.coefficients, omega) {
        case.hill_stable = Some(s.stable);
        case.floquet_re = Some(s.floquet_re);
    }
    let hbm_start = verify::hbm_state(
        problem,
        &set,
        &point.coefficients,
        freq,
        settings.steps_per_period,
    );
    match hbm_start.as_ref().map_err(|e| e.clone()).and_then(|s| {
        monodromy::monodromy_stability(problem, freq, s, settings, &MonodromySettings::default())
    }) {
        Ok(m) => {
            case.hill_monodromy_agree = case.hill_stable.map(|h| h == m.stable);
            case.monodromy = Some(m);
        }
        Err(e) => case.monodromy_error = Some(e.to_string()),
    }
    let start = match from {
        StartFrom::Hbm => hbm_start,
        StartFrom::Static => verify::static_state(problem),
    };
    let outcome = start.and_then(|start| {
        verify::verify_from(
            problem,
            &start,
            set.max_harmonic(),
            &point.amplitudes,
            freq,
            settings,
        )
    });
    match outcome {
        Ok(v) => {
            let stays = v.hbm_difference < STAY_TOLERANCE;
            case.stays = Some(stays);
            case.hill_agrees = case.hill_stable.map(|h| h == stays);
            let stem = match initial_state {
                Some(m) => format!("verify_{freq}Hz_m{m}"),
                None => format!("verify_{freq}Hz"),
            };
            if from == StartFrom::Static {
                case.curve_distances = curve_distances(problem, freq, curves, &v.fine.amplitudes);
                if let Some((label, d)) = case
                    .curve_distances
                    .iter()
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                {
                    case.reached_curve = Some(label.clone());
                    case.reached_distance = Some(*d);
                }
            }
            let _ = time_history_figure(problem, &set, &point.coefficients, &v, fig_dir, &stem);
            let _ = phase_figure(problem, &v, fig_dir, &format!("{stem}_phase"));
            let _ = hysteresis_figure(problem, &v, fig_dir, &format!("{stem}_hysteresis"));
            case.verification = Some(v);
        }
        Err(e) => case.error = Some(e.to_string()),
    }
    case
}

/// The output DOFs over the last integrated period (fine dt) against the HBM motion.
fn time_history_figure(
    problem: &crate::model::Problem,
    set: &crate::contact::harmonic::HarmonicSet,
    x: &[f64],
    v: &PointVerification,
    dir: &std::path::Path,
    stem: &str,
) -> Result<(), plot::PlotError> {
    let n = problem.model.n_dofs();
    let steps = v.fine.steps_per_period;
    let tau: Vec<f64> = (0..steps)
        .map(|k| 2.0 * PI * k as f64 / steps as f64)
        .collect();
    let mut owned: Vec<(String, Vec<f64>, bool)> = Vec::new();
    for (o, &d) in problem.outputs.iter().enumerate() {
        let name = &problem.model.dof_names[d];
        let coef: Vec<f64> = (0..set.n_blocks()).map(|j| x[j * n + d]).collect();
        let hbm: Vec<f64> = tau.iter().map(|&t| set.evaluate(&coef, t)).collect();
        owned.push((
            format!("{name} time integration"),
            v.fine.last_period[o].clone(),
            false,
        ));
        owned.push((format!("{name} HBM"), hbm, true));
    }
    let curves: Vec<Curve> = owned
        .iter()
        .enumerate()
        .map(|(i, (label, y, dashed))| Curve {
            label,
            x: &tau,
            y,
            color: palette(i / 2),
            dashed: *dashed,
            markers: false,
        })
        .collect();
    let (png, svg) = figure_files(dir, stem);
    plot::plot_lines(
        &format!(
            "Time integration vs HBM at {} Hz (last of {} periods)",
            v.fine.freq_hz, v.fine.periods
        ),
        "τ = ωt (rad)",
        "displacement (m)",
        false,
        &curves,
        &png,
        &svg,
    )
}

/// Phase portrait: q̇ against q of each output over the last integrated period (fine dt).
fn phase_figure(
    problem: &crate::model::Problem,
    v: &PointVerification,
    dir: &std::path::Path,
    stem: &str,
) -> Result<(), plot::PlotError> {
    let closed = |x: &[f64]| -> Vec<f64> { x.iter().chain(x.first()).copied().collect() };
    let owned: Vec<(String, Vec<f64>, Vec<f64>)> = problem
        .outputs
        .iter()
        .enumerate()
        .map(|(o, &d)| {
            (
                problem.model.dof_names[d].clone(),
                closed(&v.fine.last_period[o]),
                closed(&v.fine.last_period_velocity[o]),
            )
        })
        .collect();
    let curves: Vec<Curve> = owned
        .iter()
        .enumerate()
        .map(|(i, (label, x, y))| Curve {
            label,
            x,
            y,
            color: palette(i),
            dashed: false,
            markers: false,
        })
        .collect();
    let (png, svg) = figure_files(dir, stem);
    plot::plot_lines(
        &format!(
            "Phase portrait at {} Hz (last of {} periods)",
            v.fine.freq_hz, v.fine.periods
        ),
        "displacement q (m)",
        "velocity dq/dt (m/s)",
        false,
        &curves,
        &png,
        &svg,
    )
}

/// Hysteresis loops: T against the tangential relative displacement u of every contact over
/// the last integrated period (fine dt); a 2D point draws two loops, T₁ against u₁ (labelled
/// with its name) and T₂ against u₂ (`<name> t2`).
fn hysteresis_figure(
    problem: &crate::model::Problem,
    v: &PointVerification,
    dir: &std::path::Path,
    stem: &str,
) -> Result<(), plot::PlotError> {
    let second_labels: Vec<String> = problem
        .contacts
        .iter()
        .map(|c| format!("{} t2", c.name))
        .collect();
    let loops: Vec<plot::Loop> = problem
        .contacts
        .iter()
        .zip(&v.fine.contact_loops)
        .zip(&second_labels)
        .flat_map(|((c, l), second)| {
            let first = (c.name.as_str(), &l.u, &l.t);
            let other = (!l.u2.is_empty()).then_some((second.as_str(), &l.u2, &l.t2));
            std::iter::once(first).chain(other)
        })
        .enumerate()
        .map(|(i, (label, u, t))| plot::Loop {
            label,
            u,
            t,
            color: palette(i),
        })
        .collect();
    let (png, svg) = figure_files(dir, stem);
    plot::plot_hysteresis(
        &format!(
            "Contact hysteresis at {} Hz (time integration, last of {} periods)",
            v.fine.freq_hz, v.fine.periods
        ),
        &loops,
        &png,
        &svg,
    )
}

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// Refuses, on a nonlinear-mode scene, the options that belong to forced-response scenes.
fn refuse_frf_options(label: &str, options: &VerifyOptions) -> Result<(), CommandError> {
    let used = [
        (!options.freqs.is_empty(), "--freqs"),
        (!options.initial_states.is_empty(), "--initial-states"),
        (options.from != StartFrom::Hbm, "--from static"),
    ];
    match used.iter().find(|(on, _)| *on) {
        Some((_, what)) => Err(CommandError::Study {
            scene: label.to_string(),
            reason: format!(
                "{what} is for forced-response scenes; a nonlinear-mode scene is verified at \
                 --amplitudes (m at analysis.dof)"
            ),
        }),
        None => Ok(()),
    }
}

/// Runs `fricbound verify`.
pub fn run(options: &VerifyOptions) -> Result<VerifyReport, CommandError> {
    let (label, _scene, problem, limits) =
        load_scene(options.scene.as_deref(), &options.overrides)?;
    let dir = options.out.clone().unwrap_or_else(|| {
        default_out_dir(options.scene.as_deref(), &options.overrides).join("verify")
    });
    if problem.analysis.nonlinear_modes.is_some() {
        refuse_frf_options(&label, options)?;
        let mode_options = super::verify_modes::ModeVerifyOptions {
            amplitudes: options.amplitudes.clone(),
            steps_per_period: options.steps_per_period,
            periods: options.max_periods,
        };
        let r = super::verify_modes::run(&mode_options, &label, &problem, limits.as_ref(), &dir)?;
        return Ok(VerifyReport {
            text: r.text,
            incomplete: r.incomplete,
            cases: Vec::new(),
            mode_cases: r.cases,
        });
    }
    if options.freqs.is_empty() || !options.amplitudes.is_empty() {
        return Err(CommandError::Study {
            scene: label,
            reason: "a forced-response scene is verified at --freqs (Hz); --amplitudes is for \
                     nonlinear-mode scenes"
                .to_string(),
        });
    }
    let curves = compared_curves(&problem, limits.as_ref());
    create_dir(&dir)?;
    let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
    let mut settings = VerifySettings::for_harmonics(h_max);
    if let Some(s) = options.steps_per_period {
        settings.steps_per_period = s;
    }
    if let Some(p) = options.max_periods {
        settings.max_periods = p;
    }
    let states: Vec<Option<f64>> = if options.initial_states.is_empty() {
        vec![None]
    } else {
        options.initial_states.iter().map(|&m| Some(m)).collect()
    };
    let jobs: Vec<(f64, Option<f64>)> = options
        .freqs
        .iter()
        .flat_map(|&f| states.iter().map(move |&m| (f, m)))
        .collect();
    let bar = (!options.quiet).then(|| {
        let b = ProgressBar::new(jobs.len() as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} verify",
            )
            .expect("static template"),
        );
        b
    });
    let cases: Vec<VerifyCase> = jobs
        .par_iter()
        .map(|&(f, m)| {
            let c = one_case(&problem, f, m, options.from, &settings, &dir, &curves);
            if let Some(b) = &bar {
                b.inc(1);
            }
            c
        })
        .collect();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let outputs: Vec<String> = problem
        .outputs
        .iter()
        .map(|&d| problem.model.dof_names[d].clone())
        .collect();
    let mut csv = String::from("freq_hz,initial_state,from");
    for o in &outputs {
        csv.push_str(&format!(",{o}_hbm_amp,{o}_time_amp"));
    }
    csv.push_str(",rel_diff,dt_change,periods,settled,nonharmonic_energy,hill_stable,floquet_re,stays,hill_agrees,monodromy_stable,monodromy_re,monodromy_freq_hz,neutral_sliders,grazing_nudged,orbit_defect,hill_monodromy_agree,reached_curve,reached_distance,error\n");
    let mut text = format!(
        "{label}: time integration (Newmark average acceleration, {} steps/period and twice that)\n",
        settings.steps_per_period
    );
    text.push_str(
        "freq_hz  m     rel_diff   dt_change  periods settled hill_stable stays agrees monodromy_re hill=monodromy\n",
    );
    for c in &cases {
        csv.push_str(&format!(
            "{},{},{}",
            c.freq_hz,
            opt(c.initial_state),
            match c.from {
                StartFrom::Hbm => "hbm",
                StartFrom::Static => "static",
            }
        ));
        for (o, _) in outputs.iter().enumerate() {
            let t = c
                .verification
                .as_ref()
                .map(|v| v.fine.amplitudes[o].to_string())
                .unwrap_or_default();
            csv.push_str(&format!(
                ",{},{}",
                c.hbm_amplitudes
                    .get(o)
                    .map(|a| a.to_string())
                    .unwrap_or_default(),
                t
            ));
        }
        let v = c.verification.as_ref();
        let mono = c.monodromy.as_ref();
        csv.push_str(&format!(
            ",{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            opt(v.map(|v| v.hbm_difference)),
            opt(v.map(|v| v.dt_change)),
            opt(v.map(|v| v.fine.periods)),
            opt(v.map(|v| v.fine.settled)),
            opt(v.map(|v| v.fine.nonharmonic_energy)),
            opt(c.hill_stable),
            opt(c.floquet_re),
            opt(c.stays),
            opt(c.hill_agrees),
            opt(mono.map(|m| m.stable)),
            opt(mono.map(|m| m.floquet_re)),
            opt(mono.map(|m| m.floquet_freq_hz)),
            mono.map(|m| {
                m.neutral_sliders
                    .iter()
                    .map(|&i| problem.contacts[i].name.clone())
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .unwrap_or_default(),
            mono.map(|m| {
                m.grazing_nudged
                    .iter()
                    .map(|&i| problem.contacts[i].name.clone())
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .unwrap_or_default(),
            opt(mono.map(|m| m.periodicity_defect)),
            opt(c.hill_monodromy_agree),
            c.reached_curve.clone().unwrap_or_default(),
            opt(c.reached_distance),
            c.error.clone().unwrap_or_default().replace(',', ";"),
        ));
        match v {
            Some(v) => text.push_str(&format!(
                "{:<8} {:<5} {:<10.3e} {:<10.3e} {:<7} {:<7} {:<11} {:<5} {:<6} {:<12} {}\n",
                c.freq_hz,
                opt(c.initial_state),
                v.hbm_difference,
                v.dt_change,
                v.fine.periods,
                v.fine.settled,
                opt(c.hill_stable),
                opt(c.stays),
                opt(c.hill_agrees),
                mono.map(|m| format!("{:.3}", m.floquet_re))
                    .unwrap_or_else(|| "-".into()),
                opt(c.hill_monodromy_agree)
            )),
            None => text.push_str(&format!(
                "{:<8} {:<5} failed: {}\n",
                c.freq_hz,
                opt(c.initial_state),
                c.error.clone().unwrap_or_default()
            )),
        }
    }
    write_atomic(&dir.join("verify.csv"), csv.as_bytes())?;
    let json = serde_json::to_string_pretty(&cases).unwrap_or_default();
    write_atomic(&dir.join("verify.json"), json.as_bytes())?;
    text.push_str(&format!("written to {}\n", dir.display()));
    Ok(VerifyReport {
        text,
        incomplete: verify::incomplete_reason(cases.iter().map(|c| {
            (
                verify::case_name(c.freq_hz, c.initial_state),
                c.verification.as_ref(),
            )
        })),
        cases,
        mode_cases: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_starts_are_compared_with_the_per_side_cases_too() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/paper-wedge/fig16c.toml");
        let (_, _, problem, limits) = load_scene(Some(&path), &[]).unwrap();
        let curves = compared_curves(&problem, limits.as_ref());
        let labels: Vec<&str> = curves.iter().map(|c| c.label.as_str()).collect();
        assert_eq!(
            labels,
            ["m=-1", "m=-0.5", "m=0", "m=0.5", "m=1", "left+0.5"],
            "{labels:?}"
        );
        // The per-side case: m = +0.5 on the blade-1 side, the scene's own state elsewhere.
        let side_case = &curves[5].contact_states;
        for (c, m) in problem.contacts.iter().zip(side_case) {
            let expected = if problem.sides[c.side].name == "left" {
                0.5
            } else {
                c.law.initial_state
            };
            assert_eq!(*m, expected, "contact {}", c.name);
        }
    }
}
