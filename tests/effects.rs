//! Switched effects (constant normal load, no lift-off, uncoupled statics) and Jacobian
//! strategies on the paper case.

use fricbound::analysis::frf::{self, Silent};
use fricbound::hbm::{check_jacobian, HbmSystem};
use fricbound::model::Problem;

mod common;
use common::scenes;

fn paper(overrides: &[&str]) -> Problem {
    let mut o = vec!["analysis.freq_start_hz=150.0", "analysis.freq_end_hz=230.0"];
    o.extend_from_slice(overrides);
    scenes::paper(&o)
}

#[test]
fn every_effect_combination_solves_with_a_checked_jacobian() {
    for overrides in [
        vec!["effects.normal_load=\"constant\""],
        vec!["effects.liftoff=false"],
        vec!["effects.coupling=\"uncoupled\""],
        vec![
            "effects.coupling=\"uncoupled\"",
            "harmonics.max=",
            "harmonics.list=[1, 3]",
        ],
        vec!["effects.normal_load=\"constant\"", "harmonics.max=2"],
    ] {
        let problem = paper(&overrides);
        let run =
            frf::solve(&problem, &mut Silent).unwrap_or_else(|e| panic!("{overrides:?}: {e}"));
        assert!(run.points.len() > 10, "{overrides:?}");
        let mut system = HbmSystem::new(&problem).unwrap();
        for p in run.points.iter().step_by(7) {
            let omega = 2.0 * std::f64::consts::PI * p.freq_hz;
            let check = check_jacobian(&mut system, &p.coefficients, omega, 1e-7).unwrap();
            assert!(
                check.relative() < 1e-6,
                "{overrides:?} at {} Hz: {:.3e}",
                p.freq_hz,
                check.relative()
            );
        }
    }
}

#[test]
fn uncoupled_mode_has_no_static_unknowns_and_a_balanced_pre_solve() {
    let problem = paper(&["effects.coupling=\"uncoupled\""]);
    let system = HbmSystem::new(&problem).unwrap();
    assert!(!system.unknowns().has_constant());
    assert_eq!(system.dim(), 6 * 2);
    // Static pre-solve: damper pressed into both contacts by F0 (the damper moves along −y).
    assert!(system.static_offset()[5] < 0.0);
}

#[test]
fn jacobian_strategies_give_the_same_curve() {
    let base = paper(&[
        "analysis.freq_start_hz=200.0",
        "analysis.freq_end_hz=230.0",
        "analysis.max_step=0.2",
    ]);
    let reference = frf::solve(&base, &mut Silent).unwrap();
    for strategy in ["forward-difference", "central-difference"] {
        let problem = paper(&[
            "analysis.freq_start_hz=200.0",
            "analysis.freq_end_hz=230.0",
            "analysis.max_step=0.2",
            &format!("analysis.jacobian=\"{strategy}\""),
        ]);
        let run = frf::solve(&problem, &mut Silent).unwrap();
        // Compare the peaks and the end point (the paths may place points differently).
        let peak = |pts: &[fricbound::analysis::frf::FrfPoint]| {
            pts.iter().map(|p| p.amplitudes[0]).fold(0.0, f64::max)
        };
        let (a, b) = (peak(&reference.points), peak(&run.points));
        assert!((a - b).abs() / a < 2e-3, "{strategy}: peak {b} vs {a}");
        let (ea, eb) = (reference.points.last().unwrap(), run.points.last().unwrap());
        assert!((ea.freq_hz - eb.freq_hz).abs() < 1e-9);
        assert!(
            (ea.amplitudes[0] - eb.amplitudes[0]).abs() / ea.amplitudes[0] < 1e-6,
            "{strategy}: end point"
        );
    }
}
