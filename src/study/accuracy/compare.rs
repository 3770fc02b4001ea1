//! How a setting's curves compare with the reference: the L2 error over the range, the peaks
//! of each basin, and the Pareto front of cost against error.

use super::settings::Setting;
use crate::analysis::frf::{self, FrfPoint};

/// What one setting gave.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingResult {
    /// The curve (`frf` or the limit case's name).
    pub curve: String,
    /// The setting.
    pub setting: Setting,
    /// `complete`, `incomplete: …` or `failed: …`.
    pub status: String,
    /// Newton unknowns (DOFs × coefficient blocks of the problem).
    pub unknowns: usize,
    /// Converged path points.
    pub points: usize,
    /// Newton iterations over the path.
    pub newton_iterations: usize,
    /// Wall time of the continuation (s).
    pub time_s: f64,
    /// The path (empty when the setting failed).
    pub path: Vec<FrfPoint>,
    /// Refined resonance peaks of the first output: (frequency Hz, amplitude m).
    pub peaks: Vec<(f64, f64)>,
}

impl SettingResult {
    /// Whether the setting's run covered its range (status `complete`): not failed, no branch
    /// given up or left unfollowed.
    pub fn is_complete(&self) -> bool {
        self.status == "complete"
    }
}

/// Errors of a setting against the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingErrors {
    /// Relative L2 error of the first output's amplitude over the common range.
    pub curve_l2: f64,
    /// Per reference peak: relative amplitude and frequency errors of the nearest peak (NaN
    /// when the setting has no peak).
    pub peaks: Vec<(f64, f64)>,
}

impl SettingErrors {
    /// The largest peak amplitude error (NaN when some peak is missing).
    pub fn max_peak_amplitude(&self) -> f64 {
        self.peaks
            .iter()
            .map(|p| p.0)
            .fold(0.0, |a: f64, b| if b.is_nan() { b } else { a.max(b) })
    }
    /// The largest peak frequency error (NaN when some peak is missing).
    pub fn max_peak_frequency(&self) -> f64 {
        self.peaks
            .iter()
            .map(|p| p.1)
            .fold(0.0, |a: f64, b| if b.is_nan() { b } else { a.max(b) })
    }
}

/// Relative L2 error ‖a − r‖ / ‖r‖ of the first output's amplitude of `path` against
/// `reference`, on 400 uniform frequencies of the range both cover (NaN when they share none).
pub fn curve_l2_error(path: &[FrfPoint], reference: &[FrfPoint]) -> f64 {
    let range = |p: &[FrfPoint]| {
        p.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
                (a.min(q.freq_hz), b.max(q.freq_hz))
            })
    };
    let (a0, a1) = range(path);
    let (r0, r1) = range(reference);
    let (lo, hi) = (a0.max(r0), a1.min(r1));
    if hi <= lo || !hi.is_finite() {
        return f64::NAN;
    }
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..=400 {
        let f = lo + (hi - lo) * k as f64 / 400.0;
        if let (Some(a), Some(r)) = (
            frf::amplitude_on_path(path, f),
            frf::amplitude_on_path(reference, f),
        ) {
            num += (a - r) * (a - r);
            den += r * r;
        }
    }
    if den > 0.0 {
        (num / den).sqrt()
    } else {
        f64::NAN
    }
}

/// The errors of `result` against `reference`.
///
/// Each reference peak is compared with the highest peak of `result` in its basin: the
/// frequencies nearer to it than to any other reference peak (between the midpoints to its
/// neighbours; the whole range for a single peak). A resonance whose top is folded into many
/// small folds, as the blade pair's at H = 1, has many local maxima there; the one nearest in
/// frequency to the reference peak is one of those bumps, not the resonance's top (on the 2D
/// blade pair at H = 1 a bump at 867.4 Hz, 5.49 × 10⁻⁵ m, 37 % above the reference, where the
/// top is 6.46 × 10⁻⁵ m at 865.3 Hz, 61 % above). Without a peak of `result` in the basin the
/// nearest one in frequency is compared.
pub fn errors(result: &SettingResult, reference: &SettingResult) -> SettingErrors {
    let mut reference_hz: Vec<f64> = reference.peaks.iter().map(|p| p.0).collect();
    reference_hz.sort_by(f64::total_cmp);
    SettingErrors {
        curve_l2: curve_l2_error(&result.path, &reference.path),
        peaks: reference
            .peaks
            .iter()
            .map(|&(fr, ar)| {
                let basin = peak_basin(&reference_hz, fr);
                let highest_in_basin = result
                    .peaks
                    .iter()
                    .filter(|p| basin.contains(&p.0))
                    .max_by(|a, b| a.1.total_cmp(&b.1));
                let nearest = || {
                    result
                        .peaks
                        .iter()
                        .min_by(|a, b| (a.0 - fr).abs().total_cmp(&(b.0 - fr).abs()))
                };
                highest_in_basin
                    .or_else(nearest)
                    .map_or((f64::NAN, f64::NAN), |&(f, a)| {
                        ((a - ar).abs() / ar, (f - fr).abs() / fr)
                    })
            })
            .collect(),
    }
}

/// The basin of the reference peak at `freq_hz` among the reference peaks at `sorted_hz`
/// (ascending): the frequencies (Hz) between the midpoints to its neighbours, unbounded on a
/// side without one.
fn peak_basin(sorted_hz: &[f64], freq_hz: f64) -> std::ops::Range<f64> {
    let below = sorted_hz.iter().rev().find(|&&f| f < freq_hz);
    let above = sorted_hz.iter().find(|&&f| f > freq_hz);
    below.map_or(f64::NEG_INFINITY, |f| 0.5 * (f + freq_hz))
        ..above.map_or(f64::INFINITY, |f| 0.5 * (f + freq_hz))
}

/// Indices of the Pareto-optimal points of (time, error): no other point is at most as slow and
/// at most as wrong while better in one. Points with a NaN are never on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let (ti, ei) = points[i];
            ti.is_finite()
                && ei.is_finite()
                && !points
                    .iter()
                    .enumerate()
                    .any(|(j, &(tj, ej))| j != i && tj <= ti && ej <= ei && (tj < ti || ej < ei))
        })
        .collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    front
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::accuracy::run::CurveStudy;
    use crate::study::accuracy::settings::StudyCurve;

    #[test]
    fn pareto_front_keeps_the_undominated() {
        let p = [
            (1.0, 0.1),
            (2.0, 0.01),
            (3.0, 0.05),
            (0.5, 0.5),
            (4.0, 0.001),
            (5.0, f64::NAN),
        ];
        assert_eq!(pareto_front(&p), vec![3, 0, 1, 4]);
    }

    /// A harmonics setting's result without a path: its label, status, time (s) and peaks
    /// (Hz, m).
    fn setting_result(
        label: &str,
        status: &str,
        time_s: f64,
        peaks: &[(f64, f64)],
    ) -> SettingResult {
        SettingResult {
            curve: "frf".into(),
            setting: Setting {
                group: "harmonics",
                label: label.into(),
                overrides: Vec::new(),
            },
            status: status.into(),
            unknowns: 1,
            points: 1,
            newton_iterations: 1,
            time_s,
            path: Vec::new(),
            peaks: peaks.to_vec(),
        }
    }

    #[test]
    fn incomplete_settings_are_never_on_the_pareto_front() {
        let result =
            |label: &str, status: &str, time_s: f64| setting_result(label, status, time_s, &[]);
        let errors = |peak: f64| SettingErrors {
            curve_l2: peak,
            peaks: vec![(peak, 0.0)],
        };
        let reference = result("reference", "complete", 10.0);
        // The incomplete run is both the fastest and the most accurate: it would dominate.
        let results = vec![
            result("H = 1", "complete", 1.0),
            result(
                "H = 1, fewer samples",
                "incomplete: a branch was abandoned",
                0.5,
            ),
            result("H = 3", "complete", 3.0),
        ];
        let study = CurveStudy {
            curve: StudyCurve::frf(),
            reference: reference.clone(),
            check: reference,
            check_errors: errors(0.0),
            results,
            errors: vec![errors(0.3), errors(1e-3), errors(0.05)],
        };
        let (pairs, front) = study.pareto();
        assert_eq!(pairs.len(), 3);
        assert_eq!(front, vec![0, 2]);
        assert_eq!(study.front_labels(), "H = 1, H = 3");
    }

    /// Two reference resonances at 100 and 200 Hz: each is compared with the highest peak of
    /// the setting in its basin (below and above 150 Hz), not with the bump nearest to it in
    /// frequency; a basin without a peak of the setting falls back on the nearest one.
    #[test]
    fn each_reference_peak_is_compared_with_the_highest_peak_of_its_basin() {
        let result = |peaks: Vec<(f64, f64)>| setting_result("H = 1", "complete", 1.0, &peaks);
        let reference = result(vec![(100.0, 1.0), (200.0, 2.0)]);
        // A folded top near 100 Hz: a bump at 101 Hz (1.1) beside the top at 98 Hz (1.5).
        let folded = result(vec![(98.0, 1.5), (101.0, 1.1), (149.0, 0.5), (204.0, 2.2)]);
        let e = errors(&folded, &reference).peaks;
        assert!(
            (e[0].0 - 0.5).abs() < 1e-12 && (e[0].1 - 0.02).abs() < 1e-12,
            "{e:?}"
        );
        assert!(
            (e[1].0 - 0.1).abs() < 1e-12 && (e[1].1 - 0.02).abs() < 1e-12,
            "{e:?}"
        );
        // Nothing above 150 Hz: the second reference peak takes the nearest, at 149 Hz.
        let low = result(vec![(98.0, 1.5), (149.0, 0.5)]);
        let e = errors(&low, &reference).peaks;
        assert!(
            (e[1].0 - 0.75).abs() < 1e-12 && (e[1].1 - 0.255).abs() < 1e-12,
            "{e:?}"
        );
        assert_eq!(peak_basin(&[100.0, 200.0], 100.0), f64::NEG_INFINITY..150.0);
        assert_eq!(peak_basin(&[100.0, 200.0], 200.0), 150.0..f64::INFINITY);
    }

    #[test]
    fn l2_error_of_a_scaled_curve() {
        let point = |f: f64, a: f64| FrfPoint {
            freq_hz: f,
            amplitudes: vec![a],
            peaks: vec![a],
            states: Vec::new(),
            newton_iterations: 1,
            residual: 0.0,
            coefficients: Vec::new(),
            accuracy: None,
            stability: None,
            pending_estimate: None,
        };
        let r: Vec<FrfPoint> = (0..=10).map(|k| point(k as f64, 1.0 + k as f64)).collect();
        let a: Vec<FrfPoint> = (0..=10)
            .map(|k| point(k as f64, 1.01 * (1.0 + k as f64)))
            .collect();
        assert!((curve_l2_error(&a, &r) - 0.01).abs() < 1e-12);
    }
}
