//! Hill stability by the sparse shift-invert solve (`analysis::stability_sparse`, not yet used
//! by runs). Passing today: above
//! the dense limit (a chain of 90 masses with Jenkins elements, 630 unknowns) it runs, gives
//! the dense verdict, and its leading exponent is the dense one when it reports having found
//! every exponent (else marked not reliable). Ignored because they fail today (see the module's
//! Status): the comparison with the dense solve on the paper case, and the check that on a
//! linear chain every exponent found is a damped eigenvalue.

use std::f64::consts::PI;
use std::time::Instant;

use faer::linalg::solvers::DenseSolveCore;
use faer::{c64, Mat};
use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::analysis::stability::{MAX_HILL_UNKNOWNS, STABILITY_TOLERANCE};
use fricbound::analysis::stability_sparse::{
    floquet_exponents_shift_invert, point_stability_with, HillSolver, ShiftInvertSettings,
};
use fricbound::contact::ContactState;
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::study::jacobian::chain_scene;

fn problem(text: &str, overrides: &[String]) -> Problem {
    scene::parse(text, "case", overrides)
        .unwrap()
        .validate("case")
        .unwrap()
}

/// The damped eigenvalues of λ²M + λC + K (first-order form).
fn damped_eigenvalues(problem: &Problem) -> Vec<c64> {
    let n = problem.model.n_dofs();
    let (m, c, k) = (
        problem.model.mass.to_dense(),
        problem.model.damping.to_dense(),
        problem.model.stiffness.to_dense(),
    );
    let minv = m.as_ref().partial_piv_lu().inverse();
    let (mk, mc) = (&minv * &k, &minv * &c);
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - n == i)),
        (false, true) => -mk[(i - n, j)],
        (false, false) => -mc[(i - n, j - n)],
    });
    a.eigenvalues().unwrap()
}

#[test]
#[ignore = "known disagreement at 150 Hz (stuck): shift-invert -0.148 1/s vs dense -0.175 1/s; see analysis::stability_sparse, Status"]
fn below_the_dense_limit_shift_invert_gives_the_dense_leading_exponent_and_verdict() {
    // The paper system at H = 3 (6 DOFs × 7 blocks = 42 unknowns) over its 2nd and 3rd
    // resonances: stuck and stick-slip points.
    let o: Vec<String> = vec![
        "analysis.freq_start_hz=150.0".into(),
        "analysis.freq_end_hz=235.0".into(),
        "harmonics.max=3".into(),
    ];
    let problem = problem(scene::paper_wedge_scene(), &o);
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
        let tol = 1e-6 * dense.floquet_re.abs() + 10.0 * STABILITY_TOLERANCE * omega;
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
#[ignore = "fails: at 8 Hz the exponents found are 0.58 1/s from the chain's damped eigenvalues (a fixture whose mu = 0 contact is not force-free, or an error in the solve: not resolved)"]
fn on_a_linear_chain_every_exponent_found_is_a_damped_eigenvalue_and_completeness_is_reported() {
    // 12 masses, one contact without friction (μ = 0, zero normal: no force), H = 3.
    let problem = problem(&chain_scene(12, 1, 3), &["contacts.0.mu=0".to_string()]);
    let expected = damped_eigenvalues(&problem);
    let set = problem.unknown_harmonics();
    let mut solver = PointSolver::new(&problem).unwrap();
    let system = solver.system();
    for freq_hz in [8.0, 17.3, 30.0] {
        let omega = 2.0 * PI * freq_hz;
        let mut jacobian = system.new_jacobian();
        let dim = system.dim();
        let (mut r, mut dr) = (vec![0.0; dim], vec![0.0; dim]);
        system
            .residual_and_jacobian(&vec![0.0; dim], omega, &mut r, &mut jacobian, &mut dr)
            .unwrap();
        let found = floquet_exponents_shift_invert(
            &problem.model,
            &set,
            &jacobian.triplets(),
            omega,
            &ShiftInvertSettings {
                per_shift: 30,
                krylov: 90,
                ..ShiftInvertSettings::default()
            },
        )
        .unwrap();
        let missing = expected
            .iter()
            .filter(|x| {
                !found
                    .exponents
                    .iter()
                    .any(|e| (e - *x).norm().min((e.conj() - *x).norm()) <= 1e-7 * x.norm())
            })
            .count();
        println!(
            "{freq_hz} Hz: {} exponents found, {missing} of {} damped eigenvalues missing, complete = {}",
            found.exponents.len(),
            expected.len(),
            found.complete
        );
        // The completeness flag tells the truth.
        assert_eq!(found.complete, missing == 0, "{freq_hz} Hz: {found:?}");
        assert!(!found.exponents.is_empty());
        for e in &found.exponents {
            let nearest = expected
                .iter()
                .map(|x| (x - e).norm().min((x.conj() - e).norm()))
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest <= 1e-7 * e.norm(),
                "{freq_hz} Hz: {e} is no damped eigenvalue (nearest at {nearest:.3e})"
            );
        }
        let lead = found
            .exponents
            .iter()
            .map(|e| e.re)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(lead < 0.0);
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
    // The verdict is the dense one; the leading exponent is the dense one whenever the solve
    // says it found every exponent (`reliable`).
    assert_eq!(hill.stable, dense.stable);
    if hill.reliable {
        assert!(
            (hill.floquet_re - dense.floquet_re).abs()
                <= 1e-6 * dense.floquet_re.abs() + 1e-9 * omega
        );
    } else {
        assert!(hill.floquet_re <= dense.floquet_re + 1e-9 * omega);
    }
}
