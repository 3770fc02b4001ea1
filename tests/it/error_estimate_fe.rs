//! The a-posteriori error estimate on the FE scene: the generated 2D blade pair (2 contact
//! pairs per side, 8 interior modes, Craig-Bampton) around the fold of its resonance near
//! 933.5 Hz, at H = 1 and H = 3 against an H = 11 reference path (same samples), itself checked
//! against H = 9. On the upper branch (one contact of a side slips and lifts off, the others
//! stay stuck from the march's initial condition) the stuck contacts' mean tangential forces
//! depend on the harmonic count through N and u at τ = 0, and converge slowly with H: H = 5 is
//! 1-7 % off there, H = 7 up to 0.8 %, H = 9 up to 0.16 % (docs/accuracy.md), hence H = 11.
//! The estimate reaches those harmonics by its extension to 4H + 3 where a contact is stuck all
//! period (`error_estimate::TailTest`), and solves the extended system to convergence where its
//! Newton step leaves its linear range (`error_estimate::LinearRange`). Which points a
//! truncation estimate cannot size is computed, not listed: those the estimate reports as not
//! sizeable, and those where a contact's regime differs from the reference point's.

use crate::common;

use fricbound::analysis::error_estimate::{ErrorEstimator, EstimateMethod, EstimateProblems};
use fricbound::analysis::frf::{self, Silent};
use fricbound::model::Problem;
use fricbound::scene;

/// One compared point: its harmonic count, frequency (Hz), true error (against the
/// reference), estimate, the highest harmonic the estimate extended to, the reference's
/// convergence there, and whether a contact's regime (stuck / stick-slip / lift-off / open)
/// differs between the point and the reference point it is compared with.
struct Compared {
    h: usize,
    freq_hz: f64,
    truth: f64,
    estimate: f64,
    estimate_harmonic: usize,
    convergence: f64,
    regime_change: bool,
    /// How the estimate was formed (one step, solved, not sizeable) and the step's
    /// contraction of the extended residual.
    method: EstimateMethod,
    contraction: f64,
}

fn problem(dir: &std::path::Path, overrides: &[String]) -> Problem {
    let path = dir.join("blade-pair.toml");
    scene::load_problem(&path, overrides)
        .expect("scene is valid")
        .1
}

#[test]
fn truncation_estimate_tracks_the_true_error_on_the_blade_pair() {
    let dir = tempfile::tempdir().unwrap();
    let text = common::blade_pair::reduced_blade_pair_2d(dir.path());
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
            check
                .crossing_nearest(p.freq_hz, 0, p.amplitudes[0])
                .map(|c| c.amplitude)
                .map_or(f64::INFINITY, |a| {
                    (a - p.amplitudes[0]).abs() / p.amplitudes[0]
                })
        })
        .collect();
    for (p, c) in reference.points.iter().zip(&converged).step_by(5) {
        println!("REF {:.5} {:.5e} {c:.3e}", p.freq_hz, p.amplitudes[0]);
    }
    let mut compared: Vec<Compared> = Vec::new();
    // The extended system solved to convergence across the path at every point (what a point
    // next to a fold reports where its across-path step leaves its linear range), against the
    // true error across the path: (H, Hz, true error, solved estimate, reference convergence,
    // regime change), and the solves that did not converge.
    let mut solved_across: Vec<(usize, f64, f64, f64, f64, bool)> = Vec::new();
    let mut solved_across_failed = [0_usize; 2];
    let mut largest = [0.0_f64; 2];
    for (i, h) in [1, 3].into_iter().enumerate() {
        let problem = problem(dir.path(), &with(&[&format!("harmonics.max={h}")]));
        let set = problem.unknown_harmonics();
        let run = frf::solve(&problem, &mut Silent).expect("run solves");
        let refined = EstimateProblems::new(&problem).expect("the estimate is on");
        let mut estimator = ErrorEstimator::new(&problem, &refined).expect("estimator builds");
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
            if let Some(normal) = &acc.path_normal {
                let across =
                    frf::amplitude_across_path(&reference, &reference_set, p, &set, normal, 0)
                        .and_then(|(a, f)| reference.crossing_nearest(f, 0, a).map(|c| (a, c)));
                let omega = 2.0 * std::f64::consts::PI * p.freq_hz;
                match (
                    across,
                    estimator.solved_across(&p.coefficients, omega, normal, acc.estimate_harmonic),
                ) {
                    (Some((a, c)), Some(solved)) => solved_across.push((
                        h,
                        p.freq_hz,
                        (p.amplitudes[0] - a).abs() / a,
                        solved[0],
                        converged[c.segment].max(converged[c.segment + 1]),
                        p.states != reference.points[c.nearest_point].states,
                    )),
                    (Some(_), None) => solved_across_failed[i] += 1,
                    _ => {}
                }
            }
            // The true error of what the point reports: across the path where it reports
            // the across-path step, else at its frequency (on the reference branch nearest in
            // amplitude), with the reference's convergence on the segment used.
            let counterpart = if acc.across_path {
                acc.path_normal.as_ref().and_then(|normal| {
                    frf::amplitude_across_path(&reference, &reference_set, p, &set, normal, 0)
                        .and_then(|(a, f)| {
                            reference
                                .crossing_nearest(f, 0, a)
                                .map(|c| (a, c.segment, c.nearest_point))
                        })
                })
            } else {
                reference
                    .crossing_nearest(p.freq_hz, 0, p.amplitudes[0])
                    .map(|c| (c.amplitude, c.segment, c.nearest_point))
            };
            let Some((a, k, nearest)) = counterpart else {
                continue;
            };
            let truth = (p.amplitudes[0] - a).abs() / a;
            let convergence = converged[k].max(converged[k + 1]);
            let regime_change = p.states != reference.points[nearest].states;
            let (slide, step) = acc.slide_and_step;
            if truth > 1e-4 || acc.across_path {
                println!(
                    "H = {h} {:.5} Hz: amp {:.5e}, true {truth:.3e}, estimate {est:.3e} to \
                     H = {} (across {}, slide {:.1} steps, {:?}, contraction {:.2e}), \
                     reference converged to {convergence:.1e}, regime change {regime_change}",
                    p.freq_hz,
                    p.amplitudes[0],
                    acc.estimate_harmonic,
                    acc.across_path,
                    slide / step,
                    acc.method,
                    acc.contraction
                );
            }
            compared.push(Compared {
                h,
                freq_hz: p.freq_hz,
                truth,
                estimate: est,
                estimate_harmonic: acc.estimate_harmonic,
                convergence,
                regime_change,
                method: acc.method,
                contraction: acc.contraction,
            });
        }
    }
    println!(
        "largest estimates: H = 1 {:.3e}, H = 3 {:.3e}",
        largest[0], largest[1]
    );
    // The criteria where the reference measures the true error: above 1e-3 (with the
    // reference converged to a third of it) the estimate within a factor 3; below 1e-4 (with
    // the reference converged to 1e-4) no warning. Two kinds of points are outside what a
    // truncation estimate can size, and are flagged, counted and printed instead:
    //
    // - points the estimate itself reports as not sizeable (`EstimateMethod::Unsized`: its
    //   Newton step left its linear range and the extended system has no converged solution
    //   at the point's frequency; the run warns there);
    // - points where a contact's regime differs from the reference point they are compared
    //   with (a contact stuck at one and slipping at the other, ...): a step on the point's
    //   own regime cannot see another regime.
    //
    // Where the estimate's one Newton step leaves its linear range (a stuck contact at its
    // friction limit at the point and stuck with a margin on the extended set, below
    // 929.5 Hz: docs/accuracy.md) the point is solved on the extended set to convergence
    // (`EstimateMethod::Solved`); with that, the criterion holds at every other point.
    let mut failures = Vec::new();
    let mut large = [0_usize; 2];
    let mut small = 0;
    let mut unmeasured = 0;
    let mut extended = [0_usize; 2];
    let mut solved = [0_usize; 2];
    let mut regime = Vec::new();
    let mut not_sized = Vec::new();
    let mut ratios = [(f64::INFINITY, 0.0_f64); 2];
    let mut missed = Vec::new();
    // Largest contraction of a kept step, smallest of a solved one, per H.
    let mut contractions = [(0.0_f64, f64::INFINITY); 2];
    for c in &compared {
        let (h, f, truth, est) = (c.h, c.freq_hz, c.truth, c.estimate);
        let i = usize::from(h == 3);
        if c.estimate_harmonic > 2 * h + 1 {
            extended[i] += 1;
        }
        match c.method {
            EstimateMethod::Step => contractions[i].0 = contractions[i].0.max(c.contraction),
            EstimateMethod::Solved => {
                solved[i] += 1;
                contractions[i].1 = contractions[i].1.min(c.contraction);
            }
            _ => {}
        }
        let line = format!(
            "H = {h}, {f:.4} Hz: true {truth:.3e}, estimate {est:.3e} (to H = {}, {:?}, \
             contraction {:.2e})",
            c.estimate_harmonic, c.method, c.contraction
        );
        if c.method == EstimateMethod::Unsized {
            not_sized.push(line);
            continue;
        }
        if c.regime_change {
            regime.push(line);
            continue;
        }
        if truth > 1e-3 && c.convergence <= truth / 3.0 {
            large[i] += 1;
            let ratio = est / truth;
            ratios[i] = (ratios[i].0.min(ratio), ratios[i].1.max(ratio));
            if !(1.0 / 3.0..=3.0).contains(&ratio) {
                missed.push(line);
            }
        } else if truth < 1e-4 && c.convergence < 1e-4 {
            small += 1;
            if est > 0.01 {
                failures.push(format!("{line} warns"));
            }
        } else if truth > 1e-4 {
            unmeasured += 1;
        }
    }
    println!(
        "true error > 1e-3 measured, same regimes: H = 1 {} points (estimate / true \
         {:.2}-{:.2}), H = 3 {} points ({:.2}-{:.2}); {small} below 1e-4; {unmeasured} above \
         1e-4 where the reference is not converged to a third of it; estimates extended to \
         4H + 3: H = 1 {}, H = 3 {}; solved on the extended set: H = 1 {}, H = 3 {}; \
         contraction of kept steps up to {:.2e} / {:.2e}, of solved ones from {:.2e} / {:.2e}; \
         {} points not sizeable; {} points where a contact's regime differs from the reference",
        large[0],
        ratios[0].0,
        ratios[0].1,
        large[1],
        ratios[1].0,
        ratios[1].1,
        extended[0],
        extended[1],
        solved[0],
        solved[1],
        contractions[0].0,
        contractions[1].0,
        contractions[0].1,
        contractions[1].1,
        not_sized.len(),
        regime.len()
    );
    for r in &not_sized {
        println!("not sizeable: {r}");
    }
    for r in &regime {
        println!("regime change: {r}");
    }
    for m in &missed {
        println!("miss: {m}");
    }
    // The solved across-path estimates, with the same criteria.
    let mut across_large = [0_usize; 2];
    let mut across_ratios = [(f64::INFINITY, 0.0_f64); 2];
    let mut across_small = 0;
    let mut across_misses = Vec::new();
    let mut across_regime = 0;
    for &(h, f, truth, est, convergence, regime_change) in &solved_across {
        let i = usize::from(h == 3);
        if regime_change {
            across_regime += 1;
            continue;
        }
        if truth > 1e-3 && convergence <= truth / 3.0 {
            across_large[i] += 1;
            let ratio = est / truth;
            across_ratios[i] = (across_ratios[i].0.min(ratio), across_ratios[i].1.max(ratio));
            if !(1.0 / 3.0..=3.0).contains(&ratio) {
                across_misses.push(format!(
                    "H = {h}, {f:.4} Hz: true {truth:.3e}, solved {est:.3e}"
                ));
            }
        } else if truth < 1e-4 && convergence < 1e-4 {
            across_small += 1;
            if est > 0.01 {
                failures.push(format!(
                    "H = {h}, {f:.4} Hz: true error across the path {truth:.3e}, solved \
                     across-path estimate {est:.3e} warns"
                ));
            }
        }
    }
    println!(
        "solved across the path: H = 1 {} points with true error > 1e-3 (estimate / true \
         {:.2}-{:.2}), H = 3 {} ({:.2}-{:.2}); {across_small} below 1e-4; {across_regime} \
         regime changes; solves not converged: H = 1 {}, H = 3 {}; outside a factor 3: \
         {across_misses:?}",
        across_large[0],
        across_ratios[0].0,
        across_ratios[0].1,
        across_large[1],
        across_ratios[1].0,
        across_ratios[1].1,
        solved_across_failed[0],
        solved_across_failed[1]
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(missed.is_empty(), "misses:\n{}", missed.join("\n"));
    // Measured: H = 1 0.78-1.04 at 59 points, H = 3 0.83-1.82 at 70; 12 and 9 solves do not
    // converge.
    assert!(across_misses.is_empty(), "{across_misses:?}");
    assert!(across_large.iter().all(|&n| n > 20), "{across_large:?}");
    assert!(small > 20, "{small}");
    // Both runs apply the criterion above 1e-3 on the points of both branches.
    assert!(large.iter().all(|&n| n > 20), "{large:?}");
    // Bounded next to the fold (the fixed-frequency estimate was 806 % at H = 1 next to the
    // fold of the larger blade pair): here the largest is a few per cent.
    assert!(largest.iter().all(|&e| e < 0.5), "{largest:?}");
}
