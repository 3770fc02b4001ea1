//! The a-posteriori error estimate on the FE scene: the generated 2D blade pair (2 contact
//! pairs per side, 8 interior modes, Craig-Bampton) around the fold of its resonance near
//! 933.5 Hz, at H = 1 and H = 3 against an H = 7 reference path (same samples), itself checked
//! against H = 5.

use fricbound::analysis::frf::{self, FrfRun, Silent};
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::study::scaling::{self, ModelSize};

/// The first output's amplitude on the branch of `run` at `freq_hz` nearest to `near` (every
/// segment of a branch that brackets the frequency), with the segment's index.
fn amplitude_near(run: &FrfRun, freq_hz: f64, near: f64) -> Option<(f64, usize)> {
    let starts = run.branch_starts();
    let mut best: Option<(f64, usize)> = None;
    for k in 0..run.points.len().saturating_sub(1) {
        if starts.contains(&(k + 1)) {
            continue;
        }
        let (p, q) = (&run.points[k], &run.points[k + 1]);
        if (p.freq_hz - freq_hz) * (q.freq_hz - freq_hz) > 0.0 || p.freq_hz == q.freq_hz {
            continue;
        }
        let t = (freq_hz - p.freq_hz) / (q.freq_hz - p.freq_hz);
        let a = p.amplitudes[0] + t * (q.amplitudes[0] - p.amplitudes[0]);
        if best.is_none_or(|(b, _)| (a - near).abs() < (b - near).abs()) {
            best = Some((a, k));
        }
    }
    best
}

fn problem(dir: &std::path::Path, overrides: &[String]) -> Problem {
    let path = dir.join("blade-pair.toml");
    scene::load(&path, overrides)
        .expect("scene loads")
        .validate("blade-pair")
        .expect("scene is valid")
}

#[test]
fn truncation_estimate_tracks_the_true_error_on_the_blade_pair() {
    let dir = tempfile::tempdir().unwrap();
    let size = ModelSize {
        contact_pairs: Some(2),
        ..ModelSize::uniform(false, 1)
    };
    scaling::full_problem(size, 1, dir.path()).unwrap();
    let mesh = dir.path().join("blade-pair-2d-r1-p2.msh");
    let text = format!(
        "{}\n[reduction]\nmodes = 8\nmodal_damping = 0.002\n",
        scaling::blade_pair_scene(&mesh, false, 1)
    );
    std::fs::write(dir.path().join("blade-pair.toml"), text).unwrap();
    let range = [
        "analysis.freq_start_hz=928".to_string(),
        "analysis.freq_end_hz=936".to_string(),
        "harmonics.samples=128".to_string(),
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        range
            .iter()
            .cloned()
            .chain(extra.iter().map(|s| s.to_string()))
            .collect()
    };
    let reference_problem = problem(
        dir.path(),
        &with(&["harmonics.max=7", "accuracy.estimate=false"]),
    );
    let reference_set = reference_problem.unknown_harmonics();
    let reference = frf::solve(&reference_problem, &mut Silent).expect("reference solves");
    let check = problem(
        dir.path(),
        &with(&["harmonics.max=5", "accuracy.estimate=false"]),
    );
    let check = frf::solve(&check, &mut Silent).expect("check solves");
    println!(
        "reference: {} points, turning points {:?}; check: {} points",
        reference.points.len(),
        reference.turning_points,
        check.points.len()
    );
    // Convergence of the reference at each of its points: H = 5 against H = 7 on the branch
    // nearest in amplitude at the same frequency.
    let converged: Vec<f64> = reference
        .points
        .iter()
        .map(|p| {
            amplitude_near(&check, p.freq_hz, p.amplitudes[0]).map_or(f64::INFINITY, |(a, _)| {
                (a - p.amplitudes[0]).abs() / p.amplitudes[0]
            })
        })
        .collect();
    for (p, c) in reference.points.iter().zip(&converged).step_by(5) {
        println!("REF {:.5} {:.5e} {c:.3e}", p.freq_hz, p.amplitudes[0]);
    }
    // (H, frequency, true error, estimate, reference convergence there, across the path).
    let mut compared: Vec<(usize, f64, f64, f64, f64, bool)> = Vec::new();
    let mut largest = [0.0_f64; 2];
    for (i, h) in [1, 3].into_iter().enumerate() {
        let problem = problem(dir.path(), &with(&[&format!("harmonics.max={h}")]));
        let set = problem.unknown_harmonics();
        let run = frf::solve(&problem, &mut Silent).expect("run solves");
        // At H = 1 the path leaves the range below the start after the fold and the jump past
        // it finds no point: the run is incomplete above the fold, and its points are compared.
        println!(
            "H = {h}: {} points, turning points {:?}, {:?}",
            run.points.len(),
            run.turning_points,
            run.incomplete_reason()
        );
        for p in &run.points {
            let acc = p
                .accuracy
                .as_ref()
                .expect("every path point has an estimate");
            let est = acc.truncation[0];
            largest[i] = largest[i].max(est);
            // The true error of what the point reports: across the path where it reports
            // the across-path step, else at its frequency (on the reference branch nearest in
            // amplitude), with the reference's convergence on the segment used.
            let counterpart = if acc.across_path {
                acc.path_normal.as_ref().and_then(|normal| {
                    frf::amplitude_across_path(&reference, &reference_set, p, &set, normal, 0)
                        .and_then(|(a, f)| amplitude_near(&reference, f, a).map(|(_, k)| (a, k)))
                })
            } else {
                amplitude_near(&reference, p.freq_hz, p.amplitudes[0])
            };
            let Some((a, k)) = counterpart else {
                continue;
            };
            let truth = (p.amplitudes[0] - a).abs() / a;
            let convergence = converged[k].max(converged[k + 1]);
            let (slide, step) = acc.slide_and_step;
            if truth > 1e-4 || acc.across_path {
                println!(
                    "H = {h} {:.5} Hz: amp {:.5e}, true {truth:.3e}, estimate {est:.3e} \
                     (across {}, slide {:.1} steps), reference converged to {convergence:.1e}",
                    p.freq_hz,
                    p.amplitudes[0],
                    acc.across_path,
                    slide / step
                );
            }
            compared.push((h, p.freq_hz, truth, est, convergence, acc.across_path));
        }
    }
    println!(
        "largest estimates: H = 1 {:.3e}, H = 3 {:.3e}",
        largest[0], largest[1]
    );
    // The criteria where the reference measures the true error: above 1e-3 (with the
    // reference converged to a third of it) the estimate within a factor 3; below 1e-4 (with
    // the reference converged to 1e-4) no warning.
    let mut failures = Vec::new();
    let mut large = 0;
    let mut small = 0;
    let mut unmeasured = 0;
    for &(h, f, truth, est, convergence, _) in &compared {
        if truth > 1e-3 && convergence <= truth / 3.0 {
            large += 1;
            if !(truth / 3.0..=3.0 * truth).contains(&est) {
                failures.push(format!(
                    "H = {h}, {f:.4} Hz: true {truth:.3e}, estimate {est:.3e}"
                ));
            }
        } else if truth < 1e-4 && convergence < 1e-4 {
            small += 1;
            if est > 0.01 {
                failures.push(format!(
                    "H = {h}, {f:.4} Hz: true {truth:.3e}, estimate {est:.3e} warns"
                ));
            }
        } else if truth > 1e-4 {
            unmeasured += 1;
        }
    }
    println!(
        "{large} points with a measured true error > 1e-3, {small} below 1e-4, {unmeasured} \
         above 1e-4 where the reference is not converged to a third of it"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(small > 20, "{small}");
    // Bounded next to the fold (the fixed-frequency estimate was 806 % at H = 1 next to the
    // fold of the larger blade pair): here the largest is a few per cent.
    assert!(largest.iter().all(|&e| e < 0.5), "{largest:?}");
}
