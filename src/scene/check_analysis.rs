//! Validation of what is solved and reported: the `[analysis]` table (frequency range,
//! continuation steps and limits, tolerances, Jacobian and formulation) built into the
//! problem's [`Analysis`] settings, the frequency range bounded by what the model resolves,
//! and the `[output]` table into the response DOFs.

use crate::analysis::stability::{harmonics_supported, MAX_HILL_UNKNOWNS};
use crate::analysis::stability_sparse::{uses_shift_invert, MAX_ESTIMATE_DOFS};
use crate::analysis::verify::{MAX_MONODROMY_STEPS, MAX_VERIFY_DOFS, MIN_MONODROMY_STEPS};
use crate::contact::{ContactPoint, NormalLoad};
use crate::model::HillSolve;
use crate::model::{
    Analysis, Coupling, ErrorEstimateSettings, LinearModel, Problem, CHORD_MIN_UNKNOWNS,
};
use crate::numerics::ContinuationSettings;
use crate::scene::check_model::diagonal;
use crate::scene::checker::{Checker, DofNames};
use crate::scene::error::SceneError;
use crate::scene::fe_input::FeStructure;
use crate::scene::schema::{AccuracySpec, AnalysisKind, AnalysisSpec, OutputSpec};

/// Most continuation points or linear-reference points a scene may ask for.
pub const MAX_POINTS: usize = 10_000_000;

/// Largest ratio of the inertia (2π·f·h)²·Mᵢᵢ at the end frequency f and the highest balanced
/// harmonic h to the stiffness K̃ᵢᵢ (contact springs stuck included) of every DOF i that a scene
/// may ask for: above it every DOF's stiffness and the contact forces are lost in round-off
/// next to its inertia, and the response is that of free masses.
pub const MAX_INERTIA_RATIO: f64 = 1e12;

/// Checks that the end frequency `analysis.freq_end_hz` (Hz, as given: checked before the
/// rest of `[analysis]` so that an absurd frequency is explained by the model) lies below the
/// highest frequency the model resolves at the highest balanced harmonic h:
/// (2π·f·h)² ≤ [`MAX_INERTIA_RATIO`]·maxᵢ K̃ᵢᵢ/Mᵢᵢ over the DOFs with mass, K̃ the stiffness
/// with every contact stuck (K plus kₜ t tᵀ + kₙ n nᵀ per point). Each ratio K̃ᵢᵢ/Mᵢᵢ is a
/// Rayleigh quotient, so √(maxᵢ K̃ᵢᵢ/Mᵢᵢ)/2π is at or below the highest natural frequency of
/// the stuck structure, and the bound is 10⁶ times it divided by h. A massless model sets no
/// bound; a non-finite value is left to [`analysis`].
pub(super) fn frequency_bound(
    analysis: &AnalysisSpec,
    harmonics: &[usize],
    model: &LinearModel,
    contacts: &[ContactPoint],
    ck: &Checker,
) -> Result<(), SceneError> {
    let mut k = diagonal(&model.stiffness);
    for c in contacts {
        let tangential = c.tangential_rows().map(|row| (row, c.law.kt));
        for (row, stiffness) in tangential.chain([(c.normal.as_slice(), c.law.kn)]) {
            for &(d, a) in row {
                k[d] += stiffness * a * a;
            }
        }
    }
    let m = diagonal(&model.mass);
    let ratio = k
        .iter()
        .zip(&m)
        .filter(|(_, &mi)| mi > 0.0)
        .map(|(ki, mi)| ki / mi)
        .fold(0.0_f64, f64::max);
    if ratio <= 0.0 {
        return Ok(());
    }
    let h = harmonics.iter().copied().max().unwrap_or(1).max(1) as f64;
    let two_pi = 2.0 * std::f64::consts::PI;
    let natural = ratio.sqrt() / two_pi;
    let limit = (MAX_INERTIA_RATIO * ratio).sqrt() / (two_pi * h);
    let Some(f1) = analysis.freq_end_hz else {
        return Ok(());
    };
    if f1.is_finite() && f1 > limit {
        return Err(ck.err(
            "analysis.freq_end_hz",
            format!(
                "{f1:e} Hz is above {limit:.4e} Hz, the highest frequency this model resolves: \
                 at harmonic {h} the inertia (2π·f·h)²·Mᵢᵢ of every DOF would exceed its \
                 stiffness Kᵢᵢ (contacts stuck) by more than {MAX_INERTIA_RATIO:e}, so K and the \
                 contact forces are lost in round-off (the stiffest DOF for its mass has \
                 √(Kᵢᵢ/Mᵢᵢ)/2π = {natural:.4e} Hz; the bound is {:e} times that over h)",
                MAX_INERTIA_RATIO.sqrt()
            ),
        ));
    }
    Ok(())
}

/// Fraction of the chosen mode's linear frequency (contacts stuck) at which the linear
/// references of a nonlinear-mode scene start when `analysis.freq_start_hz` is not given.
pub const MODE_RANGE_START: f64 = 0.5;
/// Multiple of the chosen mode's linear frequency at which they end when
/// `analysis.freq_end_hz` is not given.
pub const MODE_RANGE_END: f64 = 1.5;

/// The frequency range (Hz) of the `[analysis]` table: both ends as given, or None for a
/// nonlinear-mode scene that gives neither (the range then follows from the mode, see
/// [`set_range`]); an error for a missing end otherwise.
fn given_range(a: &AnalysisSpec, ck: &Checker) -> Result<Option<(f64, f64)>, SceneError> {
    match (a.freq_start_hz, a.freq_end_hz) {
        (Some(f0), Some(f1)) => Ok(Some((f0, f1))),
        (None, None) if a.kind == AnalysisKind::NonlinearModes => Ok(None),
        (None, _) => Err(ck.err(
            "analysis.freq_start_hz",
            "missing: give the start of the frequency range (Hz)",
        )),
        (Some(_), None) => Err(ck.err(
            "analysis.freq_end_hz",
            "missing: give the end of the frequency range (Hz)",
        )),
    }
}

/// Sets the frequency range `f0 .. f1` (Hz) of `settings` and the arc-length steps not given
/// in `a` (defaults from the range: initial range/200, min range·1e-7, max range/50).
pub(super) fn set_range(
    settings: &mut ContinuationSettings,
    a: &AnalysisSpec,
    ck: &Checker,
    (f0, f1): (f64, f64),
) -> Result<(), SceneError> {
    let f0 = ck.positive("analysis.freq_start_hz", f0)?;
    let f1 = ck.finite("analysis.freq_end_hz", f1)?;
    if f1 <= f0 {
        return Err(ck.err(
            "analysis.freq_end_hz",
            format!("the range is reversed or empty: end {f1} Hz ≤ start {f0} Hz"),
        ));
    }
    let range = f1 - f0;
    let initial_step = ck.positive(
        "analysis.initial_step",
        a.initial_step.unwrap_or(range / 200.0),
    )?;
    let min_step = ck.positive("analysis.min_step", a.min_step.unwrap_or(range * 1e-7))?;
    let max_step = ck.positive("analysis.max_step", a.max_step.unwrap_or(range / 50.0))?;
    if min_step > max_step {
        return Err(ck.err(
            "analysis.min_step",
            format!("{min_step} exceeds max_step {max_step}"),
        ));
    }
    settings.freq_start_hz = f0;
    settings.freq_end_hz = f1;
    settings.initial_step = initial_step;
    settings.min_step = min_step;
    settings.max_step = max_step;
    Ok(())
}

/// The analysis settings of the `[analysis]` table: the frequency range (Hz), the arc-length
/// steps (defaults from the range), iteration counts and tolerances. A nonlinear-mode scene
/// without a range gets the provisional range 1 .. 2 Hz here, replaced by [`set_range`] once
/// the mode's linear frequency is known.
pub(super) fn analysis(a: &AnalysisSpec, ck: &Checker) -> Result<Analysis, SceneError> {
    let range = given_range(a, ck)?.unwrap_or((1.0, 2.0));
    let mut continuation = ContinuationSettings {
        freq_start_hz: range.0,
        freq_end_hz: range.1,
        initial_step: 0.0,
        min_step: 0.0,
        max_step: 0.0,
        max_points: a.max_points,
        target_iterations: a.target_iterations,
        max_iterations: a.max_iterations,
        residual_tolerance: a.residual_tolerance,
        step_tolerance: a.step_tolerance,
        chord_min_unknowns: CHORD_MIN_UNKNOWNS,
    };
    set_range(&mut continuation, a, ck, range)?;
    for (field, v) in [
        ("analysis.max_points", a.max_points),
        ("analysis.target_iterations", a.target_iterations),
        ("analysis.max_iterations", a.max_iterations),
        ("analysis.linear_points", a.linear_points),
    ] {
        if v == 0 {
            return Err(ck.err(field, "must be ≥ 1"));
        }
    }
    if a.linear_points < 2 {
        return Err(ck.err("analysis.linear_points", "must be ≥ 2"));
    }
    for (field, v) in [
        ("analysis.max_points", a.max_points),
        ("analysis.linear_points", a.linear_points),
    ] {
        if v > MAX_POINTS {
            return Err(ck.err(field, format!("must be ≤ {MAX_POINTS}, got {v}")));
        }
    }
    if a.stability_method.is_some() && !a.stability {
        return Err(ck.err(
            "analysis.stability_method",
            "chooses how stability is computed, but analysis.stability is off: set analysis.stability = true",
        ));
    }
    if a.hill_solver.is_some() && !a.stability_method.unwrap_or_default().uses_hill() {
        return Err(ck.err(
            "analysis.hill_solver",
            "chooses how Hill's eigenvalue problem is solved, but Hill's method does not run: set analysis.stability = true with analysis.stability_method = \"hill\" or \"hill+monodromy\"",
        ));
    }
    if a.hill_solver.is_some() && !a.stability {
        return Err(ck.err(
            "analysis.hill_solver",
            "chooses how Hill's eigenvalue problem is solved, but analysis.stability is off: set analysis.stability = true",
        ));
    }
    if let Some(f) = a.hill_max_freq_hz {
        let field = "analysis.hill_max_freq_hz";
        ck.finite(field, f)?;
        if f <= 0.0 {
            return Err(ck.err(field, format!("must be positive (Hz), got {f}")));
        }
        if !a.stability || !a.stability_method.unwrap_or_default().uses_hill() {
            return Err(ck.err(
                field,
                "limits the shift-invert Hill solve, but Hill's method does not run: set analysis.stability = true with analysis.stability_method = \"hill\" or \"hill+monodromy\"",
            ));
        }
        if a.hill_solver == Some(HillSolve::Dense) {
            return Err(ck.err(
                field,
                "limits the shift-invert Hill solve, but analysis.hill_solver = \"dense\" solves the whole spectrum: use \"auto\" or \"shift-invert\"",
            ));
        }
    }
    if let Some(steps) = a.monodromy_steps_per_period {
        if !a.stability_method.is_some_and(|m| m.uses_monodromy()) {
            return Err(ck.err(
                "analysis.monodromy_steps_per_period",
                "is used only by the monodromy: set analysis.stability_method = \"monodromy\" or \"hill+monodromy\"",
            ));
        }
        if !(MIN_MONODROMY_STEPS..=MAX_MONODROMY_STEPS).contains(&steps) {
            return Err(ck.err(
                "analysis.monodromy_steps_per_period",
                format!(
                    "must be between {MIN_MONODROMY_STEPS} and {MAX_MONODROMY_STEPS}, got {steps}"
                ),
            ));
        }
    }
    let residual_tolerance = ck.positive("analysis.residual_tolerance", a.residual_tolerance)?;
    let step_tolerance = ck.positive("analysis.step_tolerance", a.step_tolerance)?;
    continuation.residual_tolerance = residual_tolerance;
    continuation.step_tolerance = step_tolerance;
    Ok(Analysis {
        continuation,
        jacobian: a.jacobian,
        formulation: a.formulation,
        linear_points: a.linear_points,
        stability: a.stability,
        stability_method: a.stability_method.unwrap_or_default(),
        monodromy_steps_per_period: a.monodromy_steps_per_period.unwrap_or(0),
        hill_solver: a.hill_solver.unwrap_or_default(),
        hill_max_freq_hz: a.hill_max_freq_hz,
        error_estimate: ErrorEstimateSettings::default(),
        nonlinear_modes: None,
    })
}

/// The `[accuracy]` table into the error-estimate settings: the threshold must lie in (0, 1].
pub(super) fn error_estimate(
    spec: &AccuracySpec,
    ck: &Checker,
) -> Result<ErrorEstimateSettings, SceneError> {
    let threshold = ck.positive("accuracy.threshold", spec.threshold)?;
    if threshold > 1.0 {
        return Err(ck.err(
            "accuracy.threshold",
            format!("is a relative error and must be ≤ 1, got {threshold}"),
        ));
    }
    Ok(ErrorEstimateSettings {
        enabled: spec.estimate,
        warn_threshold: threshold,
        beyond_linear_range: spec.beyond_linear_range,
    })
}

/// With `analysis.stability` on: Hill's method needs the 0th harmonic among the unknowns
/// (a coupled scene) and the harmonics 0..H without gaps; its dense eigen solve
/// (`analysis.hill_solver = "dense"`) at most [`MAX_HILL_UNKNOWNS`] unknowns (DOFs ×
/// coefficient blocks, after any reduction), its shift-invert solve (`"auto"` above that
/// size, or `"shift-invert"`) at most [`MAX_ESTIMATE_DOFS`] DOFs.
///
/// With a method that uses the monodromy (`analysis.stability_method`): the time integration
/// needs variable normal load and a dense model of at most [`MAX_VERIFY_DOFS`] DOFs; the
/// Hill size limit applies only where Hill's method runs.
pub(super) fn check_stability(ck: &Checker, problem: &Problem) -> Result<(), SceneError> {
    if !problem.analysis.stability {
        return Ok(());
    }
    let method = problem.analysis.stability_method;
    let field = "analysis.stability";
    if problem.effects.coupling != Coupling::Coupled {
        return Err(ck.err(
            field,
            "Hill stability and the monodromy need the 0th harmonic among the unknowns: set effects.coupling = \"coupled\"",
        ));
    }
    if method.uses_monodromy() {
        let field = "analysis.stability_method";
        if problem.effects.contact.normal_load == NormalLoad::Constant
            && !problem.contacts.is_empty()
        {
            return Err(ck.err(
                field,
                "the monodromy integrates the equations of motion in time, where a constant normal load has no meaning: set effects.normal_load = \"variable\" or use \"hill\"",
            ));
        }
        if problem.model.n_dofs() > MAX_VERIFY_DOFS {
            return Err(ck.err(
                field,
                format!(
                    "the monodromy's dense time integration is for lumped or reduced models of at most {MAX_VERIFY_DOFS} DOFs, this one has {}",
                    problem.model.n_dofs()
                ),
            ));
        }
    }
    let set = problem.unknown_harmonics();
    if !harmonics_supported(&set) {
        return Err(ck.err(
            field,
            format!(
                "Hill stability needs the harmonics 0, 1, …, H without gaps (harmonics.max), got {:?}",
                set.harmonics()
            ),
        ));
    }
    let unknowns = problem.model.n_dofs() * set.n_blocks();
    let solver = problem.analysis.hill_solver;
    if method.uses_hill() && solver == HillSolve::Dense && unknowns > MAX_HILL_UNKNOWNS {
        return Err(ck.err(
            "analysis.hill_solver",
            format!(
                "{unknowns} harmonic-balance unknowns ({} DOFs × {} blocks) exceed the {MAX_HILL_UNKNOWNS} of the dense Hill eigen solve: use \"auto\" or \"shift-invert\", lower harmonics.max, or reduce the model",
                problem.model.n_dofs(),
                set.n_blocks()
            ),
        ));
    }
    if method.uses_hill()
        && uses_shift_invert(solver, unknowns)
        && problem.model.n_dofs() > MAX_ESTIMATE_DOFS
    {
        return Err(ck.err(
            field,
            format!(
                "the shift-invert Hill solve places its shifts by a dense eigen solve of the {} DOFs, above its {MAX_ESTIMATE_DOFS}: reduce the model (Craig-Bampton) or turn stability off",
                problem.model.n_dofs()
            ),
        ));
    }
    Ok(())
}

/// The response DOFs of the `[output]` table: the named DOFs, then every node of each group
/// in its direction.
pub(super) fn outputs(
    output: &OutputSpec,
    ck: &Checker,
    dofs: &DofNames,
    fe: Option<&FeStructure>,
) -> Result<Vec<usize>, SceneError> {
    if output.dofs.is_empty() && output.groups.is_empty() {
        return Err(ck.err("output.dofs", "name at least one response DOF"));
    }
    let mut outputs = output
        .dofs
        .iter()
        .enumerate()
        .map(|(i, d)| ck.dof(&format!("output.dofs[{i}]"), d, dofs))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, g) in output.groups.iter().enumerate() {
        let field = format!("output.groups[{i}]");
        let targets =
            ck.load_targets(&field, None, Some(&g.group), Some(&g.direction), dofs, fe)?;
        outputs.extend(targets.into_iter().map(|(d, _)| d));
    }
    Ok(outputs)
}
