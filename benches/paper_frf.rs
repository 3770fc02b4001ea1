//! One full-range FRF of the paper's wedge-damper case (β = 120°, F₀ = 120 N), at H = 1 and
//! H = 5, analytic Jacobian; and H = 1 with forward differences as the baseline; without the
//! error estimate of every point, then at H = 1 and 5 with it (its cost).
//!
//! `oscillator_frf`: one FRF (5-40 Hz, H = 1) of a one-DOF Jenkins oscillator, the smallest
//! problem there is (m = 1 kg, k = 10⁴ N/m, c = 2 N·s/m, a contact to ground with
//! kₜ = kₙ = 10⁵ N/m, μ = 0.3 and a constant 10 N normal load, 256 samples), without and
//! with the error estimate: the floor of the per-point cost.
//!
//! `contact_law_residual`: one harmonic-balance residual, and one residual with its Jacobian
//! (`_jacobian`), with every contact on the
//! event-resolved law (`jenkins-1d`) against the sampled one (`jenkins-1d-sampled`) at 128,
//! 512 and 2048 samples per period: on the paper case at its resonance peak (H = 1, 3) and on
//! the reduced 2D blade pair with 49 contact pairs per side (contact_refine 8) at H = 3 and 5,
//! at 850 Hz with the response the stuck linear system gives there.

use criterion::{criterion_group, criterion_main, Criterion};
use fricbound::analysis::frf::{self, Silent};
use fricbound::contact::TimeResolution;
use fricbound::hbm::HbmSystem;
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::scene::paper_wedge_scene;
use fricbound::study::scaling::{self, ModelSize};
use std::time::Duration;

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

/// The one-DOF Jenkins oscillator of `oscillator_frf`, the tests' scene.
const JENKINS_OSCILLATOR: &str = include_str!("../tests/it/common/jenkins-oscillator.toml");

fn oscillator_frf(c: &mut Criterion) {
    let mut group = c.benchmark_group("oscillator_frf");
    for (name, estimate) in [("H1", "false"), ("H1_estimate", "true")] {
        let o = vec![format!("accuracy.estimate={estimate}")];
        let p = scene::parse(JENKINS_OSCILLATOR, "oscillator", &o)
            .expect("oscillator scene parses")
            .validate("oscillator")
            .expect("oscillator scene is valid");
        group.bench_function(name, |b| {
            b.iter(|| frf::solve(&p, &mut Silent).expect("oscillator FRF solves"))
        });
    }
    group.finish();
}

/// `problem` with every contact on `resolution` and `samples` per period.
fn with_law(problem: &Problem, resolution: TimeResolution, samples: usize) -> Problem {
    let mut p = problem.clone();
    p.samples = samples;
    for c in &mut p.contacts {
        c.resolution = resolution;
    }
    p
}

/// Times one residual, and one residual with its Jacobian (∂R/∂x and ∂R/∂ω), of `problem` at
/// (x, ω) for both laws and three sample counts.
fn residual_group(c: &mut Criterion, name: &str, problem: &Problem, x: &[f64], omega: f64) {
    let mut group = c.benchmark_group(format!("contact_law_residual_{name}"));
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    for samples in [128, 512, 2048] {
        for (law, resolution) in [
            ("events", TimeResolution::Events),
            ("sampled", TimeResolution::Samples),
        ] {
            let p = with_law(problem, resolution, samples);
            let mut system = HbmSystem::new(&p).expect("operator");
            let mut r = vec![0.0; x.len()];
            let mut dr = vec![0.0; x.len()];
            let mut jac = system.new_jacobian();
            group.bench_function(format!("{law}_{samples}"), |b| {
                b.iter(|| system.residual(x, omega, &mut r).expect("residual"))
            });
            group.bench_function(format!("{law}_{samples}_jacobian"), |b| {
                b.iter(|| {
                    system
                        .residual_and_jacobian(x, omega, &mut r, &mut jac, &mut dr)
                        .expect("residual and Jacobian")
                })
            });
        }
    }
    group.finish();
}

fn contact_law_residual(c: &mut Criterion) {
    for h in [1, 3] {
        let p = problem(&[&format!("harmonics.max={h}"), "accuracy.estimate=false"]);
        let run = frf::solve(&p, &mut Silent).expect("paper FRF solves");
        let peak = run
            .points
            .iter()
            .max_by(|a, b| a.amplitudes[0].total_cmp(&b.amplitudes[0]))
            .expect("points");
        let omega = std::f64::consts::TAU * peak.freq_hz;
        residual_group(c, &format!("paper_h{h}"), &p, &peak.coefficients, omega);
    }
    let dir = tempfile::tempdir().expect("temporary folder");
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: 8,
        contact_pairs: None,
    };
    let base = scaling::reduced_problem(size, 20, dir.path()).expect("reduced blade pair");
    for h in [3, 5] {
        let mut p = base.clone();
        p.harmonics = (1..=h).collect();
        let omega = std::f64::consts::TAU * 850.0;
        let system = HbmSystem::new(&p).expect("operator");
        let guess = fricbound::analysis::linear::stuck_guess(&p, system.unknowns(), omega)
            .expect("linear guess");
        residual_group(c, &format!("blade_pair_49_h{h}"), &p, &guess, omega);
    }
}

criterion_group!(benches, paper_frf, oscillator_frf, contact_law_residual);
criterion_main!(benches);
