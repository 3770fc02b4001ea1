//! `fricbound bench`: the scaling study of [`crate::scaling`], printed as a table and written
//! (as the cases finish, atomically) to `scaling.md`, `scaling.json` and a figure.
//!
//! Reductions run one per child process (`fricbound bench reduction ...`), since peak resident
//! memory is a per-process figure; the solver cases run in this process, single-threaded
//! figures being what this 2-core machine can honestly report.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::model::{Formulation, JacobianStrategy};
use crate::report::files::write_atomic;
use crate::report::limit_plots::palette;
use crate::report::plot::{plot_lines, Series};
use crate::scaling::{self, ModelSize, ReductionMeasure, SolveMeasure};

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
        /// 3D hexahedra.
        #[arg(long = "3d")]
        three_d: bool,
        /// Fixed-interface modes.
        #[arg(long, default_value_t = 50)]
        modes: usize,
    },
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
}

/// Runs a bench subcommand; returns the text to print.
pub fn run(command: &BenchCommand) -> Result<String, BenchError> {
    match command {
        BenchCommand::Reduction {
            refine,
            three_d,
            modes,
        } => {
            let size = ModelSize {
                three_d: *three_d,
                refine: *refine,
            };
            let m = scaling::measure_reduction(size, *modes)?;
            serde_json::to_string(&m).map_err(|e| BenchError::Io(e.to_string()))
        }
        BenchCommand::Scaling { out, quick } => {
            let dir = out.clone().unwrap_or_else(|| PathBuf::from("out/scaling"));
            std::fs::create_dir_all(&dir)
                .map_err(|e| BenchError::Io(format!("{}: {e}", dir.display())))?;
            scaling_study(&dir, *quick)
        }
    }
}

fn tempdir() -> Result<PathBuf, BenchError> {
    let dir = std::env::temp_dir().join(format!("fricbound-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| BenchError::Io(format!("{}: {e}", dir.display())))?;
    Ok(dir)
}

/// Largest unknown count for which a whole FRF is run with the dense formulation.
const DENSE_FRF_LIMIT: usize = 3000;
/// Largest unknown count for which a whole FRF is run with finite differences.
const FD_FRF_LIMIT: usize = 400;

/// Everything measured so far.
#[derive(Default, serde::Serialize)]
struct Study {
    machine: String,
    reductions: Vec<ReductionMeasure>,
    solves: Vec<SolveMeasure>,
}

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

    // Solver costs on reduced models with growing contact counts.
    let work = tempdir()?;
    let refines: &[usize] = if quick { &[1, 2] } else { &[1, 2, 4, 8, 16] };
    let harmonics: &[usize] = if quick { &[1, 3] } else { &[1, 3, 5, 7] };
    for &refine in refines {
        let size = ModelSize {
            three_d: false,
            refine,
        };
        let reduced = scaling::reduced_problem(size, 20, &work)?;
        let case = format!("2D r{refine}, reduced");
        for &h in harmonics {
            for f in [
                Formulation::Dense,
                Formulation::Sparse,
                Formulation::Condensed,
            ] {
                eprintln!("solve: {case}, H = {h}, {}", scaling::formulation_name(f));
                // A whole FRF where it is affordable (dense LU grows as n³), else one iteration.
                let unknowns = reduced.model.n_dofs() * (2 * h + 1);
                let frf = f != Formulation::Dense || unknowns <= DENSE_FRF_LIMIT;
                let m =
                    scaling::measure_solve(&case, &reduced, h, f, JacobianStrategy::Analytic, frf)?;
                study.solves.push(m);
                // Finite differences: a whole FRF where it is affordable, else one iteration.
                let unknowns = study.solves.last().map(|m| m.unknowns).unwrap_or(0);
                let fd_frf = unknowns <= FD_FRF_LIMIT;
                let m = scaling::measure_solve(
                    &case,
                    &reduced,
                    h,
                    f,
                    JacobianStrategy::ForwardDifference,
                    fd_frf,
                )?;
                study.solves.push(m);
                write_study(dir, &study)?;
            }
        }
    }
    // The unreduced model solved by the sparse formulation, beside its reduced version.
    let size = ModelSize {
        three_d: false,
        refine: 2,
    };
    let full = scaling::full_problem(size, 1, &work)?;
    for &h in &harmonics[..harmonics.len().min(2)] {
        eprintln!("solve: 2D r2 unreduced, H = {h}, sparse");
        let m = scaling::measure_solve(
            "2D r2, unreduced",
            &full,
            h,
            Formulation::Sparse,
            JacobianStrategy::Analytic,
            true,
        )?;
        study.solves.push(m);
        write_study(dir, &study)?;
    }
    let _ = std::fs::remove_dir_all(&work);
    plot_study(dir, &study)?;
    Ok(markdown(&study))
}

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

fn write_study(dir: &Path, study: &Study) -> Result<(), BenchError> {
    let io = |e: crate::report::files::WriteError| BenchError::Io(e.to_string());
    let json = serde_json::to_string_pretty(study).map_err(|e| BenchError::Io(e.to_string()))?;
    write_atomic(&dir.join("scaling.json"), json.as_bytes()).map_err(io)?;
    write_atomic(&dir.join("scaling.md"), markdown(study).as_bytes()).map_err(io)
}

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
        "\n## Solver cost (700-1000 Hz window around the first bending pair, at most 1000 points, single FRF, m = 0)\n\n\
         Time per Newton iteration is the FRF time over its Newton iterations (tangent solves \
         included) for full runs, or the time of one iteration (residual, Jacobian, linear \
         solve) where an FRF with finite differences would take too long (`frf = no`).\n\n\
         | case | pairs/side | H | formulation | Jacobian | unknowns | frf | points | complete | FRF (s) | per point (ms) | per iteration (ms) |\n\
         | --- | ---: | ---: | --- | --- | ---: | --- | ---: | --- | ---: | ---: | ---: |"
    );
    for m in &study.solves {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} |",
            m.case,
            m.pairs_per_side,
            m.harmonics,
            m.formulation,
            m.jacobian,
            m.unknowns,
            if m.frf { "yes" } else { "no" },
            if m.frf {
                m.points.to_string()
            } else {
                "–".into()
            },
            if m.frf {
                if m.complete { "yes" } else { "stalled" }.to_string()
            } else {
                "–".into()
            },
            if m.frf {
                format!("{:.2}", m.frf_s)
            } else {
                "–".into()
            },
            if m.frf {
                format!("{:.2}", m.per_point_ms)
            } else {
                "–".into()
            },
            m.per_iteration_ms
        );
    }
    s
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
                l.2.push(m.per_iteration_ms);
            }
            None => lines.push((
                label,
                vec![m.pairs_per_side as f64],
                vec![m.per_iteration_ms],
            )),
        }
    }
    let series: Vec<Series> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| Series {
            label: &l.0,
            x: &l.1,
            y: &l.2,
            color: palette(i / 2),
            dashed: i % 2 == 1,
        })
        .collect();
    plot_lines(
        &format!("Time per Newton iteration, reduced blade pair, H = {h}"),
        "contact pairs per damper side",
        "time per Newton iteration (ms)",
        true,
        &series,
        &dir.join("scaling.png"),
        &dir.join("scaling.svg"),
    )
    .map_err(|e| BenchError::Io(e.to_string()))
}
