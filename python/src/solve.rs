//! The functions of `fricbound._native`: scene parsing and checks, and the solves, each run on
//! a worker thread with the GIL released (see [`in_background`]).

use std::sync::mpsc;
use std::time::Duration;

use numpy::PyReadonlyArray1;
use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use fricbound::analysis::frf::{self, FrfObserver, FrfPoint};
use fricbound::analysis::limits::{analyse, LimitSettings};
use fricbound::analysis::linear::LinearCase;
use fricbound::analysis::modes::natural_modes;
use fricbound::analysis::peaks::path_extrema;
use fricbound::model::Problem;
use fricbound::numerics::interrupt;
use fricbound::scene::{self, Scene, SceneError};
use fricbound::study::accuracy::{
    SettingErrors, SettingResult, StudyError, StudyObserver, StudyPlan,
};

use crate::convert;
use crate::SolveError;

/// A scene error as `ValueError`, with the library's message (file, field path, reason).
fn scene_error(e: SceneError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The built-in paper scene (Table 1 of the paper, β = 120°, F0 = 120 N): (TOML text, label).
#[pyfunction]
pub fn paper_scene() -> (String, String) {
    (
        scene::PAPER_DEFAULT_SCENE.to_string(),
        scene::default_scene_label().display().to_string(),
    )
}

/// Parses scene text with `--set` overrides and returns the canonical TOML of the result.
/// Raises `ValueError` naming the line or the override at fault.
#[pyfunction]
pub fn parse_scene(text: &str, label: &str, overrides: Vec<String>) -> PyResult<String> {
    let scene = scene::parse(text, label, &overrides).map_err(scene_error)?;
    canonical(&scene, label)
}

/// The canonical TOML text of a scene.
fn canonical(scene: &Scene, label: &str) -> PyResult<String> {
    toml::to_string(scene).map_err(|e| {
        PyValueError::new_err(format!("{label}: the scene cannot be written as TOML: {e}"))
    })
}

/// A scene given as a JSON object of the TOML tables (what `Scene.from_matrices` builds),
/// checked against the schema; returns its TOML text.
#[pyfunction]
pub fn scene_from_json(json: &str, label: &str) -> PyResult<String> {
    let value: serde_json::Value = serde_json::from_str(json)
        .map_err(|e| PyValueError::new_err(format!("{label}: not a JSON scene: {e}")))?;
    let table = toml::Value::try_from(value).map_err(|e| {
        PyValueError::new_err(format!(
            "{label}: a value cannot be written as TOML (None or NaN where a number is \
             needed?): {e}"
        ))
    })?;
    let text =
        toml::to_string(&table).map_err(|e| PyValueError::new_err(format!("{label}: {e}")))?;
    // The same parser as files: an unknown field or a wrong type is named here.
    let scene = scene::parse(&text, label, &[]).map_err(scene_error)?;
    canonical(&scene, label)
}

/// Parses and validates a scene: the scene, the checked problem, its limit settings.
pub(crate) fn load(
    text: &str,
    label: &str,
    overrides: &[String],
) -> PyResult<(Scene, Problem, Option<LimitSettings>)> {
    let scene = scene::parse(text, label, overrides).map_err(scene_error)?;
    let (problem, limits) = scene.validate_with_limits(label).map_err(scene_error)?;
    Ok((scene, problem, limits))
}

/// Refuses a problem that would not fit in memory (the CLI's check, `fricbound run`), with
/// `MemoryError` naming the estimate and the fields to lower.
fn check_memory(label: &str, problem: &Problem, parallel: usize) -> PyResult<()> {
    fricbound::hbm::cost::check_memory(problem, parallel)
        .map_err(|e| PyMemoryError::new_err(format!("{label}: {e}")))
}

/// Validates a scene and describes it (sizes, formulation, cost estimate).
#[pyfunction]
pub fn check<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, problem, limits) = load(text, label, &overrides)?;
    let d = PyDict::new(py);
    convert::problem_names(&d, &problem)?;
    let cost = fricbound::hbm::cost::estimate(&problem);
    d.set_item("title", &scene.title)?;
    d.set_item(
        "harmonics",
        problem.unknown_harmonics().harmonics().to_vec(),
    )?;
    d.set_item("samples", problem.samples)?;
    d.set_item(
        "unknowns",
        problem.model.n_dofs() * problem.unknown_harmonics().n_blocks(),
    )?;
    d.set_item(
        "formulation",
        fricbound::hbm::cost::formulation_name(cost.formulation),
    )?;
    d.set_item("newton_unknowns", cost.unknowns)?;
    d.set_item("cost", cost.summary())?;
    d.set_item("freq_start_hz", problem.analysis.continuation.freq_start_hz)?;
    d.set_item("freq_end_hz", problem.analysis.continuation.freq_end_hz)?;
    d.set_item("has_limits", limits.is_some())?;
    d.set_item("has_sweep", scene.sweep.is_some())?;
    Ok(d)
}

/// A progress event sent by a solve on the worker thread.
pub(crate) enum Event {
    /// An FRF point converged.
    Point {
        freq_hz: f64,
        amplitudes: Vec<f64>,
        count: usize,
    },
    /// A limit, intermediate or scanned curve ended.
    Curve { name: String, status: String },
    /// A setting of the accuracy study finished.
    StudySetting {
        curve: String,
        setting: String,
        done: usize,
        total: usize,
    },
    /// A sweep value finished.
    SweepValue {
        value: f64,
        series: Option<f64>,
        failures: usize,
    },
}

impl Event {
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        match self {
            Event::Point {
                freq_hz,
                amplitudes,
                count,
            } => {
                d.set_item("kind", "point")?;
                d.set_item("freq_hz", freq_hz)?;
                d.set_item("amplitudes", amplitudes.clone())?;
                d.set_item("points", count)?;
            }
            Event::Curve { name, status } => {
                d.set_item("kind", "curve")?;
                d.set_item("name", name)?;
                d.set_item("status", status)?;
            }
            Event::StudySetting {
                curve,
                setting,
                done,
                total,
            } => {
                d.set_item("kind", "setting")?;
                d.set_item("curve", curve)?;
                d.set_item("setting", setting)?;
                d.set_item("done", done)?;
                d.set_item("total", total)?;
            }
            Event::SweepValue {
                value,
                series,
                failures,
            } => {
                d.set_item("kind", "sweep")?;
                d.set_item("value", value)?;
                d.set_item("series", series)?;
                d.set_item("failures", failures)?;
            }
        }
        Ok(d)
    }
}

/// How often the calling thread checks for signals while a solve runs.
const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// Runs `job` on a worker thread with the GIL released. The calling thread forwards the
/// job's progress events to `progress` (called with one dict per event, holding the GIL) and
/// checks for signals every [`SIGNAL_POLL`]. Ctrl-C (`KeyboardInterrupt` from
/// `check_signals`), or an exception raised by the callback, requests the library's
/// continuation runs to stop ([`interrupt::request`]); the job then ends within about one
/// continuation step per thread, the request is withdrawn and the exception raised.
pub(crate) fn in_background<T, F>(
    py: Python<'_>,
    progress: Option<&Py<PyAny>>,
    job: F,
) -> PyResult<T>
where
    T: Send,
    F: FnOnce(mpsc::Sender<Event>) -> T + Send,
{
    let mut raised: Option<PyErr> = None;
    let outcome = py.detach(|| {
        std::thread::scope(|scope| {
            let (tx, rx) = mpsc::channel::<Event>();
            let worker = scope.spawn(move || job(tx));
            loop {
                let event = match rx.recv_timeout(SIGNAL_POLL) {
                    Ok(event) => Some(event),
                    Err(mpsc::RecvTimeoutError::Timeout) => None,
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                };
                if raised.is_some() {
                    continue;
                }
                let result = Python::attach(|py| -> PyResult<()> {
                    if let (Some(event), Some(callback)) = (&event, progress) {
                        callback.bind(py).call1((event.to_dict(py)?,))?;
                    }
                    py.check_signals()
                });
                if let Err(e) = result {
                    raised = Some(e);
                    interrupt::request();
                }
            }
            worker.join()
        })
    });
    if raised.is_some() {
        interrupt::clear();
    }
    match (raised, outcome) {
        (Some(e), _) => Err(e),
        (None, Ok(value)) => Ok(value),
        (None, Err(_)) => Err(PyRuntimeError::new_err(
            "the solver panicked (a bug in fricbound: please report it with the scene)",
        )),
    }
}

/// Forwards FRF points to the calling thread.
struct PointEvents {
    tx: mpsc::Sender<Event>,
    count: usize,
}

impl FrfObserver for PointEvents {
    fn point(&mut self, point: &FrfPoint) {
        self.count += 1;
        // The receiver is gone only once the caller has stopped listening.
        let _ = self.tx.send(Event::Point {
            freq_hz: point.freq_hz,
            amplitudes: point.amplitudes.clone(),
            count: self.count,
        });
    }
}

/// One nonlinear FRF of the scene (its `[limits]` and `[sweep]` tables are not run here: see
/// `limits` and `sweep`).
#[pyfunction]
#[pyo3(signature = (text, label, overrides, progress=None))]
pub fn run<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (_, problem, _) = load(text, label, &overrides)?;
    check_memory(label, &problem, 1)?;
    let result = in_background(py, progress.as_ref(), |tx| {
        let mut events = PointEvents { tx, count: 0 };
        // The refined resonances and anti-resonances within each branch, as `fricbound run`
        // writes them to peaks.csv.
        frf::solve(&problem, &mut events).map(|run| {
            let extrema = path_extrema(&problem, &run.points, &run.branch_starts());
            (run, extrema)
        })
    })?;
    let (run, extrema) = result.map_err(|e| SolveError::new_err(format!("{label}: {e}")))?;
    convert::frf_dict(py, &problem, &run, &extrema)
}

/// The paper's two-point limit analysis (the scene's `[limits]` table, or the defaults).
#[pyfunction]
#[pyo3(signature = (text, label, overrides, progress=None))]
pub fn limits<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (_, problem, settings) = load(text, label, &overrides)?;
    let settings = settings.unwrap_or_default();
    check_memory(label, &problem, rayon_threads())?;
    let result = in_background(py, progress.as_ref(), |tx| {
        let tx = std::sync::Mutex::new(tx);
        analyse(&problem, &settings, |curve| {
            if let Ok(tx) = tx.lock() {
                let _ = tx.send(Event::Curve {
                    name: curve.case.name.clone(),
                    status: curve.status.text(),
                });
            }
        })
    })?;
    let analysis = result.map_err(|e| SolveError::new_err(format!("{label}: {e}")))?;
    convert::limits_dict(py, &problem, &analysis)
}

/// Threads of rayon's pool: the most problems a limit analysis or sweep solves at once.
fn rayon_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The scene's `[sweep]` (peaks of the limit and intermediate cases at every value).
#[pyfunction]
#[pyo3(signature = (text, label, overrides, progress=None))]
pub fn sweep<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, problem, _) = load(text, label, &overrides)?;
    let Some(spec) = scene.sweep.clone() else {
        return Err(PyValueError::new_err(format!(
            "{label}: sweep: the scene has no [sweep] table (give field and values)"
        )));
    };
    check_memory(label, &problem, rayon_threads())?;
    let result = in_background(py, progress.as_ref(), |tx| {
        let tx = std::sync::Mutex::new(tx);
        fricbound::study::sweep::run(text, label, &overrides, &spec, |point| {
            if let Ok(tx) = tx.lock() {
                let _ = tx.send(Event::SweepValue {
                    value: point.value,
                    series: point.series,
                    failures: point.failures.len(),
                });
            }
        })
    })?;
    let points = result.map_err(|e| PyValueError::new_err(format!("{label}: {e}")))?;
    let d = convert::sweep_dict(py, &spec, &points)?;
    d.set_item("peaks_from", fricbound::study::sweep::peaks_from(&problem))?;
    Ok(d)
}

/// The lowest natural frequencies of the scene's structure with its contacts open or stuck.
#[pyfunction]
#[pyo3(signature = (text, label, overrides, count, case))]
pub fn modes<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    count: usize,
    case: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let case = match case {
        "open" => LinearCase::Open,
        "stuck" => LinearCase::Stuck,
        other => {
            return Err(PyValueError::new_err(format!(
                "modes: case must be \"open\" or \"stuck\", not {other:?}"
            )))
        }
    };
    if count == 0 {
        return Err(PyValueError::new_err("modes: count must be at least 1"));
    }
    let (_, problem, _) = load(text, label, &overrides)?;
    let modes = in_background(py, None, |_| natural_modes(&problem, case, count))?
        .map_err(|e| SolveError::new_err(format!("{label}: {e}")))?;
    convert::modes_dict(py, &problem, &modes)
}

/// A sparse matrix from CSC arrays (scipy's `indptr`, `indices`, `data`), checked.
fn csc_matrix(
    name: &str,
    n: usize,
    indptr: &PyReadonlyArray1<'_, i64>,
    indices: &PyReadonlyArray1<'_, i64>,
    data: &PyReadonlyArray1<'_, f64>,
) -> PyResult<faer::sparse::SparseColMat<usize, f64>> {
    let bad = |reason: String| PyValueError::new_err(format!("reduce: {name}: {reason}"));
    let (indptr, indices, data) = (indptr.as_array(), indices.as_array(), data.as_array());
    if indptr.len() != n + 1 {
        return Err(bad(format!(
            "{} column pointers for a {n} x {n} matrix",
            indptr.len()
        )));
    }
    if indices.len() != data.len() {
        return Err(bad(format!(
            "{} row indices but {} values",
            indices.len(),
            data.len()
        )));
    }
    let mut triplets = Vec::with_capacity(data.len());
    for j in 0..n {
        let (start, end) = (indptr[j], indptr[j + 1]);
        if start < 0 || end < start || end as usize > data.len() {
            return Err(bad(format!("column pointers not increasing at column {j}")));
        }
        for p in start as usize..end as usize {
            let i = indices[p];
            if i < 0 || i as usize >= n {
                return Err(bad(format!("row index {i} outside 0..{n} in column {j}")));
            }
            let v = data[p];
            if !v.is_finite() {
                return Err(bad(format!("entry ({i}, {j}) is {v}")));
            }
            triplets.push(faer::sparse::Triplet::new(i as usize, j, v));
        }
    }
    faer::sparse::SparseColMat::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| bad(format!("{e:?}")))
}

/// Craig-Bampton reduction of a sparse symmetric model (K, M given as CSC arrays, both
/// triangles stored) keeping the `boundary` DOFs physical and `modes` fixed-interface modes.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (n, k_indptr, k_indices, k_data, m_indptr, m_indices, m_data, boundary, modes, recover))]
pub fn reduce<'py>(
    py: Python<'py>,
    n: usize,
    k_indptr: PyReadonlyArray1<'py, i64>,
    k_indices: PyReadonlyArray1<'py, i64>,
    k_data: PyReadonlyArray1<'py, f64>,
    m_indptr: PyReadonlyArray1<'py, i64>,
    m_indices: PyReadonlyArray1<'py, i64>,
    m_data: PyReadonlyArray1<'py, f64>,
    boundary: Vec<i64>,
    modes: usize,
    recover: Vec<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let k = csc_matrix("K", n, &k_indptr, &k_indices, &k_data)?;
    let m = csc_matrix("M", n, &m_indptr, &m_indices, &m_data)?;
    let index = |what: &str, v: &[i64]| -> PyResult<Vec<usize>> {
        v.iter()
            .enumerate()
            .map(|(k, &i)| {
                if i < 0 || i as usize >= n {
                    Err(PyValueError::new_err(format!(
                        "reduce: {what}[{k}] = {i} is not a DOF index in 0..{n}"
                    )))
                } else {
                    Ok(i as usize)
                }
            })
            .collect()
    };
    let boundary = index("boundary", &boundary)?;
    let recover = index("recover", &recover)?;
    let options = fricbound_reduction::CbOptions::with_modes(modes);
    let reduced = in_background(py, None, |_| {
        fricbound_reduction::craig_bampton(k.as_ref(), m.as_ref(), &boundary, &recover, &options)
    })?
    .map_err(|e| PyValueError::new_err(format!("reduce: {e}")))?;
    convert::reduced_dict(py, &reduced)
}

/// Time integration of harmonic-balance points (`fricbound verify`, started from the HBM
/// state): at each frequency the point is solved from the stuck (else the open) linear guess,
/// its Hill stability computed when the harmonic set allows it, and the equations integrated
/// in time at dt and dt/2 ([`fricbound::analysis::verify::verify_point`]).
#[pyfunction]
#[pyo3(signature = (text, label, overrides, freqs_hz, steps_per_period=None, max_periods=None))]
pub fn verify<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    freqs_hz: Vec<f64>,
    steps_per_period: Option<usize>,
    max_periods: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    use fricbound::analysis::frf::PointSolver;
    use fricbound::analysis::{linear, stability, verify};
    if let Some(f) = freqs_hz.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        return Err(PyValueError::new_err(format!(
            "verify: freqs_hz: {f} is not a positive frequency (Hz)"
        )));
    }
    if steps_per_period.is_some_and(|s| s < 8) || max_periods == Some(0) {
        return Err(PyValueError::new_err(
            "verify: steps_per_period must be at least 8 and max_periods at least 1",
        ));
    }
    let (_, problem, _) = load(text, label, &overrides)?;
    let cases = in_background(py, None, |_| {
        freqs_hz
            .iter()
            .map(|&freq| {
                let omega = 2.0 * std::f64::consts::PI * freq;
                let mut solver = PointSolver::new(&problem).map_err(|e| e.to_string())?;
                let set = solver.system().unknowns().clone();
                let mut settings = verify::VerifySettings::for_harmonics(set.max_harmonic());
                if let Some(s) = steps_per_period {
                    settings.steps_per_period = s;
                }
                if let Some(p) = max_periods {
                    settings.max_periods = p;
                }
                let point = [linear::stuck_guess, linear::open_guess]
                    .iter()
                    .filter_map(|g| g(&problem, &set, omega).ok())
                    .find_map(|guess| solver.solve(&guess, freq).ok())
                    .ok_or_else(|| format!("harmonic balance did not converge at {freq} Hz"))?;
                let hill =
                    stability::point_stability(solver.system(), &point.coefficients, omega).ok();
                let checked = verify::verify_point(
                    &problem,
                    &set,
                    &point.coefficients,
                    &point.amplitudes,
                    freq,
                    &settings,
                )
                .map_err(|e| e.to_string())?;
                Ok((freq, point.amplitudes, hill, checked))
            })
            .collect::<Vec<Result<_, String>>>()
    })?;
    let cases = cases
        .into_iter()
        .map(|case| case.map_err(|e| SolveError::new_err(format!("{label}: verify: {e}"))))
        .collect::<PyResult<Vec<_>>>()?;
    // The status `fricbound verify` reports (its exit code 3 when incomplete).
    let incomplete = verify::incomplete_reason(
        cases
            .iter()
            .map(|(freq, _, _, v)| (verify::case_name(*freq, None), Some(v))),
    );
    let out = pyo3::types::PyList::empty(py);
    for (freq, hbm, hill, v) in cases {
        let d = PyDict::new(py);
        d.set_item("freq_hz", freq)?;
        d.set_item("hbm_amplitudes", hbm)?;
        d.set_item("hill_stable", hill.map(|h| h.stable))?;
        d.set_item("floquet_re", hill.map(|h| h.floquet_re))?;
        d.set_item("amplitudes", v.fine.amplitudes.clone())?;
        d.set_item("coarse_amplitudes", v.coarse.amplitudes.clone())?;
        d.set_item("hbm_difference", v.hbm_difference)?;
        d.set_item("dt_change", v.dt_change)?;
        d.set_item("periods", v.fine.periods)?;
        d.set_item("settled", v.fine.settled)?;
        d.set_item("steps_per_period", v.fine.steps_per_period)?;
        d.set_item("nonharmonic_energy", v.fine.nonharmonic_energy)?;
        d.set_item("last_period", v.fine.last_period.clone())?;
        out.append(d)?;
    }
    let result = PyDict::new(py);
    result.set_item("cases", out)?;
    result.set_item(
        "status",
        fricbound::report::files::status_text(incomplete.as_deref()),
    )?;
    Ok(result)
}

/// The linear reference of the scene with its contacts `"open"` (removed) or `"stuck"`
/// (replaced by their kt, kn springs) on `points` frequencies of the analysis range (default
/// `analysis.linear_points`), as the CLI's `linear_open.csv` / `linear_stuck.csv`.
#[pyfunction]
#[pyo3(signature = (text, label, overrides, case, points=None))]
pub fn linear<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    case: &str,
    points: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let case = match case {
        "open" => LinearCase::Open,
        "stuck" => LinearCase::Stuck,
        other => {
            return Err(PyValueError::new_err(format!(
                "linear: case must be \"open\" or \"stuck\", not {other:?}"
            )))
        }
    };
    if points.is_some_and(|p| p < 2) {
        return Err(PyValueError::new_err("linear: points must be at least 2"));
    }
    let (_, problem, _) = load(text, label, &overrides)?;
    let points = points.unwrap_or(problem.analysis.linear_points);
    let curve = in_background(py, None, |_| {
        fricbound::analysis::linear::reference_curve(&problem, case, points)
    })?
    .map_err(|e| SolveError::new_err(format!("{label}: linear reference: {e}")))?;
    let d = PyDict::new(py);
    convert::problem_names(&d, &problem)?;
    d.set_item("case", fricbound::analysis::modes::case_name(case))?;
    d.set_item(
        "freq_hz",
        numpy::PyArray1::from_vec(py, curve.freqs_hz.clone()),
    )?;
    let outputs = problem.outputs.len();
    let flat: Vec<f64> = curve.amplitudes.iter().flatten().copied().collect();
    d.set_item(
        "amplitudes",
        convert::array2(py, curve.freqs_hz.len(), outputs, flat)?,
    )?;
    Ok(d)
}

/// Forwards the accuracy study's finished jobs to the calling thread.
struct StudyEvents {
    tx: std::sync::Mutex<mpsc::Sender<Event>>,
    done: std::sync::atomic::AtomicUsize,
    total: usize,
}

impl StudyObserver for StudyEvents {
    fn setting(&self, result: &SettingResult, _errors: &SettingErrors) {
        if let Ok(tx) = self.tx.lock() {
            let _ = tx.send(Event::StudySetting {
                curve: result.curve.clone(),
                setting: result.setting.label.clone(),
                done: self.done.load(std::sync::atomic::Ordering::Relaxed),
                total: self.total,
            });
        }
    }

    fn job_done(&self) {
        self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }
}

/// The accuracy study of the scene (`fricbound study accuracy`): every setting's errors
/// against its curve's reference, time, Newton iterations and unknowns, per curve (the FRF, or
/// each limit curve of a limit scene). `quick` uses the short setting lists.
#[pyfunction]
#[pyo3(signature = (text, label, overrides, quick, progress=None))]
pub fn accuracy_study<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    overrides: Vec<String>,
    quick: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let plan = StudyPlan::new(text, label, &overrides, quick).map_err(scene_error)?;
    check_memory(label, &plan.problem, rayon_threads())?;
    let result = in_background(py, progress.as_ref(), |tx| {
        let events = StudyEvents {
            tx: std::sync::Mutex::new(tx),
            done: std::sync::atomic::AtomicUsize::new(0),
            total: plan.jobs(),
        };
        plan.run(&events)
    })?;
    let studies = result.map_err(|e| match e {
        StudyError::Scene(e) => scene_error(e),
        e @ StudyError::ReferenceFailed { .. } => SolveError::new_err(format!("{label}: {e}")),
    })?;
    convert::accuracy_dict(py, &plan, &studies)
}
