//! The Jacobian study: the analytic Jacobian against finite differences, and the dense,
//! sparse, condensed, schur and schur-lowrank formulations side by side, on a scene and on a ladder of
//! reference problems (the paper case at growing H, chains of unit masses with Jenkins
//! elements to ground, the reduced FE blade pair at growing contact counts and H).
//!
//! Per case (a problem at one harmonic set) and formulation:
//! - whether the formulation takes the problem (a refusal is kept with its reason), or whether
//!   its estimated time ([`crate::hbm::cost`]) is beyond the study's budget (skipped, with the
//!   estimate);
//! - an FRF over the case's range, capped at a number of continuation points (the same cap
//!   for every formulation, so they follow the same path): wall time per point, Newton
//!   iterations per point;
//! - at a probe state (the point of largest first-output amplitude on the first formulation's
//!   path, where contacts slip), the wall time of a residual, of a residual with its Jacobian,
//!   and of a fixed-frequency Newton iteration (residual, Jacobian, factorisation and solve);
//! - the formulation's Jacobian at the probe against forward and central differences of its
//!   own residual ([`compare_with_differences`]): the largest relative difference.
//!
//! The formulation `auto` picks for the case ([`Problem::auto_formulation`]) is marked, and
//! whether it is the fastest per FRF point.
//!
//! Timings are wall times on whatever machine runs the study; formulations run one after the
//! other (never side by side); each timing is the fastest of three batches after a warm-up
//! call, and the full study keeps the faster of two FRF runs.

use std::path::Path;
use std::time::Instant;

use crate::analysis::frf::{self, FrfPoint};
use crate::hbm::cost::{estimate_for, factored_size_for, unknowns_for};
use crate::hbm::operator::HbmOperator;
use crate::model::{Formulation, Problem};
use crate::numerics::derivatives::compare_with_differences;
use crate::numerics::path::PathEnd;
use crate::numerics::ParametricResidual;
use crate::scene;
use crate::study::scaling::{self, ModelSize};

/// Formulations the study compares, in the order they run.
pub const FORMULATIONS: [Formulation; 5] = [
    Formulation::Dense,
    Formulation::Sparse,
    Formulation::Condensed,
    Formulation::Schur,
    Formulation::SchurLowRank,
];

/// Errors of the study's set-up (a ladder problem that cannot be built).
#[derive(Debug, thiserror::Error)]
pub enum JacobianStudyError {
    /// A reference problem of the ladder could not be built.
    #[error("jacobian study: {case}: {reason}")]
    Setup {
        /// Case label.
        case: String,
        /// What failed.
        reason: String,
    },
}

/// The study's budgets: how long each measurement runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Continuation points of each FRF (the path's first points from the range's start).
    pub frf_points: usize,
    /// Each timing is repeated until it has run this long (s), at least 3 times.
    pub timing_s: f64,
    /// A formulation whose estimated FRF time ([`crate::hbm::cost`], time per point × points)
    /// exceeds this (s) is skipped, with the estimate.
    pub max_estimated_frf_s: f64,
    /// Columns of the Jacobian compared with finite differences (evenly spaced).
    pub check_columns: usize,
    /// Times each FRF is run (the fastest run's time is kept).
    pub frf_runs: usize,
}

impl Budget {
    /// The full study's budgets, or `--quick`'s.
    pub fn new(quick: bool) -> Self {
        if quick {
            Self {
                frf_points: 12,
                timing_s: 0.005,
                max_estimated_frf_s: 5.0,
                check_columns: 24,
                frf_runs: 1,
            }
        } else {
            Self {
                frf_points: 60,
                timing_s: 0.05,
                max_estimated_frf_s: 120.0,
                check_columns: 120,
                frf_runs: 2,
            }
        }
    }
}

/// One problem of the study at one harmonic set.
#[derive(Debug, Clone)]
pub struct Case {
    /// Label: model and harmonics (`paper / H = 3`).
    pub label: String,
    /// The problem (formulation set per row).
    pub problem: Problem,
}

/// `base` at harmonics 1..H (with the 0th when the problem has it) and samples per period at
/// least 32·H (and 128); no error estimate, no stability (the study times the solver).
pub fn at_harmonics(base: &Problem, h: usize) -> Problem {
    let mut p = base.clone();
    p.harmonics = (1..=h).collect();
    p.samples = p.samples.max(32 * h).max(128);
    quiet(&mut p);
    p
}

/// Switches off what the study does not time: the error estimate and Hill stability.
pub fn quiet(p: &mut Problem) {
    p.analysis.error_estimate.enabled = false;
    p.analysis.stability = false;
}

/// A chain of `n` unit masses (springs of 10⁴ N/m, the first one grounded, damping
/// 0.002·K + 0.1·M) with `jenkins` Jenkins elements to ground spread along it (kt = 10⁵ N/m,
/// μ = 0.3, a zero normal direction: constant normal load kn·10⁻⁴ m = 10 N), excited at its
/// free end (20 N), 1-40 Hz, harmonics 1..h, 128 samples. The case where `auto` once kept
/// the dense formulation at 10× the time of the others.
pub fn chain_scene(n: usize, jenkins: usize, h: usize) -> String {
    let k = 1.0e4;
    let mut stiffness = vec![vec![0.0; n]; n];
    for i in 0..n {
        stiffness[i][i] += k;
        if i + 1 < n {
            stiffness[i][i] += k;
            stiffness[i + 1][i + 1] += k;
            stiffness[i][i + 1] -= k;
            stiffness[i + 1][i] -= k;
        }
    }
    let matrix = |f: &dyn Fn(usize, usize) -> f64| {
        let rows: Vec<String> = (0..n)
            .map(|i| {
                let row: Vec<String> = (0..n).map(|j| format!("{:.6e}", f(i, j))).collect();
                format!("[{}]", row.join(", "))
            })
            .collect();
        format!("[{}]", rows.join(",\n"))
    };
    let dofs: Vec<String> = (0..n).map(|i| format!("\"x{i}\"")).collect();
    let mut s = format!(
        "title = \"chain of {n} masses, {jenkins} Jenkins elements\"\n[model]\ndofs = [{}]\n\
         mass = {}\nstiffness = {}\ndamping = {}\n",
        dofs.join(", "),
        matrix(&|i, j| if i == j { 1.0 } else { 0.0 }),
        matrix(&|i, j| stiffness[i][j]),
        matrix(&|i, j| 0.002 * stiffness[i][j] + if i == j { 0.1 } else { 0.0 }),
    );
    let step = (n / jenkins.max(1)).max(1);
    for j in 0..jenkins {
        s += &format!(
            "[[contacts]]\nname = \"g{j}\"\ndamper = [\"x{}\"]\ntangent = [1.0]\nnormal = [0.0]\n\
             kt = 1.0e5\nkn = 1.0e5\nmu = 0.3\ngap = -1.0e-4\n",
            (j * step + step / 2).min(n - 1)
        );
    }
    s += &format!(
        "[[harmonic_loads]]\ndof = \"x{}\"\nharmonic = 1\ncos = 20.0\n[harmonics]\nmax = {h}\n\
         samples = 128\n[analysis]\nfreq_start_hz = 1.0\nfreq_end_hz = 40.0\n[output]\n\
         dofs = [\"x{}\"]\n",
        n - 1,
        n - 1
    );
    s
}

/// The ladder of reference cases: the paper case (150-175 Hz, its 2nd resonance) at growing
/// H, chains of unit masses with Jenkins elements to ground at H = 5, and the reduced 2D blade
/// pair (20 interior modes, 700-1000 Hz) at growing contact pairs per side and H. `work_dir`
/// receives the generated blade-pair meshes.
pub fn ladder(quick: bool, work_dir: &Path) -> Result<Vec<Case>, JacobianStudyError> {
    let setup = |case: &str, e: &dyn std::fmt::Display| JacobianStudyError::Setup {
        case: case.to_string(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(work_dir).map_err(|e| setup(&work_dir.display().to_string(), &e))?;
    let mut cases = Vec::new();
    let paper_overrides = [
        "analysis.freq_start_hz=150".to_string(),
        "analysis.freq_end_hz=175".to_string(),
    ];
    let paper = scene::parse(scene::paper_wedge_scene(), "paper", &paper_overrides)
        .and_then(|s| s.validate("paper"))
        .map_err(|e| setup("paper", &e))?;
    let paper_h: &[usize] = if quick { &[1, 5] } else { &[1, 3, 5, 9, 15] };
    for &h in paper_h {
        cases.push(Case {
            label: format!("paper / H = {h}"),
            problem: at_harmonics(&paper, h),
        });
    }
    let chains: &[(usize, usize)] = if quick {
        &[(10, 2)]
    } else {
        &[(20, 5), (40, 10)]
    };
    for &(n, j) in chains {
        let label = format!("chain {n} masses / {j} Jenkins / H = 5");
        let mut p = scene::parse(&chain_scene(n, j, 5), "chain", &[])
            .and_then(|s| s.validate("chain"))
            .map_err(|e| setup(&label, &e))?;
        quiet(&mut p);
        cases.push(Case { label, problem: p });
    }
    // Contact pairs per side: 2 (set directly), then 3·c + 1 at refinement 1 with contact
    // refinement c.
    let sizes: Vec<ModelSize> = if quick {
        vec![ModelSize {
            contact_pairs: Some(2),
            ..ModelSize::uniform(false, 1)
        }]
    } else {
        let mut s = vec![ModelSize {
            contact_pairs: Some(2),
            ..ModelSize::uniform(false, 1)
        }];
        for c in [1, 2, 4] {
            s.push(ModelSize {
                contact_refine: c,
                ..ModelSize::uniform(false, 1)
            });
        }
        s
    };
    let blade_h: &[usize] = if quick { &[1] } else { &[1, 3] };
    for size in sizes {
        let label = format!("blade pair {}", size.label());
        let base = scaling::reduced_problem(size, 20, work_dir).map_err(|e| setup(&label, &e))?;
        let pairs = base.contacts.len() / base.sides.len().max(1);
        for &h in blade_h {
            cases.push(Case {
                label: format!("blade pair / {pairs} pairs per side / H = {h}"),
                problem: at_harmonics(&base, h),
            });
        }
    }
    Ok(cases)
}

/// What one formulation gave on one case.
#[derive(Debug, Clone, PartialEq)]
pub struct FormulationRow {
    /// Case label.
    pub case: String,
    /// The formulation.
    pub formulation: Formulation,
    /// Whether `auto` picks it for this case.
    pub auto: bool,
    /// Whether it is the fastest per FRF point of the case (set when the case is done).
    pub fastest: bool,
    /// `measured`, `refused: <reason>`, `skipped: <reason>` or `failed: <reason>`.
    pub status: String,
    /// Newton unknowns.
    pub unknowns: usize,
    /// Rows of the matrix factorised per Newton iteration.
    pub factored: usize,
    /// Estimated time per continuation point (s, [`crate::hbm::cost`]).
    pub estimated_point_s: f64,
    /// Wall time of one residual at the probe (ms).
    pub residual_ms: f64,
    /// Wall time of one residual with its Jacobian at the probe (ms; schur: the contact
    /// blocks only, its elimination is part of the factorisation in the Newton iteration).
    pub jacobian_ms: f64,
    /// Wall time of one fixed-frequency Newton iteration at the probe: residual, Jacobian,
    /// factorisation and solve (ms).
    pub iteration_ms: f64,
    /// Continuation points of the FRF.
    pub points: usize,
    /// How the FRF ended (`end frequency`, `capped at N points`, …).
    pub frf_end: String,
    /// Newton iterations of the FRF.
    pub newton_iterations: usize,
    /// Wall time of the FRF (s).
    pub frf_s: f64,
    /// Largest relative difference of the Jacobian from forward differences at the probe.
    pub forward_diff: f64,
    /// The same from central differences.
    pub central_diff: f64,
}

impl FormulationRow {
    fn new(case: &str, formulation: Formulation, p: &Problem) -> Self {
        Self {
            case: case.to_string(),
            formulation,
            auto: false,
            fastest: false,
            status: String::new(),
            unknowns: unknowns_for(p, formulation),
            factored: factored_size_for(p, formulation),
            estimated_point_s: estimate_for(p, formulation).seconds_per_point(),
            residual_ms: f64::NAN,
            jacobian_ms: f64::NAN,
            iteration_ms: f64::NAN,
            points: 0,
            frf_end: String::new(),
            newton_iterations: 0,
            frf_s: f64::NAN,
            forward_diff: f64::NAN,
            central_diff: f64::NAN,
        }
    }

    /// Whether the FRF and the timings were measured.
    pub fn measured(&self) -> bool {
        self.status == "measured"
    }

    /// Wall time per FRF point (ms; NaN when not measured).
    pub fn point_ms(&self) -> f64 {
        if self.points == 0 {
            f64::NAN
        } else {
            1e3 * self.frf_s / self.points as f64
        }
    }

    /// Newton iterations per FRF point.
    pub fn iterations_per_point(&self) -> f64 {
        if self.points == 0 {
            f64::NAN
        } else {
            self.newton_iterations as f64 / self.points as f64
        }
    }
}

/// A case's rows, with what `auto` picks and why.
#[derive(Debug, Clone)]
pub struct CaseResult {
    /// Case label.
    pub label: String,
    /// DOFs of the model solved (after any reduction).
    pub dofs: usize,
    /// Contact points.
    pub contacts: usize,
    /// Highest harmonic.
    pub harmonics: usize,
    /// The formulation `auto` picks.
    pub auto: Formulation,
    /// Why (the estimates it compared).
    pub auto_reason: String,
    /// Frequency of the probe state (Hz; NaN when no FRF ran).
    pub probe_hz: f64,
    /// One row per formulation of [`FORMULATIONS`].
    pub rows: Vec<FormulationRow>,
}

impl CaseResult {
    /// The fastest formulation per FRF point among the measured ones.
    pub fn fastest(&self) -> Option<&FormulationRow> {
        self.rows
            .iter()
            .filter(|r| r.measured() && r.point_ms().is_finite())
            .min_by(|a, b| a.point_ms().total_cmp(&b.point_ms()))
    }

    /// `auto`'s time per point over the fastest one's (NaN when either was not measured).
    pub fn auto_slowdown(&self) -> f64 {
        let auto = self.rows.iter().find(|r| r.auto).map(|r| r.point_ms());
        match (auto, self.fastest()) {
            (Some(a), Some(f)) => a / f.point_ms(),
            _ => f64::NAN,
        }
    }
}

/// The wall time of one call of `f` (ms): one warm-up call (first calls build patterns and
/// buffers), then three batches, each repeating `f` until it has run for a third of
/// `budget_s` (at least once, at most 10⁴ calls); the fastest batch's mean, the least
/// disturbed by other work on the machine.
fn time_ms<E>(budget_s: f64, mut f: impl FnMut() -> Result<(), E>) -> Result<f64, E> {
    f()?;
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let started = Instant::now();
        let mut calls = 0usize;
        loop {
            f()?;
            calls += 1;
            let elapsed = started.elapsed().as_secs_f64();
            if elapsed >= budget_s / 3.0 || calls >= 10_000 {
                best = best.min(1e3 * elapsed / calls as f64);
                break;
            }
        }
    }
    Ok(best)
}

/// The time measurements of a formulation at the probe (full coefficients `x`, `omega`
/// rad/s): residual, residual with Jacobian, Newton iteration (ms), and the Jacobian against
/// forward and central differences.
fn probe_measures(
    problem: &Problem,
    x_full: &[f64],
    omega: f64,
    budget: &Budget,
) -> Result<[f64; 5], String> {
    let mut op = HbmOperator::new(problem).map_err(|e| e.to_string())?;
    let x = op.restrict(x_full);
    let n = op.dim();
    let mut r = vec![0.0; n];
    let mut dw = vec![0.0; n];
    let mut jac = op.new_jacobian();
    let residual_ms =
        time_ms(budget.timing_s, || op.residual(&x, omega, &mut r)).map_err(|e| e.to_string())?;
    let jacobian_ms = time_ms(budget.timing_s, || {
        op.residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dw)
    })
    .map_err(|e| e.to_string())?;
    let iteration_ms = time_ms(budget.timing_s, || {
        op.residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dw)
            .map_err(|e| e.to_string())?;
        let neg: Vec<f64> = r.iter().map(|v| -v).collect();
        jac.solve(&neg).map(|_| ()).map_err(|e| e.to_string())
    })?;
    let check = compare_with_differences(&mut op, &x, omega, budget.check_columns)
        .map_err(|e| e.to_string())?;
    Ok([
        residual_ms,
        jacobian_ms,
        iteration_ms,
        check.forward,
        check.central,
    ])
}

/// Measures every formulation of [`FORMULATIONS`] on `case`, calling `done` with each row as
/// it finishes (the `fastest` flags are set on the returned rows only).
pub fn measure_case(
    case: &Case,
    budget: &Budget,
    mut done: impl FnMut(&FormulationRow),
) -> CaseResult {
    let mut auto_problem = case.problem.clone();
    auto_problem.analysis.formulation = Formulation::Auto;
    let (auto, auto_reason) = auto_problem.auto_formulation();
    let mut result = CaseResult {
        label: case.label.clone(),
        dofs: case.problem.model.n_dofs(),
        contacts: case.problem.contacts.len(),
        harmonics: case.problem.harmonics.iter().copied().max().unwrap_or(0),
        auto,
        auto_reason,
        probe_hz: f64::NAN,
        rows: Vec::new(),
    };
    let mut probe: Option<(Vec<f64>, f64)> = None;
    for formulation in FORMULATIONS {
        let mut p = case.problem.clone();
        p.analysis.formulation = formulation;
        p.analysis.continuation.max_points = budget.frf_points;
        let mut row = FormulationRow::new(&case.label, formulation, &p);
        row.auto = formulation == auto;
        row.status = measure_formulation(&p, budget, &mut probe, &mut row);
        if let Some((_, hz)) = &probe {
            result.probe_hz = *hz;
        }
        done(&row);
        result.rows.push(row);
    }
    let fastest = result.fastest().map(|r| r.formulation);
    for row in &mut result.rows {
        row.fastest = Some(row.formulation) == fastest;
    }
    result
}

/// Fills `row` for problem `p` (its formulation set) and returns its status; the first FRF
/// that solves sets the probe state (full coefficients, Hz).
fn measure_formulation(
    p: &Problem,
    budget: &Budget,
    probe: &mut Option<(Vec<f64>, f64)>,
    row: &mut FormulationRow,
) -> String {
    // A formulation that refuses the problem says why when its operator is built.
    if let Err(e) = HbmOperator::new(p) {
        return format!("refused: {e}");
    }
    let estimated = row.estimated_point_s * budget.frf_points as f64;
    if estimated > budget.max_estimated_frf_s {
        return format!(
            "skipped: estimated {:.0} s for {} points (budget {:.0} s)",
            estimated, budget.frf_points, budget.max_estimated_frf_s
        );
    }
    let mut run = None;
    for _ in 0..budget.frf_runs.max(1) {
        let started = Instant::now();
        let this = frf::solve(p, &mut frf::Silent);
        let elapsed = started.elapsed().as_secs_f64();
        match this {
            Ok(r) => {
                if row.frf_s.is_nan() || elapsed < row.frf_s {
                    row.frf_s = elapsed;
                }
                run = Some(r);
            }
            Err(e) => {
                row.frf_s = elapsed;
                return format!("failed: {e}");
            }
        }
    }
    let Some(run) = run else {
        return "failed: no FRF run".to_string();
    };
    row.points = run.points.len();
    row.newton_iterations = run.points.iter().map(|q| q.newton_iterations).sum();
    row.frf_end = match run.end {
        PathEnd::EndFrequency => "end frequency".to_string(),
        PathEnd::MaxPoints => format!("capped at {} points", budget.frf_points),
        PathEnd::LeftRangeBelow => "left the range below".to_string(),
    };
    if probe.is_none() {
        *probe = run
            .points
            .iter()
            .max_by(|a, b| {
                let amp = |q: &FrfPoint| q.amplitudes.first().copied().unwrap_or(0.0);
                amp(a).total_cmp(&amp(b))
            })
            .map(|q| (q.coefficients.clone(), q.freq_hz));
    }
    let Some((x, hz)) = probe.as_ref() else {
        return "failed: the FRF has no point".to_string();
    };
    match probe_measures(p, x, 2.0 * std::f64::consts::PI * hz, budget) {
        Ok([residual, jacobian, iteration, forward, central]) => {
            row.residual_ms = residual;
            row.jacobian_ms = jacobian;
            row.iteration_ms = iteration;
            row.forward_diff = forward;
            row.central_diff = central;
            "measured".to_string()
        }
        Err(e) => format!("failed: at the probe state: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_scene_is_valid_and_its_contacts_have_a_zero_normal() {
        let p = scene::parse(&chain_scene(10, 2, 3), "chain", &[])
            .and_then(|s| s.validate("chain"))
            .unwrap();
        assert_eq!(p.model.n_dofs(), 10);
        assert_eq!(p.contacts.len(), 2);
        assert!(p.contacts[0].normal.iter().all(|&(_, a)| a == 0.0));
        // One relative coordinate per contact and block (H = 3: 7 blocks).
        assert_eq!(factored_size_for(&p, Formulation::Schur), 2 * 7);
    }

    #[test]
    fn timing_repeats_until_the_budget_and_reports_errors() {
        let mut calls = 0;
        let ms = time_ms::<()>(0.0, || {
            calls += 1;
            Ok(())
        })
        .unwrap();
        // A warm-up call and three batches of one call each.
        assert_eq!(calls, 4);
        assert!(ms >= 0.0);
        assert_eq!(time_ms(1.0, || Err::<(), _>("no")), Err("no"));
    }
}
