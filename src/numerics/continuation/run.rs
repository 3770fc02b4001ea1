//! The path, step by step: predict, correct, accept or cut the step, and on a stall go past the
//! spot or end the path, until the end frequency, a range end or a dead end.

use super::events::{frequency_reversals, VisitedGround, RETRACE_HISTORY};
use super::predictor::{MAX_TURN_DEGREES, TARGET_LOG_AMPLITUDE_CHANGE, TARGET_TURN_DEGREES};
use super::recovery::{MAX_NARROW_PASSES, NARROW_WINDOW_FRACTIONS};
use super::settings::{Continuation, OMEGA_SCALE};
use super::step::{report, HeldBack, ObserverCall};
use crate::numerics::path::{ContinuationError, NewtonFailure, Observer, PathEnd, PathSummary};
use crate::numerics::residual::ParametricResidual;

impl Continuation {
    /// Follows the path from `x_guess` at the start frequency to the end frequency.
    ///
    /// Where the path stalls (see the module docs), it is taken on from the last point before
    /// the stall over a narrow window around it ([`Self::enter_narrow`]) and, once a point lies
    /// outside that window, on over the range with the range's scales and steps, as one path;
    /// each such pass is reported to the observer ([`Observer::narrow_pass`]). A stall inside a
    /// narrow window ends the run as a stall. The scales the run ends with ([`Self::x_scale`])
    /// are the range's.
    pub fn run<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        x_guess: &[f64],
        observer: &mut O,
    ) -> Result<PathSummary, ContinuationError> {
        let outcome = self.run_path(system, x_guess, observer);
        let mut tangent = vec![0.0; self.x_scale.len() + 1];
        tangent[self.x_scale.len()] = 1.0;
        self.leave_narrow(&mut tangent);
        outcome
    }

    /// [`Self::run`] itself.
    fn run_path<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        x_guess: &[f64],
        observer: &mut O,
    ) -> Result<PathSummary, ContinuationError> {
        let a = self.settings;
        let mut narrow_passes = 0usize;
        // A narrow-window pass taken where the path had met a dead end (see below): its points
        // are held back from the observer until the path leaves the window, and dropped, the
        // path ending at that dead end, when one lands back on the path already followed or
        // the window fails.
        let mut held: Option<HeldBack> = None;
        let omega_start = a.freq_start_hz * OMEGA_SCALE;
        let omega_end = a.freq_end_hz * OMEGA_SCALE;
        let n = system.dim();
        let first = self
            .solve_fixed(system, x_guess, omega_start)
            .map_err(|reason| ContinuationError::Start {
                freq_hz: a.freq_start_hz,
                reason,
            })?;
        let mut tangent =
            self.tangent(system, &first, None)
                .map_err(|reason| ContinuationError::Start {
                    freq_hz: a.freq_start_hz,
                    reason,
                })?;
        // The tangent evaluated the operator at the first point, as the observer expects.
        observer.accepted(system, &first, Some(&self.path_normal(&tangent)));
        let mut summary = PathSummary {
            points: vec![first],
            turning_points: Vec::new(),
            rejected_steps: 0,
            leaps: Vec::new(),
            leap_landings: Vec::new(),
            end: PathEnd::MaxPoints,
        };
        let mut ds = a.initial_step.clamp(a.min_step, a.max_step);
        let mut previous_quality: Option<f64> = None;
        // The frequency furthest toward the end reached (times the direction), and the point
        // count when the path last entered ground it had not covered ([`VisitedGround`]).
        let dir = self.direction();
        let mut furthest = dir * a.freq_start_hz;
        let mut ground = VisitedGround::new(a.freq_start_hz, a.freq_end_hz);
        let mut progressed_at = 1usize;
        while summary.points.len() < a.max_points {
            if crate::numerics::interrupt::requested() {
                let last = summary.points.last().expect("at least the first point");
                return Err(ContinuationError::Interrupted {
                    freq_hz: last.freq_hz(),
                });
            }
            let last = summary.points.last().expect("at least the first point");
            if ground.enters_new(last.freq_hz(), &last.x) {
                progressed_at = summary.points.len();
            }
            if summary.points.len() - progressed_at > self.stagnation_points() {
                self.end_path(&mut held, &mut summary, PathEnd::NoProgress);
                return Ok(summary);
            }
            furthest = furthest.max(dir * last.freq_hz());
            let y: Vec<f64> = last
                .x
                .iter()
                .zip(&self.x_scale)
                .map(|(v, s)| v / s)
                .chain(std::iter::once(last.omega / OMEGA_SCALE))
                .collect();
            let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            if self.past_end(&predicted) {
                // Land exactly on the end frequency from the linearly interpolated guess.
                let frac =
                    ((omega_end / OMEGA_SCALE - y[n]) / (predicted[n] - y[n])).clamp(0.0, 1.0);
                let guess: Vec<f64> = (0..n)
                    .map(|j| (y[j] + frac * (predicted[j] - y[j])) * self.x_scale[j])
                    .collect();
                match self.solve_fixed(system, &guess, omega_end) {
                    Ok(mut p) => {
                        if let Some(h) = held.take() {
                            if self.release_or_end(system, observer, h, &mut summary) {
                                return Ok(summary);
                            }
                        }
                        p.step = ds * frac;
                        observer.accepted(system, &p, None);
                        summary.points.push(p);
                        summary.end = PathEnd::EndFrequency;
                        return Ok(summary);
                    }
                    Err(reason) => {
                        let new_ds = ds * 0.5;
                        let call =
                            ObserverCall::Rejected(last.freq_hz(), ds, new_ds, reason.clone());
                        report(&mut held, observer, call);
                        summary.rejected_steps += 1;
                        if new_ds < a.min_step {
                            if let Some(h) = held.take() {
                                self.drop_held(h, &mut summary);
                                return Ok(summary);
                            }
                            return Err(ContinuationError::Stalled {
                                freq_hz: last.freq_hz(),
                                step: ds,
                                reason,
                            });
                        }
                        ds = new_ds;
                        continue;
                    }
                }
            }
            let outcome = self
                .correct(system, &predicted, &tangent)
                .and_then(|(yc, it, rel)| {
                    let (point, t_new, far, degrees) =
                        self.corrected_point(system, &yc, it, rel, ds, &predicted, &tangent)?;
                    // Step quality: > 1 means the corrector went far or the path turned sharply.
                    let quality = far.max(degrees / MAX_TURN_DEGREES);
                    if quality > 1.0 && ds > 2.0 * a.min_step {
                        // A corner of the piecewise-smooth path (a contact changing state) turns
                        // the tangent by the same angle whatever the step; a branch jump does not.
                        let corner = previous_quality.is_some_and(|q| quality >= 0.7 * q);
                        if !corner {
                            previous_quality = Some(quality);
                            return Err(if far >= degrees / MAX_TURN_DEGREES {
                                NewtonFailure::FarCorrection {
                                    distance: far * ds,
                                    step: ds,
                                }
                            } else {
                                NewtonFailure::SharpTurn { degrees }
                            });
                        }
                    }
                    Ok((point, t_new, degrees))
                });
            match outcome {
                Ok((point, t_new, degrees)) => {
                    previous_quality = None;
                    let iterations = point.iterations;
                    if self.take_point(
                        system,
                        observer,
                        &mut held,
                        &mut summary,
                        point,
                        t_new,
                        &mut tangent,
                    ) {
                        return Ok(summary);
                    }
                    // The next step: shorter where Newton needed many iterations, and where
                    // the path bends (the tangent turned by more than TARGET_TURN_DEGREES over
                    // this step), so that peaks and anti-resonances get points on their flanks.
                    let by_iterations = a.target_iterations as f64 / iterations.max(1) as f64;
                    let by_turn = TARGET_TURN_DEGREES / degrees.max(1e-3);
                    let by_amplitude = match &summary.points[..] {
                        [.., before, after] => {
                            TARGET_LOG_AMPLITUDE_CHANGE
                                / self.log_amplitude_change(&before.x, &after.x).max(1e-6)
                        }
                        _ => f64::INFINITY,
                    };
                    let factor = by_iterations.min(by_turn).min(by_amplitude).clamp(0.5, 2.0);
                    ds = (ds * factor).clamp(a.min_step, a.max_step);
                    let freq_hz = summary.points.last().map_or(f64::NAN, |p| p.freq_hz());
                    if self.past_narrow_window(freq_hz) {
                        if self.leave_window(
                            system,
                            observer,
                            &mut held,
                            &mut summary,
                            &mut tangent,
                            freq_hz,
                        ) {
                            return Ok(summary);
                        }
                        ds = a.initial_step.clamp(a.min_step, a.max_step);
                    }
                }
                Err(reason) => {
                    let new_ds = ds * 0.5;
                    let call = ObserverCall::Rejected(last.freq_hz(), ds, new_ds, reason.clone());
                    report(&mut held, observer, call);
                    summary.rejected_steps += 1;
                    if new_ds < a.min_step {
                        // The path cannot be followed through this spot (Newton cycles between
                        // the pieces of the sampled, piecewise-smooth contact law): try to land
                        // on it further on, with a fully converged point, before giving up.
                        let from = last.freq_hz();
                        let followed = &summary.points;
                        let recent = &followed[followed.len().saturating_sub(RETRACE_HISTORY)..];
                        let mut refused_retrace = false;
                        let resumed = match self.corner(
                            system,
                            &y,
                            &tangent,
                            followed,
                            &mut refused_retrace,
                        )? {
                            Some(found) => Some(found),
                            None => {
                                let leapt = self.leap(
                                    system,
                                    &y,
                                    &tangent,
                                    followed,
                                    &mut refused_retrace,
                                )?;
                                if let Some((point, _)) = &leapt {
                                    let call = ObserverCall::Leap(from, point.freq_hz());
                                    report(&mut held, observer, call);
                                    summary.leaps.push((from, point.freq_hz()));
                                    summary.leap_landings.push(summary.points.len());
                                }
                                leapt
                            }
                        };
                        let Some((point, t_new)) = resumed else {
                            // The next window: the first for a new stall, the next width for
                            // one inside a window.
                            let next = match self.narrow {
                                None => (narrow_passes < MAX_NARROW_PASSES).then_some(0),
                                Some(pass) => Some(pass.attempt + 1)
                                    .filter(|&k| k < NARROW_WINDOW_FRACTIONS.len()),
                            };
                            // Where the only way on found was back along the path already
                            // followed (refused: the path would retrace itself and loop through
                            // the same corners until `stagnation_points` ended it), or behind
                            // the highest frequency reached (the path turned back at a fold),
                            // the spot is a dead end: the path ends for the caller to go on
                            // past the highest frequency reached, as it would after that loop.
                            // At the highest frequency reached, where the path came to the
                            // spot monotone in frequency over its last RETRACE_HISTORY points
                            // (a single transition met head-on), the narrow windows are tried
                            // first (on the 3D blade pair they pass such a spot at 886.685 Hz
                            // onto the middle branch), their points held back until the path
                            // leaves the window; a point of theirs that lands back on the path
                            // already followed, or a window that fails, drops them and ends
                            // the path at the dead end, as without the windows. Where the
                            // frequency turned back and forth among those points, the path is
                            // bouncing between corners of the sampled law (the loop the dead
                            // end is there to end) and ends there without windows (see
                            // `frequency_reversals`). Otherwise it is a stall.
                            let behind = dir * from < furthest - a.min_step;
                            let dead_end = refused_retrace || behind;
                            let bouncing = held.is_none() && frequency_reversals(recent) > 0;
                            if dead_end && (behind || next.is_none() || bouncing) {
                                self.end_path(&mut held, &mut summary, PathEnd::DeadEnd);
                                return Ok(summary);
                            }
                            if let Some(attempt) = next {
                                if attempt == 0 {
                                    narrow_passes += 1;
                                }
                                if dead_end && held.is_none() {
                                    held = Some(self.hold_back(&summary));
                                }
                                let stalled = self.leave_narrow(&mut tangent).unwrap_or(from);
                                self.enter_narrow(from, stalled, attempt, &mut tangent);
                                ds = a.initial_step.clamp(a.min_step, a.max_step);
                                previous_quality = None;
                                continue;
                            }
                            if let Some(h) = held.take() {
                                self.drop_held(h, &mut summary);
                                return Ok(summary);
                            }
                            return Err(ContinuationError::Stalled {
                                freq_hz: from,
                                step: ds,
                                reason,
                            });
                        };
                        previous_quality = None;
                        let freq_hz = point.freq_hz();
                        if self.take_point(
                            system,
                            observer,
                            &mut held,
                            &mut summary,
                            point,
                            t_new,
                            &mut tangent,
                        ) {
                            return Ok(summary);
                        }
                        if self.past_narrow_window(freq_hz)
                            && self.leave_window(
                                system,
                                observer,
                                &mut held,
                                &mut summary,
                                &mut tangent,
                                freq_hz,
                            )
                        {
                            return Ok(summary);
                        }
                        ds = a.initial_step.clamp(a.min_step, a.max_step);
                        continue;
                    }
                    ds = new_ds;
                }
            }
        }
        self.end_path(&mut held, &mut summary, PathEnd::MaxPoints);
        Ok(summary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::{
        g, settings, CoefficientCorner, Collect, DeadEnd, FoldThenDeadEnd, Hairpin, ZPath,
    };
    use crate::numerics::linalg::norm;
    use crate::numerics::path::NoObserver;
    use crate::numerics::PathPoint;

    /// Both sharp folds of the Z are turned: the path reaches the end, passing through the
    /// steep middle piece, with a turning point at each fold, every point on the path.
    #[test]
    fn sharp_corner_folds_are_turned() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![1.0]);
        let summary = c.run(&mut ZPath, &[0.0], &mut NoObserver).unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(
            summary.turning_points.len(),
            2,
            "{:?}",
            summary.turning_points
        );
        assert!(summary
            .points
            .iter()
            .any(|p| p.x[0] > 1.01 && p.x[0] < 1.19));
        for p in &summary.points {
            assert!((p.freq_hz() - g(p.x[0]).0).abs() < 1e-9);
        }
        let last = summary.points.last().unwrap();
        assert_eq!(last.freq_hz(), 18.0);
        assert!((last.x[0] - 2.2).abs() < 1e-9);
    }

    /// With the end below the start the path runs down in frequency, through the same folds,
    /// and ends exactly at the end frequency.
    #[test]
    fn a_path_runs_down_when_the_end_is_below_the_start() {
        let mut c = Continuation::new(settings(18.0, 10.0), vec![1.0]);
        let summary = c.run(&mut ZPath, &[2.2], &mut NoObserver).unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(summary.turning_points.len(), 2);
        let last = summary.points.last().unwrap();
        assert_eq!(last.freq_hz(), 10.0);
        assert!(last.x[0].abs() < 1e-9);
    }

    /// At the dead end the corrector fails at every step; the corner search must not resume on
    /// the incoming branch backwards (it used to: a point 0.1 back on it, whose tangent differs
    /// from the incoming one by 2°, was taken and the path ran back down below its start). With
    /// nothing ahead but the way back (refused), the path ends there as [`PathEnd::DeadEnd`]
    /// (for the FRF to go on past it), every point on the incoming branch in rising frequency.
    #[test]
    fn a_corner_never_resumes_on_the_incoming_branch_backwards() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(12.0, 20.0), vec![1.0, 1.0]);
        let outcome = c.run(&mut DeadEnd, &[0.4, 1.8], &mut Collect(&mut points));
        let freqs: Vec<f64> = points.iter().map(|p| p.freq_hz()).collect();
        assert!(
            freqs.windows(2).all(|w| w[1] > w[0]),
            "the path turned back: {:?}",
            &freqs[freqs.len().saturating_sub(8)..]
        );
        match outcome {
            Ok(summary) => {
                assert_eq!(summary.end, PathEnd::DeadEnd);
                let last = freqs.last().unwrap();
                assert!((last - 15.0).abs() < 1e-3, "ended at {last} Hz");
            }
            other => panic!("expected the path to end at the dead end, got {other:?}"),
        }
        for p in &points {
            assert!(p.x[0] <= 1.0 && (p.freq_hz() - 10.0 - 5.0 * p.x[0]).abs() < 1e-9);
        }
    }

    /// Behind the highest frequency reached, a dead end past which only the path already
    /// followed lies ends the path as [`PathEnd::DeadEnd`] (for the FRF to go on past the
    /// fold), not as a stall: the path rises to the fold, turns once and runs down to the dead
    /// end at 10 Hz, never back up along itself, every point on the path.
    #[test]
    fn a_dead_end_behind_a_fold_ends_the_path_for_the_caller_to_jump() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(14.0, 30.0), vec![1.0, 1.0]);
        let summary = c
            .run(
                &mut FoldThenDeadEnd,
                &[0.55, 10.5],
                &mut Collect(&mut points),
            )
            .expect("the dead end behind the fold is not a stall");
        assert_eq!(summary.end, PathEnd::DeadEnd);
        assert_eq!(
            summary.turning_points.len(),
            1,
            "{:?}",
            summary.turning_points
        );
        assert!((summary.turning_points[0] - 15.0).abs() < 0.01);
        let freqs: Vec<f64> = points.iter().map(|p| p.freq_hz()).collect();
        let top = freqs
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(k, _)| k)
            .unwrap();
        assert!(freqs[..=top].windows(2).all(|w| w[1] > w[0]));
        assert!(
            freqs[top..].windows(2).all(|w| w[1] < w[0]),
            "the path turned back up: {:?}",
            &freqs[freqs.len().saturating_sub(8)..]
        );
        let last = points.last().unwrap();
        assert!(
            (last.freq_hz() - 10.0).abs() < 1e-3,
            "ended at {} Hz",
            last.freq_hz()
        );
        for p in &points {
            let mut r = [0.0; 2];
            FoldThenDeadEnd.residual(&p.x, p.omega, &mut r).unwrap();
            assert!(
                p.x[0] <= 2.0 && r[0].abs() < 1e-9 && r[1].abs() < 1e-9,
                "{p:?}"
            );
        }
    }

    /// The corner search keeps a genuine outgoing piece found behind the incoming direction:
    /// the path turns from A onto B (no leap, no turning point), runs up to the end frequency
    /// with every point on A or B, and never back along A.
    #[test]
    fn a_corner_keeps_an_outgoing_piece_behind_the_incoming_direction() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(10.0, 11.0), vec![1.0, 1.0]);
        let summary = c
            .run(
                &mut CoefficientCorner,
                &[0.0, 0.0],
                &mut Collect(&mut points),
            )
            .expect("the corner is turned");
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert!(
            summary.turning_points.is_empty(),
            "{:?}",
            summary.turning_points
        );
        assert!(summary.leaps.is_empty(), "{:?}", summary.leaps);
        let freqs: Vec<f64> = points.iter().map(|p| p.freq_hz()).collect();
        assert!(freqs.windows(2).all(|w| w[1] > w[0]), "{freqs:?}");
        for p in &points {
            let f = p.freq_hz();
            let on_a = p.x[0] <= 1.0 + 1e-9
                && p.x[1].abs() < 1e-9
                && (f - 10.0 - 0.1 * p.x[0]).abs() < 1e-9;
            let s = p.x[1];
            let on_b = s > 0.0
                && (p.x[0] - 1.0 + 0.5 * s).abs() < 1e-9
                && (f - 10.1 - 0.1 * s).abs() < 1e-9;
            assert!(on_a || on_b, "off the path: {p:?}");
        }
        let last = points.last().unwrap();
        assert!((last.freq_hz() - 11.0).abs() < 1e-12);
        assert!((last.x[0] + 3.5).abs() < 1e-9 && (last.x[1] - 9.0).abs() < 1e-9);
    }

    /// The outgoing side of a sharp fold that hugs the incoming side closer than the look-ahead's
    /// polyline test resolves (1.4 % of its reach against [`RETRACE_FRACTION`]) is told from
    /// the path already followed by Newton at the look-ahead's frequency, which lands on the
    /// incoming side 2εσ away: the path turns the fold (one turning point, at 10.5 Hz) and
    /// runs down along B until it leaves the range below the start, every point on A or B;
    /// before, the corner was refused as a retrace and the path ended at a dead end there.
    #[test]
    fn a_sharp_fold_whose_sides_nearly_touch_is_turned() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(10.0, 11.0), vec![1.0, 1.0]);
        let summary = c
            .run(&mut Hairpin, &[0.5, -0.01], &mut Collect(&mut points))
            .expect("the fold is turned");
        assert_eq!(summary.end, PathEnd::LeftRangeBelow, "{summary:?}");
        assert_eq!(
            summary.turning_points.len(),
            1,
            "{:?}",
            summary.turning_points
        );
        assert!((summary.turning_points[0] - 10.5).abs() < 1e-3);
        assert!(summary.leaps.is_empty(), "{:?}", summary.leaps);
        let fold = points
            .iter()
            .position(|p| p.x[1] > 0.0)
            .expect("a point on the outgoing side");
        for (k, p) in points.iter().enumerate() {
            let sigma = 10.5 - p.freq_hz();
            let side = if k < fold { -1.0 } else { 1.0 };
            assert!(
                sigma >= -1e-9
                    && (p.x[0] - 1.0 + sigma).abs() < 1e-9
                    && (p.x[1] - side * Hairpin::EPS * sigma).abs() < 1e-9,
                "point {k} off its side: {p:?}"
            );
        }
        assert!(points.last().unwrap().freq_hz() < 9.5);
    }

    /// The path already followed is the whole path, not its last [`RETRACE_HISTORY`] points: a
    /// point back on a stretch followed long before (side A, 150 points back) is on it, and a
    /// point of the other side of the fold beyond the stretch of it followed, 2εσ from A, is
    /// not, though the polyline through A passes within 4 % of its reach.
    #[test]
    fn the_followed_path_reaches_back_to_its_first_point() {
        let c = Continuation::new(settings(10.0, 11.0), vec![1.0, 1.0]);
        let on = |side: f64, f: f64| {
            let sigma = 10.5 - f;
            PathPoint {
                omega: f * OMEGA_SCALE,
                x: vec![1.0 - sigma, side * Hairpin::EPS * sigma],
                iterations: 1,
                residual: 0.0,
                step: 0.0,
            }
        };
        // Up side A from 10.0 to 10.5 Hz, then down side B to 10.35 Hz.
        let mut followed: Vec<PathPoint> = (0..=150)
            .map(|k| on(-1.0, 10.0 + k as f64 / 300.0))
            .collect();
        followed.extend((1..=50).map(|k| on(1.0, 10.5 - 0.003 * k as f64)));
        let scaled = |p: &PathPoint| c.scaled_points(std::slice::from_ref(p)).pop().unwrap();
        let last = scaled(followed.last().unwrap());
        let reach = |q: &[f64]| norm(&q.iter().zip(&last).map(|(a, b)| a - b).collect::<Vec<_>>());
        let back_on_a = scaled(&on(-1.0, 10.2));
        assert!(c.on_followed_path(&mut Hairpin, &back_on_a, reach(&back_on_a), &followed));
        let below_on_b = scaled(&on(1.0, 10.0));
        assert!(!c.on_followed_path(&mut Hairpin, &below_on_b, reach(&below_on_b), &followed));
        // Only the last RETRACE_HISTORY points, as before: A is out of sight there.
        let recent = &followed[followed.len() - RETRACE_HISTORY..];
        assert!(!c.on_followed_path(&mut Hairpin, &back_on_a, reach(&back_on_a), recent));
    }
}
