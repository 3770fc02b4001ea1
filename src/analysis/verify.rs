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
//! A point with the 2D law (`jenkins-2d`) has u, w, T ∈ ℝ² in its tangent plane (components
//! along t₁, t₂) and the same mapping with the radial return of [`crate::contact::aft2d`]:
//! trial T* = kₜ (u − w₀); |T*| ≤ μN stick, otherwise T = μN T*/|T*| and w₁ = u − T/kₜ; its
//! consistent tangent is ∂T/∂u = (μN/|T*|) kₜ (I − d dᵀ), ∂T/∂v = μ kₙ d with d = T*/|T*|. A 1D
//! point is the same mapping with the second components 0 (d = ±1, I − d dᵀ = 0: the 1D slip
//! tangent 0), so one function serves both laws and gives the 1D results unchanged. The slider
//! state of a problem ([`TimeState::sliders`]) holds one coordinate per 1D point and two per 2D
//! point, in contact order ([`slider_offsets`]).
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
//! from T(0) = m μ N(0), as the AFT does: for a 2D point by the AFT's own 2D march,
//! [`crate::contact::aft2d::Aft2dWorkspace`], whose slider at the start of its periodic period
//! is the slider at τ = 0) and integrates twice, with `steps_per_period` and twice as many
//! steps: the change of the first-harmonic amplitudes is the reported dt error.

use std::f64::consts::PI;

use faer::Mat;

use crate::contact::aft2d::Aft2dWorkspace;
use crate::contact::harmonic::HarmonicSet;
use crate::contact::{ContactPoint, NormalLoad};
use crate::model::Problem;
use crate::numerics::linalg::solve_dense;

/// Most DOFs of a model the dense time integration (and the monodromy) accepts: lumped or
/// reduced models.
pub const MAX_VERIFY_DOFS: usize = 2000;

/// Fewest Newmark steps per period a scene may ask of the monodromy
/// (`analysis.monodromy_steps_per_period`).
pub const MIN_MONODROMY_STEPS: usize = 8;

/// Most Newmark steps per period a scene may ask of the monodromy.
pub const MAX_MONODROMY_STEPS: usize = 1 << 16;

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
    /// The monodromy matrix of the periodic orbit could not be computed.
    #[error("monodromy: {0}")]
    Monodromy(String),
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
fn slider_dims(point: &ContactPoint) -> usize {
    if point.second_tangent.is_some() {
        2
    } else {
        1
    }
}

/// The tangential relative displacement (u₁, u₂) of a point at q (u₂ = 0 for a 1D point).
fn tangential_pair(point: &ContactPoint, q: &[f64]) -> [f64; 2] {
    [point.tangential_of(q), point.second_tangential_of(q)]
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
    if n > MAX_VERIFY_DOFS {
        return Err(VerifyError::Unsupported {
            reason: format!("{n} DOFs: the dense time integration is for lumped or reduced models (≤ {MAX_VERIFY_DOFS} DOFs)"),
        });
    }
    Ok(())
}

/// Per-contact result of the return mapping at a trial displacement (second tangential
/// components 0 for a 1D point).
struct ContactEval {
    /// Tangential force (T₁, T₂) (N).
    t: [f64; 2],
    /// Normal force N (N).
    n: f64,
    /// ∂Tₐ/∂u_b, row-major 2×2 (N/m).
    dt_du: [f64; 4],
    /// ∂Tₐ/∂v (N/m).
    dt_dv: [f64; 2],
    /// ∂N/∂v (N/m).
    dn_dv: f64,
    /// Slider after the step (m).
    slider: [f64; 2],
    /// Closed and sticking (the slider did not move).
    stuck: bool,
}

/// Return mapping of the Jenkins law (paper Eqs. 4-6) at u, v from the committed slider `w0`,
/// with the AFT's conventions (closed iff N > 0): for a 2D point the radial return onto the
/// friction circle of [`crate::contact::aft2d`], for a 1D point the same with u₂ = w₂ = 0
/// (which is the 1D law exactly: the slip direction is ±1 and the slip tangent 0).
fn return_map(
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
fn slider_of(w: &[f64], offsets: &[usize], c: usize) -> [f64; 2] {
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
fn contact_forces(
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

/// The full state of the Newmark scheme at one instant: positions q (m), velocities v (m/s),
/// accelerations a (m/s²) and committed sliders w (m).
#[derive(Debug, Clone)]
pub(crate) struct StepState {
    pub(crate) q: Vec<f64>,
    pub(crate) v: Vec<f64>,
    pub(crate) a: Vec<f64>,
    pub(crate) w: Vec<f64>,
}

/// One period of the step map from a [`TimeState`] (see [`Newmark::period_map`]).
#[derive(Debug, Clone)]
pub(crate) struct PeriodEnd {
    /// The state one period later.
    pub(crate) state: TimeState,
    /// Per contact: closed and sticking at every step of the period (its slider never moved).
    pub(crate) stuck_all_period: Vec<bool>,
    /// Largest half range (max − min)/2 of a DOF's displacement over the period (m).
    pub(crate) half_range: f64,
    /// After each step of the period: the smallest distance of a contact from a switch of its
    /// law, relative to its largest normal load over the period (closed: (μN − |T|)/(μ N_max),
    /// and N/N_max; open: −kₙ v / N_max; a contact that never closes counts 1). 0 where some
    /// contact slips or sits at a switch.
    pub(crate) switch_margin: Vec<f64>,
    /// Per contact, at the step where it uses most of its friction: |T|/(μN), T = (T₁, T₂)
    /// (N; T₂ = 0 for a 1D point) and N (N) (zeros for a contact that never closes or has
    /// μ = 0).
    pub(crate) peak_friction_use: Vec<(f64, [f64; 2], f64)>,
    /// Per contact: range max − min of its slider over the period (m; the larger of its two
    /// coordinates' ranges for a 2D point).
    pub(crate) slider_range: Vec<f64>,
}

/// The Newmark average-acceleration stepper of a problem at one excitation frequency (see the
/// module docs): dense M, C, K, the step sizes and the step Newton's settings.
pub(crate) struct Newmark<'a> {
    problem: &'a Problem,
    model: DenseModel,
    /// Excitation circular frequency ω (rad/s).
    pub(crate) omega: f64,
    /// Steps per period.
    pub(crate) steps: usize,
    dt: f64,
    dtau: f64,
    load_scale: f64,
    newton_tolerance: f64,
    accept_tolerance: f64,
    max_newton: usize,
}

impl<'a> Newmark<'a> {
    /// The stepper at `freq_hz` with `settings.steps_per_period` (at least 8) steps per period.
    pub(crate) fn new(
        problem: &'a Problem,
        freq_hz: f64,
        settings: &VerifySettings,
    ) -> Result<Self, VerifyError> {
        check_supported(problem)?;
        let omega = 2.0 * PI * freq_hz;
        let steps = settings.steps_per_period.max(8);
        let load_scale = problem
            .static_load
            .iter()
            .map(|v| v.abs())
            .chain(problem.harmonic_loads.iter().map(|l| l.cos.hypot(l.sin)))
            .fold(0.0_f64, f64::max)
            .max(1e-30);
        Ok(Self {
            problem,
            model: DenseModel {
                m: problem.model.mass.to_dense(),
                c: problem.model.damping.to_dense(),
                k: problem.model.stiffness.to_dense(),
            },
            omega,
            steps,
            dt: 2.0 * PI / (omega * steps as f64),
            dtau: 2.0 * PI / steps as f64,
            load_scale,
            newton_tolerance: settings.newton_tolerance,
            accept_tolerance: settings.newton_tolerance,
            max_newton: settings.max_newton,
        })
    }

    /// A stepper whose step Newton aims at `target` (relative residual) but accepts its best
    /// iterate when that is below the settings' tolerance: at a kink of the contact law
    /// (lift-off, stick-slip) Newton can cycle between the two pieces at the round-off level
    /// of a tight target.
    pub(crate) fn with_target_tolerance(mut self, target: f64) -> Self {
        self.newton_tolerance = target.min(self.accept_tolerance);
        self
    }

    /// The scheme's state at τ = `k0`·dτ from `start`: the sliders return-mapped at q₀ (a slider that
    /// would carry more than μN is moved to the slip limit) and the acceleration from the
    /// equations of motion, M a₀ = F(0) − C v₀ − K q₀ − F_c(q₀).
    pub(crate) fn start(&self, start: &TimeState, k0: usize) -> Result<StepState, VerifyError> {
        let problem = self.problem;
        let n = problem.model.n_dofs();
        let nc = problem.contacts.len();
        if start.q.len() != n || start.qdot.len() != n {
            return Err(VerifyError::WrongLength {
                expected: n,
                found: start.q.len().min(start.qdot.len()),
            });
        }
        let slider_count = slider_offsets(problem)[nc];
        if start.sliders.len() != slider_count {
            return Err(VerifyError::WrongLength {
                expected: slider_count,
                found: start.sliders.len(),
            });
        }
        let mut rhs = vec![0.0; n];
        external_load(problem, k0 as f64 * self.dtau, &mut rhs);
        mat_vec_add(&self.model.c, -1.0, &start.qdot, &mut rhs);
        mat_vec_add(&self.model.k, -1.0, &start.q, &mut rhs);
        let mut fc = vec![0.0; n];
        let mut w = start.sliders.clone();
        let mut stuck = vec![false; nc];
        contact_forces(
            problem,
            &start.q,
            &start.sliders,
            &mut fc,
            None,
            &mut w,
            &mut stuck,
        );
        rhs.iter_mut().zip(&fc).for_each(|(r, f)| *r -= f);
        let a = solve_dense(&self.model.m, &rhs).map_err(|e| VerifyError::Unsupported {
            reason: format!("mass matrix not invertible ({e}): every DOF needs mass"),
        })?;
        Ok(StepState {
            q: start.q.clone(),
            v: start.qdot.clone(),
            a,
            w,
        })
    }

    /// Advances `st` by one step, from τ = k·dτ to (k + 1)·dτ (`step_index` counts steps from
    /// the start of the integration, for the error's time), and writes whether each contact
    /// sticks at the end of the step to `stuck`.
    pub(crate) fn step(
        &self,
        st: &mut StepState,
        k: usize,
        step_index: usize,
        stuck: &mut [bool],
    ) -> Result<(), VerifyError> {
        let problem = self.problem;
        let n = problem.model.n_dofs();
        let (dt, model) = (self.dt, &self.model);
        let (c4, c2) = (4.0 / (dt * dt), 2.0 / dt);
        let tau1 = (k + 1) as f64 * self.dtau;
        // Predictor: constant acceleration.
        let mut q1: Vec<f64> = (0..n)
            .map(|i| st.q[i] + dt * st.v[i] + 0.5 * dt * dt * st.a[i])
            .collect();
        let failed = |residual: f64| VerifyError::StepFailed {
            time_s: (step_index + 1) as f64 * dt,
            residual,
        };
        let nc = problem.contacts.len();
        // The step residual at q₁ (relative to the load scale), with its tangent, the trial
        // sliders and the stick flags.
        let eval = |q1: &[f64]| -> (f64, Vec<f64>, Mat<f64>, Vec<f64>, Vec<bool>) {
            let mut r = vec![0.0; n];
            let a1: Vec<f64> = (0..n)
                .map(|i| c4 * (q1[i] - st.q[i] - dt * st.v[i]) - st.a[i])
                .collect();
            let v1: Vec<f64> = (0..n).map(|i| c2 * (q1[i] - st.q[i]) - st.v[i]).collect();
            external_load(problem, tau1, &mut r);
            r.iter_mut().for_each(|x| *x = -*x);
            mat_vec_add(&model.m, 1.0, &a1, &mut r);
            mat_vec_add(&model.c, 1.0, &v1, &mut r);
            mat_vec_add(&model.k, 1.0, q1, &mut r);
            let mut tangent = Mat::from_fn(n, n, |i, j| {
                c4 * model.m[(i, j)] + c2 * model.c[(i, j)] + model.k[(i, j)]
            });
            let mut w1 = st.w.clone();
            let mut stuck1 = vec![false; nc];
            contact_forces(
                problem,
                q1,
                &st.w,
                &mut r,
                Some(&mut tangent),
                &mut w1,
                &mut stuck1,
            );
            let res = r.iter().fold(0.0_f64, |m, x| m.max(x.abs())) / self.load_scale;
            (res, r, tangent, w1, stuck1)
        };
        let (mut res, mut r, mut tangent, mut w1, mut stuck1) = eval(&q1);
        let mut converged = false;
        // The best iterate within the accept tolerance: (residual, q₁, sliders, stick flags).
        type Candidate = (f64, Vec<f64>, Vec<f64>, Vec<bool>);
        let mut best: Option<Candidate> = None;
        for _ in 0..self.max_newton {
            if res <= self.newton_tolerance {
                converged = true;
                break;
            }
            if res <= self.accept_tolerance && best.as_ref().is_none_or(|b| res < b.0) {
                best = Some((res, q1.clone(), w1.clone(), stuck1.clone()));
            }
            let dq = solve_dense(&tangent, &r).map_err(|_| failed(res))?;
            // A correction at the round-off level of q₁ cannot lower the residual further: the
            // residual's own round-off (the inertia term 4/dt² M (q₁ − q₀ − dt v₀) is large at
            // small dt) is then above the tolerance, and the step has converged.
            let q_size = q1.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            if dq.iter().all(|d| d.abs() <= 1e-13 * q_size) {
                converged = true;
                break;
            }
            // Backtracking on the residual: at a kink of the contact law (lift-off, stick to
            // slip) full Newton steps can cycle between the two pieces.
            let mut alpha = 1.0;
            loop {
                let trial: Vec<f64> = q1.iter().zip(&dq).map(|(x, d)| x - alpha * d).collect();
                let e = eval(&trial);
                if e.0 < res || alpha < 1e-3 {
                    q1 = trial;
                    (res, r, tangent, w1, stuck1) = e;
                    break;
                }
                alpha *= 0.5;
            }
        }
        let mut w_trial = w1;
        stuck.copy_from_slice(&stuck1);
        let last_res = res;
        if !converged {
            let Some((_, q_best, w_best, stuck_best)) = best else {
                return Err(failed(last_res));
            };
            q1 = q_best;
            w_trial = w_best;
            stuck.copy_from_slice(&stuck_best);
        }
        for i in 0..n {
            let a1 = c4 * (q1[i] - st.q[i] - dt * st.v[i]) - st.a[i];
            st.v[i] = c2 * (q1[i] - st.q[i]) - st.v[i];
            st.a[i] = a1;
        }
        st.q.copy_from_slice(&q1);
        st.w.copy_from_slice(&w_trial);
        Ok(())
    }

    /// The period map: integrates one excitation period from `start` at τ = `k0`·dτ (the load
    /// is periodic, so the map from any phase is one period) and returns the state at its end.
    pub(crate) fn period_map(
        &self,
        start: &TimeState,
        k0: usize,
    ) -> Result<PeriodEnd, VerifyError> {
        let end = self.advance(start, k0, self.steps)?;
        Ok(end)
    }

    /// Integrates `count` steps from `start` at τ = `k0`·dτ (see [`Self::period_map`]).
    pub(crate) fn advance(
        &self,
        start: &TimeState,
        k0: usize,
        count: usize,
    ) -> Result<PeriodEnd, VerifyError> {
        let problem = self.problem;
        let nc = problem.contacts.len();
        let n = problem.model.n_dofs();
        let liftoff = problem.effects.contact.liftoff;
        let mut st = self.start(start, k0)?;
        let mut stuck = vec![false; nc];
        let mut stuck_all = vec![true; nc];
        let mut lo = st.q.clone();
        let mut hi = st.q.clone();
        let mut w_lo = st.w.clone();
        let mut w_hi = st.w.clone();
        let offsets = slider_offsets(problem);
        // Per step and contact: (N, T = (T₁, T₂), kₙ v).
        let mut forces: Vec<Vec<(f64, [f64; 2], f64)>> = Vec::with_capacity(count);
        for k in k0..k0 + count {
            self.step(&mut st, k, k - k0, &mut stuck)?;
            stuck_all.iter_mut().zip(&stuck).for_each(|(a, s)| *a &= *s);
            for i in 0..n {
                lo[i] = lo[i].min(st.q[i]);
                hi[i] = hi[i].max(st.q[i]);
            }
            for (i, &w) in st.w.iter().enumerate() {
                w_lo[i] = w_lo[i].min(w);
                w_hi[i] = w_hi[i].max(w);
            }
            forces.push(
                problem
                    .contacts
                    .iter()
                    .enumerate()
                    .map(|(c, p)| {
                        let u = tangential_pair(p, &st.q);
                        let w = slider_of(&st.w, &offsets, c);
                        let knv = p.law.kn * (p.normal_of(&st.q) - p.gap);
                        let nf = if liftoff { knv.max(0.0) } else { knv };
                        let t = [p.law.kt * (u[0] - w[0]), p.law.kt * (u[1] - w[1])];
                        (nf, t, knv)
                    })
                    .collect(),
            );
        }
        let n_max: Vec<f64> = (0..nc)
            .map(|c| forces.iter().map(|f| f[c].0).fold(0.0_f64, f64::max))
            .collect();
        let switch_margin = forces
            .iter()
            .map(|f| {
                (0..nc)
                    .map(|c| {
                        let (nf, t, knv) = f[c];
                        let law = &problem.contacts[c].law;
                        if n_max[c] <= 0.0 {
                            1.0
                        } else if nf > 0.0 {
                            let normal = nf / n_max[c];
                            if law.mu > 0.0 {
                                normal.min((law.mu * nf - t[0].hypot(t[1])) / (law.mu * n_max[c]))
                            } else {
                                normal
                            }
                        } else {
                            -knv / n_max[c]
                        }
                    })
                    .fold(1.0_f64, f64::min)
            })
            .collect();
        let half_range = (0..n)
            .map(|i| 0.5 * (hi[i] - lo[i]))
            .fold(0.0_f64, f64::max);
        let peak_friction_use = (0..nc)
            .map(|c| {
                let mu = problem.contacts[c].law.mu;
                forces
                    .iter()
                    .filter(|f| f[c].0 > 0.0 && mu > 0.0)
                    .map(|f| (f[c].1[0].hypot(f[c].1[1]) / (mu * f[c].0), f[c].1, f[c].0))
                    .fold((0.0, [0.0; 2], 0.0), |a, b| if b.0 > a.0 { b } else { a })
            })
            .collect();
        Ok(PeriodEnd {
            state: TimeState {
                q: st.q,
                qdot: st.v,
                sliders: st.w,
            },
            stuck_all_period: stuck_all,
            half_range,
            switch_margin,
            peak_friction_use,
            slider_range: (0..nc)
                .map(|c| {
                    (offsets[c]..offsets[c + 1])
                        .map(|i| w_hi[i] - w_lo[i])
                        .fold(0.0_f64, f64::max)
                })
                .collect(),
        })
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

/// The state at τ = 0 of a harmonic-balance solution with full coefficients `x` (harmonic-major
/// on `set`, which must contain the constant block) at `freq_hz`: q(0), q̇(0), and the slider of
/// each contact from the contact law marched over the periodic motion sampled at `samples`
/// points per period, starting from T(0) = m μ N(0) (the AFT's initial condition), until the
/// slider repeats (at most 64 periods); for a 2D point, the slider at the start of the periodic
/// period of the AFT's own 2D march ([`Aft2dWorkspace`], on the point's coefficients, with
/// `samples` samples), an error if that march does not settle.
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
    let mut sliders = Vec::with_capacity(slider_offsets(problem)[problem.contacts.len()]);
    let mut aft2d: Option<Aft2dWorkspace> = None;
    for p in &problem.contacts {
        if let Some(law) = p.law_2d() {
            // The AFT's 2D march on the point's own coefficients (u₁, u₂, v per block).
            let row_coefficients = |row: &[(usize, f64)]| -> Vec<f64> {
                (0..nb)
                    .map(|j| row.iter().map(|&(i, a)| a * x[j * n + i]).sum())
                    .collect()
            };
            let rows: Vec<&[(usize, f64)]> = p.tangential_rows().collect();
            let u1 = row_coefficients(rows[0]);
            let u2 = row_coefficients(rows[1]);
            let mut v = row_coefficients(&p.normal);
            if let Some(j0) = set.constant_block() {
                v[j0] -= p.gap;
            }
            let ws = aft2d.get_or_insert_with(|| Aft2dWorkspace::new(set, samples));
            ws.evaluate(&law, problem.effects.contact, [&u1, &u2], &v, false)
                .map_err(|e| VerifyError::Unsupported {
                    reason: format!(
                        "the 2D march of contact `{}` on the harmonic-balance point: {e}",
                        p.name
                    ),
                })?;
            sliders.extend_from_slice(&ws.slider_start);
            continue;
        }
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
                w = return_map(p, liftoff, [u, 0.0], v, [w, 0.0]).slider[0];
            }
            if (w - w_start).abs() <= 1e-14 * (w.abs() + 1e-12) {
                break;
            }
        }
        sliders.push(w);
    }
    Ok(TimeState {
        q: q0,
        qdot: qd0,
        sliders,
    })
}

/// A start at rest (q̇ = 0) at a nonlinear static equilibrium in which every closed contact
/// carries the tangential force T = m μ N of its initial state m (`law.initial_state`, the
/// paper's T(τ_ini) = m μ N of Eqs. 14-15 applied to the static state; for a 2D point
/// m = (m₁, m₂) and T = μN m along t₁, t₂): Newton with backtracking on
///
/// ```text
/// K q + Σ_c [ aₜ m μ N(q) + aₙ N(q) ] = F_static,   N = kₙ max(v, 0) (kₙ v without lift-off),
/// ```
///
/// from the stuck static deflection ([`crate::analysis::linear::stuck_guess`] at h = 0), to a
/// residual of 10⁻¹² of the load. Each slider is then placed at w = u − m μ N / kₜ, so that the
/// return mapping gives back T = m μ N (|m| ≤ 1: the contact sticks) and the start is an
/// equilibrium of the equations of motion without the harmonic load; an open contact's slider
/// is at u. An error if Newton does not converge in 100 iterations.
pub fn static_state(problem: &Problem) -> Result<TimeState, VerifyError> {
    let set = HarmonicSet::new(vec![0]);
    let mut q = crate::analysis::linear::stuck_guess(problem, &set, 0.0)
        .map_err(|e| VerifyError::Static(e.to_string()))?;
    let n = q.len();
    let liftoff = problem.effects.contact.liftoff;
    let k = problem.model.stiffness.to_dense();
    let f = &problem.static_load;
    let fnorm = f.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-30);
    let normal = |p: &ContactPoint, q: &[f64]| -> (f64, f64) {
        let v = p.normal_of(q) - p.gap;
        if liftoff && v <= 0.0 {
            (0.0, 0.0)
        } else {
            (p.law.kn * v, p.law.kn)
        }
    };
    let residual = |q: &[f64], jac: Option<&mut Mat<f64>>| -> Vec<f64> {
        let mut r: Vec<f64> = f.iter().map(|x| -x).collect();
        mat_vec_add(&k, 1.0, q, &mut r);
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.copy_from(&k);
        }
        for p in &problem.contacts {
            let (nf, dn) = normal(p, q);
            let m = initial_pair(p);
            for (row, m_a) in p.tangential_rows().zip(m) {
                for &(i, a) in row {
                    r[i] += a * m_a * p.law.mu * nf;
                }
            }
            for &(i, a) in &p.normal {
                r[i] += a * nf;
            }
            if let Some(j) = jac.as_deref_mut() {
                for &(b, ab) in &p.normal {
                    for (row, m_a) in p.tangential_rows().zip(m) {
                        for &(i, a) in row {
                            j[(i, b)] += a * m_a * p.law.mu * dn * ab;
                        }
                    }
                    for &(i, a) in &p.normal {
                        j[(i, b)] += a * dn * ab;
                    }
                }
            }
        }
        r
    };
    let norm = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>().sqrt() / fnorm;
    let mut jac = Mat::<f64>::zeros(n, n);
    let mut rel = f64::INFINITY;
    let mut converged = false;
    for _ in 0..100 {
        let r = residual(&q, Some(&mut jac));
        rel = norm(&r);
        if rel <= 1e-12 {
            converged = true;
            break;
        }
        let dq = solve_dense(&jac, &r).map_err(|e| VerifyError::Static(e.to_string()))?;
        // Backtracking on the residual norm keeps the lift-off kink from cycling.
        let mut alpha = 1.0;
        loop {
            let trial: Vec<f64> = q.iter().zip(&dq).map(|(x, d)| x - alpha * d).collect();
            if norm(&residual(&trial, None)) < rel || alpha < 1e-4 {
                q = trial;
                break;
            }
            alpha *= 0.5;
        }
    }
    if !converged {
        return Err(VerifyError::Static(format!(
            "Newton did not converge in 100 iterations (residual {rel:.3e} of the load)"
        )));
    }
    let sliders = problem
        .contacts
        .iter()
        .flat_map(|p| {
            let u = tangential_pair(p, &q);
            let (nf, _) = normal(p, &q);
            let m = initial_pair(p);
            (0..slider_dims(p)).map(move |a| {
                if nf > 0.0 {
                    u[a] - m[a] * p.law.mu * nf / p.law.kt
                } else {
                    u[a]
                }
            })
        })
        .collect();
    Ok(TimeState {
        qdot: vec![0.0; n],
        q,
        sliders,
    })
}

/// The initial tangential state (m₁, m₂) of a point (m₂ = 0 for a 1D point).
fn initial_pair(point: &ContactPoint) -> [f64; 2] {
    [
        point.law.initial_state,
        point
            .second_tangent
            .as_ref()
            .map_or(0.0, |s| s.initial_state),
    ]
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
