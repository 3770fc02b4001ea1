//! A run's accuracy warnings: consecutive points whose estimate is above the threshold, or not
//! formed, joined in frequency bands and told in words for the status and the files.

use super::problems::{extended_harmonic, wider_harmonic};
use super::report::{EstimateMethod, PointAccuracy};
use crate::model::Problem;

/// A frequency band where an estimate exceeds the scene's threshold, for the end-of-run warning.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyWarning {
    /// `truncation` or `sampling`.
    pub kind: EstimateKind,
    /// Output DOF index (into the problem's outputs).
    pub output: usize,
    /// Lowest and highest frequency of the points above the threshold (Hz).
    pub from_hz: f64,
    /// See `from_hz`.
    pub to_hz: f64,
    /// Largest estimate in the band (relative).
    pub largest: f64,
}

/// Which estimate a warning is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EstimateKind {
    /// Harmonic truncation.
    Truncation,
    /// AFT sampling.
    Sampling,
    /// Points whose truncation error could not be sized ([`EstimateMethod::Unsized`]): the
    /// band holds them whatever their estimate.
    Unsized,
    /// Points whose truncation error was not sized because the scene skips the solve beyond
    /// the step's linear range ([`EstimateMethod::Unsolved`]).
    Unsolved,
}

/// Bands of consecutive points (in path order) where an estimate exceeds `threshold`, per
/// output and kind; NaN estimates (not formed) count as above. Bands less than
/// [`MERGE_FRACTION`] of the points' frequency span apart are reported as one.
pub fn warnings(
    points: &[(f64, &PointAccuracy)],
    outputs: usize,
    threshold: f64,
) -> Vec<AccuracyWarning> {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    let gap = MERGE_FRACTION * (hi - lo).max(0.0);
    let mut merged: Vec<AccuracyWarning> = Vec::new();
    for w in bands(points, outputs, threshold) {
        match merged.last_mut() {
            Some(last)
                if last.kind == w.kind
                    && last.output == w.output
                    && w.from_hz - last.to_hz <= gap
                    && last.from_hz - w.to_hz <= gap =>
            {
                last.from_hz = last.from_hz.min(w.from_hz);
                last.to_hz = last.to_hz.max(w.to_hz);
                if w.largest > last.largest || w.largest.is_nan() {
                    last.largest = w.largest;
                }
            }
            _ => merged.push(w),
        }
    }
    merged
}

/// Fraction of the frequency span under which two warning bands are merged.
pub const MERGE_FRACTION: f64 = 0.02;

/// The bands of [`warnings`] before merging.
fn bands(points: &[(f64, &PointAccuracy)], outputs: usize, threshold: f64) -> Vec<AccuracyWarning> {
    let mut found = Vec::new();
    for kind in [
        EstimateKind::Truncation,
        EstimateKind::Sampling,
        EstimateKind::Unsized,
        EstimateKind::Unsolved,
    ] {
        for output in 0..outputs {
            let mut band: Option<AccuracyWarning> = None;
            for &(freq_hz, acc) in points {
                let values = match kind {
                    EstimateKind::Truncation | EstimateKind::Unsized | EstimateKind::Unsolved => {
                        &acc.truncation
                    }
                    EstimateKind::Sampling => &acc.sampling,
                };
                let e = values.get(output).copied().unwrap_or(f64::NAN);
                let not_sized = matches!(
                    acc.method,
                    EstimateMethod::Unsized | EstimateMethod::Unsolved
                );
                let inside = match kind {
                    // Points not sized warn in their own bands, not as a size.
                    EstimateKind::Truncation => !not_sized && (e > threshold || e.is_nan()),
                    EstimateKind::Sampling => e > threshold || e.is_nan(),
                    EstimateKind::Unsized => acc.method == EstimateMethod::Unsized,
                    EstimateKind::Unsolved => acc.method == EstimateMethod::Unsolved,
                };
                if inside {
                    let b = band.get_or_insert(AccuracyWarning {
                        kind,
                        output,
                        from_hz: freq_hz,
                        to_hz: freq_hz,
                        largest: e,
                    });
                    b.from_hz = b.from_hz.min(freq_hz);
                    b.to_hz = b.to_hz.max(freq_hz);
                    if e > b.largest || e.is_nan() {
                        b.largest = e;
                    }
                } else if let Some(b) = band.take() {
                    found.push(b);
                }
            }
            found.extend(band);
        }
    }
    found
}

/// The relative truncation estimate above which a warning says the size is not to be read:
/// the estimate is one Newton step of the extended system, and a step that changes the
/// amplitude by more than the amplitude itself is outside the reach of the linearisation it
/// comes from. Measured on the reduced blade pair at H = 1 (docs/accuracy.md, "The larger
/// blade pair at H = 1, on its small folds"): its points with estimates of 560-8907 % have no
/// state nearby at H = 3, 5 or 7 (Newton from the padded point does not converge at the
/// point's frequency), and the nearest one across the path is 33-39 % away.
pub const BEYOND_LINEAR: f64 = 1.0;

/// The warning line of a band: where, how large, and which field to raise. `h_max` is the
/// highest balanced harmonic, `samples` the samples per period, `output` the DOF's name.
pub fn warning_text(w: &AccuracyWarning, output: &str, h_max: usize, samples: usize) -> String {
    let size = if w.largest.is_nan() {
        "could not be estimated".to_string()
    } else {
        format!("is estimated at up to {:.2} %", 100.0 * w.largest)
    };
    let (what, advice) = match w.kind {
        EstimateKind::Truncation if w.largest > BEYOND_LINEAR => (
            "harmonic truncation",
            format!(
                "harmonics.max > {h_max} needed; an estimate above {:.0} % is beyond what a \
                 first-order step can size: these points may lie on a branch of the truncated \
                 model that has no counterpart at H = {} (read them as wrong, not as off by that \
                 much, and solve the band at the higher H)",
                100.0 * BEYOND_LINEAR,
                extended_harmonic(h_max)
            ),
        ),
        EstimateKind::Truncation => (
            "harmonic truncation",
            format!(
                "harmonics.max > {h_max} needed (the estimate compares with H = {}, or {} where \
                 contacts stay stuck or the harmonics decay slowly)",
                extended_harmonic(h_max),
                wider_harmonic(h_max)
            ),
        ),
        EstimateKind::Sampling => (
            "AFT sampling",
            format!("harmonics.samples > {samples} needed (try {})", 2 * samples),
        ),
        EstimateKind::Unsolved => {
            return format!(
                "accuracy: the harmonic truncation error of {output}'s amplitude was not sized \
                 between {:.4} and {:.4} Hz: the estimate's Newton step leaves its linear range \
                 there (a contact changes regime with more harmonics), or the error lies beyond \
                 H = {} (a contact stuck all period), and the solve on H = {} (or {}) or the step \
                 on H = {} that sizes it was skipped (accuracy.beyond_linear_range = \"flag\", \
                 or \"auto\" where it costs more than its budget: `fricbound check` says which \
                 and how much); set it to \"solve\", or solve the band at harmonics.max > \
                 {h_max} and compare",
                w.from_hz,
                w.to_hz,
                extended_harmonic(h_max),
                extended_harmonic(h_max),
                wider_harmonic(h_max),
                wider_harmonic(h_max)
            );
        }
        EstimateKind::Unsized => {
            return format!(
                "accuracy: the harmonic truncation error of {output}'s amplitude could not be \
                 sized between {:.4} and {:.4} Hz: the estimate's Newton step leaves its linear \
                 range there (a contact changes regime with more harmonics) and the system on \
                 H = {} (or {}) has no converged solution there (at those frequencies, or \
                 across the path next to a fold); solve the band \
                 at harmonics.max > {h_max} and compare",
                w.from_hz,
                w.to_hz,
                extended_harmonic(h_max),
                wider_harmonic(h_max)
            );
        }
    };
    format!(
        "accuracy: the {what} error of {output}'s amplitude {size} between {:.4} and {:.4} Hz: \
         {advice}",
        w.from_hz, w.to_hz
    )
}

/// The largest estimate per output over `points` (NaN ignored; 0 for no points), truncation
/// then sampling.
pub fn largest(points: &[&PointAccuracy], outputs: usize) -> (Vec<f64>, Vec<f64>) {
    let mut trunc = vec![0.0_f64; outputs];
    let mut samp = vec![0.0_f64; outputs];
    for p in points {
        for (m, v) in trunc.iter_mut().zip(&p.truncation) {
            if v.is_finite() {
                *m = m.max(*v);
            }
        }
        for (m, v) in samp.iter_mut().zip(&p.sampling) {
            if v.is_finite() {
                *m = m.max(*v);
            }
        }
    }
    (trunc, samp)
}

/// The end-of-run warning lines of a run's estimates (frequency in Hz and estimate of each
/// point that has one, in path order; see `crate::analysis::frf::accuracy_of`): one per band
/// where an estimate exceeds the scene's threshold ([`warnings`], [`warning_text`]); empty when
/// the estimate is off or everything is below the threshold.
pub fn run_warnings(problem: &Problem, with: &[(f64, &PointAccuracy)]) -> Vec<String> {
    let h_max = problem.harmonics.iter().copied().max().unwrap_or(1);
    warnings(
        with,
        problem.outputs.len(),
        problem.analysis.error_estimate.warn_threshold,
    )
    .iter()
    .map(|w| {
        let name = &problem.model.dof_names[problem.outputs[w.output]];
        warning_text(w, name, h_max, problem.samples)
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn acc(t: f64, s: f64) -> PointAccuracy {
        PointAccuracy {
            truncation: vec![t],
            sampling: vec![s],
            across_path: false,
            path_normal: None,
            both_truncation: None,
            slide_and_step: (f64::NAN, f64::NAN),
            estimate_harmonic: 3,
            step_changes_regime: false,
            contraction: 0.0,
            method: EstimateMethod::Step,
        }
    }

    #[test]
    fn warning_bands_join_consecutive_points() {
        let a = [
            acc(0.001, 0.0),
            acc(0.05, 0.0),
            acc(0.02, 0.0),
            acc(0.001, 0.2),
            acc(0.03, 0.0),
            acc(0.001, 0.0),
            acc(0.001, 0.0),
            acc(0.04, 0.0),
        ];
        let points: Vec<(f64, &PointAccuracy)> =
            [100.0, 101.0, 102.0, 103.0, 104.0, 120.0, 150.0, 200.0]
                .into_iter()
                .zip(&a)
                .collect();
        let w = warnings(&points, 1, 0.01);
        assert_eq!(w.len(), 3, "{w:?}");
        // 101-102 and 104 are 2 Hz apart, under 2 % of the 100 Hz span: one band.
        assert_eq!(w[0].kind, EstimateKind::Truncation);
        assert_eq!(
            (w[0].from_hz, w[0].to_hz, w[0].largest),
            (101.0, 104.0, 0.05)
        );
        assert_eq!((w[1].from_hz, w[1].to_hz), (200.0, 200.0));
        assert_eq!(w[2].kind, EstimateKind::Sampling);
        assert_eq!((w[2].from_hz, w[2].to_hz), (103.0, 103.0));
        let text = warning_text(&w[0], "y2", 1, 256);
        assert!(text.contains("harmonics.max > 1"), "{text}");
        assert!(text.contains("101.0000 and 104.0000 Hz"), "{text}");
        assert!(!text.contains("no counterpart"), "{text}");
        // Above 100 % the size is beyond a first-order step: the warning says so.
        let huge = AccuracyWarning {
            largest: 89.07,
            ..w[0].clone()
        };
        let text = warning_text(&huge, "y2", 1, 256);
        assert!(text.contains("8907.00 %"), "{text}");
        assert!(text.contains("no counterpart at H = 3"), "{text}");
    }

    /// Points with the truncation estimates `truncation` (sampling 0) and, at the indices
    /// given, the methods given.
    fn marked(truncation: &[f64], methods: &[(usize, EstimateMethod)]) -> Vec<PointAccuracy> {
        let mut a: Vec<PointAccuracy> = truncation.iter().map(|&t| acc(t, 0.0)).collect();
        for &(i, method) in methods {
            a[i].method = method;
        }
        a
    }

    #[test]
    fn unsized_points_warn_in_their_own_band() {
        // Two points not sizeable with small estimates between sized ones, one of them above
        // the threshold: the unsized ones form their own band and do not count as a size.
        let a = marked(
            &[0.001, 0.002, 0.003, 0.05],
            &[(1, EstimateMethod::Unsized), (2, EstimateMethod::Unsized)],
        );
        let points: Vec<(f64, &PointAccuracy)> =
            [100.0, 110.0, 120.0, 200.0].into_iter().zip(&a).collect();
        let w = warnings(&points, 1, 0.01);
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(w[0].kind, EstimateKind::Truncation);
        assert_eq!((w[0].from_hz, w[0].to_hz), (200.0, 200.0));
        assert_eq!(w[1].kind, EstimateKind::Unsized);
        assert_eq!((w[1].from_hz, w[1].to_hz), (110.0, 120.0));
        let text = warning_text(&w[1], "y2", 3, 256);
        assert!(
            text.contains("could not be sized between 110.0000 and 120.0000 Hz"),
            "{text}"
        );
        assert!(text.contains("H = 7 (or 15)"), "{text}");
        assert!(text.contains("harmonics.max > 3"), "{text}");
        assert_eq!(EstimateMethod::Unsized.label(), "unsized");
    }

    #[test]
    fn unsolved_points_warn_in_a_band_of_their_own() {
        // Points flagged because the scene skips the solve (`beyond_linear_range = "flag"`)
        // next to points whose solve failed: two bands, each with its own advice.
        let a = marked(
            &[0.001, 0.002, 0.003, 0.004],
            &[
                (0, EstimateMethod::Unsized),
                (2, EstimateMethod::Unsolved),
                (3, EstimateMethod::Unsolved),
            ],
        );
        let points: Vec<(f64, &PointAccuracy)> =
            [100.0, 150.0, 180.0, 200.0].into_iter().zip(&a).collect();
        let w = warnings(&points, 1, 0.01);
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(w[0].kind, EstimateKind::Unsized);
        assert_eq!((w[0].from_hz, w[0].to_hz), (100.0, 100.0));
        assert_eq!(w[1].kind, EstimateKind::Unsolved);
        assert_eq!((w[1].from_hz, w[1].to_hz), (180.0, 200.0));
        let text = warning_text(&w[1], "y2", 3, 256);
        assert!(
            text.contains("was not sized between 180.0000 and 200.0000 Hz")
                && text.contains("accuracy.beyond_linear_range = \"flag\"")
                && text.contains("set it to \"solve\""),
            "{text}"
        );
        assert_eq!(EstimateMethod::Unsolved.label(), "unsolved");
    }

    #[test]
    fn largest_ignores_unformed_estimates() {
        let a = [acc(0.01, f64::NAN), acc(0.03, 0.002)];
        let refs: Vec<&PointAccuracy> = a.iter().collect();
        assert_eq!(largest(&refs, 1), (vec![0.03], vec![0.002]));
    }
}
