//! One Newton iteration (residual, Jacobian, linear solve) of the reduced blade pair with 13
//! contact pairs per side (generator refine 2, contact_refine 2, 20 fixed-interface modes), at
//! H = 1 and H = 3, for each formulation (dense, sparse, condensed, schur) with the analytic
//! Jacobian and with forward differences (the baseline; per contact point for schur). `fricbound bench scaling` measures the same
//! over more contact counts and harmonics, with whole FRFs; this is its criterion counterpart.
//! Run single-threaded for figures comparable with the README: `RAYON_NUM_THREADS=1`.

use criterion::{criterion_group, criterion_main, Criterion};
use fricbound::continuation::ParametricResidual;
use fricbound::model::{Formulation, JacobianStrategy};
use fricbound::operator::HbmOperator;
use fricbound::scaling::{self, ModelSize};

fn formulations(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let size = ModelSize {
        three_d: false,
        refine: 2,
        contact_refine: 2,
    };
    let base = scaling::reduced_problem(size, 20, dir.path()).expect("reduced blade pair");
    let mut group = c.benchmark_group("hbm_iteration_13_pairs_per_side");
    group.sample_size(10);
    for h in [1usize, 3] {
        for f in [
            Formulation::Dense,
            Formulation::Sparse,
            Formulation::Condensed,
            Formulation::Schur,
        ] {
            for j in [
                JacobianStrategy::Analytic,
                JacobianStrategy::ForwardDifference,
            ] {
                let mut p = base.clone();
                p.harmonics = (1..=h).collect();
                p.samples = (32 * h).max(128);
                p.analysis.formulation = f;
                p.analysis.jacobian = j;
                let mut operator = HbmOperator::new(&p).expect("operator");
                let omega = 2.0 * std::f64::consts::PI * 850.0;
                let guess = fricbound::linear::stuck_guess(&p, operator.unknowns(), omega)
                    .expect("linear guess");
                let x = operator.restrict(&guess);
                let n = operator.dim();
                let (mut r, mut dr) = (vec![0.0; n], vec![0.0; n]);
                let mut jac = operator.new_jacobian();
                let name = format!(
                    "h{h}_{}_{}",
                    scaling::formulation_name(f),
                    scaling::jacobian_name(j)
                );
                group.bench_function(name, |b| {
                    b.iter(|| {
                        operator
                            .residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dr)
                            .expect("residual");
                        let neg: Vec<f64> = r.iter().map(|v| -v).collect();
                        jac.solve(&neg).expect("solve")
                    })
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, formulations);
criterion_main!(benches);
