//! Bad input gives clear, structured errors (no panic).

use faer::sparse::SparseColMat;
use fricbound_reduction::testmodels::{blades_and_damper, cantilever_2d};
use fricbound_reduction::*;

fn small() -> (
    SparseColMat<usize, f64>,
    SparseColMat<usize, f64>,
    Vec<usize>,
) {
    let (mesh, contact) = blades_and_damper(20, 4, true, 3, Some(1e8));
    (mesh.k, mesh.m, contact)
}

/// Position of entry (i, j) in the values of `a`.
fn pos(a: &SparseColMat<usize, f64>, i: usize, j: usize) -> usize {
    let s = a.symbolic();
    let start = s.col_ptr()[j];
    start
        + s.row_idx_of_col_raw(j)
            .iter()
            .position(|&r| r == i)
            .unwrap()
}

#[test]
fn singular_k_ii_names_the_free_body() {
    // damper not tied and none of its DOFs on the boundary
    let (mesh, contact) = blades_and_damper(20, 4, true, 3, None);
    let damper = mesh.bodies[2].all_dofs();
    let boundary: Vec<usize> = contact
        .iter()
        .copied()
        .filter(|d| !damper.contains(d))
        .collect();
    let e = craig_bampton(
        mesh.k.as_ref(),
        mesh.m.as_ref(),
        &boundary,
        &[],
        &CbOptions::with_modes(4),
    )
    .unwrap_err();
    match &e {
        ReductionError::NotPositiveDefinite { matrix, full, .. } => {
            assert_eq!(*matrix, "K_II");
            assert!(damper.contains(full), "DOF {full} is not in the damper");
        }
        other => panic!("unexpected error {other}"),
    }
    let msg = e.to_string();
    assert!(
        msg.contains("not positive definite") && msg.contains("free body"),
        "{msg}"
    );
    // the full model with shift 0 fails the same way; a negative shift works
    assert!(matches!(
        lowest_eigenpairs(mesh.k.as_ref(), mesh.m.as_ref(), 3, 0.0),
        Err(ReductionError::NotPositiveDefinite { .. })
    ));
}

#[test]
fn sizes_that_do_not_fit() {
    let (k, _, contact) = small();
    let other = cantilever_2d(200, 2.0);
    let e = craig_bampton(
        k.as_ref(),
        other.m.as_ref(),
        &contact,
        &[],
        &CbOptions::with_modes(2),
    )
    .unwrap_err();
    assert!(
        matches!(e, ReductionError::BadShape { matrix: "M", .. }),
        "{e}"
    );
    let rect = SparseColMat::<usize, f64>::try_new_from_triplets(3, 4, &[]).unwrap();
    let e = craig_bampton(
        rect.as_ref(),
        rect.as_ref(),
        &[],
        &[],
        &CbOptions::with_modes(0),
    )
    .unwrap_err();
    assert!(
        matches!(e, ReductionError::BadShape { matrix: "K", .. }),
        "{e}"
    );
    let (k, m, contact) = small();
    let n = k.nrows();
    let e = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &contact,
        &[],
        &CbOptions::with_modes(n),
    )
    .unwrap_err();
    assert!(matches!(e, ReductionError::TooManyModes { .. }), "{e}");
    let (a, b) = (k.to_dense(), m.to_dense());
    let e = dense_generalized_eigenvalues(a.as_ref(), b.submatrix(0, 0, 3, 3)).unwrap_err();
    assert!(matches!(e, ReductionError::BadShape { .. }), "{e}");
}

#[test]
fn non_symmetric_k_is_rejected() {
    let (mut k, m, contact) = small();
    // the largest off-diagonal entry of column 0
    let (r0, _) = k
        .as_ref()
        .symbolic()
        .row_idx_of_col_raw(0)
        .iter()
        .zip(k.as_ref().val_of_col(0))
        .filter(|(i, _)| **i != 0)
        .fold(
            (0, 0.0f64),
            |b, (i, v)| if v.abs() > b.1 { (*i, v.abs()) } else { b },
        );
    let p = pos(&k, r0, 0);
    k.val_mut()[p] *= 1.001;
    let e = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &contact,
        &[],
        &CbOptions::with_modes(2),
    )
    .unwrap_err();
    match e {
        ReductionError::NotSymmetric {
            matrix, row, col, ..
        } => {
            assert_eq!(matrix, "K");
            assert!((row, col) == (r0, 0) || (row, col) == (0, r0));
        }
        other => panic!("unexpected error {other}"),
    }
    let (mut k, m, _) = small();
    let p = pos(&k, r0, 0);
    k.val_mut()[p] *= 1.001;
    assert!(matches!(
        lowest_eigenpairs(k.as_ref(), m.as_ref(), 2, 0.0),
        Err(ReductionError::NotSymmetric { .. })
    ));
}

#[test]
fn nan_is_rejected() {
    let (k, mut m, contact) = small();
    let p = pos(&m, 5, 5);
    m.val_mut()[p] = f64::NAN;
    let e = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &contact,
        &[],
        &CbOptions::with_modes(2),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            ReductionError::NonFinite {
                matrix: "M",
                row: 5,
                col: 5,
                ..
            }
        ),
        "{e}"
    );
    let (mut k, m, contact) = small();
    let p = pos(&k, 0, 0);
    k.val_mut()[p] = f64::INFINITY;
    let e = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &contact,
        &[],
        &CbOptions::with_modes(2),
    )
    .unwrap_err();
    assert!(
        matches!(e, ReductionError::NonFinite { matrix: "K", .. }),
        "{e}"
    );
}

#[test]
fn bad_boundary_and_recovery_indices() {
    let (k, m, contact) = small();
    let n = k.nrows();
    let mut b = contact.clone();
    b.push(n);
    let e = craig_bampton(k.as_ref(), m.as_ref(), &b, &[], &CbOptions::with_modes(2)).unwrap_err();
    assert_eq!(
        e,
        ReductionError::IndexOutOfRange {
            list: "boundary",
            index: n,
            position: contact.len(),
            n
        }
    );
    let mut b = contact.clone();
    b.push(contact[1]);
    let e = craig_bampton(k.as_ref(), m.as_ref(), &b, &[], &CbOptions::with_modes(2)).unwrap_err();
    assert_eq!(
        e,
        ReductionError::RepeatedBoundary {
            index: contact[1],
            first: 1,
            second: contact.len()
        }
    );
    assert!(e.to_string().contains("listed twice"));
    let e = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &contact,
        &[n + 5],
        &CbOptions::with_modes(2),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            ReductionError::IndexOutOfRange {
                list: "recover",
                ..
            }
        ),
        "{e}"
    );
    let e = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &contact,
        &[],
        &CbOptions {
            block_size: 0,
            ..CbOptions::with_modes(2)
        },
    )
    .unwrap_err();
    assert!(matches!(e, ReductionError::InvalidArgument(_)));
}

#[test]
fn all_dofs_on_the_boundary_is_the_model_itself() {
    let (k, m, _) = small();
    let n = k.nrows();
    let all: Vec<usize> = (0..n).rev().collect();
    let r = craig_bampton(
        k.as_ref(),
        m.as_ref(),
        &all,
        &[3],
        &CbOptions::with_modes(0),
    )
    .unwrap();
    assert_eq!(r.n_modes, 0);
    let kd = k.to_dense();
    let e = (&r.stiffness - faer::Mat::from_fn(n, n, |i, j| kd[(n - 1 - i, n - 1 - j)])).norm_max();
    assert!(e <= 1e-12 * kd.norm_max());
    assert_eq!(r.recovery[0].row[n - 1 - 3], 1.0);
}
