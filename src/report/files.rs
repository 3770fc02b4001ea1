//! Result files: `frf.csv`, `linear_open.csv`, `linear_stuck.csv` and `solution.json`.
//!
//! Files are replaced atomically (written to a temporary sibling, then renamed), and the FRF
//! writer rewrites `frf.csv` after every converged point, so an interrupted run keeps every
//! point finished so far. `solution.json` is rewritten at most every half second while running
//! and once at the end.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::analysis::frf::{FrfObserver, FrfPoint};
use crate::analysis::linear::LinearCurve;
use crate::model::Problem;
use crate::numerics::NewtonFailure;

/// Writing a result file failed.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot write: {source}")]
pub struct WriteError {
    /// File being written.
    pub path: String,
    /// Cause.
    pub source: std::io::Error,
}

/// Writes `bytes` to `path` atomically (temporary file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    let err = |source| WriteError {
        path: path.display().to_string(),
        source,
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, bytes).map_err(err)?;
    std::fs::rename(&tmp, path).map_err(err)
}

/// Header of `frf.csv`: `freq_hz`, `<dof>_amp`, `<dof>_peak` per output, `<contact>_state` per
/// contact, `newton_iters`.
pub fn frf_header(problem: &Problem) -> String {
    let mut h = String::from("freq_hz");
    for &d in &problem.outputs {
        let name = &problem.model.dof_names[d];
        let _ = write!(h, ",{name}_amp,{name}_peak");
    }
    for c in &problem.contacts {
        let _ = write!(h, ",{}_state", c.name);
    }
    h.push_str(",newton_iters\n");
    h
}

/// One `frf.csv` row.
pub fn frf_row(point: &FrfPoint) -> String {
    let mut r = format!("{:.10e}", point.freq_hz);
    for (a, p) in point.amplitudes.iter().zip(&point.peaks) {
        let _ = write!(r, ",{a:.10e},{p:.10e}");
    }
    for s in &point.states {
        let _ = write!(r, ",{}", s.label());
    }
    let _ = writeln!(r, ",{}", point.newton_iterations);
    r
}

/// CSV of a linear reference: `freq_hz`, `<dof>_amp` per output.
pub fn linear_csv(problem: &Problem, curve: &LinearCurve) -> String {
    let mut s = String::from("freq_hz");
    for &d in &problem.outputs {
        let _ = write!(s, ",{}_amp", problem.model.dof_names[d]);
    }
    s.push('\n');
    for (f, amps) in curve.freqs_hz.iter().zip(&curve.amplitudes) {
        let _ = write!(s, "{f:.10e}");
        for a in amps {
            let _ = write!(s, ",{a:.10e}");
        }
        s.push('\n');
    }
    s
}

/// Run metadata stored in `solution.json`.
#[derive(Debug, Clone, Serialize)]
pub struct RunInfo {
    /// fricbound version.
    pub version: String,
    /// Scene file (or the built-in default).
    pub scene: String,
    /// SHA-256 of the scene as solved (after overrides), in canonical TOML.
    pub scene_hash: String,
    /// DOF names.
    pub dofs: Vec<String>,
    /// Unknown coefficient blocks, e.g. ["0", "c1", "s1"].
    pub blocks: Vec<String>,
    /// Contact names.
    pub contacts: Vec<String>,
    /// Output DOF names.
    pub outputs: Vec<String>,
}

#[derive(Serialize)]
struct SolutionFile<'a> {
    info: &'a RunInfo,
    status: &'a str,
    elapsed_s: f64,
    mean_point_ms: f64,
    turning_points_hz: &'a [f64],
    step_cuts: &'a [StepCut],
    leaps_hz: &'a [(f64, f64)],
    /// Where the coefficients are when they are not inline (large models).
    #[serde(skip_serializing_if = "Option::is_none")]
    coefficients_file: Option<CoefficientsFile>,
    points: Vec<PointRecord<'a>>,
}

/// Most coefficients per point kept inline in `solution.json`; larger models append them to
/// `coefficients.bin` instead (rewriting a JSON file of every point's full coefficients would
/// cost time quadratic in the number of points).
pub const INLINE_COEFFICIENTS: usize = 4096;

/// Description of `coefficients.bin`.
#[derive(Debug, Clone, Serialize)]
struct CoefficientsFile {
    file: &'static str,
    values_per_point: usize,
    layout: &'static str,
}

/// One point as written in `solution.json`.
#[derive(Serialize)]
struct PointRecord<'a> {
    freq_hz: f64,
    amplitudes: &'a [f64],
    peaks: &'a [f64],
    states: &'a [crate::contact::ContactState],
    newton_iterations: usize,
    residual: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    coefficients: Option<&'a [f64]>,
}

/// A cut continuation step, kept for the record.
#[derive(Debug, Clone, Serialize)]
pub struct StepCut {
    /// Frequency of the last converged point (Hz).
    pub freq_hz: f64,
    /// Step that failed.
    pub step: f64,
    /// Why.
    pub reason: String,
}

/// Observer that streams an FRF run to `frf.csv` and `solution.json` in a folder.
pub struct FrfWriter {
    dir: PathBuf,
    header: String,
    csv: String,
    info: RunInfo,
    points: Vec<FrfPoint>,
    turning_points: Vec<f64>,
    step_cuts: Vec<StepCut>,
    leaps: Vec<(f64, f64)>,
    started: Instant,
    last_json: Option<Instant>,
    /// Time the last `solution.json` write took (s); writes are spaced by at least ten times it.
    last_json_s: f64,
    /// First write error met (writing stops being attempted after it).
    pub error: Option<WriteError>,
}

impl FrfWriter {
    /// A writer into `dir` (which must exist).
    pub fn new(dir: &Path, problem: &Problem, info: RunInfo) -> Self {
        let header = frf_header(problem);
        Self {
            dir: dir.to_path_buf(),
            csv: header.clone(),
            header,
            info,
            points: Vec::new(),
            turning_points: Vec::new(),
            step_cuts: Vec::new(),
            leaps: Vec::new(),
            started: Instant::now(),
            last_json: None,
            last_json_s: 0.0,
            error: None,
        }
    }

    /// Points written so far.
    pub fn points(&self) -> &[FrfPoint] {
        &self.points
    }

    /// Header line of the CSV (for tests).
    pub fn header(&self) -> &str {
        &self.header
    }

    /// Writes `solution.json` with a status line ("running", "complete", or a failure).
    pub fn write_solution(&mut self, status: &str) -> Result<(), WriteError> {
        let write_started = Instant::now();
        let elapsed = self.started.elapsed().as_secs_f64();
        let inline = self
            .points
            .first()
            .is_none_or(|p| p.coefficients.len() <= INLINE_COEFFICIENTS);
        let file = SolutionFile {
            info: &self.info,
            status,
            elapsed_s: elapsed,
            mean_point_ms: if self.points.is_empty() {
                0.0
            } else {
                1e3 * elapsed / self.points.len() as f64
            },
            turning_points_hz: &self.turning_points,
            step_cuts: &self.step_cuts,
            leaps_hz: &self.leaps,
            coefficients_file: (!inline).then(|| CoefficientsFile {
                file: "coefficients.bin",
                values_per_point: self.points[0].coefficients.len(),
                layout: "f64 little-endian, one row per point in point order, each row the \
                         point's Fourier coefficients harmonic-major (blocks of info.blocks, each \
                         holding every DOF of info.dofs)",
            }),
            points: self
                .points
                .iter()
                .map(|p| PointRecord {
                    freq_hz: p.freq_hz,
                    amplitudes: &p.amplitudes,
                    peaks: &p.peaks,
                    states: &p.states,
                    newton_iterations: p.newton_iterations,
                    residual: p.residual,
                    coefficients: inline.then_some(p.coefficients.as_slice()),
                })
                .collect(),
        };
        let json = serde_json::to_vec_pretty(&file).expect("result types serialise");
        let result = write_atomic(&self.dir.join("solution.json"), &json);
        self.last_json_s = write_started.elapsed().as_secs_f64();
        result
    }

    /// Appends a point's coefficients to `coefficients.bin` (large models).
    fn append_coefficients(&self, point: &FrfPoint) -> Result<(), WriteError> {
        use std::io::Write as _;
        let path = self.dir.join("coefficients.bin");
        let err = |source| WriteError {
            path: path.display().to_string(),
            source,
        };
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(err)?;
        let bytes: Vec<u8> = point
            .coefficients
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        f.write_all(&bytes).map_err(err)
    }

    fn record(&mut self, r: Result<(), WriteError>) {
        if let Err(e) = r {
            if self.error.is_none() {
                self.error = Some(e);
            }
        }
    }
}

impl FrfObserver for FrfWriter {
    fn point(&mut self, point: &FrfPoint) {
        self.points.push(point.clone());
        if self.error.is_some() {
            return;
        }
        self.csv.push_str(&frf_row(point));
        let r = write_atomic(&self.dir.join("frf.csv"), self.csv.as_bytes());
        self.record(r);
        if point.coefficients.len() > INLINE_COEFFICIENTS {
            if self.points.len() == 1 {
                let _ = std::fs::remove_file(self.dir.join("coefficients.bin"));
            }
            let r = self.append_coefficients(point);
            self.record(r);
        }
        let spacing = (10.0 * self.last_json_s).max(0.5);
        let due = self
            .last_json
            .is_none_or(|t| t.elapsed().as_secs_f64() >= spacing);
        if due && self.error.is_none() {
            let r = self.write_solution("running");
            self.record(r);
            self.last_json = Some(Instant::now());
        }
    }

    fn step_cut(&mut self, freq_hz: f64, step: f64, _new_step: f64, reason: &NewtonFailure) {
        self.step_cuts.push(StepCut {
            freq_hz,
            step,
            reason: reason.to_string(),
        });
    }

    fn turning_point(&mut self, freq_hz: f64) {
        self.turning_points.push(freq_hz);
    }

    fn leap(&mut self, from_hz: f64, to_hz: f64) {
        self.leaps.push((from_hz, to_hz));
    }
}
