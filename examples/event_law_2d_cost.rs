//! Cost of one evaluation (forces and Jacobian) of a 2D contact point with the event-resolved
//! `jenkins-2d` law and the sampled `jenkins-2d-sampled` one, at 128 samples (the shipped
//! scenes' count), H = 3 and H = 5, in three regimes: a point slipping along a rotating
//! direction (stick-slip with short sticks), a partial (stick-slip) one and a stick-slip point
//! with lift-off.
//!
//! Usage: `cargo run --release --example event_law_2d_cost [-- REPS]`.

use fricbound::contact::aft2d::{Aft2dWorkspace, Jenkins2dLaw};
use fricbound::contact::harmonic::HarmonicSet;
use fricbound::contact::{ContactEffects, NormalLoad};
use std::time::Instant;

/// Coefficients of u₁, u₂ (amplitude `ua`) and v (mean `v0`, oscillation `va`) up to
/// harmonic `h`, from a fixed pseudo-random sequence, decaying with the harmonic.
fn coefficients(h: usize, ua: f64, v0: f64, va: f64) -> [Vec<f64>; 3] {
    let nb = 2 * h + 1;
    let mut x = [vec![0.0; nb], vec![0.0; nb], vec![0.0; nb]];
    let mut seed = 0.123_f64;
    let mut next = || {
        seed = (seed * 997.0 + 0.31).fract();
        2.0 * seed - 1.0
    };
    x[2][0] = v0;
    let [u1, u2, v] = &mut x;
    for (j, ((p, q), r)) in u1.iter_mut().zip(u2.iter_mut()).zip(v).enumerate() {
        let decay = 1.0 / (1 + j.saturating_sub(1) / 2) as f64;
        *p = ua * next() * decay;
        *q = ua * next() * decay;
        if j > 0 {
            *r = va * next() * decay;
        }
    }
    x
}

fn main() {
    let reps: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200);
    let law = Jenkins2dLaw {
        kt: 1e5,
        kn: 1e5,
        mu: 0.3,
        initial_state: [0.2, -0.3],
    };
    let effects = ContactEffects {
        normal_load: NormalLoad::Variable,
        liftoff: true,
    };
    println!("µs per evaluation with the Jacobian, 128 samples, {reps} repetitions");
    for h in [3, 5] {
        let set = HarmonicSet::up_to(h);
        let cases = [
            ("slipping", {
                let mut x = coefficients(h, 1e-5, 1e-4, 1e-5);
                x[0][1] += 5e-4;
                x[1][2] += 3e-4;
                x
            }),
            ("stick-slip", {
                let mut x = coefficients(h, 1e-5, 1e-4, 1e-5);
                x[0][1] += 4e-5;
                x[1][2] += 1e-5;
                x
            }),
            ("stick-slip-liftoff", {
                let mut x = coefficients(h, 1e-5, 2e-5, 2e-5);
                x[0][1] += 2e-4;
                x[1][2] += 1e-4;
                x[2][2] += 1e-4;
                x
            }),
        ];
        for (what, x) in &cases {
            let mut times = [0.0; 2];
            let mut states = [None, None];
            for (k, events) in [false, true].into_iter().enumerate() {
                let mut aft = Aft2dWorkspace::new(&set, 128);
                let started = Instant::now();
                // Two nearby points in turn (as a Newton's iterates), so no call repeats the last.
                let nearby: Vec<Vec<f64>> = x
                    .iter()
                    .map(|c| c.iter().map(|v| v * (1.0 + 1e-5)).collect())
                    .collect();
                for rep in 0..reps {
                    let y = if rep % 2 == 0 { &x[..] } else { &nearby[..] };
                    let u = [y[0].as_slice(), y[1].as_slice()];
                    let r = if events {
                        aft.evaluate_events(&law, effects, u, &y[2], true)
                    } else {
                        aft.evaluate(&law, effects, u, &y[2], true)
                    }
                    .unwrap();
                    states[k] = Some(r.state);
                }
                times[k] = 1e6 * started.elapsed().as_secs_f64() / reps as f64;
            }
            println!(
                "H = {h} {what:>18}: sampled {:8.1} µs ({:?}), events {:8.1} µs ({:?}), ratio {:6.2}",
                times[0],
                states[0].unwrap(),
                times[1],
                states[1].unwrap(),
                times[1] / times[0]
            );
        }
    }
}
