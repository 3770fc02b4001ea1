//! The paper's wedge-damper case (section 4): linear limits, static balance of the damper and
//! the qualitative contact facts of section 4.2.

use fricbound::analysis::frf::{self, FrfPoint, Silent};
use fricbound::analysis::linear::{self, LinearCase};
use fricbound::contact::ContactState;
use fricbound::hbm::{check_jacobian, HbmSystem};
use fricbound::model::Problem;

use crate::common;
use common::scenes::paper;

/// The paper structure with the damper also grounded (so that it is not a free body when
/// contacts are open), no pre-load, and contacts forced open (large gap) or stuck (interference
/// and huge friction coefficient).
fn forced(case: LinearCase) -> Problem {
    let mut o = vec![
        "model.stiffness.4.4=4.0e5",
        "model.stiffness.5.5=4.0e5",
        "static_loads.0.value=0.0",
        "analysis.freq_start_hz=60.0",
        "analysis.freq_end_hz=320.0",
    ];
    match case {
        LinearCase::Open => o.extend(["contacts.0.gap=0.1", "contacts.1.gap=0.1"]),
        LinearCase::Stuck => o.extend([
            "contacts.0.gap=-0.01",
            "contacts.1.gap=-0.01",
            "contacts.0.mu=1.0e4",
            "contacts.1.mu=1.0e4",
        ]),
    }
    paper(&o)
}

#[test]
fn forced_open_and_stuck_contacts_reproduce_linear_frfs() {
    for case in [LinearCase::Open, LinearCase::Stuck] {
        let problem = forced(case);
        let run = frf::solve(&problem, &mut Silent).unwrap();
        assert!(run.points.len() > 20);
        let expected_state = match case {
            LinearCase::Open => ContactState::Open,
            LinearCase::Stuck => ContactState::Stuck,
        };
        let freqs: Vec<f64> = run.points.iter().map(|p| p.freq_hz).collect();
        let lin = linear::frf(&problem, case, &freqs).unwrap();
        let y2 = problem.outputs[0];
        for (p, l) in run.points.iter().zip(&lin) {
            assert!(
                p.states.iter().all(|s| *s == expected_state),
                "{:?} at {} Hz",
                p.states,
                p.freq_hz
            );
            let rel = (p.amplitudes[0] - l[y2]).abs() / l[y2];
            assert!(
                rel < 1e-8,
                "{case:?} at {} Hz: {} vs {} (rel {rel:.2e})",
                p.freq_hz,
                p.amplitudes[0],
                l[y2]
            );
        }
    }
}

/// 0th harmonics of all forces on the damper (contacts, pre-load F0 and the damper spring
/// K_D), from an independent AFT evaluation at the converged coefficients; paper Eq. (11) plus
/// the K_D term. Returns the largest imbalance relative to F0.
fn damper_imbalance(problem: &Problem, points: &[FrfPoint]) -> f64 {
    let f0 = 120.0;
    let k_d = 3.0e5;
    let alpha = 30f64.to_radians();
    // Damper-face frames (t, n), n from the damper into the blade: a = 180° ∓ α.
    let frames = [
        ((-alpha.cos(), alpha.sin()), (-alpha.sin(), -alpha.cos())),
        ((-alpha.cos(), -alpha.sin()), (alpha.sin(), -alpha.cos())),
    ];
    let mut system = HbmSystem::new(problem).unwrap();
    let n = problem.model.n_dofs();
    let c0 = system.unknowns().constant_block().unwrap();
    let mut worst = 0.0_f64;
    for p in points {
        let q0 = &p.coefficients[c0 * n..(c0 + 1) * n];
        let (xd, yd) = (q0[4], q0[5]);
        // Damper spring K_D = k_D [[1, -1], [-1, 1]] acting on the damper.
        let mut fx = -k_d * (xd - yd);
        // F0 acts on the damper along −y.
        let mut fy = -k_d * (yd - xd) - f0;
        for (c, ((tx, ty), (nx, ny))) in frames.iter().enumerate() {
            system.contact_forces(c, &p.coefficients, false).unwrap();
            let t0 = system.aft().t_hat[0];
            let n0 = system.aft().n_hat[0];
            // The contact pushes the damper back along −t T − n N.
            fx -= tx * t0 + nx * n0;
            fy -= ty * t0 + ny * n0;
        }
        worst = worst.max(fx.hypot(fy) / f0);
    }
    worst
}

#[test]
fn damper_static_balance_holds_at_every_point() {
    let problem = paper(&[]);
    let run = frf::solve(&problem, &mut Silent).unwrap();
    assert!(run.points.len() > 50);
    let worst = damper_imbalance(&problem, &run.points);
    assert!(worst < 1e-8, "damper static imbalance {worst:.3e} of F0");
}

#[test]
fn analytic_jacobian_matches_central_differences_on_the_paper_path() {
    let problem = paper(&[
        "harmonics.max=3",
        "analysis.freq_start_hz=150.0",
        "analysis.freq_end_hz=230.0",
    ]);
    let run = frf::solve(&problem, &mut Silent).unwrap();
    let mut system = HbmSystem::new(&problem).unwrap();
    let mut regimes = std::collections::HashSet::new();
    for p in run.points.iter().step_by(3) {
        let check = check_jacobian(
            &mut system,
            &p.coefficients,
            2.0 * std::f64::consts::PI * p.freq_hz,
            1e-7,
        )
        .unwrap();
        regimes.extend(system.states.iter().copied());
        assert!(
            check.relative() < 1e-6,
            "{} Hz: relative error {:.3e}",
            p.freq_hz,
            check.relative()
        );
    }
    assert!(regimes.contains(&ContactState::Stuck) && regimes.contains(&ContactState::StickSlip));
}

/// Peak (largest first-harmonic amplitude) of a run and the point where it occurs.
fn peak(points: &[FrfPoint]) -> &FrfPoint {
    points
        .iter()
        .max_by(|a, b| a.amplitudes[0].total_cmp(&b.amplitudes[0]))
        .unwrap()
}

fn zoom(lo: f64, hi: f64, m: f64) -> Vec<FrfPoint> {
    let problem = paper(&[
        &format!("analysis.freq_start_hz={lo}"),
        &format!("analysis.freq_end_hz={hi}"),
        "analysis.max_step=0.05",
        &format!("contacts.0.initial_state={m}"),
        &format!("contacts.1.initial_state={m}"),
    ]);
    frf::solve(&problem, &mut Silent).unwrap().points
}

#[test]
fn second_resonance_both_contacts_slip_and_m_does_not_matter() {
    let plus = zoom(150.0, 175.0, 1.0);
    let minus = zoom(150.0, 175.0, -1.0);
    let (pp, pm) = (peak(&plus), peak(&minus));
    let mut states = pp.states.clone();
    states.sort_by_key(|s| s.label());
    assert_eq!(
        states,
        vec![ContactState::StickSlip, ContactState::StickSlipLiftoff],
        "at {} Hz",
        pp.freq_hz
    );
    let rel = (pp.amplitudes[0] - pm.amplitudes[0]).abs() / pp.amplitudes[0];
    assert!(rel < 1e-4, "2nd-resonance peaks differ by {rel:.2e}");
}

#[test]
fn third_resonance_one_side_stuck_and_m_changes_the_answer() {
    let plus = zoom(200.0, 235.0, 1.0);
    let minus = zoom(200.0, 235.0, -1.0);
    let (pp, pm) = (peak(&plus), peak(&minus));
    for p in [pp, pm] {
        let stuck = p
            .states
            .iter()
            .filter(|s| **s == ContactState::Stuck)
            .count();
        let slipping = p
            .states
            .iter()
            .filter(|s| **s == ContactState::StickSlip)
            .count();
        assert_eq!(
            (stuck, slipping),
            (1, 1),
            "states {:?} at {} Hz",
            p.states,
            p.freq_hz
        );
    }
    let rel = (pp.amplitudes[0] - pm.amplitudes[0]).abs() / pp.amplitudes[0].max(pm.amplitudes[0]);
    assert!(rel > 0.05, "3rd-resonance peaks differ by only {rel:.2e}");
}
