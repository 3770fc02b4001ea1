//! `fricbound bench contacts`: one limit curve of the reduced 2D blade pair per contact
//! refinement, harmonic count and formulation ([`crate::study::contacts`]), printed as a
//! markdown table with the fitted exponent of the time per Newton iteration against the contact
//! count, and written to `contacts.md` and `contacts.json` when an output folder is given.

use std::fmt::Write as _;
use std::path::PathBuf;

use crate::hbm::cost::{format_bytes, formulation_from_name};
use crate::report::files::write_atomic;
use crate::study::contacts::{self, ContactCase, ContactMeasure};

/// Errors of `fricbound bench contacts`.
#[derive(Debug, thiserror::Error)]
pub enum ContactsBenchError {
    /// A case could not be set up or run.
    #[error(transparent)]
    Case(#[from] crate::study::scaling::ScalingError),
    /// An unknown formulation name.
    #[error("unknown formulation `{0}` (auto, dense, sparse, condensed, schur, schur-lowrank)")]
    Formulation(String),
    /// A file or folder could not be written.
    #[error("{0}")]
    Io(String),
}

/// Options of `fricbound bench contacts`.
#[derive(Debug, Clone, clap::Args)]
pub struct ContactsArgs {
    /// Contact refinements (4, 8, 16, 32: about 25, 49, 97, 193 pairs per side).
    #[arg(long, value_delimiter = ',', default_values_t = [4, 8, 16, 32])]
    pub contact_refine: Vec<usize>,
    /// Highest harmonics H.
    #[arg(long = "harmonics", value_delimiter = ',', default_values_t = [3, 5])]
    pub harmonics: Vec<usize>,
    /// Formulations (as in scenes: auto, dense, sparse, condensed, schur, schur-lowrank).
    #[arg(long, value_delimiter = ',', default_values_t = ["schur".to_string(), "schur-lowrank".to_string()])]
    pub formulation: Vec<String>,
    /// Most continuation points per curve.
    #[arg(long, default_value_t = 150)]
    pub points: usize,
    /// Skip cases whose reduced matrix (the schur formulation's dense LU) exceeds this many rows.
    #[arg(long, default_value_t = 9000)]
    pub max_factored: usize,
    /// The smallest case only: contact refinement 4, H = 3, 20 points.
    #[arg(long)]
    pub quick: bool,
    /// Refine and list the resonance peaks of each curve (not timed).
    #[arg(long)]
    pub peaks: bool,
    /// Output folder for contacts.md and contacts.json.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs the benchmark; returns the table.
pub fn run(args: &ContactsArgs) -> Result<String, ContactsBenchError> {
    let formulations = args
        .formulation
        .iter()
        .map(|f| formulation_from_name(f).ok_or_else(|| ContactsBenchError::Formulation(f.clone())))
        .collect::<Result<Vec<_>, _>>()?;
    let (refines, harmonics, points) = if args.quick {
        (vec![4], vec![3], 20)
    } else {
        (
            args.contact_refine.clone(),
            args.harmonics.clone(),
            args.points,
        )
    };
    let dir = std::env::temp_dir().join(format!("fricbound-contacts-{}", std::process::id()));
    std::fs::create_dir_all(&dir)
        .map_err(|e| ContactsBenchError::Io(format!("{}: {e}", dir.display())))?;
    let mut measures = Vec::new();
    for &h in &harmonics {
        for &contact_refine in &refines {
            for &formulation in &formulations {
                let case = ContactCase {
                    contact_refine,
                    harmonics: h,
                    formulation,
                    max_points: points,
                };
                // The dense reduced LU of the schur formulation grows as its rows cubed.
                let pairs = 2 * (6 * contact_refine + 1);
                let factored = 2 * pairs * (2 * h + 1);
                if formulation == crate::model::Formulation::Schur && factored > args.max_factored {
                    eprintln!("skip: c{contact_refine} H = {h} schur ({factored} reduced rows)");
                    continue;
                }
                eprintln!(
                    "curve: c{contact_refine} H = {h} {}",
                    args_name(formulation)
                );
                let m = contacts::measure_case(&case, &dir, args.peaks)?;
                eprintln!("{}", row(&m));
                measures.push(m);
                if let Some(out) = &args.out {
                    write(out, &measures)?;
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(markdown(&measures))
}

fn args_name(f: crate::model::Formulation) -> &'static str {
    crate::hbm::cost::formulation_name(f)
}

/// Writes contacts.md and contacts.json into `out`.
fn write(out: &std::path::Path, measures: &[ContactMeasure]) -> Result<(), ContactsBenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| ContactsBenchError::Io(format!("{}: {e}", out.display())))?;
    let io = |e: crate::report::files::WriteError| ContactsBenchError::Io(e.to_string());
    let json = serde_json::to_string_pretty(measures)
        .map_err(|e| ContactsBenchError::Io(e.to_string()))?;
    write_atomic(&out.join("contacts.json"), json.as_bytes()).map_err(io)?;
    write_atomic(&out.join("contacts.md"), markdown(measures).as_bytes()).map_err(io)
}

/// One table row.
fn row(m: &ContactMeasure) -> String {
    let w = &m.work;
    format!(
        "| {} | {} | {} | {} | {} | {:.2} | {}{} | {} | {} | {:.1} | {:.2} | {:.2} | {:.2} | {:.2} | {} |",
        m.pairs_per_side,
        m.harmonics,
        m.unknowns,
        m.formulation,
        m.points,
        m.slipping_fraction,
        m.newton_iterations,
        if m.complete { "" } else { " (incomplete)" },
        factorisations(w),
        w.solves,
        m.per_iteration_ms,
        m.curve_s,
        w.factorisation_s,
        w.solve_s,
        w.evaluation_s,
        m.peak_memory_bytes
            .map(|b| format!("{}{}", format_bytes(b as f64), if m.memory_reset { "" } else { " (process)" }))
            .unwrap_or_else(|| "–".to_string()),
    )
}

/// Factorisations, with those by a low-rank update and their mean rank, and the harmonics
/// eliminated from the glued structure's modes.
fn factorisations(w: &crate::numerics::work::WorkReading) -> String {
    let mut parts = Vec::new();
    if w.low_rank_factorisations > 0 {
        parts.push(format!(
            "{} low-rank, mean rank {}",
            w.low_rank_factorisations,
            w.low_rank_rows / w.low_rank_factorisations
        ));
    }
    if w.modal_eliminations > 0 {
        parts.push(format!("{} harmonics from modes", w.modal_eliminations));
    }
    if parts.is_empty() {
        w.factorisations.to_string()
    } else {
        format!("{} ({})", w.factorisations, parts.join("; "))
    }
}

/// The table, the fitted exponents and the refined peaks.
fn markdown(measures: &[ContactMeasure]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| pairs/side | H | unknowns | formulation | points | slipping | Newton iterations | factorisations | solves | per iteration (ms) | curve (s) | factorising (s) | solving (s) | evaluating (s) | peak memory |\n\
         | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    for m in measures {
        let _ = writeln!(s, "{}", row(m));
    }
    let mut solvers: Vec<(&str, &str)> = measures
        .iter()
        .map(|m| (m.formulation.as_str(), m.linear_solver.as_str()))
        .collect();
    solvers.sort();
    solvers.dedup();
    for (f, solver) in solvers {
        let _ = writeln!(s, "\n{f}: {solver}");
    }
    let mut keys: Vec<(usize, String)> = measures
        .iter()
        .map(|m| (m.harmonics, m.formulation.clone()))
        .collect();
    keys.sort();
    keys.dedup();
    for (h, f) in keys {
        if let Some(a) = contacts::fitted_exponent(measures, h, &f, 49) {
            let _ = writeln!(
                s,
                "\nH = {h}, {f}: time per Newton iteration ∝ (pairs per side)^{a:.2} (least squares over 49 pairs/side and more)"
            );
        }
    }
    for m in measures.iter().filter(|m| !m.peaks.is_empty()) {
        let list: Vec<String> = m
            .peaks
            .iter()
            .map(|(f, a)| format!("{f:.6} Hz: {a:.12e} m"))
            .collect();
        let _ = writeln!(
            s,
            "\npeaks, {} pairs/side, H = {}, {}: {}",
            m.pairs_per_side,
            m.harmonics,
            m.formulation,
            list.join("; ")
        );
    }
    s
}
