//! The FRF driver: the starting guess, the continuation over the range, jumps past folds the
//! path does not come back from, and the judgements, reported to the observer as they come.

use std::collections::VecDeque;
use std::f64::consts::PI;
use std::thread::Scope;
use std::time::Instant;

use super::branches::{forward_leaps, jump_target, reversed_leaps, Branching};
use super::cuts::{branch_end, bridge_cuts, fill_cut};
use super::judge::{judge_cuts, judge_leaps};
use super::observer::{Adapter, FrfObserver, Held};
use super::scale::{adaptive_scale, arc_length_x_scale, output_amplitude_groups};
use super::status::{BranchEnd, FrfError, FrfPoint, FrfRun, GivenUp, Jump, JumpKind};
use crate::analysis::error_estimate::EstimateProblems;
use crate::analysis::estimate_pool::EstimatePool;
use crate::analysis::linear;
use crate::contact::harmonic::HarmonicSet;
use crate::hbm::operator::HbmOperator;
use crate::model::Problem;
use crate::numerics::path::NoObserver;
use crate::numerics::{Continuation, ContinuationSettings, PathEnd};

/// Point budget of the fill of a branch back toward the fold (see [`solve`]).
const FILL_POINTS: usize = 500;

/// Most jumps to another branch in one run (see [`solve`]).
const MAX_JUMPS: usize = 8;

/// Solves the nonlinear frequency response of a problem over its analysis range.
///
/// The path is followed from the start frequency. A path that turns back at a fold and does not
/// come back toward the end (it leaves the range below the start, or wanders without reaching
/// a higher frequency) is not the whole answer: as in a stepped-sine test sweeping
/// up, the response then jumps to another branch. The run solves a point just past the highest
/// frequency reached (see [`jump_target`]) and
/// follows the path on from it, up to [`MAX_JUMPS`] times. The new branch is first followed
/// back down toward the highest frequency reached, to fill the gap (those points come first,
/// in rising frequency). Each jump is reported ([`FrfRun::jumps`], [`FrfObserver::jump`]) with
/// the frequencies its ends reached: the stretch between them was not computed on any branch
/// (empty when the fill got back to the highest frequency).
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
    let mut x_scale = arc_length_x_scale(problem, &set, &system)?;
    let mut guess = start_guess(problem, &set, &mut system, &x_scale, omega0)?;
    // How the scale grows and which amplitudes the steps follow: the same on every branch.
    let adaptive = adaptive_scale(problem, &set, &system);
    let amplitude_groups = output_amplitude_groups(problem, &set, &system);
    let pool = refined
        .map(|r| EstimatePool::start(scope, problem, r, EstimatePool::default_workers()))
        .transpose()?;
    let mut adapter = Adapter {
        observer,
        points: Vec::new(),
        failure: None,
        estimates: pool.as_ref(),
        in_order: true,
        held: VecDeque::new(),
    };
    let mut run = FrfRun {
        points: Vec::new(),
        turning_points: Vec::new(),
        rejected_steps: 0,
        leaps: Vec::new(),
        leap_points: Vec::new(),
        leap_checks: Vec::new(),
        jumps: Vec::new(),
        end: PathEnd::MaxPoints,
        elapsed_s: 0.0,
    };
    let mut start_hz = settings.freq_start_hz;
    loop {
        let segment_start = adapter.points.len();
        let segment_fold: Option<f64>;
        let segment = ContinuationSettings {
            freq_start_hz: start_hz,
            max_points: settings.max_points.saturating_sub(adapter.points.len()),
            ..settings
        };
        let mut continuation = Continuation::new(segment, x_scale.clone())
            .with_adaptive_scale(adaptive.clone())
            .with_amplitude_steps(amplitude_groups.clone());
        // Where this branch's points go in the report (one per point of its path).
        let offset = adapter.points.len();
        let outcome = continuation.run(&mut system, &guess, &mut adapter);
        // The next branch starts with the scale this one grew to.
        x_scale.clone_from(&continuation.x_scale);
        if let Some(e) = adapter.failure.take() {
            return Err(FrfError::Setup(e));
        }
        match outcome {
            Ok(summary) => {
                segment_fold = summary.turning_points.last().copied();
                run.turning_points.extend(summary.turning_points);
                run.rejected_steps += summary.rejected_steps;
                run.leaps.extend(summary.leaps);
                run.leap_points
                    .extend(forward_leaps(&summary.leap_landings, 0, offset));
                run.end = summary.end;
            }
            // A stall is not a fold: the path goes on past it, but could not be followed. (A
            // spot past which only the way back was found ends the summary as
            // `PathEnd::DeadEnd` and is jumped past below.)
            Err(e) => return Err(e.into()),
        }
        let turned_back = matches!(
            run.end,
            PathEnd::LeftRangeBelow | PathEnd::NoProgress | PathEnd::DeadEnd
        );
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        let past_folds = run
            .jumps
            .iter()
            .filter(|j| matches!(j.kind, JumpKind::PastFold | JumpKind::PastDeadEnd))
            .count();
        if !turned_back || past_folds >= MAX_JUMPS || budget < 2 {
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
        let branching = Branching {
            settings,
            x_scale: &x_scale,
            adaptive: &adaptive,
            amplitude_groups: &amplitude_groups,
        };
        // Fill the gap on the new branch, back down toward the highest frequency reached, and
        // report those points first (in rising frequency) so that the path reads on from the
        // jump. The fill's first point (at the jump target) is solved again by the branch's
        // own run.
        let budget = settings.max_points.saturating_sub(adapter.points.len());
        let (mut fill, summary) = branching.follow(
            &mut system,
            &x,
            freq_hz,
            highest,
            (budget / 2).min(FILL_POINTS),
            adapter.estimates,
        );
        let cut = summary.as_ref().and_then(|summary| {
            fill_cut(
                &adapter.points,
                &run.branch_starts(),
                &fill,
                true,
                summary.end,
                summary.turning_points.last().copied(),
            )
        });
        // A stretch neither branch reached: solve branches inside it, between the highest
        // point before the jump and the lowest point of the new branch.
        let top = adapter
            .points
            .iter()
            .rev()
            .find(|p| p.freq_hz == highest)
            .cloned();
        let bottom = fill
            .iter()
            .min_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz))
            .cloned();
        // The fill as followed, from the jump target: a branch given up at the point where
        // the fill ends (its end frequency) lies on the fill's segment into the jump target.
        let followed_fill = fill.clone();
        fill.reverse();
        fill.pop();
        let bridges = match (top, bottom) {
            (Some(top), Some(bottom)) if bottom.freq_hz > highest => {
                let budget = settings
                    .max_points
                    .saturating_sub(adapter.points.len() + fill.len())
                    / 2;
                branching.bridge(
                    &mut system,
                    &top,
                    &bottom,
                    budget,
                    adapter.estimates,
                    (&adapter.points, &run.branch_starts()),
                )
            }
            _ => Vec::new(),
        };
        // What the bridges and the fill met, in the order they are reported (bridges first);
        // their turning points and leaps go to the observer too (`solution.json` lists them),
        // its leaps in the order of `run.leaps`, which the leaps' judgements follow.
        // The fill's leaps as placed in its report: followed down from the jump target and
        // reported in reverse without that first point, which the next branch solves again
        // and reports right after the fill.
        let fill_leaps = summary.as_ref().map_or(Vec::new(), |s| {
            reversed_leaps(&s.leap_landings, followed_fill.len())
        });
        let met = bridges
            .iter()
            .map(|b| {
                (
                    &b.turning_points,
                    b.rejected_steps,
                    &b.leaps,
                    &b.leap_points,
                    b.points.len(),
                )
            })
            .chain(summary.as_ref().map(|s| {
                (
                    &s.turning_points,
                    s.rejected_steps,
                    &s.leaps,
                    &fill_leaps,
                    fill.len(),
                )
            }));
        let mut offset = adapter.points.len();
        for (turning_points, rejected_steps, leaps, places, length) in met {
            for &freq_hz in turning_points {
                run.turning_points.push(freq_hz);
                adapter.report(Held::TurningPoint(freq_hz));
            }
            run.rejected_steps += rejected_steps;
            for (&(from_hz, to_hz), place) in leaps.iter().zip(places) {
                run.leaps.push((from_hz, to_hz));
                run.leap_points
                    .push(place.map(|(before, landing)| (offset + before, offset + landing)));
                adapter.report(Held::Leap(from_hz, to_hz));
            }
            offset += length;
        }
        // How the branch before ended, now that the branches solved past it are known (a
        // branch given up whose last point one of them passes through abandoned nothing).
        let later: Vec<&[FrfPoint]> = bridges
            .iter()
            .map(|b| b.points.as_slice())
            .chain([followed_fill.as_slice()])
            .collect();
        let branch_end = branch_end(
            &adapter.points,
            &run.branch_starts(),
            segment_start,
            segment_fold,
            run.end,
            &later,
            settings.freq_start_hz,
        );
        let mut reached = highest;
        let mut kind = if run.end == PathEnd::DeadEnd {
            JumpKind::PastDeadEnd
        } else {
            JumpKind::PastFold
        };
        let mut before = branch_end;
        // A bridge's cuts: its way down's, then its way up's.
        let cuts: Vec<[Option<GivenUp>; 2]> = bridges
            .iter()
            .map(|b| b.cuts)
            .chain([[cut, None]])
            .collect();
        let branches = bridges.into_iter().map(|b| b.points).chain([fill]);
        for (branch, cuts) in branches.zip(cuts) {
            let (cut, second_cut) = bridge_cuts(cuts);
            let lowest = branch
                .iter()
                .map(|p| p.freq_hz)
                .fold(f64::INFINITY, f64::min);
            let jump = Jump {
                from_hz: reached,
                // A fill that solved nothing below the jump target starts there.
                to_hz: if lowest.is_finite() { lowest } else { freq_hz },
                first_point: adapter.points.len(),
                kind,
                before,
                fill_cut: cut,
                cut_check: None,
                second_cut,
                second_cut_check: None,
                end_check: None,
            };
            adapter.report(Held::Jump(Box::new(jump)));
            run.jumps.push(jump);
            for mut p in branch {
                reached = reached.max(p.freq_hz);
                // Points followed on a branch have their estimate (across the path) already,
                // or pending; the others (solved at a fixed frequency) take it at their
                // frequency.
                if p.accuracy.is_none() && p.pending_estimate.is_none() {
                    let omega = 2.0 * PI * p.freq_hz;
                    adapter.estimate(&mut p, omega, None);
                }
                adapter.push_point(p);
            }
            kind = JumpKind::Bridge;
            before = BranchEnd::Bridge;
        }
        start_hz = freq_hz;
        guess = x;
    }
    run.points = adapter.take_points();
    // Every branch is known now: judge the cuts of the fills and bridges against all of them.
    let newton = Continuation::new(settings, x_scale.clone());
    judge_cuts(&mut system, &newton, &mut run, &mut *adapter.observer);
    let branching = Branching {
        settings,
        x_scale: &x_scale,
        adaptive: &adaptive,
        amplitude_groups: &amplitude_groups,
    };
    judge_leaps(
        &mut system,
        &newton,
        &branching,
        &mut run,
        &mut *adapter.observer,
    );
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
