//! `fricbound._native`: the extension module of the Python package.
//!
//! It only converts and calls: scene text and `--set` overrides go to the library's scene
//! parser ([`fricbound::scene::parse`]), solves go to the same library functions the CLI calls
//! ([`fricbound::analysis::frf::solve`], [`fricbound::analysis::limits::analyse`],
//! [`fricbound::study::sweep::run`], [`fricbound::analysis::modes::natural_modes`],
//! [`fricbound::analysis::verify::verify_point`], [`fricbound::study::accuracy::StudyPlan`],
//! [`fricbound_reduction::craig_bampton`]), and results come back as dicts of numpy arrays that
//! the pure-Python layer (`python/fricbound/`) wraps in result classes.
//!
//! Errors: a bad scene or bad input raises `ValueError` with the library's message (file,
//! dotted field path, reason); a solve that fails raises `fricbound.SolveError` (a
//! `RuntimeError`). Solves run with the GIL released on a worker thread while the calling
//! thread forwards progress events to the optional callback and checks for signals: Ctrl-C
//! (or an exception raised by the callback) asks the library's continuation runs to stop
//! ([`fricbound::numerics::interrupt`]) and is raised once they have.

mod convert;
mod modes_nl;
mod solve;

use pyo3::prelude::*;

pyo3::create_exception!(
    _native,
    SolveError,
    pyo3::exceptions::PyRuntimeError,
    "A solve failed (no solution at the start frequency, a stalled continuation, a singular \
     system); the message names the scene and the cause."
);

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SolveError", m.py().get_type::<SolveError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(solve::paper_scene, m)?)?;
    m.add_function(wrap_pyfunction!(solve::parse_scene, m)?)?;
    m.add_function(wrap_pyfunction!(solve::scene_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(solve::check, m)?)?;
    m.add_function(wrap_pyfunction!(solve::run, m)?)?;
    m.add_function(wrap_pyfunction!(solve::limits, m)?)?;
    m.add_function(wrap_pyfunction!(solve::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(solve::modes, m)?)?;
    m.add_function(wrap_pyfunction!(modes_nl::nonlinear_modes, m)?)?;
    m.add_function(wrap_pyfunction!(solve::reduce, m)?)?;
    m.add_function(wrap_pyfunction!(solve::verify, m)?)?;
    m.add_function(wrap_pyfunction!(solve::linear, m)?)?;
    m.add_function(wrap_pyfunction!(solve::accuracy_study, m)?)?;
    Ok(())
}
