//! The error estimates of a run's points ([`ErrorEstimator`]) on worker threads of their own,
//! so that the continuation goes on while the points it has accepted are estimated.
//!
//! A point's estimate depends only on the point (its coefficients, frequency, contact states,
//! and on a path its normal and step): every evaluation of the extended harmonic balance
//! marches the AFT from the law's initial state, with no memory of the evaluations before it.
//! The estimates of different points are therefore independent, and a pool of estimators, one
//! per worker, gives the same numbers as one estimator taking the points in turn. On the larger
//! blade pair at H = 1 the estimate takes 6.8-8.2× the CPU of the run itself
//! (docs/accuracy.md, "What the estimate costs, and where the time goes"); run inline, that is
//! the run's wall time too, while with workers it is shared over the machine's cores.
//!
//! A run started from inside a rayon job (the limit curves, the accuracy study's settings,
//! which already keep every core busy with runs of their own) estimates inline, on its own
//! thread, as does a run on a machine where no worker thread can be started. Elsewhere there
//! is one worker per thread of rayon's global pool (`RAYON_NUM_THREADS` sets it). Each worker
//! owns an estimator, and each estimator factorises on a one-thread pool of its own
//! ([`ErrorEstimator::estimate`]).
//!
//! A panic inside an estimator (a bug: the estimator does not panic on user data) gives that
//! point a NaN estimate, as one that cannot be formed, and stops that worker; the others take
//! the jobs still queued, and with none left the points still waiting go without an estimate
//! ([`EstimatePool::wait`] returns None) instead of the run waiting for ever.
//!
//! Written by hand on the standard library's scoped threads and channels: the estimators
//! borrow the problem, so the workers must be scoped to the run, and rayon's scoped spawns
//! would run on its global pool, whose threads the estimate's factorisations are kept off.

use std::cell::RefCell;
use std::collections::HashMap;
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::thread::Scope;

use crate::analysis::error_estimate::{ErrorEstimator, EstimateProblems, PathPlace, PointAccuracy};
use crate::contact::ContactState;
use crate::hbm::HbmError;
use crate::model::Problem;

/// The estimate a submitted point waits for (see [`EstimatePool::submit`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct EstimateTicket(usize);

/// What [`EstimatePool::submit`] gives back.
#[derive(Debug)]
pub enum Submitted {
    /// Estimated inline, on the submitting thread.
    Ready(PointAccuracy),
    /// Handed to a worker: [`EstimatePool::get`] or [`EstimatePool::wait`] collect it.
    Pending(EstimateTicket),
}

/// One point to estimate, owned (the worker outlives the borrow the point came with).
struct Job {
    ticket: EstimateTicket,
    x: Vec<f64>,
    omega: f64,
    /// The path's normal and step at the point, on a path point.
    path: Option<(Vec<f64>, f64)>,
    states: Vec<ContactState>,
}

/// Error estimates of converged points, inline or on workers (see the module docs).
pub struct EstimatePool<'p> {
    /// The estimator used on the submitting thread where no worker runs.
    inline: Option<RefCell<ErrorEstimator<'p>>>,
    /// Where the workers take their jobs from; None once the pool is closed.
    jobs: Option<mpsc::Sender<Job>>,
    /// Where the workers put their estimates.
    results: mpsc::Receiver<(EstimateTicket, PointAccuracy)>,
    /// Estimates received, by ticket.
    done: RefCell<HashMap<EstimateTicket, PointAccuracy>>,
    /// The next ticket.
    next: std::cell::Cell<usize>,
    /// Set when the pool is dropped: the workers skip the jobs still queued.
    cancelled: Arc<AtomicBool>,
}

impl<'p> EstimatePool<'p> {
    /// Workers a run started on the current thread uses: none inside a rayon job, else one
    /// per thread of rayon's global pool (see the module docs).
    pub fn default_workers() -> usize {
        if rayon::current_thread_index().is_some() {
            0
        } else {
            rayon::current_num_threads()
        }
    }

    /// A pool of `workers` estimators of `problem` on `refined` (inline when `workers` is 0 or
    /// no worker thread could be started), its workers scoped to `scope`.
    pub fn start<'scope>(
        scope: &'scope Scope<'scope, 'p>,
        problem: &'p Problem,
        refined: &'p EstimateProblems,
        workers: usize,
    ) -> Result<Self, HbmError> {
        let (jobs, queue) = mpsc::channel::<Job>();
        let (report, results) = mpsc::channel();
        let queue = Arc::new(Mutex::new(queue));
        let cancelled = Arc::new(AtomicBool::new(false));
        let mut started = 0;
        for _ in 0..workers {
            let mut estimator = ErrorEstimator::new(problem, refined)?;
            let (queue, report, cancelled) = (queue.clone(), report.clone(), cancelled.clone());
            let spawned = std::thread::Builder::new()
                .name("error-estimate-worker".to_string())
                .spawn_scoped(scope, move || loop {
                    // The lock is held only while taking the next job.
                    let next = match queue.lock() {
                        Ok(queue) => queue.recv(),
                        Err(_) => return,
                    };
                    let Ok(job) = next else { return };
                    if cancelled.load(Ordering::Relaxed) {
                        continue;
                    }
                    let path = job.path.as_ref().map(|(normal, step)| PathPlace {
                        normal,
                        step: *step,
                    });
                    // A panic inside the estimator (a bug, not user data) must not leave the
                    // run waiting for this ticket for ever: the point goes without an
                    // estimate (NaN, as one that cannot be formed) and the worker, whose
                    // estimator may be left half-updated, stops; the others go on.
                    let estimated = std::panic::catch_unwind(AssertUnwindSafe(|| {
                        estimator.estimate(&job.x, job.omega, path, &job.states)
                    }));
                    let panicked = estimated.is_err();
                    let accuracy = estimated
                        .unwrap_or_else(|_| PointAccuracy::not_formed(problem.outputs.len()));
                    if report.send((job.ticket, accuracy)).is_err() || panicked {
                        return;
                    }
                });
            if spawned.is_ok() {
                started += 1;
            }
        }
        let inline = if started == 0 {
            Some(RefCell::new(ErrorEstimator::new(problem, refined)?))
        } else {
            None
        };
        Ok(Self {
            inline,
            jobs: (started > 0).then_some(jobs),
            results,
            done: RefCell::new(HashMap::new()),
            next: std::cell::Cell::new(0),
            cancelled,
        })
    }

    /// The estimate of the converged point `x` (full coefficients) at ω = `omega` (rad/s), as
    /// [`ErrorEstimator::estimate`] forms it: at once where the pool is inline, else handed to
    /// a worker.
    pub fn submit(
        &self,
        x: &[f64],
        omega: f64,
        path: Option<PathPlace>,
        states: &[ContactState],
    ) -> Submitted {
        if let Some(inline) = &self.inline {
            return Submitted::Ready(inline.borrow_mut().estimate(x, omega, path, states));
        }
        let ticket = EstimateTicket(self.next.get());
        self.next.set(ticket.0 + 1);
        let job = Job {
            ticket,
            x: x.to_vec(),
            omega,
            path: path.map(|p| (p.normal.to_vec(), p.step)),
            states: states.to_vec(),
        };
        if let Some(jobs) = &self.jobs {
            // A send fails only where every worker has stopped; `wait` then reports the
            // estimate as lost.
            let _ = jobs.send(job);
        }
        Submitted::Pending(ticket)
    }

    /// The estimate of `ticket` if it has come in, without waiting; handed over once (the
    /// pool keeps no copy).
    pub fn get(&self, ticket: EstimateTicket) -> Option<PointAccuracy> {
        let mut done = self.done.borrow_mut();
        while let Ok((t, accuracy)) = self.results.try_recv() {
            done.insert(t, accuracy);
        }
        done.remove(&ticket)
    }

    /// The estimate of `ticket`, waiting for it; None when it cannot come any more (every
    /// worker has stopped). Handed over once, as by [`Self::get`].
    pub fn wait(&self, ticket: EstimateTicket) -> Option<PointAccuracy> {
        let mut done = self.done.borrow_mut();
        while !done.contains_key(&ticket) {
            match self.results.recv() {
                Ok((t, accuracy)) => {
                    done.insert(t, accuracy);
                }
                Err(_) => return None,
            }
        }
        done.remove(&ticket)
    }
}

impl Drop for EstimatePool<'_> {
    /// Closes the queue: the workers skip what is still queued and end, and the scope joins
    /// them.
    fn drop(&mut self) {
        self.cancelled.store(true, Ordering::Relaxed);
        self.jobs = None;
    }
}
