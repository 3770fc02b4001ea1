//! Files of `fricbound modes`: the natural frequencies of the full and the reduced model side
//! by side (`modes.csv`), the damped modes (`damped_modes.csv`), the mode shapes (VTU on the
//! mesh, CSV otherwise) and everything in `modes.json` with the reduction report.
//!
//! `modes.csv` columns: `case` (open|stuck), `mode` (1-based), `full_hz`, `full_rigid`
//! (true for a rigid-body mode, reported at 0 Hz), `reduced_hz`, `reduced_rigid`, `rel_error`
//! ((f_reduced − f_full)/f_full; empty where either model has no such mode or the mode is
//! rigid). Modes are paired by their rank in each model.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::analysis::modes::{case_name, DampedModes, EigenMethod, NaturalModes};
use crate::fe::{write_vtu, PointField, VtuError};
use crate::model::Problem;
use crate::report::files::WriteError;
use crate::report::reduced_files::ReductionJson;

/// The modes of one contact case in the full model and, when the scene reduces, the reduced
/// model.
#[derive(Debug, Clone)]
pub struct CaseModes {
    /// Full model.
    pub full: NaturalModes,
    /// Reduced model.
    pub reduced: Option<NaturalModes>,
    /// Damped modes of the full model (None: undamped or too large).
    pub full_damped: Option<DampedModes>,
    /// Damped modes of the reduced model.
    pub reduced_damped: Option<DampedModes>,
}

/// Relative error of a reduced frequency, `None` where it has no meaning.
pub fn relative_error(
    full: f64,
    full_rigid: bool,
    reduced: f64,
    reduced_rigid: bool,
) -> Option<f64> {
    (!full_rigid && !reduced_rigid && full > 0.0).then(|| (reduced - full) / full)
}

/// `modes.csv` (columns in the module docs).
pub fn modes_csv(cases: &[CaseModes]) -> String {
    let mut s = String::from("case,mode,full_hz,full_rigid,reduced_hz,reduced_rigid,rel_error\n");
    for c in cases {
        let name = case_name(c.full.case);
        let rows = c
            .full
            .modes
            .len()
            .max(c.reduced.as_ref().map_or(0, |r| r.modes.len()));
        for i in 0..rows {
            let f = c.full.modes.get(i);
            let r = c.reduced.as_ref().and_then(|r| r.modes.get(i));
            let cell = |m: Option<&crate::analysis::modes::Mode>| {
                m.map(|m| (format!("{:.10e}", m.frequency_hz), m.rigid.to_string()))
                    .unwrap_or_default()
            };
            let (fh, fr) = cell(f);
            let (rh, rr) = cell(r);
            let err = match (f, r) {
                (Some(f), Some(r)) => {
                    relative_error(f.frequency_hz, f.rigid, r.frequency_hz, r.rigid)
                        .map(|e| format!("{e:.6e}"))
                        .unwrap_or_default()
                }
                _ => String::new(),
            };
            let _ = writeln!(s, "{name},{},{fh},{fr},{rh},{rr},{err}", i + 1);
        }
    }
    s
}

/// `damped_modes.csv`: `case,model,mode,natural_hz,damped_hz,damping_ratio,re,im` (s = re + i·im
/// in 1/s); elastic modes only, rigid-body eigenvalues are counted in `modes.json`.
pub fn damped_csv(cases: &[CaseModes]) -> String {
    let mut s = String::from("case,model,mode,natural_hz,damped_hz,damping_ratio,re,im\n");
    for c in cases {
        let name = case_name(c.full.case);
        for (model, modes) in [("full", &c.full_damped), ("reduced", &c.reduced_damped)] {
            for (i, m) in modes.iter().flat_map(|d| &d.modes).enumerate() {
                let _ = writeln!(
                    s,
                    "{name},{model},{},{:.10e},{:.10e},{:.6e},{:.10e},{:.10e}",
                    i + 1,
                    m.natural_hz,
                    m.damped_hz,
                    m.damping_ratio,
                    m.eigenvalue.re,
                    m.eigenvalue.im
                );
            }
        }
    }
    s
}

/// Mode shapes as CSV: `dof,mode_1,...` one row per DOF of `problem` (mass-normalised).
pub fn shapes_csv(problem: &Problem, modes: &NaturalModes) -> String {
    let mut s = String::from("dof");
    for j in 0..modes.modes.len() {
        let _ = write!(s, ",mode_{}", j + 1);
    }
    s.push('\n');
    for (i, name) in problem.model.dof_names.iter().enumerate() {
        s.push_str(name);
        for j in 0..modes.modes.len() {
            let _ = write!(s, ",{:.10e}", modes.shapes[(i, j)]);
        }
        s.push('\n');
    }
    s
}

/// Writes the mode shapes on the mesh as VTU (one vector field `mode_NN` per mode; the
/// frequencies are in `modes.csv`); false when the problem has no mesh, or is reduced without
/// a kept basis.
pub fn write_shapes_vtu(
    path: &Path,
    problem: &Problem,
    modes: &NaturalModes,
) -> Result<bool, VtuError> {
    let Some(fe) = &problem.fe else {
        return Ok(false);
    };
    let index = fe.mesh.node_index_map();
    let n = problem.model.n_dofs();
    let mut fields = Vec::new();
    for mode in 0..modes.modes.len() {
        let shape: Vec<f64> = (0..n).map(|i| modes.shapes[(i, mode)]).collect();
        let Some(full) = fe.full_values(&shape) else {
            return Ok(false);
        };
        let mut nodal = vec![[0.0; 3]; fe.mesh.nodes.len()];
        for (row, dof) in fe.dofs.dofs().iter().enumerate() {
            if let (Some(&i), true) = (index.get(&dof.node), dof.direction.is_translation()) {
                nodal[i][dof.direction.axis()] = full[row];
            }
        }
        fields.push(PointField::vectors(&format!("mode_{:02}", mode + 1), nodal));
    }
    write_vtu(path, &fe.mesh, &fields)?;
    Ok(true)
}

/// One model's modes in `modes.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ModelModesJson {
    /// Frequencies (Hz), rigid-body modes at 0.
    pub frequencies_hz: Vec<f64>,
    /// Eigenvalues λ = ω² (rad²/s²).
    pub eigenvalues: Vec<f64>,
    /// Rigid-body flags.
    pub rigid: Vec<bool>,
    /// `dense` or `lanczos`.
    pub method: String,
    /// Sturm count of the Lanczos check (eigenvalues below `sturm_shift_hz`).
    pub sturm_count: Option<usize>,
    /// Shift of the Sturm check (Hz).
    pub sturm_shift_hz: Option<f64>,
    /// Largest relative residual of the Lanczos pairs.
    pub max_residual: Option<f64>,
    /// Wall-clock time (s).
    pub seconds: f64,
    /// Damped elastic modes: natural and damped frequency (Hz) and damping ratio.
    pub damped: Option<Vec<[f64; 3]>>,
    /// Rigid-body eigenvalues of the damped problem left out of `damped`.
    pub damped_rigid: Option<usize>,
}

impl ModelModesJson {
    /// From computed modes.
    pub fn new(m: &NaturalModes, damped: Option<&DampedModes>) -> Self {
        let (method, sturm_count, sturm_shift_hz, max_residual) = match &m.method {
            EigenMethod::Dense => ("dense", None, None, None),
            EigenMethod::Lanczos {
                sturm_count,
                sturm_shift_hz,
                max_residual,
            } => (
                "lanczos",
                *sturm_count,
                Some(*sturm_shift_hz),
                Some(*max_residual),
            ),
        };
        ModelModesJson {
            frequencies_hz: m.modes.iter().map(|x| x.frequency_hz).collect(),
            eigenvalues: m.modes.iter().map(|x| x.eigenvalue).collect(),
            rigid: m.modes.iter().map(|x| x.rigid).collect(),
            method: method.to_string(),
            sturm_count,
            sturm_shift_hz,
            max_residual,
            seconds: m.seconds,
            damped_rigid: damped.map(|d| d.rigid),
            damped: damped.map(|d| {
                d.modes
                    .iter()
                    .map(|x| [x.natural_hz, x.damped_hz, x.damping_ratio])
                    .collect()
            }),
        }
    }
}

/// One contact case in `modes.json`.
#[derive(Debug, Clone, Serialize)]
pub struct CaseJson {
    /// `open` or `stuck`.
    pub case: String,
    /// Full model.
    pub full: ModelModesJson,
    /// Reduced model.
    pub reduced: Option<ModelModesJson>,
    /// Relative errors of the reduced frequencies, by rank (null where meaningless).
    pub relative_errors: Vec<Option<f64>>,
}

/// `modes.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ModesJson {
    /// Program version.
    pub version: String,
    /// Scene label.
    pub scene: String,
    /// Full-model DOFs.
    pub dofs: usize,
    /// Modes asked per case.
    pub count: usize,
    /// Per contact case.
    pub cases: Vec<CaseJson>,
    /// The reduction, when the scene reduces.
    pub reduction: Option<ReductionJson>,
}

/// Relative errors by rank.
pub fn relative_errors(c: &CaseModes) -> Vec<Option<f64>> {
    let Some(r) = &c.reduced else {
        return Vec::new();
    };
    c.full
        .modes
        .iter()
        .zip(&r.modes)
        .map(|(f, r)| relative_error(f.frequency_hz, f.rigid, r.frequency_hz, r.rigid))
        .collect()
}

impl CaseJson {
    /// From computed modes.
    pub fn new(c: &CaseModes) -> Self {
        CaseJson {
            case: case_name(c.full.case).to_string(),
            full: ModelModesJson::new(&c.full, c.full_damped.as_ref()),
            reduced: c
                .reduced
                .as_ref()
                .map(|r| ModelModesJson::new(r, c.reduced_damped.as_ref())),
            relative_errors: relative_errors(c),
        }
    }
}

/// Writes `modes.json`.
pub fn write_modes_json(path: &Path, json: &ModesJson) -> Result<(), WriteError> {
    crate::report::reduced_files::write_json(path, json)
}
