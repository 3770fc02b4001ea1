//! Reduced (Craig-Bampton) and unreduced (sparse) harmonic balance of the committed blade-pair
//! mesh (≈ 5k DOFs) solve the same friction problem: at frequencies around the first
//! resonance, for both limit cases (m = ±1 on every contact point), the response amplitudes
//! agree within 0.5 %, and so do their largest values (the sampled peaks).

use fricbound::frf::PointSolver;
use fricbound::limits::LimitCase;
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
            let guess = fricbound::linear::stuck_guess(
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
