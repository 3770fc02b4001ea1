//! The contact states of the small generated blade pair (2 contact pairs per side, 8 interior
//! modes, the scene of `tests/it/error_estimate_fe.rs`) along the upper branch of its resonance
//! near 933.5 Hz, at several harmonic counts and sample counts: why the H = 5 and H = 7 paths
//! differ there (docs/accuracy.md, "The upper branch of the small blade pair").
//!
//! For each setting the FRF is solved over 928-936 Hz; at a few frequencies every crossing of
//! the path is printed with its first-output amplitude and, per contact, its state over the
//! period, its constant tangential force T̂⁰ (N), whether a stuck contact still keeps the
//! march's initial condition T(0) = m μ N(0) (`ic`: it never slipped nor separated, so its T̂⁰
//! depends on m and on N(0)) or forgot it (`hist`: it slipped in the transient or in the period),
//! and its smallest friction margin over the closed samples, min (μN − |T|)/(μ max N) (0 where
//! it slips), and its open samples (`common::describe`).
//!
//! Run: `cargo run --release --example upper_branch_states [H ...] [-- samples=S ...]`
//! (default H = 5 7 9 11 at 128 samples, and 128, 512, 2048 samples at H = 7).

use fricbound::analysis::frf::{self, FrfRun, Silent};
use fricbound::hbm::system::HbmSystem;

mod common;
use common::{describe, SmallBladePair};

/// Frequencies (Hz) at which the crossings of each path are compared.
const PROBES: [f64; 9] = [
    924.3, 928.61, 929.5, 930.5, 931.5, 932.5, 933.2, 934.5, 935.5,
];

/// Every crossing of `freq_hz` by the path of `run`: (interpolated amplitude, index of the path
/// point nearest in frequency on that segment).
fn crossings(run: &FrfRun, freq_hz: f64) -> Vec<(f64, usize)> {
    let mut out: Vec<(f64, usize)> = run
        .crossings(freq_hz, 0)
        .into_iter()
        .map(|c| (c.amplitude, c.nearest_point))
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut settings: Vec<(usize, usize)> = Vec::new();
    for a in &args {
        if let Some(s) = a.strip_prefix("samples=") {
            settings.push((7, s.parse().expect("samples=S")));
        } else if let Ok(h) = a.parse::<usize>() {
            settings.push((h, 128));
        }
    }
    if settings.is_empty() {
        settings = vec![(5, 128), (7, 128), (9, 128), (11, 128), (7, 512), (7, 2048)];
    }
    let scene = SmallBladePair::new();
    let mut runs = Vec::new();
    for (h, samples) in settings {
        let overrides: Vec<String> = [
            "analysis.freq_start_hz=928".to_string(),
            "analysis.freq_end_hz=936".to_string(),
            format!("harmonics.samples={samples}"),
            format!("harmonics.max={h}"),
            "accuracy.estimate=false".to_string(),
        ]
        .to_vec();
        let problem = scene.problem(&overrides);
        let names: Vec<String> = problem.contacts.iter().map(|c| c.name.clone()).collect();
        let started = std::time::Instant::now();
        let run = frf::solve(&problem, &mut Silent).expect("run solves");
        println!(
            "== H = {h}, {samples} samples: {} points in {:.1} s, turning points {:?}, {:?}; contacts {names:?}",
            run.points.len(),
            started.elapsed().as_secs_f64(),
            run.turning_points,
            run.incomplete_reason()
        );
        let mut system = HbmSystem::new(&problem).expect("system");
        for f in PROBES {
            for (a, k) in crossings(&run, f) {
                let p = &run.points[k];
                let head = format!(
                    "H{h:>2} S{samples:>4} {f:8.2} Hz amp {a:.6e} (pt {:.4} Hz):",
                    p.freq_hz
                );
                println!("{head}{}", describe(&mut system, &problem, &p.coefficients));
            }
        }
        runs.push((h, samples, problem, run));
    }
    // Each path's probe crossings carried to the next harmonic count (same samples): the point
    // padded with zero coefficients and solved at its frequency by Newton. Where it lands on
    // the next path's crossing the two are one family refined; elsewhere it is another state.
    for i in 0..runs.len() {
        let Some(j) = (i + 1..runs.len()).find(|&j| runs[j].1 == runs[i].1) else {
            continue;
        };
        let (h, samples, _, run) = &runs[i];
        let (h2, _, problem2, _) = &runs[j];
        let mut solver = frf::PointSolver::new(problem2).expect("point solver");
        let n = problem2.model.n_dofs();
        let blocks2 = problem2.unknown_harmonics().n_blocks();
        for f in PROBES {
            for (a, k) in crossings(run, f) {
                let p = &run.points[k];
                let mut x0 = p.coefficients.clone();
                x0.resize(n * blocks2, 0.0);
                let head = format!(
                    "H{h:>2}->{h2:>2} S{samples:>4} {f:8.2} Hz from amp {a:.6e} (pt {:.4} Hz, amp {:.6e}):",
                    p.freq_hz, p.amplitudes[0]
                );
                match solver.solve(&x0, p.freq_hz) {
                    Ok(q) => {
                        let text = describe(solver.system(), problem2, &q.coefficients);
                        println!(
                            "{head} -> amp {:.6e} ({:+.3e}){text}",
                            q.amplitudes[0],
                            q.amplitudes[0] / p.amplitudes[0] - 1.0
                        );
                    }
                    Err(e) => println!("{head} -> no convergence ({e:?})"),
                }
            }
        }
    }
}
