//! The a-posteriori error estimate of every converged point against the true error: the paper
//! case around its 2nd resonance (where one contact lifts off) at H = 1, 3, 5, 7, each point's
//! first-harmonic amplitude compared with a converged H = 15 path at the same frequency and
//! the same samples per period (so that the true error is the truncation's alone).
//!
//! The criteria: where the true error exceeds 10⁻³ the truncation estimate is within a
//! factor of 3 of it; where it is below 10⁻⁴ the estimate stays below the warning threshold.
//! Measured: never below a third; above 3× at 9 of 220 points, all on the steep flank of the
//! H = 1 curve where it crosses the reference (the test pins that down).
//!
//! The reported estimate is the fixed-frequency one on every point here (no fold: the
//! fixed-frequency step never slides along the path by more than
//! `PathSwitch::SLIDE_STEPS`); the across-path estimate is compared too, against the
//! reference where it crosses the hyperplane normal to the path, and printed.

use fricbound::analysis::error_estimate::{
    run_warnings, ErrorEstimator, EstimateProblems, PathSwitch,
};
use fricbound::analysis::frf::{self, Silent};
use fricbound::model::Problem;
use fricbound::scene;

fn zoom_2nd(overrides: &[String]) -> Problem {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/paper-wedge/zoom-2nd.toml");
    scene::load(&path, overrides)
        .expect("scene loads")
        .validate("zoom-2nd")
        .expect("scene is valid")
}

#[test]
fn truncation_estimate_tracks_the_true_error_on_the_paper_case() {
    // A fine reference path: small steps, so that interpolating it costs far less than 1e-4.
    let reference = zoom_2nd(&[
        "harmonics.max=15".into(),
        "accuracy.estimate=false".into(),
        "analysis.max_step=0.02".into(),
    ]);
    let reference_set = reference.unknown_harmonics();
    let reference = frf::solve(&reference, &mut Silent).expect("reference solves");
    assert!(reference.is_complete());
    // Across the path: each bordered estimate against the reference where it crosses the
    // hyperplane the step stayed in, (H, true error, estimate) where the true error > 1e-3.
    let mut across: Vec<(usize, f64, f64)> = Vec::new();
    let mut across_small_warns = 0;
    let mut largest_slide = 0.0_f64;
    let mut switched = 0;
    // Points per H whose estimate went on to the wider set (4H + 3).
    let mut extended = [0_usize; 4];
    let mut checked_large = 0;
    let mut checked_small = 0;
    let mut failures = Vec::new();
    // Points where the estimate exceeds 3× the true error (conservative side).
    let mut over: Vec<(usize, f64)> = Vec::new();
    // The extended system solved to convergence across the path at every point (what a point
    // next to a fold reports where its across-path step leaves its linear range; no point of
    // this path reports it, so it is formed here for each): (H, true error across the path,
    // solved estimate) where the true error > 1e-3, and the points below 1e-4 that would warn.
    let mut solved_across: Vec<(usize, f64, f64)> = Vec::new();
    let mut solved_across_small = 0;
    let mut solved_across_warns = Vec::new();
    let mut solved_across_failed = 0;
    println!("H  freq_hz   true_err   trunc_est  ratio   sampling_est");
    for h in [1, 3, 5, 7] {
        let problem = zoom_2nd(&[format!("harmonics.max={h}")]);
        let run = frf::solve(&problem, &mut Silent).expect("run solves");
        assert!(run.is_complete());
        let set = problem.unknown_harmonics();
        let refined = EstimateProblems::new(&problem).expect("the estimate is on");
        let mut estimator = ErrorEstimator::new(&problem, &refined).expect("estimator builds");
        for p in &run.points {
            let acc = p
                .accuracy
                .as_ref()
                .expect("every path point has an estimate");
            let (slide, step) = acc.slide_and_step;
            if step > 0.0 {
                largest_slide = largest_slide.max(slide / step);
            }
            switched += usize::from(acc.across_path);
            extended[(h - 1) / 2] += usize::from(acc.estimate_harmonic > 2 * h + 1);
            // The across-path estimate against the reference where it crosses the hyperplane
            // the step stayed in (reported, not asserted: see the module docs).
            if let (Some((_, across_est)), Some(normal)) = (&acc.both_truncation, &acc.path_normal)
            {
                if let Some((amp, _)) =
                    frf::amplitude_across_path(&reference, &reference_set, p, &set, normal, 0)
                {
                    let truth = (p.amplitudes[0] - amp).abs() / amp;
                    if truth > 1e-3 {
                        across.push((h, truth, across_est[0]));
                    } else if truth < 1e-4 && across_est[0] > 0.01 {
                        across_small_warns += 1;
                    }
                    let omega = 2.0 * std::f64::consts::PI * p.freq_hz;
                    match estimator.solved_across(
                        &p.coefficients,
                        omega,
                        normal,
                        acc.estimate_harmonic,
                    ) {
                        Some(solved) if truth > 1e-3 => solved_across.push((h, truth, solved[0])),
                        Some(solved) if truth < 1e-4 => {
                            solved_across_small += 1;
                            if solved[0] > problem.analysis.error_estimate.warn_threshold {
                                solved_across_warns.push((h, p.freq_hz, truth, solved[0]));
                            }
                        }
                        Some(_) => {}
                        None => solved_across_failed += 1,
                    }
                }
            }
            let Some(truth_amp) = frf::amplitude_on_path(&reference.points, p.freq_hz) else {
                continue;
            };
            let truth = (p.amplitudes[0] - truth_amp).abs() / truth_amp;
            let est = acc.truncation[0];
            let ratio = est / truth;
            if (p.freq_hz * 4.0).fract() < 0.05
                || truth > 1e-3 && !(1.0 / 3.0..=3.0).contains(&ratio)
            {
                println!(
                    "{h}  {:8.3}  {truth:.3e}  {est:.3e}  {ratio:6.2}  {:.3e}",
                    p.freq_hz, acc.sampling[0]
                );
            }
            if truth > 1e-3 {
                checked_large += 1;
                if ratio < 1.0 / 3.0 || ratio.is_nan() {
                    failures.push(format!(
                        "H = {h}, {:.4} Hz: true {truth:.3e}, estimate {est:.3e} too low",
                        p.freq_hz
                    ));
                } else if ratio > 3.0 {
                    over.push((h, p.freq_hz));
                }
            }
            if truth < 1e-4 {
                checked_small += 1;
                if est > problem.analysis.error_estimate.warn_threshold {
                    failures.push(format!(
                        "H = {h}, {:.4} Hz: true {truth:.3e} but estimate {est:.3e} warns",
                        p.freq_hz
                    ));
                }
            }
        }
        let warnings = run_warnings(&problem, &frf::accuracy_of(&run.points));
        println!(
            "H = {h}: {} points ({} estimated on the wider set), warnings: {warnings:#?}",
            run.points.len(),
            extended[(h - 1) / 2]
        );
        if h == 1 {
            assert!(
                warnings.iter().any(|w| w.contains("harmonics.max > 1")),
                "H = 1 is 16 % off near the resonance and must warn: {warnings:?}"
            );
        }
    }
    println!(
        "{checked_large} points with true error > 1e-3, {checked_small} below 1e-4; \
         estimate above 3x the true error at {over:?}"
    );
    for h in [1, 3, 5, 7] {
        let ratios: Vec<f64> = across
            .iter()
            .filter(|a| a.0 == h)
            .map(|a| a.2 / a.1)
            .collect();
        let largest = across
            .iter()
            .filter(|a| a.0 == h)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        println!(
            "across the path, H = {h}: {} points with true error > 1e-3, ratio {:.3}-{:.3}, \
             largest true error and estimate there {largest:?}",
            ratios.len(),
            ratios.iter().copied().fold(f64::INFINITY, f64::min),
            ratios.iter().copied().fold(0.0, f64::max)
        );
    }
    let solved_misses: Vec<&(usize, f64, f64)> = solved_across
        .iter()
        .filter(|a| !(1.0 / 3.0..=3.0).contains(&(a.2 / a.1)))
        .collect();
    for h in [1, 3, 5, 7] {
        let ratios: Vec<f64> = solved_across
            .iter()
            .filter(|a| a.0 == h)
            .map(|a| a.2 / a.1)
            .collect();
        println!(
            "solved across the path, H = {h}: {} points with true error > 1e-3, ratio \
             {:.3}-{:.3}",
            ratios.len(),
            ratios.iter().copied().fold(f64::INFINITY, f64::min),
            ratios.iter().copied().fold(0.0, f64::max)
        );
    }
    println!(
        "solved across the path: {solved_across_small} points below 1e-4, of which warn \
         {solved_across_warns:?}; {solved_across_failed} solves did not converge; outside a \
         factor 3: {solved_misses:?}"
    );
    println!(
        "across the path: {across_small_warns} points with true error < 1e-4 would warn; \
         largest slide {largest_slide:.1} steps, {switched} points report the across-path step"
    );
    // The converged across-path solve meets the criteria against the true error across the
    // path (measured: H = 1 0.91-1.01 at 105 points, H = 3 0.99-1.05 at 103, every solve
    // converges, none of the 1036 points below 1e-4 warns).
    assert!(solved_misses.is_empty(), "{solved_misses:?}");
    assert!(solved_across_warns.is_empty(), "{solved_across_warns:?}");
    assert!(solved_across.len() > 100 && solved_across_small > 100);
    // No point of this path is next to a fold: the fixed-frequency step is reported
    // everywhere (the largest slide measured: 21 steps, on the H = 1 flank).
    assert_eq!(switched, 0);
    assert!(largest_slide < PathSwitch::SLIDE_STEPS);
    assert!(checked_large > 20 && checked_small > 20);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Measured: 9 of 220 points, all at H = 1 on the steep flank below the resonance
    // (159.97-160.33 Hz), where the H = 1 curve crosses the reference: the true error at a
    // fixed frequency passes through zero there while the first-order estimate sees the
    // curve's shift. Elsewhere (and at every point of H = 3, 5, 7) the estimate is within 3×.
    assert!(
        over.iter()
            .all(|&(h, f)| h == 1 && (159.9..160.4).contains(&f)),
        "estimate far above the true error away from the H = 1 flank: {over:?}"
    );
    assert!(over.len() * 20 <= checked_large, "{over:?}");
}

/// Where the padded point already solves the extended system within the run's Newton
/// tolerance (every contact stuck all period: the contact forces are linear in the motion and
/// hold no harmonic the point lacks), the estimate is `converged`, 0, without a Newton step;
/// the extended system solved to convergence across the path from that point moves each
/// amplitude by no more than the run resolves.
#[test]
fn a_point_whose_padding_solves_the_extension_is_converged() {
    use fricbound::analysis::error_estimate::{extended_harmonic, EstimateMethod};
    let problem = zoom_2nd(&[
        "harmonics.max=3".into(),
        // A pre-load that keeps both contacts stuck over the whole range.
        "static_loads.0.value=-1e5".into(),
    ]);
    let run = frf::solve(&problem, &mut Silent).expect("run solves");
    assert!(run.is_complete());
    let refined = EstimateProblems::new(&problem).expect("the estimate is on");
    let mut estimator = ErrorEstimator::new(&problem, &refined).expect("estimator builds");
    let mut largest_solved = 0.0_f64;
    let mut solved = 0;
    for p in &run.points {
        assert!(
            p.states.iter().all(|s| s.label() == "stuck"),
            "{:?}",
            p.states
        );
        let acc = p.accuracy.as_ref().expect("every point has an estimate");
        assert_eq!(acc.method, EstimateMethod::Converged, "at {} Hz", p.freq_hz);
        assert_eq!((acc.truncation[0], acc.sampling[0]), (0.0, 0.0));
        let Some(normal) = &acc.path_normal else {
            continue;
        };
        let omega = 2.0 * std::f64::consts::PI * p.freq_hz;
        if let Some(change) =
            estimator.solved_across(&p.coefficients, omega, normal, extended_harmonic(3))
        {
            largest_solved = largest_solved.max(change[0]);
            solved += 1;
        }
    }
    println!(
        "{} points, {solved} solved across the path on H = 7: largest change {largest_solved:.2e}",
        run.points.len()
    );
    assert!(solved > run.points.len() / 2, "{solved}");
    assert!(largest_solved < 1e-8, "{largest_solved:e}");
}
