//! The event-resolved law's analytic Jacobian against central differences in every regime
//! (stuck, stick-slip, slip with lift-off, open, grazing lift-off, no lift-off), away from the
//! law's seam, and its forces against the sampled law's.

use super::{
    coefficients, effects, grazing_inputs, jacobian_scales, law, liftoff_inputs, regime_strategy,
    stick_slip_inputs,
};
use fricbound::contact::aft::AftWorkspace;
use fricbound::contact::events::march::{Anchor, Phase, Piece};
use fricbound::contact::harmonic::HarmonicSet;
use fricbound::contact::{ContactEffects, ContactState, JenkinsLaw};
use proptest::prelude::*;
use std::f64::consts::PI;

/// Whether two event-law evaluations have the same phases in the same order, each stick's
/// slider set by the same kind of anchor within 10⁻³ rad: across the law's seam (a slip
/// that appears inside a stick, or a stick's slider anchored at another peak of its trial
/// force) they do not.
fn same_phases(a: &[Piece], b: &[Piece]) -> bool {
    let anchor_tau = |anchor: Anchor| match anchor {
        Anchor::Initial => None,
        Anchor::SlipEnd { tau, .. } | Anchor::Closing { tau } => Some(tau.rem_euclid(2.0 * PI)),
    };
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| match (p.phase, q.phase) {
            (Phase::Slip { sign: s }, Phase::Slip { sign: t }) => s == t,
            (Phase::Open, Phase::Open) => true,
            (Phase::Stick { anchor: x, .. }, Phase::Stick { anchor: y, .. }) => {
                std::mem::discriminant(&x) == std::mem::discriminant(&y)
                    && match (anchor_tau(x), anchor_tau(y)) {
                        (Some(tx), Some(ty)) => {
                            let d = (tx - ty).abs();
                            d.min(2.0 * PI - d) < 1e-3
                        }
                        _ => true,
                    }
            }
            _ => false,
        })
}

/// Largest |analytic − central difference| of the event law's Jacobian, relative to the
/// largest entry (each column scaled by its coefficient scale), at H = 3 with a coarse
/// bracketing grid. Each column takes the better of two difference steps (10⁻⁶ and 10⁻⁷ of its
/// scale): a right Jacobian's error falls like the step squared, and where a slider's anchor
/// moves fast (a flat peak of the trial force) the larger step's error is that truncation,
/// not a wrong derivative. The law is C¹ in every regime except across its one seam, where a
/// stick's slider changes anchor (`a_slip_appearing_inside_a_stick_is_a_seam_of_the_element`);
/// a step that reaches across it ([`same_phases`] fails) is not used, and the error is `None`
/// where both steps of a column do, there being no derivative to check.
fn event_jacobian_error(
    l: JenkinsLaw,
    effects: ContactEffects,
    u: &[f64],
    v: &[f64],
) -> (Option<f64>, ContactState) {
    let set = HarmonicSet::up_to(3);
    let nb = set.n_blocks();
    let mut aft = AftWorkspace::new(&set, 32);
    let state = aft.evaluate_events(&l, effects, u, v, true).unwrap().state;
    let base_phases = aft.event_phases().to_vec();
    let (tu, tv, nv) = (aft.dt_du.clone(), aft.dt_dv.clone(), aft.dn_dv.clone());
    let [scale_u, scale_v, max_entry] = jacobian_scales((u, v), (&tu, &tv, &nv));
    let mut max_err = 0.0_f64;
    for i in 0..nb {
        for (which, scale) in [(0, scale_u), (1, scale_v)] {
            let mut column_err: Option<f64> = None;
            for step in [1e-6, 1e-7] {
                let h = step * scale;
                let mut across_seam = false;
                let mut forces = |sign: f64| {
                    let (mut up, mut vp) = (u.to_vec(), v.to_vec());
                    if which == 0 {
                        up[i] += sign * h;
                    } else {
                        vp[i] += sign * h;
                    }
                    aft.evaluate_events(&l, effects, &up, &vp, false).unwrap();
                    across_seam |= !same_phases(aft.event_phases(), &base_phases);
                    (aft.t_hat.clone(), aft.n_hat.clone())
                };
                let (tp, np) = forces(1.0);
                let (tm, nm) = forces(-1.0);
                if across_seam {
                    continue;
                }
                let err = (0..nb)
                    .map(|j| {
                        let (at, an) = if which == 0 {
                            (tu[j * nb + i], 0.0)
                        } else {
                            (tv[j * nb + i], nv[j * nb + i])
                        };
                        let ct = (tp[j] - tm[j]) / (2.0 * h);
                        let cn = (np[j] - nm[j]) / (2.0 * h);
                        (ct - at).abs().max((cn - an).abs()) * scale
                    })
                    .fold(0.0_f64, f64::max);
                column_err = Some(column_err.map_or(err, |e| e.min(err)));
            }
            match column_err {
                Some(err) => max_err = max_err.max(err),
                None => return (None, state),
            }
        }
    }
    (Some(max_err / max_entry), state)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn event_jacobian_stuck((s, m, mu) in regime_strategy(), constant in any::<bool>()) {
        let (u, v) = coefficients(&s, 1e-6, 1e-3, 1e-5);
        let (err, state) = event_jacobian_error(law(1e5, 1e5, mu, m), effects(constant, true), &u, &v);
        prop_assert_eq!(state, ContactState::Stuck);
        let Some(err) = err else {
            return Err(TestCaseError::reject("a difference step reaches the onset of slip"));
        };
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_stick_slip((s, m, mu) in regime_strategy(), constant in any::<bool>()) {
        let (u, v) = stick_slip_inputs(&s);
        let (err, state) = event_jacobian_error(law(1e5, 1e5, mu, m), effects(constant, true), &u, &v);
        prop_assert_eq!(state, ContactState::StickSlip);
        let Some(err) = err else {
            return Err(TestCaseError::reject("a difference step reaches a slip appearing inside a stick"));
        };
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_stick_slip_liftoff((s, m, mu) in regime_strategy()) {
        let (u, v) = liftoff_inputs(&s, 1e-4);
        let (err, state) = event_jacobian_error(law(1e5, 1e5, mu, m), effects(false, true), &u, &v);
        prop_assert_eq!(state, ContactState::StickSlipLiftoff);
        let Some(err) = err else {
            return Err(TestCaseError::reject("a difference step reaches a slip appearing inside a stick"));
        };
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_open((s, m, mu) in regime_strategy()) {
        let (u, v) = coefficients(&s, 1e-4, -1e-3, 1e-4);
        let mut aft = AftWorkspace::new(&HarmonicSet::up_to(3), 32);
        let report = aft.evaluate_events(&law(1e5, 1e5, mu, m), effects(false, true), &u, &v, true).unwrap();
        prop_assert_eq!(report.state, ContactState::Open);
        prop_assert!(aft.dt_du.iter().chain(&aft.dt_dv).chain(&aft.dn_dv).all(|x| *x == 0.0));
        prop_assert!(aft.t_hat.iter().chain(&aft.n_hat).all(|x| *x == 0.0));
    }

    #[test]
    fn event_jacobian_grazing((s, m, mu) in regime_strategy(), touch in 0.97..1.03f64) {
        // The contact just touches or just separates once per period: no input is excluded,
        // the closing instant being located, not sampled.
        let (u, v) = grazing_inputs(&s, touch);
        let (err, _) = event_jacobian_error(law(1e5, 1e5, mu, m), effects(false, true), &u, &v);
        let Some(err) = err else {
            return Err(TestCaseError::reject("a difference step reaches a slip appearing inside a stick"));
        };
        prop_assert!(err < 1e-5, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_without_liftoff((s, m, mu) in regime_strategy()) {
        let (u, v) = liftoff_inputs(&s, 4e-5);
        let (err, _) = event_jacobian_error(law(1e5, 1e5, mu, m), effects(false, false), &u, &v);
        let Some(err) = err else {
            return Err(TestCaseError::reject("a difference step reaches a slip appearing inside a stick"));
        };
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn event_law_tends_to_the_sampled_law((s, m, mu) in regime_strategy()) {
        // Both laws on the same stick-slip-liftoff input: the sampled law's error falls like
        // 1/N (each transition snapped to the grid), so at 8 192 samples the two agree to a
        // few 1e-4 of the force scale.
        let (u, v) = liftoff_inputs(&s, 1e-4);
        let l = law(1e5, 1e5, mu, m);
        let set = HarmonicSet::up_to(3);
        let mut events = AftWorkspace::new(&set, 64);
        events.evaluate_events(&l, effects(false, true), &u, &v, false).unwrap();
        let mut sampled = AftWorkspace::new(&set, 8192);
        sampled.evaluate(&l, effects(false, true), &u, &v, false).unwrap();
        let scale = events.n_hat.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        for (a, b) in events.t_hat.iter().chain(&events.n_hat).zip(sampled.t_hat.iter().chain(&sampled.n_hat)) {
            prop_assert!((a - b).abs() < 2e-3 * scale, "{} vs {} (scale {})", a, b, scale);
        }
    }
}
