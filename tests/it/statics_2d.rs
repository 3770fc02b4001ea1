//! The static pre-solve of `effects.coupling = "uncoupled"` with 2D-friction points
//! (`law = "jenkins-2d"`): the static 2D law from rest (radial return onto the friction circle)
//! and its consistent tangent against central differences in every regime, the assembled static
//! Jacobian against central differences of the static residual, the 3D paper system with the
//! out-of-plane motion constrained against the planar one (static solution and FRF points), an
//! out-of-plane static load that makes a point slip off t₁, and the uncoupled FRF of a 2D case
//! in every formulation.

use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::contact::Jenkins2dLaw;
use fricbound::hbm::statics::{static_point_2d, static_solve, StaticSystem};
use fricbound::hbm::{check_jacobian, HbmSystem};
use fricbound::model::{Formulation, Problem};

use crate::common;
use common::{
    assert_formulations_agree, compare_on_planar_path, excited_out_of_plane, planar, problem,
    IN_PLANE, OUT_OF_PLANE, OUT_OF_PLANE_RUN, SPATIAL,
};

/// The damper's out-of-plane DOF (zD) in the 3D scene.
const Z_DAMPER: usize = 8;

const LAW: Jenkins2dLaw = Jenkins2dLaw {
    kt: 3.0e5,
    kn: 2.0e5,
    mu: 0.5,
    initial_state: [0.0, 0.0],
};

/// Largest difference between the law's tangent and central differences of its forces.
fn law_tangent_error(u: [f64; 2], v: f64) -> f64 {
    let point = static_point_2d(&LAW, u, v);
    let forces = |x: [f64; 3]| {
        let p = static_point_2d(&LAW, [x[0], x[1]], x[2]);
        [p.tangential[0], p.tangential[1], p.normal]
    };
    let h = 1e-9;
    let mut worst = 0.0_f64;
    for col in 0..3 {
        let mut plus = [u[0], u[1], v];
        let mut minus = plus;
        plus[col] += h;
        minus[col] -= h;
        let (fp, fm) = (forces(plus), forces(minus));
        for row in 0..3 {
            let fd = (fp[row] - fm[row]) / (2.0 * h);
            worst = worst.max((fd - point.tangent[row][col]).abs());
        }
    }
    worst
}

#[test]
fn static_2d_law_and_its_tangent_match_central_differences_in_every_regime() {
    let v = 1e-3; // N = 200 N, μN = 100 N
    let limit = LAW.mu * LAW.kn * v;
    // Stuck: |T_pred| = kₜ|u| < μN, T = kₜ u, tangent kₜ I₂.
    let u = [1e-4, -2e-4];
    let stuck = static_point_2d(&LAW, u, v);
    assert_eq!(stuck.tangential, [LAW.kt * u[0], LAW.kt * u[1]]);
    assert_eq!(stuck.normal, LAW.kn * v);
    assert!(law_tangent_error(u, v) <= 1e-6 * LAW.kt);
    // Slipping along directions that rotate around the circle (|T_pred| = 600 N > μN).
    for i in 0..12 {
        let angle = 0.3 + i as f64 * std::f64::consts::TAU / 12.0;
        let u = [2e-3 * angle.cos(), 2e-3 * angle.sin()];
        let p = static_point_2d(&LAW, u, v);
        let size = p.tangential[0].hypot(p.tangential[1]);
        assert!(
            (size - limit).abs() <= 1e-12 * limit,
            "|T| = {size}, μN = {limit}"
        );
        let predictor = [LAW.kt * u[0], LAW.kt * u[1]];
        let cross = p.tangential[0] * predictor[1] - p.tangential[1] * predictor[0];
        let dot = p.tangential[0] * predictor[0] + p.tangential[1] * predictor[1];
        assert!(cross.abs() <= 1e-12 * size * LAW.kt * 2e-3 && dot > 0.0);
        let error = law_tangent_error(u, v);
        assert!(
            error <= 1e-6 * LAW.kt,
            "slip at {angle:.3} rad: {error:.3e}"
        );
        // The tangent is not the stuck one: the radial return's (μN/|T_pred|) kₜ (I − t̂t̂ᵀ).
        assert!(p.tangent[0][0] < 0.5 * LAW.kt);
        assert!(p.tangent[0][2].abs() + p.tangent[1][2].abs() > 0.0);
    }
    // Open: no force, no tangent.
    let open = static_point_2d(&LAW, [1e-3, 1e-3], -1e-4);
    assert_eq!(open.tangential, [0.0, 0.0]);
    assert_eq!(open.normal, 0.0);
    assert!(open.tangent.iter().flatten().all(|&x| x == 0.0));
    assert_eq!(law_tangent_error([1e-3, 1e-3], -1e-4), 0.0);
    // Motion along t₁ only: exactly the 1D static law T = clamp(kₜu, −μN, μN).
    for u1 in [-2e-3, -1e-4, 0.0, 3e-4, 5e-3] {
        let p = static_point_2d(&LAW, [u1, 0.0], v);
        assert_eq!(p.tangential[0], (LAW.kt * u1).clamp(-limit, limit));
        assert_eq!(p.tangential[1], 0.0);
    }
}

/// The 3D scene in the uncoupled mode.
fn uncoupled_3d(overrides: &[&str]) -> Problem {
    let mut all = vec!["effects.coupling=uncoupled"];
    all.extend_from_slice(overrides);
    problem(SPATIAL, &all)
}

/// Largest entry-wise difference between the assembled static Jacobian at q and central
/// differences of the static residual, relative to the largest entry.
fn assembled_jacobian_error(p: &Problem, q: &[f64]) -> f64 {
    let system = StaticSystem::new(p);
    let n = q.len();
    let mut jac = system.new_jacobian();
    let mut r = vec![0.0; n];
    system.evaluate(q, &mut r, Some(&mut jac));
    let analytic = jac.to_dense();
    let h = 1e-10;
    let (mut worst, mut largest) = (0.0_f64, 0.0_f64);
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    for col in 0..n {
        let mut x = q.to_vec();
        x[col] += h;
        system.evaluate(&x, &mut rp, None);
        x[col] -= 2.0 * h;
        system.evaluate(&x, &mut rm, None);
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * h);
            worst = worst.max((fd - analytic[(row, col)]).abs());
            largest = largest.max(analytic[(row, col)].abs());
        }
    }
    worst / largest
}

/// Regimes of the two contacts at q: "stuck", "slip" (with |T₂| > 1 % of |T|), "slip-t1" or
/// "open".
fn regimes(p: &Problem, q: &[f64]) -> Vec<&'static str> {
    p.contacts
        .iter()
        .map(|c| {
            let law = c.law_2d().unwrap();
            let v = c.normal_of(q) - c.gap;
            if v < 0.0 {
                return "open";
            }
            let u = [c.tangential_of(q), c.second_tangential_of(q)];
            let size = law.kt * u[0].hypot(u[1]);
            if size <= law.mu * law.kn * v {
                "stuck"
            } else if u[1].abs() > 0.01 * u[0].hypot(u[1]) {
                "slip"
            } else {
                "slip-t1"
            }
        })
        .collect()
}

#[test]
fn assembled_static_jacobian_matches_central_differences() {
    for formulation in [Formulation::Dense, Formulation::Sparse] {
        let mut p = uncoupled_3d(&[]);
        p.analysis.formulation = formulation;
        let mut seen = Vec::new();
        // Damper pushed down and sideways: the left point stuck with a tilted predictor, the
        // right one slipping in a direction off t₁.
        let mut mixed = vec![0.0; 9];
        mixed[6] = -0.577e-3;
        mixed[7] = -1e-3;
        mixed[Z_DAMPER] = 2e-4;
        // Damper lifted: both points open.
        let mut lifted = vec![0.0; 9];
        lifted[7] = 1e-3;
        lifted[Z_DAMPER] = 1e-4;
        for q in [mixed, lifted] {
            let error = assembled_jacobian_error(&p, &q);
            assert!(error <= 1e-6, "{formulation:?}: {error:.3e}");
            seen.extend(regimes(&p, &q));
        }
        for regime in ["stuck", "slip", "open"] {
            assert!(seen.contains(&regime), "{regime} not covered: {seen:?}");
        }
    }
}

#[test]
fn uncoupled_3d_paper_system_equals_the_planar_one() {
    let overrides = [
        "effects.coupling=uncoupled",
        "analysis.freq_start_hz=200",
        "analysis.freq_end_hz=235",
    ];
    let planar = planar(&overrides);
    let spatial = problem(SPATIAL, &overrides);
    // Static solutions.
    let a = static_solve(&planar).unwrap();
    let b = static_solve(&spatial).unwrap();
    let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (k, &d) in IN_PLANE.iter().enumerate() {
        assert!(
            (a[k] - b[d]).abs() <= 1e-10 * scale,
            "static DOF {d}: {} vs {}",
            a[k],
            b[d]
        );
    }
    for &d in &OUT_OF_PLANE {
        assert_eq!(b[d], 0.0);
    }
    // FRF points from the same guesses (harmonics ≥ 1 only in the uncoupled mode).
    let (largest, pairs) = compare_on_planar_path(&planar, &spatial, (200.0, 235.0), 8, 1e-10);
    let slipping = pairs
        .iter()
        .filter(|(a, _)| a.states.iter().any(|s| s.is_unique()))
        .count();
    println!("largest in-plane FRF difference / scale: {largest:.3e}, {slipping} points with slip");
    assert!(slipping >= 3, "only {slipping} points with slip compared");
}

/// The 3D scene, uncoupled, with an out-of-plane static load on the damper (N).
fn with_out_of_plane_static_load(load: f64, overrides: &[&str]) -> Problem {
    let mut p = uncoupled_3d(overrides);
    p.static_load[Z_DAMPER] += load;
    p
}

#[test]
fn out_of_plane_static_load_slips_a_point_off_t1() {
    let p = with_out_of_plane_static_load(100.0, &[]);
    let q = static_solve(&p).unwrap();
    // Independent check of the solution: forces of each point from the radial return written
    // out here, and the equilibrium K q + F_c = F_static.
    let mut r: Vec<f64> = p.static_load.iter().map(|f| -f).collect();
    p.model.stiffness.mul_add(1.0, &q, &mut r);
    let mut off_t1 = 0;
    for c in &p.contacts {
        let law = c.law_2d().unwrap();
        let v = c.normal_of(&q) - c.gap;
        assert!(v > 0.0, "{} open", c.name);
        let normal = law.kn * v;
        let predictor = [
            law.kt * c.tangential_of(&q),
            law.kt * c.second_tangential_of(&q),
        ];
        let size = predictor[0].hypot(predictor[1]);
        let limit = law.mu * normal;
        let t = if size <= limit {
            predictor
        } else {
            [limit * predictor[0] / size, limit * predictor[1] / size]
        };
        let second = &c.second_tangent.as_ref().unwrap().row;
        for (row, force) in [(&c.tangential, t[0]), (second, t[1]), (&c.normal, normal)] {
            for &(d, a) in row {
                r[d] += a * force;
            }
        }
        println!(
            "{}: N = {normal:.6} N, T = ({:.6}, {:.6}) N, |T|/μN = {:.12}",
            c.name,
            t[0],
            t[1],
            t[0].hypot(t[1]) / limit
        );
        if size > limit && t[1].abs() > 0.1 * limit && t[0].abs() > 0.1 * limit {
            off_t1 += 1;
            let tangential = t[0].hypot(t[1]);
            assert!((tangential - limit).abs() <= 1e-10 * limit);
            let cross = t[0] * predictor[1] - t[1] * predictor[0];
            assert!(cross.abs() <= 1e-10 * tangential * size);
            assert!(t[0] * predictor[0] + t[1] * predictor[1] > 0.0);
        }
    }
    let f = p.static_load.iter().map(|x| x * x).sum::<f64>().sqrt();
    let residual = r.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(
        residual <= 1e-10 * f,
        "equilibrium residual {residual:.3e} N"
    );
    assert!(off_t1 >= 1, "no point slips off t₁");
    // The HBM system takes this static solution as its fixed 0th harmonic.
    let system = HbmSystem::new(&p).unwrap();
    assert_eq!(system.static_offset(), &q[..]);
    // Its assembled Jacobian at the solution.
    let error = assembled_jacobian_error(&p, &q);
    assert!(error <= 1e-6, "{error:.3e}");
}

#[test]
fn uncoupled_frf_with_2d_points_agrees_across_formulations() {
    let build = |formulation: Formulation| {
        excited_out_of_plane(
            with_out_of_plane_static_load(40.0, &OUT_OF_PLANE_RUN),
            formulation,
        )
    };
    let dense = build(Formulation::Dense);
    let run = frf::solve(&dense, &mut Silent).unwrap();
    let mut reference = PointSolver::new(&dense).unwrap();
    let variants = [
        ("sparse", build(Formulation::Sparse)),
        ("condensed", build(Formulation::Condensed)),
        ("schur", build(Formulation::Schur)),
    ];
    let mut compared = 0;
    let mut slipping = 0;
    for p in run.points.iter().step_by((run.points.len() / 10).max(1)) {
        let f = p.freq_hz;
        let a = assert_formulations_agree(&mut reference, &variants, &p.coefficients, f);
        compared += 1;
        if a.states.iter().any(|s| s.is_unique()) {
            slipping += 1;
            // The analytic HBM Jacobian around the fixed 0th harmonic of 2D points against
            // central differences of the residual (dense and sparse storage).
            let omega = 2.0 * std::f64::consts::PI * f;
            for (name, p) in [("dense", &dense), ("sparse", &variants[0].1)] {
                let mut system = HbmSystem::new(p).unwrap();
                let check = check_jacobian(&mut system, &a.coefficients, omega, 1e-7).unwrap();
                assert!(
                    check.relative() < 1e-6,
                    "{name} at {f:.3} Hz: {:.3e}",
                    check.relative()
                );
            }
        }
    }
    println!("{compared} points compared, {slipping} with slip");
    assert!(compared >= 6);
    assert!(slipping >= 3, "only {slipping} points with slip compared");
}
