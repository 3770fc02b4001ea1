//! One Newton iteration (residual, Jacobian, linear solve) of the reduced blade pair with 13
//! contact pairs per side (generator refine 2, contact_refine 2, 20 fixed-interface modes), at
//! H = 1 and H = 3, for each formulation (dense, sparse, condensed, schur) with the analytic
//! Jacobian and with forward differences (the baseline; per contact point for schur).
//! `fricbound bench scaling` measures the same configurations ([`SolverConfig::grid`], the
//! same [`NewtonIteration`]) over more contact counts and harmonics, with whole FRFs; this is
//! its criterion counterpart. Run single-threaded for figures comparable with the README:
//! `RAYON_NUM_THREADS=1`.

use criterion::{criterion_group, criterion_main, Criterion};
use fricbound::study::scaling::{self, ModelSize, NewtonIteration, SolverConfig};

fn formulations(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: 2,
        contact_pairs: None,
    };
    let base = scaling::reduced_problem(size, 20, dir.path()).expect("reduced blade pair");
    let mut group = c.benchmark_group("hbm_iteration_13_pairs_per_side");
    group.sample_size(10);
    for config in SolverConfig::grid(&[1, 3]) {
        let p = config.apply(&base);
        let mut iteration = NewtonIteration::new(&p, 850.0).expect("linear guess");
        let name = format!(
            "h{}_{}_{}",
            config.harmonics,
            scaling::formulation_name(config.formulation),
            scaling::jacobian_name(config.jacobian)
        );
        group.bench_function(name, |b| b.iter(|| iteration.run().expect("solve")));
    }
    group.finish();
}

criterion_group!(benches, formulations);
criterion_main!(benches);
