//! Resonance peaks of a limit case: the highest peak of a nonlinear path in the peak window,
//! refined along the path ([`crate::analysis::peaks`]), and the resonance of a linear reference
//! curve.

use crate::analysis::frf::{FrfError, FrfPoint, PointSolver};
use crate::analysis::peaks::refine_at;
pub use crate::analysis::peaks::Peak;
use crate::model::Problem;

/// Locates the resonance peak of output `output` on a path: the largest interior local maximum
/// of the first-harmonic amplitude among the points inside `window` (Hz; the whole path when
/// `None`), refined along the path between its two neighbours ([`refine_at`]: a scan of the
/// bracket, then a golden-section search on the pseudo-arc-length hyperplanes, so folds and
/// overhangs are followed; a stationary point of the amplitude along the path to a relative
/// 1e-7 of the chord, the highest point solved). Where no local maximum lies in the window, the
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
    let mut solver = PointSolver::new(problem)?;
    Ok(Some(refine_at(&mut solver, points, output, best)))
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
