//! The Jenkins element's describing function (paper Appendix, Eqs. 17-18): the exact first
//! harmonic of the contact law under constant normal load, the reference the AFT is checked
//! against.

/// Describing function of a Jenkins element with constant normal load N₀ under
/// u = q̂ cos ωt (paper Appendix, Eqs. 17-18): returns (k_eq, c_eq) such that the first
/// harmonic of T is k_eq q̂ cos τ − c_eq q̂ sin τ. Units: N/m for both (c_eq is the
/// hysteretic, frequency-independent part).
pub fn jenkins_describing_function(kt: f64, mu: f64, n0: f64, amplitude: f64) -> (f64, f64) {
    let slip_ratio = mu * n0 / (kt * amplitude);
    if slip_ratio >= 1.0 {
        return (kt, 0.0);
    }
    let phi = (1.0 - 2.0 * slip_ratio).acos();
    let k_eq = kt / std::f64::consts::PI * (phi - (2.0 * phi).sin() / 2.0);
    let c_eq = 4.0 * mu * n0 / (std::f64::consts::PI * amplitude) * (1.0 - slip_ratio);
    (k_eq, c_eq)
}
