//! The response envelope with 2D tangential friction (`law = "jenkins-2d"`): each side's
//! initial state m = (m₁, m₂) is searched in the unit disc. The disc map and its Jacobian
//! against central differences; the sensitivity dA/dm₂ of a stuck 2D point against central
//! differences of solved amplitudes; and on the 3D paper system with the out-of-plane motion
//! constrained, the disc envelope equals the planar envelope and contains the m = (±1, 0)
//! limit states.

use std::f64::consts::PI;

use fricbound::analysis::frf::PointSolver;
use fricbound::analysis::limits::envelope::{disc_to_square, square_to_disc};
use fricbound::analysis::limits::{
    self, amplitude_sensitivity_of, envelope_at, EnvelopeMode, EnvelopeSeeds, StateVariable,
};
use fricbound::analysis::linear;
use fricbound::contact::ContactState;
use fricbound::model::{HarmonicLoad, Problem};
use fricbound::scene;

use crate::common;
use common::blade_pair::coarse_blade_pair;
use common::envelope::{as_seeds, limit_states, LimitState};
use common::{planar, problem, PLANAR, SPATIAL};

#[test]
fn the_disc_map_is_one_to_one_and_its_jacobian_matches_central_differences() {
    for &s in &[
        [0.3, -0.7],
        [1.0, 0.0],
        [-0.9, 0.95],
        [0.0, 1.0],
        [0.55, 0.55],
    ] {
        let (m, j) = square_to_disc(s);
        assert!(m[0].hypot(m[1]) <= 1.0 + 1e-15, "{s:?} -> {m:?}");
        let back = disc_to_square(m);
        assert!(
            (back[0] - s[0]).abs() < 1e-12 && (back[1] - s[1]).abs() < 1e-12,
            "{s:?} -> {m:?} -> {back:?}"
        );
        let h = 1e-6;
        for b in 0..2 {
            let (mut sp, mut sm) = (s, s);
            sp[b] = (s[b] + h).min(1.0);
            sm[b] = (s[b] - h).max(-1.0);
            let (p, q) = (square_to_disc(sp).0, square_to_disc(sm).0);
            for a in 0..2 {
                let fd = (p[a] - q[a]) / (sp[b] - sm[b]);
                assert!((fd - j[2 * a + b]).abs() < 1e-6, "{s:?} ∂m{a}/∂s{b}");
            }
        }
    }
    // The square's edges go onto the circle; s = (±1, 0) are the limit states m = (±1, 0).
    assert_eq!(square_to_disc([1.0, 0.0]).0, [1.0, 0.0]);
    assert_eq!(square_to_disc([-1.0, 0.0]).0, [-1.0, 0.0]);
    let corner = square_to_disc([1.0, 1.0]).0;
    assert!((corner[0].hypot(corner[1]) - 1.0).abs() < 1e-15);
}

#[test]
fn the_sensitivity_to_both_components_of_a_stuck_2d_point_matches_central_differences() {
    // Out-of-plane load on blade 1 at 160 Hz: the left contact is stuck over the period (for m
    // in a range found below), the right one slips and separates.
    let mut p = problem(
        SPATIAL,
        &["analysis.freq_start_hz=150", "analysis.freq_end_hz=185"],
    );
    p.harmonic_loads.push(HarmonicLoad {
        dof: 2,
        harmonic: 1,
        cos: 10.0,
        sin: 0.0,
    });
    let freq = 160.0;
    let omega = 2.0 * PI * freq;
    let mut solver = PointSolver::new(&p).unwrap();
    let set = solver.system().unknowns().clone();
    let guess = linear::stuck_guess(&p, &set, omega).unwrap();
    let states = |m: [f64; 2]| vec![m, [0.0, 0.0]];
    let variables: Vec<StateVariable> = (0..2)
        .map(|component| StateVariable {
            contacts: vec![0],
            component,
        })
        .collect();
    // The first m (on a grid of the disc, off both axes) at which the left contact stays stuck
    // from its start, so that both components act.
    let grid: Vec<[f64; 2]> = (-4..=4)
        .flat_map(|i| (-4..=4).map(move |j| [0.15 * i as f64, 0.15 * j as f64]))
        .filter(|m| m[0] != 0.0 && m[1] != 0.0 && m[0].hypot(m[1]) < 0.9)
        .collect();
    let (m0, point, s) = grid
        .iter()
        .find_map(|&m| {
            solver.system().set_initial_states_2d(&states(m));
            let point = solver.solve(&guess, freq).ok()?;
            let s =
                amplitude_sensitivity_of(solver.system(), &point.coefficients, omega, &variables)
                    .ok()?;
            println!(
                "m_left = {m:?}: states {:?}, active {:?}, effective {:?}",
                point.states, s.active, s.effective
            );
            (s.active == [true, true]).then_some((m, point, s))
        })
        .expect("an m at which the left contact sticks from its start");
    assert_eq!(point.states[0], ContactState::Stuck);
    let h = 1e-5;
    for a in 0..2 {
        let mut amplitude = |sign: f64| {
            let mut m = m0;
            m[a] += sign * h;
            solver.system().set_initial_states_2d(&states(m));
            solver.solve(&point.coefficients, freq).unwrap().amplitudes[0]
        };
        let fd = (amplitude(1.0) - amplitude(-1.0)) / (2.0 * h);
        println!(
            "dA/dm{}: analytic {:.6e}, central differences {fd:.6e}",
            a + 1,
            s.gradient[0][a]
        );
        assert!(
            (fd - s.gradient[0][a]).abs() <= 1e-4 * fd.abs().max(1e-3 * s.amplitudes[0]),
            "component {a}: {fd} {}",
            s.gradient[0][a]
        );
    }
    // m₂ moves the mean of T₂ only, which a stuck contact carries statically out of plane: y2's
    // first harmonic does not see it (the check above is then 0 = 0). ∂R/∂m itself, for both
    // components, against central differences of the residual at fixed coefficients.
    solver.system().set_initial_states_2d(&states(m0));
    let derivative =
        limits::residual_derivative_of(solver.system(), &point.coefficients, &variables).unwrap();
    let dim = point.coefficients.len();
    let mut largest = 0.0_f64;
    for a in 0..2 {
        let mut residual = |sign: f64| {
            let mut m = m0;
            m[a] += sign * h;
            let system = solver.system();
            system.set_initial_states_2d(&states(m));
            let mut r = vec![0.0; dim];
            system.residual(&point.coefficients, omega, &mut r).unwrap();
            r
        };
        let (rp, rm) = (residual(1.0), residual(-1.0));
        let scale = derivative.per_group[a]
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "component {a}: ∂R/∂m is zero");
        for i in 0..dim {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            let diff = (fd - derivative.per_group[a][i]).abs();
            largest = largest.max(diff / scale);
            assert!(
                diff <= 1e-6 * scale,
                "component {a}, row {i}: {fd} {}",
                derivative.per_group[a][i]
            );
        }
    }
    println!(
        "∂R/∂m against central differences: largest difference {largest:.3e} of the largest entry"
    );
}

#[test]
fn the_disc_envelope_of_the_constrained_3d_system_equals_the_planar_one() {
    let planar = planar(&[]);
    let spatial = problem(SPATIAL, &[]);
    let freqs = [205.0, 215.0, 219.0];
    let planar_seeds = limit_states(&planar, &freqs);
    let spatial_seeds = limit_states(&spatial, &freqs);
    let (_, planar_groups) = EnvelopeMode::Sides.groups(&planar);
    let (_, spatial_groups) = EnvelopeMode::Sides.groups(&spatial);
    for (g, &f) in freqs.iter().enumerate() {
        let run = |p: &Problem, groups: &[Vec<usize>], seeds: &[LimitState]| {
            let started = std::time::Instant::now();
            let point = envelope_at(
                p,
                groups,
                f,
                &EnvelopeSeeds {
                    states: as_seeds(seeds),
                    starts: Vec::new(),
                },
                &limits::envelope::search_settings(),
            );
            (point, started.elapsed().as_secs_f64())
        };
        let (a, ta) = run(&planar, &planar_groups, &planar_seeds[g]);
        let (b, tb) = run(&spatial, &spatial_groups, &spatial_seeds[g]);
        let (a_hi, a_lo) = (a.max[0].as_ref().unwrap(), a.min[0].as_ref().unwrap());
        let (b_hi, b_lo) = (b.max[0].as_ref().unwrap(), b.min[0].as_ref().unwrap());
        println!(
            "{f} Hz: planar max {:.9e} (m {:?}) min {:.9e} ({} solves, {ta:.2} s); disc max {:.9e} (m {:?}) min {:.9e} (m {:?}) ({} solves, {tb:.2} s)",
            a_hi.amplitude, a_hi.m, a_lo.amplitude, a.solves, b_hi.amplitude, b_hi.m,
            b_lo.amplitude, b_lo.m, b.solves
        );
        // Two variables (m₁, m₂) per side, every bound in the disc.
        assert_eq!(b_hi.m.len(), 4);
        for m in [&b_hi.m, &b_lo.m] {
            for side in 0..2 {
                assert!(m[2 * side].hypot(m[2 * side + 1]) <= 1.0 + 1e-12, "{m:?}");
            }
        }
        // The same envelope as the planar search over m₁ ∈ [-1, 1] per side.
        for (x, y) in [
            (a_hi.amplitude, b_hi.amplitude),
            (a_lo.amplitude, b_lo.amplitude),
        ] {
            assert!(
                (x - y).abs() <= 1e-6 * x,
                "{f} Hz: planar {x:.9e}, disc {y:.9e}"
            );
        }
        // It contains the limit states m = (±1, 0).
        for (m, _, amplitude) in &spatial_seeds[g] {
            assert!(
                b_hi.amplitude >= amplitude * (1.0 - 1e-9)
                    && b_lo.amplitude <= amplitude * (1.0 + 1e-9),
                "{f} Hz, limit state {m:?}: {amplitude:.9e} outside [{:.9e}, {:.9e}]",
                b_lo.amplitude,
                b_hi.amplitude
            );
        }
    }
}

/// The 3D blade pair scene (the generator's coarsest mesh, 2 node pairs per side) with the
/// patch fields `extra` added after each patch's `tolerance`.
fn blade_pair_3d(dir: &std::path::Path, extra: &str) -> Result<Problem, String> {
    coarse_blade_pair(dir, true, extra)
}

#[test]
fn contact_patches_set_the_second_initial_state_component() {
    let dir = tempfile::tempdir().unwrap();
    let p = blade_pair_3d(
        dir.path(),
        "law = \"jenkins-2d\"\ninitial_state = 0.6\ninitial_state2 = -0.5\n",
    )
    .unwrap();
    assert!(!p.contacts.is_empty());
    for c in &p.contacts {
        let law = c.law_2d().unwrap();
        assert_eq!(law.initial_state, [0.6, -0.5], "{}", c.name);
    }
    let err = blade_pair_3d(
        dir.path(),
        "law = \"jenkins-2d\"\ninitial_state = 0.6\ninitial_state2 = 0.9\n",
    )
    .unwrap_err();
    assert!(err.contains("contact_patches[0].initial_state2"), "{err}");
    assert!(err.contains("unit disc"), "{err}");
    let err = blade_pair_3d(dir.path(), "initial_state2 = 0.1\n").unwrap_err();
    assert!(err.contains("contact_patches[0].initial_state2"), "{err}");
    assert!(err.contains("only a `law = \"jenkins-2d\"` patch"), "{err}");
}

/// The 3D paper scene with one `[[limits.cases]]` entry of the given fields.
fn with_case(fields: &str) -> Result<(Problem, Vec<limits::LimitCase>), String> {
    let text = format!("{SPATIAL}\n[[limits.cases]]\n{fields}\n");
    let (problem, settings) = scene::parse(&text, "scene", &[])
        .and_then(|s| s.validate_with_limits("scene"))
        .map_err(|e| e.to_string())?;
    let cases = settings
        .unwrap()
        .cases
        .iter()
        .map(|spec| limits::LimitCase::from_spec(&problem, spec))
        .collect();
    Ok((problem, cases))
}

#[test]
fn limit_cases_set_the_second_initial_state_component() {
    let (problem, cases) = with_case("sides = { left = 0.3 }\nsides2 = { left = -0.5 }").unwrap();
    assert_eq!(cases[0].name, "left+0.3_left_m2-0.5");
    let applied = cases[0].apply(&problem);
    assert_eq!(
        applied.contacts[0].law_2d().unwrap().initial_state,
        [0.3, -0.5]
    );
    assert_eq!(
        applied.contacts[1].law_2d().unwrap().initial_state,
        [0.0, 0.0]
    );
    let (problem, cases) = with_case("contacts2 = { right = 0.8 }").unwrap();
    let applied = cases[0].apply(&problem);
    assert_eq!(
        applied.contacts[1].law_2d().unwrap().initial_state,
        [0.0, 0.8]
    );
    // Without m₂ the case keeps the meaning of the 1D limit method: (m, 0).
    let (problem, cases) = with_case("sides = { right = -1.0 }").unwrap();
    assert_eq!(cases[0].second_states, None);
    let applied = cases[0].apply(&problem);
    assert_eq!(
        applied.contacts[1].law_2d().unwrap().initial_state,
        [-1.0, 0.0]
    );
    // Refusals name the field.
    let err = with_case("sides = { left = 0.8 }\nsides2 = { left = 0.7 }").unwrap_err();
    assert!(err.contains("limits.cases[0].sides2.left"), "{err}");
    assert!(err.contains("unit disc"), "{err}");
    let err = with_case("contacts2 = { nowhere = 0.1 }").unwrap_err();
    assert!(err.contains("limits.cases[0].contacts2.nowhere"), "{err}");
    let planar = format!("{PLANAR}\n[[limits.cases]]\nsides2 = {{ left = 0.1 }}\n");
    let err = scene::parse(&planar, "scene", &[])
        .and_then(|s| s.validate_with_limits("scene"))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(err.contains("limits.cases[0].sides2.left"), "{err}");
    assert!(err.contains("no `jenkins-2d` point"), "{err}");
}
