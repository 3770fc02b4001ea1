//! Floquet multipliers from the monodromy matrix of the time integration's periodic orbit
//! (`analysis::monodromy`): on a linear system they are the trapezoidal rule's images of the
//! damped eigenvalues (and the exponents those eigenvalues to O(dt²)); on the softening fold of
//! `tests/data/liftoff-fold.toml` the saddle branch is unstable with a real multiplier above 1,
//! as Hill's method says, and the branch below the fold stable.

use std::f64::consts::PI;

use faer::{c64, Mat};
use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::analysis::linear;
use fricbound::analysis::monodromy::{monodromy_stability, MonodromySettings};
use fricbound::analysis::stability;
use fricbound::analysis::verify::{self, VerifySettings};
use fricbound::model::matrix::StructuralMatrix;
use fricbound::model::Problem;

use crate::common;
use common::linear::damped_eigenvalues;
use common::scenes::{load, paper};

fn paper_h1() -> Problem {
    paper(&[
        "analysis.freq_start_hz=150.0",
        "analysis.freq_end_hz=230.0",
        "harmonics.max=1",
    ])
}

#[test]
fn linear_multipliers_are_the_trapezoidal_images_of_the_damped_eigenvalues() {
    // Contacts stuck by a large μ all period: the system is linear with the kt, kn springs
    // (the stuck linear model; the contact springs enter K through the stuck reference).
    let mut problem = paper_h1();
    for c in &mut problem.contacts {
        c.law.mu = 1e3;
    }
    let n = problem.model.n_dofs();
    problem.model.damping = StructuralMatrix::Dense(Mat::from_fn(n, n, |i, j| {
        if i == j {
            20.0 + 3.0 * i as f64
        } else {
            0.0
        }
    }));
    let freq = 120.0;
    let mut solver = PointSolver::new(&problem).unwrap();
    let set = solver.system().unknowns().clone();
    let guess = linear::stuck_guess(&problem, &set, 2.0 * PI * freq).unwrap();
    let point = solver.solve(&guess, freq).unwrap();
    let settings = VerifySettings {
        steps_per_period: 256,
        ..VerifySettings::for_harmonics(1)
    };
    let start = verify::hbm_state(&problem, &set, &point.coefficients, freq, 256).unwrap();
    let mono = monodromy_stability(
        &problem,
        freq,
        &start,
        &settings,
        &MonodromySettings::default(),
    )
    .unwrap();
    // Both sliders stuck all period: their unit multipliers are removed, 2n remain.
    assert_eq!(mono.neutral_sliders, vec![0, 1]);
    assert!(mono.orbit_converged, "{mono:?}");
    assert_eq!(mono.multipliers_re.len(), 2 * n);
    assert!(mono.stable);
    // The stuck linear model's damped eigenvalues: K plus the stuck contact springs.
    let mut stuck = problem.clone();
    let mut k_stuck = problem.model.stiffness.to_dense();
    for (i, j, v) in linear::contact_stiffness(&problem) {
        k_stuck[(i, j)] += v;
    }
    stuck.model.stiffness = StructuralMatrix::Dense(k_stuck);
    let s = damped_eigenvalues(&stuck);
    let period = 1.0 / freq;
    let dt = period / 256.0;
    let computed: Vec<c64> = mono
        .multipliers_re
        .iter()
        .zip(&mono.multipliers_im)
        .map(|(&re, &im)| c64::new(re, im))
        .collect();
    let mut worst_map = 0.0_f64;
    let mut worst_exponent = 0.0_f64;
    for &si in &s {
        // One Newmark (trapezoidal) step multiplies the mode by (1 + s dt/2)/(1 − s dt/2).
        let one = c64::new(1.0, 0.0);
        let half = si * c64::new(dt / 2.0, 0.0);
        let step = (one + half) / (one - half);
        let mut rho = one;
        for _ in 0..256 {
            rho *= step;
        }
        let nearest = computed
            .iter()
            .map(|c| (c - rho).norm())
            .fold(f64::INFINITY, f64::min);
        worst_map = worst_map.max(nearest);
        // The exponent of the nearest multiplier against the eigenvalue's real part.
        let c = computed
            .iter()
            .min_by(|a, b| (*a - rho).norm().total_cmp(&(*b - rho).norm()))
            .unwrap();
        let re = c.norm().ln() / period;
        let bound = (si.norm() * dt).powi(2) * si.re.abs();
        worst_exponent = worst_exponent.max((re - si.re).abs() / bound.max(1e-12));
        println!(
            "s = {:.4} {:+.2}i: multiplier {:.8} {:+.8}i, Re λ = {:.5} (exact {:.5})",
            si.re, si.im, c.re, c.im, re, si.re
        );
    }
    println!("largest multiplier error {worst_map:.3e}, exponent error / (|s|dt)²|Re s| {worst_exponent:.3}");
    assert!(worst_map < 1e-6, "{worst_map}");
    // The exponents are the damped eigenvalues' real parts to the scheme's O((|s| dt)²).
    assert!(worst_exponent < 1.0, "{worst_exponent}");
    // The leading exponent is the least damped eigenvalue's real part.
    let least = s.iter().map(|v| v.re).fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (mono.floquet_re - least).abs() < 1e-2 * least.abs(),
        "{} {least}",
        mono.floquet_re
    );
}

fn fold_problem() -> Problem {
    load("tests/data/liftoff-fold.toml", &[])
}

#[test]
fn the_saddle_branch_of_a_softening_fold_has_a_real_multiplier_above_one() {
    let problem = fold_problem();
    let run = frf::solve(&problem, &mut Silent).unwrap();
    let f: Vec<f64> = run.points.iter().map(|p| p.freq_hz).collect();
    let fold = (1..f.len()).find(|&i| f[i] < f[i - 1]).unwrap() - 1;
    let back_end = (fold + 1..f.len())
        .find(|&i| f[i] > f[i - 1])
        .unwrap_or(f.len());
    let settings = VerifySettings::for_harmonics(5);
    let mut solver = PointSolver::new(&problem).unwrap();
    let set = solver.system().unknowns().clone();
    let check = |index: usize, solver: &mut PointSolver| {
        let p = &run.points[index];
        let omega = 2.0 * PI * p.freq_hz;
        let hill = stability::point_stability(solver.system(), &p.coefficients, omega).unwrap();
        let start = verify::hbm_state(&problem, &set, &p.coefficients, p.freq_hz, 1280).unwrap();
        let mono = monodromy_stability(
            &problem,
            p.freq_hz,
            &start,
            &settings,
            &MonodromySettings::default(),
        )
        .unwrap();
        println!(
            "{:.3} Hz (point {index}): Hill {} {:.4} 1/s {:.2} Hz; monodromy {} {:.4} 1/s {:.2} Hz, defect {:.1e} after {} shootings, leading multiplier {:.6} {:+.6}i",
            p.freq_hz, hill.stable, hill.floquet_re, hill.floquet_freq_hz, mono.stable, mono.floquet_re,
            mono.floquet_freq_hz, mono.periodicity_defect, mono.shooting_iterations,
            mono.multipliers_re[0], mono.multipliers_im[0]
        );
        (hill, mono)
    };
    // On the saddle branch, halfway along the first backward stretch.
    let middle = (fold + back_end) / 2;
    let (hill, mono) = check(middle, &mut solver);
    assert!(mono.orbit_converged, "{mono:?}");
    assert!(!hill.stable && !mono.stable);
    assert!(mono.multipliers_re[0] > 1.0 && mono.multipliers_im[0].abs() < 1e-9);
    assert_eq!(mono.floquet_freq_hz, 0.0);
    // Hill's exponent (AFT Jacobian of a smooth-enough law, mu = 0) and the monodromy's agree.
    let rel = (hill.floquet_re - mono.floquet_re).abs() / mono.floquet_re;
    assert!(
        rel < 0.1,
        "Hill {} monodromy {}",
        hill.floquet_re,
        mono.floquet_re
    );
    // On the linear branch below the fold (contact closed all period): stable, both ways.
    let below = fold / 2;
    let (hill, mono) = check(below, &mut solver);
    assert!(hill.stable && mono.stable);
    assert!(
        (hill.floquet_re - mono.floquet_re).abs() < 1e-2 * hill.floquet_re.abs(),
        "Hill {} monodromy {}",
        hill.floquet_re,
        mono.floquet_re
    );
}
