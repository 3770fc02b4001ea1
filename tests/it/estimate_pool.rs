//! The error estimates formed on worker threads while the path goes on
//! (`fricbound::analysis::estimate_pool`) against the same run estimating inline: the same
//! points with the same estimates, bit for bit, and the observer's events in the same order,
//! each point with its estimate when the observer receives it.
//!
//! A run inside a rayon job estimates inline (as the limit curves and the accuracy study do);
//! the same run on a thread of its own uses one worker per thread of rayon's global pool. The
//! paper's system at F0 = 1 N (50-350 Hz) has step cuts and turning points between its points,
//! whose events must stay in order behind the points' pending estimates.

use std::f64::consts::PI;

use fricbound::analysis::error_estimate::{EstimateMethod, EstimateProblems, PointAccuracy};
use fricbound::analysis::estimate_pool::{EstimatePool, Submitted};
use fricbound::analysis::frf::{self, FrfObserver, FrfPoint, FrfRun, Jump, Silent};
use fricbound::model::Problem;
use fricbound::numerics::NewtonFailure;
use fricbound::scene::{self, paper_wedge_scene};

fn paper(overrides: &[&str]) -> Problem {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::parse(paper_wedge_scene(), "paper", &overrides)
        .and_then(|s| s.validate("paper"))
        .unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}

/// Every event an observer receives, in order, as text (`{:?}` of an f64 is its shortest
/// round-trip form, so equal texts are equal bits, NaN included).
#[derive(Default)]
struct Recorder {
    events: Vec<String>,
    /// Points received without an estimate.
    without_estimate: usize,
}

impl FrfObserver for Recorder {
    fn point(&mut self, point: &FrfPoint) {
        if point.accuracy.is_none() || point.pending_estimate.is_some() {
            self.without_estimate += 1;
        }
        self.events.push(format!("point {point:?}"));
    }
    fn step_cut(&mut self, freq_hz: f64, step: f64, new_step: f64, reason: &NewtonFailure) {
        self.events
            .push(format!("cut {freq_hz:?} {step:?} {new_step:?} {reason:?}"));
    }
    fn turning_point(&mut self, freq_hz: f64) {
        self.events.push(format!("turn {freq_hz:?}"));
    }
    fn jump(&mut self, jump: &Jump) {
        self.events.push(format!("jump {jump:?}"));
    }
}

fn run_recorded(p: &Problem) -> (FrfRun, Recorder) {
    let mut recorder = Recorder::default();
    let run = frf::solve(p, &mut recorder).unwrap();
    (run, recorder)
}

/// The points of a run as text, without the timing.
fn points_text(run: &FrfRun) -> String {
    format!(
        "{:?} {:?} {:?} {:?}",
        run.points, run.jumps, run.turning_points, run.rejected_steps
    )
}

#[test]
fn estimates_on_workers_equal_the_inline_ones_and_keep_the_events_in_order() {
    let p = paper(&["static_loads.0.value=-1"]);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (inline, inline_events) = one.install(|| {
        assert_eq!(
            EstimatePool::default_workers(),
            0,
            "inline inside a rayon job"
        );
        run_recorded(&p)
    });
    let pooled_workers = std::thread::spawn(EstimatePool::default_workers)
        .join()
        .unwrap();
    assert!(pooled_workers >= 1, "{pooled_workers}");
    let (pooled, pooled_events) = std::thread::spawn(move || run_recorded(&p)).join().unwrap();

    assert!(
        inline.rejected_steps > 0 && !inline.turning_points.is_empty(),
        "{} step cuts, turning points {:?}",
        inline.rejected_steps,
        inline.turning_points
    );
    assert!(inline.points.len() > 100, "{}", inline.points.len());
    assert!(inline.points.iter().all(|q| q.accuracy.is_some()));
    assert!(pooled
        .points
        .iter()
        .all(|q| q.accuracy.is_some() && q.pending_estimate.is_none()));
    assert_eq!(points_text(&inline), points_text(&pooled));
    assert_eq!(inline_events.without_estimate, 0);
    assert_eq!(pooled_events.without_estimate, 0);
    assert_eq!(inline_events.events.len(), pooled_events.events.len());
    for (k, (a, b)) in inline_events
        .events
        .iter()
        .zip(&pooled_events.events)
        .enumerate()
    {
        assert_eq!(a, b, "event {k}");
    }
}

/// What the pool gives for a job whose estimator panics (a point of the wrong length: the
/// estimator indexes past its end) followed by a good point, with `workers` workers: the
/// panicking job's estimate and then the good one's (None where no worker is left).
fn after_a_panic(workers: usize) -> (Option<PointAccuracy>, Option<PointAccuracy>) {
    let p = paper(&["analysis.freq_start_hz=100", "analysis.freq_end_hz=101"]);
    let refined = EstimateProblems::new(&p).expect("the estimate is on by default");
    let run = frf::solve(&p, &mut Silent).expect("FRF over 100-101 Hz");
    let point = &run.points[0];
    let omega = 2.0 * PI * point.freq_hz;
    std::thread::scope(|scope| {
        let pool = EstimatePool::start(scope, &p, &refined, workers).expect("pool");
        let wait = |x: &[f64]| match pool.submit(x, omega, None, &point.states) {
            Submitted::Ready(_) => panic!("{workers} workers estimate inline"),
            Submitted::Pending(ticket) => pool.wait(ticket),
        };
        (wait(&[]), wait(&point.coefficients))
    })
}

/// A panic inside an estimate worker does not leave the run waiting for that point's
/// estimate for ever: the point gets a NaN estimate (not formed), its worker stops, and the
/// other workers estimate the points after it; with no worker left the next estimate is
/// reported lost (None) instead of waited for. Run under a watchdog, so that a regression
/// fails the test instead of hanging it.
#[test]
fn a_panicking_estimate_is_not_formed_and_the_pool_goes_on() {
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = sender.send((after_a_panic(2), after_a_panic(1)));
    });
    let ((bad, good), (bad_alone, after)) = receiver
        .recv_timeout(std::time::Duration::from_secs(300))
        .expect("the pool answered within 5 minutes");
    for bad in [bad, bad_alone] {
        let bad = bad.expect("the panicking job is answered");
        assert_eq!(bad.method, EstimateMethod::None);
        assert!(bad.truncation.iter().all(|v| v.is_nan()), "{bad:?}");
        assert!(bad.sampling.iter().all(|v| v.is_nan()), "{bad:?}");
    }
    let good = good.expect("the other worker estimates the next point");
    assert_ne!(good.method, EstimateMethod::None, "{good:?}");
    assert!(good.truncation.iter().all(|v| v.is_finite()), "{good:?}");
    assert!(after.is_none(), "{after:?}");
}
