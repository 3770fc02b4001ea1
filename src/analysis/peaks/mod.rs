//! Resonance peaks and anti-resonances along a solved path: which local maxima (minima) of an
//! output's amplitude are resonances (anti-resonances), and where exactly each one is.
//!
//! With the event-resolved contact laws the amplitude along a path is smooth, so every interior
//! local maximum of it is a resonance peak (a sampled law, `jenkins-1d-sampled`, leaves wiggles
//! of about 10⁻⁴ where a transition crosses a sample, and each is then listed: they are local
//! maxima of what that law computes). The refinement first scans the bracket, then searches
//! around the best point found, and returns the highest point solved.
//!
//! Anti-resonances are the same question for the amplitude with its sign flipped: one routine
//! ([`extremum_indices`], [`refine_extremum_at`]) serves both kinds ([`ExtremumKind`]), and
//! [`path_extrema`] reports both for every output of a run, each with the path point it was
//! refined from, without ever failing the run (a failed refinement reports the path point).

use crate::analysis::frf::{FrfError, FrfPoint, PointSolver};
use crate::contact::ContactState;
use crate::model::Problem;
use crate::numerics::golden;

/// Smallest prominence, relative to its amplitude, of a resonance that stands out only toward
/// a break between branches ([`branch_end_peak_indices`]): one that stands out less is the
/// junction with the branch that carries the response on.
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
/// interior local maxima of `kind.sign()` × amplitude. Of a run of equal values, the first
/// counts.
pub fn extremum_indices(points: &[FrfPoint], output: usize, kind: ExtremumKind) -> Vec<usize> {
    let sign = kind.sign();
    let amp: Vec<f64> = points.iter().map(|p| sign * p.amplitudes[output]).collect();
    let n = amp.len();
    (1..n.saturating_sub(1))
        .filter(|&i| amp[i] > amp[i - 1] && amp[i] >= amp[i + 1])
        .collect()
}

/// Indices of the resonance peaks of output `output` along `points` (path order): interior
/// local maxima ([`extremum_indices`] for [`ExtremumKind::Resonance`]).
pub fn peak_indices(points: &[FrfPoint], output: usize) -> Vec<usize> {
    extremum_indices(points, output, ExtremumKind::Resonance)
}

/// How far a point stands out on one side along a branch: the walk from it toward one end of
/// the branch, up to the first higher point or the end.
struct Side {
    /// Lowest amplitude met before a higher point (or the end): the base of the prominence.
    low: f64,
    /// Index of that lowest point (the point itself when the side is empty).
    low_at: usize,
    /// Whether the walk reached the end of the branch without meeting a higher point.
    reached_end: bool,
}

/// The walk from `i` over `range` (indices into `amp`, in walking order).
fn side(amp: &[f64], i: usize, range: impl Iterator<Item = usize>) -> Side {
    let mut s = Side {
        low: amp[i],
        low_at: i,
        reached_end: true,
    };
    for j in range {
        if amp[j] > amp[i] {
            s.reached_end = false;
            break;
        }
        if amp[j] < s.low {
            s.low = amp[j];
            s.low_at = j;
        }
    }
    s
}

/// The branches of a path of `n` points: the index ranges between `branch_starts` (indices of
/// points not continuous with the point before; others than 1..n are ignored), in path order.
fn branches(n: usize, branch_starts: &[usize]) -> Vec<std::ops::Range<usize>> {
    let mut cuts: Vec<usize> = branch_starts
        .iter()
        .copied()
        .filter(|&i| i > 0 && i < n)
        .collect();
    cuts.push(0);
    cuts.push(n);
    cuts.sort_unstable();
    cuts.dedup();
    cuts.windows(2).map(|w| w[0]..w[1]).collect()
}

/// Indices (into the whole path, in path order) of the resonances of output `output` that
/// stand out only toward a branch end: points of a branch of `points` (between
/// `branch_starts`, see [`path_extrema`]) that are not resonances by [`extremum_indices`]
/// because on one side (or both) the branch ends at a break between branches before any
/// higher point, so the response may rise beyond the break, unfollowed. Such a point counts
/// when
/// - it is a local maximum of its branch, its first or last point included (higher than its
///   neighbour before, at least its neighbour after; an end has one neighbour);
/// - it is neither the first nor the last point of the whole path (those are the ends of the
///   frequency range, where the run stops on purpose);
/// - it stands out by [`MIN_PROMINENCE`] of its amplitude on its sides that meet a higher
///   point or the path's own ends (the usual prominence, one side only), or, when both sides
///   run into breaks, on its deeper side;
/// - within its reach (the frequencies of its branch from it to the bases of its prominence,
///   or to the break on a side that runs into one, mirrored about its own frequency), every
///   point of the other branches lies below it by at least [`MIN_PROMINENCE`] of its
///   amplitude, so it is not the junction with another branch that carries the response on
///   (a branch resumed at a dead end starts at the point where the one before stopped).
pub fn branch_end_peak_indices(
    points: &[FrfPoint],
    output: usize,
    branch_starts: &[usize],
) -> Vec<usize> {
    let amp: Vec<f64> = points.iter().map(|p| p.amplitudes[output]).collect();
    let freq: Vec<f64> = points.iter().map(|p| p.freq_hz).collect();
    let n = amp.len();
    let mut found = Vec::new();
    for range in branches(n, branch_starts) {
        let (start, end) = (range.start, range.end);
        let branch = &points[range.clone()];
        let a = &amp[range.clone()];
        let m = a.len();
        if m < 2 {
            continue;
        }
        let usual = extremum_indices(branch, output, ExtremumKind::Resonance);
        for i in 0..m {
            let global = start + i;
            if usual.contains(&i) || global == 0 || global + 1 == n {
                continue;
            }
            let local_max = (i == 0 || a[i] > a[i - 1]) && (i + 1 == m || a[i] >= a[i + 1]);
            if !local_max {
                continue;
            }
            let left = side(a, i, (0..i).rev());
            let right = side(a, i, i + 1..m);
            // A side is open when it runs into a break between branches without a higher
            // point (the path's own first and last points close it).
            let left_open = left.reached_end && start > 0;
            let right_open = right.reached_end && end < n;
            if !left_open && !right_open {
                continue;
            }
            let base = match (left_open, right_open) {
                (true, true) => left.low.min(right.low),
                (true, false) => right.low,
                _ => left.low,
            };
            let margin = MIN_PROMINENCE * a[i].abs();
            if a[i] - base < margin {
                continue;
            }
            let from = if left_open { 0 } else { left.low_at };
            let to = if right_open { m - 1 } else { right.low_at };
            let reach = (from..=to)
                .map(|j| (freq[start + j] - freq[global]).abs())
                .fold(0.0, f64::max);
            let overtaken = (0..n)
                .filter(|j| !range.contains(j))
                .any(|j| (freq[j] - freq[global]).abs() <= reach && amp[j] > a[i] - margin);
            if !overtaken {
                found.push(global);
            }
        }
    }
    found
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
    /// Whether this is a resonance at a branch end ([`branch_end_peak_indices`]): the highest
    /// response of its branch toward a break between branches, where the path was not
    /// followed on. The response may rise beyond it; when the point is its branch's first or
    /// last point it cannot be bracketed and `peak` is the path point, `refined = false`.
    pub at_branch_end: bool,
}

/// Every resonance and anti-resonance of every output along a solved path ([`extremum_indices`]),
/// refined ([`refine_extremum_at`]): ordered by output (in `problem.outputs` order), then along
/// the path. `branch_starts` are the indices of points where the path is not continuous with
/// the point before (a branch reached by a jump over a fold; empty for one branch): extrema are
/// searched and refined within each branch only, never across such a break. A resonance that
/// stands out only toward a break ([`branch_end_peak_indices`]) is added, marked
/// `at_branch_end`: refined when it lies inside its branch, the path point (`refined = false`)
/// when it is the branch's first or last point. This never fails:
/// when no point solver can be built for the problem, or a refinement fails, the path point is
/// reported with `refined = false`.
///
/// Only extrema inside the analysis range (`freq_start_hz` to `freq_end_hz`) are reported: a
/// path may follow a fold out of the range (below its start), and what it finds there is not
/// a resonance of the range asked for. An extremum whose path point lies outside is not
/// refined; one refined to a frequency outside is left out.
pub fn path_extrema(
    problem: &Problem,
    points: &[FrfPoint],
    branch_starts: &[usize],
) -> Vec<PathExtremum> {
    let range = &problem.analysis.continuation;
    let (lo, hi) = (
        range.freq_start_hz.min(range.freq_end_hz),
        range.freq_start_hz.max(range.freq_end_hz),
    );
    let in_range = |f: f64| (lo..=hi).contains(&f);
    let mut solver = PointSolver::new(problem).ok();
    let spans = branches(points.len(), branch_starts);
    let mut found = Vec::new();
    for output in 0..problem.outputs.len() {
        for span in &spans {
            let (start, branch) = (span.start, &points[span.clone()]);
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
            for (i, kind) in at.into_iter().filter(|&(i, _)| in_range(branch[i].freq_hz)) {
                let peak = match solver.as_mut() {
                    Some(solver) => refine_extremum_at(solver, branch, output, i, kind),
                    None => Peak::from_point(&branch[i], output, false),
                };
                if !in_range(peak.freq_hz) {
                    continue;
                }
                found.push(PathExtremum {
                    output,
                    kind,
                    peak,
                    path_index: start + i,
                    path_freq_hz: branch[i].freq_hz,
                    path_amplitude: branch[i].amplitudes[output],
                    at_branch_end: false,
                });
            }
        }
    }
    // The resonances at branch ends, refined after all the others (so those are solved exactly
    // as without them): an interior point between its neighbours, an end point not at all.
    for output in 0..problem.outputs.len() {
        for index in branch_end_peak_indices(points, output, branch_starts) {
            let Some(span) = spans.iter().find(|s| s.contains(&index)) else {
                continue;
            };
            let (branch, i) = (&points[span.clone()], index - span.start);
            if !in_range(branch[i].freq_hz) {
                continue;
            }
            let interior = i > 0 && i + 1 < branch.len();
            let peak = match solver.as_mut() {
                Some(solver) if interior => {
                    refine_extremum_at(solver, branch, output, i, ExtremumKind::Resonance)
                }
                _ => Peak::from_point(&branch[i], output, false),
            };
            if !in_range(peak.freq_hz) {
                continue;
            }
            found.push(PathExtremum {
                output,
                kind: ExtremumKind::Resonance,
                peak,
                path_index: index,
                path_freq_hz: branch[i].freq_hz,
                path_amplitude: branch[i].amplitudes[output],
                at_branch_end: true,
            });
        }
    }
    // By output, then along the path (a stable sort: the order above within each).
    found.sort_by_key(|e| (e.output, e.path_index));
    found
}

#[cfg(test)]
mod tests;
