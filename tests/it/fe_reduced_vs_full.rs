//! Reduced (Craig-Bampton) and unreduced (sparse) harmonic balance of the committed blade-pair
//! mesh (≈ 5k DOFs) solve the same friction problem: at frequencies around the first
//! resonance, for both limit cases (m = ±1 on every contact point), the response amplitudes
//! agree within 0.5 %, and so do their largest values (the sampled peaks).

use fricbound::analysis::frf::PointSolver;
use fricbound::analysis::limits::LimitCase;
use fricbound::model::{Formulation, Problem};
use fricbound::scene;

fn problem(extra: &[&str]) -> Problem {
    let overrides: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
    scene::load_problem(
        std::path::Path::new("meshes/blade-pair/blade-pair-2d.toml"),
        &overrides,
    )
    .unwrap()
    .1
}

/// Amplitudes of the first output at `freqs` (Hz), each solved by Newton from the stuck linear
/// response (None where Newton fails).
fn amplitudes(p: &Problem, freqs: &[f64]) -> Vec<Option<f64>> {
    let mut solver = PointSolver::new(p).unwrap();
    freqs
        .iter()
        .map(|&f| {
            let guess = fricbound::analysis::linear::stuck_guess(
                p,
                &p.unknown_harmonics(),
                2.0 * std::f64::consts::PI * f,
            )
            .unwrap();
            solver.solve(&guess, f).ok().map(|q| q.amplitudes[0])
        })
        .collect()
}

#[test]
fn reduced_and_unreduced_limit_responses_agree() {
    let reduced = problem(&[]);
    let full = problem(&["reduction="]);
    assert!(
        reduced.model.n_dofs() < 200,
        "{} reduced DOFs",
        reduced.model.n_dofs()
    );
    assert!(
        full.model.n_dofs() > 4000,
        "{} full DOFs",
        full.model.n_dofs()
    );
    assert_eq!(full.formulation(), Formulation::Sparse);
    let freqs: Vec<f64> = (0..16).map(|i| 852.0 + 1.5 * i as f64).collect();
    for m in [1.0, -1.0] {
        let r = LimitCase::uniform(&reduced, m).apply(&reduced);
        let f = LimitCase::uniform(&full, m).apply(&full);
        let (ar, af) = (amplitudes(&r, &freqs), amplitudes(&f, &freqs));
        let mut compared = 0;
        let (mut peak_r, mut peak_f) = (0.0_f64, 0.0_f64);
        for (i, (a, b)) in ar.iter().zip(&af).enumerate() {
            if let (Some(a), Some(b)) = (a, b) {
                let rel = (a - b).abs() / b;
                assert!(
                    rel < 5e-3,
                    "m = {m}, {} Hz: reduced {a:.6e} vs unreduced {b:.6e} ({:.3} %)",
                    freqs[i],
                    100.0 * rel
                );
                peak_r = peak_r.max(*a);
                peak_f = peak_f.max(*b);
                compared += 1;
            }
        }
        assert!(
            compared >= 12,
            "m = {m}: only {compared} frequencies solved in both models"
        );
        assert!(
            (peak_r - peak_f).abs() < 5e-3 * peak_f,
            "m = {m}: peaks {peak_r:.6e} vs {peak_f:.6e}"
        );
    }
}

/// The Craig-Bampton basis kept with the reduced problem maps its solution back onto the mesh:
/// at one frequency, the first-harmonic displacement of every full-model DOF recovered from the
/// reduced solution matches the unreduced solution within 1 % of the largest amplitude.
#[test]
fn reduced_solution_recovers_the_full_displacement_field() {
    let reduced = problem(&[]);
    let full = problem(&["reduction="]);
    let (Some(fe_r), Some(fe_f)) = (&reduced.fe, &full.fe) else {
        panic!("both problems keep their mesh");
    };
    assert!(fe_r.reduced && fe_r.recovery.is_some());
    assert!(!fe_f.reduced);
    let freq = 860.0;
    let solve = |p: &Problem| {
        let guess = fricbound::analysis::linear::stuck_guess(
            p,
            &p.unknown_harmonics(),
            2.0 * std::f64::consts::PI * freq,
        )
        .unwrap();
        PointSolver::new(p).unwrap().solve(&guess, freq).unwrap()
    };
    let (sr, sf) = (solve(&reduced), solve(&full));
    let block = |p: &Problem, x: &[f64], j: usize| {
        let n = p.model.n_dofs();
        p.fe.as_ref()
            .unwrap()
            .full_values(&x[j * n..(j + 1) * n])
            .unwrap()
    };
    let set = reduced.unknown_harmonics();
    let (c, s) = (set.cos_block(1).unwrap(), set.sin_block(1).unwrap());
    let amp = |p: &Problem, x: &[f64]| -> Vec<f64> {
        let (a, b) = (block(p, x, c), block(p, x, s));
        a.iter().zip(&b).map(|(a, b)| a.hypot(*b)).collect()
    };
    let (ar, af) = (
        amp(&reduced, &sr.coefficients),
        amp(&full, &sf.coefficients),
    );
    assert_eq!(ar.len(), af.len());
    let largest = af.iter().cloned().fold(0.0, f64::max);
    assert!(largest > 0.0);
    let worst = ar
        .iter()
        .zip(&af)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-2 * largest,
        "largest deviation {worst:.3e} m against largest amplitude {largest:.3e} m"
    );
    // The contact states and the VTU written from either solution agree.
    assert_eq!(sr.states, sf.states);
    let dir = std::env::temp_dir().join(format!("fricbound-vtu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let written = fricbound::report::mesh_results::write_point(
        &dir,
        "reduced",
        &reduced,
        &sr.coefficients,
        &sr.states,
    )
    .unwrap()
    .expect("the reduced problem keeps its basis");
    let fields = crate::support::vtu_point_arrays(&crate::support::vtu_piece(&written));
    let names: Vec<&str> = fields.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "contact_state",
            "first_harmonic_amplitude",
            "first_harmonic_cos",
            "first_harmonic_sin",
            "static_displacement"
        ]
    );
    // The amplitude is the modulus of the cosine and sine parts, which hold the phase: both
    // are nonzero somewhere (the damped response is not in phase with the load everywhere).
    let (amplitude, cos, sin) = (
        &fields["first_harmonic_amplitude"],
        &fields["first_harmonic_cos"],
        &fields["first_harmonic_sin"],
    );
    let largest = amplitude.iter().fold(0.0_f64, |m, v| m.max(*v));
    assert!(largest > 0.0);
    for k in 0..amplitude.len() {
        assert!((amplitude[k] - cos[k].hypot(sin[k])).abs() <= 1e-12 * largest);
    }
    assert!(cos.iter().any(|v| v.abs() > 1e-3 * largest));
    assert!(sin.iter().any(|v| v.abs() > 1e-3 * largest));
    std::fs::remove_dir_all(&dir).ok();
}

/// The stuck-contact modes written on the mesh come from the reduced pencil: their lowest
/// frequencies match the unreduced model's (K + contact springs, M), solved independently by
/// the sparse block Lanczos solver, within 0.5 %; the VTU holds one field per mode.
#[test]
fn stuck_modes_on_the_mesh_match_the_unreduced_model() {
    let reduced = problem(&[]);
    let full = problem(&["reduction="]);
    let dir = std::env::temp_dir().join(format!("fricbound-modes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let modes = fricbound::report::mesh_modes::write_stuck_modes(&dir, &reduced, 6)
        .unwrap()
        .expect("the reduced problem keeps its basis");
    assert_eq!(modes.frequencies_hz.len(), 6);
    let text = std::fs::read_to_string(&modes.path).unwrap();
    assert_eq!(
        text.matches("Name=\"mode_").count(),
        6,
        "one field per mode"
    );
    std::fs::remove_dir_all(&dir).ok();

    let n = full.model.n_dofs();
    let mut triplets = full.model.stiffness.triplets();
    triplets.extend(fricbound::analysis::linear::contact_stiffness(&full));
    let k = fricbound::model::matrix::StructuralMatrix::sparse_from_triplets(n, &triplets);
    let (
        fricbound::model::matrix::StructuralMatrix::Sparse(k),
        fricbound::model::matrix::StructuralMatrix::Sparse(m),
    ) = (&k, &full.model.mass)
    else {
        panic!("the unreduced FE model is sparse");
    };
    let shift = -(2.0 * std::f64::consts::PI * 10.0_f64).powi(2);
    let eigen = fricbound_reduction::lowest_eigenpairs(k.as_ref(), m.as_ref(), 6, shift).unwrap();
    for (i, (&fr, &lambda)) in modes.frequencies_hz.iter().zip(&eigen.values).enumerate() {
        let ff = lambda.sqrt() / (2.0 * std::f64::consts::PI);
        assert!(
            (fr - ff).abs() < 5e-3 * ff,
            "mode {}: reduced {fr:.3} Hz, unreduced {ff:.3} Hz",
            i + 1
        );
    }
}

/// The linear references of the unreduced model (sparse solves of an ill-conditioned FE
/// matrix) are computed. With the contacts open, blade 2 (the output) is not connected to the
/// excited blade 1 and stays at rest in both models; with the contacts stuck, off resonance
/// (700 Hz) its response in the two models agrees within 1 %.
#[test]
fn unreduced_linear_references_solve_and_match_the_reduced_ones() {
    use fricbound::analysis::linear::{reference_curve, LinearCase};
    let reduced = problem(&[]);
    let full = problem(&["reduction="]);
    for case in [LinearCase::Open, LinearCase::Stuck] {
        let f = reference_curve(&full, case, 21).unwrap();
        let r = reference_curve(&reduced, case, 21).unwrap();
        assert!(f.amplitudes.iter().flatten().all(|v| v.is_finite()));
        let (a, b) = (r.amplitudes[0][0], f.amplitudes[0][0]);
        match case {
            LinearCase::Open => assert!(a.abs() < 1e-15 && b == 0.0, "open: {a:.3e}, {b:.3e}"),
            LinearCase::Stuck => assert!(
                b > 0.0 && (a - b).abs() < 1e-2 * b,
                "stuck at {} Hz: reduced {a:.4e} m, unreduced {b:.4e} m",
                f.freqs_hz[0]
            ),
        }
    }
}
