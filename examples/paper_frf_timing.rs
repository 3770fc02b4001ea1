//! Times the paper's full-range FRF (H = 1) over repeated solves; a profiling target.
//! Usage: cargo run --release --example paper_frf_timing [-- REPEATS [FIELD=VALUE ...]]

use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let repeats: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(20);
    let overrides: Vec<String> = args.collect();
    let problem =
        fricbound::scene::parse(fricbound::scene::paper_wedge_scene(), "paper", &overrides)
            .and_then(|s| s.validate("paper"))
            .unwrap_or_else(|e| panic!("{e}"));
    let mut best = f64::INFINITY;
    let mut points = 0;
    for _ in 0..repeats {
        let t = Instant::now();
        let run = fricbound::analysis::frf::solve(&problem, &mut fricbound::analysis::frf::Silent)
            .expect("solves");
        best = best.min(t.elapsed().as_secs_f64());
        points = run.points.len();
    }
    println!(
        "{points} points, best of {repeats}: {:.2} ms ({:.3} ms/point)",
        best * 1e3,
        best * 1e3 / points as f64
    );
}
