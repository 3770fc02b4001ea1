//! The schur-lowrank formulation: its structured factorisation of the reduced matrix (a
//! per-harmonic baseline and a low-rank update for the contacts that couple harmonics) solves as
//! the dense LU does, and a limit curve of the reduced blade pair with 49 contact pairs per side
//! at H = 3 (its harmonics eliminated from the glued structure's modes, schur's by LU) has the
//! schur formulation's peaks.

use std::sync::Arc;

use fricbound::hbm::schur::{ReducedSolver, RelativeCoordinates};
use fricbound::numerics::ImplicitFactor;
use fricbound::study::scaling::{self, ModelSize};

/// Contact blocks where every contact is stuck (kt, kn on every coefficient block, no coupling
/// of harmonics) except `slipping` ones, whose blocks are full (deterministic pseudo-random, of
/// entries up to `strength` / 2).
fn contact_values(coords: &RelativeCoordinates, slipping: &[usize], strength: f64) -> Vec<f64> {
    let offsets = coords.value_offsets();
    let nb = coords.n_blocks();
    let mut values = vec![0.0; *offsets.last().unwrap()];
    let mut seed = 12345_u64;
    let mut random = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f64 / (1u64 << 31) as f64) - 0.5
    };
    for (p, &offset) in offsets.iter().enumerate().take(coords.n_contacts()) {
        let k = coords.contact_rows(p);
        for j in 0..nb {
            for i in 0..nb {
                for a in 0..k {
                    for b in 0..k {
                        let at = offset + ((j * nb + i) * k + a) * k + b;
                        values[at] = if slipping.contains(&p) {
                            strength * random()
                        } else if i == j && a == b {
                            2.0e7
                        } else {
                            0.0
                        };
                    }
                }
            }
        }
    }
    values
}

#[test]
fn the_structured_factorisation_solves_as_the_dense_lu() {
    let dir = tempfile::tempdir().unwrap();
    let size = ModelSize {
        contact_refine: 2,
        ..ModelSize::uniform(false, 2)
    };
    let mut p = scaling::reduced_problem(size, 8, dir.path()).unwrap();
    p.harmonics = vec![1, 2, 3];
    let set = p.unknown_harmonics();
    let coords = Arc::new(RelativeCoordinates::new(&p, &set).unwrap());
    let n = coords.n_dofs() * coords.n_blocks();
    let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 101) as f64 - 50.0).collect();
    let omega = 2.0 * std::f64::consts::PI * 850.0;
    let mut signs = Vec::new();
    // Slip stiffnesses up to the stuck one, and far above it (where they decide the sign).
    for (slipping, strength) in [
        (vec![], 0.0),
        (vec![0, 3, 7], 2.0e7),
        (vec![1], 2.0e10),
        (vec![2, 5], 2.0e10),
        (vec![4, 6, 8], 2.0e10),
        (vec![1, 2], -2.0e10),
    ] {
        let values = contact_values(&coords, &slipping, strength);
        let dense = coords.factor(omega, &values, ReducedSolver::Dense).unwrap();
        let structured = coords
            .factor(omega, &values, ReducedSolver::Structured)
            .unwrap();
        assert_eq!(dense.low_rank(), None);
        // Each slipping contact couples all its rows (2 per block); a stuck one none.
        assert_eq!(
            structured.low_rank(),
            Some(2 * coords.n_blocks() * slipping.len()),
            "slipping {slipping:?}"
        );
        let (x, y) = (dense.solve(&b, false), structured.solve(&b, false));
        let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(&y)
            .fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
        assert!(
            diff <= 1e-9 * scale,
            "slipping {slipping:?}: {diff:e} of {scale:e}"
        );
        // And it solves J x = b: the residual of the structured solution.
        let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
        coords.mul_add(omega, &values, 1.0, &y, &mut r);
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(rn <= 1e-9 * bn, "residual {rn:e} of {bn:e}");
        // The sign of the determinant, which orients the continuation's tangent, is the dense
        // LU's: the matrix determinant lemma on the per-harmonic baseline and the update.
        signs.push(dense.det_sign());
        assert_eq!(
            structured.det_sign(),
            dense.det_sign(),
            "slipping {slipping:?}"
        );
    }
    assert!(
        signs.contains(&Some(-1.0)) && signs.contains(&Some(1.0)),
        "{signs:?}"
    );
}

/// One case of `fricbound bench contacts` as its contacts.json writes it. The benchmark runs in
/// its own process: the work counters ([`fricbound::numerics::work`]) are process-wide, and the
/// other tests of this binary add into them while they run.
fn bench_case(dir: &std::path::Path) -> Vec<serde_json::Value> {
    let out = dir.join("bench");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_fricbound"))
        .args([
            "bench",
            "contacts",
            "--contact-refine",
            "8",
            "--harmonics",
            "3",
            "--formulation",
            "schur,schur-lowrank",
            "--points",
            "150",
            "--peaks",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let json = std::fs::read_to_string(out.join("contacts.json")).unwrap();
    serde_json::from_str(&json).unwrap()
}

#[test]
fn a_limit_curve_with_49_pairs_per_side_has_the_schur_peaks() {
    let dir = tempfile::tempdir().unwrap();
    let cases = bench_case(dir.path());
    assert_eq!(cases.len(), 2);
    let (schur, structured) = (&cases[0], &cases[1]);
    let count = |case: &serde_json::Value, field: &str| case["work"][field].as_u64().unwrap();
    assert_eq!(schur["pairs_per_side"], 49);
    assert_eq!(schur["formulation"], "schur");
    assert_eq!(structured["formulation"], "schur-lowrank");
    // The structured factorisation was used, with a rank below the reduced rows.
    let low_rank = count(structured, "low_rank_factorisations");
    assert!(low_rank > 0);
    assert!(count(structured, "low_rank_rows") / low_rank < 49 * 2 * 2 * 7);
    // Its harmonics were eliminated from the glued structure's modes (the blade pair's damping
    // is of low rank), schur's by LU.
    assert!(count(structured, "modal_eliminations") >= 4 * count(structured, "factorisations") / 2);
    assert_eq!(count(schur, "modal_eliminations"), 0);
    let peaks = |case: &serde_json::Value| -> Vec<(f64, f64)> {
        case["peaks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect()
    };
    let (schur_peaks, structured_peaks) = (peaks(schur), peaks(structured));
    assert!(!schur_peaks.is_empty());
    assert_eq!(schur_peaks.len(), structured_peaks.len());
    for (a, b) in schur_peaks.iter().zip(&structured_peaks) {
        let rel = (a.1 - b.1).abs() / a.1.abs();
        assert!(
            rel <= 1e-8,
            "peak at {} Hz: {} against {} ({rel:e})",
            a.0,
            a.1,
            b.1
        );
        assert!(
            (a.0 - b.0).abs() <= 1e-6 * a.0,
            "peak frequency {} against {}",
            a.0,
            b.0
        );
    }
    // Exact solves: Newton takes the same iterations (within round-off effects on a few points).
    let iterations = |case: &serde_json::Value| case["newton_iterations"].as_f64().unwrap();
    let (i0, i1) = (iterations(schur), iterations(structured));
    assert!(
        (i1 - i0).abs() <= 0.05 * i0,
        "{i0} against {i1} Newton iterations"
    );
}
