//! Resonance peaks along a solved path: which local maxima of an output's amplitude are peaks,
//! and where exactly each one is.
//!
//! The AFT samples the contact law, so the amplitude along a path carries small wiggles (about
//! 10⁻⁴ relative where a contact transition moves across a sample): a plain "local maximum"
//! test finds many near one resonance, and a golden-section search alone can stop on a wiggle
//! below a higher point of the same bracket. Here a local maximum counts as a peak only when it
//! stands out of its surroundings by at least [`MIN_PROMINENCE`] of its amplitude (its
//! prominence: the drop to the higher of the lowest points between it and a higher point on
//! either side), and the refinement first scans the bracket, then searches around the best
//! point found, and returns the highest point solved.

use crate::analysis::frf::{FrfError, FrfPoint, PointSolver};
use crate::contact::ContactState;
use crate::model::Problem;

/// Smallest prominence of a peak, relative to its amplitude: local maxima that stand out less
/// are wiggles of the sampled contact law (about 10⁻⁴) or numerical noise.
pub const MIN_PROMINENCE: f64 = 1e-3;

/// Scan points per chord of the bracket before the search (the bracket is two chords).
const SCAN_PER_CHORD: usize = 4;

/// A refined resonance peak of a curve.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Peak {
    /// Frequency of the peak (Hz).
    pub freq_hz: f64,
    /// First-harmonic amplitude of the output DOF at the peak (m).
    pub amplitude: f64,
    /// Whether the peak is an interior local maximum of the path refined by extra solves.
    /// False when the curve has no local maximum in the peak window: the value is then the
    /// largest at an end of the window or range, not a resonance peak.
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

/// Indices of the peaks of output `output` along `points` (path order): interior local maxima
/// whose prominence is at least [`MIN_PROMINENCE`] of their amplitude. Of a run of equal
/// values, the first counts.
pub fn peak_indices(points: &[FrfPoint], output: usize) -> Vec<usize> {
    let amp: Vec<f64> = points.iter().map(|p| p.amplitudes[output]).collect();
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

/// Refines the local maximum of output `output` at `points[index]` (an interior point) along
/// the path between its neighbours.
///
/// Trials are solved on the hyperplane normal to the chord through the neighbours (the
/// pseudo-arc-length corrector), not at a fixed frequency, so the search follows the branch
/// through folds and overhangs. The bracket (path parameter s ∈ [0, 2]: the chord to the
/// previous point for s ≤ 1, to the next beyond) is scanned at [`SCAN_PER_CHORD`] points per
/// chord, then a golden-section search runs between the neighbours of the best scanned point
/// down to 10⁻⁷ of a chord. On a smooth path this is the stationary point of the amplitude; on
/// a wiggly one the scan keeps the search off the wiggles below the bracket's highest point.
/// The highest point solved is returned.
pub fn refine_at(
    solver: &mut PointSolver<'_>,
    points: &[FrfPoint],
    output: usize,
    index: usize,
) -> Peak {
    let (p0, p1, p2) = (&points[index - 1], &points[index], &points[index + 1]);
    let mut eval = |s: f64| -> Option<FrfPoint> {
        let solved = if s <= 1.0 {
            solver.solve_on_chord(p0, p1, s)
        } else {
            solver.solve_on_chord(p1, p2, s - 1.0)
        };
        solved.ok().filter(|q| q.amplitudes[output].is_finite())
    };
    let value = |q: &Option<FrfPoint>| {
        q.as_ref()
            .map(|q| q.amplitudes[output])
            .unwrap_or(f64::NEG_INFINITY)
    };
    let mut best_point = p1.clone();
    let keep = |q: &Option<FrfPoint>, best_point: &mut FrfPoint| {
        if let Some(q) = q {
            if q.amplitudes[output] > best_point.amplitudes[output] {
                *best_point = q.clone();
            }
        }
    };
    // Scan: s = k / SCAN_PER_CHORD; s = 1 is the path point itself.
    let step = 1.0 / SCAN_PER_CHORD as f64;
    let mut best_s = 1.0;
    let mut best_value = p1.amplitudes[output];
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
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = ((best_s - step).max(0.0), (best_s + step).min(2.0));
    let mut c = hi - ratio * (hi - lo);
    let mut d = lo + ratio * (hi - lo);
    let (mut pc, mut pd) = (eval(c), eval(d));
    keep(&pc, &mut best_point);
    keep(&pd, &mut best_point);
    while hi - lo > 2e-7 {
        if value(&pc) >= value(&pd) {
            hi = d;
            d = c;
            pd = pc;
            c = hi - ratio * (hi - lo);
            pc = eval(c);
            keep(&pc, &mut best_point);
        } else {
            lo = c;
            c = d;
            pc = pd;
            d = lo + ratio * (hi - lo);
            pd = eval(d);
            keep(&pd, &mut best_point);
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
