//! `fricbound modes` and `fricbound reduce`: the FE analyst's checks of the linear model
//! before any friction analysis.
//!
//! `modes` computes the lowest natural frequencies of the full model with the contacts open
//! and/or stuck and, when the scene has a `[reduction]` table, of the Craig-Bampton reduced
//! model, side by side with their relative errors; damped eigenvalues and modal damping
//! ratios for damped models; mode shapes (VTU on a mesh, CSV otherwise); the reduction report.
//! `reduce` writes the reduced matrices, the reduced DOF map and the recovery rows of the
//! outputs (files in [`crate::report::reduced_files`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::analysis::linear::LinearCase;
use crate::analysis::modes::{self, case_name, EigenMethod, NaturalModes};
use crate::cli::context::{create_dir, default_out_dir, CommandError};
use crate::model::reduce::{self, Reduction, ReductionSettings};
use crate::model::Problem;
use crate::report::files::write_atomic;
use crate::report::modes_files::{self, CaseJson, CaseModes, ModesJson};
use crate::report::reduced_files::{self, ReductionJson};
use crate::scene::{self, SceneError};

/// Which contact cases `modes` solves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum ContactCases {
    /// Contacts removed.
    Open,
    /// Contacts replaced by their kt, kn springs.
    Stuck,
    /// Both.
    #[default]
    Both,
}

impl ContactCases {
    /// The linear cases, open first.
    pub fn cases(self) -> Vec<LinearCase> {
        match self {
            ContactCases::Open => vec![LinearCase::Open],
            ContactCases::Stuck => vec![LinearCase::Stuck],
            ContactCases::Both => vec![LinearCase::Open, LinearCase::Stuck],
        }
    }
}

/// Options of `fricbound modes`.
#[derive(Debug, Clone)]
pub struct ModesOptions {
    /// Scene file.
    pub scene: PathBuf,
    /// Modes per case (every copy of a repeated last frequency is added).
    pub count: usize,
    /// Contact cases.
    pub contacts: ContactCases,
    /// Output folder (default: `out/<scene>/modes`).
    pub out: Option<PathBuf>,
    /// Scene overrides.
    pub overrides: Vec<String>,
}

/// What `modes` computed and where it wrote it.
#[derive(Debug, Clone)]
pub struct ModesReport {
    /// Output folder.
    pub dir: PathBuf,
    /// Per contact case.
    pub cases: Vec<CaseModes>,
    /// The reduction report, when the scene reduces.
    pub reduction: Option<ReductionJson>,
    /// Text summary (printed by the binary).
    pub text: String,
}

/// The scene's full problem and, when it has a `[reduction]` table, its reduction with the
/// recovery rows of the outputs.
fn full_and_reduced(
    path: &Path,
    overrides: &[String],
) -> Result<(String, Problem, Option<Reduction>), CommandError> {
    let label = path.display().to_string();
    let scene = scene::load(path, overrides)?;
    let (full, settings) = scene.validate_unreduced(&label)?;
    let reduction = match settings {
        Some(settings) => Some(reduce_with_outputs(&label, &full, settings)?),
        None => None,
    };
    Ok((label, full, reduction))
}

fn reduce_with_outputs(
    label: &str,
    full: &Problem,
    mut settings: ReductionSettings,
) -> Result<Reduction, CommandError> {
    settings.recover = full.outputs.clone();
    reduce::reduce(full, &settings)
        .map_err(|e| SceneError::invalid(label, "reduction", e.to_string()).into())
}

/// Runs `fricbound modes` (module docs) and writes its files.
pub fn modes(options: &ModesOptions) -> Result<ModesReport, CommandError> {
    if options.count == 0 {
        return Err(SceneError::invalid(
            &options.scene.display().to_string(),
            "--count",
            "ask for at least one mode",
        )
        .into());
    }
    let (label, full, reduction) = full_and_reduced(&options.scene, &options.overrides)?;
    let dir = options
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(Some(&options.scene), &options.overrides).join("modes"));
    create_dir(&dir)?;
    let reduced = reduction.as_ref().map(|r| &r.problem);
    let mut cases = Vec::new();
    for case in options.contacts.cases() {
        let f = modes::natural_modes(&full, case, options.count)?;
        let r = match reduced {
            Some(p) => Some(modes::natural_modes(p, case, options.count)?),
            None => None,
        };
        cases.push(CaseModes {
            full_damped: modes::damped_modes(&full, case, options.count)?,
            reduced_damped: match reduced {
                Some(p) => modes::damped_modes(p, case, options.count)?,
                None => None,
            },
            full: f,
            reduced: r,
        });
    }
    write_atomic(
        &dir.join("modes.csv"),
        modes_files::modes_csv(&cases).as_bytes(),
    )?;
    let any_damped = cases
        .iter()
        .any(|c| c.full_damped.is_some() || c.reduced_damped.is_some());
    if any_damped {
        write_atomic(
            &dir.join("damped_modes.csv"),
            modes_files::damped_csv(&cases).as_bytes(),
        )?;
    }
    let mut shape_files = Vec::new();
    for c in &cases {
        let name = case_name(c.full.case);
        for (model, problem, m) in [
            ("full", Some(&full), Some(&c.full)),
            ("reduced", reduced, c.reduced.as_ref()),
        ] {
            let (Some(problem), Some(m)) = (problem, m) else {
                continue;
            };
            let vtu = dir.join(format!("modes_{model}_{name}.vtu"));
            if modes_files::write_shapes_vtu(&vtu, problem, m)? {
                shape_files.push(vtu);
            } else {
                let csv = dir.join(format!("mode_shapes_{model}_{name}.csv"));
                write_atomic(&csv, modes_files::shapes_csv(problem, m).as_bytes())?;
                shape_files.push(csv);
            }
        }
    }
    let reduction_json = reduction.as_ref().map(ReductionJson::new);
    modes_files::write_modes_json(
        &dir.join("modes.json"),
        &ModesJson {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: label.clone(),
            dofs: full.model.n_dofs(),
            count: options.count,
            cases: cases.iter().map(CaseJson::new).collect(),
            reduction: reduction_json.clone(),
        },
    )?;
    let text = modes_text(
        &label,
        &full,
        &cases,
        reduction.as_ref(),
        &dir,
        &shape_files,
    );
    Ok(ModesReport {
        dir,
        cases,
        reduction: reduction_json,
        text,
    })
}

fn method_text(m: &NaturalModes) -> String {
    match &m.method {
        EigenMethod::Dense => format!("dense, {:.2} s", m.seconds),
        EigenMethod::Lanczos {
            sturm_count,
            sturm_shift_hz,
            max_residual,
        } => format!(
            "Lanczos, {:.2} s, residual {max_residual:.1e}, Sturm count {} below {sturm_shift_hz:.4} Hz",
            m.seconds,
            sturm_count.map_or("n/a (zero pivot)".to_string(), |c| c.to_string())
        ),
    }
}

fn freq_cell(m: Option<&modes::Mode>) -> String {
    match m {
        Some(m) if m.rigid => "0 (rigid body)".to_string(),
        Some(m) => format!("{:.6}", m.frequency_hz),
        None => "-".to_string(),
    }
}

/// The summary printed by `fricbound modes`.
fn modes_text(
    label: &str,
    full: &Problem,
    cases: &[CaseModes],
    reduction: Option<&Reduction>,
    dir: &Path,
    shape_files: &[PathBuf],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "scene        {label}");
    let _ = writeln!(s, "full model   {} DOFs", full.model.n_dofs());
    if let Some(r) = reduction {
        let j = ReductionJson::new(r);
        let _ = writeln!(s, "reduced      {} DOFs: {}", j.n_reduced, j.makeup_line());
        let report = r.model.report.to_string();
        let _ = writeln!(s, "{}", report.trim_end());
        let fi: Vec<String> = j
            .fixed_interface_hz
            .iter()
            .map(|f| format!("{f:.4}"))
            .collect();
        let _ = writeln!(s, "  fixed-interface modes (Hz): {}", fi.join(", "));
        for p in r.boundary.partial_contact_nodes.iter().take(5) {
            let _ = writeln!(
                s,
                "  note: contact {} uses {} of node {} (which has {}): all kept physical",
                p.contact,
                p.used.join(","),
                p.node,
                p.model.join(",")
            );
        }
    }
    for c in cases {
        let name = case_name(c.full.case);
        let _ = writeln!(
            s,
            "\ncontacts {name}: full model ({})",
            method_text(&c.full)
        );
        if let Some(r) = &c.reduced {
            let _ = writeln!(s, "               reduced model ({})", method_text(r));
        }
        let rigid = c.full.modes.iter().filter(|m| m.rigid).count();
        if rigid > 0 {
            let _ = writeln!(
                s,
                "  {rigid} rigid-body mode(s) at 0 Hz: a body is free with the contacts {name}"
            );
        }
        let errors = modes_files::relative_errors(c);
        let rows = c
            .full
            .modes
            .len()
            .max(c.reduced.as_ref().map_or(0, |r| r.modes.len()));
        // Without a reduction, the full model's column alone.
        let line = |a: &str, b: &str, c2: &str, d: &str| match c.reduced {
            Some(_) => format!("  {a:>4}  {b:>18}  {c2:>18}  {d:>11}\n"),
            None => format!("  {a:>4}  {b:>18}\n"),
        };
        s.push_str(&line("mode", "full (Hz)", "reduced (Hz)", "rel. error"));
        for i in 0..rows {
            s.push_str(&line(
                &(i + 1).to_string(),
                &freq_cell(c.full.modes.get(i)),
                &freq_cell(c.reduced.as_ref().and_then(|r| r.modes.get(i))),
                &errors
                    .get(i)
                    .copied()
                    .flatten()
                    .map_or("-".to_string(), |e| format!("{e:.3e}")),
            ));
        }
        for (model, damped) in [("full", &c.full_damped), ("reduced", &c.reduced_damped)] {
            if let Some(d) = damped {
                let _ = writeln!(
                    s,
                    "  damped modes, {model} model: natural Hz, damped Hz, ζ{}",
                    if d.rigid > 0 {
                        format!(" ({} rigid-body eigenvalues s ≈ 0 left out)", d.rigid)
                    } else {
                        String::new()
                    }
                );
                for (i, m) in d.modes.iter().enumerate() {
                    let _ = writeln!(
                        s,
                        "  {:>4}  {:>14.6}  {:>14.6}  {:.4e}",
                        i + 1,
                        m.natural_hz,
                        m.damped_hz,
                        m.damping_ratio
                    );
                }
            }
        }
    }
    let _ = writeln!(s, "\nwritten to {}: modes.csv, modes.json", dir.display());
    for f in shape_files {
        let _ = writeln!(s, "  {}", f.display());
    }
    s
}

/// Options of `fricbound reduce`.
#[derive(Debug, Clone)]
pub struct ReduceOptions {
    /// Scene file (with a `[reduction]` table).
    pub scene: PathBuf,
    /// Output folder (default: `out/<scene>/reduced`).
    pub out: Option<PathBuf>,
    /// Scene overrides.
    pub overrides: Vec<String>,
}

/// What `reduce` wrote.
#[derive(Debug, Clone)]
pub struct ReduceReport {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// The reduction report.
    pub reduction: ReductionJson,
    /// Text summary.
    pub text: String,
}

/// Runs `fricbound reduce`: writes the reduced model (files in
/// [`crate::report::reduced_files`]).
pub fn reduce(options: &ReduceOptions) -> Result<ReduceReport, CommandError> {
    let (label, full, reduction) = full_and_reduced(&options.scene, &options.overrides)?;
    let Some(reduction) = reduction else {
        return Err(SceneError::invalid(
            &label,
            "reduction",
            "the scene has no [reduction] table (modes = N): nothing to reduce",
        )
        .into());
    };
    let dir = options.out.clone().unwrap_or_else(|| {
        default_out_dir(Some(&options.scene), &options.overrides).join("reduced")
    });
    create_dir(&dir)?;
    let files = reduced_files::write_reduced_model(&dir, &reduction, &full.model.dof_names)?;
    let json = ReductionJson::new(&reduction);
    let mut text = String::new();
    let _ = writeln!(text, "scene        {label}");
    let _ = writeln!(
        text,
        "reduced      {} -> {} DOFs: {}",
        json.n_full,
        json.n_reduced,
        json.makeup_line()
    );
    let _ = writeln!(text, "{}", reduction.model.report.to_string().trim_end());
    let _ = writeln!(text, "written to {}:", dir.display());
    for f in &files {
        let _ = writeln!(text, "  {}", f.display());
    }
    Ok(ReduceReport {
        files,
        reduction: json,
        text,
    })
}

/// Lines of `fricbound check` for a scene with a `[reduction]` table: the boundary's make-up
/// by origin, and a warning per contact node whose contact rows use fewer directions than the
/// model has there (those directions are kept physical all the same, see
/// [`crate::model::reduce`]). Empty without a `[reduction]` table. Builds the full problem
/// again (no reduction).
pub fn boundary_check_lines(scene: &scene::Scene, label: &str) -> Result<String, CommandError> {
    if scene.reduction.is_none() {
        return Ok(String::new());
    }
    let (full, settings) = scene.validate_unreduced(label)?;
    let Some(settings) = settings else {
        return Ok(String::new());
    };
    let b = reduce::boundary(&full, &settings.boundary);
    let m = &b.makeup;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "boundary     {} DOFs kept physical: {} contact, {} other directions of contact nodes, \
         {} output, {} extra; {} loaded DOFs projected on the basis; + {} fixed-interface modes",
        b.dofs.len(),
        m.contacts,
        m.contact_nodes,
        m.outputs,
        m.extra,
        m.loaded,
        settings.modes
    );
    const LISTED: usize = 12;
    for p in b.partial_contact_nodes.iter().take(LISTED) {
        let _ = writeln!(
            s,
            "warning      contact {} uses direction(s) {} of node {}, which has {}: the other \
             direction(s) are kept physical in the boundary too",
            p.contact,
            p.used.join(","),
            p.node,
            p.model.join(",")
        );
    }
    if b.partial_contact_nodes.len() > LISTED {
        let _ = writeln!(
            s,
            "warning      ... {} more contact nodes like these",
            b.partial_contact_nodes.len() - LISTED
        );
    }
    Ok(s)
}
