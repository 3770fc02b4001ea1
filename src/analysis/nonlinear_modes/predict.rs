//! The forced response near a resonance from the nonlinear mode (single-nonlinear-mode theory,
//! Krack 2015, §4; Szemplińska-Stupnicka's resonant-mode approach): the forced motion is taken as
//! the mode's, q = x_s + a ψ(a), driven by the modal force of the first harmonic,
//!
//! ```text
//! a² [(ω(a)² − Ω²)² + (ξ(a) Ω)²] = |ψ₁(a)ᴴ F̂₁|²,   ψ₁ = ψ_c1 − i ψ_s1,  F̂₁ = F_c1 − i F_s1
//! ```
//!
//! (the mode's own frequency ω, artificial damping ξ = 2Dω and shape at each modal amplitude a;
//! Ω the excitation frequency). At phase resonance Ω = ω the peak's modal amplitude solves
//! ξ(a) ω(a) a = |ψ₁(a)ᴴ F̂₁|, found here along the computed backbone. The theory holds where
//! the mode is well separated from the others and the excitation drives it alone; the
//! harmonics h ≥ 2 of the force are left out.

use std::f64::consts::TAU;

use super::run::{NonlinearModePoint, NonlinearModeRun};
use crate::model::Problem;

/// The predicted resonance peak.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PredictedPeak {
    /// Modal amplitude a (kg^½·m).
    pub modal_amplitude: f64,
    /// First-harmonic amplitude at the mode's DOF (m).
    pub dof_amplitude: f64,
    /// Frequency of the peak, the mode's frequency there (Hz).
    pub freq_hz: f64,
}

/// |ψ₁ᴴ F̂₁| (N/kg^½) at a point of the mode, with the first-harmonic loads of `problem`.
pub fn modal_force(problem: &Problem, point: &NonlinearModePoint) -> f64 {
    let n = problem.model.n_dofs();
    let set = problem.unknown_harmonics();
    let (Some(c1), Some(s1)) = (set.cos_block(1), set.sin_block(1)) else {
        return 0.0;
    };
    let a = point.modal_amplitude;
    let (mut re, mut im) = (0.0, 0.0);
    for load in problem.harmonic_loads.iter().filter(|l| l.harmonic == 1) {
        let (pc, ps) = (
            point.coefficients[c1 * n + load.dof] / a,
            point.coefficients[s1 * n + load.dof] / a,
        );
        re += pc * load.cos + ps * load.sin;
        im += ps * load.cos - pc * load.sin;
    }
    re.hypot(im)
}

/// Where the peak predicted from the mode for the first-harmonic loads of `problem` lies: the
/// first crossing, rising in modal amplitude along the path, of ξ ω a = |ψ₁ᴴ F̂₁|, as the
/// index i of the point after it and the fraction t ∈ (0, 1] of the way from point i − 1 to
/// point i (linear in the crossing function). None when the mode does not reach it (the
/// excitation drives the mode beyond the amplitudes computed, or not at all).
pub fn peak_crossing(problem: &Problem, run: &NonlinearModeRun) -> Option<(usize, f64)> {
    let g = |p: &NonlinearModePoint| p.xi * p.omega * p.modal_amplitude - modal_force(problem, p);
    let points = &run.points;
    (1..points.len()).find_map(|i| {
        let (g0, g1) = (g(&points[i - 1]), g(&points[i]));
        (g0 <= 0.0 && g1 > 0.0).then(|| (i, -g0 / (g1 - g0)))
    })
}

/// The peak predicted from the mode for the first-harmonic loads of `problem`
/// ([`peak_crossing`]). None when the mode does not reach it.
pub fn predicted_peak(problem: &Problem, run: &NonlinearModeRun) -> Option<PredictedPeak> {
    peak_crossing(problem, run).map(|crossing| peak_at(run, crossing))
}

/// The peak at a crossing `(i, t)` of [`peak_crossing`]: its amplitudes interpolated linearly
/// in log a, its frequency linearly, between the points i − 1 and i.
pub fn peak_at(run: &NonlinearModeRun, (i, t): (usize, f64)) -> PredictedPeak {
    let (p0, p1) = (&run.points[i - 1], &run.points[i]);
    let lerp = |u: f64, v: f64| u + t * (v - u);
    PredictedPeak {
        modal_amplitude: lerp(p0.modal_amplitude.ln(), p1.modal_amplitude.ln()).exp(),
        dof_amplitude: lerp(p0.dof_amplitude.ln(), p1.dof_amplitude.ln()).exp(),
        freq_hz: lerp(p0.omega, p1.omega) / TAU,
    }
}

/// The predicted forced response near the resonance: for every point of the mode, the
/// excitation frequencies Ω (Hz) at which the forced amplitude equals the point's (both flanks
/// of the peak, where they exist), with the first-harmonic amplitude at the mode's DOF (m).
/// Ω² = ω² − ξ²/2 ± √((ω² − ξ²/2)² − ω⁴ + (|ψ₁ᴴF̂₁|/a)²). Returned as (Hz, m) pairs, the lower
/// flank rising in amplitude then the upper flank falling.
pub fn predicted_frf(problem: &Problem, run: &NonlinearModeRun) -> Vec<(f64, f64)> {
    let mut lower = Vec::new();
    let mut upper = Vec::new();
    for p in &run.points {
        let f = modal_force(problem, p) / p.modal_amplitude;
        let w2 = p.omega * p.omega;
        let centre = w2 - 0.5 * p.xi * p.xi;
        let disc = centre * centre - w2 * w2 + f * f;
        if disc < 0.0 {
            continue;
        }
        let root = disc.sqrt();
        for (sign, side) in [(-1.0, &mut lower), (1.0, &mut upper)] {
            let big_omega2 = centre + sign * root;
            if big_omega2 > 0.0 {
                side.push((big_omega2.sqrt() / TAU, p.dof_amplitude));
            }
        }
    }
    upper.reverse();
    lower.into_iter().chain(upper).collect()
}
