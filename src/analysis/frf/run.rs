//! The FRF driver: the starting guess, the continuation over the range, and the jump past a
//! fold the path does not come back from, reported to the observer as they come.

use std::f64::consts::PI;
use std::thread::Scope;
use std::time::Instant;

use super::branches::{jump_target, Branching};
use super::observer::{Adapter, FrfObserver, Held};
use super::scale::{adaptive_scale, arc_length_x_scale, output_amplitude_groups};
use super::status::{FrfError, FrfRun, Jump};
use crate::analysis::error_estimate::EstimateProblems;
use crate::analysis::estimate_pool::EstimatePool;
use crate::analysis::linear;
use crate::contact::harmonic::HarmonicSet;
use crate::hbm::operator::HbmOperator;
use crate::model::Problem;
use crate::numerics::path::NoObserver;
use crate::numerics::{Continuation, ContinuationSettings, PathEnd};

/// Most jumps to another branch in one run (see [`solve`]).
const MAX_JUMPS: usize = 8;

/// Solves the nonlinear frequency response of a problem over its analysis range.
///
/// The path is followed from the start frequency to the end frequency. A path that turns back
/// at a fold and leaves the range below the start is not the whole answer: as in a stepped-sine
/// test sweeping up, the response then jumps to another branch. The run solves a point just
/// past the highest frequency reached (see [`jump_target`]) and follows the path on from it, up
/// to [`MAX_JUMPS`] times. The new branch is first followed back down toward the highest
/// frequency reached, to fill the gap (those points come first, in rising frequency). Each jump
/// is reported ([`FrfRun::jumps`], [`FrfObserver::jump`]) with the frequencies its ends
/// reached: the stretch between them was not computed on any branch (empty when the fill got
/// back to the highest frequency).
///
/// The points' error estimates (when the scene asks for them) are formed on worker threads
/// while the path goes on ([`crate::analysis::estimate_pool`]); the observer still receives
/// every event in the order of the run, each point with its estimate.
pub fn solve<O: FrfObserver>(problem: &Problem, observer: &mut O) -> Result<FrfRun, FrfError> {
    let started = Instant::now();
    let refined = EstimateProblems::new(problem);
    std::thread::scope(|scope| solve_in(scope, problem, refined.as_ref(), observer, started))
}

/// [`solve`], its estimates' workers (if any) scoped to `scope`.
fn solve_in<'scope, 'p, O: FrfObserver>(
    scope: &'scope Scope<'scope, 'p>,
    problem: &'p Problem,
    refined: Option<&'p EstimateProblems>,
    observer: &mut O,
    started: Instant,
) -> Result<FrfRun, FrfError> {
    let mut system = HbmOperator::new(problem)?;
    let set = system.unknowns().clone();
    let settings = problem.analysis.continuation;
    let omega0 = 2.0 * PI * settings.freq_start_hz;
    let mut branching = Branching {
        settings,
        x_scale: arc_length_x_scale(problem, &set, &system)?,
        adaptive: adaptive_scale(problem, &set, &system),
        amplitude_groups: output_amplitude_groups(problem, &set, &system),
    };
    let mut guess = start_guess(problem, &set, &mut system, &branching.x_scale, omega0)?;
    let pool = refined
        .map(|r| EstimatePool::start(scope, problem, r, EstimatePool::default_workers()))
        .transpose()?;
    let mut adapter = Adapter::new(observer, pool.as_ref(), true);
    let mut run = FrfRun {
        points: Vec::new(),
        turning_points: Vec::new(),
        rejected_steps: 0,
        jumps: Vec::new(),
        end: PathEnd::MaxPoints,
        elapsed_s: 0.0,
    };
    let mut start_hz = settings.freq_start_hz;
    loop {
        let remaining = settings.max_points.saturating_sub(adapter.points.len());
        let mut continuation = branching.continuation(start_hz, settings.freq_end_hz, remaining);
        let outcome = continuation.run(&mut system, &guess, &mut adapter);
        // The next branch starts with the scale this one grew to.
        branching.x_scale.clone_from(&continuation.x_scale);
        if let Some(e) = adapter.failure.take() {
            return Err(FrfError::Setup(e));
        }
        let summary = outcome.map_err(|e| FrfError::from_continuation(e, problem))?;
        run.turning_points.extend(summary.turning_points);
        run.rejected_steps += summary.rejected_steps;
        run.end = summary.end;
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        if run.end != PathEnd::LeftRangeBelow || run.jumps.len() >= MAX_JUMPS || budget < 2 {
            break;
        }
        let highest = adapter
            .points
            .iter()
            .map(|p| p.freq_hz)
            .fold(f64::NEG_INFINITY, f64::max);
        let Some((freq_hz, x)) = jump_target(
            problem,
            &set,
            &mut system,
            &continuation,
            &adapter.points,
            highest,
        )?
        else {
            break;
        };
        // Fill the gap on the new branch, back down toward the highest frequency reached, and
        // report those points first (in rising frequency) so that the path reads on from the
        // jump. The fill's first point (at the jump target) is solved again by the branch's
        // own run.
        let (mut fill, fill_summary) = branching.follow(
            &mut system,
            &x,
            freq_hz,
            highest,
            budget / 2,
            adapter.estimates,
        );
        if let Some(s) = &fill_summary {
            for &f in &s.turning_points {
                run.turning_points.push(f);
                adapter.report(Held::TurningPoint(f));
            }
            run.rejected_steps += s.rejected_steps;
        }
        fill.reverse();
        fill.pop();
        let lowest = fill.first().map_or(freq_hz, |p| p.freq_hz.min(freq_hz));
        let jump = Jump {
            from_hz: highest,
            to_hz: lowest,
            first_point: adapter.points.len(),
        };
        adapter.report(Held::Jump(jump));
        run.jumps.push(jump);
        for p in fill {
            adapter.push_point(p);
        }
        start_hz = freq_hz;
        guess = x;
    }
    run.points = adapter.take_points();
    run.elapsed_s = started.elapsed().as_secs_f64();
    Ok(run)
}

/// The starting guess at ω0 (rad/s): the stuck linear solution, or where Newton does not converge
/// from it (a low pre-load: the contacts open for most of the period) the solution converged from
/// the open-contact guess ([`linear::open_guess`]), else from either on the static state with the
/// contacts ([`contact_statics`]), else the end of a short continuation onto ω0 from a point solved
/// a little off it ([`START_OFFSETS`]). When none converges the stuck guess is returned and the run
/// reports its failure at the start.
fn start_guess(
    problem: &Problem,
    set: &HarmonicSet,
    system: &mut HbmOperator<'_>,
    x_scale: &[f64],
    omega0: f64,
) -> Result<Vec<f64>, FrfError> {
    let stuck = system.restrict(&linear::stuck_guess(problem, set, omega0)?);
    let newton = Continuation::new(problem.analysis.continuation, x_scale.to_vec());
    if newton.solve_fixed(system, &stuck, omega0).is_ok() {
        return Ok(stuck);
    }
    let open = system.restrict(&linear::open_guess(problem, set, omega0)?);
    if let Ok(p) = newton.solve_fixed(system, &open, omega0) {
        return Ok(p.x);
    }
    // Contacts open at rest (gaps the pre-load must close): the linear guesses leave the
    // damper where it hangs free. Solve the statics with the contacts first, then the linear
    // harmonics on that static state.
    if let Some(statics) = contact_statics(problem, set)? {
        for dynamic in [
            linear::stuck_guess(problem, set, omega0)?,
            linear::open_guess(problem, set, omega0)?,
        ] {
            let n = problem.model.n_dofs();
            let mut guess = dynamic;
            if let Some(j) = set.constant_block() {
                guess[j * n..(j + 1) * n].copy_from_slice(&statics);
            }
            let guess = system.restrict(&guess);
            if let Ok(p) = newton.solve_fixed(system, &guess, omega0) {
                return Ok(p.x);
            }
        }
    }
    // On (or next to) a resonance of the stuck structure the stuck guess is near-singular:
    // start a little off it, where the guess is sound, and follow the path onto ω0 (from
    // below, then from above).
    for offset in START_OFFSETS {
        for sign in [-1.0, 1.0] {
            let f0 = omega0 / (2.0 * PI);
            let from_hz = f0 * (1.0 + sign * offset);
            let near = system.restrict(&linear::stuck_guess(problem, set, 2.0 * PI * from_hz)?);
            let settings = ContinuationSettings {
                freq_start_hz: from_hz,
                freq_end_hz: f0,
                max_points: START_APPROACH_POINTS,
                ..problem.analysis.continuation
            };
            let mut approach = Continuation::new(settings, x_scale.to_vec());
            if let Ok(summary) = approach.run(system, &near, &mut NoObserver) {
                if summary.end == PathEnd::EndFrequency {
                    if let Some(p) = summary.points.last() {
                        return Ok(p.x.clone());
                    }
                }
            }
        }
    }
    Ok(stuck)
}

/// The static state with the contacts (m), when the unknowns include the 0th harmonic: the
/// harmonic balance of the 0th harmonic alone (normal springs with lift-off, and the
/// tangential force m μ N of each contact's initial state, since nothing moves), solved by
/// Newton from the sliding static state ([`linear::sliding_static`]), else from the stuck
/// static guess. None when neither converges.
fn contact_statics(problem: &Problem, set: &HarmonicSet) -> Result<Option<Vec<f64>>, FrfError> {
    if !set.has_constant() {
        return Ok(None);
    }
    let mut statics = problem.clone();
    statics.harmonics = Vec::new();
    let static_set = HarmonicSet::new(vec![0]);
    let mut system = HbmOperator::new(&statics)?;
    let mut guesses = Vec::new();
    if let Ok(q) = linear::sliding_static(&statics) {
        guesses.push(system.restrict(&q));
    }
    guesses.push(system.restrict(&linear::stuck_guess(&statics, &static_set, 0.0)?));
    let scale = vec![1.0; guesses[0].len()];
    let newton = Continuation::new(statics.analysis.continuation, scale);
    let omega = 2.0 * PI * statics.analysis.continuation.freq_start_hz;
    for guess in guesses {
        if let Ok(p) = newton.solve_fixed(&mut system, &guess, omega) {
            return Ok(Some(system.expand(&p.x, omega)?));
        }
    }
    Ok(None)
}

/// Relative frequency offsets at which a start on a resonance of the stuck structure is first
/// solved (see [`start_guess`]).
const START_OFFSETS: &[f64] = &[1e-2, 5e-2];

/// Point budget of the approach onto the start frequency (see [`start_guess`]).
const START_APPROACH_POINTS: usize = 200;
