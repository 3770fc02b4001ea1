//! `fricbound check`: validates a scene and describes it (sizes, formulation, cost and memory
//! estimates, effects, accuracy settings, contacts, loads, analysis, limits and sweep), long
//! lists abbreviated ([`abbreviated_list`]).

use std::path::Path;

use super::context::{load_scene, parallel_solves, CommandError};
use super::modes;

/// `fricbound check`: validates the scene and returns a printable summary.
pub fn check(scene_path: Option<&Path>, overrides: &[String]) -> Result<String, CommandError> {
    let (label, scene, problem, limits) = load_scene(scene_path, overrides)?;
    let set = problem.unknown_harmonics();
    let n = problem.model.n_dofs();
    let e = &problem.effects;
    let a = &problem.analysis.continuation;
    let mut s = String::new();
    use std::fmt::Write as _;
    let _ = writeln!(s, "scene        {label}");
    if !scene.title.is_empty() {
        let _ = writeln!(s, "title        {}", scene.title);
    }
    let _ = writeln!(
        s,
        "DOFs         {n}: {}",
        abbreviated_list(&problem.model.dof_names)
    );
    let harmonics = set.harmonics();
    let _ = writeln!(
        s,
        "harmonics    [{}] ({}{} blocks), {} samples per period",
        abbreviated_list(harmonics),
        if harmonics.len() > CHECK_LISTED {
            format!("{} harmonics, ", harmonics.len())
        } else {
            String::new()
        },
        set.n_blocks(),
        problem.samples
    );
    let _ = writeln!(
        s,
        "unknowns     {} (+1 frequency in continuation)",
        n * set.n_blocks()
    );
    let cost = crate::hbm::cost::estimate(&problem);
    let _ = writeln!(
        s,
        "formulation  {}{}: {} Newton unknowns, factorised matrix of {} rows",
        crate::hbm::cost::formulation_name(cost.formulation),
        if problem.analysis.formulation == crate::model::Formulation::Auto {
            " (auto)"
        } else {
            ""
        },
        cost.unknowns,
        cost.factored
    );
    if problem.analysis.formulation == crate::model::Formulation::Auto {
        let _ = writeln!(s, "  auto       {}", problem.auto_formulation().1);
    }
    let _ = writeln!(
        s,
        "  solver     {}",
        crate::hbm::cost::linear_solver_description(&problem, cost.formulation)
    );
    let _ = writeln!(s, "cost         {}", cost.summary());
    let parallel = parallel_solves(&scene, &problem, limits.as_ref());
    use crate::hbm::cost::{available_memory, memory_refusal, MEMINFO};
    match available_memory() {
        Some(available) => {
            let verdict = match memory_refusal(&problem, &cost, parallel, available as f64) {
                Some(_) => "`run` refuses this scene: lower harmonics.max, harmonics.samples or \
                            the model size"
                    .to_string(),
                None => format!(
                    "fits{}",
                    if parallel > 1 {
                        format!(" ({parallel} curves solved at once)")
                    } else {
                        String::new()
                    }
                ),
            };
            let _ = writeln!(
                s,
                "memory       {} available ({MEMINFO}): {verdict}",
                crate::hbm::cost::format_bytes(available as f64)
            );
        }
        None => {
            let _ = writeln!(
                s,
                "memory       available memory unknown ({MEMINFO} unreadable): not checked"
            );
        }
    }
    let _ = writeln!(
        s,
        "effects      normal load {:?}, lift-off {}, statics {:?}",
        e.contact.normal_load, e.contact.liftoff, e.coupling
    );
    let estimate = &problem.analysis.error_estimate;
    let _ = writeln!(
        s,
        "accuracy     {}",
        if estimate.enabled && problem.analysis.nonlinear_modes.is_some() {
            let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
            format!(
                "error estimate on every mode point (the change of its frequency, damping \
                 ratio and amplitude at the DOF on H = {} harmonics, solved to convergence), \
                 warning above {} %",
                crate::analysis::error_estimate::extended_harmonic(h_max),
                100.0 * estimate.warn_threshold,
            )
        } else if estimate.enabled {
            let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
            format!(
                "error estimate on every point (truncation to H = {}, or {} where contacts \
                 stay stuck or the harmonics decay slowly; sampling at {} samples), warning \
                 above {} %",
                crate::analysis::error_estimate::extended_harmonic(h_max),
                crate::analysis::error_estimate::wider_harmonic(h_max),
                2 * problem.samples,
                100.0 * estimate.warn_threshold,
            )
        } else {
            "error estimate off ([accuracy] estimate = false)".to_string()
        }
    );
    let frf_estimate = problem.analysis.nonlinear_modes.is_none();
    if let Some(refined) =
        crate::analysis::error_estimate::EstimateProblems::new(&problem).filter(|_| frf_estimate)
    {
        let budget = crate::analysis::error_estimate::SolveBudget::new(&problem, &refined);
        let _ = writeln!(
            s,
            "  beyond     the step's linear range: {}",
            budget.summary(estimate.beyond_linear_range)
        );
        for (label, extended) in [("2H + 1", &refined.truncation), ("4H + 3", &refined.wider)] {
            let cost = crate::hbm::cost::estimate(extended);
            let _ = writeln!(
                s,
                "  {label:<10} {}: factorised matrix of {} rows, {}",
                crate::hbm::cost::formulation_name(cost.formulation),
                cost.factored,
                crate::hbm::cost::linear_solver_description(extended, cost.formulation)
            );
        }
    }
    let _ = writeln!(s, "stability    {}", stability_line(&problem));
    let _ = writeln!(
        s,
        "contacts     {} on {} damper side(s)",
        problem.contacts.len(),
        problem.sides.len()
    );
    let laws = contact_laws(&problem);
    let _ = writeln!(s, "  laws       {laws}");
    for c in problem.contacts.iter().take(CHECK_LISTED) {
        let _ = writeln!(
            s,
            "  {:<12} side {:<8} kt {:.3e} N/m  kn {:.3e} N/m  mu {}  gap {:.3e} m  m {}  law {}",
            c.name,
            problem.sides[c.side].name,
            c.law.kt,
            c.law.kn,
            c.law.mu,
            c.gap,
            c.law.initial_state,
            c.friction_law().name()
        );
    }
    more_line(&mut s, problem.contacts.len());
    let statics: Vec<String> = problem
        .static_load
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(i, v)| format!("{} {v} N", problem.model.dof_names[i]))
        .collect();
    let _ = writeln!(
        s,
        "static loads {}",
        if statics.is_empty() {
            "none".into()
        } else if statics.len() > CHECK_LISTED {
            format!(
                "{}, ... ({} DOFs loaded)",
                statics[..CHECK_LISTED].join(", "),
                statics.len()
            )
        } else {
            statics.join(", ")
        }
    );
    for l in problem.harmonic_loads.iter().take(CHECK_LISTED) {
        let _ = writeln!(
            s,
            "harmonic load {} h{}: cos {} N, sin {} N",
            problem.model.dof_names[l.dof], l.harmonic, l.cos, l.sin
        );
    }
    more_line(&mut s, problem.harmonic_loads.len());
    let _ = writeln!(
        s,
        "analysis     {} .. {} Hz, steps {:.3e} (min {:.3e}, max {:.3e}), jacobian {:?}{}",
        a.freq_start_hz,
        a.freq_end_hz,
        a.initial_step,
        a.min_step,
        a.max_step,
        problem.analysis.jacobian,
        mode_range_note(&scene.analysis, &problem)
    );
    let _ = writeln!(
        s,
        "outputs      {}",
        problem
            .outputs
            .iter()
            .map(|&d| problem.model.dof_names[d].as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    if let Some(line) = mode_line(&label, &problem, limits.is_some())? {
        s.push_str(&line);
    }
    if let Some(l) = &limits {
        let cases = if problem.analysis.nonlinear_modes.is_some() {
            crate::analysis::nonlinear_modes::mode_cases(&problem, l)
        } else {
            crate::analysis::limits::two_point_cases(&problem)
                .into_iter()
                .chain(l.intermediate_cases(&problem))
                .collect()
        };
        let cases: Vec<String> = cases.into_iter().map(|c| c.name).collect();
        let _ = writeln!(
            s,
            "limits       curves {}; grid {} points; bound scan {:?}; peak window {}",
            cases.join(", "),
            l.grid_points,
            l.bound_scan,
            l.peak_window_hz
                .map(|(a, b)| format!("{a} .. {b} Hz"))
                .unwrap_or_else(|| "the range".to_string())
        );
    }
    if let Some(sw) = &scene.sweep {
        let mut line = format!(
            "sweep        {} over {} values ({:?} each)",
            sw.parameter,
            sw.values.len(),
            sw.output
        );
        if let Some(series) = &sw.series {
            let _ = write!(
                line,
                ", for each of {} values of {}",
                series.values.len(),
                series.parameter
            );
        }
        let _ = writeln!(s, "{line}");
    }
    s.push_str(&modes::boundary_check_lines(&scene, &label)?);
    Ok(s)
}

/// What `check` says of the stability verdicts: off, or the method and how each of its solves
/// runs at this problem's size, with the dense matrices it holds (Hill's dense eigen solve of
/// the companion matrix up to [`MAX_HILL_UNKNOWNS`](crate::analysis::stability::MAX_HILL_UNKNOWNS)
/// unknowns, the sparse shift-invert solve above it; the monodromy's dense time integration).
fn stability_line(problem: &crate::model::Problem) -> String {
    use crate::analysis::stability_sparse::uses_shift_invert;
    use crate::hbm::cost::format_bytes;
    let analysis = &problem.analysis;
    if !analysis.stability {
        return "off (analysis.stability = false)".to_string();
    }
    let method = analysis.stability_method;
    let n = problem.model.n_dofs();
    let unknowns = n * problem.unknown_harmonics().n_blocks();
    let mut parts = Vec::new();
    if method.uses_hill() {
        parts.push(if uses_shift_invert(analysis.hill_solver, unknowns) {
            format!(
                "Hill by the sparse shift-invert solve of its {unknowns} unknowns (a complex \
                 sparse LU per shift), exponents {}",
                analysis
                    .hill_max_freq_hz
                    .map(|f| format!("up to {f} Hz"))
                    .unwrap_or_else(|| "of every mode".to_string())
            )
        } else {
            let rows = 2 * unknowns;
            format!(
                "Hill by the dense eigen solve of the {rows}-row companion matrix ({} per \
                 dense copy)",
                format_bytes((rows * rows * 8) as f64)
            )
        });
    }
    if method.uses_monodromy() {
        parts.push(format!(
            "the monodromy by a dense time integration of the {n} DOFs ({} per dense matrix, \
             at most {} DOFs){}",
            format_bytes((n * n * 8) as f64),
            crate::analysis::verify::MAX_VERIFY_DOFS,
            if method.uses_hill() {
                " where Hill is not reliable"
            } else {
                ""
            }
        ));
    }
    format!("{}: {}", method.label(), parts.join("; "))
}

/// Most contacts and loads `check` lists one by one (FE scenes have hundreds).
const CHECK_LISTED: usize = 12;

/// Items shown at each end of a long list by [`abbreviated_list`].
const LIST_ENDS: usize = 5;

/// A list as "a, b, c", or for more than [`CHECK_LISTED`] items its first and last
/// [`LIST_ENDS`] around "…" (a scene with 10 000 harmonics or DOFs must not print them all).
pub fn abbreviated_list<T: std::fmt::Display>(items: &[T]) -> String {
    let join = |part: &[T]| {
        part.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if items.len() <= CHECK_LISTED {
        join(items)
    } else {
        format!(
            "{}, …, {}",
            join(&items[..LIST_ENDS]),
            join(&items[items.len() - LIST_ENDS..])
        )
    }
}

/// Which contact laws a problem uses and how each resolves time, e.g. `jenkins-1d × 2
/// (transitions located in continuous time, the samples bracket them)`.
fn contact_laws(problem: &crate::model::Problem) -> String {
    use crate::contact::FrictionLaw;
    [
        FrictionLaw::Jenkins1d,
        FrictionLaw::Jenkins1dSampled,
        FrictionLaw::Jenkins2d,
        FrictionLaw::Jenkins2dSampled,
    ]
    .into_iter()
    .filter_map(|law| {
        let count = problem
            .contacts
            .iter()
            .filter(|c| c.friction_law() == law)
            .count();
        (count > 0).then(|| {
            let how = match law {
                FrictionLaw::Jenkins1d => {
                    "transitions located in continuous time, the samples bracket them"
                }
                FrictionLaw::Jenkins2d => {
                    "transitions located in continuous time, slip direction integrated, the \
                     samples bracket them"
                }
                FrictionLaw::Jenkins1dSampled | FrictionLaw::Jenkins2dSampled => {
                    "marched on the samples"
                }
            };
            format!("{} × {count} ({how})", law.name())
        })
    })
    .collect::<Vec<_>>()
    .join(", ")
}

/// The line after a list cut at [`CHECK_LISTED`] items.
fn more_line(s: &mut String, total: usize) {
    use std::fmt::Write as _;
    if total > CHECK_LISTED {
        let _ = writeln!(s, "  ... and {} more", total - CHECK_LISTED);
    }
}

/// For a nonlinear-mode scene, what its frequency range is: the range of the linear
/// references written beside the mode, given by the scene or derived from the mode's linear
/// frequency (0.5-1.5 times it) where the scene gives neither end. Empty for an FRF scene.
fn mode_range_note(
    analysis: &crate::scene::schema::AnalysisSpec,
    problem: &crate::model::Problem,
) -> String {
    if problem.analysis.nonlinear_modes.is_none() {
        return String::new();
    }
    if analysis.freq_start_hz.is_none() && analysis.freq_end_hz.is_none() {
        format!(
            "; range of the linear references derived: {}-{} times the mode's linear \
             frequency (analysis.freq_start_hz / freq_end_hz not given)",
            crate::scene::MODE_RANGE_START,
            crate::scene::MODE_RANGE_END
        )
    } else {
        "; range of the linear references, as given".to_string()
    }
}

/// The line of a nonlinear-mode scene: the mode, its linear frequency and damping ratio at
/// rest, the amplitude range and DOF; an error when the mode cannot start (no such mode, the
/// DOF at a node of it). None for an FRF scene.
fn mode_line(
    label: &str,
    problem: &crate::model::Problem,
    with_limits: bool,
) -> Result<Option<String>, CommandError> {
    let Some(m) = problem.analysis.nonlinear_modes else {
        return Ok(None);
    };
    let free = crate::analysis::nonlinear_modes::autonomous(problem);
    let start =
        crate::analysis::nonlinear_modes::linear_start(&free, m.mode, m.dof).map_err(|source| {
            CommandError::NonlinearMode {
                scene: label.to_string(),
                source,
            }
        })?;
    Ok(Some(format!(
        "nonlinear mode {} by EPMC (linear at rest: {:.4} Hz, modal damping ratio {:.3e}); amplitude {:e} .. {:e} m at {}; harmonic loads left out{}\n",
        start.number,
        start.omega / std::f64::consts::TAU,
        start.xi / (2.0 * start.omega),
        m.amplitude[0],
        m.amplitude[1],
        problem.model.dof_names[m.dof],
        if with_limits {
            ", one mode per limit case"
        } else {
            ""
        }
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn abbreviates_long_lists() {
        assert_eq!(abbreviated_list(&[0, 1, 2]), "0, 1, 2");
        let long: Vec<usize> = (0..=10_000).collect();
        assert_eq!(
            abbreviated_list(&long),
            "0, 1, 2, 3, 4, …, 9996, 9997, 9998, 9999, 10000"
        );
        let twelve: Vec<usize> = (0..CHECK_LISTED).collect();
        assert_eq!(
            abbreviated_list(&twelve).matches(", ").count(),
            CHECK_LISTED - 1
        );
    }
}
