//! Accepting a point and reporting it: the observer's events, made at once or held back while a
//! window taken from a dead end has not left it, then released or dropped with the window.

use super::settings::{AdaptiveScale, Continuation, NarrowPass};
use crate::numerics::path::{NewtonFailure, Observer, PathEnd, PathPoint, PathSummary};
use crate::numerics::residual::ParametricResidual;

/// A narrow-window pass taken from a dead end, whose points are held back from the observer
/// until the path leaves the window: the state of the path at the dead end (to end there, as
/// if no window had been tried, when the window fails) and what the observer is owed.
#[derive(Debug, Clone)]
pub(super) struct HeldBack {
    /// Points of the path at the dead end.
    pub(super) points: usize,
    /// Turning points of the path at the dead end.
    pub(super) turning_points: usize,
    /// Leaps of the path at the dead end.
    pub(super) leaps: usize,
    /// Rejected steps of the path at the dead end.
    pub(super) rejected_steps: usize,
    /// Arc-length scales at the dead end (m).
    pub(super) x_scale: Vec<f64>,
    /// Adaptive scale at the dead end.
    pub(super) adaptive: Option<AdaptiveScale>,
    /// Narrow-window pass under way at the dead end.
    pub(super) narrow: Option<NarrowPass>,
    /// Observer calls owed since the dead end, in order.
    events: Vec<HeldEvent>,
}

/// An observer call held back (see [`HeldBack`]).
#[derive(Debug, Clone)]
enum HeldEvent {
    /// [`Observer::accepted`] for the path point of this index, with this normal (the operator
    /// is evaluated at the point again before the call).
    Accepted(usize, Vec<f64>),
    /// Any other call.
    Call(ObserverCall),
}

/// An observer call that needs nothing but its arguments, reported at once or held back with
/// a window's points ([`report`]).
#[derive(Debug, Clone)]
pub(super) enum ObserverCall {
    /// [`Observer::rejected`]: frequency (Hz), step, new step, reason.
    Rejected(f64, f64, f64, NewtonFailure),
    /// [`Observer::turning_point`] (Hz).
    TurningPoint(f64),
    /// [`Observer::leap`] from, to (Hz).
    Leap(f64, f64),
}

impl ObserverCall {
    /// Makes the call.
    fn send<S: ParametricResidual, O: Observer<S>>(self, observer: &mut O) {
        match self {
            Self::Rejected(freq_hz, step, new_step, reason) => {
                observer.rejected(freq_hz, step, new_step, &reason)
            }
            Self::TurningPoint(freq_hz) => observer.turning_point(freq_hz),
            Self::Leap(from_hz, to_hz) => observer.leap(from_hz, to_hz),
        }
    }
}

/// Makes `call` on `observer`, or keeps it with the calls of the window held back (`held`).
pub(super) fn report<S: ParametricResidual, O: Observer<S>>(
    held: &mut Option<HeldBack>,
    observer: &mut O,
    call: ObserverCall,
) {
    match held {
        Some(h) => h.events.push(HeldEvent::Call(call)),
        None => call.send(observer),
    }
}

impl Continuation {
    /// Takes a converged point with its tangent onto the path: reports it (and a turning point
    /// when dω/ds changed sign from `tangent`), makes its tangent the current one and lets the
    /// scale follow the response. Returns true when the point left the range for good (the
    /// summary's end is then set).
    /// With a window's points held back (`held`), the observer calls are kept in it instead.
    #[allow(clippy::too_many_arguments)]
    fn accept<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        point: PathPoint,
        t_new: Vec<f64>,
        tangent: &mut Vec<f64>,
    ) -> bool {
        let n = t_new.len() - 1;
        if t_new[n] * tangent[n] < 0.0 {
            summary.turning_points.push(point.freq_hz());
            report(held, observer, ObserverCall::TurningPoint(point.freq_hz()));
        }
        let normal = self.path_normal(&t_new);
        match held {
            Some(h) => h
                .events
                .push(HeldEvent::Accepted(summary.points.len(), normal)),
            None => observer.accepted(system, &point, Some(&normal)),
        }
        let left = self.left_range(&point);
        *tangent = t_new;
        self.adapt_scale(&point.x, tangent);
        summary.points.push(point);
        if left {
            summary.end = PathEnd::LeftRangeBelow;
        }
        left
    }

    /// Starts holding back the points of a narrow window taken from a dead end: the path's
    /// state there.
    pub(super) fn hold_back(&self, summary: &PathSummary) -> HeldBack {
        HeldBack {
            points: summary.points.len(),
            turning_points: summary.turning_points.len(),
            leaps: summary.leaps.len(),
            rejected_steps: summary.rejected_steps,
            x_scale: self.x_scale.clone(),
            adaptive: self.adaptive.clone(),
            narrow: self.narrow,
            events: Vec::new(),
        }
    }

    /// Takes a converged point onto the path. A point of a held-back window that lands back on
    /// the path already followed drops the window ([`Self::drop_held`]: the path ends at the
    /// dead end the window was taken from); any other point is accepted ([`Self::accept`]),
    /// and when that ends the path a held-back window is released or dropped
    /// ([`Self::release_or_end`]). True when the path ends here.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn take_point<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        point: PathPoint,
        t_new: Vec<f64>,
        tangent: &mut Vec<f64>,
    ) -> bool {
        if held.is_some() && self.narrow.is_some() && self.retraces(&point, &summary.points) {
            if let Some(h) = held.take() {
                self.drop_held(h, summary);
                return true;
            }
        }
        if self.accept(system, observer, held, summary, point, t_new, tangent) {
            if let Some(h) = held.take() {
                self.release_or_end(system, observer, h, summary);
            }
            return true;
        }
        false
    }

    /// Drops a held-back window: the path and the scales as they were at the dead end it was
    /// taken from, and the path ends there ([`PathEnd::DeadEnd`]), as without the window.
    pub(super) fn drop_held(&mut self, held: HeldBack, summary: &mut PathSummary) {
        summary.points.truncate(held.points);
        summary.turning_points.truncate(held.turning_points);
        summary.leaps.truncate(held.leaps);
        summary.leap_landings.truncate(held.leaps);
        summary.rejected_steps = held.rejected_steps;
        self.x_scale = held.x_scale;
        self.adaptive = held.adaptive;
        self.narrow = held.narrow;
        *self.last_factor.borrow_mut() = None;
        *self.carried.borrow_mut() = None;
        summary.end = PathEnd::DeadEnd;
    }

    /// Ends the path with `end`, or, with a window held back (`held`), drops the window and
    /// ends it at the dead end the window was taken from ([`Self::drop_held`]).
    pub(super) fn end_path(
        &mut self,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        end: PathEnd,
    ) {
        match held.take() {
            Some(h) => self.drop_held(h, summary),
            None => summary.end = end,
        }
    }

    /// Leaves the narrow window the path has passed at `freq_hz` (Hz): the range's scales
    /// again ([`Self::leave_narrow`]), a held-back window's calls handed over
    /// ([`Self::release_or_end`]) and the pass reported. True when handing them over ended the
    /// path.
    pub(super) fn leave_window<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        tangent: &mut [f64],
        freq_hz: f64,
    ) -> bool {
        let left = self.leave_narrow(tangent);
        if let Some(h) = held.take() {
            if self.release_or_end(system, observer, h, summary) {
                return true;
            }
        }
        if let Some(from_hz) = left {
            observer.narrow_pass(from_hz, freq_hz);
        }
        false
    }

    /// Hands a held-back window's observer calls over, in order, the operator evaluated at
    /// each point again before it is reported (as [`Observer::accepted`] expects). Returns
    /// true when such an evaluation fails: the path then ends at the last point reported, as
    /// at a dead end (the summary's end is set).
    pub(super) fn release_or_end<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: HeldBack,
        summary: &mut PathSummary,
    ) -> bool {
        let n = system.dim();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        for event in held.events {
            match event {
                HeldEvent::Accepted(index, normal) => {
                    let Some(point) = summary.points.get(index) else {
                        continue;
                    };
                    if system
                        .residual_and_jacobian(&point.x, point.omega, &mut r, &mut jac, &mut dr)
                        .is_err()
                    {
                        summary.points.truncate(index);
                        // The leaps whose landing was dropped with it go too.
                        let kept = summary.leap_landings.iter().filter(|&&l| l < index).count();
                        summary.leaps.truncate(kept);
                        summary.leap_landings.truncate(kept);
                        summary.end = PathEnd::DeadEnd;
                        return true;
                    }
                    observer.accepted(system, point, Some(&normal));
                }
                HeldEvent::Call(call) => call.send(observer),
            }
        }
        false
    }
}
