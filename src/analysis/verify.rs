//! Time integration of the equations of motion, as an independent check of a harmonic-balance
//! point (validation ladder step 4 of the design notes).
//!
//! The same equations the harmonic balance solves,
//!
//! ```text
//! M q̈ + C q̇ + K q + F_c(q, w) = F_static + F_h(t),     F_h(t) = Σ (cos·cos hωt + sin·sin hωt)
//! ```
//!
//! are integrated in time with the Newmark average-acceleration scheme (trapezoidal rule,
//! β = 1/4, γ = 1/2: unconditionally stable and non-dissipative for the linear part, second-order
//! accurate), with a fixed number of steps per excitation period. The contact forces are implicit:
//! each step solves the Newmark residual
//!
//! ```text
//! R(q₁) = M a₁ + C v₁ + K q₁ + F_c(q₁, w₀) − F(t₁),
//! a₁ = 4/dt² (q₁ − q₀ − dt v₀) − a₀,   v₁ = 2/dt (q₁ − q₀) − v₀,
//! ```
//!
//! by Newton with the consistent tangent 4/dt² M + 2/dt C + K + K_c. F_c is the contact law of
//! [`crate::contact`] (paper Eqs. 4-6) as a return mapping per contact point: N = max(kₙ v, 0)
//! (v = aₙ·q − g; bilateral without lift-off), trial T = kₜ (u − w₀); |T| ≤ μN stick, otherwise
//! T = ±μN (slip) and the slider moves to w₁ = u − T/kₜ; an open contact (N ≤ 0) carries no
//! tangential force and its slider follows u. This is exactly the sample-by-sample march of the
//! AFT ([`crate::contact::aft`]), here driven by the integrated motion instead of a prescribed
//! periodic one. Only variable normal load is supported (a constant normal load is defined from
//! the 0th harmonic of a periodic motion, which a time integration does not have).
//!
//! Integration goes period by period (τ = ωt; period starts at τ = 2πp) until the state at the
//! period start (q, q̇/ω) changes by less than a tolerance relative to the largest first-harmonic
//! amplitude, or a budget of periods runs out. The last period's samples are then projected on
//! harmonics 0..H (rectangle rule on the uniform grid, exact for trigonometric polynomials of
//! degree < steps/2); the energy of the dynamic part outside harmonics 1..H, relative to the
//! dynamic part's total, tells whether the motion is periodic at the excitation's period.
//!
//! [`verify_point`] starts on a harmonic-balance solution (positions and velocities at τ = 0
//! from its coefficients; slider positions by marching the contact law on its periodic motion
//! from T(0) = m μ N(0), as the AFT does) and integrates twice, with `steps_per_period` and
//! twice as many steps: the change of the first-harmonic amplitudes is the reported dt error.

use std::f64::consts::PI;

use faer::Mat;

use crate::contact::harmonic::HarmonicSet;
use crate::contact::{ContactPoint, NormalLoad};
use crate::model::Problem;
use crate::numerics::linalg::solve_dense;

/// Settings of a time integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifySettings {
    /// Newmark steps per excitation period (≥ 8·H is sensible; the default 256·H).
    pub steps_per_period: usize,
    /// Most periods integrated.
    pub max_periods: usize,
    /// Fewest periods integrated, even if the start already repeats.
    pub min_periods: usize,
    /// Tolerance on the period-to-period change of the state at the period start, relative to
    /// the largest first-harmonic amplitude of the last period.
    pub periodicity_tolerance: f64,
    /// Newton tolerance on the step residual, relative to the load scale.
    pub newton_tolerance: f64,
    /// Newton iterations per step before the step is reported failed.
    pub max_newton: usize,
}

impl VerifySettings {
    /// Defaults for a harmonic set with highest harmonic `h_max`: 256·H steps per period,
    /// 300 periods at most, at least 4, periodicity tolerance 10⁻⁵.
    pub fn for_harmonics(h_max: usize) -> Self {
        Self {
            steps_per_period: 256 * h_max.max(1),
            max_periods: 300,
            min_periods: 4,
            periodicity_tolerance: 1e-5,
            newton_tolerance: 1e-9,
            max_newton: 50,
        }
    }
}

/// Errors of a time integration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VerifyError {
    /// The model is not supported by the time integration.
    #[error("time integration not supported: {reason}")]
    Unsupported {
        /// Why.
        reason: String,
    },
    /// The step Newton did not converge.
    #[error("Newton did not converge at t = {time_s:.6e} s (residual {residual:.3e})")]
    StepFailed {
        /// Time of the failed step (s).
        time_s: f64,
        /// Last relative residual.
        residual: f64,
    },
    /// The static deflection could not be solved.
    #[error("static deflection: {0}")]
    Static(String),
    /// The initial coefficients do not match the problem's layout.
    #[error("initial coefficients have length {found}, expected {expected}")]
    WrongLength {
        /// Expected length.
        expected: usize,
        /// Found length.
        found: usize,
    },
}

/// The state of the structure and its contact sliders at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeState {
    /// Displacements q (m).
    pub q: Vec<f64>,
    /// Velocities q̇ (m/s).
    pub qdot: Vec<f64>,
    /// Slider position w of each contact point (m, along its tangential coordinate u).
    pub sliders: Vec<f64>,
}

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

/// Dense M, C, K of the problem's model.
struct DenseModel {
    m: Mat<f64>,
    c: Mat<f64>,
    k: Mat<f64>,
}

fn check_supported(problem: &Problem) -> Result<(), VerifyError> {
    if problem.effects.contact.normal_load == NormalLoad::Constant && !problem.contacts.is_empty() {
        return Err(VerifyError::Unsupported {
            reason:
                "effects.normal_load = \"constant\" has no time-domain meaning; use \"variable\""
                    .into(),
        });
    }
    let n = problem.model.n_dofs();
    if n > 2000 {
        return Err(VerifyError::Unsupported {
            reason: format!("{n} DOFs: the dense time integration is for lumped or reduced models (≤ 2000 DOFs)"),
        });
    }
    Ok(())
}

/// Per-contact result of the return mapping at a trial displacement.
struct ContactEval {
    t: f64,
    n: f64,
    dt_du: f64,
    dt_dv: f64,
    dn_dv: f64,
    slider: f64,
}

/// Return mapping of the Jenkins law (paper Eqs. 4-6) at u, v from the committed slider `w0`,
/// with the AFT's conventions (closed iff N > 0).
fn return_map(point: &ContactPoint, liftoff: bool, u: f64, v: f64, w0: f64) -> ContactEval {
    let law = &point.law;
    let nk = law.kn * v;
    let (n, dn_dv) = if liftoff && nk <= 0.0 {
        (0.0, 0.0)
    } else {
        (nk, law.kn)
    };
    if n <= 0.0 {
        return ContactEval {
            t: 0.0,
            n,
            dt_du: 0.0,
            dt_dv: 0.0,
            dn_dv,
            slider: u,
        };
    }
    let limit = law.mu * n;
    let trial = law.kt * (u - w0);
    if trial.abs() <= limit {
        ContactEval {
            t: trial,
            n,
            dt_du: law.kt,
            dt_dv: 0.0,
            dn_dv,
            slider: w0,
        }
    } else {
        let s = trial.signum();
        ContactEval {
            t: s * limit,
            n,
            dt_du: 0.0,
            dt_dv: s * law.mu * law.kn,
            dn_dv,
            slider: u - s * limit / law.kt,
        }
    }
}

/// Adds the contact forces at `q` (from committed sliders `w0`) to `f`, their tangent to `kc`
/// if given, and writes the trial sliders to `w1`.
fn contact_forces(
    problem: &Problem,
    q: &[f64],
    w0: &[f64],
    f: &mut [f64],
    mut kc: Option<&mut Mat<f64>>,
    w1: &mut [f64],
) {
    let liftoff = problem.effects.contact.liftoff;
    for (ci, p) in problem.contacts.iter().enumerate() {
        let u = p.tangential_of(q);
        let v = p.normal_of(q) - p.gap;
        let e = return_map(p, liftoff, u, v, w0[ci]);
        w1[ci] = e.slider;
        for &(i, a) in &p.tangential {
            f[i] += a * e.t;
        }
        for &(i, a) in &p.normal {
            f[i] += a * e.n;
        }
        if let Some(kc) = kc.as_deref_mut() {
            for &(i, ai) in &p.tangential {
                for &(j, aj) in &p.tangential {
                    kc[(i, j)] += ai * e.dt_du * aj;
                }
                for &(j, aj) in &p.normal {
                    kc[(i, j)] += ai * e.dt_dv * aj;
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

fn mat_vec_add(a: &Mat<f64>, alpha: f64, x: &[f64], y: &mut [f64]) {
    for j in 0..a.ncols() {
        let xj = alpha * x[j];
        if xj != 0.0 {
            for i in 0..a.nrows() {
                y[i] += a[(i, j)] * xj;
            }
        }
    }
}

/// External load F_static + F_h at τ = ωt (N).
fn external_load(problem: &Problem, tau: f64, f: &mut [f64]) {
    f.copy_from_slice(&problem.static_load);
    for l in &problem.harmonic_loads {
        let a = l.harmonic as f64 * tau;
        f[l.dof] += l.cos * a.cos() + l.sin * a.sin();
    }
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
    check_supported(problem)?;
    let n = problem.model.n_dofs();
    let nc = problem.contacts.len();
    if start.q.len() != n || start.qdot.len() != n || start.sliders.len() != nc {
        return Err(VerifyError::WrongLength {
            expected: n,
            found: start.q.len(),
        });
    }
    let model = DenseModel {
        m: problem.model.mass.to_dense(),
        c: problem.model.damping.to_dense(),
        k: problem.model.stiffness.to_dense(),
    };
    let omega = 2.0 * PI * freq_hz;
    let steps = settings.steps_per_period.max(8);
    let dt = 2.0 * PI / (omega * steps as f64);
    let dtau = 2.0 * PI / steps as f64;
    let load_scale = problem
        .static_load
        .iter()
        .map(|v| v.abs())
        .chain(problem.harmonic_loads.iter().map(|l| l.cos.hypot(l.sin)))
        .fold(0.0_f64, f64::max)
        .max(1e-30);

    let mut q = start.q.clone();
    let mut v = start.qdot.clone();
    let mut w = start.sliders.clone();
    let mut w_trial = w.clone();
    // Initial acceleration: M a₀ = F(0) − C v₀ − K q₀ − F_c(q₀).
    let mut rhs = vec![0.0; n];
    external_load(problem, 0.0, &mut rhs);
    mat_vec_add(&model.c, -1.0, &v, &mut rhs);
    mat_vec_add(&model.k, -1.0, &q, &mut rhs);
    let mut fc = vec![0.0; n];
    contact_forces(problem, &q, &w, &mut fc, None, &mut w_trial);
    w.copy_from_slice(&w_trial);
    rhs.iter_mut().zip(&fc).for_each(|(r, f)| *r -= f);
    let mut a = solve_dense(&model.m, &rhs).map_err(|e| VerifyError::Unsupported {
        reason: format!("mass matrix not invertible ({e}): every DOF needs mass"),
    })?;

    let outputs = &problem.outputs;
    let mut history: Vec<Vec<f64>> = vec![vec![0.0; steps]; outputs.len()];
    let mut all_history: Vec<Vec<f64>> = vec![vec![0.0; steps]; n];
    let mut period_start = (q.clone(), v.clone());
    let mut last_change = f64::INFINITY;
    let mut settled = false;
    let mut periods = 0;
    let (c4, c2) = (4.0 / (dt * dt), 2.0 / dt);
    let mut q1 = vec![0.0; n];
    let mut r = vec![0.0; n];
    for period in 1..=settings.max_periods.max(1) {
        periods = period;
        for k in 0..steps {
            for (i, hist) in all_history.iter_mut().enumerate() {
                hist[k] = q[i];
            }
            let tau1 = (k + 1) as f64 * dtau;
            // Predictor: constant acceleration.
            for i in 0..n {
                q1[i] = q[i] + dt * v[i] + 0.25 * dt * dt * 2.0 * a[i];
            }
            let mut converged = false;
            let mut last_res = f64::INFINITY;
            for _ in 0..settings.max_newton {
                let a1: Vec<f64> = (0..n)
                    .map(|i| c4 * (q1[i] - q[i] - dt * v[i]) - a[i])
                    .collect();
                let v1: Vec<f64> = (0..n).map(|i| c2 * (q1[i] - q[i]) - v[i]).collect();
                external_load(problem, tau1, &mut r);
                r.iter_mut().for_each(|x| *x = -*x);
                mat_vec_add(&model.m, 1.0, &a1, &mut r);
                mat_vec_add(&model.c, 1.0, &v1, &mut r);
                mat_vec_add(&model.k, 1.0, &q1, &mut r);
                let mut tangent = Mat::from_fn(n, n, |i, j| {
                    c4 * model.m[(i, j)] + c2 * model.c[(i, j)] + model.k[(i, j)]
                });
                contact_forces(problem, &q1, &w, &mut r, Some(&mut tangent), &mut w_trial);
                last_res = r.iter().fold(0.0_f64, |m, x| m.max(x.abs())) / load_scale;
                if last_res <= settings.newton_tolerance {
                    converged = true;
                    break;
                }
                let dq = solve_dense(&tangent, &r).map_err(|_| VerifyError::StepFailed {
                    time_s: ((period - 1) * steps + k + 1) as f64 * dt,
                    residual: last_res,
                })?;
                q1.iter_mut().zip(&dq).for_each(|(x, d)| *x -= d);
            }
            if !converged {
                return Err(VerifyError::StepFailed {
                    time_s: ((period - 1) * steps + k + 1) as f64 * dt,
                    residual: last_res,
                });
            }
            for i in 0..n {
                let a1 = c4 * (q1[i] - q[i] - dt * v[i]) - a[i];
                v[i] = c2 * (q1[i] - q[i]) - v[i];
                a[i] = a1;
            }
            q.copy_from_slice(&q1);
            w.copy_from_slice(&w_trial);
        }
        // Periodicity: change of (q, q̇/ω) at the period start relative to the amplitude.
        let amp = (0..n)
            .map(|i| first_harmonic(&all_history[i]).0)
            .fold(0.0_f64, f64::max)
            .max(1e-300);
        let change = (0..n)
            .map(|i| {
                (q[i] - period_start.0[i])
                    .abs()
                    .max((v[i] - period_start.1[i]).abs() / omega)
            })
            .fold(0.0_f64, f64::max)
            / amp;
        last_change = change;
        period_start = (q.clone(), v.clone());
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

/// The state at τ = 0 of a harmonic-balance solution with full coefficients `x` (harmonic-major
/// on `set`, which must contain the constant block) at `freq_hz`: q(0), q̇(0), and the slider of
/// each contact from the contact law marched over the periodic motion sampled at `samples`
/// points per period, starting from T(0) = m μ N(0) (the AFT's initial condition), until the
/// slider repeats (at most 64 periods).
pub fn hbm_state(
    problem: &Problem,
    set: &HarmonicSet,
    x: &[f64],
    freq_hz: f64,
    samples: usize,
) -> Result<TimeState, VerifyError> {
    let n = problem.model.n_dofs();
    let nb = set.n_blocks();
    if x.len() != n * nb {
        return Err(VerifyError::WrongLength {
            expected: n * nb,
            found: x.len(),
        });
    }
    if !set.has_constant() {
        return Err(VerifyError::Unsupported {
            reason: "the harmonic-balance point has no 0th harmonic (effects.coupling = \"uncoupled\"); verify needs \"coupled\"".into(),
        });
    }
    let omega = 2.0 * PI * freq_hz;
    let at = |tau: f64| -> (Vec<f64>, Vec<f64>) {
        let mut q = vec![0.0; n];
        let mut qd = vec![0.0; n];
        for (j, b) in set.blocks().iter().enumerate() {
            let h = b.harmonic() as f64;
            let (val, der) = match b {
                crate::contact::harmonic::Block::Constant => (1.0, 0.0),
                crate::contact::harmonic::Block::Cos(_) => ((h * tau).cos(), -h * (h * tau).sin()),
                crate::contact::harmonic::Block::Sin(_) => ((h * tau).sin(), h * (h * tau).cos()),
            };
            for i in 0..n {
                q[i] += x[j * n + i] * val;
                qd[i] += x[j * n + i] * der * omega;
            }
        }
        (q, qd)
    };
    let (q0, qd0) = at(0.0);
    let samples = samples.max(8);
    let qs: Vec<Vec<f64>> = (0..samples)
        .map(|k| at(2.0 * PI * k as f64 / samples as f64).0)
        .collect();
    let liftoff = problem.effects.contact.liftoff;
    let sliders = problem
        .contacts
        .iter()
        .map(|p| {
            let u0 = p.tangential_of(&qs[0]);
            let v0 = p.normal_of(&qs[0]) - p.gap;
            let n0 = if liftoff {
                (p.law.kn * v0).max(0.0)
            } else {
                p.law.kn * v0
            };
            let mut w = if n0 > 0.0 {
                u0 - p.law.initial_state * p.law.mu * n0 / p.law.kt
            } else {
                u0
            };
            for _ in 0..64 {
                let w_start = w;
                for qk in qs.iter().skip(1).chain(std::iter::once(&qs[0])) {
                    let u = p.tangential_of(qk);
                    let v = p.normal_of(qk) - p.gap;
                    w = return_map(p, liftoff, u, v, w).slider;
                }
                if (w - w_start).abs() <= 1e-14 * (w.abs() + 1e-12) {
                    break;
                }
            }
            w
        })
        .collect();
    Ok(TimeState {
        q: q0,
        qdot: qd0,
        sliders,
    })
}

/// A start at rest (q̇ = 0) at the static deflection with every contact stuck by its kₜ, kₙ
/// springs about the rest position ([`crate::analysis::linear::stuck_guess`] at h = 0), and each
/// contact's slider placed so that its tangential force is T = m μ N there (N = kₙ v, zero when
/// open), m = `initial_state` ∈ [−1, 1]. Unless m makes T equal the stuck spring force this is
/// not an equilibrium: the integration starts with the transient the changed slider causes.
pub fn static_state(problem: &Problem, initial_state: f64) -> Result<TimeState, VerifyError> {
    let set = HarmonicSet::new(vec![0]);
    let q = crate::analysis::linear::stuck_guess(problem, &set, 0.0)
        .map_err(|e| VerifyError::Static(e.to_string()))?;
    let liftoff = problem.effects.contact.liftoff;
    let sliders = problem
        .contacts
        .iter()
        .map(|p| {
            let u = p.tangential_of(&q);
            let v = p.normal_of(&q) - p.gap;
            let n = if liftoff {
                (p.law.kn * v).max(0.0)
            } else {
                p.law.kn * v
            };
            if n > 0.0 {
                u - initial_state * p.law.mu * n / p.law.kt
            } else {
                u
            }
        })
        .collect();
    Ok(TimeState {
        qdot: vec![0.0; q.len()],
        q,
        sliders,
    })
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
