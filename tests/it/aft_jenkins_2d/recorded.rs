//! States of the event-resolved 2D law met on the 3D blade pair (`meshes/blade-pair/
//! blade-pair-3d.toml`, 700-1100 Hz, H = 1, 128 samples) that the law failed on: the inputs
//! of two damper contact points, recorded where the continuation cut its steps.

use super::*;

/// The scene's force scale (N: the static pre-load and the harmonic loads summed), which
/// sets the periodicity tolerance's floor as in a run.
const FORCE_SCALE: f64 = 50.05;

/// The scene's patch law on one point (tributary stiffness, N/m).
fn patch_law(k: f64) -> Jenkins2dLaw {
    Jenkins2dLaw {
        kt: k,
        kn: k,
        mu: 0.3,
        initial_state: [0.0, 0.0],
    }
}

fn workspace(samples: usize) -> Aft2dWorkspace {
    let mut aft = Aft2dWorkspace::new(&HarmonicSet::up_to(1), samples);
    aft.settings.force_scale = FORCE_SCALE;
    aft
}

/// The tangential force harmonics at `samples` bracketing samples.
fn forces(l: &Jenkins2dLaw, x: [&[f64]; 3], samples: usize) -> (ContactState, Vec<f64>) {
    let mut aft = workspace(samples);
    let report = aft
        .evaluate_events(l, effects(false), [x[0], x[1]], x[2], false)
        .expect("the march settles");
    let t = aft.t_hat[0].iter().chain(&aft.t_hat[1]).copied().collect();
    (report.state, t)
}

/// Asserts the point's state at 128 bracketing samples and that its forces at 128 and 512
/// samples differ by less than `bound` relative to the largest force.
fn assert_grid_independent(l: &Jenkins2dLaw, x: [&[f64]; 3], state: ContactState, bound: f64) {
    let (found, coarse) = forces(l, x, 128);
    assert_eq!(found, state);
    let (_, fine) = forces(l, x, 512);
    let scale = coarse.iter().fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    let difference = coarse
        .iter()
        .zip(&fine)
        .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()))
        / scale;
    assert!(
        difference < bound,
        "128 against 512 samples: {difference:.2e}"
    );
}

/// A point whose normal gap closes to within 3 × 10⁻¹⁵ m of opening once a period while it
/// slips (v from 3.8 × 10⁻⁸ m down to about −2.7 × 10⁻¹⁵ m): the contact opens and closes
/// again within a sliver of a bracketing cell. The march took the closing's end for the
/// closing itself and alternated between the two phases at one instant (`too many events`).
/// Now the events are located and the forces do not depend on the bracketing grid. (The
/// point lies 3 × 10⁻¹⁵ m from the seam where the opening vanishes, closer than any central
/// difference step that rises above round-off, so its Jacobian is checked by the grazing
/// properties in `events.rs`, not here.)
#[test]
fn a_contact_opening_for_an_instant_while_it_slips_is_located() {
    let l = patch_law(1.111_111_111_111_112_6e6);
    let u1 = [
        6.102_957_721_613_431_5e-6,
        3.767_419_417_968_601e-10,
        -5.564_644_087_787_745e-13,
    ];
    let u2 = [
        3.028_766_415_850_383_3e-6,
        -2.395_165_074_799_07e-10,
        1.097_988_858_257_053e-12,
    ];
    let v = [
        3.820_705_605_023_151e-8,
        3.820_684_533_700_604e-8,
        1.276_744_084_634_616e-10,
    ];
    let x = [&u1[..], &u2[..], &v[..]];
    assert_grid_independent(&l, x, ContactState::StickSlipLiftoff, 1e-11);
}

/// A point whose nearly straight tangential path (amplitude 1.2 × 10⁻⁸ m) slips a little at
/// two instants of each period and creeps into the corner of its thin stuck set, by a ratio of
/// 0.9997 a period (the right damper side at 926.65 Hz). The creep's two grazing peaks lie
/// between samples, where the samples next to them are 10⁻¹⁴ m inside the friction circle,
/// so the corner finder, which looked for the peaks on the samples, never recognised it, and
/// the march ended after 2000 periods with a drift of 3 × 10⁻¹⁶ m (`did not settle`). Now the
/// corner is found from the refined peaks: the state is stuck all period, the slider lies on
/// two friction circles at once, inside all others, and the forces do not depend on the
/// bracketing grid.
#[test]
fn a_creeping_corner_whose_grazings_lie_between_samples_is_found() {
    let l = patch_law(1.111_111_111_111_111_7e6);
    let u1 = [
        -6.080_619_095_708_16e-6,
        1.044_827_953_386_974_7e-8,
        4.039_831_986_086_696_7e-10,
    ];
    let u2 = [
        3.805_902_664_766_275_7e-6,
        -5.426_419_694_862_139_5e-9,
        -2.851_122_115_471_736_4e-10,
    ];
    let v = [
        3.943_766_461_783_095e-8,
        3.562_544_978_570_236_6e-8,
        -4.149_167_156_564_255_5e-11,
    ];
    let x = [&u1[..], &u2[..], &v[..]];
    assert_grid_independent(&l, x, ContactState::Stuck, 1e-11);

    // The slider against the friction circles: g(τ) = |u(τ) − w| − μ kₙ v(τ)/kₜ on a fine
    // grid (H = 1: blocks constant, cos τ, sin τ).
    let mut aft = workspace(128);
    aft.evaluate_events(&l, effects(false), [x[0], x[1]], x[2], false)
        .expect("the march settles");
    let w = aft.slider_start;
    let at = |c: &[f64], t: f64| c[0] + c[1] * t.cos() + c[2] * t.sin();
    let n = 200_000;
    let g: Vec<f64> = (0..n)
        .map(|k| {
            let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            (at(&u1, t) - w[0]).hypot(at(&u2, t) - w[1]) - l.mu * l.kn * at(&v, t) / l.kt
        })
        .collect();
    let amplitude = u1[1].hypot(u1[2]).hypot(u2[1].hypot(u2[2]));
    let highest = g.iter().fold(f64::MIN, |m, &x| m.max(x));
    assert!(
        highest.abs() < 1e-9 * amplitude,
        "the slider touches the friction limit: max g = {highest:.3e} m"
    );
    let touching = (0..n)
        .filter(|&k| {
            let (before, after) = (g[(k + n - 1) % n], g[(k + 1) % n]);
            g[k] >= before && g[k] > after && g[k] > -1e-6 * amplitude
        })
        .count();
    assert_eq!(touching, 2, "the slider sits on two friction circles");
}

/// A point that closes while its trial force grows almost exactly as fast as the friction
/// limit (kₜ|u′| = 0.0846383 N/rad against L′ = 0.0846386 N/rad at the closing): just after it,
/// the stick's exit function and the slip's both lie within the 10⁻¹² band that stands for
/// their round-off, and each phase was taken to end where it began, for ever (`too many
/// events` on the 3D blade pair at 857.2 Hz). After a phase that ends at once, the next one's
/// first cell now reads signs against round-off alone, which finds the short stick that
/// follows. The forces do not depend on the bracketing grid and the Jacobian equals
/// central differences.
#[test]
fn a_contact_closing_with_its_trial_force_as_fast_as_the_limit_is_marched() {
    let l = patch_law(5.555_555_555_555_539e5);
    let u1 = [
        2.369_517_727_749_461_5e-6,
        -2.510_344_050_772_008e-7,
        2.201_736_511_283_204_6e-8,
    ];
    let u2 = [
        2.018_778_369_945_838_7e-6,
        -1.043_264_385_907_125_9e-7,
        7.998_518_790_269_09e-9,
    ];
    let v = [
        6.457_622_351_239_471e-7,
        8.110_466_593_783_59e-7,
        -1.307_874_855_333_614_3e-7,
    ];
    let x = [&u1[..], &u2[..], &v[..]];
    assert_grid_independent(&l, x, ContactState::StickSlipLiftoff, 1e-12);
    let (error, _) = jacobian_error_of(March::Events, l, effects(false), x, 1e-7);
    assert!(
        error < 1e-6,
        "Jacobian against central differences: {error:.2e}"
    );
}
