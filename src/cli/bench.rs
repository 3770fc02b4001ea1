//! `fricbound bench`: the scaling study of [`crate::study::scaling`], printed as a table and written
//! (as the cases finish, atomically) to `scaling.md`, `scaling.json` and a figure.
//!
//! Reductions run one per child process (`fricbound bench reduction ...`), since peak resident
//! memory is a per-process figure; the solver cases run in this process, single-threaded
//! figures being what this 2-core machine can honestly report.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::model::{Formulation, JacobianStrategy};
use crate::report::files::write_atomic;
use crate::report::plot::{figure_files, palette, plot_lines, Curve};
use crate::study::scaling::{self, ModelSize, ReductionMeasure, SolveMeasure, SolverConfig};

/// Bench subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum BenchCommand {
    /// The scaling study: reduction time and memory against FE size, and solver time against
    /// contact points, harmonics and strategy; writes scaling.md, scaling.json, scaling.png.
    Scaling {
        /// Output folder [default: out/scaling].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Small sizes only (a few minutes).
        #[arg(long)]
        quick: bool,
    },
    /// One reduction of the blade-pair model in this process, printed as one JSON line (the
    /// scaling study runs each size in its own process to measure its peak memory).
    Reduction {
        /// Generator refinement.
        #[arg(long)]
        refine: usize,
        /// Extra refinement of the contact faces and the damper.
        #[arg(long, default_value_t = 1)]
        contact_refine: usize,
        /// Contact pairs per side set directly (with --contact-refine 1).
        #[arg(long)]
        contact_pairs: Option<usize>,
        /// 3D hexahedra.
        #[arg(long = "3d")]
        three_d: bool,
        /// Fixed-interface modes.
        #[arg(long, default_value_t = 50)]
        modes: usize,
    },
    /// One limit curve (m = +1 on every point) of the reduced 2D blade pair per contact
    /// refinement, H and formulation: unknowns, Newton and Krylov iterations, factorisations,
    /// time per iteration and curve and where it went, peak memory, and the fitted exponent of
    /// the time per iteration against the contact count.
    Contacts(super::bench_contacts::ContactsArgs),
}

/// Errors of the bench command.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A case could not be set up or run.
    #[error(transparent)]
    Case(#[from] scaling::ScalingError),
    /// A file could not be written or a child process failed.
    #[error("{0}")]
    Io(String),
    /// `bench contacts` failed.
    #[error(transparent)]
    Contacts(#[from] super::bench_contacts::ContactsBenchError),
}

/// Runs a bench subcommand; returns the text to print.
pub fn run(command: &BenchCommand) -> Result<String, BenchError> {
    match command {
        BenchCommand::Reduction {
            refine,
            contact_refine,
            contact_pairs,
            three_d,
            modes,
        } => {
            let size = ModelSize {
                three_d: *three_d,
                refine: *refine,
                contact_refine: *contact_refine,
                contact_pairs: *contact_pairs,
            };
            let m = scaling::measure_reduction(size, *modes)?;
            serde_json::to_string(&m).map_err(|e| BenchError::Io(e.to_string()))
        }
        BenchCommand::Contacts(args) => Ok(super::bench_contacts::run(args)?),
        BenchCommand::Scaling { out, quick } => {
            let dir = out.clone().unwrap_or_else(|| PathBuf::from("out/scaling"));
            std::fs::create_dir_all(&dir)
                .map_err(|e| BenchError::Io(format!("{}: {e}", dir.display())))?;
            scaling_study(&dir, *quick)
        }
    }
}

/// A scratch folder for this process (`fricbound-bench-<pid>` in the system temp folder).
fn tempdir() -> Result<PathBuf, BenchError> {
    let dir = std::env::temp_dir().join(format!("fricbound-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| BenchError::Io(format!("{}: {e}", dir.display())))?;
    Ok(dir)
}

/// Largest unknown count for which one iteration with the analytic Jacobian is timed (dense
/// LU grows as n³: about 10 s at 8000 unknowns here).
const ANALYTIC_LIMIT: usize = 8000;
/// Largest unknown count for which one iteration with finite differences is timed (n residual
/// evaluations of O(n²) each on reduced models).
const FD_LIMIT: usize = 3000;
/// Largest one-iteration time (ms) for which an FRF is run as well.
const FRF_ITERATION_LIMIT_MS: f64 = 40.0;
/// Continuation points of the FRFs of the study (the targets speak of FRFs of about 150).
const FRF_POINTS: usize = 150;

/// Everything measured so far.
#[derive(Default, serde::Serialize)]
struct Study {
    machine: String,
    reductions: Vec<ReductionMeasure>,
    solves: Vec<SolveMeasure>,
    limit_curves: Vec<SolveMeasure>,
}

/// Runs the scaling study (reductions in child processes, then the solves) and returns its
/// summary; `quick` keeps to the smallest sizes.
fn scaling_study(dir: &Path, quick: bool) -> Result<String, BenchError> {
    let mut study = Study {
        machine: machine(),
        ..Default::default()
    };
    // Reductions, one process each.
    let sizes: &[(bool, usize)] = if quick {
        &[(false, 3), (true, 1)]
    } else {
        &[(false, 3), (false, 10), (false, 30), (true, 1), (true, 3)]
    };
    let exe = std::env::current_exe().map_err(|e| BenchError::Io(e.to_string()))?;
    for &(three_d, refine) in sizes {
        let mut cmd = std::process::Command::new(&exe);
        cmd.args([
            "bench",
            "reduction",
            "--refine",
            &refine.to_string(),
            "--modes",
            "50",
        ]);
        if three_d {
            cmd.arg("--3d");
        }
        eprintln!(
            "reduction: {} refine {refine}",
            if three_d { "3D" } else { "2D" }
        );
        let out = cmd.output().map_err(|e| BenchError::Io(e.to_string()))?;
        if !out.status.success() {
            return Err(BenchError::Io(format!(
                "bench reduction --refine {refine}{}: {}",
                if three_d { " --3d" } else { "" },
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        let m: ReductionMeasure = serde_json::from_slice(&out.stdout)
            .map_err(|e| BenchError::Io(format!("bench reduction output: {e}")))?;
        study.reductions.push(m);
        write_study(dir, &study)?;
    }

    // Solver costs on reduced models with growing contact counts: the coarse 2D blade pair
    // (refine 2) with 2 contact pairs per side, then with its contact faces and damper
    // refined (7 to 199 pairs per side).
    let work = tempdir()?;
    let contact_ladder: &[(usize, Option<usize>)] = if quick {
        &[(1, Some(2)), (1, None), (2, None)]
    } else {
        &[
            (1, Some(2)),
            (1, None),
            (2, None),
            (4, None),
            (8, None),
            (16, None),
            (33, None),
        ]
    };
    let harmonics: &[usize] = if quick { &[1, 3] } else { &[1, 3, 5, 7] };
    for &(contact_refine, contact_pairs) in contact_ladder {
        let size = ModelSize {
            three_d: false,
            refine: 2,
            contact_refine,
            contact_pairs,
        };
        let reduced = scaling::reduced_problem(size, 20, &work)?;
        let case = format!("{}, reduced", size.label());
        for config in SolverConfig::grid(harmonics) {
            let mut p = config.apply(&reduced);
            p.analysis.continuation.max_points = FRF_POINTS;
            // The cost grows with the factorised size; the schur formulation's finite
            // differences are per contact point, not per unknown.
            let limit = if config.jacobian == JacobianStrategy::Analytic
                || matches!(
                    p.formulation(),
                    Formulation::Schur | Formulation::SchurLowRank
                ) {
                ANALYTIC_LIMIT
            } else {
                FD_LIMIT
            };
            if scaling::factored_size(&p) > limit {
                eprintln!(
                    "skip: {case}, {}: {} unknowns",
                    config.label(),
                    scaling::unknowns(&p)
                );
                continue;
            }
            eprintln!("solve: {case}, {}", config.label());
            let mut m = scaling::measure_solve(&case, &p, &config, false)?;
            if m.iteration_ms <= FRF_ITERATION_LIMIT_MS {
                m = scaling::measure_solve(&case, &p, &config, true)?;
            }
            study.solves.push(m);
            write_study(dir, &study)?;
        }
        // The target case: a limit curve (m = +1 on every point) with about 50 points per
        // side at H = 3, analytic against finite differences, with the automatic formulation.
        if contact_refine == 8 || (quick && contact_refine == 2) {
            for jacobian in scaling::JACOBIANS {
                let config = SolverConfig {
                    harmonics: 3,
                    formulation: Formulation::Auto,
                    jacobian,
                    m: 1.0,
                };
                let mut p = config.apply(&reduced);
                p.analysis.continuation.max_points = FRF_POINTS;
                eprintln!("limit FRF: {case}, {}", config.label());
                let mut m = scaling::measure_solve(&case, &p, &config, false)?;
                if jacobian == JacobianStrategy::Analytic || m.iteration_ms <= 1000.0 {
                    m = scaling::measure_solve(&case, &p, &config, true)?;
                }
                study.limit_curves.push(m);
                write_study(dir, &study)?;
            }
        }
    }
    // The unreduced model solved by the sparse formulation, beside its reduced version.
    let size = ModelSize::uniform(false, 2);
    let full = scaling::full_problem(size, 1, &work)?;
    for &h in &harmonics[..harmonics.len().min(2)] {
        let config = SolverConfig {
            harmonics: h,
            formulation: Formulation::Sparse,
            jacobian: JacobianStrategy::Analytic,
            m: 0.0,
        };
        let mut p = config.apply(&full);
        p.analysis.continuation.max_points = FRF_POINTS;
        eprintln!("solve: 2D r2 unreduced, {}", config.label());
        let m = scaling::measure_solve("2D r2, unreduced", &p, &config, true)?;
        study.solves.push(m);
        write_study(dir, &study)?;
    }
    let _ = std::fs::remove_dir_all(&work);
    plot_study(dir, &study)?;
    Ok(markdown(&study))
}

/// The CPU model and core count, so that timings can be read against the machine.
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".to_string());
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    format!(
        "{cpu}, {cores} cores available, rayon threads {}",
        rayon::current_num_threads()
    )
}

/// Writes the study as `scaling.json` and `scaling.md` in `dir`.
fn write_study(dir: &Path, study: &Study) -> Result<(), BenchError> {
    let io = |e: crate::report::files::WriteError| BenchError::Io(e.to_string());
    let json = serde_json::to_string_pretty(study).map_err(|e| BenchError::Io(e.to_string()))?;
    write_atomic(&dir.join("scaling.json"), json.as_bytes()).map_err(io)?;
    write_atomic(&dir.join("scaling.md"), markdown(study).as_bytes()).map_err(io)
}

/// `scaling.md`: the reduction and solve tables of the study.
fn markdown(study: &Study) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Scaling study\n\nMachine: {}.\n", study.machine);
    let _ = writeln!(
        s,
        "## Craig-Bampton reduction of the blade pair (50 fixed-interface modes)\n\n\
         | model | DOFs | pairs/side | boundary DOFs | model build (s) | reduction (s) | factor (s) | eigen (s) | constraint modes (s) | factor entries | peak memory (GiB) |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    for r in &study.reductions {
        let _ = writeln!(
            s,
            "| {} r{} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} |",
            if r.three_d { "3D" } else { "2D" },
            r.refine,
            r.dofs,
            r.pairs_per_side,
            r.boundary,
            r.model_s,
            r.reduction_s,
            r.factor_s,
            r.eigen_s,
            r.constraint_s,
            r.factor_entries,
            r.peak_memory_bytes
                .map(|b| format!("{:.2}", b as f64 / (1u64 << 30) as f64))
                .unwrap_or_else(|| "–".to_string())
        );
    }
    let _ = writeln!(
        s,
        "\n## Solver cost (700-1000 Hz window around the first bending pair, 20 fixed-interface modes, m = 0)\n\n\
         `iteration` is one Newton iteration (residual, Jacobian, linear solve) at the stuck \
         linear guess at 850 Hz. Where it takes at most {FRF_ITERATION_LIMIT_MS} ms an FRF over \
         the window is run as well, limited to {FRF_POINTS} continuation points (`complete`: it \
         reached 1000 Hz within them); its time per Newton iteration includes the tangent \
         solves. Cases whose factorised matrix exceeds {ANALYTIC_LIMIT} rows (analytic) or \
         {FD_LIMIT} (finite differences) are not run. `unknowns` are those of Newton's \
         iteration; the schur formulation factorises a matrix of 2 rows per contact point \
         and coefficient block only, and forms its finite differences per contact point.\n"
    );
    solve_table(&mut s, &study.solves);
    if !study.limit_curves.is_empty() {
        let _ = writeln!(
            s,
            "\n## Limit curve with about 50 contact points per side, H = 3\n\n\
             One limit curve (m = +1 at every point), automatic formulation, at most \
             {FRF_POINTS} continuation points; the finite-difference FRF is run only where one \
             of its iterations takes at most 1 s.\n"
        );
        solve_table(&mut s, &study.limit_curves);
    }
    s
}

/// The table of solve measurements: one row per case, the FRF columns dashed where no FRF
/// was run.
fn solve_table(s: &mut String, rows: &[SolveMeasure]) {
    let _ = writeln!(
        s,
        "| case | pairs/side | H | formulation | Jacobian | unknowns | iteration (ms) | FRF points | complete | FRF (s) | per point (ms) | per FRF iteration (ms) |\n\
         | --- | ---: | ---: | --- | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: |"
    );
    for m in rows {
        // The FRF columns of a row that timed Newton iterations only are dashes.
        let frf = |cell: String| if m.frf { cell } else { "–".to_string() };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {:.2} | {} | {} | {} | {} | {} |",
            m.case,
            m.pairs_per_side,
            m.harmonics,
            m.formulation,
            m.jacobian,
            m.unknowns,
            m.iteration_ms,
            frf(m.points.to_string()),
            frf(if m.complete { "yes" } else { "no" }.to_string()),
            frf(format!("{:.2}", m.frf_s)),
            frf(format!("{:.2}", m.per_point_ms)),
            frf(format!("{:.2}", m.frf_iteration_ms)),
        );
    }
}

/// Time per Newton iteration against contact pairs per side, one line per formulation and
/// Jacobian strategy, at H = 3 (or the largest H measured below it).
fn plot_study(dir: &Path, study: &Study) -> Result<(), BenchError> {
    let h = study
        .solves
        .iter()
        .map(|m| m.harmonics)
        .filter(|&h| h <= 3)
        .max()
        .unwrap_or(1);
    let mut lines: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    for m in study
        .solves
        .iter()
        .filter(|m| m.harmonics == h && m.case.contains("reduced") && !m.case.contains("unreduced"))
    {
        let label = format!("{}, {}", m.formulation, m.jacobian);
        match lines.iter_mut().find(|l| l.0 == label) {
            Some(l) => {
                l.1.push(m.pairs_per_side as f64);
                l.2.push(m.iteration_ms);
            }
            None => lines.push((label, vec![m.pairs_per_side as f64], vec![m.iteration_ms])),
        }
    }
    let series: Vec<Curve> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| Curve {
            label: &l.0,
            x: &l.1,
            y: &l.2,
            color: palette(i / 2),
            dashed: i % 2 == 1,
            markers: false,
        })
        .collect();
    let (png, svg) = figure_files(dir, "scaling");
    plot_lines(
        &format!("Time per Newton iteration, reduced blade pair, H = {h}"),
        "contact pairs per damper side",
        "time per Newton iteration (ms)",
        true,
        &series,
        &png,
        &svg,
    )
    .map_err(|e| BenchError::Io(e.to_string()))
}
