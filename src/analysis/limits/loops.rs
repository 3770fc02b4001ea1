//! Hysteresis loops: the contact time histories (u, T, v, N) over one period at a solved point,
//! and the loops a limit analysis computes on each curve (at its peak, at requested frequencies).

use crate::hbm::{HbmError, HbmSystem};
use crate::model::Problem;

use super::curve::CaseCurve;
use super::grid::on_grid;

/// Where hysteresis loops are wanted, on every limit and intermediate curve.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HysteresisRequest {
    /// At each curve's resonance peak (paper Fig. 16c).
    pub at_peaks: bool,
    /// At these frequencies (Hz), on the first path segment of each curve that brackets them.
    pub freqs_hz: Vec<f64>,
}

impl Default for HysteresisRequest {
    fn default() -> Self {
        Self {
            at_peaks: true,
            freqs_hz: Vec::new(),
        }
    }
}

/// Hysteresis loops of every contact of one curve at one point.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LoopSet {
    /// Case name of the curve.
    pub case: String,
    /// Where: `peak` or the requested frequency, e.g. `214.5 Hz`.
    pub at: String,
    /// Frequency of the point (Hz).
    pub freq_hz: f64,
    /// Output amplitude at the point (m).
    pub amplitude: f64,
    /// One loop per contact.
    pub loops: Vec<HysteresisLoop>,
}

/// The requested loops of one curve, and the requests it has no solution for (as text: no
/// peak, a frequency outside its finished path, a solve or contact evaluation that failed).
pub(super) fn curve_loops(
    problem: &Problem,
    curve: &CaseCurve,
    request: &HysteresisRequest,
) -> (Vec<LoopSet>, Vec<String>) {
    let p = curve.case.apply(problem);
    let name = &curve.case.name;
    let mut sets = Vec::new();
    let mut missing = Vec::new();
    if request.at_peaks {
        match &curve.peak {
            Some(peak) => match hysteresis(&p, &peak.coefficients) {
                Ok(loops) => sets.push(LoopSet {
                    case: name.clone(),
                    at: "peak".to_string(),
                    freq_hz: peak.freq_hz,
                    amplitude: peak.amplitude,
                    loops,
                }),
                Err(e) => missing.push(format!("curve `{name}` at its peak: {e}")),
            },
            None => missing.push(format!("curve `{name}` has no peak in the peak window")),
        }
    }
    if request.freqs_hz.is_empty() {
        return (sets, missing);
    }
    let solved = match on_grid(problem, &curve.case, &curve.points, &request.freqs_hz) {
        Ok(solved) => solved,
        Err(e) => {
            missing.push(format!("{e}"));
            return (sets, missing);
        }
    };
    for (&f, s) in request.freqs_hz.iter().zip(solved) {
        let Some((point, _)) = s else {
            missing.push(format!(
                "curve `{name}` has no solution at {f} Hz (outside its path or Newton failed)"
            ));
            continue;
        };
        match hysteresis(&p, &point.coefficients) {
            Ok(loops) => sets.push(LoopSet {
                case: name.clone(),
                at: format!("{f} Hz"),
                freq_hz: f,
                amplitude: point.amplitudes[0],
                loops,
            }),
            Err(e) => missing.push(format!("curve `{name}` at {f} Hz: {e}")),
        }
    }
    (sets, missing)
}

/// Time histories over one period of every contact at coefficients x: (u, T, v, N) samples.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HysteresisLoop {
    /// Contact name.
    pub contact: String,
    /// Tangential relative displacement u(τ_k) (m).
    pub u: Vec<f64>,
    /// Tangential force T(τ_k) (N).
    pub t: Vec<f64>,
    /// Normal relative displacement v(τ_k) (m).
    pub v: Vec<f64>,
    /// Normal force N(τ_k) (N).
    pub n: Vec<f64>,
}

impl HysteresisLoop {
    /// Energy dissipated over the period, ∮ T du (J), by the trapezoidal rule over the samples
    /// (closed loop): zero for a fully stuck or open contact, positive when it slips.
    pub fn dissipated_energy(&self) -> f64 {
        let n = self.u.len().min(self.t.len());
        (0..n)
            .map(|k| {
                let j = (k + 1) % n;
                0.5 * (self.t[k] + self.t[j]) * (self.u[j] - self.u[k])
            })
            .sum()
    }
}

/// Hysteresis loops of all contacts of `problem` at coefficients x.
pub fn hysteresis(problem: &Problem, x: &[f64]) -> Result<Vec<HysteresisLoop>, HbmError> {
    let mut system = HbmSystem::new(problem)?;
    let mut loops = Vec::new();
    for (c, contact) in problem.contacts.iter().enumerate() {
        system.contact_forces(c, x, false)?;
        if contact.second_tangent.is_some() {
            // A 2D point's loop along its first tangent: (u₁, T₁).
            let aft = system.aft2d().expect("2D points have a 2D workspace");
            loops.push(HysteresisLoop {
                contact: contact.name.clone(),
                u: aft.u[0].clone(),
                t: aft.t[0].clone(),
                v: aft.v.clone(),
                n: aft.n.clone(),
            });
            continue;
        }
        let aft = system.aft();
        loops.push(HysteresisLoop {
            contact: contact.name.clone(),
            u: aft.u.clone(),
            t: aft.t.clone(),
            v: aft.v.clone(),
            n: aft.n.clone(),
        });
    }
    Ok(loops)
}
