//! A nonlinear-mode run's error estimates in words: the largest over its points, and the
//! warnings of the estimates above the scene's threshold ([`super::accuracy`]).

use super::run::NonlinearModePoint;

/// The largest of each sized estimate over `points` and how many points could not be sized
/// (None without estimates).
pub fn largest(points: &[NonlinearModePoint]) -> Option<([f64; 3], usize)> {
    let mut out: Option<([f64; 3], usize)> = None;
    for acc in points.iter().filter_map(|p| p.accuracy) {
        let (o, not_sized) = out.get_or_insert(([0.0; 3], 0));
        if !acc.is_sized() {
            *not_sized += 1;
        }
        for (k, v) in acc.values().into_iter().enumerate() {
            if v.is_finite() {
                o[k] = o[k].max(v);
            }
        }
    }
    out
}

/// The run's accuracy warnings in words: per property, the amplitudes at the DOF
/// (`dof_name`) between which its estimate exceeds `threshold`, the largest there and how many
/// points, with the harmonics a run needs; and, apart, the points that could not be sized.
pub fn warnings(points: &[NonlinearModePoint], dof_name: &str, threshold: f64) -> Vec<String> {
    let mut out = Vec::new();
    let Some(h) = points.iter().find_map(|p| p.accuracy.map(|a| a.harmonic)) else {
        return out;
    };
    let h_run = (h - 1) / 2;
    let span = |band: &[&NonlinearModePoint]| {
        band.iter().fold((f64::INFINITY, 0.0_f64), |(l, u), p| {
            (l.min(p.dof_amplitude), u.max(p.dof_amplitude))
        })
    };
    let names = [
        "frequency".to_string(),
        "modal damping ratio".to_string(),
        format!("amplitude at {dof_name}"),
    ];
    for (k, property) in names.iter().enumerate() {
        let above: Vec<&NonlinearModePoint> = points
            .iter()
            .filter(|p| p.accuracy.is_some_and(|a| a.values()[k] > threshold))
            .collect();
        if above.is_empty() {
            continue;
        }
        let (lo, hi) = span(&above);
        let top = above
            .iter()
            .filter_map(|p| p.accuracy.map(|a| a.values()[k]))
            .fold(0.0_f64, f64::max);
        out.push(format!(
            "accuracy: the harmonic truncation error of the {property} is estimated at up to \
             {:.2} % between {lo:.3e} and {hi:.3e} m at {dof_name} ({} of {} points above \
             {:.2} %): harmonics.max > {h_run} needed (the estimate compares with H = {h})",
            100.0 * top,
            above.len(),
            points.len(),
            100.0 * threshold
        ));
    }
    let not_sized: Vec<&NonlinearModePoint> = points
        .iter()
        .filter(|p| p.accuracy.is_some_and(|a| !a.is_sized()))
        .collect();
    if !not_sized.is_empty() {
        let (lo, hi) = span(&not_sized);
        out.push(format!(
            "accuracy: the harmonic truncation error could not be sized at {} of {} points \
             between {lo:.3e} and {hi:.3e} m at {dof_name} (the system on H = {h} did not \
             converge there): compare runs at two harmonics.max there",
            not_sized.len(),
            points.len()
        ));
    }
    out
}
