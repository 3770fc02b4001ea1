//! `fricbound study jacobian`: the Jacobian study ([`crate::study::jacobian`]) of a scene and
//! of the reference ladder: `jacobian.csv` (one row per case and formulation, appended as each
//! finishes) and `jacobian.md`.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};

use super::shared::{io_error, read_scene, study_dir, StudyReport};
use crate::cli::context::CommandError;
use crate::hbm::cost::formulation_name;
use crate::report::files::write_atomic;
use crate::study::accuracy;
use crate::study::jacobian::{self, CaseResult, FormulationRow};

/// Header of `jacobian.csv`.
const JACOBIAN_CSV_HEADER: &str = "case,dofs,contacts,harmonics,formulation,auto,fastest,status,\
unknowns,factored,estimated_point_ms,residual_ms,jacobian_ms,iteration_ms,frf_points,frf_end,\
newton_iterations,iterations_per_point,point_ms,frf_s,jacobian_vs_forward,jacobian_vs_central\n";

/// One `jacobian.csv` row (commas in a status become semicolons: one cell each).
fn jacobian_csv_row(case: &CaseResult, r: &FormulationRow) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{},{:.4e},{:.4e},{:.4e},{:.4e},{},{},{},{:.3},{:.4e},{:.4e},{:.3e},{:.3e}\n",
        r.case,
        case.dofs,
        case.contacts,
        case.harmonics,
        formulation_name(r.formulation),
        r.auto,
        r.fastest,
        r.status.replace(',', ";"),
        r.unknowns,
        r.factored,
        1e3 * r.estimated_point_s,
        r.residual_ms,
        r.jacobian_ms,
        r.iteration_ms,
        r.points,
        r.frf_end,
        r.newton_iterations,
        r.iterations_per_point(),
        r.point_ms(),
        r.frf_s,
        r.forward_diff,
        r.central_diff,
    )
}

/// A time in ms for the tables (`–` when not measured).
fn ms(v: f64) -> String {
    if !v.is_finite() {
        "–".to_string()
    } else if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// A relative difference for the tables.
fn rel(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.1e}")
    } else {
        "–".to_string()
    }
}

/// The markdown table of one case (also printed).
fn jacobian_case_table(case: &CaseResult) -> String {
    let mut t = format!(
        "### {}\n\n{} DOFs, {} contact points, H = {}; probe state at {:.2} Hz. `auto` picks \
         **{}** ({}).{}\n\n\
         | formulation | unknowns | factorised rows | residual (ms) | residual + Jacobian (ms) | \
         Newton iteration (ms) | FRF points | Newton its per point | ms per FRF point | J vs forward | \
         J vs central | note |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        case.label,
        case.dofs,
        case.contacts,
        case.harmonics,
        case.probe_hz,
        formulation_name(case.auto),
        case.auto_reason,
        match case.fastest() {
            Some(f) if f.formulation == case.auto => " It is the fastest per FRF point.".to_string(),
            Some(f) => format!(
                " The fastest per FRF point is {}; `auto`'s choice takes {:.2}× as long.",
                formulation_name(f.formulation),
                case.auto_slowdown()
            ),
            None => " No formulation was measured.".to_string(),
        }
    );
    for r in &case.rows {
        let mut note: Vec<String> = Vec::new();
        if r.auto {
            note.push("**auto**".into());
        }
        if r.fastest {
            note.push("fastest".into());
        }
        if !r.measured() {
            note.push(r.status.clone());
        } else if !r.frf_end.is_empty() {
            note.push(format!("FRF: {}", r.frf_end));
        }
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            formulation_name(r.formulation),
            r.unknowns,
            r.factored,
            ms(r.residual_ms),
            ms(r.jacobian_ms),
            ms(r.iteration_ms),
            if r.points > 0 {
                r.points.to_string()
            } else {
                "–".into()
            },
            if r.points > 0 {
                format!("{:.2}", r.iterations_per_point())
            } else {
                "–".into()
            },
            ms(r.point_ms()),
            rel(r.forward_diff),
            rel(r.central_diff),
            note.join("; ")
        );
    }
    t.push('\n');
    t
}

pub(super) fn jacobian_study(
    scene_path: &std::path::Path,
    quick: bool,
    out: Option<PathBuf>,
    user: &[String],
    quiet: bool,
) -> Result<StudyReport, CommandError> {
    let (label, text) = read_scene(scene_path)?;
    // The scene's own FRF (a limit or sweep scene without its `[limits]` and `[sweep]`).
    let (_, mut problem, _) = accuracy::load(&text, &label, user)?;
    jacobian::quiet(&mut problem);
    let (dir, stem) = study_dir(scene_path, out, "jacobian")?;
    let budget = jacobian::Budget::new(quick);
    let h = problem.harmonics.iter().copied().max().unwrap_or(0);
    let mut cases = vec![jacobian::Case {
        label: format!("{stem} / H = {h}"),
        problem,
    }];
    // The ladder's generated meshes live in a work folder of the output folder, removed after.
    let work = dir.join("ladder-meshes");
    let ladder = jacobian::ladder(quick, &work);
    let _ = std::fs::remove_dir_all(&work);
    cases.extend(ladder.map_err(|e| CommandError::Study {
        scene: label.clone(),
        reason: e.to_string(),
    })?);
    let csv_path = dir.join("jacobian.csv");
    let mut file = std::fs::File::create(&csv_path).map_err(|e| io_error(&csv_path, e))?;
    file.write_all(JACOBIAN_CSV_HEADER.as_bytes())
        .map_err(|e| io_error(&csv_path, e))?;
    let bar = (!quiet).then(|| {
        let bar = ProgressBar::new((cases.len() * jacobian::FORMULATIONS.len()) as u64);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}",
            )
            .expect("static template"),
        );
        bar
    });
    let mut results = Vec::with_capacity(cases.len());
    for case in &cases {
        if let Some(bar) = &bar {
            bar.set_message(case.label.clone());
        }
        let mut written: Result<(), std::io::Error> = Ok(());
        let result = jacobian::measure_case(case, &budget, |_row| {
            if let Some(bar) = &bar {
                bar.inc(1);
            }
        });
        // Rows go out when the case is done (its `fastest` flags need every row).
        for r in &result.rows {
            if written.is_ok() {
                written = file
                    .write_all(jacobian_csv_row(&result, r).as_bytes())
                    .and_then(|()| file.flush());
            }
        }
        written.map_err(|e| io_error(&csv_path, e))?;
        results.push(result);
    }
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let mut md = format!(
        "# Jacobian study: {label}\n\nPer case and formulation: the wall time of a residual, of a \
         residual with its Jacobian (schur: the contact blocks; its elimination belongs to the \
         factorisation) and of a fixed-frequency Newton iteration (residual, Jacobian, \
         factorisation, solve) at a probe state (the largest response of the first FRF); an FRF \
         of at most {} continuation points from the range's start (ms per point, Newton \
         iterations per point); and the formulation's Jacobian at the probe against forward and \
         central differences of its own residual (largest difference over the largest entry, \
         {} columns at most). Formulations run one after the other; each timing is the fastest \
         of three batches of {:.1} ms after a warm-up call, and each FRF time the fastest of {} \
         run(s). {} a formulation that refuses the case or whose estimated FRF \
         time exceeds {:.0} s has its reason instead.\n\n",
        budget.frf_points,
        budget.check_columns,
        1e3 * budget.timing_s / 3.0,
        budget.frf_runs,
        if quick { "--quick:" } else { "Full study:" },
        budget.max_estimated_frf_s,
    );
    let mut summary = String::new();
    for r in &results {
        let table = jacobian_case_table(r);
        md.push_str(&table);
        summary.push_str(&table);
    }
    let auto_fastest = results
        .iter()
        .filter(|r| r.fastest().is_some_and(|f| f.formulation == r.auto))
        .count();
    let measured_cases = results.iter().filter(|r| r.fastest().is_some()).count();
    let verdict = format!(
        "`auto` picks the fastest formulation per FRF point in {auto_fastest} of {measured_cases} \
         cases{}.\n",
        {
            let slower: Vec<String> = results
                .iter()
                .filter(|r| r.auto_slowdown() > 1.0)
                .map(|r| {
                    format!(
                        "{}: {} takes {:.2}× the time of {}",
                        r.label,
                        formulation_name(r.auto),
                        r.auto_slowdown(),
                        r.fastest().map_or("?", |f| formulation_name(f.formulation))
                    )
                })
                .collect();
            if slower.is_empty() {
                String::new()
            } else {
                format!(" (elsewhere: {})", slower.join("; "))
            }
        }
    );
    md.push_str(&verdict);
    write_atomic(&dir.join("jacobian.md"), md.as_bytes())?;
    let failed: Vec<String> = results
        .iter()
        .flat_map(|c| &c.rows)
        .filter(|r| r.status.starts_with("failed"))
        .map(|r| {
            format!(
                "{} {} ({})",
                r.case,
                formulation_name(r.formulation),
                r.status
            )
        })
        .collect();
    summary.push_str(&verdict);
    let _ = writeln!(summary, "results in {}", dir.display());
    Ok(StudyReport {
        summary,
        incomplete: (!failed.is_empty())
            .then(|| format!("formulations that failed: {}", failed.join("; "))),
    })
}
