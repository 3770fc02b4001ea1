//! Comparisons of solved harmonic-balance points.

use fricbound::analysis::frf::FrfPoint;

/// Asserts that `b` has the coefficients of `a` to 1e-8 of their largest and the same contact
/// states; `what` names the pair in the failure message (e.g. "schur at 201.000 Hz").
pub fn assert_same_point(a: &FrfPoint, b: &FrfPoint, what: &str) {
    let scale = a.coefficients.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let diff = a
        .coefficients
        .iter()
        .zip(&b.coefficients)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(
        diff <= 1e-8 * scale,
        "{what}: coefficients differ by {diff:.3e} (scale {scale:.3e})"
    );
    assert_eq!(a.states, b.states, "{what}");
}
