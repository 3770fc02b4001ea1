//! Resonance peaks and anti-resonances along a solved path: which local maxima (minima) of an
//! output's amplitude are resonances (anti-resonances), and where exactly each one is.
//!
//! The AFT samples the contact law, so the amplitude along a path carries small wiggles (about
//! 10⁻⁴ relative where a contact transition moves across a sample): a plain "local maximum"
//! test finds many near one resonance, and a golden-section search alone can stop on a wiggle
//! below a higher point of the same bracket. Here a local maximum counts as a peak only when it
//! stands out of its surroundings by at least [`MIN_PROMINENCE`] of its amplitude (its
//! prominence: the drop to the higher of the lowest points between it and a higher point on
//! either side), and the refinement first scans the bracket, then searches around the best
//! point found, and returns the highest point solved.
//!
//! Anti-resonances are the same question for the amplitude with its sign flipped: one routine
//! ([`extremum_indices`], [`refine_extremum_at`]) serves both kinds ([`ExtremumKind`]), and
//! [`path_extrema`] reports both for every output of a run, each with the path point it was
//! refined from, without ever failing the run (a failed refinement reports the path point).

use crate::analysis::frf::{FrfError, FrfPoint, PointSolver};
use crate::contact::ContactState;
use crate::model::Problem;
use crate::numerics::golden;

/// Smallest prominence of a peak, relative to its amplitude: local maxima that stand out less
/// are wiggles of the sampled contact law (about 10⁻⁴) or numerical noise.
pub const MIN_PROMINENCE: f64 = 1e-3;

/// Scan points per chord of the bracket before the search (the bracket is two chords).
const SCAN_PER_CHORD: usize = 4;

/// A refined resonance peak (or anti-resonance, see [`PathExtremum`]) of a curve.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Peak {
    /// Frequency of the peak (Hz).
    pub freq_hz: f64,
    /// First-harmonic amplitude of the output DOF at the peak (m).
    pub amplitude: f64,
    /// Whether the peak is an interior local maximum of the path refined by extra solves.
    /// False when the curve has no local maximum in the peak window (the value is then the
    /// largest at an end of the window or range, not a resonance peak), and when the refining
    /// search failed to solve one of its trial points (the value is then the path point's).
    pub refined: bool,
    /// Coefficients at the peak.
    #[serde(skip)]
    pub coefficients: Vec<f64>,
    /// Contact states at the peak.
    pub states: Vec<ContactState>,
}

impl Peak {
    /// The peak at a solved point.
    pub fn from_point(p: &FrfPoint, output: usize, refined: bool) -> Self {
        Self {
            freq_hz: p.freq_hz,
            amplitude: p.amplitudes[output],
            refined,
            coefficients: p.coefficients.clone(),
            states: p.states.clone(),
        }
    }
}

/// Which kind of extremum of an output's amplitude along a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ExtremumKind {
    /// A local maximum: a resonance peak.
    Resonance,
    /// A local minimum: an anti-resonance.
    AntiResonance,
}

impl ExtremumKind {
    /// The sign that turns this kind's extremum into a maximum: +1 for a resonance, −1 for an
    /// anti-resonance.
    pub fn sign(self) -> f64 {
        match self {
            Self::Resonance => 1.0,
            Self::AntiResonance => -1.0,
        }
    }

    /// Name in result files: `resonance` or `anti-resonance`.
    pub fn label(self) -> &'static str {
        match self {
            Self::Resonance => "resonance",
            Self::AntiResonance => "anti-resonance",
        }
    }
}

/// Indices of the extrema of kind `kind` of output `output` along `points` (path order):
/// interior local maxima of `kind.sign()` × amplitude whose prominence is at least
/// [`MIN_PROMINENCE`] of their amplitude. Of a run of equal values, the first counts.
pub fn extremum_indices(points: &[FrfPoint], output: usize, kind: ExtremumKind) -> Vec<usize> {
    let sign = kind.sign();
    let amp: Vec<f64> = points.iter().map(|p| sign * p.amplitudes[output]).collect();
    let n = amp.len();
    (1..n.saturating_sub(1))
        .filter(|&i| amp[i] > amp[i - 1] && amp[i] >= amp[i + 1])
        .filter(|&i| {
            // The lowest point on each side before a higher one (or the end).
            let base = |range: &mut dyn Iterator<Item = usize>| {
                let mut low = amp[i];
                for j in range {
                    if amp[j] > amp[i] {
                        break;
                    }
                    low = low.min(amp[j]);
                }
                low
            };
            let left = base(&mut (0..i).rev());
            let right = base(&mut (i + 1..n));
            amp[i] - left.max(right) >= MIN_PROMINENCE * amp[i].abs()
        })
        .collect()
}

/// Indices of the resonance peaks of output `output` along `points` (path order): interior
/// local maxima whose prominence is at least [`MIN_PROMINENCE`] of their amplitude
/// ([`extremum_indices`] for [`ExtremumKind::Resonance`]).
pub fn peak_indices(points: &[FrfPoint], output: usize) -> Vec<usize> {
    extremum_indices(points, output, ExtremumKind::Resonance)
}

/// Refines the local maximum of output `output` at `points[index]` (an interior point) along
/// the path between its neighbours: [`refine_extremum_at`] for [`ExtremumKind::Resonance`].
pub fn refine_at(
    solver: &mut PointSolver<'_>,
    points: &[FrfPoint],
    output: usize,
    index: usize,
) -> Peak {
    refine_extremum_at(solver, points, output, index, ExtremumKind::Resonance)
}

/// Refines the extremum of kind `kind` of output `output` at `points[index]` (an interior
/// point) along the path between its neighbours; the search maximises `kind.sign()` ×
/// amplitude, so an anti-resonance is the same search upside down.
///
/// Trials are solved on the hyperplane normal to the chord through the neighbours (the
/// pseudo-arc-length corrector), not at a fixed frequency, so the search follows the branch
/// through folds and overhangs. The bracket (path parameter s ∈ [0, 2]: the chord to the
/// previous point for s ≤ 1, to the next beyond) is scanned at [`SCAN_PER_CHORD`] points per
/// chord, then a golden-section search runs between the neighbours of the best scanned point
/// down to 10⁻⁷ of a chord. On a smooth path this is the stationary point of the amplitude; on
/// a wiggly one the scan keeps the search off the wiggles below the bracket's highest point.
/// The most extreme point solved is returned, `refined`. A scan point that fails only leaves
/// the scan blind there; when a trial of the golden-section search fails, the search cannot
/// vouch for its result and the path point itself is returned with `refined = false`.
pub fn refine_extremum_at(
    solver: &mut PointSolver<'_>,
    points: &[FrfPoint],
    output: usize,
    index: usize,
    kind: ExtremumKind,
) -> Peak {
    let sign = kind.sign();
    let (p0, p1, p2) = (&points[index - 1], &points[index], &points[index + 1]);
    let mut eval = |s: f64| -> Option<FrfPoint> {
        let solved = if s <= 1.0 {
            solver.solve_on_chord(p0, p1, s)
        } else {
            solver.solve_on_chord(p1, p2, s - 1.0)
        };
        solved.ok().filter(|q| q.amplitudes[output].is_finite())
    };
    // The objective: sign × amplitude, −∞ where the solve failed.
    let value = |q: &Option<FrfPoint>| {
        q.as_ref()
            .map(|q| sign * q.amplitudes[output])
            .unwrap_or(f64::NEG_INFINITY)
    };
    let mut best_point = p1.clone();
    let keep = |q: &Option<FrfPoint>, best_point: &mut FrfPoint| {
        if let Some(q) = q {
            if sign * q.amplitudes[output] > sign * best_point.amplitudes[output] {
                *best_point = q.clone();
            }
        }
    };
    // Scan: s = k / SCAN_PER_CHORD; s = 1 is the path point itself.
    let step = 1.0 / SCAN_PER_CHORD as f64;
    let mut best_s = 1.0;
    let mut best_value = sign * p1.amplitudes[output];
    for k in 1..2 * SCAN_PER_CHORD {
        let s = k as f64 * step;
        if k == SCAN_PER_CHORD {
            continue;
        }
        let q = eval(s);
        if value(&q) > best_value {
            best_value = value(&q);
            best_s = s;
        }
        keep(&q, &mut best_point);
    }
    let search = golden::maximise(
        (best_s - step).max(0.0),
        (best_s + step).min(2.0),
        2e-7,
        |s| {
            let q = eval(s)?;
            Some((sign * q.amplitudes[output], q))
        },
    );
    if !search.complete {
        return Peak::from_point(p1, output, false);
    }
    if let Some((_, v, q)) = search.best {
        if v > sign * best_point.amplitudes[output] {
            best_point = q;
        }
    }
    Peak::from_point(&best_point, output, true)
}

/// Every peak of every output along a solved path, refined ([`peak_indices`], [`refine_at`]):
/// one list per output of `problem.outputs`, in path order.
pub fn path_peaks(problem: &Problem, points: &[FrfPoint]) -> Result<Vec<Vec<Peak>>, FrfError> {
    let mut solver = PointSolver::new(problem)?;
    Ok((0..problem.outputs.len())
        .map(|output| {
            peak_indices(points, output)
                .into_iter()
                .map(|i| refine_at(&mut solver, points, output, i))
                .collect()
        })
        .collect())
}

/// A resonance or anti-resonance of one output of a run, refined, with the path point it was
/// refined from (the raw maximum or minimum of the plotted curve).
#[derive(Debug, Clone, PartialEq)]
pub struct PathExtremum {
    /// Index of the output DOF in `problem.outputs`.
    pub output: usize,
    /// Resonance (local maximum) or anti-resonance (local minimum).
    pub kind: ExtremumKind,
    /// The refined extremum; `refined` is false when the refinement failed (the values are
    /// then the path point's).
    pub peak: Peak,
    /// Index of the path point the extremum was refined from, in path order.
    pub path_index: usize,
    /// Frequency of that path point (Hz).
    pub path_freq_hz: f64,
    /// First-harmonic amplitude of the output at that path point (m).
    pub path_amplitude: f64,
}

/// Every resonance and anti-resonance of every output along a solved path ([`extremum_indices`]),
/// refined ([`refine_extremum_at`]): ordered by output (in `problem.outputs` order), then along
/// the path. `branch_starts` are the indices of points where the path is not continuous with
/// the point before (a branch reached by a jump over a fold; empty for one branch): extrema are
/// searched and refined within each branch only, never across such a break. This never fails:
/// when no point solver can be built for the problem, or a refinement fails, the path point is
/// reported with `refined = false`.
pub fn path_extrema(
    problem: &Problem,
    points: &[FrfPoint],
    branch_starts: &[usize],
) -> Vec<PathExtremum> {
    let mut solver = PointSolver::new(problem).ok();
    let mut cuts: Vec<usize> = branch_starts
        .iter()
        .copied()
        .filter(|&i| i > 0 && i < points.len())
        .collect();
    cuts.push(0);
    cuts.push(points.len());
    cuts.sort_unstable();
    cuts.dedup();
    let mut found = Vec::new();
    for output in 0..problem.outputs.len() {
        for span in cuts.windows(2) {
            let (start, branch) = (span[0], &points[span[0]..span[1]]);
            let mut at: Vec<(usize, ExtremumKind)> =
                [ExtremumKind::Resonance, ExtremumKind::AntiResonance]
                    .into_iter()
                    .flat_map(|kind| {
                        extremum_indices(branch, output, kind)
                            .into_iter()
                            .map(move |i| (i, kind))
                    })
                    .collect();
            at.sort_by_key(|&(i, _)| i);
            for (i, kind) in at {
                let peak = match solver.as_mut() {
                    Some(solver) => refine_extremum_at(solver, branch, output, i, kind),
                    None => Peak::from_point(&branch[i], output, false),
                };
                found.push(PathExtremum {
                    output,
                    kind,
                    peak,
                    path_index: start + i,
                    path_freq_hz: branch[i].freq_hz,
                    path_amplitude: branch[i].amplitudes[output],
                });
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::frf::PointSolver;

    /// Two masses: x1 (1 kg) on a 10⁴ N/m spring to the ground, x2 (0.1 kg) hung from it by
    /// 10³ N/m, driven by 1 N cos ωt on x1, with a grounded contact on x1 without friction
    /// (μ = 0, normal direction zero), so the harmonic balance is exactly linear. Resonances at
    /// 13.6 and 18.6 Hz; x1 has an anti-resonance at √(k₂/m₂)/2π = 15.9 Hz, and x2's amplitude
    /// a shallow minimum between the resonances (16.3 Hz; a local minimum, not a zero).
    const TWO_DOF: &str = include_str!("../../tests/data/two-dof-grounded.toml");

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
            stability: None,
        }
    }

    /// A maximum and a minimum that stand out are found, with their kinds; wiggles of 10⁻⁴
    /// (the sampled law's) and the ends of the path are not extrema.
    #[test]
    fn extrema_are_told_from_wiggles() {
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
            vec![2, 10]
        );
        assert_eq!(peak_indices(&points, 0), vec![2, 10]);
        assert_eq!(
            extremum_indices(&points, 0, ExtremumKind::AntiResonance),
            vec![5]
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
}
