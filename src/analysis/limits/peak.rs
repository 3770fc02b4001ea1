//! Resonance peaks: the peak of a nonlinear path, refined by a golden-section search along the
//! path, and the resonance of a linear reference curve.

use crate::analysis::frf::{FrfError, FrfPoint, PointSolver};
use crate::contact::ContactState;
use crate::model::Problem;

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
    fn from_point(p: &FrfPoint, output: usize, refined: bool) -> Self {
        Self {
            freq_hz: p.freq_hz,
            amplitude: p.amplitudes[output],
            refined,
            coefficients: p.coefficients.clone(),
            states: p.states.clone(),
        }
    }
}

/// Locates the resonance peak of output `output` on a path: the largest interior local maximum
/// of the first-harmonic amplitude among the points inside `window` (Hz; the whole path when
/// `None`), refined by a golden-section search along the path between its two neighbours.
///
/// Each trial is solved on the hyperplane normal to the chord through the neighbours (the
/// pseudo-arc-length corrector), not at a fixed frequency, so the search follows the branch
/// through folds and overhangs; the refined point is a stationary point of the amplitude along
/// the path to a relative 1e-7 of the chord. Where no local maximum lies in the window, the
/// largest amplitude in it is returned unrefined. `None` when no point lies in the window.
pub fn refine_peak(
    problem: &Problem,
    points: &[FrfPoint],
    output: usize,
    window: Option<(f64, f64)>,
) -> Result<Option<Peak>, FrfError> {
    let inside = |p: &FrfPoint| window.is_none_or(|(lo, hi)| p.freq_hz >= lo && p.freq_hz <= hi);
    let amp = |i: usize| points[i].amplitudes[output];
    let local_max = (1..points.len().saturating_sub(1))
        .filter(|&i| inside(&points[i]) && amp(i) >= amp(i - 1) && amp(i) >= amp(i + 1))
        .max_by(|&i, &j| amp(i).total_cmp(&amp(j)));
    let Some(best) = local_max else {
        return Ok((0..points.len())
            .filter(|&i| inside(&points[i]))
            .max_by(|&i, &j| amp(i).total_cmp(&amp(j)))
            .map(|i| Peak::from_point(&points[i], output, false)));
    };
    let (p0, p1, p2) = (&points[best - 1], &points[best], &points[best + 1]);
    let mut solver = PointSolver::new(problem)?;
    // Path parameter s ∈ [0, 2]: chord p0 → p1 for s ≤ 1, chord p1 → p2 beyond.
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
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0_f64, 2.0_f64);
    let mut c = hi - ratio * (hi - lo);
    let mut d = lo + ratio * (hi - lo);
    let (mut pc, mut pd) = (eval(c), eval(d));
    let mut best_point = p1.clone();
    let keep = |q: &Option<FrfPoint>, best_point: &mut FrfPoint| {
        if let Some(q) = q {
            if q.amplitudes[output] > best_point.amplitudes[output] {
                *best_point = q.clone();
            }
        }
    };
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
    Ok(Some(Peak::from_point(&best_point, output, true)))
}

/// The resonance of a linear reference: its largest local maximum of output `output` inside
/// `window` (Hz; anywhere when `None`), as (frequency in Hz, amplitude in m), at the reference's
/// grid resolution.
pub fn linear_resonance(
    curve: &crate::analysis::linear::LinearCurve,
    output: usize,
    window: Option<(f64, f64)>,
) -> Option<(f64, f64)> {
    let a: Vec<f64> = curve.amplitudes.iter().map(|r| r[output]).collect();
    (1..a.len().saturating_sub(1))
        .filter(|&i| a[i] > a[i - 1] && a[i] >= a[i + 1])
        .filter(|&i| window.is_none_or(|(lo, hi)| (lo..=hi).contains(&curve.freqs_hz[i])))
        .map(|i| (curve.freqs_hz[i], a[i]))
        .max_by(|x, y| x.1.total_cmp(&y.1))
}
