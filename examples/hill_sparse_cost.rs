//! Cost per point of Hill's stability by the dense eigen solve of the whole spectrum and by the
//! sparse shift-invert solve (`analysis::stability_sparse`), on chains of unit masses with 4
//! Jenkins elements to ground (`study::jacobian::chain_scene`) at H = 3, one converged point at
//! 5 Hz each, and on the paper system at H = 3 and 5 (150 Hz, contacts stuck). Prints a
//! Markdown table: wall times (best of `repeats`), leading exponents and verdicts of both.
//!
//! `cargo run --release --example hill_sparse_cost [max_dense_unknowns]` (default 700: the
//! dense solve is skipped above it).

use std::f64::consts::PI;
use std::time::Instant;

use fricbound::analysis::frf::PointSolver;
use fricbound::analysis::linear::stuck_guess;
use fricbound::analysis::stability_sparse::{
    point_stability_with, HillSolver, ShiftInvertSettings,
};
use fricbound::scene;
use fricbound::study::jacobian::chain_scene;

fn main() {
    let max_dense: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(700);
    let mut cases: Vec<(String, String, Vec<String>, f64)> = [30, 60, 90, 150, 300]
        .iter()
        .map(|&n| {
            (
                format!("chain, {n} masses"),
                chain_scene(n, 4, 3),
                Vec::new(),
                5.0,
            )
        })
        .collect();
    for h in [3, 5] {
        cases.push((
            format!("paper system, H = {h}"),
            scene::paper_wedge_scene().to_string(),
            vec![format!("harmonics.max={h}")],
            150.0,
        ));
    }
    println!("| case | DOFs | unknowns | dense per point | shift-invert per point | dense leading λ (1/s, Hz) | shift-invert leading λ (1/s, Hz), reliable |");
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for (name, text, overrides, freq_hz) in cases {
        let problem = match scene::parse(&text, "case", &overrides).and_then(|s| s.validate("case"))
        {
            Ok(p) => p,
            Err(e) => {
                eprintln!("{name}: {e}");
                std::process::exit(1);
            }
        };
        let set = problem.unknown_harmonics();
        let unknowns = problem.model.n_dofs() * set.n_blocks();
        let omega = 2.0 * PI * freq_hz;
        let mut solver = PointSolver::new(&problem).expect("a point solver");
        let guess = stuck_guess(&problem, &set, omega).expect("the stuck guess");
        let point = solver.solve(&guess, freq_hz).expect("a converged point");
        let time = |solver: &mut PointSolver, hill: &HillSolver, repeats: usize| {
            let mut best = f64::INFINITY;
            let mut out = None;
            for _ in 0..repeats {
                let t0 = Instant::now();
                let s = point_stability_with(solver.system(), &point.coefficients, omega, hill)
                    .expect("a Hill solve");
                best = best.min(t0.elapsed().as_secs_f64());
                out = Some(s);
            }
            (best, out.expect("one repeat"))
        };
        let sparse = HillSolver::ShiftInvert(ShiftInvertSettings::default());
        let (ts, s) = time(&mut solver, &sparse, 3);
        let dense = (unknowns <= max_dense).then(|| time(&mut solver, &HillSolver::Dense, 2));
        let dense_text = dense.map_or(("skipped".to_string(), "—".to_string()), |(td, d)| {
            (
                format!("{:.1} ms", td * 1e3),
                format!("{:.6}, {:.2}", d.floquet_re, d.floquet_freq_hz),
            )
        });
        println!(
            "| {name} | {} | {unknowns} | {} | {:.1} ms | {} | {:.6}, {:.2}, {} |",
            problem.model.n_dofs(),
            dense_text.0,
            ts * 1e3,
            dense_text.1,
            s.floquet_re,
            s.floquet_freq_hz,
            s.reliable
        );
    }
}
