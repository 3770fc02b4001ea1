//! Result files: `frf.csv`, `linear_open.csv`, `linear_stuck.csv`, `peaks.csv` and
//! `solution.json`.
//!
//! The FRF writer appends one row of `frf.csv` per converged point (flushed at once, so an
//! interrupted run keeps every point finished so far) and rewrites `solution.json` whole, and
//! atomically, at checkpoints and at the end ([`FrfWriter`]); after the continuation it writes
//! the refined resonances and anti-resonances of every output to `peaks.csv` and to the
//! `peaks` array of `solution.json` ([`FrfWriter::write_peaks`]). The other files are replaced
//! atomically (written to a temporary sibling, then renamed) by [`write_atomic`].

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::analysis::error_estimate::EstimateMethod;
use crate::analysis::frf::{FrfObserver, FrfPoint, Jump};
use crate::analysis::linear::LinearCurve;
use crate::analysis::peaks::{ExtremumKind, PathExtremum};
use crate::contact::ContactState;
use crate::model::Problem;
use crate::numerics::NewtonFailure;
use crate::report::stability_columns;

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
/// contact, `newton_iters`, then the error-estimate columns ([`accuracy_header`]), then with
/// `analysis.stability` the columns of [`stability_columns`].
pub fn frf_header(problem: &Problem) -> String {
    let mut h = String::from("freq_hz");
    for &d in &problem.outputs {
        let name = &problem.model.dof_names[d];
        let _ = write!(h, ",{name}_amp,{name}_peak");
    }
    for c in &problem.contacts {
        let _ = write!(h, ",{}_state", c.name);
    }
    h.push_str(",newton_iters");
    accuracy_header(problem, &mut h);
    h.push_str(stability_columns::header(problem));
    h.push('\n');
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
    let _ = write!(r, ",{}", point.newton_iterations);
    accuracy_cells(point, &mut r);
    r.push_str(&stability_columns::cells(point.stability.as_ref()));
    r.push('\n');
    r
}

// ---- Error-estimate columns: kept together here so that other column additions
// merge beside them.

/// The error-estimate columns of `frf.csv` and `curve_*.csv`, when the scene asks for the
/// estimate (`[accuracy].estimate`): `<dof>_trunc_err` and `<dof>_sampling_err` per output,
/// the estimated relative error of the first-harmonic amplitude due to harmonic truncation and
/// AFT sampling ([`crate::analysis::error_estimate`]), then `estimate_harmonic`, the highest
/// harmonic of the extended set the point's truncation estimate comes from (2H + 1, or 4H + 3
/// where the estimate was widened; 0 where it could not be formed:
/// [`crate::analysis::error_estimate::PointAccuracy::estimate_harmonic`]), and
/// `estimate_method`, how the truncation estimate was formed: `step` (one Newton step of the
/// extended system), `solved` (the extended system solved to convergence, where the step left
/// its linear range), `unsized` (not sizeable: the run warns) or `none` (not formed:
/// [`crate::analysis::error_estimate::EstimateMethod`]).
pub fn accuracy_header(problem: &Problem, h: &mut String) {
    if problem.analysis.error_estimate.enabled {
        for &d in &problem.outputs {
            let name = &problem.model.dof_names[d];
            let _ = write!(h, ",{name}_trunc_err,{name}_sampling_err");
        }
        h.push_str(",estimate_harmonic,estimate_method");
    }
}

/// The cells of [`accuracy_header`] for one point (nothing when the point has no estimate;
/// every continuation point of a run with the estimate on has one). NaN: not formed.
pub fn accuracy_cells(point: &FrfPoint, r: &mut String) {
    if let Some(acc) = &point.accuracy {
        for (t, s) in acc.truncation.iter().zip(&acc.sampling) {
            let _ = write!(r, ",{t:.3e},{s:.3e}");
        }
        let _ = write!(r, ",{},{}", acc.estimate_harmonic, acc.method.label());
    }
}

/// The largest error estimates of a run's points, for `solution.json` and `limits.json`.
#[derive(Debug, Clone, Serialize)]
pub struct AccuracySummary {
    /// Output DOF names.
    pub outputs: Vec<String>,
    /// Largest harmonic-truncation estimate per output (relative).
    pub max_trunc_err: Vec<f64>,
    /// Largest AFT-sampling estimate per output (relative).
    pub max_sampling_err: Vec<f64>,
    /// Frequency of the point with the largest truncation estimate per output (Hz).
    pub max_trunc_err_hz: Vec<f64>,
    /// Frequency of the point with the largest sampling estimate per output (Hz).
    pub max_sampling_err_hz: Vec<f64>,
    /// Points whose estimate could not be formed (NaN cells).
    pub unformed_points: usize,
    /// Highest harmonic any point's truncation estimate extended to (the largest
    /// `estimate_harmonic` of the CSV rows: 2H + 1, or 4H + 3 when some point was widened).
    pub max_estimate_harmonic: usize,
    /// Points whose truncation estimate is the extended system solved to convergence
    /// (`estimate_method` `solved`).
    pub solved_points: usize,
    /// Points whose truncation error could not be sized (`estimate_method` `unsized`).
    pub unsized_points: usize,
    /// Points whose truncation error was not sized because the scene skips the solve beyond
    /// the step's linear range (`estimate_method` `unsolved`,
    /// `accuracy.beyond_linear_range = "flag"`).
    pub unsolved_points: usize,
    /// The warning threshold of the scene (relative).
    pub threshold: f64,
}

/// The [`AccuracySummary`] of `points` (None when no point carries an estimate).
pub fn accuracy_summary(
    outputs: &[String],
    threshold: f64,
    points: &[FrfPoint],
) -> Option<AccuracySummary> {
    let with: Vec<(f64, &crate::analysis::error_estimate::PointAccuracy)> = points
        .iter()
        .filter_map(|p| p.accuracy.as_ref().map(|a| (p.freq_hz, a)))
        .collect();
    if with.is_empty() {
        return None;
    }
    let k = outputs.len();
    let mut s = AccuracySummary {
        outputs: outputs.to_vec(),
        max_trunc_err: vec![0.0; k],
        max_sampling_err: vec![0.0; k],
        max_trunc_err_hz: vec![f64::NAN; k],
        max_sampling_err_hz: vec![f64::NAN; k],
        unformed_points: 0,
        max_estimate_harmonic: 0,
        solved_points: 0,
        unsized_points: 0,
        unsolved_points: 0,
        threshold,
    };
    for (f, a) in with {
        let values = a.truncation.iter().chain(&a.sampling);
        if values.clone().any(|v| v.is_nan()) {
            s.unformed_points += 1;
        }
        s.max_estimate_harmonic = s.max_estimate_harmonic.max(a.estimate_harmonic);
        match a.method {
            EstimateMethod::Solved => s.solved_points += 1,
            EstimateMethod::Unsized => s.unsized_points += 1,
            EstimateMethod::Unsolved => s.unsolved_points += 1,
            EstimateMethod::Step | EstimateMethod::Converged | EstimateMethod::None => {}
        }
        for o in 0..k.min(a.truncation.len()) {
            if a.truncation[o] > s.max_trunc_err[o] {
                s.max_trunc_err[o] = a.truncation[o];
                s.max_trunc_err_hz[o] = f;
            }
            if a.sampling[o] > s.max_sampling_err[o] {
                s.max_sampling_err[o] = a.sampling[o];
                s.max_sampling_err_hz[o] = f;
            }
        }
    }
    Some(s)
}

// ---- end of the error-estimate columns.

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

/// Header of an FRF run's `peaks.csv`: `dof`, `kind` (`resonance` or `anti-resonance`),
/// `freq_hz` and `amplitude` (the refined extremum: Hz, first-harmonic amplitude in m),
/// `refined` (`true`, or `false` when the refinement failed or the extremum is the first or
/// last point of a branch, and the values are the path point's), `at_branch_end` (`true` for a
/// resonance that stands out only toward a break between branches, where the path was not
/// followed on, so the response may rise beyond it: [`crate::analysis::peaks::branch_end_peak_indices`]),
/// `path_index`, `path_freq_hz` and `path_amplitude` (the point of the solved path
/// the extremum was refined from: its index in path order, Hz, m), then `<contact>_state` at
/// the refined extremum per contact of `contacts`.
pub fn peaks_header(contacts: &[String]) -> String {
    let mut h = String::from(
        "dof,kind,freq_hz,amplitude,refined,at_branch_end,path_index,path_freq_hz,path_amplitude",
    );
    for c in contacts {
        let _ = write!(h, ",{c}_state");
    }
    h.push('\n');
    h
}

/// An FRF run's `peaks.csv` ([`peaks_header`], then one row per extremum, in the order of
/// `extrema`); `outputs` names the output DOFs, `contacts` the contacts.
pub fn peaks_csv(outputs: &[String], contacts: &[String], extrema: &[PathExtremum]) -> String {
    let mut s = peaks_header(contacts);
    for e in extrema {
        let dof = outputs.get(e.output).map_or("?", String::as_str);
        let _ = write!(
            s,
            "{dof},{},{:.10e},{:.10e},{},{},{},{:.10e},{:.10e}",
            e.kind.label(),
            e.peak.freq_hz,
            e.peak.amplitude,
            e.peak.refined,
            e.at_branch_end,
            e.path_index,
            e.path_freq_hz,
            e.path_amplitude
        );
        for state in &e.peak.states {
            let _ = write!(s, ",{}", state.label());
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
    /// Jumps to another branch past a fold (highest frequency before, lowest of the new
    /// branch, its first point's index).
    jumps: &'a [Jump],
    /// Where the coefficients are when they are not inline (large models).
    #[serde(skip_serializing_if = "Option::is_none")]
    coefficients_file: Option<CoefficientsFile>,
    /// Refined resonances and anti-resonances, once computed (after the continuation).
    #[serde(skip_serializing_if = "Option::is_none")]
    peaks: Option<&'a [PeakRecord]>,
    /// Largest error estimates over the points (when the scene asks for the estimate).
    #[serde(skip_serializing_if = "Option::is_none")]
    accuracy: Option<AccuracySummary>,
    points: Vec<PointRecord<'a>>,
}

/// One resonance or anti-resonance as written in `solution.json` (the columns of
/// `peaks.csv`, see [`peaks_header`]).
#[derive(Debug, Clone, Serialize)]
struct PeakRecord {
    /// Output DOF name.
    dof: String,
    kind: ExtremumKind,
    /// Refined frequency (Hz).
    freq_hz: f64,
    /// Refined first-harmonic amplitude (m).
    amplitude: f64,
    /// False when the refinement failed or the extremum is a branch's first or last point
    /// (the values are then the path point's).
    refined: bool,
    /// A resonance standing out only toward a break between branches: the response may rise
    /// beyond it, where the path was not followed on.
    at_branch_end: bool,
    /// Contact states at the refined extremum.
    states: Vec<ContactState>,
    /// The path point it was refined from: index, frequency (Hz), amplitude (m).
    path_index: usize,
    path_freq_hz: f64,
    path_amplitude: f64,
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
    /// `stable`, `floquet_re`, `floquet_freq_hz` when the scene sets `analysis.stability`.
    #[serde(flatten)]
    stability: Option<&'a crate::analysis::stability::PointStability>,
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

/// Points written to `solution.json` before the first count-based checkpoint, and the least
/// number of new points between two count-based checkpoints.
pub const CHECKPOINT_POINTS: usize = 50;

/// Least time between two time-based checkpoints of `solution.json` (s).
pub const CHECKPOINT_SECONDS: f64 = 2.0;

/// Observer that streams an FRF run to `frf.csv` (one appended row per converged point) and
/// `coefficients.bin` (large models), and writes the whole `solution.json` at checkpoints.
///
/// Output cost is linear in the number of points: a row is appended (and flushed, so an
/// interrupted run keeps every finished point), and `solution.json`, which holds every point
/// and so costs time proportional to the points so far, is rewritten (atomically) only at the
/// first point, when the points have doubled since the last write (and at least
/// [`CHECKPOINT_POINTS`] are new), when [`CHECKPOINT_SECONDS`] have passed and at least ten times
/// the last write's duration, and at the end ([`Self::write_solution`]). The doubling makes
/// the count-based writes cost at most twice the final one; the time-based ones cost at most a
/// tenth of the run.
pub struct FrfWriter {
    dir: PathBuf,
    header: String,
    info: RunInfo,
    points: Vec<FrfPoint>,
    turning_points: Vec<f64>,
    step_cuts: Vec<StepCut>,
    jumps: Vec<Jump>,
    /// Refined extrema, set by [`Self::write_peaks`].
    peaks: Option<Vec<PeakRecord>>,
    started: Instant,
    /// `frf.csv`, opened (truncated, header written) at the first point.
    csv: Option<std::fs::File>,
    /// `coefficients.bin`, opened (truncated) at the first point of a large model.
    coefficients: Option<std::fs::File>,
    /// When the last `solution.json` checkpoint was written.
    last_json: Option<Instant>,
    /// Points in the last `solution.json` checkpoint.
    last_json_points: usize,
    /// Time the last `solution.json` write took (s).
    last_json_s: f64,
    /// `solution.json` writes so far (checkpoints and final).
    json_writes: usize,
    /// First write error met (writing stops being attempted after it).
    pub error: Option<WriteError>,
    /// Warning threshold of the error estimate (relative), for `solution.json`.
    threshold: f64,
}

/// Opens `path` for writing, truncated.
fn create_file(path: &Path) -> Result<std::fs::File, WriteError> {
    std::fs::File::create(path).map_err(|source| WriteError {
        path: path.display().to_string(),
        source,
    })
}

/// Appends `bytes` to the open file `file` (named `path` in errors), unbuffered: the bytes are
/// with the operating system when this returns.
fn append(file: &mut std::fs::File, path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    use std::io::Write as _;
    file.write_all(bytes)
        .and_then(|()| file.flush())
        .map_err(|source| WriteError {
            path: path.display().to_string(),
            source,
        })
}

impl FrfWriter {
    /// A writer into `dir` (which must exist). Nothing is written before the first point.
    pub fn new(dir: &Path, problem: &Problem, info: RunInfo) -> Self {
        Self {
            dir: dir.to_path_buf(),
            header: frf_header(problem),
            info,
            points: Vec::new(),
            turning_points: Vec::new(),
            step_cuts: Vec::new(),
            jumps: Vec::new(),
            peaks: None,
            started: Instant::now(),
            csv: None,
            coefficients: None,
            last_json: None,
            last_json_points: 0,
            last_json_s: 0.0,
            json_writes: 0,
            error: None,
            threshold: problem.analysis.error_estimate.warn_threshold,
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

    /// `solution.json` writes so far, checkpoints and final (for tests of the output cost).
    pub fn json_writes(&self) -> usize {
        self.json_writes
    }

    /// Writes `solution.json` (atomically) with a status line ("running", "complete",
    /// "incomplete: …" or "failed: …").
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
            jumps: &self.jumps,
            coefficients_file: (!inline).then(|| CoefficientsFile {
                file: "coefficients.bin",
                values_per_point: self.points[0].coefficients.len(),
                layout: "f64 little-endian, one row per point in point order, each row the \
                         point's Fourier coefficients harmonic-major (blocks of info.blocks, each \
                         holding every DOF of info.dofs)",
            }),
            peaks: self.peaks.as_deref(),
            accuracy: accuracy_summary(&self.info.outputs, self.threshold, &self.points),
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
                    stability: p.stability.as_ref(),
                })
                .collect(),
        };
        let json = serde_json::to_vec_pretty(&file).expect("result types serialise");
        let result = write_atomic(&self.dir.join("solution.json"), &json);
        self.last_json_s = write_started.elapsed().as_secs_f64();
        self.last_json = Some(Instant::now());
        self.last_json_points = self.points.len();
        self.json_writes += 1;
        result
    }

    /// Writes `peaks.csv` (atomically) with the refined resonances and anti-resonances of the
    /// run's outputs ([`peaks_csv`]), and keeps them for the `peaks` array of `solution.json`,
    /// written by the next [`Self::write_solution`].
    pub fn write_peaks(&mut self, extrema: &[PathExtremum]) -> Result<(), WriteError> {
        let outputs = &self.info.outputs;
        self.peaks = Some(
            extrema
                .iter()
                .map(|e| PeakRecord {
                    dof: outputs.get(e.output).cloned().unwrap_or_default(),
                    kind: e.kind,
                    freq_hz: e.peak.freq_hz,
                    amplitude: e.peak.amplitude,
                    refined: e.peak.refined,
                    at_branch_end: e.at_branch_end,
                    states: e.peak.states.clone(),
                    path_index: e.path_index,
                    path_freq_hz: e.path_freq_hz,
                    path_amplitude: e.path_amplitude,
                })
                .collect(),
        );
        let csv = peaks_csv(outputs, &self.info.contacts, extrema);
        write_atomic(&self.dir.join("peaks.csv"), csv.as_bytes())
    }

    /// Appends a point's row to `frf.csv` (creating it with its header at the first point).
    fn append_row(&mut self, point: &FrfPoint) -> Result<(), WriteError> {
        let path = self.dir.join("frf.csv");
        if self.csv.is_none() {
            let mut file = create_file(&path)?;
            append(&mut file, &path, self.header.as_bytes())?;
            self.csv = Some(file);
        }
        let file = self.csv.as_mut().expect("opened above");
        append(file, &path, frf_row(point).as_bytes())
    }

    /// Appends a point's coefficients to `coefficients.bin` (large models; created at the
    /// first point).
    fn append_coefficients(&mut self, point: &FrfPoint) -> Result<(), WriteError> {
        let path = self.dir.join("coefficients.bin");
        if self.coefficients.is_none() {
            self.coefficients = Some(create_file(&path)?);
        }
        let bytes: Vec<u8> = point
            .coefficients
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let file = self.coefficients.as_mut().expect("opened above");
        append(file, &path, &bytes)
    }

    /// Whether `solution.json` is due for a checkpoint (see the type's docs).
    fn checkpoint_due(&self) -> bool {
        let Some(last) = self.last_json else {
            return true;
        };
        let n = self.points.len();
        let new = n - self.last_json_points;
        let by_count = new >= CHECKPOINT_POINTS && new >= self.last_json_points;
        let since = last.elapsed().as_secs_f64();
        let by_time = since >= CHECKPOINT_SECONDS.max(10.0 * self.last_json_s);
        by_count || by_time
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
        let r = self.append_row(point);
        self.record(r);
        if point.coefficients.len() > INLINE_COEFFICIENTS && self.error.is_none() {
            let r = self.append_coefficients(point);
            self.record(r);
        }
        if self.error.is_none() && self.checkpoint_due() {
            let r = self.write_solution("running");
            self.record(r);
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

    fn jump(&mut self, jump: &Jump) {
        self.jumps.push(*jump);
    }
}

/// The status written into a run's JSON file: `complete`, or `incomplete: <reason>`.
pub fn status_text(incomplete: Option<&str>) -> String {
    match incomplete {
        None => "complete".to_string(),
        Some(reason) => format!("incomplete: {reason}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactState;

    fn problem() -> Problem {
        crate::scene::parse(crate::scene::PAPER_DEFAULT_SCENE, "paper", &[])
            .and_then(|s| s.validate("paper"))
            .expect("the built-in scene is valid")
    }

    fn info() -> RunInfo {
        RunInfo {
            version: "test".into(),
            scene: "paper".into(),
            scene_hash: String::new(),
            dofs: Vec::new(),
            blocks: Vec::new(),
            contacts: Vec::new(),
            outputs: Vec::new(),
        }
    }

    fn point(k: usize) -> FrfPoint {
        let f = 50.0 + 0.01 * k as f64;
        FrfPoint {
            freq_hz: f,
            amplitudes: vec![1e-5 * (1.0 + (k as f64).sin())],
            peaks: vec![2e-5 + 1e-9 * k as f64],
            states: vec![ContactState::Stuck, ContactState::StickSlip],
            newton_iterations: 1 + k % 4,
            residual: 1e-12,
            coefficients: vec![k as f64; 18],
            accuracy: None,
            pending_estimate: None,
            stability: None,
        }
    }

    /// The streamed `frf.csv` is the header and one row per point, byte for byte what a whole
    /// rewrite would give, and `solution.json` is rewritten a number of times that grows with
    /// the logarithm of the points (plus the time-based checkpoints), not with the points.
    #[test]
    fn streams_rows_and_checkpoints_the_json_rarely() {
        let dir = tempfile::tempdir().unwrap();
        let p = problem();
        let mut w = FrfWriter::new(dir.path(), &p, info());
        assert!(
            !dir.path().join("frf.csv").exists(),
            "nothing before the first point"
        );
        let started = Instant::now();
        let n = 5000;
        let mut expected = frf_header(&p);
        for k in 0..n {
            let q = point(k);
            expected.push_str(&frf_row(&q));
            w.point(&q);
            if k == 0 {
                // Flushed at once: the first row is on disk before the next point.
                let text = std::fs::read_to_string(dir.path().join("frf.csv")).unwrap();
                assert_eq!(text, expected);
                assert_eq!(w.json_writes(), 1, "solution.json at the first point");
            }
        }
        assert!(w.error.is_none());
        w.write_solution("complete").unwrap();
        let text = std::fs::read_to_string(dir.path().join("frf.csv")).unwrap();
        assert_eq!(text, expected);
        // Count-based checkpoints at 1, 51, 102, 204, … 3264 points: 8, the final write, and
        // at most one time-based write per CHECKPOINT_SECONDS of the test.
        let time_based = (started.elapsed().as_secs_f64() / CHECKPOINT_SECONDS).ceil() as usize;
        assert!(
            w.json_writes() <= 9 + time_based,
            "{} writes of solution.json for {n} points",
            w.json_writes()
        );
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("solution.json")).unwrap())
                .unwrap();
        assert_eq!(json["status"], "complete");
        assert_eq!(json["points"].as_array().unwrap().len(), n);
    }

    /// A point of a large model appends its coefficients to `coefficients.bin` instead of
    /// inlining them.
    #[test]
    fn large_models_append_coefficients() {
        let dir = tempfile::tempdir().unwrap();
        let p = problem();
        let mut w = FrfWriter::new(dir.path(), &p, info());
        for k in 0..3 {
            let mut q = point(k);
            q.coefficients = vec![k as f64; INLINE_COEFFICIENTS + 1];
            w.point(&q);
        }
        w.write_solution("complete").unwrap();
        let bytes = std::fs::read(dir.path().join("coefficients.bin")).unwrap();
        assert_eq!(bytes.len(), 3 * (INLINE_COEFFICIENTS + 1) * 8);
        let last = f64::from_le_bytes(bytes[bytes.len() - 8..].try_into().unwrap());
        assert_eq!(last, 2.0);
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("solution.json")).unwrap())
                .unwrap();
        assert!(json["points"][0].get("coefficients").is_none());
        assert_eq!(json["coefficients_file"]["file"], "coefficients.bin");
    }
}
