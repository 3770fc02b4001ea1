//! The process-wide stop request of `numerics::interrupt` (Ctrl-C of an embedding caller, the
//! Python package): a run started while it is set ends with `ContinuationError::Interrupted`
//! after its first point, and once it is withdrawn the same run reaches the end frequency.
//! Its own test binary: the request is process-wide and would stop other tests' runs.

use fricbound::analysis::frf::{self, FrfError, FrfObserver, FrfPoint};
use fricbound::numerics::{interrupt, ContinuationError};
use fricbound::scene;

/// Counts the points reported, and requests the stop at the `stop_at`-th.
struct StopAt {
    stop_at: usize,
    points: usize,
}

impl FrfObserver for StopAt {
    fn point(&mut self, _point: &FrfPoint) {
        self.points += 1;
        if self.points == self.stop_at {
            interrupt::request();
        }
    }
}

#[test]
fn a_requested_stop_ends_the_run_at_the_next_step_and_clears() {
    let problem = scene::parse(scene::paper_wedge_scene(), "paper", &[])
        .unwrap()
        .validate("paper")
        .unwrap();
    let mut observer = StopAt {
        stop_at: 10,
        points: 0,
    };
    let result = frf::solve(&problem, &mut observer);
    assert!(interrupt::requested());
    interrupt::clear();
    match result {
        Err(FrfError::Continuation(ContinuationError::Interrupted { freq_hz })) => {
            assert!(freq_hz > 50.0 && freq_hz < 350.0, "{freq_hz}");
        }
        other => panic!("expected an interrupted run, got {other:?}"),
    }
    // Stopped at the step after the 10th point, not at the end of the range.
    assert_eq!(observer.points, 10);

    let mut observer = StopAt {
        stop_at: usize::MAX,
        points: 0,
    };
    let run = frf::solve(&problem, &mut observer).unwrap();
    assert!(run.is_complete());
    assert_eq!(observer.points, run.points.len());
    assert!(run.points.len() > 100);
}
