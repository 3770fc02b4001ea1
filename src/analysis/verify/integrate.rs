//! Integration to the steady state and the comparison with the harmonic balance: periods until
//! the response repeats, its first harmonic and contact loops, for a point of a run.

use std::f64::consts::PI;

use super::contact::{slider_of, slider_offsets, tangential_pair, TimeState};
use super::newmark::Newmark;
use super::settings::{VerifyError, VerifySettings};
use super::start::hbm_state;
use crate::contact::harmonic::HarmonicSet;
use crate::model::Problem;

/// Steady state reached by a time integration.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TimeResponse {
    /// Excitation frequency (Hz).
    pub freq_hz: f64,
    /// Steps per period used.
    pub steps_per_period: usize,
    /// Periods integrated.
    pub periods: usize,
    /// Whether the period-to-period change fell below the tolerance.
    pub settled: bool,
    /// Last period-to-period change of the state, relative to the amplitude.
    pub last_change: f64,
    /// First-harmonic amplitude √(c₁² + s₁²) of each output DOF over the last period (m).
    pub amplitudes: Vec<f64>,
    /// Fourier coefficients of each output DOF over the last period: [c₀, c₁, s₁, …, c_H, s_H].
    pub output_coefficients: Vec<Vec<f64>>,
    /// Largest fraction, over the output DOFs, of the dynamic part's energy (mean removed)
    /// outside harmonics 1..H over the last period (0 for a periodic motion resolved by H).
    pub nonharmonic_energy: f64,
    /// Each output DOF sampled over the last period (m), `steps_per_period` values.
    pub last_period: Vec<Vec<f64>>,
    /// Each output DOF's velocity q̇ over the last period (m/s), at the same instants.
    pub last_period_velocity: Vec<Vec<f64>>,
    /// Each contact's tangential relative displacement u (m) and force T (N) over the last
    /// period, at the same instants: its hysteresis loop.
    pub contact_loops: Vec<ContactLoop>,
}

/// One contact's tangential relative displacement and force over a period.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ContactLoop {
    /// Tangential relative displacement u = aₜ·q (m) (along t₁ for a 2D point).
    pub u: Vec<f64>,
    /// Tangential force T = kₜ (u − w) (N): the spring to the committed slider, which is the
    /// stick force, ±μN in slip and 0 open (the slider then follows u) (T₁ for a 2D point).
    pub t: Vec<f64>,
    /// A 2D point's second tangential relative displacement u₂ = aₜ₂·q (m); empty for a 1D
    /// point.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub u2: Vec<f64>,
    /// A 2D point's second tangential force component T₂ = kₜ (u₂ − w₂) (N); empty for a 1D
    /// point.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub t2: Vec<f64>,
}

/// Result of [`verify_point`]: the time integration at two time steps against the HBM point.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PointVerification {
    /// Integration with `steps_per_period`.
    pub coarse: TimeResponse,
    /// Integration with twice as many steps (halved dt), from the same start.
    pub fine: TimeResponse,
    /// Largest relative change of the first-harmonic output amplitudes when dt halves.
    pub dt_change: f64,
    /// Largest relative difference of the fine integration's amplitudes from the HBM point's.
    pub hbm_difference: f64,
}

/// Integrates the problem at `freq_hz` from `start` over whole periods until a periodic steady
/// state or the budget (see the module docs), and analyses the last period on harmonics 0..`h_max`.
pub fn integrate(
    problem: &Problem,
    freq_hz: f64,
    start: &TimeState,
    h_max: usize,
    settings: &VerifySettings,
) -> Result<TimeResponse, VerifyError> {
    let stepper = Newmark::new(problem, freq_hz, settings)?;
    let n = problem.model.n_dofs();
    let omega = stepper.omega;
    let steps = stepper.steps;
    let mut st = stepper.start(start, 0)?;
    let mut stuck = vec![false; problem.contacts.len()];

    let outputs = &problem.outputs;
    let mut history: Vec<Vec<f64>> = vec![vec![0.0; steps]; outputs.len()];
    let mut all_history: Vec<Vec<f64>> = vec![vec![0.0; steps]; n];
    let mut velocity: Vec<Vec<f64>> = vec![vec![0.0; steps]; outputs.len()];
    let offsets = slider_offsets(problem);
    let mut loops: Vec<ContactLoop> = problem
        .contacts
        .iter()
        .map(|p| {
            let second = if p.second_tangent.is_some() { steps } else { 0 };
            ContactLoop {
                u: vec![0.0; steps],
                t: vec![0.0; steps],
                u2: vec![0.0; second],
                t2: vec![0.0; second],
            }
        })
        .collect();
    let mut period_start = (st.q.clone(), st.v.clone());
    let mut last_change = f64::INFINITY;
    let mut settled = false;
    let mut periods = 0;
    for period in 1..=settings.max_periods.max(1) {
        periods = period;
        for k in 0..steps {
            for (i, hist) in all_history.iter_mut().enumerate() {
                hist[k] = st.q[i];
            }
            for (o, &d) in outputs.iter().enumerate() {
                velocity[o][k] = st.v[d];
            }
            for (c, p) in problem.contacts.iter().enumerate() {
                let u = tangential_pair(p, &st.q);
                let w = slider_of(&st.w, &offsets, c);
                loops[c].u[k] = u[0];
                loops[c].t[k] = p.law.kt * (u[0] - w[0]);
                if p.second_tangent.is_some() {
                    loops[c].u2[k] = u[1];
                    loops[c].t2[k] = p.law.kt * (u[1] - w[1]);
                }
            }
            stepper.step(&mut st, k, (period - 1) * steps + k, &mut stuck)?;
        }
        // Periodicity: change of (q, q̇/ω) at the period start relative to the amplitude.
        let amp = (0..n)
            .map(|i| first_harmonic(&all_history[i]).0)
            .fold(0.0_f64, f64::max)
            .max(1e-300);
        let change = (0..n)
            .map(|i| {
                (st.q[i] - period_start.0[i])
                    .abs()
                    .max((st.v[i] - period_start.1[i]).abs() / omega)
            })
            .fold(0.0_f64, f64::max)
            / amp;
        last_change = change;
        period_start = (st.q.clone(), st.v.clone());
        if period >= settings.min_periods && change <= settings.periodicity_tolerance {
            settled = true;
            break;
        }
    }
    for (o, &d) in outputs.iter().enumerate() {
        history[o].copy_from_slice(&all_history[d]);
    }
    let mut amplitudes = Vec::with_capacity(outputs.len());
    let mut output_coefficients = Vec::with_capacity(outputs.len());
    let mut nonharmonic_energy = 0.0_f64;
    for h in &history {
        let coef = fourier(h, h_max);
        amplitudes.push(
            coef.get(1)
                .copied()
                .unwrap_or(0.0)
                .hypot(coef.get(2).copied().unwrap_or(0.0)),
        );
        let mean = coef[0];
        let total: f64 = h.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / h.len() as f64;
        let resolved: f64 = coef[1..].iter().map(|c| 0.5 * c * c).sum();
        if total > 0.0 {
            nonharmonic_energy = nonharmonic_energy.max(((total - resolved) / total).max(0.0));
        }
        output_coefficients.push(coef);
    }
    Ok(TimeResponse {
        freq_hz,
        steps_per_period: steps,
        periods,
        settled,
        last_change,
        amplitudes,
        output_coefficients,
        nonharmonic_energy,
        last_period: history,
        last_period_velocity: velocity,
        contact_loops: loops,
    })
}

/// Fourier coefficients [c₀, c₁, s₁, …, c_H, s_H] of one period sampled uniformly from τ = 0.
pub fn fourier(samples: &[f64], h_max: usize) -> Vec<f64> {
    let ns = samples.len() as f64;
    let mut out = Vec::with_capacity(1 + 2 * h_max);
    out.push(samples.iter().sum::<f64>() / ns);
    for h in 1..=h_max {
        let (mut c, mut s) = (0.0, 0.0);
        for (k, x) in samples.iter().enumerate() {
            let t = 2.0 * PI * (h * k) as f64 / ns;
            c += x * t.cos();
            s += x * t.sin();
        }
        out.push(2.0 * c / ns);
        out.push(2.0 * s / ns);
    }
    out
}

fn first_harmonic(samples: &[f64]) -> (f64, f64) {
    let c = fourier(samples, 1);
    (c[1].hypot(c[2]), c[0])
}

/// Integrates from `start` at dt and dt/2 (see [`verify_point`]) and compares with the HBM
/// amplitudes `hbm_amplitudes` of the outputs.
pub fn verify_from(
    problem: &Problem,
    start: &TimeState,
    h_max: usize,
    hbm_amplitudes: &[f64],
    freq_hz: f64,
    settings: &VerifySettings,
) -> Result<PointVerification, VerifyError> {
    let coarse = integrate(problem, freq_hz, start, h_max, settings)?;
    let fine_settings = VerifySettings {
        steps_per_period: 2 * settings.steps_per_period,
        ..*settings
    };
    let fine = integrate(problem, freq_hz, start, h_max, &fine_settings)?;
    let rel = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs() / y.abs().max(1e-300))
            .fold(0.0_f64, f64::max)
    };
    Ok(PointVerification {
        dt_change: rel(&coarse.amplitudes, &fine.amplitudes),
        hbm_difference: rel(&fine.amplitudes, hbm_amplitudes),
        coarse,
        fine,
    })
}

/// Verifies a harmonic-balance point (full coefficients `x` on `set` at `freq_hz`, with
/// first-harmonic output amplitudes `hbm_amplitudes`): integrates from its state at τ = 0 with
/// `settings.steps_per_period` and with twice as many steps, and reports the dt change and the
/// difference from the HBM amplitudes.
pub fn verify_point(
    problem: &Problem,
    set: &HarmonicSet,
    x: &[f64],
    hbm_amplitudes: &[f64],
    freq_hz: f64,
    settings: &VerifySettings,
) -> Result<PointVerification, VerifyError> {
    let h_max = set.max_harmonic();
    let start = hbm_state(problem, set, x, freq_hz, settings.steps_per_period)?;
    verify_from(problem, &start, h_max, hbm_amplitudes, freq_hz, settings)
}
