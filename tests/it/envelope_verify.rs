//! Time-domain validation of the response envelope (`[limits] envelope`): steady states of the
//! time integration (`analysis::verify`, the same equations and contact law, Newmark) started at
//! rest at the static equilibrium of random initial slider states (one m per damper side, seeded)
//! settle inside the envelope of the harmonic balance over all m per side, on the paper case
//! around the 3rd resonance (`meshes/paper-wedge/fig13-3rd.toml`, with damper damping
//! C_D = 5 N s/m on xD, yD so that the states settle).

use fricbound::analysis::limits::{self, envelope_at, group_states, EnvelopeMode, EnvelopeSeeds};
use fricbound::analysis::verify::{self, VerifySettings};
use fricbound::model::Problem;
use std::path::Path;

/// Highest harmonic of the harmonic balance (and of the analysis of the last period).
const H: usize = 5;

/// The scene of Figs. 13-14 at H = 5 with damper damping C_D = 5 N s/m.
fn fig13_damped() -> Problem {
    let overrides: Vec<String> = [
        format!("harmonics.max={H}"),
        "model.damping.4.4=5".to_string(),
        "model.damping.5.5=5".to_string(),
    ]
    .to_vec();
    fricbound::scene::load(Path::new("meshes/paper-wedge/fig13-3rd.toml"), &overrides)
        .and_then(|s| s.validate("fig13-3rd"))
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A reproducible stream of m ∈ [−1, 1] (xorshift64*, fixed seed).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0
    }
}

/// Relative tolerance between a settled time-domain amplitude and the harmonic balance's: the
/// truncation to H = 5 and the trapezoidal rule's dt error at 1 280 steps per period; the limit
/// states, integrated from their HBM state, must settle within it (checked and printed here).
const TOLERANCE: f64 = 1e-3;

#[test]
fn settled_states_from_random_initial_sliders_lie_inside_the_envelope() {
    let (settled, inside) = check_random_states(&[215.0, 218.0], 3, true);
    assert_eq!((settled, inside), (6, 6));
}

/// The README's table: more frequencies and states (about a minute in release; run with
/// `cargo test --release --test it -- envelope_verify:: --ignored --nocapture`). A state that does
/// not settle within the period budget is reported and not judged; every settled one must lie
/// inside the envelope.
#[test]
#[ignore]
fn more_frequencies_and_states_for_the_readme_table() {
    let (settled, inside) = check_random_states(&[212.0, 215.0, 218.0, 222.0, 226.0], 6, false);
    println!("{inside} of {settled} settled states inside the envelope");
    assert_eq!(settled, inside);
}

/// At each of `freqs`, the envelope of y2 over m per side, then `per_freq` seeded random m
/// vectors integrated from rest: (states that settled, of which inside the envelope). With
/// `strict`, a state that does not settle fails the test.
fn check_random_states(freqs: &[f64], per_freq: usize, strict: bool) -> (usize, usize) {
    let problem = fig13_damped();
    let (_, groups) = EnvelopeMode::Sides.groups(&problem);
    // The limit curves on the frequencies: the envelope's seeds, and the time integration's
    // check on states whose HBM amplitude is known.
    let cases = limits::two_point_cases(&problem);
    let on_freqs: Vec<Vec<limits::GridSolution>> = cases
        .iter()
        .map(|c| {
            let curve = limits::solve_case(&problem, c, None).unwrap_or_else(|e| panic!("{e}"));
            limits::on_grid(&problem, c, &curve.points, freqs).unwrap_or_else(|e| panic!("{e}"))
        })
        .collect();
    let settings = VerifySettings::for_harmonics(H);
    let mut random = Uniform(0x5eed_1234_abcd_0042);
    let (mut settled, mut inside) = (0, 0);
    for (g, &f) in freqs.iter().enumerate() {
        let seeds: Vec<(Vec<f64>, Vec<f64>)> = cases
            .iter()
            .zip(&on_freqs)
            .filter_map(|(c, sols)| {
                sols[g]
                    .as_ref()
                    .map(|(p, _)| (group_states(c, &groups), p.coefficients.clone()))
            })
            .collect();
        assert_eq!(seeds.len(), 2, "{f} Hz: both limit states solved");
        let point = envelope_at(
            &problem,
            &groups,
            f,
            &EnvelopeSeeds {
                states: seeds,
                starts: Vec::new(),
            },
            &limits::envelope::search_settings(),
        );
        let hi = point.max[0].as_ref().expect("envelope max").amplitude;
        let lo = point.min[0].as_ref().expect("envelope min").amplitude;
        println!("{f} Hz: envelope of y2 [{lo:.6e}, {hi:.6e}] m");
        // The tolerance: the time integration started on each limit state settles at its HBM
        // amplitude within it.
        for (c, sols) in cases.iter().zip(&on_freqs) {
            let (hbm, _) = sols[g].as_ref().expect("solved above");
            let p = c.apply(&problem);
            let set = p.unknown_harmonics();
            let start =
                verify::hbm_state(&p, &set, &hbm.coefficients, f, settings.steps_per_period)
                    .unwrap_or_else(|e| panic!("{e}"));
            let response = verify::integrate(&p, f, &start, H, &settings)
                .unwrap_or_else(|e| panic!("{f} Hz, {}: {e}", c.name));
            let difference = (response.amplitudes[0] / hbm.amplitudes[0] - 1.0).abs();
            println!(
                "  limit {}: HBM {:.6e} m, time {:.6e} m (settled {} in {} periods), difference \
                 {difference:.2e}",
                c.name,
                hbm.amplitudes[0],
                response.amplitudes[0],
                response.settled,
                response.periods
            );
            assert!(
                response.settled && difference < TOLERANCE,
                "{f} Hz, {}",
                c.name
            );
        }
        for _ in 0..per_freq {
            let m = vec![random.next(), random.next()];
            let p = limits::LimitCase::per_side(&problem, &m).apply(&problem);
            let start = verify::static_state(&p).unwrap_or_else(|e| panic!("{e}"));
            let response = verify::integrate(&p, f, &start, H, &settings)
                .unwrap_or_else(|e| panic!("{f} Hz, m = {m:?}: {e}"));
            let a = response.amplitudes[0];
            println!(
                "  m = [{:+.3}, {:+.3}]: settled {} in {} periods, y2 {a:.6e} m ({:+.4} % of the \
                 envelope max, {:+.4} % of its min)",
                m[0],
                m[1],
                response.settled,
                response.periods,
                100.0 * (a / hi - 1.0),
                100.0 * (a / lo - 1.0)
            );
            assert!(
                !strict || response.settled,
                "{f} Hz, m = {m:?}: did not settle"
            );
            if !response.settled {
                continue;
            }
            settled += 1;
            assert!(
                a <= hi * (1.0 + TOLERANCE) && a >= lo * (1.0 - TOLERANCE),
                "{f} Hz, m = {m:?}: settled amplitude {a:.6e} outside the envelope \
                 [{lo:.6e}, {hi:.6e}]"
            );
            inside += 1;
        }
    }
    (settled, inside)
}
