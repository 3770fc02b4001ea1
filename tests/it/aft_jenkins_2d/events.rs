//! The event-resolved 2D law (`jenkins-2d`) against the 1D event law, the sampled 2D law,
//! closed forms and central differences.

use super::*;
use fricbound::contact::aft::AftWorkspace;
use fricbound::contact::JenkinsLaw;

fn c(set: &HarmonicSet, e: &[(usize, f64)]) -> Vec<f64> {
    let mut x = vec![0.0; set.n_blocks()];
    for &(j, v) in e {
        x[j] = v;
    }
    x
}

#[test]
fn straight_motion_equals_the_1d_event_law() {
    let set = HarmonicSet::up_to(3);
    let nb = set.n_blocks();
    let mut plane = Aft2dWorkspace::new(&set, 64);
    let mut line = AftWorkspace::new(&set, 64);
    let zero = vec![0.0; nb];
    let cases = [
        (
            c(&set, &[(0, 1e-6), (1, 8e-5), (2, 2e-5), (3, 1e-5)]),
            c(&set, &[(0, 1e-4), (1, 3e-5), (4, 1e-5)]),
        ),
        (
            c(&set, &[(1, 5e-5), (2, -3e-5)]),
            c(&set, &[(0, 2e-5), (1, 4e-5), (2, 1e-5)]),
        ),
        (c(&set, &[(1, 1e-6), (5, 2e-7)]), c(&set, &[(0, 1e-4)])),
    ];
    let (kt, kn, mu): (f64, f64, f64) = (1e5, 2e5, 0.3);
    let mut worst = (0.0_f64, 0.0_f64);
    for constant in [false, true] {
        for (u, v) in &cases {
            for m in [-1.0, -0.4, 0.0, 0.7, 1.0] {
                let law1 = JenkinsLaw {
                    kt,
                    kn,
                    mu,
                    initial_state: m,
                };
                let law2 = Jenkins2dLaw {
                    kt,
                    kn,
                    mu,
                    initial_state: [m, 0.0],
                };
                let r1 = line
                    .evaluate_events(&law1, effects(constant), u, v, true)
                    .unwrap();
                let r2 = plane
                    .evaluate_events(&law2, effects(constant), [u, &zero], v, true)
                    .unwrap();
                assert_eq!(r1.state, r2.state, "state at m = {m}");
                let scale = line.t_hat.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
                for j in 0..nb {
                    let e = (plane.t_hat[0][j] - line.t_hat[j])
                        .abs()
                        .max(plane.t_hat[1][j].abs())
                        .max((plane.n_hat[j] - line.n_hat[j]).abs());
                    worst.0 = worst.0.max(e / scale);
                    for i in 0..nb {
                        let d = (plane.dt_dx[j * 3 * nb + i] - line.dt_du[j * nb + i])
                            .abs()
                            .max(
                                (plane.dt_dx[j * 3 * nb + 2 * nb + i] - line.dt_dv[j * nb + i])
                                    .abs(),
                            )
                            .max((plane.dn_dv[j * nb + i] - line.dn_dv[j * nb + i]).abs())
                            .max(plane.dt_dx[(nb + j) * 3 * nb + i].abs())
                            .max(plane.dt_dx[(nb + j) * 3 * nb + 2 * nb + i].abs());
                        worst.1 = worst.1.max(d / kn);
                    }
                }
            }
        }
    }
    println!(
        "largest force difference {:.2e} (relative), Jacobian {:.2e} (of kₙ)",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-12, "{worst:?}");
    assert!(worst.1 < 1e-12, "{worst:?}");
}

/// Circular motion of radius q̂ under a constant N with kₜ q̂ > μN: T has magnitude μN
/// and leads the slider's radius by a right angle; the coefficients are closed forms
/// (the sampled law errs by about 2.7/N of μN here, the event law by its ODE tolerance).
#[test]
fn circular_motion_matches_the_closed_form() {
    let set = HarmonicSet::up_to(3);
    let (kt, kn, mu): (f64, f64, f64) = (1e5, 2e5, 0.3);
    let v0 = 1e-4;
    let limit = mu * kn * v0;
    let q = 2.0 * limit / kt;
    let rho = (q * q - (limit / kt).powi(2)).sqrt();
    let (cos_phi, sin_phi) = (rho / q, limit / (kt * q));
    let u1 = c(&set, &[(1, q)]);
    let u2 = c(&set, &[(2, q)]);
    let v = c(&set, &[(0, v0)]);
    let mut aft = Aft2dWorkspace::new(&set, 64);
    for m in [[0.0, 0.0], [1.0, 0.0], [-0.6, 0.8]] {
        let l = Jenkins2dLaw {
            kt,
            kn,
            mu,
            initial_state: m,
        };
        let report = aft
            .evaluate_events(&l, effects(true), [&u1, &u2], &v, true)
            .unwrap();
        assert_eq!(report.state, ContactState::StickSlip);
        let expected = [
            (aft.t_hat[0][1], limit * sin_phi),
            (aft.t_hat[0][2], -limit * cos_phi),
            (aft.t_hat[1][1], limit * cos_phi),
            (aft.t_hat[1][2], limit * sin_phi),
        ];
        let error = expected
            .iter()
            .fold(0.0_f64, |e, (x, y)| e.max((x - y).abs() / limit));
        println!(
            "m = {m:?}: {} periods, coefficient error {error:.2e} of μN",
            report.periods
        );
        assert!(error < 1e-9, "m = {m:?}: {error:.2e}");
    }
}

/// The sampled law converges to the event law like 1/N (stick-slip with a variable
/// normal load and lift-off, and a rotating slip under a constant one).
#[test]
fn the_sampled_law_converges_to_the_event_law() {
    let set = HarmonicSet::up_to(3);
    let l = law(0.3, [0.2, -0.3]);
    let cases = [
        (
            false,
            [
                c(&set, &[(1, 2e-4), (4, 3e-5)]),
                c(&set, &[(2, 1e-4), (1, 2e-5)]),
                c(&set, &[(0, 2e-5), (1, 1e-5), (4, 3e-5)]),
            ],
        ),
        (
            true,
            [
                c(&set, &[(1, 8e-5), (3, 1e-5)]),
                c(&set, &[(2, 5e-5), (5, 1e-5)]),
                c(&set, &[(0, 1e-4)]),
            ],
        ),
    ];
    for (constant, x) in &cases {
        let mut events = Aft2dWorkspace::new(&set, 128);
        events
            .evaluate_events(&l, effects(*constant), [&x[0], &x[1]], &x[2], false)
            .unwrap();
        let size = events.t_hat[0]
            .iter()
            .chain(&events.t_hat[1])
            .fold(0.0_f64, |a, x| a.max(x.abs()));
        let mut errors = Vec::new();
        for ns in [512, 2048, 8192] {
            let mut sampled = Aft2dWorkspace::new(&set, ns);
            sampled
                .evaluate(&l, effects(*constant), [&x[0], &x[1]], &x[2], false)
                .unwrap();
            let error = (0..2)
                .flat_map(|a| (0..set.n_blocks()).map(move |j| (a, j)))
                .fold(0.0_f64, |e, (a, j)| {
                    e.max((sampled.t_hat[a][j] - events.t_hat[a][j]).abs() / size)
                });
            println!(
                "constant N {constant}, N = {ns}: {error:.3e} (N·error {:.2})",
                error * ns as f64
            );
            errors.push((ns, error));
        }
        for &(ns, error) in &errors {
            assert!(error * (ns as f64) < 10.0, "N = {ns}: {error:.2e}");
        }
        assert!(errors[2].1 < errors[0].1 / 8.0, "{errors:?}");
    }
}

/// The event law's analytic Jacobian against central differences in every regime.
#[test]
fn jacobian_matches_central_differences_in_every_regime() {
    let set = HarmonicSet::up_to(3);
    let (kt, kn, mu): (f64, f64, f64) = (1e5, 2e5, 0.3);
    let stick = mu * kn * 1e-4 / kt;
    let variable = effects(false);
    let constant = effects(true);
    let l = |m: [f64; 2]| Jenkins2dLaw {
        kt,
        kn,
        mu,
        initial_state: m,
    };
    type Case = (
        &'static str,
        ContactEffects,
        [f64; 2],
        [Vec<f64>; 3],
        ContactState,
    );
    let cases: Vec<Case> = vec![
        (
            "stuck",
            variable,
            [0.3, -0.2],
            [
                c(&set, &[(1, 0.2 * stick)]),
                c(&set, &[(2, 0.1 * stick), (3, 0.05 * stick)]),
                c(&set, &[(0, 1e-4), (1, 1e-5)]),
            ],
            ContactState::Stuck,
        ),
        (
            "full slip, circular orbit",
            constant,
            [0.0, 0.0],
            [
                c(&set, &[(1, 3.0 * stick)]),
                c(&set, &[(2, 3.0 * stick)]),
                c(&set, &[(0, 1e-4)]),
            ],
            ContactState::StickSlip,
        ),
        (
            "partial slip",
            variable,
            [0.5, 0.5],
            [
                c(&set, &[(1, 1.5 * stick), (4, 0.2 * stick)]),
                c(&set, &[(2, 0.7 * stick), (1, 0.3 * stick)]),
                c(&set, &[(0, 1e-4), (1, 3e-5), (2, -2e-5)]),
            ],
            ContactState::StickSlip,
        ),
        (
            "lift-off",
            variable,
            [-1.0, 0.0],
            [
                c(&set, &[(1, 1.2 * stick)]),
                c(&set, &[(1, 0.5 * stick), (2, 0.8 * stick)]),
                c(&set, &[(0, 3e-5), (1, 6e-5), (3, 1e-5)]),
            ],
            ContactState::StickSlipLiftoff,
        ),
        (
            "grazing",
            constant,
            [0.0, 0.0],
            [
                c(&set, &[(1, 1.05 * stick)]),
                c(&set, &[(2, 0.3 * stick)]),
                c(&set, &[(0, 1e-4)]),
            ],
            ContactState::StickSlip,
        ),
    ];
    for (what, effects, m, x, expected) in &cases {
        let (error, state) =
            jacobian_error_of(March::Events, l(*m), *effects, [&x[0], &x[1], &x[2]], 1e-6);
        println!("{what}: {state:?}, relative error {error:.2e}");
        assert_eq!(state, *expected, "{what}");
        assert!(error < 1e-6, "{what}: {error:.2e}");
    }
}

/// A straight path just off t₁ that slips by 10⁻³ or 10⁻⁶ of its stick amplitude,
/// started with T(0) across the path: a partial slip along one direction, whose plain
/// period map creeps (the slider's offset across the path contracts by 1 − O(offset²)
/// per period). Newton on the period map settles it in a few periods on the 1D event
/// law's forces along the path.
#[test]
fn a_partial_one_directional_slip_reaches_its_periodic_state() {
    let set = HarmonicSet::up_to(1);
    let (kt, kn, mu): (f64, f64, f64) = (1e5, 2e5, 0.3);
    let stick = mu * kn * 1e-4 / kt;
    let angle: f64 = 1e-3;
    let (co, si) = (angle.cos(), angle.sin());
    let v = vec![1e-4, 0.0, 0.0];
    let friction = mu * kn * 1e-4;
    for excess in [1e-3, 1e-6] {
        let a = (1.0 + excess) * stick;
        let along = vec![0.0, a, 0.0];
        let (u1, u2) = (vec![0.0, co * a, 0.0], vec![0.0, si * a, 0.0]);
        let l2 = Jenkins2dLaw {
            kt,
            kn,
            mu,
            initial_state: [0.0, 1.0],
        };
        let mut plane = Aft2dWorkspace::new(&set, 128);
        let report = plane
            .evaluate_events(&l2, effects(false), [&u1, &u2], &v, true)
            .unwrap();
        let mut sampled = Aft2dWorkspace::new(&set, 128);
        let sampled_report = sampled
            .evaluate(&l2, effects(false), [&u1, &u2], &v, false)
            .unwrap();
        let mut line = AftWorkspace::new(&set, 128);
        let l1 = JenkinsLaw {
            kt,
            kn,
            mu,
            initial_state: 0.0,
        };
        line.evaluate_events(&l1, effects(false), &along, &v, false)
            .unwrap();
        let (mut along, mut across) = (0.0_f64, 0.0_f64);
        for j in 0..set.n_blocks() {
            let (t1, t2) = (plane.t_hat[0][j], plane.t_hat[1][j]);
            along = along.max((co * t1 + si * t2 - line.t_hat[j]).abs());
            across = across.max((-si * t1 + co * t2).abs());
        }
        println!(
            "excess {excess:e}: {:?} in {} periods (sampled law with Newton restarts: {}), \
             largest difference from the 1D event law {:.2e} of μN along the path, \
             force across it {:.2e} of μN",
            report.state,
            report.periods,
            sampled_report.periods,
            along / friction,
            across / friction
        );
        assert_eq!(report.state, ContactState::StickSlip);
        assert!(report.periods <= 30, "{report:?}");
        assert!(along < 1e-13 * friction, "{:.2e}", along / friction);
        // Across the path the fixed point is ill-conditioned: the offset contracts only by
        // 1 − 4·excess per period, so rounding of the period's end (about ε of the stick
        // range) moves the fixed point across the path by ε/(4·excess), whatever finds it
        // (the polish already measures the Newton step, the distance to the fixed point, not
        // the mismatch). Measured 9.8e-15 of μN in the force across the path at an excess of
        // 10⁻³ and 4.6e-11 at 10⁻⁶ (ε/(4·10⁻⁶) = 5.5e-11), while the along-path forces agree
        // to round-off.
        assert!(across < 1e-10 * friction, "{:.2e}", across / friction);
        assert!(plane.dt_dx.iter().all(|x| x.is_finite()));
    }
}

/// The limit states m = ±e (any direction e) of a point stuck all period keep
/// T(0) = μN(0) m, as the sampled law does.
#[test]
fn limit_states_stuck_all_period_keep_their_initial_state() {
    let set = HarmonicSet::up_to(3);
    let (kt, kn, mu): (f64, f64, f64) = (1e5, 2e5, 0.3);
    let stick = mu * kn * 1e-4 / kt;
    // u′(0) = 0 and N at its minimum at τ = 0, the friction circle growing faster than
    // the trial force moves: stuck all period from any point of the circle's edge.
    let x = [
        c(&set, &[(1, 0.01 * stick), (3, 0.005 * stick)]),
        c(&set, &[(3, 0.005 * stick), (5, 0.002 * stick)]),
        c(&set, &[(0, 1e-4), (1, -1e-5)]),
    ];
    for angle in [0.0, 0.7, 2.0, std::f64::consts::PI] {
        for sign in [1.0, -1.0] {
            let m = [sign * f64::cos(angle), sign * f64::sin(angle)];
            let l = Jenkins2dLaw {
                kt,
                kn,
                mu,
                initial_state: m,
            };
            // (A constant N cannot keep both m = e and m = −e stuck.)
            let constant = false;
            let mut events = Aft2dWorkspace::new(&set, 128);
            let report = events
                .evaluate_events(&l, effects(constant), [&x[0], &x[1]], &x[2], true)
                .unwrap();
            let mut sampled = Aft2dWorkspace::new(&set, 128);
            let sampled_report = sampled
                .evaluate(&l, effects(constant), [&x[0], &x[1]], &x[2], false)
                .unwrap();
            let limit0 = mu * events.n[0];
            let t0 = [events.t[0][0], events.t[1][0]];
            let error = (t0[0] - limit0 * m[0]).hypot(t0[1] - limit0 * m[1]) / limit0;
            let difference = (0..2)
                .flat_map(|a| (0..set.n_blocks()).map(move |j| (a, j)))
                .fold(0.0_f64, |e, (a, j)| {
                    e.max((events.t_hat[a][j] - sampled.t_hat[a][j]).abs() / limit0)
                });
            let (r1, r2) = (report.state, sampled_report.state);
            // The sampled law's state: the sampled path may touch the circle apart.
            assert_eq!(r1, ContactState::Stuck, "m = {m:?}");
            assert_eq!(r2, ContactState::Stuck, "m = {m:?}");
            assert!(error < 1e-12, "m = {m:?}: T(0) off by {error:.2e}");
            // Stuck all period, both laws give T = kₜ(u − w₀) exactly.
            assert!(difference < 1e-12, "m = {m:?}: {difference:.2e}");
        }
    }
}

// Steps of 10⁻⁶ of the largest coefficient: the slip angle's integration leaves noise
// of about 10⁻¹² of the forces (its tolerance, where the adaptive steps change), which
// smaller steps amplify (measured on a lift-off case: 2.2e-6, 2.1e-5, 2.2e-4 relative
// error for steps of 10⁻⁶, 10⁻⁷, 10⁻⁸).
proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn event_jacobian_stuck((s, m, mu) in regime(), constant in any::<bool>()) {
        let x = coefficients(&s, 1e-6, 1e-3, 1e-5);
        let l = law(mu, [0.5 * m[0], 0.5 * m[1]]);
        let (err, state) =
            jacobian_error_of(March::Events, l, effects(constant), [&x[0], &x[1], &x[2]], 1e-6);
        prop_assert_eq!(state, ContactState::Stuck);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_rotating_slip((s, m, mu) in regime(), constant in any::<bool>()) {
        let mut x = coefficients(&s, 1e-4, 1e-4, 3e-5);
        x[0][1] += 5e-4;
        x[1][2] += 3e-4;
        let (err, state) =
            jacobian_error_of(March::Events, law(mu, m), effects(constant), [&x[0], &x[1], &x[2]], 1e-6);
        prop_assert_eq!(state, ContactState::StickSlip);
        prop_assert!(err < 1e-6, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_nearly_straight_slip((s, m, mu) in regime(), constant in any::<bool>()) {
        let mut x = coefficients(&s, 1e-6, 1e-4, 1e-5);
        x[0][1] += 5e-4;
        let (err, state) =
            jacobian_error_of(March::Events, law(mu, m), effects(constant), [&x[0], &x[1], &x[2]], 1e-6);
        prop_assert_eq!(state, ContactState::StickSlip);
        prop_assert!(err < 1e-5, "relative error {}", err);
    }

    #[test]
    fn event_jacobian_liftoff((s, m, mu) in regime()) {
        let mut x = coefficients(&s, 1e-4, 2e-5, 2e-5);
        x[0][1] += 2e-4;
        x[1][2] += 1e-4;
        x[2][2] += 1e-4;
        let (err, state) =
            jacobian_error_of(March::Events, law(mu, m), effects(false), [&x[0], &x[1], &x[2]], 1e-6);
        prop_assert_eq!(state, ContactState::StickSlipLiftoff);
        prop_assert!(err < 1e-5, "relative error {}", err);
    }

    /// A circle of about the stick radius μN/kₜ that slips every period. (Inside it, from
    /// T(0) = 0, the first period slips and the orbit then creeps towards the edge of
    /// the continuum of stuck states: the state reached there is one of that continuum,
    /// its forces are not a differentiable function of the path, under either law.)
    ///
    /// The circle's radius exceeds the stick radius by twice the largest excursion of the
    /// random perturbation (the sum of its coefficients' magnitudes) on top of `reach`:
    /// a path that barely leaves the stick circle somewhere is that close to the stuck
    /// continuum's edge, where the forces' curvature grows without bound and central
    /// differences are no reference. Measured on the case the bare `reach` ≥ 1 found
    /// (the regressions file's entry with reach = 1.0, a perturbation of 9.3e-8 m on a
    /// stick radius of 1e-5 m), against steps of 10⁻⁵, 10⁻⁶, 10⁻⁷: relative errors
    /// 4.9e-2, 2.8e-4, 4.7e-6 at reach 1.0 and 1.8e-2, 1.7e-4, 1.4e-6 at 1.003 (falling
    /// like the step squared: the truncation error of the differences, the analytic
    /// Jacobian is their limit; the sampled law's differences behave alike, 1.5e-3 at
    /// 1.001 and a step of 10⁻⁶), then 8.9e-7 at 1.005, 1.2e-8 at 1.02 and 4.8e-9 at 1.03
    /// for steps of 10⁻⁶; the margin puts that case at reach ≥ 1.019.
    #[test]
    fn event_jacobian_grazing((s, m, mu) in regime(), reach in 1.0..1.1f64) {
        let v0 = 1e-4;
        let mut x = coefficients(&s, 1e-7, v0, 0.0);
        let excursion: f64 = x[0].iter().chain(&x[1]).map(|c| c.abs()).sum();
        let radius = reach * mu * v0 + 2.0 * excursion;
        x[0][1] += radius;
        x[1][2] += radius;
        let l = law(mu, [0.5 * m[0], 0.5 * m[1]]);
        let (err, state) =
            jacobian_error_of(March::Events, l, effects(true), [&x[0], &x[1], &x[2]], 1e-6);
        prop_assert!(err < 1e-5, "relative error {} ({:?})", err, state);
    }

    #[test]
    fn event_jacobian_slight_one_directional_slip(
        (s, m, mu) in regime(),
        angle in 0.0..std::f64::consts::PI,
        log_excess in -9.0..-4.0f64,
        wobble in prop::sample::select(vec![0.0, 1e-3, 0.1]),
    ) {
        let v0 = 1e-4;
        let stick = mu * v0;
        let excess = log_excess.exp() * stick;
        let amplitude = stick + excess;
        let (c, sn) = (angle.cos(), angle.sin());
        let mut x = coefficients(&s, wobble * excess, v0, 0.0);
        x[0][1] += c * amplitude;
        x[1][1] += sn * amplitude;
        let (err, state) =
            jacobian_error_of(March::Events, law(mu, m), effects(true), [&x[0], &x[1], &x[2]], 1e-6);
        prop_assert_eq!(state, ContactState::StickSlip);
        prop_assert!(err < 1e-5, "relative error {}", err);
    }
}

/// Cost of one point's evaluation with each law (forces alone and with the Jacobian), in
/// the stuck, partial-slip, rotating-slip and lift-off regimes at H = 3 and 128 samples:
/// `cargo test --release --test it -- aft_jenkins_2d::events::cost --ignored --nocapture`.
#[test]
#[ignore]
fn cost_per_evaluation() {
    let set = HarmonicSet::up_to(3);
    let l = law(0.3, [0.2, -0.3]);
    let cases = [
        ("stuck", false, coefficients(&[0.3; 21], 1e-6, 1e-3, 1e-5)),
        ("partial slip", false, {
            let mut x = coefficients(&[0.2; 21], 1e-5, 1e-4, 1e-5);
            x[0][1] += 4e-5;
            x[1][2] += 1e-5;
            x
        }),
        ("rotating slip", true, {
            let mut x = coefficients(&[0.1; 21], 1e-5, 1e-4, 0.0);
            x[0][1] += 5e-4;
            x[1][2] += 3e-4;
            x
        }),
        ("lift-off", false, {
            let mut x = coefficients(&[0.1; 21], 1e-5, 2e-5, 2e-5);
            x[0][1] += 2e-4;
            x[1][2] += 1e-4;
            x[2][2] += 1e-4;
            x
        }),
    ];
    for (what, constant, x) in &cases {
        for jacobian in [false, true] {
            let mut times = [0.0; 2];
            let mut states = [ContactState::Open; 2];
            for (k, march) in [March::Sampled, March::Events].into_iter().enumerate() {
                let mut aft = Aft2dWorkspace::new(&set, 128);
                let reps = 200;
                let started = std::time::Instant::now();
                for _ in 0..reps {
                    let r = evaluate(
                        &mut aft,
                        march,
                        &l,
                        effects(*constant),
                        [&x[0], &x[1], &x[2]],
                        jacobian,
                    )
                    .unwrap();
                    states[k] = r.state;
                }
                times[k] = started.elapsed().as_secs_f64() / reps as f64;
            }
            println!(
                "{what} (jacobian {jacobian}): sampled {:.1} µs ({:?}), events {:.1} µs ({:?}), ratio {:.2}",
                1e6 * times[0], states[0], 1e6 * times[1], states[1], times[1] / times[0]
            );
        }
    }
}
