//! Files of `fricbound reduce`: the reduced model for use elsewhere or for checking, and the
//! reduction report shared with `fricbound modes`.
//!
//! - `K_r.mtx`, `M_r.mtx`, `C_r.mtx`: Matrix Market `coordinate real symmetric` (one
//!   triangle, 1-based) of the reduced stiffness (N/m), mass (kg) and damping (N·s/m), in the
//!   reduced coordinates q = [u_B; η]. The Craig-Bampton products are symmetric up to
//!   round-off; the files hold (A + Aᵀ)/2. C_r is the reduced damping the solver uses
//!   (Rayleigh αM_r + βK_r plus 2ζω_i on the modal coordinates), written only when non-zero.
//! - `reduced_dofs.csv`: `row,name,kind,node,direction,fixed_interface_hz`, one line per
//!   reduced coordinate, `row` 1-based as in the `.mtx` files; `kind` is `physical` (a
//!   boundary DOF of the full model, named `<node>.<dir>`, with its node and direction) or
//!   `modal` (a fixed-interface mode `modeN`, with its frequency in Hz).
//! - `recovery.mtx` (`coordinate real general`) and `recovery_dofs.csv` (`row,dof`): the rows
//!   of the Craig-Bampton basis T for the recovered full-model DOFs (the scene's outputs),
//!   u_dof = T[dof, :] q.
//! - `reduction.json`: [`ReductionJson`].

use std::path::{Path, PathBuf};

use faer::Mat;
use serde::Serialize;

use crate::model::reduce::{BoundaryMakeup, Reduction};
use crate::report::files::{write_atomic, WriteError};

/// The reduction report in JSON (`reduction.json`, and the `reduction` of `modes.json`).
#[derive(Debug, Clone, Serialize)]
pub struct ReductionJson {
    /// Full-model DOFs.
    pub n_full: usize,
    /// Boundary DOFs kept physical.
    pub n_boundary: usize,
    /// Boundary make-up by origin.
    pub boundary_contacts: usize,
    /// Other directions of contact nodes kept physical.
    pub boundary_contact_nodes: usize,
    /// Output DOFs.
    pub boundary_outputs: usize,
    /// `[reduction.boundary]` DOFs.
    pub boundary_extra: usize,
    /// Loaded DOFs (projected on the basis, not in the boundary).
    pub loaded_dofs: usize,
    /// Contact nodes whose contact rows use fewer directions than the node has.
    pub partial_contact_nodes: usize,
    /// Fixed-interface modes kept.
    pub n_modes: usize,
    /// Reduced size.
    pub n_reduced: usize,
    /// Fixed-interface frequencies (Hz).
    pub fixed_interface_hz: Vec<f64>,
    /// Highest kept fixed-interface frequency (Hz).
    pub cutoff_hz: f64,
    /// Next fixed-interface frequency not kept (Hz).
    pub next_hz: Option<f64>,
    /// Sturm count of the fixed-interface check (should equal `n_modes`).
    pub sturm_count: Option<usize>,
    /// Seconds in all (wall clock).
    pub t_total: f64,
    /// Seconds of the fill-reducing ordering, symbolic and numeric factorisation.
    pub t_factor: f64,
    /// Seconds of the fixed-interface eigen solve.
    pub t_eigen: f64,
    /// Seconds of the constraint modes and reduced matrices.
    pub t_constraint: f64,
    /// Seconds of the Sturm check.
    pub t_sturm: f64,
    /// CPU seconds of the process during the reduction.
    pub cpu_seconds: Option<f64>,
    /// Peak resident memory (bytes).
    pub peak_memory_bytes: Option<u64>,
}

impl ReductionJson {
    /// From a reduction.
    pub fn new(r: &Reduction) -> Self {
        let rep = &r.model.report;
        let BoundaryMakeup {
            contacts,
            contact_nodes,
            outputs,
            extra,
            loaded,
        } = r.boundary.makeup;
        ReductionJson {
            n_full: rep.n_full,
            n_boundary: rep.n_boundary,
            boundary_contacts: contacts,
            boundary_contact_nodes: contact_nodes,
            boundary_outputs: outputs,
            boundary_extra: extra,
            loaded_dofs: loaded,
            partial_contact_nodes: r.boundary.partial_contact_nodes.len(),
            n_modes: rep.n_modes,
            n_reduced: r.model.size(),
            fixed_interface_hz: r.model.modal_frequencies_hz.clone(),
            cutoff_hz: rep.cutoff_hz,
            next_hz: rep.next_hz,
            sturm_count: rep.sturm_count,
            t_total: rep.t_total,
            t_factor: rep.t_ordering + rep.t_symbolic + rep.t_numeric,
            t_eigen: rep.t_eigen,
            t_constraint: rep.t_constraint,
            t_sturm: rep.t_sturm,
            cpu_seconds: rep.cpu_seconds,
            peak_memory_bytes: rep.peak_memory_bytes,
        }
    }

    /// The boundary's make-up as one line.
    pub fn makeup_line(&self) -> String {
        format!(
            "{} boundary DOFs: {} contact, {} other directions of contact nodes, {} output, {} \
             extra ([reduction.boundary]); {} loaded DOFs projected on the basis",
            self.n_boundary,
            self.boundary_contacts,
            self.boundary_contact_nodes,
            self.boundary_outputs,
            self.boundary_extra,
            self.loaded_dofs
        )
    }
}

/// Writes `value` as pretty JSON.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), WriteError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| WriteError {
        path: path.display().to_string(),
        source: std::io::Error::other(e),
    })?;
    write_atomic(path, text.as_bytes())
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> WriteError + '_ {
    move |source| WriteError {
        path: path.display().to_string(),
        source,
    }
}

/// Writes a dense symmetric matrix as Matrix Market `coordinate real symmetric` ((A + Aᵀ)/2,
/// non-zero entries of one triangle).
pub fn write_symmetric_mtx(path: &Path, a: &Mat<f64>) -> Result<(), WriteError> {
    let n = a.nrows();
    let mut tri = sprs::TriMatI::<f64, usize>::new((n, n));
    for j in 0..n {
        for i in j..n {
            let v = 0.5 * (a[(i, j)] + a[(j, i)]);
            if v != 0.0 {
                // sprs writes the entries with row ≤ column of a symmetric file.
                tri.add_triplet(j, i, v);
            }
        }
    }
    let csc: sprs::CsMatI<f64, usize> = tri.to_csc();
    sprs::io::write_matrix_market_sym(path, &csc, sprs::io::SymmetryMode::Symmetric)
        .map_err(io_err(path))
}

/// Writes rows of a dense matrix as Matrix Market `coordinate real general`.
pub fn write_general_mtx(path: &Path, rows: &[Vec<f64>], ncols: usize) -> Result<(), WriteError> {
    let mut tri = sprs::TriMatI::<f64, usize>::new((rows.len(), ncols));
    for (i, r) in rows.iter().enumerate() {
        for (j, &v) in r.iter().enumerate() {
            if v != 0.0 {
                tri.add_triplet(i, j, v);
            }
        }
    }
    let csc: sprs::CsMatI<f64, usize> = tri.to_csc();
    sprs::io::write_matrix_market(path, &csc).map_err(io_err(path))
}

/// `reduced_dofs.csv` of a reduction (columns in the module docs).
pub fn reduced_dofs_csv(r: &Reduction) -> String {
    use std::fmt::Write as _;
    let mut s = String::from("row,name,kind,node,direction,fixed_interface_hz\n");
    let nb = r.model.boundary.len();
    for (i, name) in r.problem.model.dof_names.iter().enumerate() {
        if i < nb {
            let (node, dir) = name.rsplit_once('.').unwrap_or((name.as_str(), ""));
            let _ = writeln!(s, "{},{name},physical,{node},{dir},", i + 1);
        } else {
            let f = r
                .model
                .modal_frequencies_hz
                .get(i - nb)
                .copied()
                .unwrap_or(f64::NAN);
            let _ = writeln!(s, "{},{name},modal,,,{f:.10e}", i + 1);
        }
    }
    s
}

/// Writes the files of `fricbound reduce` into `dir` (module docs); `full_names` are the
/// full model's DOF names (for the recovery rows). Returns the paths written.
pub fn write_reduced_model(
    dir: &Path,
    r: &Reduction,
    full_names: &[String],
) -> Result<Vec<PathBuf>, WriteError> {
    let mut written = Vec::new();
    let model = &r.problem.model;
    for (file, m) in [("K_r.mtx", &model.stiffness), ("M_r.mtx", &model.mass)] {
        let path = dir.join(file);
        write_symmetric_mtx(&path, &m.to_dense())?;
        written.push(path);
    }
    let c = model.damping.to_dense();
    let damped = (0..c.ncols()).any(|j| (0..c.nrows()).any(|i| c[(i, j)] != 0.0));
    if damped {
        let path = dir.join("C_r.mtx");
        write_symmetric_mtx(&path, &c)?;
        written.push(path);
    }
    let path = dir.join("reduced_dofs.csv");
    write_atomic(&path, reduced_dofs_csv(r).as_bytes())?;
    written.push(path);
    if !r.model.recovery.is_empty() {
        let rows: Vec<Vec<f64>> = r.model.recovery.iter().map(|x| x.row.clone()).collect();
        let path = dir.join("recovery.mtx");
        write_general_mtx(&path, &rows, r.model.size())?;
        written.push(path);
        let mut s = String::from("row,dof\n");
        for (i, x) in r.model.recovery.iter().enumerate() {
            s.push_str(&format!("{},{}\n", i + 1, full_names[x.dof]));
        }
        let path = dir.join("recovery_dofs.csv");
        write_atomic(&path, s.as_bytes())?;
        written.push(path);
    }
    let path = dir.join("reduction.json");
    write_json(&path, &ReductionJson::new(r))?;
    written.push(path);
    Ok(written)
}
