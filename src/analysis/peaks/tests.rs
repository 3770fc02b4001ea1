//! Unit tests of peak finding and refinement along a path.

use super::*;
use crate::analysis::frf::PointSolver;

/// Two masses: x1 (1 kg) on a 10⁴ N/m spring to the ground, x2 (0.1 kg) hung from it by
/// 10³ N/m, driven by 1 N cos ωt on x1, with a grounded contact on x1 without friction
/// (μ = 0, normal direction zero), so the harmonic balance is exactly linear. Resonances at
/// 13.6 and 18.6 Hz; x1 has an anti-resonance at √(k₂/m₂)/2π = 15.9 Hz, and x2's amplitude
/// a shallow minimum between the resonances (16.3 Hz; a local minimum, not a zero).
const TWO_DOF: &str = include_str!("../../../tests/data/two-dof-grounded.toml");

fn problem() -> Problem {
    crate::scene::parse(TWO_DOF, "two-dof", &[])
        .and_then(|s| s.validate("two-dof"))
        .expect("the two-DOF scene is valid")
}

/// First-harmonic amplitudes |X| of (K − ω²M + iωC) X = F for the scene's matrices,
/// written out here (2 × 2 complex solve by Cramer's rule), at `f` Hz.
fn linear_amplitudes(f: f64) -> [f64; 2] {
    let w = 2.0 * std::f64::consts::PI * f;
    // Entries (re, im) of the dynamic stiffness.
    let a = (1.1e4 - w * w, 2.0 * w);
    let b = (-1.0e3, 0.0);
    let d = (1.0e3 - 0.1 * w * w, 0.5 * w);
    let mul = |p: (f64, f64), q: (f64, f64)| (p.0 * q.0 - p.1 * q.1, p.0 * q.1 + p.1 * q.0);
    let ad = mul(a, d);
    let bb = mul(b, b);
    let det = (ad.0 - bb.0, ad.1 - bb.1);
    let det_abs = det.0.hypot(det.1);
    // X1 = d / det, X2 = −b / det (F = [1, 0]).
    [d.0.hypot(d.1) / det_abs, b.0.hypot(b.1) / det_abs]
}

/// Golden-section search of sign × |X_output| between `lo` and `hi` (Hz): (f, |X|).
fn linear_extremum(output: usize, sign: f64, lo: f64, hi: f64) -> (f64, f64) {
    let search = golden::maximise(lo, hi, 1e-10, |f| {
        Some((sign * linear_amplitudes(f)[output], ()))
    });
    let (f, _, _) = search.best.expect("the linear FRF evaluates everywhere");
    (f, linear_amplitudes(f)[output])
}

/// The path: fixed-frequency solves every 0.5 Hz, as coarse as the resonances
/// half-power widths (0.3-0.5 Hz), so raw extrema are far off.
fn coarse_path(p: &Problem) -> Vec<FrfPoint> {
    let mut solver = PointSolver::new(p).expect("solver");
    let set = p.unknown_harmonics();
    let mut x = crate::analysis::linear::stuck_guess(p, &set, 2.0 * std::f64::consts::PI * 5.0)
        .expect("guess");
    (0..=70)
        .map(|k| {
            let q = solver
                .solve(&x, 5.0 + 0.5 * k as f64)
                .expect("linear point");
            x = q.coefficients.clone();
            q
        })
        .collect()
}

fn point(freq_hz: f64, amplitude: f64) -> FrfPoint {
    FrfPoint {
        freq_hz,
        amplitudes: vec![amplitude],
        peaks: vec![amplitude],
        states: Vec::new(),
        newton_iterations: 1,
        residual: 0.0,
        coefficients: Vec::new(),
        accuracy: None,
        pending_estimate: None,
        stability: None,
    }
}

/// Every interior local maximum and minimum is found, with its kind, small ones (wiggles of
/// 10⁻⁴, as a sampled law leaves) included; the ends of the path are not extrema.
#[test]
fn every_interior_extremum_is_found_wiggles_included() {
    let amps = [
        1.0, 2.0, 3.0, 2.0, 1.0, 0.5, 1.0, 1.0001, 1.00005, 1.0002, 1.5, 0.9999, 0.99995, 0.9,
    ];
    let points: Vec<FrfPoint> = amps
        .iter()
        .enumerate()
        .map(|(k, &a)| point(k as f64, a))
        .collect();
    assert_eq!(
        extremum_indices(&points, 0, ExtremumKind::Resonance),
        vec![2, 7, 10, 12]
    );
    assert_eq!(peak_indices(&points, 0), vec![2, 7, 10, 12]);
    assert_eq!(
        extremum_indices(&points, 0, ExtremumKind::AntiResonance),
        vec![5, 8, 11]
    );
}

/// On the linear two-DOF system every resonance and anti-resonance of a coarse path is
/// found and refined to the closed-form linear FRF's (amplitude within 10⁻⁷, frequency
/// within 10⁻⁴ Hz), while the raw path values it was refined from are percents off.
#[test]
fn refined_extrema_match_the_linear_frf() {
    let p = problem();
    let points = coarse_path(&p);
    let found = path_extrema(&p, &points, &[]);
    let kinds = |output: usize| -> Vec<ExtremumKind> {
        found
            .iter()
            .filter(|e| e.output == output)
            .map(|e| e.kind)
            .collect()
    };
    use ExtremumKind::{AntiResonance, Resonance};
    assert_eq!(kinds(0), vec![Resonance, AntiResonance, Resonance]);
    assert_eq!(kinds(1), vec![Resonance, AntiResonance, Resonance]);
    let mut worst_raw: f64 = 0.0;
    for e in &found {
        let f0 = e.path_freq_hz;
        let (f, a) = linear_extremum(e.output, e.kind.sign(), f0 - 0.5, f0 + 0.5);
        let rel = (e.peak.amplitude - a).abs() / a;
        assert!(e.peak.refined, "{e:?}");
        assert!(
            rel < 1e-7 && (e.peak.freq_hz - f).abs() < 1e-4,
            "{:?} of output {}: refined {:.9e} at {:.6} Hz, linear {a:.9e} at {f:.6} Hz",
            e.kind,
            e.output,
            e.peak.amplitude,
            e.peak.freq_hz
        );
        assert_eq!(e.path_amplitude, points[e.path_index].amplitudes[e.output]);
        worst_raw = worst_raw.max((e.path_amplitude - a).abs() / a);
    }
    assert!(worst_raw > 1e-2, "the coarse path is off: {worst_raw:.2e}");
}

/// A path that runs out of the analysis range (a fold followed below its start) reports
/// only the extrema inside the range: with the range starting at 15 Hz, the resonances at
/// 13.6 Hz of the same path are left out and the others kept as they were.
#[test]
fn extrema_outside_the_range_are_left_out() {
    let p = problem();
    let points = coarse_path(&p);
    let whole = path_extrema(&p, &points, &[]);
    let narrowed = crate::scene::parse(TWO_DOF, "two-dof", &["analysis.freq_start_hz=15".into()])
        .and_then(|s| s.validate("two-dof"))
        .unwrap();
    let inside = path_extrema(&narrowed, &points, &[]);
    let expected: Vec<&PathExtremum> = whole.iter().filter(|e| e.peak.freq_hz >= 15.0).collect();
    assert_eq!(
        expected.len() + 2,
        whole.len(),
        "one resonance per output below 15 Hz"
    );
    // The same extrema (their refinement starts from another solver state: equal to
    // round-off).
    let key = |e: &PathExtremum| (e.output, e.kind, e.path_index);
    assert_eq!(
        inside.iter().map(key).collect::<Vec<_>>(),
        expected.iter().map(|e| key(e)).collect::<Vec<_>>()
    );
    for (a, b) in inside.iter().zip(&expected) {
        assert!(
            (a.peak.freq_hz - b.peak.freq_hz).abs() < 1e-6,
            "{a:?} {b:?}"
        );
    }
}

/// A break between branches is no extremum: the same path cut in two at x1's
/// anti-resonance loses it (it is an end of both branches) and keeps the others, with
/// their indices into the whole path.
#[test]
fn extrema_stay_within_their_branch() {
    let p = problem();
    let points = coarse_path(&p);
    let whole = path_extrema(&p, &points, &[]);
    let anti = whole
        .iter()
        .find(|e| e.output == 0 && e.kind == ExtremumKind::AntiResonance)
        .expect("x1's anti-resonance")
        .path_index;
    let split = path_extrema(&p, &points, &[anti]);
    let expected: Vec<&PathExtremum> = whole
        .iter()
        .filter(|e| e.path_index + 1 != anti && e.path_index != anti)
        .collect();
    assert_eq!(split.len() + 1, whole.len(), "{split:?}");
    assert_eq!(split.iter().collect::<Vec<_>>(), expected);
}

fn path(points: &[(f64, f64)]) -> Vec<FrfPoint> {
    points.iter().map(|&(f, a)| point(f, a)).collect()
}

/// A branch that rises up to a break (a dead end) has its last point reported; the branch
/// after the break, which starts lower and has its own resonance, adds nothing: its first
/// point stands out toward the break but the first branch is higher within its reach.
#[test]
fn a_branch_rising_to_its_end_has_a_peak_there() {
    let points = path(&[
        (0.0, 1.0),
        (1.0, 1.5),
        (2.0, 2.0),
        (3.0, 2.5),
        (3.5, 1.0),
        (4.0, 0.8),
        (5.0, 0.9),
        (6.0, 0.7),
    ]);
    assert_eq!(branch_end_peak_indices(&points, 0, &[4]), vec![3]);
    // The usual resonance of the second branch is not one at a branch end.
    assert_eq!(
        extremum_indices(&points[4..], 0, ExtremumKind::Resonance),
        vec![2]
    );
    // One branch: the rise ends inside the path, at a valley, and nothing is added.
    assert!(branch_end_peak_indices(&points, 0, &[]).is_empty());
}

/// A branch whose highest point is its second, its first only 3·10⁻⁴ lower: an interior
/// local maximum of the branch, so a resonance of its own and not one at a branch end; the
/// same points as one branch, or with the rise at the path's own last point, have no
/// resonance at a branch end either.
#[test]
fn a_maximum_next_to_a_branch_start_is_an_ordinary_peak() {
    let mut points = path(&[
        (0.0, 1.0),
        (1.0, 2.0),
        (2.0, 2.5),
        (3.0, 2.0),
        (4.0, 1.0),
        (5.0, 2.999),
        (4.9, 3.0),
        (6.0, 2.0),
        (7.0, 1.5),
        (8.0, 1.0),
    ]);
    assert_eq!(
        extremum_indices(&points[5..], 0, ExtremumKind::Resonance),
        vec![1]
    );
    assert_eq!(peak_indices(&points, 0), vec![2, 6]);
    assert!(branch_end_peak_indices(&points, 0, &[5]).is_empty());
    assert!(branch_end_peak_indices(&points, 0, &[]).is_empty());
    // A higher point of the first branch within its reach takes it over.
    points[2].amplitudes[0] = 3.0;
    assert!(branch_end_peak_indices(&points, 0, &[5]).is_empty());
    // The run's own last point is an end of the range, not of a branch.
    let rising = path(&[(0.0, 1.0), (1.0, 0.5), (2.0, 1.0), (3.0, 2.0)]);
    assert!(branch_end_peak_indices(&rising, 0, &[]).is_empty());
    assert!(branch_end_peak_indices(&rising, 0, &[2]).is_empty());
}

/// A branch resumed where the one before stopped (a dead end: its first point is that
/// point again) and rising on is no peak, nor is the point where the first stopped.
#[test]
fn a_branch_resumed_at_a_dead_end_adds_no_peak() {
    let points = path(&[
        (0.0, 1.0),
        (1.0, 1.5),
        (2.0, 2.0),
        (2.0, 2.0),
        (1.9, 1.9),
        (3.0, 2.5),
        (4.0, 3.0),
        (5.0, 1.0),
    ]);
    assert!(branch_end_peak_indices(&points, 0, &[3]).is_empty());
}

/// The linear two-DOF path cut at x1's first resonance (the peak point starts the second
/// branch) reports that point as a resonance at a branch end, unrefined, with the path
/// point's values; every other extremum is the one of the whole path, and without the cut
/// no extremum is at a branch end.
#[test]
fn a_resonance_cut_at_its_peak_is_reported_at_the_branch_end() {
    let p = problem();
    let points = coarse_path(&p);
    let whole = path_extrema(&p, &points, &[]);
    assert!(whole.iter().all(|e| !e.at_branch_end));
    let r = whole
        .iter()
        .find(|e| e.output == 0 && e.kind == ExtremumKind::Resonance)
        .expect("x1's first resonance")
        .path_index;
    let split = path_extrema(&p, &points, &[r]);
    let ends: Vec<&PathExtremum> = split.iter().filter(|e| e.at_branch_end).collect();
    assert!(ends.iter().any(|e| e.output == 0), "{split:?}");
    for e in &ends {
        assert_eq!(e.path_index, r, "{e:?}");
        assert_eq!(e.kind, ExtremumKind::Resonance);
        assert!(!e.peak.refined);
        assert_eq!(e.peak.freq_hz, points[r].freq_hz);
        assert_eq!(e.peak.amplitude, points[r].amplitudes[e.output]);
    }
    let kept: Vec<&PathExtremum> = split.iter().filter(|e| !e.at_branch_end).collect();
    let expected: Vec<&PathExtremum> = whole.iter().filter(|e| e.path_index != r).collect();
    assert_eq!(kept, expected);
    // Ordered by output, then along the path.
    assert!(split
        .windows(2)
        .all(|w| (w[0].output, w[0].path_index) <= (w[1].output, w[1].path_index)));
}

/// When the refining solves fail (no Newton iteration allowed), the path points are
/// reported, marked unrefined, and nothing fails.
#[test]
fn failed_refinement_reports_the_path_point() {
    let p = problem();
    let points = coarse_path(&p);
    let mut q = p.clone();
    q.analysis.continuation.max_iterations = 0;
    let found = path_extrema(&q, &points, &[]);
    assert_eq!(found.len(), 6);
    for e in &found {
        assert!(!e.peak.refined, "{e:?}");
        assert_eq!(e.peak.freq_hz, e.path_freq_hz);
        assert_eq!(e.peak.amplitude, e.path_amplitude);
    }
}
