//! The files of a nonlinear-mode run: `modes_nl.csv` (every point of every case),
//! `modes_nl.json` (status, run metadata, each case's mode with its shape harmonics, the
//! resonance peak and forced response predicted from it for the scene's harmonic loads, and
//! the band of the cases), `modes_nl_band.csv` (with `[limits]`), and the figures
//! `modes_nl_frequency` and `modes_nl_damping` (frequency and modal damping ratio against the
//! first-harmonic amplitude at the mode's DOF, on a logarithmic amplitude axis, one curve per
//! case, with the contact-state strips below), and for FE scenes the mode shape on the mesh
//! (`modes_nl_first.vtu`, `modes_nl_last.vtu`, `modes_nl_max_damping.vtu`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::nonlinear_modes::{
    predicted_frf, predicted_peak, ModeBand, ModeLimits, NonlinearModePoint, NonlinearModeRun,
    PredictedPeak,
};
use crate::fe::VtuError;
use crate::model::Problem;
use crate::report::files::{write_atomic, RunInfo, WriteError};
use crate::report::mesh_results::write_point;
use crate::report::plot::{
    self, figure_files, palette, BackboneFigure, Curve, PlotError, StateRow,
};

/// Header of `modes_nl.csv`: `case`, `modal_amplitude` (kg^½·m), `<dof>_amp` (m), `freq_hz`,
/// `damping_ratio`, `xi_per_s`, `dissipated_energy_j`, `friction_energy_j`,
/// `<contact>_state` per contact, `newton_iterations`, `residual`, and with the error estimate
/// (`accuracy.estimate`, on by default) `freq_trunc_err`, `damping_trunc_err` and
/// `<dof>_amp_trunc_err` (relative changes when the harmonics are raised to 2H + 1, empty
/// where not sized).
pub fn modes_nl_header(problem: &Problem, dof: usize) -> String {
    let dof_name = &problem.model.dof_names[dof];
    let mut s = format!(
        "case,modal_amplitude,{dof_name}_amp,freq_hz,damping_ratio,xi_per_s,dissipated_energy_j,friction_energy_j",
    );
    for c in &problem.contacts {
        let _ = write!(s, ",{}_state", c.name);
    }
    s.push_str(",newton_iterations,residual");
    if problem.analysis.error_estimate.enabled {
        let _ = write!(
            s,
            ",freq_trunc_err,damping_trunc_err,{dof_name}_amp_trunc_err"
        );
    }
    s.push('\n');
    s
}

/// A CSV field of an estimate: empty where it could not be sized.
fn estimate_field(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3e}")
    } else {
        String::new()
    }
}

/// `modes_nl.csv` of the cases' modes (failed cases have no rows).
pub fn modes_nl_csv(problem: &Problem, dof: usize, limits: &ModeLimits) -> String {
    let mut s = modes_nl_header(problem, dof);
    for case in &limits.cases {
        let Ok(run) = &case.run else { continue };
        for p in &run.points {
            let _ = write!(
                s,
                "{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
                case.case.name,
                p.modal_amplitude,
                p.dof_amplitude,
                p.freq_hz,
                p.damping_ratio,
                p.xi,
                p.dissipated_energy,
                p.friction_energy
            );
            for state in &p.states {
                let _ = write!(s, ",{}", state.label());
            }
            let _ = write!(s, ",{},{:.3e}", p.newton_iterations, p.residual);
            if problem.analysis.error_estimate.enabled {
                let values = p.accuracy.map_or([f64::NAN; 3], |a| a.values());
                for v in values {
                    let _ = write!(s, ",{}", estimate_field(v));
                }
            }
            s.push('\n');
        }
    }
    s
}

/// `modes_nl_band.csv`: `<dof>_amp` (m), `freq_min_hz`, `freq_max_hz`, `damping_min`,
/// `damping_max`, `cases` (how many reach the amplitude).
pub fn band_csv(problem: &Problem, dof: usize, band: &ModeBand) -> String {
    let mut s = format!(
        "{}_amp,freq_min_hz,freq_max_hz,damping_min,damping_max,cases\n",
        problem.model.dof_names[dof]
    );
    for i in 0..band.amplitude.len() {
        let (f, d) = (band.freq_hz[i], band.damping_ratio[i]);
        let _ = writeln!(
            s,
            "{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{}",
            band.amplitude[i], f[0], f[1], d[0], d[1], band.cases[i]
        );
    }
    s
}

#[derive(Serialize)]
struct CaseEntry<'a> {
    name: &'a str,
    contact_states: &'a [f64],
    status: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    mode: Option<&'a NonlinearModeRun>,
    /// The resonance peak predicted from the mode for the scene's first-harmonic loads.
    #[serde(skip_serializing_if = "Option::is_none")]
    predicted_peak: Option<PredictedPeak>,
    /// The forced response predicted from the mode near the resonance: (Hz, m at the DOF).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    predicted_frf: Vec<(f64, f64)>,
    /// The largest error estimate over the sized points: frequency, damping ratio, amplitude at
    /// the DOF (relative), and the points that could not be sized.
    #[serde(skip_serializing_if = "Option::is_none")]
    largest_trunc_err: Option<LargestEstimate>,
}

#[derive(Serialize)]
struct LargestEstimate {
    frequency: f64,
    damping_ratio: f64,
    dof_amplitude: f64,
    /// The highest harmonic compared with.
    harmonic: usize,
    /// Points whose estimate could not be formed.
    not_sized: usize,
}

#[derive(Serialize)]
struct ModesFile<'a> {
    info: &'a RunInfo,
    status: &'a str,
    dof: &'a str,
    amplitude_range_m: [f64; 2],
    cases: Vec<CaseEntry<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    band: Option<&'a ModeBand>,
}

/// Writes `modes_nl.csv`, `modes_nl.json` (status `status`) and, when there are several cases,
/// `modes_nl_band.csv` into `dir`.
pub fn write_modes_nl(
    dir: &Path,
    info: &RunInfo,
    status: &str,
    problem: &Problem,
    (dof, range): (usize, [f64; 2]),
    limits: &ModeLimits,
) -> Result<(), WriteError> {
    write_atomic(
        &dir.join("modes_nl.csv"),
        modes_nl_csv(problem, dof, limits).as_bytes(),
    )?;
    let several = limits.cases.len() > 1;
    if several {
        write_atomic(
            &dir.join("modes_nl_band.csv"),
            band_csv(problem, dof, &limits.band).as_bytes(),
        )?;
    }
    let cases = limits
        .cases
        .iter()
        .map(|c| CaseEntry {
            name: &c.case.name,
            contact_states: &c.case.contact_states,
            status: match &c.run {
                Ok(r) => crate::report::files::status_text(r.incomplete_reason().as_deref()),
                Err(e) => format!("failed: {e}"),
            },
            mode: c.run.as_ref().ok(),
            predicted_peak: c.run.as_ref().ok().and_then(|r| predicted_peak(problem, r)),
            predicted_frf: c
                .run
                .as_ref()
                .map(|r| predicted_frf(problem, r))
                .unwrap_or_default(),
            largest_trunc_err: c.run.as_ref().ok().and_then(|r| {
                let ([frequency, damping_ratio, dof_amplitude], not_sized) =
                    crate::analysis::nonlinear_modes::warnings::largest(&r.points)?;
                Some(LargestEstimate {
                    frequency,
                    damping_ratio,
                    dof_amplitude,
                    harmonic: r.points.iter().find_map(|p| p.accuracy)?.harmonic,
                    not_sized,
                })
            }),
        })
        .collect();
    let file = ModesFile {
        info,
        status,
        dof: &problem.model.dof_names[dof],
        amplitude_range_m: range,
        cases,
        band: several.then_some(&limits.band),
    };
    let json =
        serde_json::to_string_pretty(&file).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
    write_atomic(&dir.join("modes_nl.json"), json.as_bytes())
}

/// Writes the mode shape on the mesh (FE scenes) at the first point, the last point and the
/// point of largest modal damping ratio of each case's mode: `modes_nl_first.vtu`,
/// `modes_nl_last.vtu`, `modes_nl_max_damping.vtu`, named `modes_nl_<case>_first.vtu` etc.
/// with several cases. Each holds the static displacement (m), the first-harmonic amplitude
/// per direction (m) and the contact states, as `response_peak.vtu` of a forced response.
/// Returns the files written (none without a mesh or a kept reduction basis).
pub fn write_mode_shapes(
    dir: &Path,
    problem: &Problem,
    limits: &ModeLimits,
) -> Result<Vec<PathBuf>, VtuError> {
    let several = limits.cases.len() > 1;
    let mut written = Vec::new();
    for case in &limits.cases {
        let Ok(run) = &case.run else { continue };
        let most_damped = run
            .points
            .iter()
            .max_by(|a, b| a.damping_ratio.total_cmp(&b.damping_ratio));
        let chosen = [
            ("first", run.points.first()),
            ("last", run.points.last()),
            ("max_damping", most_damped),
        ];
        for (which, point) in chosen {
            let Some(p) = point else { continue };
            let name = if several {
                format!("modes_nl_{}_{which}", case.case.name)
            } else {
                format!("modes_nl_{which}")
            };
            if let Some(path) = write_point(dir, &name, problem, &p.coefficients, &p.states)? {
                written.push(path);
            }
        }
    }
    Ok(written)
}

/// A backbone figure: file stem, y-axis description and the property drawn.
type Property = (&'static str, &'static str, fn(&NonlinearModePoint) -> f64);

/// Draws `modes_nl_frequency` and `modes_nl_damping` (PNG and SVG) into `dir`: one curve per
/// case against the first-harmonic amplitude at the DOF (m) on a logarithmic axis, with one
/// contact-state strip per contact (per case and contact with several cases) below the chart.
pub fn plot_modes_nl(
    dir: &Path,
    title: &str,
    problem: &Problem,
    dof: usize,
    limits: &ModeLimits,
) -> Result<(), PlotError> {
    let runs: Vec<(&str, &NonlinearModeRun)> = limits
        .cases
        .iter()
        .filter_map(|c| c.run.as_ref().ok().map(|r| (c.case.name.as_str(), r)))
        .collect();
    let amps: Vec<Vec<f64>> = runs
        .iter()
        .map(|(_, r)| r.points.iter().map(|p| p.dof_amplitude).collect())
        .collect();
    let x_label = format!(
        "first-harmonic amplitude at {} (m)",
        problem.model.dof_names[dof]
    );
    let single = runs.len() == 1;
    let states: Vec<StateRow> = runs
        .iter()
        .zip(&amps)
        .flat_map(|((name, run), x)| {
            problem
                .contacts
                .iter()
                .enumerate()
                .map(move |(k, c)| StateRow {
                    name: if single {
                        c.name.clone()
                    } else {
                        format!("{name}: {}", c.name)
                    },
                    x,
                    states: run
                        .points
                        .iter()
                        .map(|p| p.states.get(k).copied())
                        .collect(),
                })
        })
        .collect();
    let figures: [Property; 2] = [
        ("modes_nl_frequency", "frequency (Hz)", |p| p.freq_hz),
        (
            "modes_nl_damping",
            "modal damping ratio D = ξ/2ω (-)",
            |p| p.damping_ratio,
        ),
    ];
    for (stem, y_label, value) in figures {
        let ys: Vec<Vec<f64>> = runs
            .iter()
            .map(|(_, r)| r.points.iter().map(value).collect())
            .collect();
        let curves: Vec<Curve> = runs
            .iter()
            .enumerate()
            .map(|(i, (name, _))| Curve {
                label: if single { "" } else { name },
                x: &amps[i],
                y: &ys[i],
                color: palette(i),
                dashed: false,
                markers: false,
            })
            .collect();
        let (png, svg) = figure_files(dir, stem);
        let fig = BackboneFigure {
            title,
            x_label: &x_label,
            y_label,
            curves: &curves,
            states: &states,
        };
        plot::plot_backbone(&fig, &png, &svg)?;
    }
    Ok(())
}
