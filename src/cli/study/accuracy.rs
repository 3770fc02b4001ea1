//! `fricbound study accuracy`: the accuracy study of a scene ([`crate::study::accuracy`]) on its
//! FRF, or on each limit curve of a limit scene: `study.csv` (one row per curve and setting,
//! appended as each finishes), `study.md` (a section per curve) and the error-against-time
//! figures with the Pareto front.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Mutex;

use indicatif::{ProgressBar, ProgressStyle};
use plotters::style::RGBColor;

use super::shared::{io_error, read_scene, study_dir, StudyReport};
use crate::cli::context::CommandError;
use crate::report::files::write_atomic;
use crate::report::plot::{self, figure_files, Curve};
use crate::study::accuracy::{
    self, CurveStudy, SettingErrors, SettingResult, StudyCurve, StudyError, StudyObserver,
    StudyPlan,
};

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

pub(super) fn accuracy_study(
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
