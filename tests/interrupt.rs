//! The process-wide stop request of `numerics::interrupt` (Ctrl-C of an embedding caller, the
//! Python package): a run started while it is set ends with `ContinuationError::Interrupted`
//! at the next step of its path, every point it accepted before still reaches the observer,
//! and once the request is withdrawn the same run reaches the end frequency.
//! Its own test binary: the request is process-wide and would stop other tests' runs.

use fricbound::analysis::frf::{self, FrfError, FrfObserver, FrfPoint};
use fricbound::model::Problem;
use fricbound::numerics::{interrupt, ContinuationError};
use fricbound::scene;

/// Counts the points reported, remembers the last one's frequency, and requests the stop at
/// the `stop_at`-th.
struct StopAt {
    stop_at: usize,
    points: usize,
    last_hz: f64,
}

impl StopAt {
    fn new(stop_at: usize) -> Self {
        Self {
            stop_at,
            points: 0,
            last_hz: f64::NAN,
        }
    }
}

impl FrfObserver for StopAt {
    fn point(&mut self, point: &FrfPoint) {
        self.points += 1;
        self.last_hz = point.freq_hz;
        if self.points == self.stop_at {
            interrupt::request();
        }
    }
}

fn paper(overrides: &[&str]) -> Problem {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::parse(scene::paper_wedge_scene(), "paper", &overrides)
        .unwrap()
        .validate("paper")
        .unwrap()
}

/// Runs `problem` with a stop requested at the 10th point reported; returns the observer and
/// the frequency of the last point the run converged (Hz).
fn stopped_at_the_10th(problem: &Problem) -> (StopAt, f64) {
    let mut observer = StopAt::new(10);
    let result = frf::solve(problem, &mut observer);
    assert!(interrupt::requested());
    interrupt::clear();
    match result {
        Err(FrfError::Continuation(ContinuationError::Interrupted { freq_hz })) => {
            assert!(freq_hz > 50.0 && freq_hz < 350.0, "{freq_hz}");
            (observer, freq_hz)
        }
        other => panic!("expected an interrupted run, got {other:?}"),
    }
}

#[test]
fn a_requested_stop_ends_the_run_at_the_next_step_and_clears() {
    // Without the error estimate the observer hears of each point as the path accepts it:
    // the run stops at the step after the 10th point.
    let (observer, last_hz) = stopped_at_the_10th(&paper(&["accuracy.estimate=false"]));
    assert_eq!(observer.points, 10);
    assert_eq!(observer.last_hz, last_hz);

    // With it, the points reach the observer once their estimates (formed on worker threads
    // while the path goes on) arrive, so the path has gone some steps further when the stop is
    // requested; it still stops at its next step, and every point it accepted, up to the last
    // one converged, is reported.
    let problem = paper(&[]);
    let (stopped, last_hz) = stopped_at_the_10th(&problem);
    assert!(stopped.points >= 10, "{}", stopped.points);
    assert_eq!(stopped.last_hz, last_hz);

    let mut observer = StopAt::new(usize::MAX);
    let run = frf::solve(&problem, &mut observer).unwrap();
    assert!(run.is_complete());
    assert_eq!(observer.points, run.points.len());
    assert!(run.points.len() > 100);
    // The stopped run ended short of the range.
    assert!(stopped.points < run.points.len() / 2, "{}", stopped.points);
}
