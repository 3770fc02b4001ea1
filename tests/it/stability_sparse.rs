//! Hill stability by the sparse shift-invert solve (`analysis::stability_sparse`): on a linear
//! chain the exponents are the damped eigenvalues; on the paper system (below the dense limit)
//! the leading exponent and verdict are the dense solve's at stuck and stick-slip points; above
//! the limit (a chain of 90 masses, 630 unknowns) the dense solve's at one point, and a run
//! fills every point's verdict, checked against the dense solve.

use std::f64::consts::PI;
use std::time::Instant;

use faer::{c64, Mat};
use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::analysis::stability::{VerdictSource, MAX_HILL_UNKNOWNS};
use fricbound::analysis::stability_sparse::{
    floquet_exponents_shift_invert, point_stability_with, HillSolver, ShiftInvertSettings,
};
use fricbound::contact::ContactState;
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::study::jacobian::chain_scene;

use crate::common;
use common::linear::damped_eigenvalues;
use common::scenes::{paper, problem};

#[test]
fn below_the_dense_limit_shift_invert_gives_the_dense_leading_exponent_and_verdict() {
    // The paper system at H = 3 (6 DOFs × 7 blocks = 42 unknowns) over its 2nd and 3rd
    // resonances: stuck and stick-slip points.
    let problem = paper(&[
        "analysis.freq_start_hz=150.0",
        "analysis.freq_end_hz=235.0",
        "harmonics.max=3",
    ]);
    let run = frf::solve(&problem, &mut Silent).unwrap();
    let mut solver = PointSolver::new(&problem).unwrap();
    let settings = HillSolver::ShiftInvert(ShiftInvertSettings::default());
    let (mut stuck, mut slipping, mut checked) = (0, 0, 0);
    let step = (run.points.len() / 12).max(1);
    for p in run.points.iter().step_by(step) {
        let omega = 2.0 * PI * p.freq_hz;
        let t0 = Instant::now();
        let dense =
            point_stability_with(solver.system(), &p.coefficients, omega, &HillSolver::Dense)
                .unwrap();
        let t1 = Instant::now();
        let sparse =
            point_stability_with(solver.system(), &p.coefficients, omega, &settings).unwrap();
        let t2 = Instant::now();
        let all_stuck = p
            .states
            .iter()
            .all(|s| matches!(s, ContactState::Stuck | ContactState::Open));
        println!(
            "{:.2} Hz {:?}: dense {} {:.6} 1/s {:.2} Hz ({:.1} ms); shift-invert {} {:.6} 1/s {:.2} Hz ({:.1} ms)",
            p.freq_hz,
            p.states,
            dense.stable,
            dense.floquet_re,
            dense.floquet_freq_hz,
            (t1 - t0).as_secs_f64() * 1e3,
            sparse.stable,
            sparse.floquet_re,
            sparse.floquet_freq_hz,
            (t2 - t1).as_secs_f64() * 1e3
        );
        assert!(
            sparse.reliable || !dense.reliable,
            "{} Hz: incomplete",
            p.freq_hz
        );
        assert_eq!(dense.stable, sparse.stable, "{} Hz", p.freq_hz);
        assert_eq!(dense.reliable, sparse.reliable, "{} Hz", p.freq_hz);
        assert!(
            (dense.floquet_freq_hz - sparse.floquet_freq_hz).abs()
                <= 1e-6 * dense.floquet_freq_hz + 1e-6
        );
        let tol = 1e-6 * dense.floquet_re.abs() + 1e-9 * omega;
        assert!(
            (dense.floquet_re - sparse.floquet_re).abs() <= tol,
            "{} Hz: dense {dense:?} vs shift-invert {sparse:?}",
            p.freq_hz
        );
        if all_stuck {
            stuck += 1;
        } else {
            slipping += 1;
        }
        checked += 1;
    }
    assert!(
        stuck > 0 && slipping > 0,
        "{stuck} stuck, {slipping} slipping"
    );
    assert!(checked >= 8);
}

#[test]
fn on_a_linear_chain_the_exponents_are_the_damped_eigenvalues() {
    // 12 masses with Rayleigh-plus damping (study::jacobian::chain_scene), H = 3; the
    // Jacobian is the linear one of M, C, K (the chain's contact removed).
    let problem = problem(&chain_scene(12, 1, 3), &[]);
    let expected: Vec<c64> = damped_eigenvalues(&problem)
        .into_iter()
        .filter(|x| x.im >= 0.0)
        .collect();
    let set = problem.unknown_harmonics();
    for freq_hz in [8.0, 17.3, 30.0] {
        let omega = 2.0 * PI * freq_hz;
        let lin = linear_jacobian(&problem, &set, omega);
        let mut triplets = Vec::new();
        for j in 0..lin.ncols() {
            for i in 0..lin.nrows() {
                if lin[(i, j)] != 0.0 {
                    triplets.push((i, j, lin[(i, j)]));
                }
            }
        }
        let found = floquet_exponents_shift_invert(
            &problem.model,
            &set,
            &triplets,
            omega,
            &ShiftInvertSettings::default(),
        )
        .unwrap();
        println!(
            "{freq_hz} Hz: {} exponents from {} shifts (radii {:?}), {} uncovered",
            found.exponents.len(),
            found.shifts.len(),
            found.radii,
            found.uncovered
        );
        assert!(found.complete, "{freq_hz} Hz: {found:?}");
        assert_eq!(found.exponents.len(), expected.len(), "{freq_hz} Hz");
        for x in &expected {
            let nearest = found
                .exponents
                .iter()
                .map(|e| (e - x).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest <= 1e-9 * x.norm(),
                "{freq_hz} Hz: damped eigenvalue {x} found only {nearest:.3e} away"
            );
        }
    }
}

#[test]
fn above_the_dense_limit_it_runs_and_says_whether_it_found_every_exponent() {
    // 90 masses, 4 Jenkins elements to ground, H = 3: 630 unknowns.
    let problem = problem(&chain_scene(90, 4, 3), &[]);
    let set = problem.unknown_harmonics();
    assert!(problem.model.n_dofs() * set.n_blocks() > MAX_HILL_UNKNOWNS);
    let mut solver = PointSolver::new(&problem).unwrap();
    let freq_hz = 5.0;
    let omega = 2.0 * PI * freq_hz;
    let guess = fricbound::analysis::linear::stuck_guess(&problem, &set, omega).unwrap();
    let point = solver.solve(&guess, freq_hz).unwrap();
    let t0 = Instant::now();
    let hill = point_stability_with(
        solver.system(),
        &point.coefficients,
        omega,
        &HillSolver::ShiftInvert(ShiftInvertSettings::default()),
    )
    .unwrap();
    let t1 = Instant::now();
    let dense = point_stability_with(
        solver.system(),
        &point.coefficients,
        omega,
        &HillSolver::Dense,
    )
    .unwrap();
    let t2 = Instant::now();
    println!(
        "{freq_hz} Hz {:?}: shift-invert {} {:.6} 1/s {:.3} Hz reliable {} in {:.1} ms; dense {} {:.6} 1/s {:.3} Hz in {:.1} ms",
        point.states,
        hill.stable,
        hill.floquet_re,
        hill.floquet_freq_hz,
        hill.reliable,
        (t1 - t0).as_secs_f64() * 1e3,
        dense.stable,
        dense.floquet_re,
        dense.floquet_freq_hz,
        (t2 - t1).as_secs_f64() * 1e3
    );
    // Every estimate covered, and the dense verdict and leading exponent.
    assert!(hill.reliable, "some estimated exponent not covered");
    assert_eq!(hill.stable, dense.stable);
    assert!(
        (hill.floquet_re - dense.floquet_re).abs() <= 1e-6 * dense.floquet_re.abs() + 1e-9 * omega
    );
    assert!((hill.floquet_freq_hz - dense.floquet_freq_hz).abs() <= 1e-6 * dense.floquet_freq_hz);

    // With the coverage limited to exponents below twice the leading one's frequency
    // (`analysis.hill_max_freq_hz`), fewer shifts find the same leading exponent.
    let limit = 2.0 * dense.floquet_freq_hz.max(freq_hz);
    let t3 = Instant::now();
    let limited = point_stability_with(
        solver.system(),
        &point.coefficients,
        omega,
        &HillSolver::ShiftInvert(ShiftInvertSettings {
            max_freq_hz: Some(limit),
            ..ShiftInvertSettings::default()
        }),
    )
    .unwrap();
    println!(
        "limited to {limit:.2} Hz: {} {:.6} 1/s {:.3} Hz reliable {} in {:.1} ms",
        limited.stable,
        limited.floquet_re,
        limited.floquet_freq_hz,
        limited.reliable,
        t3.elapsed().as_secs_f64() * 1e3
    );
    assert!(limited.reliable);
    assert_eq!(limited.stable, dense.stable);
    assert!(
        (limited.floquet_re - dense.floquet_re).abs()
            <= 1e-6 * dense.floquet_re.abs() + 1e-9 * omega
    );
}

#[test]
fn the_coverage_limit_is_checked_at_the_door() {
    let text = chain_scene(12, 1, 3);
    let refused = |o: &[&str]| {
        let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
        let err = scene::parse(&text, "case", &o)
            .unwrap()
            .validate("case")
            .expect_err("refused")
            .to_string();
        assert!(err.contains("analysis.hill_max_freq_hz"), "{err}");
    };
    refused(&["analysis.stability=true", "analysis.hill_max_freq_hz=-5"]);
    refused(&["analysis.hill_max_freq_hz=50"]);
    refused(&[
        "analysis.stability=true",
        "analysis.hill_solver=dense",
        "analysis.hill_max_freq_hz=50",
    ]);
    let ok = problem(
        &text,
        &[
            "analysis.stability=true",
            "analysis.hill_solver=shift-invert",
            "analysis.hill_max_freq_hz=50",
        ],
    );
    assert_eq!(ok.analysis.hill_max_freq_hz, Some(50.0));
}

#[test]
fn a_run_above_the_dense_limit_fills_the_stability_columns_by_shift_invert() {
    // 90 masses, 4 Jenkins elements, H = 3 (630 unknowns): the scene check no longer refuses
    // stability; the run's points get Hill verdicts by the shift-invert solve, checked against
    // the dense solve at one point.
    let problem = problem(
        &chain_scene(90, 4, 3),
        &[
            "analysis.stability=true",
            "analysis.freq_start_hz=5.0",
            "analysis.freq_end_hz=5.3",
        ],
    );
    let set = problem.unknown_harmonics();
    assert!(problem.model.n_dofs() * set.n_blocks() > MAX_HILL_UNKNOWNS);
    let run = frf::solve(&problem, &mut Silent).unwrap();
    assert!(run.points.len() >= 2);
    for p in &run.points {
        let s = p.stability.expect("every point has a verdict");
        assert_eq!(s.method, VerdictSource::HillSparse, "{} Hz", p.freq_hz);
        assert!(s.floquet_re.is_finite() && s.floquet_freq_hz.is_finite());
    }
    // The middle point against the dense solve of the whole Hill spectrum (the monodromy of
    // the time integration, tried here, agreed on the verdict but took over two minutes).
    let p = &run.points[run.points.len() / 2];
    let hill = p.stability.unwrap();
    let mut solver = PointSolver::new(&problem).unwrap();
    let omega = 2.0 * PI * p.freq_hz;
    let dense =
        point_stability_with(solver.system(), &p.coefficients, omega, &HillSolver::Dense).unwrap();
    println!(
        "{:.3} Hz {:?}: hill-sparse {} {:.6} 1/s {:.3} Hz reliable {}; dense {} {:.6} 1/s {:.3} Hz",
        p.freq_hz,
        p.states,
        hill.stable,
        hill.floquet_re,
        hill.floquet_freq_hz,
        hill.reliable,
        dense.stable,
        dense.floquet_re,
        dense.floquet_freq_hz,
    );
    assert!(hill.reliable);
    assert_eq!(hill.stable, dense.stable);
    assert!(
        (hill.floquet_re - dense.floquet_re).abs() <= 1e-6 * dense.floquet_re.abs() + 1e-9 * omega
    );
}

/// The linear harmonic-balance Jacobian of the problem's M, C, K (paper Eq. 7 without
/// contacts): K − (hω)²M on every block, +hωC from sine to cosine, −hωC back.
fn linear_jacobian(
    problem: &Problem,
    set: &fricbound::contact::harmonic::HarmonicSet,
    omega: f64,
) -> Mat<f64> {
    use fricbound::contact::harmonic::Block;
    let n = problem.model.n_dofs();
    let (m, c, k) = (
        problem.model.mass.to_dense(),
        problem.model.damping.to_dense(),
        problem.model.stiffness.to_dense(),
    );
    let nb = set.n_blocks();
    let mut j = Mat::zeros(n * nb, n * nb);
    for (jb, block) in set.blocks().iter().enumerate() {
        let hw = block.harmonic() as f64 * omega;
        let partner = match block {
            Block::Cos(h) => set.sin_block(*h).map(|s| (s, 1.0)),
            Block::Sin(h) => set.cos_block(*h).map(|s| (s, -1.0)),
            Block::Constant => None,
        };
        for r in 0..n {
            for q in 0..n {
                j[(jb * n + r, jb * n + q)] = k[(r, q)] - hw * hw * m[(r, q)];
                if let Some((pb, sign)) = partner {
                    j[(jb * n + r, pb * n + q)] = sign * hw * c[(r, q)];
                }
            }
        }
    }
    j
}
