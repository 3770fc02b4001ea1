//! Sparse eigen solver: residuals, mass normalisation, M-orthogonality,
//! agreement of the Lanczos and dense paths, repeated eigenvalues.

use faer::Mat;
use fricbound_reduction::testmodels::{blades_and_damper, cantilever_2d};
use fricbound_reduction::*;

fn check_pairs(
    k: &faer::sparse::SparseColMat<usize, f64>,
    m: &faer::sparse::SparseColMat<usize, f64>,
    e: &Eigen,
) {
    let kd = k.to_dense();
    let md = m.to_dense();
    let x = &e.vectors;
    let xmx = x.transpose() * &md * x;
    let xkx = x.transpose() * &kd * x;
    let q = e.values.len();
    // mass-normalised and M-orthogonal, K-orthogonal with diag λ
    let err_m = (&xmx - Mat::<f64>::identity(q, q)).norm_max();
    assert!(err_m < 1e-10, "ΦᵀMΦ − I = {err_m:e}");
    let lmax = e.values.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for i in 0..q {
        for j in 0..q {
            let want = if i == j { e.values[i] } else { 0.0 };
            assert!((xkx[(i, j)] - want).abs() < 1e-9 * lmax, "ΦᵀKΦ[{i},{j}]");
        }
    }
    // residuals
    for c in 0..q {
        let phi = x.col(c);
        let kx = &kd * phi;
        let mx = &md * phi;
        let r = &kx - e.values[c] * &mx;
        let rel = r.norm_l2() / kx.norm_l2();
        assert!(rel < 1e-7, "residual of pair {c}: {rel:e}");
    }
    assert!(e.max_residual < 1e-7);
    assert!(e.values.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn lanczos_pairs_are_accurate_and_m_orthonormal() {
    let mesh = cantilever_2d(3000, 4.0);
    let opts = LanczosOptions {
        dense_below: 0,
        ..Default::default()
    };
    let e = lowest_eigenpairs_with(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        15,
        0.0,
        Ordering::Metis,
        &opts,
    )
    .unwrap();
    assert_eq!(e.values.len(), 15);
    assert!(e.solves > 0);
    check_pairs(&mesh.k, &mesh.m, &e);
}

#[test]
fn lanczos_matches_dense_solver() {
    let mesh = cantilever_2d(1200, 3.0);
    let lanczos = LanczosOptions {
        dense_below: 0,
        block: 3,
        ..Default::default()
    };
    let dense = LanczosOptions {
        dense_below: usize::MAX,
        ..Default::default()
    };
    let a = lowest_eigenpairs_with(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        20,
        0.0,
        Ordering::Amd,
        &lanczos,
    )
    .unwrap();
    let b = lowest_eigenpairs_with(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        20,
        0.0,
        Ordering::Amd,
        &dense,
    )
    .unwrap();
    assert_eq!(b.solves, 0);
    for (x, y) in a.values.iter().zip(&b.values) {
        assert!((x - y).abs() < 1e-10 * y, "{x} vs {y}");
    }
    check_pairs(&mesh.k, &mesh.m, &b);
    // the dense generalized solver on the same (dense) pencil
    let (vals, vecs) =
        dense_generalized_eigenvalues(mesh.k.to_dense().as_ref(), mesh.m.to_dense().as_ref())
            .unwrap();
    for (x, y) in a.values.iter().zip(&vals) {
        assert!((x - y).abs() < 1e-9 * y, "{x} vs {y}");
    }
    let md = mesh.m.to_dense();
    let c0 = vecs.col(0);
    let mass = c0.transpose() * &md * c0;
    assert!((mass - 1.0).abs() < 1e-10);
}

#[test]
fn repeated_eigenvalues_all_found_with_any_block_size() {
    // two identical blades: every eigenvalue has multiplicity 2
    let (mesh, _) = blades_and_damper(30, 6, false, 3, None);
    for block in [1, 2, 8] {
        let opts = LanczosOptions {
            dense_below: 0,
            block,
            ..Default::default()
        };
        let e = lowest_eigenpairs_with(
            mesh.k.as_ref(),
            mesh.m.as_ref(),
            10,
            0.0,
            Ordering::Metis,
            &opts,
        )
        .unwrap();
        for i in 0..5 {
            let (a, b) = (e.values[2 * i], e.values[2 * i + 1]);
            assert!(
                (a - b).abs() <= 1e-8 * a,
                "block {block}: pair {i} = {a}, {b} ({:?})",
                e.frequencies_hz()
            );
        }
        check_pairs(&mesh.k, &mesh.m, &e);
    }
}

#[test]
fn negative_shift_handles_free_bodies() {
    let (mesh, _) = blades_and_damper(20, 4, true, 3, None);
    let sigma = -1e6;
    let e = lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 6, sigma).unwrap();
    // three rigid-body modes of the free damper, then elastic ones
    let lmax = e.values[5];
    for i in 0..3 {
        assert!(
            e.values[i].abs() < 1e-8 * lmax,
            "rigid mode {i}: {}",
            e.values[i]
        );
    }
    assert!(e.values[3] > 1e4);
}
