//! Accuracy, exactness, multiplicity and ordering-independence checks of the
//! Craig-Bampton reduction on synthetic 2D FE models (two clamped blades and
//! a damper block, a few thousand DOFs).

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use fricbound_reduction::testmodels::{blades_and_damper, Mesh};
use fricbound_reduction::*;
use std::f64::consts::PI;

/// Blades (50 × 10 elements each) and a damper joined to blade 0 by stuck
/// contact springs: the full K is positive definite.
fn stuck_model() -> (Mesh, Vec<usize>) {
    blades_and_damper(50, 10, true, 6, Some(5e8))
}

/// Boundary: contact DOFs plus an excitation DOF at the tip of each blade.
fn boundary_of(mesh: &Mesh, contact: &[usize]) -> Vec<usize> {
    let mut b = contact.to_vec();
    for body in 0..2 {
        let bd = &mesh.bodies[body];
        let [nx, _, _] = bd.nodes;
        let d = bd.dof(nx - 1, 0, 0, 1).unwrap();
        if !b.contains(&d) {
            b.push(d);
        }
    }
    b
}

fn hz(l: f64) -> f64 {
    l.max(0.0).sqrt() / (2.0 * PI)
}

fn reduced_hz(r: &ReducedModel) -> Vec<f64> {
    let (vals, _) = dense_generalized_eigenvalues(r.stiffness.as_ref(), r.mass.as_ref()).unwrap();
    vals.into_iter().map(hz).collect()
}

/// Two reductions of the same model agree: K_r, the boundary block of M_r,
/// the fixed-interface eigenvalues, Ψ rows, and — since the basis inside a
/// repeated eigenvalue is arbitrary — the coupling block C = M_r[B, modes]
/// through C Cᵀ and the modal parts of recovery rows through r Cᵀ.
fn assert_same_model(a: &ReducedModel, b: &ReducedModel, nb: usize, tol: f64) {
    let rel = |x: faer::MatRef<f64>, y: faer::MatRef<f64>| (x - y).norm_max() / x.norm_max();
    assert!(
        rel(a.stiffness.as_ref(), b.stiffness.as_ref()) < tol,
        "K_r differ"
    );
    let nm = a.n_modes;
    let bb = |r: &ReducedModel| r.mass.submatrix(0, 0, nb, nb).to_owned();
    assert!(
        rel(bb(a).as_ref(), bb(b).as_ref()) < tol,
        "M_r boundary blocks differ"
    );
    for (x, y) in a.modal_eigenvalues.iter().zip(&b.modal_eigenvalues) {
        assert!((x - y).abs() < tol * x);
    }
    // the two blades have equal fixed-interface modes in pairs: the modal
    // basis of a pair is arbitrary, so compare quantities invariant under a
    // rotation of the modal basis: C Cᵀ for the coupling C = M_r[B, modes],
    // and recovered row (modal part) times Cᵀ
    let c = |r: &ReducedModel| r.mass.submatrix(0, nb, nb, nm).to_owned();
    let (ca, cb) = (c(a), c(b));
    let cca = &ca * ca.transpose();
    let ccb = &cb * cb.transpose();
    assert!(
        rel(cca.as_ref(), ccb.as_ref()) < 10.0 * tol,
        "coupling blocks differ"
    );
    for (ra, rb) in a.recovery.iter().zip(&b.recovery) {
        let psi_a = faer::Mat::from_fn(1, nb, |_, j| ra.row[j]);
        let psi_b = faer::Mat::from_fn(1, nb, |_, j| rb.row[j]);
        if psi_a.norm_max() > 0.0 {
            assert!(rel(psi_a.as_ref(), psi_b.as_ref()) < tol, "Ψ rows differ");
        }
        let pa = faer::Mat::from_fn(1, nm, |_, j| ra.row[nb + j]) * ca.transpose();
        let pb = faer::Mat::from_fn(1, nm, |_, j| rb.row[nb + j]) * cb.transpose();
        if pa.norm_max() > 0.0 {
            assert!(rel(pa.as_ref(), pb.as_ref()) < 10.0 * tol, "Φ rows differ");
        }
    }
    // and the reduced models have the same eigenvalues
    let (fa, fb) = (reduced_hz(a), reduced_hz(b));
    for (x, y) in fa.iter().zip(&fb) {
        assert!((x - y).abs() <= 10.0 * tol * x.max(1.0));
    }
}

#[test]
fn lowest_ten_frequencies_within_half_percent() {
    let (mesh, contact) = stuck_model();
    assert!(mesh.n() > 2000, "model of a few thousand DOFs");
    let boundary = boundary_of(&mesh, &contact);
    let full = lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 10, 0.0).unwrap();
    // 60 fixed-interface modes: cut-off about 5 times the 10th frequency
    let opts = CbOptions::with_modes(60);
    let r = craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &boundary, &[], &opts).unwrap();
    assert!(r.report.cutoff_hz > 4.0 * full.frequencies_hz()[9]);
    let red = reduced_hz(&r);
    for (i, f) in full.frequencies_hz().iter().enumerate() {
        let e = (red[i] - f).abs() / f;
        assert!(
            e < 5e-3,
            "mode {i}: full {f} Hz, reduced {} Hz, error {e:e}",
            red[i]
        );
        // the reduced model is a Rayleigh-Ritz approximation: never below
        assert!(red[i] >= f * (1.0 - 1e-9), "mode {i} below the full model");
    }
    // a reduction with too few modes is visibly worse: the check can fail
    let r2 = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[],
        &CbOptions::with_modes(1),
    )
    .unwrap();
    let red2 = reduced_hz(&r2);
    let worst = full
        .frequencies_hz()
        .iter()
        .zip(&red2)
        .map(|(f, g)| (g - f).abs() / f)
        .fold(0.0, f64::max);
    assert!(worst > 5e-3, "one mode is not enough, error {worst:e}");
}

#[test]
fn free_damper_keeps_rigid_body_modes() {
    // damper held only through its contact DOFs: K singular, K_II definite
    let (mesh, contact) = blades_and_damper(40, 8, true, 5, None);
    let boundary = boundary_of(&mesh, &contact);
    // full model: negative shift, 3 rigid-body modes of the damper
    let sigma = -(2.0 * PI * 100.0f64).powi(2);
    let full = lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 10, sigma).unwrap();
    let f_full = full.frequencies_hz();
    assert!(f_full[..3].iter().all(|&f| f < 1.0), "{f_full:?}");
    assert!(f_full[3] > 100.0);
    let r = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[],
        &CbOptions::with_modes(60),
    )
    .unwrap();
    let red = reduced_hz(&r);
    assert!(red[..3].iter().all(|&f| f < 1.0), "{red:?}");
    for i in 3..10 {
        let e = (red[i] - f_full[i]).abs() / f_full[i];
        assert!(e < 5e-3, "mode {i}: {} vs {}", red[i], f_full[i]);
    }
}

#[test]
fn static_response_to_boundary_loads_is_exact() {
    let (mesh, contact) = stuck_model();
    let n = mesh.n();
    let boundary = boundary_of(&mesh, &contact);
    // recover some interior DOFs and some boundary DOFs
    let bd = &mesh.bodies[0];
    let mut recover: Vec<usize> = (1..50)
        .step_by(7)
        .filter_map(|ix| bd.dof(ix, 5, 0, 1))
        .collect();
    recover.push(boundary[3]);
    recover.push(mesh.bodies[2].dof(2, 1, 0, 0).unwrap());
    let r = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &recover,
        &CbOptions::with_modes(10),
    )
    .unwrap();
    // loads on boundary DOFs only
    let mut f = Mat::<f64>::zeros(n, 1);
    let mut fr = Mat::<f64>::zeros(r.size(), 1);
    for (pos, &b) in boundary.iter().enumerate() {
        let v = ((pos * 37 % 11) as f64 - 5.0) * 10.0;
        f[(b, 0)] = v;
        fr[(pos, 0)] = v;
    }
    let kd = mesh.k.to_dense();
    kd.llt(Side::Lower).unwrap().solve_in_place(f.as_mut());
    let u = f;
    r.stiffness
        .llt(Side::Lower)
        .unwrap()
        .solve_in_place(fr.as_mut());
    let q: Vec<f64> = (0..r.size()).map(|i| fr[(i, 0)]).collect();
    let scale = (0..n).map(|i| u[(i, 0)].abs()).fold(0.0, f64::max);
    for (pos, &b) in boundary.iter().enumerate() {
        let e = (q[pos] - u[(b, 0)]).abs() / scale;
        assert!(e < 1e-9, "boundary DOF {b}: {} vs {}", q[pos], u[(b, 0)]);
    }
    for &qm in &q[boundary.len()..] {
        assert!(qm.abs() / scale < 1e-9, "modal coordinate not zero: {qm}");
    }
    let rec = r.recover(&q).unwrap();
    for (row, &d) in r.recovery.iter().zip(&recover) {
        assert_eq!(row.dof, d);
    }
    for (v, &d) in rec.iter().zip(&recover) {
        let e = (v - u[(d, 0)]).abs() / scale;
        assert!(e < 1e-9, "recovered DOF {d}: {v} vs {}", u[(d, 0)]);
    }
}

#[test]
fn symmetric_pair_keeps_every_copy() {
    // two identical clamped blades, no damper: every eigenvalue is double
    let (mesh, contact) = blades_and_damper(40, 8, false, 5, None);
    let full = lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 12, 0.0).unwrap();
    for i in 0..6 {
        let (a, b) = (full.values[2 * i], full.values[2 * i + 1]);
        assert!((a - b).abs() <= 1e-8 * a, "pair {i}: {a} {b}");
        if i > 0 {
            assert!(
                a > full.values[2 * i - 1] * (1.0 + 1e-3),
                "pairs are distinct"
            );
        }
    }
    // odd number of modes asked: the cut pair is completed
    let opts = CbOptions::with_modes(39);
    let r = craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &contact, &[], &opts).unwrap();
    assert_eq!(
        r.n_modes, 40,
        "the 39th eigenvalue is double: both copies kept"
    );
    for i in 0..5 {
        let (a, b) = (r.modal_eigenvalues[2 * i], r.modal_eigenvalues[2 * i + 1]);
        assert!(
            (a - b).abs() <= 1e-8 * a,
            "fixed-interface pair {i}: {a} {b}"
        );
    }
    // reduced model: pairs again, matching the full model
    let red = reduced_hz(&r);
    let f_full = full.frequencies_hz();
    for i in 0..5 {
        assert!((red[2 * i] - red[2 * i + 1]).abs() <= 1e-7 * red[2 * i]);
        let e = (red[2 * i] - f_full[2 * i]).abs() / f_full[2 * i];
        assert!(
            e < 5e-3,
            "pair {i}: {} vs {} ({e:e})",
            red[2 * i],
            f_full[2 * i]
        );
    }
    // without completion exactly 39 are kept
    let opts = CbOptions {
        complete_clusters: false,
        ..CbOptions::with_modes(39)
    };
    let r = craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &contact, &[], &opts).unwrap();
    assert_eq!(r.n_modes, 39);
}

#[test]
fn metis_and_amd_give_the_same_reduced_model() {
    let (mesh, contact) = stuck_model();
    let boundary = boundary_of(&mesh, &contact);
    let recover = vec![boundary[0], 100, 1234];
    let run = |ordering| {
        let opts = CbOptions {
            ordering,
            ..CbOptions::with_modes(15)
        };
        craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &boundary, &recover, &opts).unwrap()
    };
    let a = run(Ordering::Metis);
    let b = run(Ordering::Amd);
    assert_eq!(a.n_modes, b.n_modes);
    assert_ne!(a.report.factor_nnz, b.report.factor_nnz);
    assert_same_model(&a, &b, boundary.len(), 1e-10);
    assert_ne!(a.report.factor_nnz, 0);
    assert_eq!(a.report.ordering, Ordering::Metis);
    assert_eq!(b.report.ordering, Ordering::Amd);
}

#[test]
fn results_do_not_depend_on_thread_count_or_block_size() {
    let (mesh, contact) = stuck_model();
    let boundary = boundary_of(&mesh, &contact);
    let run = |threads| {
        let opts = CbOptions {
            threads,
            block_size: 8,
            ..CbOptions::with_modes(12)
        };
        craig_bampton(mesh.k.as_ref(), mesh.m.as_ref(), &boundary, &[7], &opts).unwrap()
    };
    let a = run(1);
    let b = run(2);
    // the same up to round-off (faer's kernels may round differently with
    // the placement of their buffers); the pairs of equal fixed-interface
    // eigenvalues make the modal basis itself arbitrary
    assert_same_model(&a, &b, boundary.len(), 1e-10);
    // block size does not matter either (up to round-off)
    let c = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[7],
        &CbOptions {
            block_size: 1000,
            ..CbOptions::with_modes(12)
        },
    )
    .unwrap();
    assert_same_model(&a, &c, boundary.len(), 1e-10);
}

#[test]
fn reduced_matrices_are_symmetric_and_structured() {
    let (mesh, contact) = stuck_model();
    let boundary = boundary_of(&mesh, &contact);
    let r = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[boundary[2]],
        &CbOptions::with_modes(8),
    )
    .unwrap();
    let nb = boundary.len();
    assert_eq!(r.stiffness.nrows(), nb + 8);
    assert_eq!(r.stiffness, r.stiffness.transpose().to_owned());
    assert_eq!(r.mass, r.mass.transpose().to_owned());
    for a in 0..8 {
        assert_eq!(r.mass[(nb + a, nb + a)], 1.0);
        assert_eq!(r.stiffness[(nb + a, nb + a)], r.modal_eigenvalues[a]);
        for i in 0..nb {
            assert_eq!(r.stiffness[(i, nb + a)], 0.0);
        }
    }
    let f = &r.modal_frequencies_hz;
    assert!(f.windows(2).all(|w| w[0] <= w[1]));
    assert!((r.report.cutoff_hz - f[7]).abs() < 1e-9 * f[7]);
    // recovery row of a boundary DOF is a unit vector
    let row = &r.recovery[0].row;
    assert_eq!(row[2], 1.0);
    assert_eq!(row.iter().filter(|v| **v != 0.0).count(), 1);
    // modal damping: 2 ζ ω on the modal diagonal only
    let c = r.modal_damping(0.01);
    for a in 0..8 {
        let w = 2.0 * PI * f[a];
        assert!((c[(nb + a, nb + a)] - 0.02 * w).abs() < 1e-9 * w);
    }
    assert_eq!(c.norm_max(), c[(nb + 7, nb + 7)]);
    for i in 0..nb {
        assert_eq!(c[(i, i)], 0.0);
    }
    assert!(r.modal_damping_per_mode(&[0.01; 3]).is_err());
    let z: Vec<f64> = (0..8).map(|i| 0.001 * i as f64).collect();
    let c2 = r.modal_damping_per_mode(&z).unwrap();
    assert_eq!(c2[(nb, nb)], 0.0);
    assert!(c2[(nb + 7, nb + 7)] > 0.0);
    // report
    let rep = &r.report;
    assert_eq!(rep.n_full, mesh.n());
    assert_eq!(rep.n_boundary, nb);
    assert_eq!(rep.n_interior, mesh.n() - nb);
    assert!(rep.factor_nnz >= rep.k_ii_nnz);
    assert_eq!(rep.sturm_count, Some(8), "Sturm count = modes kept");
    assert!(rep.t_total > 0.0);
    if cfg!(target_os = "linux") {
        assert!(rep.peak_memory_bytes.unwrap() > 0);
    }
    assert!(format!("{rep}").contains("Craig-Bampton"));
}

#[test]
fn guyan_and_pure_modal_limits() {
    let (mesh, contact) = stuck_model();
    let boundary = boundary_of(&mesh, &contact);
    // no modes: Guyan reduction, K_r = K_BB + K_BI Ψ only
    let g = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[10],
        &CbOptions::with_modes(0),
    )
    .unwrap();
    assert_eq!(g.n_modes, 0);
    assert_eq!(g.size(), boundary.len());
    assert_eq!(g.recovery[0].row.len(), boundary.len());
    let r = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[10],
        &CbOptions::with_modes(5),
    )
    .unwrap();
    let nb = boundary.len();
    let d = (g.stiffness.as_ref() - r.stiffness.submatrix(0, 0, nb, nb)).norm_max();
    assert!(d <= 1e-12 * g.stiffness.norm_max());
    // no boundary: K_r = Λ, M_r = I, the lowest modes of the clamped model
    let strip = fricbound_reduction::testmodels::cantilever_2d(1500, 3.0);
    let m = craig_bampton(
        strip.k.as_ref(),
        strip.m.as_ref(),
        &[],
        &[],
        &CbOptions::with_modes(6),
    )
    .unwrap();
    let full = lowest_eigenpairs(strip.k.as_ref(), strip.m.as_ref(), 6, 0.0).unwrap();
    for i in 0..6 {
        assert_eq!(m.mass[(i, i)], 1.0);
        assert!((m.stiffness[(i, i)] - full.values[i]).abs() < 1e-9 * full.values[i]);
    }
}
