//! The path, step by step: predict along the tangent, correct on the hyperplane normal to it,
//! accept the point or halve the step, until the end frequency, the range's end behind the
//! start or the point budget.

use super::predictor::{
    Oriented, MAX_TURN_DEGREES, TARGET_LOG_AMPLITUDE_CHANGE, TARGET_TURN_DEGREES,
};
use super::settings::{Continuation, OMEGA_SCALE};
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::{ContinuationError, NewtonFailure, Observer, PathEnd, PathSummary};
use crate::numerics::residual::ParametricResidual;

/// Scale factor of the response's arc-length scale (and of the adaptive scale's climb) over
/// the window around a corner neither the steps nor [`Continuation::turn_corner`] got past: the
/// response weighs as in a range this fraction of the run's, so that a corner where the path
/// turns into the response at nearly constant frequency becomes an ordinary bend. Over
/// 50-600 Hz the paper's system stalls at 396.5722 Hz, where a contact starts to slip, with
/// the range's scales, and passes it over 380-420 Hz. The window ends at the first point
/// further than half the range times this fraction from the corner, and the range's scales
/// come back.
///
/// Still needed with the event-resolved laws: without the window the 3D blade pair's path over
/// 840-900 Hz (`blade_pair_3d::the_3d_frf_over_the_bending_pair_is_complete_through_both_folds`)
/// stalls at 885.7109 Hz, where the corrector stagnates at a relative residual of about
/// 10⁻⁹ on every hyperplane down to the minimum step and the corner's way on does not get
/// past; with it the path passes. (The out-of-plane 2D case of `friction_2d`, which
/// needed it before the 2D law's fixes, no longer does.)
const WINDOW_FRACTION: f64 = 0.01;

/// A step refused as far from its prediction or sharply turned is the path's own corner when
/// the step of half its length from the same point lands on the straight line through the two
/// landings that meets the incoming tangent's line within the shorter step: near a corner the
/// pieces are straight, so both landings lie on the outgoing piece, which starts at the corner
/// on the incoming piece, while landings on another branch lie on a line that passes the
/// incoming one at about their distance from the point. Within this fraction: of the shorter
/// landing's distance from the point for the gap between the two lines, of the shorter step
/// for where they meet. The corner is then taken at once, not after the step has been cut to
/// the minimum.
const CORNER_HALVING: f64 = 0.1;

/// Largest turn (degrees) between the incoming tangent and the outgoing piece of a corner
/// taken by [`CORNER_HALVING`]'s test. Towards 90° the hyperplane meets the outgoing piece ever
/// further from the corner, and where several pieces leave it the landing need not be on the
/// one the path goes on along: on the 3rd nonlinear mode of the paper's system at H = 5 that
/// the guide verifies (`fricbound verify meshes/paper-wedge/modes-3rd.toml --amplitudes
/// 1e-6,1e-4,3e-4 --set harmonics.max=5`, run by
/// `cli_run::every_documented_command_exits_as_documented`), corners of 85-88° taken this way
/// led the m = +1, m = 0 and mixed cases onto another branch (156 Hz instead of 203 Hz at
/// 3·10⁻⁴ m, which time integration does not verify).
const CORNER_MAX_TURN_DEGREES: f64 = 75.0;

/// Why a step fails, with the landing (scaled) of a step refused as far or sharply turned.
type Refusal = (NewtonFailure, Option<Vec<f64>>);

impl Continuation {
    /// Half width (Hz) of the window around a corner (see [`WINDOW_FRACTION`]).
    fn window_half_width(&self) -> f64 {
        0.5 * WINDOW_FRACTION * (self.settings.freq_end_hz - self.settings.freq_start_hz).abs()
    }

    /// Follows the path from `x_guess` at the start frequency to the end frequency.
    ///
    /// Each step predicts y + Δs·t and corrects on the hyperplane normal to t (paper Eqs. 8-9).
    /// A step is cut (halved) when the corrector fails, or when it went further from the
    /// prediction than the step or turned the tangent by more than [`MAX_TURN_DEGREES`]
    /// (a jump to another branch, unless the half step's landing shows a corner of the path,
    /// [`CORNER_HALVING`], or the step is already within twice the minimum); an
    /// accepted step sets the next one from Newton's iterations, the tangent's turn and the
    /// change of the watched amplitudes. Turning points (dω/ds changing sign) are reported and
    /// followed. The last point is solved at exactly the end frequency, unless the observer's
    /// own end comes first ([`Observer::reached_end`]). A step cut below the
    /// minimum is a corner of the path, taken on a sphere about the last point
    /// ([`Self::turn_corner`]); where that finds no way on, the run ends with
    /// [`ContinuationError::Stalled`], every point accepted before reported to the observer.
    pub fn run<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        x_guess: &[f64],
        observer: &mut O,
    ) -> Result<PathSummary, ContinuationError> {
        let a = self.settings;
        let start_failed = |reason| ContinuationError::Start {
            freq_hz: a.freq_start_hz,
            reason,
        };
        let first = self
            .solve_fixed(system, x_guess, a.freq_start_hz * OMEGA_SCALE)
            .map_err(start_failed)?;
        let first_tangent = self.tangent(system, &first, None).map_err(start_failed)?;
        self.orientation = first_tangent.sign;
        let mut tangent = first_tangent.t;
        // The tangent evaluated the operator at the first point, as the observer expects.
        observer.accepted(system, &first, Some(&self.path_normal(&tangent)));
        let mut summary = PathSummary {
            points: vec![first],
            turning_points: Vec::new(),
            rejected_steps: 0,
            end: PathEnd::MaxPoints,
        };
        if observer.reached_end() {
            summary.end = PathEnd::EndFrequency;
            return Ok(summary);
        }
        let mut ds = a.initial_step.clamp(a.min_step, a.max_step);
        // The frequency (Hz) of a corner the path is being taken past with the response
        // weighing more in the arc length (see `WINDOW_FRACTION`).
        let mut window: Option<f64> = None;
        // The landing (scaled) of the last step from the current point refused as far or
        // sharply turned, of twice the present step (see `CORNER_HALVING`).
        let mut refused: Option<Vec<f64>> = None;
        while summary.points.len() < a.max_points {
            let last = summary.points.last().expect("at least the first point");
            if crate::numerics::interrupt::requested() {
                return Err(ContinuationError::Interrupted {
                    freq_hz: last.freq_hz(),
                });
            }
            let from_hz = last.freq_hz();
            let y = self.scaled(last);
            let predicted: Vec<f64> = y.iter().zip(&tangent).map(|(v, t)| v + ds * t).collect();
            let failure = if self.past_end(&predicted) {
                refused = None;
                match self.land_on_end(system, &y, &predicted) {
                    Ok((mut point, fraction)) => {
                        point.step = ds * fraction;
                        observer.accepted(system, &point, None);
                        summary.points.push(point);
                        summary.end = PathEnd::EndFrequency;
                        return Ok(summary);
                    }
                    Err(reason) => reason,
                }
            } else {
                match self.step(system, (&y, &predicted), &tangent, ds, refused.take()) {
                    Ok((point, t_new, degrees)) => {
                        let iterations = point.iterations;
                        if self.accept(system, observer, &mut summary, point, t_new, &mut tangent) {
                            return Ok(summary);
                        }
                        ds = self.next_step(ds, iterations, degrees, &summary);
                        if let Some(corner_hz) = window {
                            let reached = summary.points.last().map_or(corner_hz, |p| p.freq_hz());
                            if (reached - corner_hz).abs() > self.window_half_width() {
                                self.rescale(1.0 / WINDOW_FRACTION, &mut tangent);
                                window = None;
                                ds = a.initial_step.clamp(a.min_step, a.max_step);
                            }
                        }
                        continue;
                    }
                    Err((reason, landing)) => {
                        refused = landing;
                        reason
                    }
                }
            };
            let new_ds = ds * 0.5;
            observer.rejected(from_hz, ds, new_ds, &failure);
            summary.rejected_steps += 1;
            if new_ds < a.min_step {
                // A corner of the path (see `corner`): go on past it on a sphere.
                if let Some((point, t_new)) =
                    self.turn_corner(system, &y, &tangent, &summary.points)
                {
                    refused = None;
                    if self.accept(system, observer, &mut summary, point, t_new, &mut tangent) {
                        return Ok(summary);
                    }
                    ds = a.initial_step.clamp(a.min_step, a.max_step);
                    continue;
                }
                refused = None;
                if window.is_none() {
                    self.rescale(WINDOW_FRACTION, &mut tangent);
                    window = Some(from_hz);
                    ds = a.initial_step.clamp(a.min_step, a.max_step);
                    continue;
                }
                return Err(ContinuationError::Stalled {
                    freq_hz: from_hz,
                    step: ds,
                    reason: failure,
                });
            }
            ds = new_ds;
        }
        Ok(summary)
    }

    /// One predictor-corrector step from the last point `y` to the prediction `predicted`
    /// (scaled, ω last) along `tangent`: the corrected point, its tangent and the tangent's
    /// turn (degrees), or why the step fails (the corrector's failure, or a correction far
    /// from the prediction or a sharp turn while the step can still be cut) with the landing
    /// of a far or sharply turned step. Such a landing is taken as the path's own corner when
    /// it lies with `refused`, the landing of the step twice as long from `y` refused before,
    /// on a straight piece that starts at the incoming one (see [`CORNER_HALVING`]).
    fn step<S: ParametricResidual>(
        &self,
        system: &mut S,
        (y, predicted): (&[f64], &[f64]),
        tangent: &[f64],
        ds: f64,
        refused: Option<Vec<f64>>,
    ) -> Result<(crate::numerics::PathPoint, Oriented, f64), Refusal> {
        let (yc, iterations, residual) = self
            .correct(system, predicted, tangent)
            .map_err(|e| (e, None))?;
        let (point, t_new, far, degrees) = self
            .corrected_point(system, &yc, iterations, residual, ds, predicted, tangent)
            .map_err(|e| (e, None))?;
        // Within twice the minimum step a far correction or a sharp turn is taken as the path's
        // own (a corner that the steps have closed in on). Still needed with the event-resolved
        // laws: with these checks at every step, the 3rd nonlinear mode of the paper's system at
        // H = 5 that the guide verifies (`fricbound verify meshes/paper-wedge/modes-3rd.toml
        // --amplitudes 1e-6,1e-4,3e-4 --set harmonics.max=5`, run by
        // `cli_run::every_documented_command_exits_as_documented`) no longer verifies at
        // 3·10⁻⁴ m: its first harmonic is 1.9·10⁻² to 0.29 from the mode's (tolerance 10⁻²).
        let corner = refused.is_some_and(|full| corner_between(y, tangent, (&full, &yc), ds));
        if ds > 2.0 * self.settings.min_step && !corner {
            if far > 1.0 {
                let failure = NewtonFailure::FarCorrection {
                    distance: far * ds,
                    step: ds,
                };
                return Err((failure, Some(yc)));
            }
            if degrees > MAX_TURN_DEGREES {
                return Err((NewtonFailure::SharpTurn { degrees }, Some(yc)));
            }
        }
        Ok((point, t_new, degrees))
    }

    /// The point at exactly the end frequency, by Newton from the guess interpolated between
    /// the last point `y` and the prediction past the end (both scaled), with the fraction of
    /// the step that reaches the end.
    fn land_on_end<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        predicted: &[f64],
    ) -> Result<(crate::numerics::PathPoint, f64), NewtonFailure> {
        let n = y.len() - 1;
        let end = self.settings.freq_end_hz;
        let fraction = ((end - y[n]) / (predicted[n] - y[n])).clamp(0.0, 1.0);
        let guess: Vec<f64> = (0..n)
            .map(|j| (y[j] + fraction * (predicted[j] - y[j])) * self.x_scale[j])
            .collect();
        let point = self.solve_fixed(system, &guess, end * OMEGA_SCALE)?;
        Ok((point, fraction))
    }

    /// The step after an accepted one of length `ds`: shorter where Newton needed more than
    /// the target iterations, where the path bends (the tangent turned by more than
    /// [`TARGET_TURN_DEGREES`]) and where a watched amplitude changed by more than
    /// [`TARGET_LOG_AMPLITUDE_CHANGE`] in ln, so that peaks and anti-resonances get points
    /// on their flanks; longer where all allow it; at most halved or doubled, within the bounds.
    fn next_step(&self, ds: f64, iterations: usize, degrees: f64, summary: &PathSummary) -> f64 {
        let a = self.settings;
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
        (ds * factor).clamp(a.min_step, a.max_step)
    }
}

/// Whether the landings `full` of a step from `y` along the unit tangent `tangent` and `half`
/// of the step of half its length `ds` (all scaled) lie on a straight piece that meets the
/// incoming tangent's line between `y` and the shorter step's prediction (within
/// [`CORNER_HALVING`]), the corner behind `half` on it.
fn corner_between(y: &[f64], tangent: &[f64], (full, half): (&[f64], &[f64]), ds: f64) -> bool {
    let along: Vec<f64> = full.iter().zip(half).map(|(f, h)| f - h).collect();
    let length = norm(&along);
    let from: Vec<f64> = y.iter().zip(half).map(|(a, h)| a - h).collect();
    let b: Vec<f64> = along.iter().map(|v| v / length).collect();
    let (c, d, e) = (dot(tangent, &b), dot(tangent, &from), dot(&b, &from));
    let parallel = 1.0 - c * c;
    if !(length > 0.0 && parallel > 1e-9 && c >= CORNER_MAX_TURN_DEGREES.to_radians().cos()) {
        return false;
    }
    // The closest points y + τ·tangent and half + s·b of the two lines.
    let tau = (c * e - d) / parallel;
    let s = (e - c * d) / parallel;
    let gap: Vec<f64> = (0..y.len())
        .map(|i| from[i] + tau * tangent[i] - s * b[i])
        .collect();
    // The shorter landing's offset from the incoming tangent's line: it lies on the outgoing
    // piece, past the corner, not on the incoming piece (a turn flagged at a landing where the
    // path is still straight says nothing of the piece beyond it).
    let along_in = dot(&from, tangent);
    let offset: Vec<f64> = (0..y.len())
        .map(|i| from[i] - along_in * tangent[i])
        .collect();
    norm(&gap) <= CORNER_HALVING * norm(&from)
        && norm(&offset) >= CORNER_HALVING * norm(&from)
        && tau >= -CORNER_HALVING * ds
        && tau <= (1.0 + CORNER_HALVING) * ds
        && s <= CORNER_HALVING * length
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::continuation::fixtures::{b, bend, settings, Collect, SmoothS};
    use crate::numerics::path::{NoObserver, PathPoint};

    /// Both folds of the smooth S are followed: the path reaches the end, with a turning point
    /// at each fold (16 and 12 Hz), through the middle branch, every point on the path.
    #[test]
    fn both_folds_of_an_s_are_followed() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(12.0, 17.0), vec![1.0]);
        let summary = c
            .run(&mut SmoothS::whole(), &[-2.0], &mut Collect(&mut points))
            .unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(summary.turning_points.len(), 2, "{summary:?}");
        assert!((summary.turning_points[0] - 16.0).abs() < 0.05);
        assert!((summary.turning_points[1] - 12.0).abs() < 0.05);
        assert!(points.iter().any(|p| p.x[0].abs() < 0.5));
        for p in &points {
            assert!((p.freq_hz() - SmoothS::g(p.x[0])).abs() < 1e-9);
        }
        let last = points.last().unwrap();
        assert!((last.freq_hz() - 17.0).abs() < 1e-12);
        assert!((SmoothS::g(last.x[0]) - 17.0).abs() < 1e-9 && last.x[0] > 2.0);
        assert_eq!(points.len(), summary.points.len());
    }

    /// At a corner where the path bends by 60° (more than a step may turn) the step that
    /// crosses it is refused, and the step of half its length lands on the outgoing piece
    /// too, on the line through the longer one's landing and the corner: the corner is taken
    /// there, after two refused steps, not after the step has been cut to within twice the
    /// minimum (15 refused steps).
    #[test]
    fn a_corner_is_taken_once_halving_the_step_halves_the_landing() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(10.0, 12.0), vec![1.0]);
        let summary = c
            .run(&mut bend(), &[0.0], &mut Collect(&mut points))
            .unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        for p in &points {
            assert!((p.freq_hz() - b(p.x[0]).0).abs() < 1e-9, "{p:?}");
        }
        assert!(points.iter().any(|p| p.x[0] > 1.0 && p.x[0] < 1.1));
        assert!(summary.rejected_steps <= 3, "{}", summary.rejected_steps);
    }

    /// With the end below the start the path runs down in frequency, through the same folds,
    /// and ends exactly at the end frequency.
    #[test]
    fn a_path_runs_down_when_the_end_is_below_the_start() {
        let mut c = Continuation::new(settings(17.0, 11.0), vec![1.0]);
        let summary = c
            .run(&mut SmoothS::whole(), &[2.1], &mut NoObserver)
            .unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(summary.turning_points.len(), 2);
        let last = summary.points.last().unwrap();
        assert!((last.freq_hz() - 11.0).abs() < 1e-12);
        assert!(last.x[0] < -2.0);
    }

    /// A path that turns back at its fold and runs on below the start ends as
    /// [`PathEnd::LeftRangeBelow`] once it is half the range behind the start.
    #[test]
    fn a_path_that_turns_back_for_good_leaves_the_range() {
        // From x = −1.6 (14.70 Hz) over a range of 2 Hz, the path rises to the fold at 16 Hz,
        // turns, and falls along the middle branch, 1 Hz (half the range) below the start
        // at 13.70 Hz, well before the lower fold at 12 Hz.
        let start = SmoothS::g(-1.6);
        let mut c = Continuation::new(settings(start, start + 2.0), vec![1.0]);
        let summary = c
            .run(&mut SmoothS::whole(), &[-1.6], &mut NoObserver)
            .unwrap();
        assert_eq!(summary.end, PathEnd::LeftRangeBelow, "{summary:?}");
        assert_eq!(summary.turning_points.len(), 1);
        assert!(summary.points.last().unwrap().freq_hz() < start - 1.0);
    }

    /// An observer whose own end is x ≥ 0 (on the S's middle branch, after its upper fold)
    /// stops the path at the first point past it, as at the end frequency: the points before
    /// it are below, and none after it is taken.
    #[test]
    fn a_path_stops_at_the_observers_end() {
        struct UpToZero(Vec<PathPoint>);
        impl<S: ParametricResidual> Observer<S> for UpToZero {
            fn accepted(&mut self, _: &mut S, point: &PathPoint, _: Option<&[f64]>) {
                self.0.push(point.clone());
            }
            fn reached_end(&self) -> bool {
                self.0.last().is_some_and(|p| p.x[0] >= 0.0)
            }
        }
        let mut observer = UpToZero(Vec::new());
        let mut c = Continuation::new(settings(12.0, 17.0), vec![1.0]);
        let summary = c
            .run(&mut SmoothS::whole(), &[-2.0], &mut observer)
            .unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(summary.turning_points.len(), 1, "{summary:?}");
        let (last, before) = observer.0.split_last().unwrap();
        assert!(last.x[0] >= 0.0 && before.iter().all(|p| p.x[0] < 0.0));
        assert_eq!(summary.points.len(), observer.0.len());
    }

    /// A residual with no solution past a point stalls the run there: the error names the
    /// last frequency reached, and the observer has every point accepted before.
    #[test]
    fn a_path_without_a_way_on_stalls_with_its_points_reported() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(12.0, 20.0), vec![1.0]);
        let outcome = c.run(
            &mut SmoothS::ending_at(1.5),
            &[-2.0],
            &mut Collect(&mut points),
        );
        match outcome {
            Err(ContinuationError::Stalled { freq_hz, .. }) => {
                assert_eq!(freq_hz, points.last().unwrap().freq_hz());
                assert!(points.iter().all(|p| p.x[0] <= 1.5));
            }
            other => panic!("expected a stall, got {other:?}"),
        }
    }
}
