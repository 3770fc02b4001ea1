//! AFT of a single Jenkins element: describing function (paper Appendix) and the analytic
//! Jacobian against central differences in every contact regime.

use fricbound::contact::aft::AftWorkspace;
use fricbound::contact::harmonic::HarmonicSet;
use fricbound::contact::jenkins_describing_function;
use fricbound::contact::{ContactEffects, ContactState, JenkinsLaw, NormalLoad};
use proptest::prelude::*;

mod event_jacobian;
mod seam;

fn law(kt: f64, kn: f64, mu: f64, m: f64) -> JenkinsLaw {
    JenkinsLaw {
        kt,
        kn,
        mu,
        initial_state: m,
    }
}

/// First harmonic of T for u = q cos τ and constant N0, both normal-load models.
fn first_harmonic(ratio: f64, normal_load: NormalLoad) -> (f64, f64, ContactState) {
    let (kt, kn, mu, n0) = (2.0e5, 1.0e5, 0.4, 50.0);
    let q = mu * n0 / (kt * ratio);
    let set = HarmonicSet::up_to(1);
    let mut aft = AftWorkspace::new(&set, 1024);
    let u = [0.0, q, 0.0];
    let v = [n0 / kn, 0.0, 0.0];
    let effects = ContactEffects {
        normal_load,
        liftoff: true,
    };
    let report = aft
        .evaluate(&law(kt, kn, mu, 0.0), effects, &u, &v, false)
        .unwrap();
    (aft.t_hat[1] / q, -aft.t_hat[2] / q, report.state)
}

#[test]
fn describing_function_matches_paper_appendix_over_stick_slip_range() {
    let (kt, mu, n0) = (2.0e5, 0.4, 50.0);
    for i in 0..=47 {
        let ratio = 0.01 + (0.95 - 0.01) * i as f64 / 47.0;
        let q = mu * n0 / (kt * ratio);
        let (k_ref, c_ref) = jenkins_describing_function(kt, mu, n0, q);
        for model in [NormalLoad::Variable, NormalLoad::Constant] {
            let (k, c, state) = first_harmonic(ratio, model);
            assert_eq!(state, ContactState::StickSlip, "ratio {ratio}");
            let ek = (k - k_ref).abs() / k_ref;
            let ec = (c - c_ref).abs() / c_ref;
            assert!(
                ek < 1e-3,
                "k_eq at ratio {ratio}: {k} vs {k_ref} (rel {ek:.2e})"
            );
            assert!(
                ec < 1e-3,
                "c_eq at ratio {ratio}: {c} vs {c_ref} (rel {ec:.2e})"
            );
        }
    }
}

#[test]
fn describing_function_full_stick() {
    for ratio in [1.05, 2.0, 10.0] {
        let (k, c, state) = first_harmonic(ratio, NormalLoad::Variable);
        assert_eq!(state, ContactState::Stuck);
        assert!((k - 2.0e5).abs() / 2.0e5 < 1e-12, "k {k}");
        assert!(c.abs() < 1e-9 * 2.0e5, "c {c}");
    }
}

#[test]
fn stuck_limit_states_touch_the_coulomb_limits() {
    // Fully stuck at steady state: the tangential force is only known up to a constant. The
    // limit cases m = ±1 end on the curves that touch +μN and −μN (paper Eqs. 14-15, Fig. 5);
    // m = 0 starts at T(0) = 0 and never slips.
    let set = HarmonicSet::up_to(1);
    let mut aft = AftWorkspace::new(&set, 256);
    let (kt, kn, mu) = (1.0e5, 1.0e5, 0.5);
    let u = [0.0, 1e-5, 0.0];
    let v = [1e-3, 0.0, 0.0];
    let limit = mu * kn * 1e-3;
    let mut means = Vec::new();
    let mut dynamic = Vec::new();
    for m in [-1.0, 0.0, 1.0] {
        let r = aft
            .evaluate(
                &law(kt, kn, mu, m),
                ContactEffects::default(),
                &u,
                &v,
                false,
            )
            .unwrap();
        assert_eq!(r.state, ContactState::Stuck, "m = {m}");
        let max = aft.t.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let min = aft.t.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!(max <= limit * (1.0 + 1e-12) && min >= -limit * (1.0 + 1e-12));
        if m == 1.0 {
            assert!(
                (max - limit).abs() < 1e-9 * limit,
                "T_max touches +μN: {max}"
            );
        } else if m == -1.0 {
            assert!(
                (min + limit).abs() < 1e-9 * limit,
                "T_min touches −μN: {min}"
            );
        } else {
            assert!(aft.t[0].abs() < 1e-12 * limit, "T(0) = {}", aft.t[0]);
        }
        means.push(aft.t_hat[0]);
        dynamic.push((aft.t_hat[1], aft.t_hat[2]));
    }
    assert!(
        means[0] < means[1] && means[1] < means[2],
        "T⁰ by m: {means:?}"
    );
    // The dynamic part is the same whatever m (paper §3.1): kₜ times the motion.
    for (c, s) in dynamic {
        assert!((c - kt * 1e-5).abs() < 1e-9 * kt * 1e-5 && s.abs() < 1e-9 * kt * 1e-5);
    }
}

/// The coefficient scales of û and v̂ (their largest magnitudes) and the largest Jacobian entry
/// with each column scaled by its coefficient's scale: what the Jacobian checks measure
/// their errors against.
fn jacobian_scales((u, v): (&[f64], &[f64]), (tu, tv, nv): (&[f64], &[f64], &[f64])) -> [f64; 3] {
    let scale_u = u.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let scale_v = v.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let max_entry = (0..tu.len())
        .map(|k| (tu[k].abs() * scale_u).max((tv[k].abs().max(nv[k].abs())) * scale_v))
        .fold(f64::MIN_POSITIVE, f64::max);
    [scale_u, scale_v, max_entry]
}

/// Time samples per period in [`jacobian_error`].
const GRAZING_SAMPLES: usize = 128;

/// Largest |analytic − finite difference| relative to the largest Jacobian entry.
///
/// The AFT forces are piecewise smooth: stick-slip transitions and the closing instant move
/// across time samples. Where a perturbation of ±h crosses such a kink, the forward and
/// backward differences disagree and the central difference is neither one-sided
/// derivative; the analytic Jacobian is then checked against the one-sided difference of the
/// smooth piece it was evaluated on (the closer of the two).
fn jacobian_error(
    l: JenkinsLaw,
    effects: ContactEffects,
    u: &[f64],
    v: &[f64],
) -> (f64, ContactState) {
    let set = HarmonicSet::up_to(3);
    let nb = set.n_blocks();
    let mut aft = AftWorkspace::new(&set, GRAZING_SAMPLES);
    let state = aft.evaluate(&l, effects, u, v, true).unwrap().state;
    let (tu, tv, nv) = (aft.dt_du.clone(), aft.dt_dv.clone(), aft.dn_dv.clone());
    let (t0, n0) = (aft.t_hat.clone(), aft.n_hat.clone());
    let [scale_u, scale_v, max_entry] = jacobian_scales((u, v), (&tu, &tv, &nv));
    let mut max_err = 0.0_f64;
    for i in 0..nb {
        for (which, scale) in [(0, scale_u), (1, scale_v)] {
            let h = 1e-7 * scale;
            let (mut up, mut vp) = (u.to_vec(), v.to_vec());
            let (mut um, mut vm) = (u.to_vec(), v.to_vec());
            if which == 0 {
                up[i] += h;
                um[i] -= h;
            } else {
                vp[i] += h;
                vm[i] -= h;
            }
            aft.evaluate(&l, effects, &up, &vp, false).unwrap();
            let (tp, np) = (aft.t_hat.clone(), aft.n_hat.clone());
            aft.evaluate(&l, effects, &um, &vm, false).unwrap();
            let (tm, nm) = (aft.t_hat.clone(), aft.n_hat.clone());
            // Column errors against the central, forward and backward differences, and the
            // spread between the two one-sided ones.
            let (mut central, mut forward, mut backward, mut spread) =
                (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
            for j in 0..nb {
                let (at, an) = if which == 0 {
                    (tu[j * nb + i], 0.0)
                } else {
                    (tv[j * nb + i], nv[j * nb + i])
                };
                let (ft, fn_) = ((tp[j] - t0[j]) / h, (np[j] - n0[j]) / h);
                let (bt, bn) = ((t0[j] - tm[j]) / h, (n0[j] - nm[j]) / h);
                let (ct, cn) = (0.5 * (ft + bt), 0.5 * (fn_ + bn));
                central = central.max((ct - at).abs().max((cn - an).abs()) * scale);
                forward = forward.max((ft - at).abs().max((fn_ - an).abs()) * scale);
                backward = backward.max((bt - at).abs().max((bn - an).abs()) * scale);
                spread = spread.max((ft - bt).abs().max((fn_ - bn).abs()) * scale);
            }
            let column = if spread < 1e-6 * max_entry {
                central
            } else {
                forward.min(backward)
            };
            max_err = max_err.max(column);
        }
    }
    (max_err / max_entry, state)
}

/// Inputs that guarantee slip: u(0) − u(π) = 2(c₁ + c₃) ≥ 2(5e-4 − 1e-4 − 0.5e-4) = 7e-4, so
/// kₜ times the tangential travel (70) exceeds the width of the Coulomb band,
/// 2μN ≤ 2 · 1e5 · (1e-4 + 3e-5 · 11/3) = 42.
fn stick_slip_inputs(seed: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (mut u, v) = coefficients(seed, 1e-4, 1e-4, 3e-5);
    u[1] += 5e-4;
    (u, v)
}

/// Slip, and a normal oscillation larger than the mean plus all other harmonics (by
/// `normal_extra` on the second harmonic's cosine): with 1e-4 the contact separates for part
/// of the period whatever the random coefficients.
fn liftoff_inputs(seed: &[f64], normal_extra: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut u, mut v) = coefficients(seed, 1e-4, 2e-5, 2e-5);
    u[1] += 2e-4;
    v[2] += normal_extra;
    (u, v)
}

/// Mean normal gap `touch` times the normal amplitude: the contact just touches or just
/// separates once per period.
fn grazing_inputs(seed: &[f64], touch: f64) -> (Vec<f64>, Vec<f64>) {
    let mut u: Vec<f64> = seed.iter().take(7).map(|x| 1e-5 * x).collect();
    let mut v = vec![0.0; 7];
    v[1] = 3e-5;
    v[0] = 3e-5 * touch;
    u[1] += 1e-4;
    (u, v)
}

/// Random coefficients for harmonics 0..3: u with amplitude `ua`, v with mean `v0` and
/// oscillation amplitude `va`.
fn coefficients(seed: &[f64], ua: f64, v0: f64, va: f64) -> (Vec<f64>, Vec<f64>) {
    let mut u = vec![0.0; 7];
    let mut v = vec![0.0; 7];
    u[0] = ua * seed[0];
    v[0] = v0;
    for j in 1..7 {
        let decay = 1.0 / (1 + (j - 1) / 2) as f64;
        u[j] = ua * seed[j] * decay;
        v[j] = va * seed[6 + j] * decay;
    }
    (u, v)
}

fn regime_strategy() -> impl Strategy<Value = (Vec<f64>, f64, f64)> {
    (
        prop::collection::vec(-1.0..1.0f64, 13),
        -1.0..1.0f64,
        0.1..1.0f64,
    )
        .prop_map(|(s, m, mu)| (s, m, mu))
}

fn effects(constant: bool, liftoff: bool) -> ContactEffects {
    ContactEffects {
        normal_load: if constant {
            NormalLoad::Constant
        } else {
            NormalLoad::Variable
        },
        liftoff,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn jacobian_stuck((s, m, mu) in regime_strategy(), constant in any::<bool>()) {
        // Large normal load, small tangential motion: never slips.
        let (u, v) = coefficients(&s, 1e-6, 1e-3, 1e-5);
        let (err, state) = jacobian_error(law(1e5, 1e5, mu, m * 0.5), effects(constant, true), &u, &v);
        prop_assert_eq!(state, ContactState::Stuck);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn jacobian_stick_slip((s, m, mu) in regime_strategy(), constant in any::<bool>()) {
        let (u, v) = stick_slip_inputs(&s);
        let (err, state) = jacobian_error(law(1e5, 1e5, mu, m), effects(constant, true), &u, &v);
        prop_assert_eq!(state, ContactState::StickSlip);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn jacobian_stick_slip_liftoff((s, m, mu) in regime_strategy()) {
        let (u, v) = liftoff_inputs(&s, 1e-4);
        let (err, state) = jacobian_error(law(1e5, 1e5, mu, m), effects(false, true), &u, &v);
        prop_assert_eq!(state, ContactState::StickSlipLiftoff);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn jacobian_open((s, m, mu) in regime_strategy()) {
        let (u, v) = coefficients(&s, 1e-4, -1e-3, 1e-4);
        let (_, state) = jacobian_error(law(1e5, 1e5, mu, m), effects(false, true), &u, &v);
        prop_assert_eq!(state, ContactState::Open);
        // All derivatives vanish; jacobian_error is 0/0 → compare absolute values instead.
        let set = HarmonicSet::up_to(3);
        let mut aft = AftWorkspace::new(&set, 128);
        aft.evaluate(&law(1e5, 1e5, mu, m), effects(false, true), &u, &v, true).unwrap();
        prop_assert!(aft.dt_du.iter().chain(&aft.dt_dv).chain(&aft.dn_dv).all(|x| *x == 0.0));
        prop_assert!(aft.t_hat.iter().chain(&aft.n_hat).all(|x| *x == 0.0));
    }

    #[test]
    fn jacobian_grazing((s, m, mu) in regime_strategy(), touch in 0.97..1.03f64) {
        // Mean normal gap about equal to the normal amplitude: the contact just touches or
        // just separates once per period.
        // The normal force has a kink where the gap closes. Central differences of step
        // 1e-7 straddle it when a time sample lies that close to the closing instant, and
        // then they measure neither one-sided derivative: such inputs are not a check.
        let closest = (0..GRAZING_SAMPLES)
            .map(|k| (touch + (std::f64::consts::TAU * k as f64 / GRAZING_SAMPLES as f64).cos()).abs())
            .fold(f64::INFINITY, f64::min);
        prop_assume!(closest > 1e-5);
        let (u, v) = grazing_inputs(&s, touch);
        let (err, _) = jacobian_error(law(1e5, 1e5, mu, m), effects(false, true), &u, &v);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn jacobian_without_liftoff((s, m, mu) in regime_strategy()) {
        let (u, v) = liftoff_inputs(&s, 4e-5);
        let (err, _) = jacobian_error(law(1e5, 1e5, mu, m), effects(false, false), &u, &v);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }
}

// ---------------------------------------------------------------------------------------
// The event-resolved law (`AftWorkspace::evaluate_events`): exact where the sampled law is
// O(1/N), and smooth, so central differences check its Jacobian everywhere.

/// First harmonic of T for u = q cos τ and constant N0 with the event-resolved law.
fn first_harmonic_events(ratio: f64, normal_load: NormalLoad, samples: usize) -> (f64, f64) {
    let (kt, kn, mu, n0) = (2.0e5, 1.0e5, 0.4, 50.0);
    let q = mu * n0 / (kt * ratio);
    let mut aft = AftWorkspace::new(&HarmonicSet::up_to(1), samples);
    let effects = ContactEffects {
        normal_load,
        liftoff: true,
    };
    let report = aft
        .evaluate_events(
            &law(kt, kn, mu, 0.0),
            effects,
            &[0.0, q, 0.0],
            &[n0 / kn, 0.0, 0.0],
            false,
        )
        .unwrap();
    let expected = if ratio < 1.0 {
        ContactState::StickSlip
    } else {
        ContactState::Stuck
    };
    assert_eq!(report.state, expected, "ratio {ratio}");
    (aft.t_hat[1] / q, -aft.t_hat[2] / q)
}

#[test]
fn event_law_equals_the_describing_function_to_round_off() {
    let (kt, mu, n0) = (2.0e5, 0.4, 50.0);
    for i in 0..=40 {
        let ratio = 0.01 + (1.2 - 0.01) * i as f64 / 40.0;
        let q = mu * n0 / (kt * ratio);
        let (k_ref, c_ref) = jenkins_describing_function(kt, mu, n0, q);
        for model in [NormalLoad::Variable, NormalLoad::Constant] {
            // A coarse bracketing grid gives the same values: it only brackets the events.
            for samples in [16, 256] {
                let (k, c) = first_harmonic_events(ratio, model, samples);
                assert!(
                    (k - k_ref).abs() <= 1e-11 * kt,
                    "k_eq at ratio {ratio}, {samples} samples: {k} vs {k_ref}"
                );
                assert!(
                    (c - c_ref).abs() <= 1e-11 * kt,
                    "c_eq at ratio {ratio}, {samples} samples: {c} vs {c_ref}"
                );
            }
        }
    }
}

/// Force coefficients (T̂, N̂) of one law at coefficients (û, v̂).
type Forces<'a> = dyn FnMut(&[f64], &[f64]) -> Vec<f64> + 'a;

/// A line in the unknowns: its name, (û₀, v̂₀) and direction (dû, dv̂) at H = 2.
type Line = (&'static str, [f64; 5], [f64; 5], [f64; 5], [f64; 5]);

/// Largest second difference |F(s+h) − 2F(s) + F(s−h)| / h² of the force coefficients
/// F = (T̂, N̂) along the line x(s) = x₀ + s·d, over every s = i·h on [0, 0.2]: with the step
/// as the spacing, every kink on the stretch lies within ±h of some s.
fn largest_second_difference(
    evaluate: &mut Forces<'_>,
    (u0, v0): (&[f64], &[f64]),
    (du, dv): (&[f64], &[f64]),
    h: f64,
) -> f64 {
    let mut at = |s: f64| {
        let u: Vec<f64> = u0.iter().zip(du).map(|(a, b)| a + s * b).collect();
        let v: Vec<f64> = v0.iter().zip(dv).map(|(a, b)| a + s * b).collect();
        evaluate(&u, &v)
    };
    let values: Vec<Vec<f64>> = (0..=(0.2 / h).round() as usize)
        .map(|i| at(i as f64 * h))
        .collect();
    values
        .windows(3)
        .map(|w| {
            (0..w[1].len())
                .map(|j| ((w[2][j] - 2.0 * w[1][j] + w[0][j]) / (h * h)).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// Along a line in the unknowns that moves a stick-slip transition (the tangential amplitude
/// grows) and one that moves the lift-off instants (the mean gap shrinks), the event law's
/// second differences stay bounded as the step shrinks: the forces are C¹ with a bounded
/// second derivative on each side of a transition. The sampled law's grow like 1/h: each time
/// a transition crosses a sample the forces have a kink.
#[test]
fn event_law_forces_have_no_kinks_along_a_line() {
    let set = HarmonicSet::up_to(2);
    let l = law(1e5, 1e5, 0.5, 0.0);
    let lines: [Line; 2] = [
        (
            "stick-slip",
            [0.0, 2e-4, 0.0, 0.0, 3e-5],
            [1e-4, 0.0, 2e-5, 0.0, 0.0],
            [0.0, 2e-4, 0.0, 0.0, 0.0],
            [0.0; 5],
        ),
        (
            "lift-off",
            [0.0, 3e-4, 0.0, 0.0, 3e-5],
            [2e-5, 0.0, 3e-5, 0.0, 0.0],
            [0.0; 5],
            [-1e-5, 0.0, 0.0, 0.0, 0.0],
        ),
    ];
    let mut events = AftWorkspace::new(&set, 64);
    let mut sampled = AftWorkspace::new(&set, 256);
    for (name, u0, v0, du, dv) in lines {
        let mut by_event = |u: &[f64], v: &[f64]| {
            events
                .evaluate_events(&l, effects(false, true), u, v, false)
                .unwrap();
            [events.t_hat.clone(), events.n_hat.clone()].concat()
        };
        let event: Vec<f64> = [1e-3, 1e-4, 1e-5]
            .iter()
            .map(|&h| largest_second_difference(&mut by_event, (&u0, &v0), (&du, &dv), h))
            .collect();
        let mut by_sample = |u: &[f64], v: &[f64]| {
            sampled
                .evaluate(&l, effects(false, true), u, v, false)
                .unwrap();
            [sampled.t_hat.clone(), sampled.n_hat.clone()].concat()
        };
        let sample: Vec<f64> = [1e-3, 1e-4, 1e-5]
            .iter()
            .map(|&h| largest_second_difference(&mut by_sample, (&u0, &v0), (&du, &dv), h))
            .collect();
        eprintln!("{name}: event law {event:?}, sampled law {sample:?}");
        assert!(
            event[2] < 2.0 * event[0],
            "{name}: the event law's second differences grow as the step shrinks: {event:?}"
        );
        assert!(
            sample[2] > 20.0 * sample[0],
            "{name}: the sampled law's kinks are not seen: {sample:?}"
        );
    }
}

/// The limit cases' stuck orbits touch ±μN where they start (paper Eqs. 14-15): with u and N
/// moving in phase the touch is a double root of |T| − μN at τ = 0 and 2π, which the event
/// law must not take for a slip (the sampled law's "slip by rounding"). Without friction
/// (μ = 0, a retaining spring) the normal force still follows the compression.
#[test]
fn event_law_limit_cases_touch_the_cone_and_stay_stuck() {
    let set = HarmonicSet::up_to(1);
    let mut aft = AftWorkspace::new(&set, 64);
    let (kt, kn, mu) = (3.3e6, 3.3e6, 0.3);
    let v = [2.5e-6, 4.7e-7, 0.0];
    // m = +1 touches +μN where T is largest; m = −1 touches −μN where T is smallest, so its
    // tangential motion is in antiphase.
    for m in [-1.0, 1.0] {
        let u = [-1.0e-5, m * 1.8e-7, 0.0];
        let r = aft
            .evaluate_events(&law(kt, kn, mu, m), ContactEffects::default(), &u, &v, true)
            .unwrap();
        assert_eq!(r.state, ContactState::Stuck, "m = {m}");
        // T = kₜ(u − u(0)) + m μ kₙ v(0): its cosine part is kₜ û_c1, its mean kₜ(û₀ − u(0))
        // + m μN(0).
        let t0 = kt * (u[0] - (u[0] + u[1])) + m * mu * kn * (v[0] + v[1]);
        assert!((aft.t_hat[0] - t0).abs() < 1e-9 * t0.abs(), "m = {m}");
        assert!(
            (aft.t_hat[1] - kt * u[1]).abs() < 1e-9 * kt * u[1].abs(),
            "m = {m}"
        );
    }
    let u = [-1.0e-5, 1.8e-7, 0.0];
    let r = aft
        .evaluate_events(
            &law(kt, kn, 0.0, 1.0),
            ContactEffects::default(),
            &u,
            &v,
            true,
        )
        .unwrap();
    assert!(aft.t_hat.iter().all(|t| *t == 0.0));
    assert!(
        (aft.n_hat[0] - kn * v[0]).abs() < 1e-12 * kn * v[0],
        "{:?}",
        aft.n_hat
    );
    assert!(
        (aft.n_hat[1] - kn * v[1]).abs() < 1e-12 * kn * v[0],
        "{:?}",
        aft.n_hat
    );
    assert!((aft.dn_dv[0] - kn).abs() < 1e-12 * kn, "{:?}", r);
}

/// A frictionless contact (μ = 0) that opens and closes: the normal force follows the
/// compression where v > 0 only, and the contact is reported as lifting off (the stick phase
/// with T = 0 ends at the opening, which no slip onset precedes).
#[test]
fn event_law_frictionless_contact_opens_and_closes() {
    let set = HarmonicSet::up_to(1);
    let mut aft = AftWorkspace::new(&set, 64);
    let v = [1e-5, 2e-5, 0.0];
    let r = aft
        .evaluate_events(
            &law(1e5, 1e5, 0.0, 0.0),
            ContactEffects::default(),
            &[0.0; 3],
            &v,
            true,
        )
        .unwrap();
    assert_eq!(r.state, ContactState::StickSlipLiftoff);
    // N = kₙ max(v, 0) with v = v₀ + v₁ cos τ: closed for |τ| < θ, cos θ = −v₀/v₁.
    let theta = (-v[0] / v[1]).acos();
    let pi = std::f64::consts::PI;
    let n0 = 1e5 * (v[0] * theta + v[1] * theta.sin()) / pi;
    assert!(
        (aft.n_hat[0] - n0).abs() < 1e-12 * n0,
        "{} vs {n0}",
        aft.n_hat[0]
    );
    assert!(aft.t_hat.iter().all(|t| *t == 0.0));
}

/// The sampled law's error against the event law on one stick-slip-lift-off orbit (H = 3)
/// at N = 64, 128, …, 8192 samples: (N, largest |sampled − event| over T̂ and N̂ relative to
/// the largest N̂ coefficient), and the least-squares slope of ln(error) against ln(N).
/// `tangential` (m) scales the tangential motion: u = ua cos τ + smaller harmonics against
/// v = 2e-5 + 1e-4 sin τ + smaller harmonics (m), kₜ = kₙ = 1e5 N/m, μ = 0.5.
fn sampled_law_convergence(tangential: f64) -> (Vec<(usize, f64)>, f64) {
    let seed = [
        0.3, -0.5, 0.2, 0.7, -0.1, 0.4, 0.6, -0.3, 0.5, -0.2, 0.1, 0.8, -0.4,
    ];
    let (mut u, mut v) = coefficients(&seed, 0.5 * tangential, 2e-5, 2e-5);
    u[1] += tangential;
    v[2] += 1e-4;
    let (l, fx) = (law(1e5, 1e5, 0.5, 0.0), effects(false, true));
    let set = HarmonicSet::up_to(3);
    let mut events = AftWorkspace::new(&set, 256);
    let report = events.evaluate_events(&l, fx, &u, &v, false).unwrap();
    assert_eq!(report.state, ContactState::StickSlipLiftoff);
    let scale = events.n_hat.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let table: Vec<(usize, f64)> = (6..=13)
        .map(|p| {
            let n = 1usize << p;
            let mut sampled = AftWorkspace::new(&set, n);
            let report = sampled.evaluate(&l, fx, &u, &v, false).unwrap();
            assert_eq!(report.state, ContactState::StickSlipLiftoff, "N = {n}");
            let error = events
                .t_hat
                .iter()
                .chain(&events.n_hat)
                .zip(sampled.t_hat.iter().chain(&sampled.n_hat))
                .fold(0.0_f64, |e, (a, b)| e.max((a - b).abs()));
            (n, error / scale)
        })
        .collect();
    let points: Vec<(f64, f64)> = table
        .iter()
        .map(|&(n, e)| ((n as f64).ln(), e.ln()))
        .collect();
    let k = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / k, b + y / k));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (table, sxy / sxx)
}

/// The sampled law converges to the event law at first order in 1/N where a stick follows a
/// closing (the slider is set at the last open sample, up to one sample late), at second
/// order where the contact slips at once on closing and every stick starts at the end of a
/// slip (the late start then costs O(Δτ²)): least-squares slopes of its error against N
/// (docs/accuracy.md, "Event-resolved against sampled contact law").
#[test]
fn sampled_law_error_against_the_event_law_falls_like_one_over_n() {
    let mut slopes = Vec::new();
    // kₜ|u′| ≈ 2 N/rad below μkₙ v′ ≈ 5 N/rad at closing: stuck on closing; then 20 N/rad.
    for tangential in [2e-5, 2e-4] {
        let (table, slope) = sampled_law_convergence(tangential);
        for (n, e) in &table {
            println!("u amplitude {tangential:.0e} m, N = {n:5}: relative error {e:.3e}");
        }
        println!("least-squares slope of ln(error) against ln(N): {slope:.3}");
        slopes.push(slope);
    }
    assert!(
        (-1.3..=-0.8).contains(&slopes[0]),
        "stuck on closing: {slopes:?}"
    );
    assert!(
        (-2.5..=-1.7).contains(&slopes[1]),
        "slipping on closing: {slopes:?}"
    );
}
