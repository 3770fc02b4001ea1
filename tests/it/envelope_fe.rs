//! The response envelope on an FE model with many contact points per side: the reduced 2D blade
//! pair (`meshes/blade-pair/blade-pair-2d-envelope.toml`, 7 contact pairs per side), at one
//! frequency of the first bending resonance. One m per contact point (14) is more freedom than
//! one m per side (2), so the per-point envelope must contain the per-side one, and both must
//! contain the two limit states (m = +1 and m = −1 on every point). Run at H = 1 to stay fast
//! (the scene's H = 3 is measured in the README).

use fricbound::analysis::frf::{FrfPoint, PointSolver};
use fricbound::analysis::limits::{self, envelope_at, EnvelopeMode, EnvelopeSeeds, LimitCase};
use fricbound::analysis::linear;
use fricbound::model::Problem;
use std::path::Path;

fn blade_pair() -> Problem {
    let overrides = vec!["harmonics.max=1".to_string()];
    let path = Path::new("meshes/blade-pair/blade-pair-2d-envelope.toml");
    fricbound::scene::load_problem(path, &overrides)
        .map(|(_, problem)| problem)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The state with the same m on every contact at `freq_hz`, by Newton from the stuck linear
/// response (then from the open one).
fn uniform_state(problem: &Problem, m: f64, freq_hz: f64) -> FrfPoint {
    let p = LimitCase::uniform(problem, m).apply(problem);
    let mut solver = PointSolver::new(&p).unwrap_or_else(|e| panic!("{e}"));
    let set = solver.system().unknowns().clone();
    let omega = 2.0 * std::f64::consts::PI * freq_hz;
    [linear::stuck_guess, linear::open_guess]
        .iter()
        .filter_map(|guess| guess(&p, &set, omega).ok())
        .find_map(|x0| solver.solve(&x0, freq_hz).ok())
        .unwrap_or_else(|| panic!("no state with m = {m} at {freq_hz} Hz"))
}

#[test]
fn per_point_envelope_contains_the_per_side_envelope_and_the_limit_states() {
    let problem = blade_pair();
    assert_eq!(problem.contacts.len(), 14, "7 pairs per side");
    let freq_hz = 850.0;
    let limit_states: Vec<(f64, FrfPoint)> = [1.0, -1.0]
        .into_iter()
        .map(|m| (m, uniform_state(&problem, m, freq_hz)))
        .collect();
    let mut bounds = Vec::new();
    for mode in [EnvelopeMode::Sides, EnvelopeMode::Points] {
        let (_, groups) = mode.groups(&problem);
        let seeds = EnvelopeSeeds {
            states: limit_states
                .iter()
                .map(|(m, p)| (vec![*m; groups.len()], p.coefficients.clone()))
                .collect(),
            starts: Vec::new(),
        };
        let point = envelope_at(
            &problem,
            &groups,
            freq_hz,
            &seeds,
            &limits::envelope::search_settings(),
        );
        let (lo, hi) = (
            point.min[0].as_ref().expect("a state was solved"),
            point.max[0].as_ref().expect("a state was solved"),
        );
        println!(
            "{mode:?}: [{:.6e}, {:.6e}] m in {} solves; acting {}/{}; max at m = {:?}",
            lo.amplitude,
            hi.amplitude,
            point.solves,
            point.acting.iter().filter(|a| **a).count(),
            groups.len(),
            hi.m
        );
        bounds.push((lo.amplitude, hi.amplitude));
    }
    for (m, p) in &limit_states {
        println!("limit state m = {m:+}: {:.6e} m", p.amplitudes[0]);
    }
    let ((side_lo, side_hi), (point_lo, point_hi)) = (bounds[0], bounds[1]);
    // Both envelopes contain both limit states (a limit state is one of the states searched).
    for (m, p) in &limit_states {
        let a = p.amplitudes[0];
        for (what, (lo, hi)) in [("sides", bounds[0]), ("points", bounds[1])] {
            assert!(
                lo <= a * (1.0 + 1e-9) && a <= hi * (1.0 + 1e-9),
                "{what} envelope [{lo:.6e}, {hi:.6e}] misses the m = {m} state {a:.6e}"
            );
        }
    }
    // One m per point includes every per-side state: its envelope is at least as wide.
    assert!(
        point_hi >= side_hi * (1.0 - 1e-6),
        "per-point max {point_hi:.6e} below the per-side max {side_hi:.6e}"
    );
    assert!(
        point_lo <= side_lo * (1.0 + 1e-6),
        "per-point min {point_lo:.6e} above the per-side min {side_lo:.6e}"
    );
}

/// A `[[limits.cases]]` entry may name a contact patch's side and its points (`<side>-<k>`,
/// numbered as the matching made them): the case sets m on exactly those points. A point
/// beyond the patch is refused, the error naming the patch's points.
#[test]
fn limit_cases_name_contact_patch_sides_and_points() {
    let mesh = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/meshes/blade-pair/blade-pair-2d.msh"
    );
    let text = std::fs::read_to_string("meshes/blade-pair/blade-pair-2d-envelope.toml")
        .unwrap()
        .replace("mesh = \"blade-pair-2d.msh\"", &format!("mesh = {mesh:?}"));
    let dir = tempfile::tempdir().unwrap();
    let validate = |point: &str| {
        let case = format!(
            "\n[[limits.cases]]\nname = \"probe\"\nsides = {{ right = -0.5 }}\n\
             contacts = {{ \"{point}\" = 0.5 }}\n"
        );
        let file = dir.path().join("scene.toml");
        std::fs::write(&file, format!("{text}{case}")).unwrap();
        fricbound::scene::load(&file, &["harmonics.max=1".to_string()])
            .and_then(|scene| scene.validate_with_limits("scene.toml"))
    };
    let (problem, settings) = validate("left-3").unwrap_or_else(|e| panic!("{e}"));
    let settings = settings.expect("the scene has [limits]");
    let case = LimitCase::from_spec(&problem, &settings.cases[0]);
    for (contact, m) in problem.contacts.iter().zip(&case.contact_states) {
        let expected = match (contact.name.as_str(), contact.name.starts_with("right-")) {
            ("left-3", _) => 0.5,
            (_, true) => -0.5,
            _ => contact.law.initial_state,
        };
        assert_eq!(*m, expected, "{}", contact.name);
    }
    let error = validate("left-8").unwrap_err().to_string();
    assert!(
        error.contains("limits.cases[0].contacts.left-8")
            && error.contains(
                "unknown contact `left-8` (the scene has left-1 … left-7, right-1 … right-7)"
            ),
        "{error}"
    );
}
