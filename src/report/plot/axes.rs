//! Axes: the ranges of the data (linear and logarithmic), the ticks of a log axis and the tick
//! labels, so that every axis carries several readable ticks whatever the data.

/// Range of finite values, widened by `pad` of its span; a default or widened range when empty
/// or degenerate.
pub(super) fn linear_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return (lo - d, hi + d);
    }
    let d = pad * (hi - lo);
    (lo - d, hi + d)
}

/// Log range of the positive finite values: padded by 4 % of the decades spanned and at least a
/// factor 4 wide, so that the axis always carries several ticks.
pub(super) fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (1e-6, 1e-3);
    }
    let (mut a, mut b) = (lo.log10(), hi.log10());
    let min_span = 4f64.log10();
    if b - a < min_span {
        let mid = 0.5 * (a + b);
        a = mid - 0.5 * min_span;
        b = mid + 0.5 * min_span;
    }
    let pad = 0.04 * (b - a);
    (10f64.powf(a - pad), 10f64.powf(b + pad))
}

/// Labelled (bold) and grid-only (light) ticks of a log axis over `lo..hi`.
pub(super) fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let e0 = lo.log10().floor() as i32;
    let e1 = hi.log10().ceil() as i32;
    let mut all = Vec::new();
    for e in e0..=e1 {
        for m in 1..=9 {
            let v = m as f64 * 10f64.powi(e);
            if v >= lo && v <= hi {
                all.push((m, e, v));
            }
        }
    }
    let decades: Vec<_> = all.iter().filter(|t| t.0 == 1).copied().collect();
    let main: Vec<_> = all
        .iter()
        .filter(|t| matches!(t.0, 1 | 2 | 5))
        .copied()
        .collect();
    let bold: Vec<(i32, i32, f64)> = if decades.len() >= 4 {
        let step = decades.len().div_ceil(8);
        decades.into_iter().step_by(step).collect()
    } else if main.len() >= 3 {
        main
    } else {
        all.clone()
    };
    let dense = e1 - e0 <= 8;
    let light = all
        .iter()
        .filter(|t| !bold.iter().any(|b| b.0 == t.0 && b.1 == t.1))
        .filter(|t| dense || t.0 == 1)
        .map(|t| t.2)
        .collect();
    (bold.into_iter().map(|t| t.2).collect(), light)
}

/// Tick label of a log axis: "1e-5", "2.5e-5".
pub(super) fn format_log(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let mut e = v.log10().floor() as i32;
    let mut m = (v / 10f64.powi(e) * 10.0).round() / 10.0;
    if m >= 10.0 {
        m /= 10.0;
        e += 1;
    }
    if m.fract() == 0.0 {
        format!("{m:.0}e{e}")
    } else {
        format!("{m:.1}e{e}")
    }
}

/// Below this fraction of an axis's largest magnitude, a tick value is zero to round-off: the
/// ticks are computed as start + k·step, so the zero tick of a range such as -1.6e-4..1e-4
/// comes out as 5.42e-20, while a real tick is at least a few thousandths of the scale.
const ZERO_TICK: f64 = 1e-9;

/// Tick label of a linear axis whose values reach `scale` in magnitude; a tick zero to
/// round-off of the scale ([`ZERO_TICK`]) reads `0`.
pub(super) fn format_linear(v: f64, scale: f64) -> String {
    if v == 0.0 || v.abs() <= ZERO_TICK * scale.abs() {
        return "0".to_string();
    }
    if scale != 0.0 && !(1e-2..1e5).contains(&scale) {
        let s = format!("{v:.2e}");
        match s.split_once('e') {
            Some((m, e)) => {
                let m = m.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{e}")
            }
            None => s,
        }
    } else {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".to_string()
        } else {
            s.to_string()
        }
    }
}

/// Range and scale of the y axis.
pub(super) enum YAxis {
    /// Linear from the first value to the second.
    Linear(f64, f64),
    /// Logarithmic from the first value to the second (both positive).
    Log(f64, f64),
}

impl YAxis {
    /// The y axis over `values`: logarithmic over the positive ones if `log_y`, otherwise
    /// linear, padded by 5 % of their span.
    pub(super) fn fit(values: impl Iterator<Item = f64>, log_y: bool) -> YAxis {
        if log_y {
            let (lo, hi) = log_range(values);
            YAxis::Log(lo, hi)
        } else {
            let (lo, hi) = linear_range(values, 0.05);
            YAxis::Linear(lo, hi)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_and_labels() {
        let (bold, light) = log_ticks(1.1e-6, 3e-4);
        assert_eq!(bold.len(), 7);
        assert!(!light.is_empty());
        let (bold, light) = log_ticks(1.1e-9, 3e-4);
        assert_eq!(bold.len(), 5);
        assert!(!light.is_empty());
        let (bold, _) = log_ticks(2.2e-5, 9e-5);
        assert!(bold.len() >= 2, "{bold:?}");
        assert_eq!(format_log(2e-5), "2e-5");
        assert_eq!(format_log(1e-4), "1e-4");
        assert_eq!(format_log(2.5e-7), "2.5e-7");
        assert_eq!(format_linear(0.5, 1.0), "0.5");
        assert_eq!(format_linear(2.5e-5, 1e-4), "2.5e-5");
        // The zero tick of a range computed as start + k·step is zero to round-off.
        assert_eq!(format_linear(5.42e-20, 1.6e-4), "0");
        assert_eq!(format_linear(-3e-17, 20.0), "0");
        assert_eq!(format_linear(2e-7, 1.6e-4), "2e-7");
        let (lo, hi) = log_range([3e-5, 3e-5].into_iter());
        assert!(hi / lo >= 4.0);
        assert_eq!(log_range(std::iter::empty()), (1e-6, 1e-3));
        assert_eq!(linear_range([f64::NAN].into_iter(), 0.0), (0.0, 1.0));
    }
}
