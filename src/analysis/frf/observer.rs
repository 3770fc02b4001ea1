//! The run's observer: the events an FRF run reports as they come, and the adapter that turns the
//! continuation's events into them (holding events back until their points' estimates are in).

use std::collections::VecDeque;

use super::point::{full_point, with_stability};
use super::status::{FrfPoint, Jump};
use crate::analysis::error_estimate::PathPlace;
use crate::analysis::estimate_pool::{EstimatePool, Submitted};
use crate::hbm::operator::HbmOperator;
use crate::hbm::HbmError;
use crate::numerics::{NewtonFailure, Observer, PathPoint};

/// Receives the events of an FRF run.
pub trait FrfObserver {
    /// A point converged.
    fn point(&mut self, _point: &FrfPoint) {}
    /// A step was cut (frequency of the last converged point, Hz).
    fn step_cut(&mut self, _freq_hz: f64, _step: f64, _new_step: f64, _reason: &NewtonFailure) {}
    /// A turning point was passed (Hz).
    fn turning_point(&mut self, _freq_hz: f64) {}
    /// The path turned back at a fold and did not return; it goes on on another branch, whose
    /// points come next (see [`Jump`]).
    fn jump(&mut self, _jump: &Jump) {}
}

/// Observer that ignores everything.
pub struct Silent;

impl FrfObserver for Silent {}

pub(super) struct Adapter<'o, 'p, 'e, O: FrfObserver> {
    pub(super) observer: &'o mut O,
    pub(super) points: Vec<FrfPoint>,
    /// A converged point whose full coefficients could not be recovered.
    pub(super) failure: Option<HbmError>,
    /// The error estimate of every accepted point, when the scene asks for it.
    pub(super) estimates: Option<&'p EstimatePool<'e>>,
    /// Whether the observer's events keep their order behind points whose estimates are still
    /// being formed (the run's own observer); a branch followed silently passes them on at once,
    /// its points keeping their pending estimates until the run reports them.
    pub(super) in_order: bool,
    /// Events held back behind a point whose estimate has not come in yet, in order.
    pub(super) held: VecDeque<Held>,
}

/// An observer event of [`Adapter`], held back until the estimates of the points before it
/// have come in.
pub(super) enum Held {
    /// The point at this index of [`Adapter::points`].
    Point(usize),
    StepCut(f64, f64, f64, NewtonFailure),
    TurningPoint(f64),
    Jump(Jump),
}

impl<'o, 'p, 'e, O: FrfObserver> Adapter<'o, 'p, 'e, O> {
    /// An adapter with no points yet, passing events to `observer` (in order behind pending
    /// estimates when `in_order`), estimating on `estimates` when the run estimates.
    pub(super) fn new(
        observer: &'o mut O,
        estimates: Option<&'p EstimatePool<'e>>,
        in_order: bool,
    ) -> Self {
        Adapter {
            observer,
            points: Vec::new(),
            failure: None,
            estimates,
            in_order,
            held: VecDeque::new(),
        }
    }

    /// Gives `point` its error estimate at ω = `omega` (rad/s), at once or pending on a
    /// worker, when the run estimates.
    pub(super) fn estimate(&self, point: &mut FrfPoint, omega: f64, place: Option<PathPlace>) {
        let Some(pool) = self.estimates else { return };
        match pool.submit(&point.coefficients, omega, place, &point.states) {
            Submitted::Ready(accuracy) => point.accuracy = Some(accuracy),
            Submitted::Pending(ticket) => point.pending_estimate = Some(ticket),
        }
    }

    /// Appends `point` to the run's points and reports it (in order).
    pub(super) fn push_point(&mut self, point: FrfPoint) {
        self.points.push(point);
        self.report(Held::Point(self.points.len() - 1));
    }

    /// Reports `event` to the observer, after the events held back before it.
    pub(super) fn report(&mut self, event: Held) {
        self.held.push_back(event);
        self.flush(false);
    }

    /// Passes the held events on in order, each point with its estimate, up to the first point
    /// whose estimate has not come in (or, with `wait`, waiting for every one).
    fn flush(&mut self, wait: bool) {
        while let Some(front) = self.held.front() {
            if let (&Held::Point(i), true) = (front, self.in_order) {
                if let (Some(ticket), Some(pool)) =
                    (self.points[i].pending_estimate, self.estimates)
                {
                    let accuracy = if wait {
                        pool.wait(ticket)
                    } else {
                        match pool.get(ticket) {
                            Some(accuracy) => Some(accuracy),
                            None => break,
                        }
                    };
                    // None with `wait`: the workers stopped, the point goes without.
                    self.points[i].accuracy = accuracy;
                    self.points[i].pending_estimate = None;
                }
            }
            let Some(event) = self.held.pop_front() else {
                break;
            };
            match event {
                Held::Point(i) => self.observer.point(&self.points[i]),
                Held::StepCut(freq_hz, step, new_step, reason) => {
                    self.observer.step_cut(freq_hz, step, new_step, &reason)
                }
                Held::TurningPoint(freq_hz) => self.observer.turning_point(freq_hz),
                Held::Jump(jump) => self.observer.jump(&jump),
            }
        }
    }

    /// The points, every estimate in (the events all passed on).
    pub(super) fn take_points(&mut self) -> Vec<FrfPoint> {
        self.flush(true);
        std::mem::take(&mut self.points)
    }
}

impl<O: FrfObserver> Drop for Adapter<'_, '_, '_, O> {
    /// A run that ends early (an error) still reports every point it accepted.
    fn drop(&mut self) {
        if self.in_order {
            self.flush(true);
        }
    }
}

impl<O: FrfObserver> Observer<HbmOperator<'_>> for Adapter<'_, '_, '_, O> {
    fn accepted(&mut self, system: &mut HbmOperator<'_>, p: &PathPoint, normal: Option<&[f64]>) {
        let mut point =
            match full_point(system, p).and_then(|point| with_stability(system, point, p.omega)) {
                Ok(point) => point,
                Err(e) => {
                    self.failure.get_or_insert(e);
                    return;
                }
            };
        let place = normal.map(|normal| PathPlace {
            normal,
            step: p.step,
        });
        self.estimate(&mut point, p.omega, place);
        self.push_point(point);
    }
    fn rejected(&mut self, freq_hz: f64, step: f64, new_step: f64, reason: &NewtonFailure) {
        self.report(Held::StepCut(freq_hz, step, new_step, reason.clone()));
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.report(Held::TurningPoint(freq_hz));
    }
}
