//! The contact forces of a time step: the normal law and the tangential return mapping of each
//! contact point, with the slider states the march carries from step to step.

use faer::Mat;

use crate::contact::ContactPoint;
use crate::model::Problem;

/// The state of the structure and its contact sliders at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeState {
    /// Displacements q (m).
    pub q: Vec<f64>,
    /// Velocities q̇ (m/s).
    pub qdot: Vec<f64>,
    /// Slider positions (m), in contact order: one coordinate w (along u) per 1D point, two
    /// (w₁, w₂ along t₁, t₂) per 2D point; contact c's start at [`slider_offsets`]`[c]`.
    pub sliders: Vec<f64>,
}

/// Where each contact's slider coordinates start in [`TimeState::sliders`]: entry c is the
/// first coordinate of contact c (1 coordinate for a 1D point, 2 for a 2D point), the last
/// entry is the total count.
pub fn slider_offsets(problem: &Problem) -> Vec<usize> {
    let mut offsets = Vec::with_capacity(problem.contacts.len() + 1);
    let mut next = 0;
    offsets.push(0);
    for c in &problem.contacts {
        next += slider_dims(c);
        offsets.push(next);
    }
    offsets
}

/// Slider coordinates of a point: 1 for the 1D law, 2 for the 2D law.
pub(super) fn slider_dims(point: &ContactPoint) -> usize {
    if point.second_tangent.is_some() {
        2
    } else {
        1
    }
}

/// The tangential relative displacement (u₁, u₂) of a point at q (u₂ = 0 for a 1D point).
pub(super) fn tangential_pair(point: &ContactPoint, q: &[f64]) -> [f64; 2] {
    [point.tangential_of(q), point.second_tangential_of(q)]
}

/// Per-contact result of the return mapping at a trial displacement (second tangential
/// components 0 for a 1D point).
pub(super) struct ContactEval {
    /// Tangential force (T₁, T₂) (N).
    pub(super) t: [f64; 2],
    /// Normal force N (N).
    pub(super) n: f64,
    /// ∂Tₐ/∂u_b, row-major 2×2 (N/m).
    dt_du: [f64; 4],
    /// ∂Tₐ/∂v (N/m).
    dt_dv: [f64; 2],
    /// ∂N/∂v (N/m).
    dn_dv: f64,
    /// Slider after the step (m).
    pub(super) slider: [f64; 2],
    /// Closed and sticking (the slider did not move).
    pub(super) stuck: bool,
}

/// Return mapping of the Jenkins law (paper Eqs. 4-6) at u, v from the committed slider `w0`,
/// with the AFT's conventions (closed iff N > 0): for a 2D point the radial return onto the
/// friction circle of [`crate::contact::aft2d`], for a 1D point the same with u₂ = w₂ = 0
/// (which is the 1D law exactly: the slip direction is ±1 and the slip tangent 0).
pub(super) fn return_map(
    point: &ContactPoint,
    liftoff: bool,
    u: [f64; 2],
    v: f64,
    w0: [f64; 2],
) -> ContactEval {
    let law = &point.law;
    let nk = law.kn * v;
    let (n, dn_dv) = if liftoff && nk <= 0.0 {
        (0.0, 0.0)
    } else {
        (nk, law.kn)
    };
    if n <= 0.0 {
        return ContactEval {
            t: [0.0; 2],
            n,
            dt_du: [0.0; 4],
            dt_dv: [0.0; 2],
            dn_dv,
            slider: u,
            stuck: false,
        };
    }
    let limit = law.mu * n;
    let trial = [law.kt * (u[0] - w0[0]), law.kt * (u[1] - w0[1])];
    let magnitude = trial[0].hypot(trial[1]);
    if magnitude <= limit {
        let second = if point.second_tangent.is_some() {
            law.kt
        } else {
            0.0
        };
        ContactEval {
            t: trial,
            n,
            dt_du: [law.kt, 0.0, 0.0, second],
            dt_dv: [0.0; 2],
            dn_dv,
            slider: w0,
            stuck: true,
        }
    } else {
        let d = [trial[0] / magnitude, trial[1] / magnitude];
        let t = [limit * d[0], limit * d[1]];
        // Consistent tangent of the radial return: (μN/|T*|) kₜ (I − d dᵀ).
        let g = limit / magnitude * law.kt;
        ContactEval {
            t,
            n,
            dt_du: [
                g * (1.0 - d[0] * d[0]),
                -g * d[0] * d[1],
                -g * d[1] * d[0],
                g * (1.0 - d[1] * d[1]),
            ],
            dt_dv: [law.mu * law.kn * d[0], law.mu * law.kn * d[1]],
            dn_dv,
            slider: [u[0] - t[0] / law.kt, u[1] - t[1] / law.kt],
            stuck: false,
        }
    }
}

/// The committed slider of contact c from the slider coordinates `w` (`offsets` from
/// [`slider_offsets`]); w₂ = 0 for a 1D point.
pub(super) fn slider_of(w: &[f64], offsets: &[usize], c: usize) -> [f64; 2] {
    let o = offsets[c];
    if offsets[c + 1] - o == 2 {
        [w[o], w[o + 1]]
    } else {
        [w[o], 0.0]
    }
}

/// Writes contact c's slider into the slider coordinates `w`.
fn store_slider(w: &mut [f64], offsets: &[usize], c: usize, slider: [f64; 2]) {
    let (o, dims) = (offsets[c], offsets[c + 1] - offsets[c]);
    w[o..o + dims].copy_from_slice(&slider[..dims]);
}

/// Adds the contact forces at `q` (from committed slider coordinates `w0`) to `f`, their
/// tangent to `kc` if given, and writes the trial slider coordinates to `w1` and whether each
/// contact sticks to `stuck`.
pub(super) fn contact_forces(
    problem: &Problem,
    q: &[f64],
    w0: &[f64],
    f: &mut [f64],
    mut kc: Option<&mut Mat<f64>>,
    w1: &mut [f64],
    stuck: &mut [bool],
) {
    let liftoff = problem.effects.contact.liftoff;
    let offsets = slider_offsets(problem);
    for (ci, p) in problem.contacts.iter().enumerate() {
        let u = tangential_pair(p, q);
        let v = p.normal_of(q) - p.gap;
        let e = return_map(p, liftoff, u, v, slider_of(w0, &offsets, ci));
        store_slider(w1, &offsets, ci, e.slider);
        stuck[ci] = e.stuck;
        let tangential: Vec<&[(usize, f64)]> = p.tangential_rows().collect();
        for (a, row) in tangential.iter().enumerate() {
            for &(i, coef) in *row {
                f[i] += coef * e.t[a];
            }
        }
        for &(i, a) in &p.normal {
            f[i] += a * e.n;
        }
        if let Some(kc) = kc.as_deref_mut() {
            for (a, row_a) in tangential.iter().enumerate() {
                for &(i, ai) in *row_a {
                    for (b, row_b) in tangential.iter().enumerate() {
                        let d = e.dt_du[2 * a + b];
                        if d != 0.0 {
                            for &(j, bj) in *row_b {
                                kc[(i, j)] += ai * d * bj;
                            }
                        }
                    }
                    for &(j, aj) in &p.normal {
                        kc[(i, j)] += ai * e.dt_dv[a] * aj;
                    }
                }
            }
            for &(i, ai) in &p.normal {
                for &(j, aj) in &p.normal {
                    kc[(i, j)] += ai * e.dn_dv * aj;
                }
            }
        }
    }
}
