//! Library results into dicts of numpy arrays, lists and scalars (the pure-Python layer wraps
//! them in result classes). Units as in the library: frequencies in Hz, displacements in m.

use numpy::ndarray::{Array2, Array3};
use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use fricbound::analysis::frf::{FrfPoint, FrfRun};
use fricbound::analysis::limits::envelope::{Envelope, EnvelopeBound};
use fricbound::analysis::limits::{CaseCurve, LimitAnalysis, Peak, Regime};
use fricbound::analysis::modes::{EigenMethod, NaturalModes};
use fricbound::analysis::peaks::PathExtremum;
use fricbound::model::Problem;
use fricbound::report::files;
use fricbound::scene::SweepSpec;
use fricbound::study::accuracy::{CurveStudy, SettingErrors, SettingResult, StudyPlan};
use fricbound::study::sweep::SweepPoint;

/// The response envelope (`[limits] envelope`): per grid frequency and output DOF the smallest
/// and largest amplitude over the initial states (m; NaN where no state was solved), the m of
/// each group attaining them, and the check of the two limit curves against it.
fn envelope_dict<'py>(py: Python<'py>, e: &Envelope) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = e.points.len();
    let outputs = e.points.first().map_or(0, |p| p.max.len());
    let groups = e.groups.len();
    d.set_item("mode", format!("{:?}", e.mode).to_lowercase())?;
    d.set_item("groups", e.groups.clone())?;
    d.set_item(
        "freq_hz",
        PyArray1::from_vec(py, e.points.iter().map(|p| p.freq_hz).collect()),
    )?;
    let amplitude = |b: &Option<EnvelopeBound>| b.as_ref().map_or(f64::NAN, |b| b.amplitude);
    let mins: Vec<&[Option<EnvelopeBound>]> = e.points.iter().map(|p| p.min.as_slice()).collect();
    let maxs: Vec<&[Option<EnvelopeBound>]> = e.points.iter().map(|p| p.max.as_slice()).collect();
    let bounds = |rows: &[&[Option<EnvelopeBound>]]| {
        array2(
            py,
            n,
            outputs,
            rows.iter().flat_map(|r| r.iter().map(amplitude)).collect(),
        )
    };
    let states = |rows: &[&[Option<EnvelopeBound>]]| {
        let mut m = Array3::from_elem((n, outputs, groups), f64::NAN);
        for (k, r) in rows.iter().enumerate() {
            for (o, b) in r.iter().enumerate().take(outputs) {
                if let Some(b) = b {
                    for (g, x) in b.m.iter().enumerate().take(groups) {
                        m[(k, o, g)] = *x;
                    }
                }
            }
        }
        PyArray3::from_owned_array(py, m)
    };
    d.set_item("min", bounds(&mins)?)?;
    d.set_item("max", bounds(&maxs)?)?;
    d.set_item("min_m", states(&mins))?;
    d.set_item("max_m", states(&maxs))?;
    let c = &e.check;
    let cd = PyDict::new(py);
    cd.set_item("compared", c.compared)?;
    cd.set_item("max_excess_above", c.max_excess_above)?;
    cd.set_item("above_at", c.above_at.clone())?;
    cd.set_item("max_excess_below", c.max_excess_below)?;
    cd.set_item("below_at", c.below_at.clone())?;
    cd.set_item("points_above", c.points_above)?;
    cd.set_item("points_below", c.points_below)?;
    cd.set_item("peak_excess_above", c.peak_excess_above)?;
    d.set_item("check", cd)?;
    d.set_item("solves", e.solves)?;
    d.set_item("unsolved", e.unsolved)?;
    d.set_item("elapsed_s", e.elapsed_s)?;
    Ok(d)
}

/// A row-major `rows × cols` numpy array from flat values.
pub fn array2<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    flat: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = Array2::from_shape_vec((rows, cols), flat)
        .map_err(|e| PyRuntimeError::new_err(format!("result array shape: {e}")))?;
    Ok(PyArray2::from_owned_array(py, a))
}

/// A faer matrix as a numpy array.
fn mat<'py>(py: Python<'py>, m: faer::MatRef<'_, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (r, c) = (m.nrows(), m.ncols());
    let flat: Vec<f64> = (0..r)
        .flat_map(|i| (0..c).map(move |j| m[(i, j)]))
        .collect();
    array2(py, r, c, flat)
}

/// Names of the problem's DOFs, outputs, contacts, damper sides and coefficient blocks.
pub fn problem_names(d: &Bound<'_, PyDict>, problem: &Problem) -> PyResult<()> {
    let dofs = &problem.model.dof_names;
    d.set_item("dofs", dofs.clone())?;
    d.set_item(
        "outputs",
        problem
            .outputs
            .iter()
            .map(|&i| dofs[i].clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "contacts",
        problem
            .contacts
            .iter()
            .map(|c| c.name.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "sides",
        problem
            .sides
            .iter()
            .map(|s| s.name.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item("blocks", problem.unknown_harmonics().block_labels())?;
    Ok(())
}

/// The per-point arrays of a path: `freq_hz` (n), `amplitudes` and `max_displacement` (the
/// time-domain peak |q(τ)| over the period, the `<dof>_peak` column of `frf.csv`; n × outputs),
/// `states` (n lists of contact-state labels), `newton_iterations`, `residual`,
/// `coefficients` (n × DOFs·blocks, harmonic-major), `trunc_err` and `sampling_err`
/// (n × outputs, NaN where not estimated), `estimate_harmonic` (n) and `estimate_method` (n
/// labels: `step`, `solved`, `unsized`, `unsolved`, `converged`, `none`) (all four absent when the scene does not ask
/// for the estimate), `stable`, `floquet_re`, `floquet_freq_hz`, `stability_method`,
/// `stability_reliable` (absent without `analysis.stability`).
pub fn points_dict<'py>(py: Python<'py>, points: &[FrfPoint]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = points.len();
    let outputs = points.first().map_or(0, |p| p.amplitudes.len());
    let coefs = points.first().map_or(0, |p| p.coefficients.len());
    d.set_item(
        "freq_hz",
        PyArray1::from_vec(py, points.iter().map(|p| p.freq_hz).collect()),
    )?;
    let per_output = |f: &dyn Fn(&FrfPoint) -> &[f64]| -> Vec<f64> {
        points.iter().flat_map(|p| f(p).iter().copied()).collect()
    };
    d.set_item(
        "amplitudes",
        array2(py, n, outputs, per_output(&|p| &p.amplitudes))?,
    )?;
    d.set_item(
        "max_displacement",
        array2(py, n, outputs, per_output(&|p| &p.peaks))?,
    )?;
    d.set_item(
        "coefficients",
        array2(py, n, coefs, per_output(&|p| &p.coefficients))?,
    )?;
    let states: Vec<Vec<&str>> = points
        .iter()
        .map(|p| p.states.iter().map(|s| s.label()).collect())
        .collect();
    d.set_item("states", states)?;
    d.set_item(
        "newton_iterations",
        PyArray1::from_vec(
            py,
            points.iter().map(|p| p.newton_iterations as i64).collect(),
        ),
    )?;
    d.set_item(
        "residual",
        PyArray1::from_vec(py, points.iter().map(|p| p.residual).collect()),
    )?;
    if points.iter().any(|p| p.accuracy.is_some()) {
        let est = |f: &dyn Fn(&fricbound::analysis::error_estimate::PointAccuracy) -> &[f64]| {
            let flat: Vec<f64> = points
                .iter()
                .flat_map(|p| match &p.accuracy {
                    Some(a) => f(a).to_vec(),
                    None => vec![f64::NAN; outputs],
                })
                .collect();
            array2(py, n, outputs, flat)
        };
        d.set_item("trunc_err", est(&|a| &a.truncation)?)?;
        d.set_item("sampling_err", est(&|a| &a.sampling)?)?;
        let harmonic: Vec<i64> = points
            .iter()
            .map(|p| {
                p.accuracy
                    .as_ref()
                    .map_or(0, |a| a.estimate_harmonic as i64)
            })
            .collect();
        d.set_item("estimate_harmonic", PyArray1::from_vec(py, harmonic))?;
        let method: Vec<&str> = points
            .iter()
            .map(|p| {
                p.accuracy.as_ref().map_or(
                    fricbound::analysis::error_estimate::EstimateMethod::None.label(),
                    |a| a.method.label(),
                )
            })
            .collect();
        d.set_item("estimate_method", method)?;
    }
    if points.iter().any(|p| p.stability.is_some()) {
        let stable: Vec<bool> = points
            .iter()
            .map(|p| p.stability.as_ref().is_some_and(|s| s.stable))
            .collect();
        d.set_item("stable", PyArray1::from_vec(py, stable))?;
        let field = |f: &dyn Fn(&fricbound::analysis::stability::PointStability) -> f64| {
            PyArray1::from_vec(
                py,
                points
                    .iter()
                    .map(|p| p.stability.as_ref().map_or(f64::NAN, f))
                    .collect(),
            )
        };
        d.set_item("floquet_re", field(&|s| s.floquet_re))?;
        d.set_item("floquet_freq_hz", field(&|s| s.floquet_freq_hz))?;
        d.set_item(
            "stability_method",
            points
                .iter()
                .map(|p| p.stability.as_ref().map_or("", |s| s.method.label()))
                .collect::<Vec<_>>(),
        )?;
        let reliable: Vec<bool> = points
            .iter()
            .map(|p| p.stability.as_ref().is_some_and(|s| s.reliable))
            .collect();
        d.set_item("stability_reliable", PyArray1::from_vec(py, reliable))?;
    }
    Ok(d)
}

/// An FRF run: its points ([`points_dict`]), the names ([`problem_names`]), how it ended
/// (`status`: `complete` or `incomplete: <reason>`, as in `solution.json`), turning points,
/// jumps, cut steps, wall time, `csv`: the run's `frf.csv` text as the CLI writes it, and
/// the refined resonances and anti-resonances ([`peaks_dict`], `peaks_csv`: the CLI's
/// `peaks.csv`).
pub fn frf_dict<'py>(
    py: Python<'py>,
    problem: &Problem,
    run: &FrfRun,
    extrema: &[PathExtremum],
) -> PyResult<Bound<'py, PyDict>> {
    let d = points_dict(py, &run.points)?;
    problem_names(&d, problem)?;
    let outputs: Vec<String> = problem
        .outputs
        .iter()
        .map(|&i| problem.model.dof_names[i].clone())
        .collect();
    let contacts: Vec<String> = problem.contacts.iter().map(|c| c.name.clone()).collect();
    d.set_item("peaks", peaks_dict(py, &outputs, &contacts, extrema)?)?;
    d.set_item("peaks_csv", files::peaks_csv(&outputs, &contacts, extrema))?;
    d.set_item(
        "status",
        fricbound::report::files::status_text(run.incomplete_reason().as_deref()),
    )?;
    d.set_item("turning_points_hz", run.turning_points.clone())?;
    let jumps = PyList::empty(py);
    for j in &run.jumps {
        let jd = PyDict::new(py);
        jd.set_item("from_hz", j.from_hz)?;
        jd.set_item("to_hz", j.to_hz)?;
        jd.set_item("first_point", j.first_point)?;
        jumps.append(jd)?;
    }
    d.set_item("jumps", jumps)?;
    d.set_item("rejected_steps", run.rejected_steps)?;
    d.set_item("elapsed_s", run.elapsed_s)?;
    let mut csv = files::frf_header(problem);
    for p in &run.points {
        csv.push_str(&files::frf_row(p));
    }
    d.set_item("csv", csv)?;
    Ok(d)
}

/// The refined resonances and anti-resonances of an FRF run as columns named as `peaks.csv`
/// ([`files::peaks_header`]): `dof`, `kind`, `freq_hz`, `amplitude`, `refined`,
/// `at_branch_end`, `path_index`, `path_freq_hz`, `path_amplitude`, `<contact>_state`.
fn peaks_dict<'py>(
    py: Python<'py>,
    outputs: &[String],
    contacts: &[String],
    extrema: &[PathExtremum],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let floats =
        |f: &dyn Fn(&PathExtremum) -> f64| PyArray1::from_vec(py, extrema.iter().map(f).collect());
    let flags =
        |f: &dyn Fn(&PathExtremum) -> bool| PyArray1::from_vec(py, extrema.iter().map(f).collect());
    d.set_item(
        "dof",
        extrema
            .iter()
            .map(|e| outputs.get(e.output).cloned().unwrap_or_default())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "kind",
        extrema.iter().map(|e| e.kind.label()).collect::<Vec<_>>(),
    )?;
    d.set_item("freq_hz", floats(&|e| e.peak.freq_hz))?;
    d.set_item("amplitude", floats(&|e| e.peak.amplitude))?;
    d.set_item("refined", flags(&|e| e.peak.refined))?;
    d.set_item("at_branch_end", flags(&|e| e.at_branch_end))?;
    d.set_item(
        "path_index",
        PyArray1::from_vec(py, extrema.iter().map(|e| e.path_index as i64).collect()),
    )?;
    d.set_item("path_freq_hz", floats(&|e| e.path_freq_hz))?;
    d.set_item("path_amplitude", floats(&|e| e.path_amplitude))?;
    for (k, c) in contacts.iter().enumerate() {
        d.set_item(
            format!("{c}_state"),
            extrema
                .iter()
                .map(|e| e.peak.states.get(k).map_or("", |s| s.label()))
                .collect::<Vec<_>>(),
        )?;
    }
    Ok(d)
}

/// A resonance peak as a dict (`freq_hz`, `amplitude`, `refined`, `states`), or None.
fn peak_obj<'py>(py: Python<'py>, peak: Option<&Peak>) -> PyResult<Bound<'py, PyAny>> {
    match peak {
        None => Ok(py.None().into_bound(py)),
        Some(p) => {
            let d = PyDict::new(py);
            d.set_item("freq_hz", p.freq_hz)?;
            d.set_item("amplitude", p.amplitude)?;
            d.set_item("refined", p.refined)?;
            d.set_item(
                "states",
                p.states.iter().map(|s| s.label()).collect::<Vec<_>>(),
            )?;
            Ok(d.into_any())
        }
    }
}

/// One limit or intermediate curve: `name`, `contact_states` (m per contact), `status`,
/// `complete`, `peak`, `turning_points_hz` and its `points` ([`points_dict`]).
fn curve_dict<'py>(py: Python<'py>, c: &CaseCurve) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &c.case.name)?;
    d.set_item("contact_states", c.case.contact_states.clone())?;
    d.set_item("status", c.status.text())?;
    d.set_item("complete", c.status.is_complete())?;
    d.set_item("peak", peak_obj(py, c.peak.as_ref())?)?;
    d.set_item("turning_points_hz", c.turning_points.clone())?;
    d.set_item("points", points_dict(py, &c.points)?)?;
    Ok(d)
}

/// A limit analysis: `limits` and `intermediate` curves ([`curve_dict`]), the common grid
/// (`grid_freq_hz`, `grid_lower`, `grid_upper`, `grid_amplitudes` grid × limit cases,
/// `grid_regime` labels `unique`/`multiple`/`unknown`), the bound check (largest excess of
/// any scanned solution above the upper and below the lower limit, m), scanned cases'
/// peaks, the variability summary, `unfinished` and `status`.
pub fn limits_dict<'py>(
    py: Python<'py>,
    problem: &Problem,
    a: &LimitAnalysis,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    problem_names(&d, problem)?;
    let curves = |cs: &[CaseCurve]| -> PyResult<Bound<'py, PyList>> {
        let l = PyList::empty(py);
        for c in cs {
            l.append(curve_dict(py, c)?)?;
        }
        Ok(l)
    };
    d.set_item("limits", curves(&a.limits)?)?;
    d.set_item("intermediate", curves(&a.intermediate)?)?;
    let g = &a.grid;
    d.set_item(
        "grid_freq_hz",
        PyArray1::from_vec(py, g.iter().map(|p| p.freq_hz).collect()),
    )?;
    d.set_item(
        "grid_lower",
        PyArray1::from_vec(py, g.iter().map(|p| p.lower).collect()),
    )?;
    d.set_item(
        "grid_upper",
        PyArray1::from_vec(py, g.iter().map(|p| p.upper).collect()),
    )?;
    let cases = g.first().map_or(0, |p| p.amplitudes.len());
    d.set_item(
        "grid_amplitudes",
        array2(
            py,
            g.len(),
            cases,
            g.iter()
                .flat_map(|p| p.amplitudes.iter().copied())
                .collect(),
        )?,
    )?;
    d.set_item(
        "grid_regime",
        g.iter()
            .map(|p| match p.regime {
                Regime::Unique => "unique",
                Regime::Multiple { .. } => "multiple",
                Regime::Unknown => "unknown",
            })
            .collect::<Vec<_>>(),
    )?;
    if let Some(b) = &a.bounds {
        let bd = PyDict::new(py);
        bd.set_item("max_excess_above", b.max_excess_above)?;
        bd.set_item("max_excess_below", b.max_excess_below)?;
        bd.set_item("peak_excess_above", b.peak_excess_above)?;
        bd.set_item("peak_excess_below", b.peak_excess_below)?;
        bd.set_item("compared", b.compared)?;
        d.set_item("bounds", bd)?;
    } else {
        d.set_item("bounds", py.None())?;
    }
    match &a.envelope {
        Some(e) => d.set_item("envelope", envelope_dict(py, e)?)?,
        None => d.set_item("envelope", py.None())?,
    }
    let scanned = PyList::empty(py);
    for s in &a.scanned {
        let sd = PyDict::new(py);
        sd.set_item("name", &s.case.name)?;
        sd.set_item("contact_states", s.case.contact_states.clone())?;
        sd.set_item("status", s.status.text())?;
        sd.set_item("peak", peak_obj(py, s.peak.as_ref())?)?;
        scanned.append(sd)?;
    }
    d.set_item("scanned", scanned)?;
    let v = a.variability();
    let vd = PyDict::new(py);
    vd.set_item("upper_peak", v.upper_peak)?;
    vd.set_item("lower_peak", v.lower_peak)?;
    vd.set_item("peak_ratio", v.peak_ratio)?;
    vd.set_item("peak_freq_change_pct", v.peak_freq_change_pct)?;
    vd.set_item("widest_band", v.widest_band)?;
    vd.set_item("widest_band_hz", v.widest_band_hz)?;
    vd.set_item("multiple_points", v.multiple_points)?;
    vd.set_item("grid_points", v.grid_points)?;
    d.set_item("variability", vd)?;
    let unfinished = a.unfinished();
    d.set_item(
        "status",
        fricbound::report::files::status_text(
            if unfinished.is_empty() {
                None
            } else {
                Some(unfinished.join("; "))
            }
            .as_deref(),
        ),
    )?;
    d.set_item("unfinished", unfinished)?;
    Ok(d)
}

/// A sweep: `parameter`, `unit`, `series_parameter`, per point (in scene order) `value`,
/// `series` (NaN without a series), and per point × case (`cases`) the resonance peak's
/// `peak_amplitude` (m) and `peak_freq_hz` (NaN where the case failed or did not cover the
/// range), `peak_refined`; `limit_cases` (how many leading cases bound the
/// response), `peaks_from`; `failures` (one list of lines per point) and `status`.
pub fn sweep_dict<'py>(
    py: Python<'py>,
    spec: &SweepSpec,
    points: &[SweepPoint],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("parameter", &spec.parameter)?;
    d.set_item("unit", &spec.unit)?;
    d.set_item(
        "series_parameter",
        spec.series.as_ref().map(|s| s.parameter.clone()),
    )?;
    let n = points.len();
    let cases = points.first().map(|p| p.cases.clone()).unwrap_or_default();
    let k = cases.len();
    d.set_item(
        "value",
        PyArray1::from_vec(py, points.iter().map(|p| p.value).collect()),
    )?;
    d.set_item(
        "series",
        PyArray1::from_vec(
            py,
            points
                .iter()
                .map(|p| p.series.unwrap_or(f64::NAN))
                .collect(),
        ),
    )?;
    let peak_field = |f: &dyn Fn(&Peak) -> f64| -> Vec<f64> {
        points
            .iter()
            .flat_map(|p| {
                (0..k).map(|c| p.peaks.get(c).and_then(|x| x.as_ref()).map_or(f64::NAN, f))
            })
            .collect()
    };
    d.set_item(
        "peak_amplitude",
        array2(py, n, k, peak_field(&|p| p.amplitude))?,
    )?;
    d.set_item(
        "peak_freq_hz",
        array2(py, n, k, peak_field(&|p| p.freq_hz))?,
    )?;
    d.set_item(
        "peak_refined",
        array2(py, n, k, peak_field(&|p| if p.refined { 1.0 } else { 0.0 }))?,
    )?;
    d.set_item("cases", cases)?;
    d.set_item(
        "limit_cases",
        points.first().map_or(2, |p| p.limit_cases),
    )?;
    let failures: Vec<Vec<String>> = points.iter().map(|p| p.failures.clone()).collect();
    let failed: Vec<String> = points
        .iter()
        .filter(|p| !p.failures.is_empty())
        .map(|p| {
            format!(
                "{} = {}: {}",
                spec.parameter,
                p.value,
                p.failures.join("; ")
            )
        })
        .collect();
    d.set_item(
        "status",
        fricbound::report::files::status_text(
            if failed.is_empty() {
                None
            } else {
                Some(failed.join(" | "))
            }
            .as_deref(),
        ),
    )?;
    d.set_item("failures", failures)?;
    Ok(d)
}

/// Natural modes: `case`, `frequency_hz`, `eigenvalue` (rad²/s²), `rigid`, `shapes` (DOFs ×
/// modes, mass-normalised), `method` (`dense` or `lanczos`), `seconds`, and the DOF names.
pub fn modes_dict<'py>(
    py: Python<'py>,
    problem: &Problem,
    m: &NaturalModes,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    problem_names(&d, problem)?;
    d.set_item("case", fricbound::analysis::modes::case_name(m.case))?;
    d.set_item(
        "frequency_hz",
        PyArray1::from_vec(py, m.modes.iter().map(|x| x.frequency_hz).collect()),
    )?;
    d.set_item(
        "eigenvalue",
        PyArray1::from_vec(py, m.modes.iter().map(|x| x.eigenvalue).collect()),
    )?;
    d.set_item(
        "rigid",
        PyArray1::from_vec(py, m.modes.iter().map(|x| x.rigid).collect()),
    )?;
    d.set_item("shapes", mat(py, m.shapes.as_ref())?)?;
    d.set_item(
        "method",
        match m.method {
            EigenMethod::Dense => "dense",
            EigenMethod::Lanczos { .. } => "lanczos",
        },
    )?;
    d.set_item("seconds", m.seconds)?;
    Ok(d)
}

/// A Craig-Bampton reduced model: `stiffness`, `mass` (reduced, symmetric), `boundary` (full
/// indices of the first coordinates), `n_modes`, `modal_frequencies_hz` of the fixed-interface
/// modes, `recovery` (rows × reduced size) and `recover` (the full DOF of each row).
pub fn reduced_dict<'py>(
    py: Python<'py>,
    r: &fricbound_reduction::ReducedModel,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("stiffness", mat(py, r.stiffness.as_ref())?)?;
    d.set_item("mass", mat(py, r.mass.as_ref())?)?;
    d.set_item("boundary", r.boundary.clone())?;
    d.set_item("n_modes", r.n_modes)?;
    d.set_item(
        "modal_frequencies_hz",
        PyArray1::from_vec(py, r.modal_frequencies_hz.clone()),
    )?;
    let size = r.size();
    d.set_item(
        "recovery",
        array2(
            py,
            r.recovery.len(),
            size,
            r.recovery
                .iter()
                .flat_map(|x| x.row.iter().copied())
                .collect(),
        )?,
    )?;
    d.set_item(
        "recover",
        r.recovery.iter().map(|x| x.dof).collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// The accuracy study as a dict: one row per (curve, setting) including each curve's
/// reference and check (`role`), as columns (`curve`, `role`, `group`, `setting`,
/// `setting_status`,
/// `unknowns`, `points`, `newton_iterations`, `time_s`, `curve_l2`, `peak_amp_err`,
/// `peak_freq_err`, `pareto`), and per curve the reference's label and peaks.
pub fn accuracy_dict<'py>(
    py: Python<'py>,
    plan: &StudyPlan,
    studies: &[CurveStudy],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    problem_names(&d, &plan.problem)?;
    let mut curve = Vec::new();
    let mut role = Vec::new();
    let mut rows: Vec<(&SettingResult, SettingErrors, bool)> = Vec::new();
    for s in studies {
        let front = s.pareto().1;
        let check = (&s.check, s.check_errors.clone(), false);
        let reference = (
            &s.reference,
            SettingErrors {
                curve_l2: 0.0,
                peaks: vec![(0.0, 0.0); s.reference.peaks.len()],
            },
            false,
        );
        for (r, label) in [(reference, "reference"), (check, "check")] {
            curve.push(s.curve.name.clone());
            role.push(label);
            rows.push(r);
        }
        for (i, (r, e)) in s.results.iter().zip(&s.errors).enumerate() {
            curve.push(s.curve.name.clone());
            role.push("setting");
            rows.push((r, e.clone(), front.contains(&i)));
        }
    }
    d.set_item("curve", curve)?;
    d.set_item("role", role)?;
    d.set_item(
        "group",
        rows.iter().map(|r| r.0.setting.group).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "setting",
        rows.iter()
            .map(|r| r.0.setting.label.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "setting_status",
        rows.iter().map(|r| r.0.status.clone()).collect::<Vec<_>>(),
    )?;
    let column = |f: &dyn Fn(&(&SettingResult, SettingErrors, bool)) -> f64| {
        PyArray1::from_vec(py, rows.iter().map(f).collect())
    };
    d.set_item("unknowns", column(&|r| r.0.unknowns as f64))?;
    d.set_item("points", column(&|r| r.0.points as f64))?;
    d.set_item(
        "newton_iterations",
        column(&|r| r.0.newton_iterations as f64),
    )?;
    d.set_item("time_s", column(&|r| r.0.time_s))?;
    d.set_item("curve_l2", column(&|r| r.1.curve_l2))?;
    d.set_item("peak_amp_err", column(&|r| r.1.max_peak_amplitude()))?;
    d.set_item("peak_freq_err", column(&|r| r.1.max_peak_frequency()))?;
    d.set_item("pareto", rows.iter().map(|r| r.2).collect::<Vec<_>>())?;
    let references = PyDict::new(py);
    for s in studies {
        let r = PyDict::new(py);
        r.set_item("setting", &s.reference.setting.label)?;
        r.set_item(
            "peaks_hz",
            s.reference.peaks.iter().map(|p| p.0).collect::<Vec<_>>(),
        )?;
        r.set_item(
            "peaks_amp",
            s.reference.peaks.iter().map(|p| p.1).collect::<Vec<_>>(),
        )?;
        r.set_item("check_curve_l2", s.check_errors.curve_l2)?;
        r.set_item("check_peak_amp_err", s.check_errors.max_peak_amplitude())?;
        references.set_item(&s.curve.name, r)?;
    }
    d.set_item("references", references)?;
    d.set_item("status", "complete")?;
    Ok(d)
}
