//! The stability part of the study: where the limit curves of the paper's damper around the
//! 3rd resonance (Fig. 13a, F0 = 120 N) are unstable, with the damper's own damping C_D = 0 as
//! printed in Table 1 and with a small damper damping (5 N s/m on xD and yD). Two extra runs of
//! `fig13-3rd.toml` (limit curves only, `analysis.stability = true`,
//! `analysis.stability_method = "hill+monodromy"`), each into its own sub-folder, summarised
//! in a section of `summary.md` and in `stability.json`.
//!
//! Hill's verdict uses the AFT Jacobian for the Jenkins contacts, exact where every contact is
//! stuck or open; where a contact stick-slips it is replaced by the monodromy of the time
//! integration's periodic orbit (README, "Stability"), with 256 Newmark steps per period
//! (64 with `--quick`).

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::figures::FIGURES;
use crate::analysis::stability::{stretches_text, unstable_stretches};
use crate::cli::context::{RunOptions, RunOutcome};
use crate::cli::run;

/// One stability run: sub-folder, what it is, and its overrides of `fig13-3rd.toml`.
struct StabilityJob {
    id: &'static str,
    damper_damping: &'static str,
    overrides: &'static [&'static str],
}

/// The sub-folders of the stability runs, for clearing an earlier study's.
pub(super) fn stability_folders() -> impl Iterator<Item = &'static str> {
    JOBS.iter().map(|j| j.id)
}

const JOBS: [StabilityJob; 2] = [
    StabilityJob {
        id: "stability-3rd",
        damper_damping: "C_D = 0 (Table 1)",
        overrides: &[],
    },
    StabilityJob {
        id: "stability-3rd-damped",
        damper_damping: "C_D = 5 N s/m on xD, yD",
        overrides: &["model.damping.4.4=5", "model.damping.5.5=5"],
    },
];

/// Settings of both runs: stability on, limit curves only (no intermediate curves, no bound
/// scan); harmonics 0..5 for the study, 0..1
/// and coarser steps with `--quick`.
fn common_overrides(quick: bool) -> Vec<String> {
    let mut o = vec![
        "analysis.stability=true".to_string(),
        "analysis.stability_method=hill+monodromy".to_string(),
        "limits.intermediate=[]".to_string(),
        "limits.bound_scan=[]".to_string(),
    ];
    if quick {
        o.extend(
            [
                "harmonics.max=1",
                "analysis.max_step=0.25",
                "limits.grid_points=41",
                "analysis.monodromy_steps_per_period=64",
            ]
            .map(String::from),
        );
    } else {
        o.push("harmonics.max=5".to_string());
        o.push("analysis.monodromy_steps_per_period=256".to_string());
    }
    o
}

/// Where one limit curve is unstable.
#[derive(Debug, Clone, Serialize)]
pub struct CurveStability {
    /// Damper damping of the run.
    pub damper_damping: String,
    /// The limit case (`m+1`, `m-1`).
    pub curve: String,
    /// Points on the curve.
    pub points: usize,
    /// Points found unstable (Hill's verdict where every contact is stuck or open, the
    /// monodromy's on stick-slip points).
    pub unstable_points: usize,
    /// Points whose verdict is the monodromy's.
    pub monodromy_points: usize,
    /// Points whose verdict is not reliable (the monodromy's shooting did not converge).
    pub unreliable_points: usize,
    /// Unstable stretches `[from_hz, to_hz]`.
    pub unstable_hz: Vec<[f64; 2]>,
    /// Largest leading-exponent real part over the curve (1/s).
    pub max_floquet_re: Option<f64>,
}

/// The result of the stability runs: per run, its rows or why it failed.
#[derive(Debug, Clone, Serialize)]
pub struct StabilityStudy {
    /// Harmonics used.
    pub harmonics: usize,
    /// Rows of the runs that finished.
    pub curves: Vec<CurveStability>,
    /// Runs that failed, with the reason.
    pub failed: Vec<String>,
}

/// Runs both stability runs into `<dir>/<id>/` and collects where each limit curve is unstable.
pub fn stability_study(dir: &Path, quick: bool, quiet: bool) -> StabilityStudy {
    let job = FIGURES
        .iter()
        .find(|f| f.id == "fig13-3rd")
        .expect("the study has the 3rd-resonance figure");
    let mut study = StabilityStudy {
        harmonics: if quick { 1 } else { 5 },
        curves: Vec::new(),
        failed: Vec::new(),
    };
    for s in &JOBS {
        if !quiet {
            eprintln!(
                "{}: stability of the limit curves (Hill, monodromy on stick-slip), {}",
                s.id, s.damper_damping
            );
        }
        let mut overrides = common_overrides(quick);
        overrides.extend(s.overrides.iter().map(|o| o.to_string()));
        let options = RunOptions {
            scene: Some(PathBuf::from("meshes/paper-wedge").join(job.scene_file)),
            scene_text: Some(job.text.to_string()),
            out: Some(dir.join(s.id)),
            overrides,
            quiet,
        };
        match run(&options) {
            Ok(report) => match &report.outcome {
                RunOutcome::Limits(a) => {
                    for c in &a.limits {
                        let stretches =
                            unstable_stretches(c.points.iter().map(|p| (p.freq_hz, p.stability)));
                        let unstable: Vec<f64> = c
                            .points
                            .iter()
                            .filter_map(|p| p.stability)
                            .filter(|s| s.is_unstable())
                            .map(|s| s.floquet_re)
                            .collect();
                        study.curves.push(CurveStability {
                            damper_damping: s.damper_damping.to_string(),
                            curve: c.case.name.clone(),
                            points: c.points.len(),
                            unstable_points: unstable.len(),
                            monodromy_points: c
                                .points
                                .iter()
                                .filter(|p| {
                                    p.stability.is_some_and(|s| {
                                        s.method
                                            == crate::analysis::stability::VerdictSource::Monodromy
                                    })
                                })
                                .count(),
                            unreliable_points: c
                                .points
                                .iter()
                                .filter(|p| p.stability.is_some_and(|s| !s.reliable))
                                .count(),
                            unstable_hz: stretches,
                            max_floquet_re: c
                                .points
                                .iter()
                                .filter_map(|p| p.stability.map(|s| s.floquet_re))
                                .reduce(f64::max),
                        });
                    }
                }
                _ => study.failed.push(format!("{}: not a limit analysis", s.id)),
            },
            Err(e) => study.failed.push(format!("{}: {e}", s.id)),
        }
    }
    study
}

/// The `summary.md` section of the stability runs.
pub fn stability_markdown(study: &StabilityStudy) -> String {
    let mut md = String::from("\n## Stability of the limit curves (3rd resonance, Fig. 13a)\n\n");
    md.push_str(&format!(
        "The stability of every point of the two limit curves of `fig13-3rd.toml` (F0 = 120 N, \
         harmonics 0..{}), without and with a small damper damping (sub-folders \
         `stability-3rd`, `stability-3rd-damped`; `analysis.stability_method = \
         \"hill+monodromy\"`). An unstable stretch of a limit curve is not a state the damper \
         keeps there, so the band is no bound of the reachable response there. Hill's method \
         (the AFT Jacobian of the periodic forces) gives the verdict where the contacts are \
         fully stuck or open, where it is exact; on stick-slip points, where its growth rates \
         are not reliable, the verdict is the monodromy's: the Floquet multipliers of the time \
         integration's periodic orbit through the point (README, \"Stability\").\n\n",
        study.harmonics
    ));
    md.push_str("| damper damping | curve | points | by the monodromy | unreliable | unstable | unstable stretches (Hz) | largest Re λ (1/s) |\n");
    md.push_str("| --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for c in &study.curves {
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.damper_damping,
            c.curve,
            c.points,
            c.monodromy_points,
            c.unreliable_points,
            c.unstable_points,
            if c.unstable_hz.is_empty() {
                "none".to_string()
            } else {
                stretches_text(&c.unstable_hz)
            },
            c.max_floquet_re
                .map(|v| format!("{v:.3}"))
                .unwrap_or_default()
        ));
    }
    for f in &study.failed {
        md.push_str(&format!("\nFailed: {f}\n"));
    }
    md
}
