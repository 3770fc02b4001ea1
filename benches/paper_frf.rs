//! One full-range FRF of the paper's wedge-damper case (β = 120°, F₀ = 120 N), at H = 1 and
//! H = 5, analytic Jacobian; and H = 1 with forward differences as the baseline; without the
//! error estimate of every point, then at H = 1 and 5 with it (its cost).

use criterion::{criterion_group, criterion_main, Criterion};
use fricbound::analysis::frf::{self, Silent};
use fricbound::scene;
use fricbound::scene::paper_wedge_scene;

fn problem(overrides: &[&str]) -> fricbound::model::Problem {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::parse(paper_wedge_scene(), "paper", &o)
        .expect("paper scene parses")
        .validate("paper")
        .expect("paper scene is valid")
}

fn paper_frf(c: &mut Criterion) {
    let mut group = c.benchmark_group("paper_frf");
    group.sample_size(20);
    for (name, overrides) in [
        ("H1_analytic", vec!["accuracy.estimate=false"]),
        (
            "H5_analytic",
            vec!["harmonics.max=5", "accuracy.estimate=false"],
        ),
        (
            "H1_forward_difference",
            vec![
                "analysis.jacobian=forward-difference",
                "accuracy.estimate=false",
            ],
        ),
        // The same runs with the error estimate of every point (the scene default).
        ("H1_analytic_estimate", vec![]),
        ("H5_analytic_estimate", vec!["harmonics.max=5"]),
    ] {
        let p = problem(&overrides);
        group.bench_function(name, |b| {
            b.iter(|| frf::solve(&p, &mut Silent).expect("paper FRF solves"))
        });
    }
    group.finish();
}

criterion_group!(benches, paper_frf);
criterion_main!(benches);
