//! The pre-load sweep of the paper's Figs. 16a and 16d: at each of 50 pre-loads F0 = 10-500 N,
//! the two limit FRFs (m = +1 and m = −1) around the 3rd resonance (175-245 Hz, steps of at
//! most 0.1 Hz) with their refined resonance peaks. Also one limit FRF alone, and a CI-sized
//! sweep of 5 pre-loads.
//!
//! Sweep points run in parallel with rayon: set `RAYON_NUM_THREADS=1` for single-thread
//! figures (the README's speed table is measured so).

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use fricbound::analysis::limits::{self, LimitCase};
use fricbound::scene;
use fricbound::study::sweep;

const SCENE: &str = include_str!("../meshes/paper-wedge/fig16a-d.toml");

fn f0_sweep(c: &mut Criterion) {
    let spec = scene::parse(SCENE, "fig16a-d", &[])
        .expect("scene parses")
        .sweep
        .expect("the scene has a sweep");
    assert_eq!(spec.values.len(), 50);

    let mut group = c.benchmark_group("f0_sweep");
    group.sampling_mode(SamplingMode::Flat);
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(60));
    group.bench_function("50_preloads_x_2_limit_frfs", |b| {
        b.iter(|| {
            let points = sweep::run(SCENE, "fig16a-d", &[], &spec, |_| {}).expect("sweep runs");
            assert!(points.iter().all(|p| p.failures.is_empty()));
            points
        })
    });
    group.finish();

    let mut group = c.benchmark_group("f0_sweep_ci");
    group.sample_size(10);
    let ci = ["sweep.values=[20.0, 60.0, 120.0, 250.0, 500.0]".to_string()];
    group.bench_function("5_preloads_x_2_limit_frfs", |b| {
        b.iter(|| sweep::run(SCENE, "fig16a-d", &ci, &spec_with(&ci), |_| {}).expect("runs"))
    });
    let (problem, limits) = scene::parse(SCENE, "fig16a-d", &["sweep=".to_string()])
        .and_then(|s| s.validate_with_limits("fig16a-d"))
        .expect("valid");
    let window = limits.as_ref().and_then(|l| l.peak_window_hz);
    let case = LimitCase::uniform(&problem, 1.0);
    group.bench_function("one_limit_frf_F0_120N", |b| {
        b.iter(|| limits::solve_case(&problem, &case, window).expect("solves"))
    });
    group.finish();
}

fn spec_with(overrides: &[String]) -> scene::SweepSpec {
    scene::parse(SCENE, "fig16a-d", overrides)
        .expect("scene parses")
        .sweep
        .expect("the scene has a sweep")
}

criterion_group!(benches, f0_sweep);
criterion_main!(benches);
