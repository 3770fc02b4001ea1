//! The judgement of a branch an FRF run abandoned ([`Jump::end_check`]), checked again by
//! fixed-frequency Newton solves of [`PointSolver`].

use fricbound::analysis::frf::{CutVerdict, FrfRun, Jump, PointSolver};
use fricbound::model::Problem;

/// Relative distance between two coefficient vectors, over the second's norm.
fn distance(a: &[f64], reference: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(reference).map(|(u, v)| (u - v).powi(2)).sum();
    let n: f64 = reference.iter().map(|v| v * v).sum();
    (d / n).sqrt()
}

/// For every jump of `run` whose branch before was abandoned ([`Jump::abandons_branch`]): the
/// run judged it ([`Jump::end_check`]) and not covered; where Newton landed past the point
/// given up, `PointSolver` from that point at the landing's frequency lands there too (the
/// same first-output amplitude within 10⁻⁶), and no crossing of the run at that frequency
/// holds that solution: each differs from it by more than 1 % on the first output's amplitude,
/// or Newton from the crossing's nearer point at that frequency converges to another solution
/// (more than 10⁻⁸ apart on the coefficients) or nowhere. Returns the abandoned jumps.
pub fn abandoned_branches_are_off_the_run(p: &Problem, run: &FrfRun, label: &str) -> Vec<Jump> {
    let mut solver = PointSolver::new(p).expect("point solver");
    let mut abandoned = Vec::new();
    for jump in run.jumps.iter().filter(|j| j.abandons_branch()) {
        let check = jump
            .end_check
            .unwrap_or_else(|| panic!("{label}: the abandoned branch is not judged: {jump:?}"));
        assert_ne!(check.verdict, CutVerdict::Covered, "{label}: {check:?}");
        abandoned.push(*jump);
        let Some(amplitude) = check.landing.amplitude else {
            assert_eq!(check.verdict, CutVerdict::Unjudged, "{label}: {check:?}");
            continue;
        };
        let f = check.landing.freq_hz;
        let given_up = &run.points[jump.first_point - 1];
        let landing = solver
            .solve(&given_up.coefficients, f)
            .unwrap_or_else(|e| panic!("{label}: Newton past the point given up, at {f} Hz: {e}"));
        assert!(
            (landing.amplitudes[0] - amplitude).abs() <= 1e-6 * amplitude,
            "{label}: {} m against the judgement's {amplitude} m at {f} Hz",
            landing.amplitudes[0]
        );
        for crossing in run.crossings(f, 0) {
            if (crossing.amplitude - amplitude).abs() > 1e-2 * amplitude {
                continue;
            }
            let start = &run.points[crossing.nearest_point].coefficients;
            if let Ok(q) = solver.solve(start, f) {
                let d = distance(&q.coefficients, &landing.coefficients);
                assert!(
                    d > 1e-8,
                    "{label}: the landing at {f} Hz ({amplitude} m) is the solution of the run's \
                     crossing at point {} ({d:e} apart)",
                    crossing.nearest_point
                );
            }
        }
    }
    abandoned
}
