//! METIS against AMD ordering on a ~10k-DOF 2D plane-stress strip:
//! whole Craig-Bampton reductions (20 modes, 100 boundary DOFs) and the
//! full-model eigen solve. Small sizes so that the bench finishes quickly;
//! the factor sizes of both orderings are printed once.

use criterion::{criterion_group, criterion_main, Criterion};
use fricbound_reduction::testmodels::cantilever_2d;
use fricbound_reduction::{
    craig_bampton, lowest_eigenpairs_with, CbOptions, LanczosOptions, Ordering,
};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mesh = cantilever_2d(10_000, 2.0);
    let bd = &mesh.bodies[0];
    let [nx, ny, _] = bd.nodes;
    let boundary: Vec<usize> = (nx - 50..nx)
        .flat_map(|ix| bd.node_dofs(ix, ny - 1, 0))
        .collect();
    for ordering in [Ordering::Metis, Ordering::Amd] {
        let opts = CbOptions {
            ordering,
            ..CbOptions::with_modes(20)
        };
        let r = craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &boundary, &[], &opts)
            .expect("reduction");
        eprintln!(
            "{ordering}: {} DOFs, factor entries {}, factor {:.3} s (ordering {:.3}, symbolic {:.3}, numeric {:.3})",
            r.report.n_full,
            r.report.factor_nnz,
            r.report.t_ordering + r.report.t_symbolic + r.report.t_numeric,
            r.report.t_ordering,
            r.report.t_symbolic,
            r.report.t_numeric
        );
    }
    let mut g = c.benchmark_group("craig_bampton_10k");
    g.sample_size(10);
    for ordering in [Ordering::Metis, Ordering::Amd] {
        let opts = CbOptions {
            ordering,
            ..CbOptions::with_modes(20)
        };
        g.bench_function(format!("{ordering}"), |b| {
            b.iter(|| {
                black_box(
                    craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &boundary, &[], &opts)
                        .expect("reduction"),
                )
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("eigen_10k_20_modes");
    g.sample_size(10);
    for ordering in [Ordering::Metis, Ordering::Amd] {
        g.bench_function(format!("{ordering}"), |b| {
            b.iter(|| {
                black_box(
                    lowest_eigenpairs_with(
                        mesh.k.as_ref(),
                        mesh.m.as_ref(),
                        20,
                        0.0,
                        ordering,
                        &LanczosOptions::default(),
                    )
                    .expect("eigen"),
                )
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
