//! Switched effects (constant normal load, no lift-off, uncoupled statics) and Jacobian
//! strategies on the paper case.

use fricbound::analysis::frf::{self, PointSolver, Silent};
use fricbound::analysis::limits::{self, LimitCase};
use fricbound::hbm::{check_jacobian, HbmSystem};
use fricbound::model::Problem;

use crate::common;
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

/// The resonance peak (frequency in Hz, amplitude in m) of that oscillator at H = 1 from the
/// describing function (paper Appendix, Eqs. 17-18): the response is x = A cos(ωt − φ) with
/// A² [(k + k_eq(A) − mω²)² + (cω + c_eq(A))²] = F², and the peak is the largest A for which
/// some ω solves it: the minimum over ω of the bracket equals F²/A² there.
fn describing_function_peak() -> (f64, f64) {
    let (m, k, c, kt, mu, n0, force) = (1.0, 1.0e4, 2.0, 1.0e5, 0.3, 10.0, 5.0);
    // min over ω of G(ω) = (K − mω²)² + (cω + D)²: G′ = −4mω(K − mω²) + 2c(cω + D) = 0.
    let minimum = |a: f64| -> (f64, f64) {
        let (k_eq, c_eq) = fricbound::contact::jenkins_describing_function(kt, mu, n0, a);
        let (kk, d) = (k + k_eq, c_eq);
        let mut w = (kk / m).sqrt();
        for _ in 0..100 {
            let g1 = -4.0 * m * w * (kk - m * w * w) + 2.0 * c * (c * w + d);
            let g2 = -4.0 * m * kk + 12.0 * m * m * w * w + 2.0 * c * c;
            let step = g1 / g2;
            w -= step;
            if step.abs() < 1e-15 * w {
                break;
            }
        }
        ((kk - m * w * w).powi(2) + (c * w + d).powi(2), w)
    };
    let h = |a: f64| a * a * minimum(a).0 - force * force;
    // A bracket: small amplitudes lie below the curve's top, h < 0; large ones above.
    let (mut lo, mut hi) = (1e-4, 1.0);
    assert!(h(lo) < 0.0 && h(hi) > 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if h(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a = 0.5 * (lo + hi);
    (minimum(a).1 / std::f64::consts::TAU, a)
}

/// A 1-DOF Jenkins oscillator at H = 1 with a constant normal load: the refined resonance
/// peak of the event-resolved law equals the describing function's to 1e-9; the sampled law
/// at 256 samples is off by its sampling error (about 1e-4), at 8 192 samples by less than
/// 1e-5.
#[test]
fn jenkins_oscillator_peak_equals_the_describing_function() {
    let (f_ref, a_ref) = describing_function_peak();
    let mut errors = Vec::new();
    for (law, samples) in [
        ("jenkins-1d", 256),
        ("jenkins-1d-sampled", 256),
        ("jenkins-1d-sampled", 8192),
    ] {
        let overrides = [
            format!("contacts.0.law=\"{law}\""),
            format!("harmonics.samples={samples}"),
        ];
        let overrides: Vec<&str> = overrides.iter().map(|s| s.as_str()).collect();
        let problem = scenes::problem(scenes::JENKINS_OSCILLATOR, &overrides);
        let run = frf::solve(&problem, &mut Silent).unwrap();
        assert!(run.is_complete(), "{law}: {:?}", run.incomplete_reason());
        let peaks = fricbound::analysis::peaks::path_peaks(&problem, &run.points).unwrap();
        assert_eq!(peaks[0].len(), 1, "{law}: {:?}", peaks[0]);
        let peak = &peaks[0][0];
        assert!(peak.refined, "{law}");
        let error = (peak.amplitude - a_ref).abs() / a_ref;
        eprintln!(
            "{law}, {samples} samples: peak {:.12e} m at {:.9} Hz; describing function \
             {a_ref:.12e} m at {f_ref:.9} Hz; relative error {error:.2e}",
            peak.amplitude, peak.freq_hz
        );
        errors.push(error);
    }
    assert!(errors[0] < 1e-9, "event law: {:.2e}", errors[0]);
    assert!(
        errors[1] > 1e-6,
        "the sampled law's error is its sampling error: {:.2e}",
        errors[1]
    );
    assert!(
        errors[2] < 1e-5,
        "sampled law at 8192 samples: {:.2e}",
        errors[2]
    );
}

/// The paper scene (`fricbound run` defaults) around its 3rd resonance, 200-235 Hz, where the
/// limit curves differ: on the event law, and on the sampled law at 8 192 samples.
fn paper_on_both_laws() -> (Problem, Problem) {
    let window = ["analysis.freq_start_hz=200.0", "analysis.freq_end_hz=235.0"];
    let event = scenes::paper(&window);
    let mut sampled: Vec<&str> = window.to_vec();
    sampled.extend_from_slice(&scenes::SAMPLED_PAPER);
    sampled.push("harmonics.samples=8192");
    (event, scenes::paper(&sampled))
}

/// The paper case's FRF (m = 0) and its limit peaks (m = ±1) with the event law equal those
/// of the sampled law at 8 192 samples, whose error is O(1/N): points of the event curve
/// solved again at their frequencies with the sampled law, and the refined peaks.
#[test]
fn paper_case_event_law_equals_the_sampled_law_at_8192_samples() {
    let (event, sampled) = paper_on_both_laws();
    let run = frf::solve(&event, &mut Silent).unwrap();
    assert!(run.is_complete(), "{:?}", run.incomplete_reason());
    let mut solver = PointSolver::new(&sampled).unwrap();
    let mut worst: f64 = 0.0;
    for p in run.points.iter().step_by(run.points.len() / 12) {
        let q = solver.solve(&p.coefficients, p.freq_hz).unwrap();
        let rel = (q.amplitudes[0] - p.amplitudes[0]).abs() / p.amplitudes[0];
        println!(
            "{:.4} Hz: event {:.9e} m, sampled {:.9e} m, relative {rel:.2e}",
            p.freq_hz, p.amplitudes[0], q.amplitudes[0]
        );
        worst = worst.max(rel);
    }
    let mut peak_worst: f64 = 0.0;
    for m in [1.0, -1.0] {
        let peaks: Vec<_> = [&event, &sampled]
            .iter()
            .map(|p| {
                let curve = limits::solve_case(p, &LimitCase::uniform(p, m), None).unwrap();
                curve.peak.unwrap()
            })
            .collect();
        let (a, b) = (&peaks[0], &peaks[1]);
        assert!(a.refined && b.refined, "m = {m}");
        let rel = (a.amplitude - b.amplitude).abs() / a.amplitude;
        let rel_f = (a.freq_hz - b.freq_hz).abs() / a.freq_hz;
        println!(
            "m = {m:+}: event peak {:.9e} m at {:.6} Hz, sampled {:.9e} m at {:.6} Hz, \
             relative {rel:.2e} (frequency {rel_f:.2e})",
            a.amplitude, a.freq_hz, b.amplitude, b.freq_hz
        );
        peak_worst = peak_worst.max(rel).max(rel_f);
    }
    assert!(worst < 1e-5, "FRF points: {worst:.2e}");
    assert!(peak_worst < 1e-5, "limit peaks: {peak_worst:.2e}");
}
