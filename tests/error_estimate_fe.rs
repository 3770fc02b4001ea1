//! The a-posteriori error estimate on the FE scene: the generated 2D blade pair (2 contact
//! pairs per side, 8 interior modes, Craig-Bampton) around the fold of its resonance near
//! 933.5 Hz, at H = 1 and H = 3 against an H = 11 reference path (same samples), itself checked
//! against H = 9. On the upper branch (one contact of a side slips and lifts off, the others
//! stay stuck from the march's initial condition) the stuck contacts' mean tangential forces
//! depend on the harmonic count through N and u at τ = 0, and converge slowly with H: H = 5 is
//! 1-7 % off there, H = 7 up to 0.8 %, H = 9 up to 0.16 % (docs/accuracy.md), hence H = 11.

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

/// Bands (harmonic count, Hz) where the estimate is known to miss the criteria on
/// this scene; see the test's comment and docs/accuracy.md.
const KNOWN_MISSES: &[(usize, f64, f64)] = &[(3, 924.0, 924.7), (3, 928.60, 928.63)];

/// Whether a failure line ("H = h, f Hz: ...") is at a frequency in [lo, hi].
fn in_band(line: &str, lo: f64, hi: f64) -> bool {
    line.split(", ")
        .nth(1)
        .and_then(|rest| rest.split(" Hz").next())
        .and_then(|f| f.parse::<f64>().ok())
        .is_some_and(|f| (lo..=hi).contains(&f))
}

/// One compared point: its harmonic count, frequency (Hz), true error (against the
/// reference), estimate, the reference's convergence there, the change of its amplitude to the
/// path at H' = 2H + 1 (NaN across the path) and the error left beyond H' (H' against the
/// reference; 0 across the path).
struct Compared {
    h: usize,
    freq_hz: f64,
    truth: f64,
    estimate: f64,
    convergence: f64,
    to_extended: f64,
    beyond: f64,
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
        &with(&["harmonics.max=11", "accuracy.estimate=false"]),
    );
    let reference_set = reference_problem.unknown_harmonics();
    let reference = frf::solve(&reference_problem, &mut Silent).expect("reference solves");
    let check = problem(
        dir.path(),
        &with(&["harmonics.max=9", "accuracy.estimate=false"]),
    );
    let check = frf::solve(&check, &mut Silent).expect("check solves");
    println!(
        "reference: {} points, turning points {:?}; check: {} points",
        reference.points.len(),
        reference.turning_points,
        check.points.len()
    );
    // Convergence of the reference at each of its points: H = 9 against H = 11 on the branch
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
    // The paths the estimates compare with, H' = 2H + 1 (same samples, estimate off): the
    // change from H to H' is what the estimate sizes; the rest of the true error, from H' to
    // the reference, is beyond its reach.
    let extended: Vec<FrfRun> = [3, 7]
        .into_iter()
        .map(|h| {
            let p = problem(
                dir.path(),
                &with(&[&format!("harmonics.max={h}"), "accuracy.estimate=false"]),
            );
            frf::solve(&p, &mut Silent).expect("extended run solves")
        })
        .collect();
    let mut compared: Vec<Compared> = Vec::new();
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
            // At a fixed frequency: the change to H' (what the estimate sizes) and the error
            // left beyond H' (H' against the reference).
            let (to_extended, beyond) = if acc.across_path {
                (f64::NAN, 0.0)
            } else {
                amplitude_near(&extended[i], p.freq_hz, p.amplitudes[0])
                    .map_or((f64::NAN, f64::INFINITY), |(e, _)| {
                        ((p.amplitudes[0] - e).abs() / e, (e - a).abs() / a)
                    })
            };
            let (slide, step) = acc.slide_and_step;
            if truth > 1e-4 || acc.across_path {
                println!(
                    "H = {h} {:.5} Hz: amp {:.5e}, true {truth:.3e}, estimate {est:.3e} \
                     (across {}, slide {:.1} steps), reference converged to {convergence:.1e}, \
                     change to H' {to_extended:.3e}, beyond H' {beyond:.3e}",
                    p.freq_hz,
                    p.amplitudes[0],
                    acc.across_path,
                    slide / step
                );
            }
            compared.push(Compared {
                h,
                freq_hz: p.freq_hz,
                truth,
                estimate: est,
                convergence,
                to_extended,
                beyond,
            });
        }
    }
    println!(
        "largest estimates: H = 1 {:.3e}, H = 3 {:.3e}",
        largest[0], largest[1]
    );
    // The criteria where the reference measures the true error: above 1e-3 (with the
    // reference converged to a third of it) the estimate within a factor 3; below 1e-4 (with
    // the reference converged to 1e-4) no warning. The estimate is one Newton step towards
    // H' = 2H + 1; where the error left beyond H' is more than a third of the true error, the
    // true error is out of its reach (on the upper branch the stuck contacts' mean forces
    // converge slowly and not monotonically with H: docs/accuracy.md): there the estimate is
    // held to the change it sizes, the one to H', within a factor 3 where that change exceeds
    // 1e-3, and the point is counted as out of reach.
    let mut failures = Vec::new();
    let mut large = 0;
    let mut small = 0;
    let mut unmeasured = 0;
    let mut out_of_reach = Vec::new();
    for c in &compared {
        let (h, f, truth, est) = (c.h, c.freq_hz, c.truth, c.estimate);
        let within_three = |x: f64| (x / 3.0..=3.0 * x).contains(&est);
        if truth > 1e-3 && c.convergence <= truth / 3.0 {
            large += 1;
            if c.beyond > truth / 3.0 {
                out_of_reach.push(format!(
                    "H = {h} {f:.2} Hz: true {truth:.2e}, estimate {est:.2e}, change to H' {:.2e}",
                    c.to_extended
                ));
                if c.to_extended > 1e-3 && !within_three(c.to_extended) {
                    failures.push(format!(
                        "H = {h}, {f:.4} Hz: change to H' {:.3e}, estimate {est:.3e}",
                        c.to_extended
                    ));
                }
            } else if !within_three(truth) {
                failures.push(format!(
                    "H = {h}, {f:.4} Hz: true {truth:.3e}, estimate {est:.3e}"
                ));
            }
        } else if truth < 1e-4 && c.convergence < 1e-4 {
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
        "{large} points with a measured true error > 1e-3 (of which {} out of the estimate's \
         reach), {small} below 1e-4, {unmeasured} above 1e-4 where the reference is not \
         converged to a third of it",
        out_of_reach.len()
    );
    for o in &out_of_reach {
        println!("out of reach: {o}");
    }
    // Known misses of the estimate, measured and documented (docs/accuracy.md), both changes
    // of contact regime between H and H' that a first-order step on the point's regime cannot
    // see: the H = 3 path below 924.7 Hz keeps `right-1` stuck where at H = 7 and 11 it
    // stick-slips (the reference folds twice at 924.7-924.9 Hz; the true error is 31 %, the
    // estimate 1.3-4.7 %: it warns but cannot size it), and at 928.61 Hz `left-2` slips at a
    // sample at H = 3 and not at H = 7 (the estimate 12 times below the change to H' = 7). Any
    // other miss fails; the hits of each known miss are printed so that the list can shrink.
    let known = |f: &str| {
        KNOWN_MISSES
            .iter()
            .any(|(h, lo, hi)| f.starts_with(&format!("H = {h}, ")) && in_band(f, *lo, *hi))
    };
    let unknown: Vec<&String> = failures.iter().filter(|f| !known(f)).collect();
    for (h, lo, hi) in KNOWN_MISSES {
        let hits = failures
            .iter()
            .filter(|f| f.starts_with(&format!("H = {h}, ")) && in_band(f, *lo, *hi))
            .count();
        println!("known miss H = {h}, {lo}-{hi} Hz: {hits} points");
    }
    assert!(
        unknown.is_empty(),
        "{}",
        unknown
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(small > 20, "{small}");
    // Bounded next to the fold (the fixed-frequency estimate was 806 % at H = 1 next to the
    // fold of the larger blade pair): here the largest is a few per cent.
    assert!(largest.iter().all(|&e| e < 0.5), "{largest:?}");
}
