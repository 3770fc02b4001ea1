//! The integrator: Newmark's average acceleration on the dense model, each step solved by
//! Newton with the contacts' return mapping, and the period map its monodromy uses.

use std::f64::consts::PI;

use faer::Mat;

use super::contact::{contact_forces, slider_of, slider_offsets, tangential_pair, TimeState};
use super::settings::{check_supported, VerifyError, VerifySettings};
use crate::model::Problem;
use crate::numerics::linalg::solve_dense;

/// Fewest Newmark steps per period a scene may ask of the monodromy
/// (`analysis.monodromy_steps_per_period`).
pub const MIN_MONODROMY_STEPS: usize = 8;

/// Most Newmark steps per period a scene may ask of the monodromy.
pub const MAX_MONODROMY_STEPS: usize = 1 << 16;

/// Dense M, C, K of the problem's model.
pub(super) struct DenseModel {
    m: Mat<f64>,
    pub(super) c: Mat<f64>,
    pub(super) k: Mat<f64>,
}

pub(super) fn mat_vec_add(a: &Mat<f64>, alpha: f64, x: &[f64], y: &mut [f64]) {
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
    pub(super) problem: &'a Problem,
    pub(super) model: DenseModel,
    /// Excitation circular frequency ω (rad/s).
    pub(crate) omega: f64,
    /// Steps per period.
    pub(crate) steps: usize,
    dt: f64,
    dtau: f64,
    load_scale: f64,
    pub(super) newton_tolerance: f64,
    accept_tolerance: f64,
    pub(super) max_newton: usize,
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
