//! `fricbound study accuracy`: the accuracy study of a scene ([`crate::study::accuracy`]) on its
//! FRF, or on each limit curve of a limit scene, with its files: `study.csv` (one row per curve
//! and setting, appended as each finishes), `study.md` (a section per curve) and the
//! error-against-time figure `accuracy_pareto.png`/`.svg` with the Pareto front (a limit scene:
//! every curve in it, and one `accuracy_pareto_<curve>` figure per curve).
//!
//! `fricbound study jacobian`: the Jacobian study ([`crate::study::jacobian`]) of a scene and
//! of the reference ladder, with `jacobian.csv` (one row per case and formulation, appended as
//! each finishes) and `jacobian.md`.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Mutex;

use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::style::RGBColor;

use super::context::CommandError;
use crate::hbm::cost::formulation_name;
use crate::report::files::write_atomic;
use crate::report::plot::{self, figure_files, Curve};
use crate::scene::SceneError;
use crate::study::accuracy::{
    self, CurveStudy, SettingErrors, SettingResult, StudyCurve, StudyError, StudyObserver,
    StudyPlan,
};
use crate::study::jacobian::{self, CaseResult, FormulationRow};

/// Studies over solver settings.
#[derive(Debug, Clone, Subcommand)]
pub enum StudyCommand {
    /// What accuracy costs in time: each setting (harmonics, samples, tolerance, interior modes,
    /// effect switches) against a converged reference.
    Accuracy(StudyArgs),
    /// The analytic Jacobian against finite differences, and the dense, sparse, condensed and
    /// schur formulations side by side (time per residual, Jacobian, Newton iteration and FRF
    /// point), on the scene and on the paper case, chains with Jenkins elements to ground and
    /// the reduced blade pair; the formulation `auto` picks is marked.
    Jacobian(StudyArgs),
}

/// The arguments every study takes.
#[derive(Debug, Clone, Args)]
pub struct StudyArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Short setting lists and budgets (seconds on the paper case).
    #[arg(long)]
    pub quick: bool,
    /// Output folder (default: out/<scene name>-accuracy or -jacobian).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override a scene field by its dotted path (accuracy: applied to every setting;
    /// jacobian: the scene's own case only).
    #[arg(long = "set", value_name = "FIELD=VALUE")]
    pub overrides: Vec<String>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// What a study produced: the summary text and, when some setting failed or did not cover the
/// range, why (exit code 3).
#[derive(Debug, Clone)]
pub struct StudyReport {
    /// Printable summary.
    pub summary: String,
    /// Failed or incomplete settings, None when all are complete.
    pub incomplete: Option<String>,
}

/// Header of `study.csv` when the curves' references have at most `peaks` resonance peaks.
fn csv_header(peaks: usize) -> String {
    let mut h = String::from(
        "curve,group,setting,status,unknowns,points,newton_iterations,time_s,curve_l2_err,\
         peak_amp_err,peak_freq_err",
    );
    for k in 1..=peaks {
        let _ = write!(h, ",peak{k}_amp_err,peak{k}_freq_err");
    }
    h.push('\n');
    h
}

/// One `study.csv` row, its peak cells padded (empty) to `peaks` peaks.
fn csv_row(r: &SettingResult, e: &SettingErrors, peaks: usize) -> String {
    // Commas in a label or a status become semicolons: one cell each, no quoting.
    let status = r.status.replace(',', ";");
    let mut s = format!(
        "{},{},{},{status},{},{},{},{:.4e},{:.3e},{:.3e},{:.3e}",
        r.curve.replace(',', ";"),
        r.setting.group,
        r.setting.label.replace(',', ";"),
        r.unknowns,
        r.points,
        r.newton_iterations,
        r.time_s,
        e.curve_l2,
        e.max_peak_amplitude(),
        e.max_peak_frequency()
    );
    for (a, f) in &e.peaks {
        let _ = write!(s, ",{a:.3e},{f:.3e}");
    }
    for _ in e.peaks.len()..peaks {
        s.push_str(",,");
    }
    s.push('\n');
    s
}

/// Runs a study command.
pub fn run(command: &StudyCommand) -> Result<StudyReport, CommandError> {
    match command {
        StudyCommand::Accuracy(a) => {
            accuracy_study(&a.scene, a.quick, a.out.clone(), &a.overrides, a.quiet)
        }
        StudyCommand::Jacobian(a) => {
            jacobian_study(&a.scene, a.quick, a.out.clone(), &a.overrides, a.quiet)
        }
    }
}

fn io_error(path: &std::path::Path, source: std::io::Error) -> CommandError {
    CommandError::Write(crate::report::files::WriteError {
        path: path.display().to_string(),
        source,
    })
}

/// The scene file's label (its path) and text.
fn read_scene(scene_path: &std::path::Path) -> Result<(String, String), CommandError> {
    let label = scene_path.display().to_string();
    let text = std::fs::read_to_string(scene_path).map_err(|source| SceneError::Io {
        file: label.clone(),
        source,
    })?;
    Ok((label, text))
}

/// The study's output folder, created (`out` or `out/<scene stem>-<study>`), and the stem.
fn study_dir(
    scene_path: &std::path::Path,
    out: Option<PathBuf>,
    study: &str,
) -> Result<(PathBuf, String), CommandError> {
    let stem = scene_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{stem}-{study}")));
    std::fs::create_dir_all(&dir).map_err(|source| CommandError::OutputDir {
        path: dir.display().to_string(),
        source,
    })?;
    Ok((dir, stem))
}

/// Figure file stem of a curve's own Pareto figure: `accuracy_pareto` for a scene's FRF,
/// `accuracy_pareto_<curve>` for a limit curve.
fn pareto_stem(curve: &StudyCurve, several: bool) -> String {
    if several || curve.case.is_some() {
        format!("accuracy_pareto_{}", curve.name)
    } else {
        "accuracy_pareto".to_string()
    }
}

/// Lone points (NaN between them breaks the line) of `pairs` not in `front`.
fn lone_points(pairs: &[(f64, f64)], front: &[usize]) -> (Vec<f64>, Vec<f64>) {
    lone_points_where(pairs, |i| !front.contains(&i))
}

/// Lone points (NaN between them breaks the line) of the `pairs` whose index passes `keep`.
fn lone_points_where(pairs: &[(f64, f64)], keep: impl Fn(usize) -> bool) -> (Vec<f64>, Vec<f64>) {
    (0..pairs.len())
        .filter(|&i| keep(i))
        .flat_map(|i| [pairs[i], (f64::NAN, f64::NAN)])
        .unzip()
}

/// One curve's figure: peak amplitude error against time, the Pareto front dashed and each of
/// its settings labelled in the legend; the settings whose run is not complete (never on the
/// front, [`CurveStudy::pareto`]) as a series of their own.
fn curve_pareto_figure(
    study: &CurveStudy,
    title: &str,
    dir: &std::path::Path,
    stem: &str,
) -> Result<(), CommandError> {
    let (pairs, front) = study.pareto();
    let front_x: Vec<f64> = front.iter().map(|&i| pairs[i].0).collect();
    let front_y: Vec<f64> = front.iter().map(|&i| pairs[i].1).collect();
    let complete = |i: usize| study.results[i].is_complete();
    let (others_x, others_y) = lone_points_where(&pairs, |i| complete(i) && !front.contains(&i));
    let (partial_x, partial_y) = lone_points_where(&pairs, |i| !complete(i));
    let fronts: Vec<([f64; 1], [f64; 1])> = front
        .iter()
        .map(|&i| ([pairs[i].0], [pairs[i].1]))
        .collect();
    let mut series: Vec<Curve> = vec![
        marked(
            "Pareto front",
            &front_x,
            &front_y,
            RGBColor(200, 30, 30),
            true,
        ),
        marked(
            "other settings",
            &others_x,
            &others_y,
            RGBColor(150, 150, 150),
            false,
        ),
    ];
    if !partial_x.is_empty() {
        series.push(marked(
            "incomplete runs (peak error on the curve as followed)",
            &partial_x,
            &partial_y,
            RGBColor(175, 165, 215),
            false,
        ));
    }
    for (k, (&i, (x, y))) in front.iter().zip(&fronts).enumerate() {
        let label = study.results[i].setting.label.as_str();
        series.push(marked(label, x, y, plot::palette(k + 1), false));
    }
    pareto_plot(title, &series, dir, stem)
}

/// The figure of several curves: per curve, its Pareto front dashed and its other settings as
/// points, in the curve's colour.
fn curves_pareto_figure(
    studies: &[CurveStudy],
    title: &str,
    dir: &std::path::Path,
) -> Result<(), CommandError> {
    /// One curve's points: labels, then the front's and the other settings' (time, error).
    struct CurvePoints {
        front_label: String,
        others_label: String,
        front: (Vec<f64>, Vec<f64>),
        others: (Vec<f64>, Vec<f64>),
    }
    let data: Vec<CurvePoints> = studies
        .iter()
        .map(|s| {
            let (pairs, front) = s.pareto();
            CurvePoints {
                front_label: format!("{}: Pareto front", s.curve.name),
                others_label: format!("{}: other settings", s.curve.name),
                front: front.iter().map(|&i| pairs[i]).unzip(),
                others: lone_points(&pairs, &front),
            }
        })
        .collect();
    let mut series: Vec<Curve> = Vec::new();
    for (k, d) in data.iter().enumerate() {
        let color = plot::palette(k);
        series.push(marked(&d.front_label, &d.front.0, &d.front.1, color, true));
        series.push(marked(
            &d.others_label,
            &d.others.0,
            &d.others.1,
            color,
            false,
        ));
    }
    pareto_plot(title, &series, dir, "accuracy_pareto")
}

/// A series of a Pareto figure: its points marked, joined by a dashed or a solid line.
fn marked<'a>(
    label: &'a str,
    x: &'a [f64],
    y: &'a [f64],
    color: RGBColor,
    dashed: bool,
) -> Curve<'a> {
    Curve {
        label,
        x,
        y,
        color,
        dashed,
        markers: true,
    }
}

/// Draws error-against-time `series` (log-log) to `<dir>/<stem>.png` and `.svg`.
fn pareto_plot(
    title: &str,
    series: &[Curve],
    dir: &std::path::Path,
    stem: &str,
) -> Result<(), CommandError> {
    let (png, svg) = figure_files(dir, stem);
    plot::plot_lines(
        title,
        "wall time of the FRF (s)",
        "largest relative peak amplitude error",
        true,
        series,
        &png,
        &svg,
    )?;
    Ok(())
}

/// What a curve is, for `study.md`.
fn curve_description(curve: &StudyCurve) -> String {
    match &curve.case {
        None => "The scene's FRF with its own initial states.".to_string(),
        Some(case) => {
            let first = case.contact_states.first().copied().unwrap_or(f64::NAN);
            if case.contact_states.iter().all(|&m| m == first) {
                format!(
                    "Limit curve: every contact point starts at T = m·μN with m = {first:+} \
                     (paper Eqs. 14-15)."
                )
            } else {
                format!(
                    "Limit case given per side or point: initial states m = {:?} (contact order).",
                    case.contact_states
                )
            }
        }
    }
}

/// The `study.md` section of one curve.
fn curve_section(
    study: &CurveStudy,
    reference: &accuracy::Setting,
    check: &accuracy::Setting,
    output: &str,
    stem: &str,
) -> String {
    let (_, front) = study.pareto();
    let mut md = format!(
        "## Curve `{}`\n\n{} Reference: {} ({} points, {:.2} s). Reference converged to: curve \
         L2 {:.2e}, peak amplitude {:.2e}, peak frequency {:.2e} (against {}, {}). Errors are \
         relative to this curve's reference, for the first output ({output}); each reference \
         peak is compared with the setting's highest peak in its basin (the frequencies nearer \
         to it than to another reference peak). A setting whose run is not `complete` has its peak errors measured on the curve as followed and is \
         never on the Pareto front.\n\n\
         | group | setting | status | unknowns | points | Newton its | time (s) | curve L2 err | \
         peak amp err | peak freq err | Pareto |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        study.curve.name,
        curve_description(&study.curve),
        reference.label,
        study.reference.points,
        study.reference.time_s,
        study.check_errors.curve_l2,
        study.check_errors.max_peak_amplitude(),
        study.check_errors.max_peak_frequency(),
        check.label,
        study.check.status,
    );
    for (i, (r, e)) in study.results.iter().zip(&study.errors).enumerate() {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {:.3} | {:.2e} | {:.2e} | {:.2e} | {} |",
            r.setting.group,
            r.setting.label,
            r.status,
            r.unknowns,
            r.points,
            r.newton_iterations,
            r.time_s,
            e.curve_l2,
            e.max_peak_amplitude(),
            e.max_peak_frequency(),
            if front.contains(&i) { "yes" } else { "" }
        );
    }
    let _ = writeln!(
        md,
        "\nReference peaks (Hz, m): {:?}\n\n![error against time]({stem}.png)\n",
        study.reference.peaks
    );
    md
}

/// Writes `study.csv` as the study runs (header and reference checks once the references are
/// solved, then one row per finished setting) and advances the progress bar; the first write
/// error is kept and reported at the end.
struct CsvRows<'a> {
    file: Mutex<(std::fs::File, Option<std::io::Error>)>,
    peaks: std::sync::atomic::AtomicUsize,
    bar: Option<&'a ProgressBar>,
}

impl CsvRows<'_> {
    fn write(&self, text: &str) {
        let mut guard = self.file.lock().expect("no panics while holding the lock");
        if guard.1.is_none() {
            if let Err(e) = guard
                .0
                .write_all(text.as_bytes())
                .and_then(|()| guard.0.flush())
            {
                guard.1 = Some(e);
            }
        }
    }
}

impl StudyObserver for CsvRows<'_> {
    fn references(&self, pairs: &[(SettingResult, SettingResult)], peaks: usize) {
        self.peaks
            .store(peaks, std::sync::atomic::Ordering::Relaxed);
        let mut head = csv_header(peaks);
        for (r, c) in pairs {
            head.push_str(&csv_row(c, &accuracy::errors(c, r), peaks));
        }
        self.write(&head);
    }

    fn setting(&self, result: &SettingResult, errors: &SettingErrors) {
        let peaks = self.peaks.load(std::sync::atomic::Ordering::Relaxed);
        self.write(&csv_row(result, errors, peaks));
        if let Some(bar) = self.bar {
            bar.set_message(format!("{}: {}", result.curve, result.setting.label));
        }
    }

    fn job_done(&self) {
        if let Some(bar) = self.bar {
            bar.inc(1);
        }
    }
}

fn accuracy_study(
    scene_path: &std::path::Path,
    quick: bool,
    out: Option<PathBuf>,
    user: &[String],
    quiet: bool,
) -> Result<StudyReport, CommandError> {
    let (label, text) = read_scene(scene_path)?;
    let plan = StudyPlan::new(&text, &label, user, quick)?;
    let (dir, _) = study_dir(scene_path, out, "accuracy")?;
    let several = plan.curves.len() > 1;
    let bar = (!quiet).then(|| {
        let bar = ProgressBar::new(plan.jobs() as u64);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}",
            )
            .expect("static template"),
        );
        bar.set_message("references");
        bar
    });
    // study.csv, its rows appended as settings finish (the reference checks first).
    let csv_path = dir.join("study.csv");
    let file = std::fs::File::create(&csv_path).map_err(|e| io_error(&csv_path, e))?;
    let observer = CsvRows {
        file: Mutex::new((file, None)),
        peaks: std::sync::atomic::AtomicUsize::new(0),
        bar: bar.as_ref(),
    };
    let studies = plan.run(&observer).map_err(|e| match e {
        StudyError::Scene(e) => CommandError::from(e),
        StudyError::ReferenceFailed { .. } => CommandError::Study {
            scene: label.clone(),
            reason: e.to_string(),
        },
    })?;
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    if let Some(e) = observer.file.into_inner().expect("lock not poisoned").1 {
        return Err(io_error(&csv_path, e));
    }
    let StudyPlan {
        scene,
        problem,
        reference,
        check,
        settings,
        curves,
        ..
    } = plan;
    // The figures: per curve, peak amplitude error against time with the Pareto front marked
    // and labelled; with several curves also all of them in one figure.
    for s in &studies {
        let title = if several || s.curve.case.is_some() {
            format!(
                "What accuracy costs: {}, curve {}",
                scene.title, s.curve.name
            )
        } else {
            format!("What accuracy costs: {}", scene.title)
        };
        curve_pareto_figure(s, &title, &dir, &pareto_stem(&s.curve, several))?;
    }
    if several {
        curves_pareto_figure(
            &studies,
            &format!("What accuracy costs: {}, per curve", scene.title),
            &dir,
        )?;
    }
    // study.md
    let output = &problem.model.dof_names[problem.outputs[0]];
    let mut md = format!(
        "# Accuracy study: {}\n\nScene `{label}`{}. Curves: {}. Settings are varied one at a \
         time from the scene as given, on each curve against that curve's reference. Times are \
         wall times of the continuation with the settings running in parallel (one per \
         core).\n\n",
        scene.title,
        if user.is_empty() {
            String::new()
        } else {
            format!(" with {}", user.join(" "))
        },
        curves
            .iter()
            .map(|c| format!("`{}`", c.name))
            .collect::<Vec<_>>()
            .join(", "),
    );
    if several {
        md.push_str("![error against time, every curve](accuracy_pareto.png)\n\n");
    }
    for s in &studies {
        md.push_str(&curve_section(
            s,
            &reference,
            &check,
            output,
            &pareto_stem(&s.curve, several),
        ));
    }
    write_atomic(&dir.join("study.md"), md.as_bytes())?;
    let unfinished: Vec<String> = studies
        .iter()
        .flat_map(|s| s.results.iter().chain([&s.check]))
        .filter(|r| r.status != "complete")
        .map(|r| {
            if several || r.curve != "frf" {
                format!("{}: {} ({})", r.curve, r.setting.label, r.status)
            } else {
                format!("{} ({})", r.setting.label, r.status)
            }
        })
        .collect();
    let mut summary = format!(
        "accuracy study of {label}: {} settings on {} curve(s)\n",
        settings.len(),
        curves.len()
    );
    for s in &studies {
        let _ = writeln!(
            summary,
            "{}reference {} converged to {:.2e} (peak amplitude against {}); Pareto front: {}",
            if several || s.curve.case.is_some() {
                format!("curve {}: ", s.curve.name)
            } else {
                String::new()
            },
            reference.label,
            s.check_errors.max_peak_amplitude(),
            check.label,
            s.front_labels()
        );
    }
    let _ = writeln!(summary, "results in {}", dir.display());
    Ok(StudyReport {
        summary,
        incomplete: (!unfinished.is_empty())
            .then(|| format!("settings not complete: {}", unfinished.join("; "))),
    })
}

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

fn jacobian_study(
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
