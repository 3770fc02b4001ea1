//! `fricbound._native.nonlinear_modes`: the scene's nonlinear mode (or, with `[limits]`, one
//! per initial tangential state, [`fricbound::analysis::nonlinear_modes::mode_limits`]) as a
//! dict of numpy arrays per case, with the band and the peak predicted for the scene's loads.

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use fricbound::analysis::nonlinear_modes::{self as nm, NonlinearModeRun, NonlinearModeSettings};
use fricbound::model::Problem;

use crate::solve::{in_background, load};
use crate::SolveError;

/// The scene's nonlinear mode(s) by EPMC: `analysis.kind` must be `"nonlinear-modes"`.
#[pyfunction]
pub fn nonlinear_modes<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let (_, problem, limits) = load(text, label, &overrides)?;
    let settings = NonlinearModeSettings::of_problem(&problem).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{label}: field `analysis.kind`: nonlinear_modes needs analysis.kind = \"nonlinear-modes\""
        ))
    })?;
    let result = in_background(py, None, |_| {
        nm::scene_modes(&problem, &settings, limits.as_ref())
    })?;
    if limits.is_none() {
        if let Err(e) = &result.cases[0].run {
            return Err(SolveError::new_err(format!("{label}: {e}")));
        }
    }
    let d = PyDict::new(py);
    crate::convert::problem_names(&d, &problem)?;
    d.set_item("dof", problem.model.dof_names[settings.dof].clone())?;
    d.set_item("amplitude_range", settings.amplitude.to_vec())?;
    d.set_item(
        "status",
        match result.incomplete_reason() {
            None => "complete".to_string(),
            Some(r) => format!("incomplete: {r}"),
        },
    )?;
    let cases = PyDict::new(py);
    let mut names = Vec::new();
    for c in &result.cases {
        names.push(c.case.name.clone());
        let entry = PyDict::new(py);
        match &c.run {
            Ok(run) => case_dict(py, &entry, &problem, run)?,
            Err(e) => entry.set_item("status", format!("failed: {e}"))?,
        }
        cases.set_item(&c.case.name, entry)?;
    }
    d.set_item("case_names", names)?;
    d.set_item("cases", cases)?;
    if result.cases.len() > 1 {
        let b = &result.band;
        let band = PyDict::new(py);
        band.set_item("amplitude", PyArray1::from_vec(py, b.amplitude.clone()))?;
        let pair = |v: &[[f64; 2]], k: usize| v.iter().map(|p| p[k]).collect::<Vec<f64>>();
        band.set_item("freq_min_hz", PyArray1::from_vec(py, pair(&b.freq_hz, 0)))?;
        band.set_item("freq_max_hz", PyArray1::from_vec(py, pair(&b.freq_hz, 1)))?;
        band.set_item(
            "damping_min",
            PyArray1::from_vec(py, pair(&b.damping_ratio, 0)),
        )?;
        band.set_item(
            "damping_max",
            PyArray1::from_vec(py, pair(&b.damping_ratio, 1)),
        )?;
        band.set_item(
            "wide",
            b.wide.iter().map(|w| w.to_vec()).collect::<Vec<_>>(),
        )?;
        d.set_item("band", band)?;
    }
    Ok(d)
}

/// One case's mode as arrays.
fn case_dict(
    py: Python<'_>,
    d: &Bound<'_, PyDict>,
    problem: &Problem,
    run: &NonlinearModeRun,
) -> PyResult<()> {
    let p = &run.points;
    let column = |f: &dyn Fn(&nm::NonlinearModePoint) -> f64| {
        PyArray1::from_vec(py, p.iter().map(f).collect())
    };
    d.set_item(
        "status",
        match run.incomplete_reason() {
            None => "complete".to_string(),
            Some(r) => format!("incomplete: {r}"),
        },
    )?;
    d.set_item("mode", run.mode)?;
    d.set_item("linear_freq_hz", run.linear_freq_hz)?;
    d.set_item("linear_damping_ratio", run.linear_damping_ratio)?;
    d.set_item("modal_amplitude", column(&|x| x.modal_amplitude))?;
    d.set_item("amplitude", column(&|x| x.dof_amplitude))?;
    d.set_item("freq_hz", column(&|x| x.freq_hz))?;
    d.set_item("damping_ratio", column(&|x| x.damping_ratio))?;
    d.set_item("xi", column(&|x| x.xi))?;
    d.set_item("dissipated_energy", column(&|x| x.dissipated_energy))?;
    d.set_item("friction_energy", column(&|x| x.friction_energy))?;
    // The error estimate (NaN where not sized), when the scene computes it.
    if p.iter().any(|x| x.accuracy.is_some()) {
        let estimate = |k: usize| {
            PyArray1::from_vec(
                py,
                p.iter()
                    .map(|x| x.accuracy.map_or(f64::NAN, |a| a.values()[k]))
                    .collect(),
            )
        };
        d.set_item("freq_trunc_err", estimate(0))?;
        d.set_item("damping_trunc_err", estimate(1))?;
        d.set_item("amplitude_trunc_err", estimate(2))?;
    }
    d.set_item(
        "newton_iterations",
        PyArray1::from_vec(py, p.iter().map(|x| x.newton_iterations as i64).collect()),
    )?;
    let states: Vec<Vec<String>> = p
        .iter()
        .map(|x| x.states.iter().map(|s| s.label().to_string()).collect())
        .collect();
    d.set_item("states", states)?;
    let width = p.first().map_or(0, |x| x.coefficients.len());
    let flat: Vec<f64> = p
        .iter()
        .flat_map(|x| x.coefficients.iter().copied())
        .collect();
    d.set_item(
        "coefficients",
        crate::convert::array2(py, p.len(), width, flat)?,
    )?;
    d.set_item("blocks", problem.unknown_harmonics().block_labels())?;
    if let Some(peak) = nm::predicted_peak(problem, run) {
        let pk = PyDict::new(py);
        pk.set_item("amplitude", peak.dof_amplitude)?;
        pk.set_item("freq_hz", peak.freq_hz)?;
        pk.set_item("modal_amplitude", peak.modal_amplitude)?;
        d.set_item("predicted_peak", pk)?;
    }
    Ok(())
}
