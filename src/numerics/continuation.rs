//! Newton's method with pseudo-arc-length continuation in the frequency (paper Eqs. 8-9).
//!
//! The path y(s) = (x(s), ω(s)) is followed in a scaled space where one unit of ω is 1 Hz
//! (ω/2π) and one unit of x is `x_scale` (m), so step sizes read as "Hz-equivalent" arc length.
//! Each step predicts along the unit tangent t, y_p = y + Δs·t, and corrects with Newton on
//!
//! R(x, ω) = 0,   tᵀ (y − y_p) = 0.
//!
//! A point converges when ‖R‖ ≤ tol_R·‖F_ex‖ and the scaled Newton step ≤ tol_y, or when
//! ‖R‖ ≤ tol_R·‖F_ex‖ and the full Newton step no longer lowers it (the step is then round-off
//! amplified by an ill-conditioned Jacobian near a lightly damped resonance). A failed
//! corrector (iteration limit, divergence, singular Jacobian, failed AFT) is not a result: the
//! step is cut and the reason reported to the observer; below the minimum step the run ends
//! with [`ContinuationError::Stalled`]. Turning points (sign changes of dω/ds) are reported and
//! traversed. The last point is solved at exactly the end frequency.
//!
//! On large problems (at least [`Analysis::chord_min_unknowns`] unknowns) the corrector takes
//! chord iterations: the bordered Newton matrix factorised at one iterate is reused for the
//! next steps, with Broyden's secant updates (`BroydenUpdates`), as long as each cuts the
//! relative residual by at least a factor of 2; otherwise the Jacobian is evaluated and
//! factorised afresh at the current iterate. A chord step costs one residual and one solve
//! against an O(n³) factorisation of a Newton matrix that is dense in the contact DOFs of a
//! reduced model (single-precision factors where the storage keeps them, see
//! [`crate::hbm::schur`]). Where the border is eliminated by blocks (sparse and schur storage) the
//! last factorisation is carried over to the next continuation points (up to `CARRY_POINTS`)
//! with the new tangent as border; a carried factorisation whose full step does not lower the
//! residual is dropped at once. Fixed-frequency Newton takes chord steps the same way. The
//! convergence tests are the same, on the true residual, so the points are those of full
//! Newton; the iteration count reported (and used for step adaptation) counts three chord steps
//! as one iteration. The tangent at the corrected point is then solved with the corrector's
//! last factorisation (the same bordered system) instead of a new Jacobian.

use std::f64::consts::PI;

use crate::model::Analysis;
use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::linalg::LinearSolveError;

/// An operator R(x, λ) with its Jacobian, as continuation needs it.
pub trait ParametricResidual {
    /// Evaluation error of the operator.
    type Error: std::error::Error + Clone;
    /// Number of unknowns x.
    fn dim(&self) -> usize;
    /// Norm that makes residuals relative (e.g. the load norm).
    fn residual_scale(&self) -> f64;
    /// R(x, λ) into r.
    fn residual(&mut self, x: &[f64], lambda: f64, r: &mut [f64]) -> Result<(), Self::Error>;
    /// An empty Jacobian with the operator's storage and pattern.
    fn new_jacobian(&mut self) -> AssembledJacobian;
    /// R, ∂R/∂x and ∂R/∂λ.
    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), Self::Error>;
}

impl ParametricResidual for crate::hbm::HbmSystem<'_> {
    type Error = crate::hbm::HbmError;
    fn dim(&self) -> usize {
        crate::hbm::HbmSystem::dim(self)
    }
    fn residual_scale(&self) -> f64 {
        self.load_norm()
    }
    fn residual(&mut self, x: &[f64], lambda: f64, r: &mut [f64]) -> Result<(), Self::Error> {
        crate::hbm::HbmSystem::residual(self, x, lambda, r)
    }
    fn new_jacobian(&mut self) -> AssembledJacobian {
        crate::hbm::HbmSystem::new_jacobian(self)
    }
    fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_dlambda: &mut [f64],
    ) -> Result<(), Self::Error> {
        crate::hbm::HbmSystem::residual_and_jacobian(self, x, lambda, r, jac, dr_dlambda)
    }
}

/// Why a Newton corrector failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NewtonFailure {
    /// Iteration limit reached.
    #[error("no convergence in {iterations} iterations (relative residual {residual:.3e})")]
    MaxIterations {
        /// Iterations made.
        iterations: usize,
        /// Last relative residual.
        residual: f64,
    },
    /// The residual grew far beyond its starting value.
    #[error("diverged (relative residual {residual:.3e})")]
    Diverged {
        /// Relative residual when stopped.
        residual: f64,
    },
    /// A linear solve failed.
    #[error("{0}")]
    Linear(#[from] LinearSolveError),
    /// The operator failed to evaluate.
    #[error("{0}")]
    Evaluation(String),
    /// The tangent turned too sharply between two points (possible branch jump).
    #[error("tangent turned by {degrees:.1}° in one step")]
    SharpTurn {
        /// Angle between successive tangents.
        degrees: f64,
    },
    /// The corrector converged far from the predicted point (possible branch jump).
    #[error("corrector moved {distance:.3e} from the prediction, more than the step {step:.3e}")]
    FarCorrection {
        /// Scaled distance between predicted and corrected points.
        distance: f64,
        /// Step length.
        step: f64,
    },
}

/// Fatal continuation errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContinuationError {
    /// The first point could not be solved.
    #[error("no solution at the start frequency {freq_hz:.4} Hz: {reason}")]
    Start {
        /// Start frequency (Hz).
        freq_hz: f64,
        /// Cause.
        reason: NewtonFailure,
    },
    /// The step fell below the minimum. When Newton stagnates just above the tolerance, a
    /// contact transition (stick-slip or lift-off) usually sits between two AFT time samples,
    /// where the residual has a kink; the message says so and names the remedy.
    #[error(
        "continuation stalled at {freq_hz:.4} Hz (step {step:.3e} below minimum): {reason}; \
         if the residual stagnates just above tolerance, a contact transition falls between AFT \
         time samples: more samples ([harmonics] samples) usually get past it"
    )]
    Stalled {
        /// Frequency of the last converged point (Hz).
        freq_hz: f64,
        /// Step that failed.
        step: f64,
        /// Last failure.
        reason: NewtonFailure,
    },
}

/// A converged point of the path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathPoint {
    /// Angular frequency ω (rad/s).
    pub omega: f64,
    /// Unknowns x.
    pub x: Vec<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// Final residual relative to the residual scale.
    pub residual: f64,
    /// Arc-length step that reached this point (0 for the first).
    pub step: f64,
}

impl PathPoint {
    /// Frequency in Hz.
    pub fn freq_hz(&self) -> f64 {
        self.omega / (2.0 * PI)
    }
}

/// Receives continuation events; writing results as they come is an observer's job.
pub trait Observer<S: ParametricResidual> {
    /// A point converged. The operator was last evaluated at this point.
    fn accepted(&mut self, _system: &mut S, _point: &PathPoint) {}
    /// A step was rejected and will be retried with `new_step`.
    fn rejected(&mut self, _freq_hz: f64, _step: f64, _new_step: f64, _reason: &NewtonFailure) {}
    /// dω/ds changed sign between the previous and this point.
    fn turning_point(&mut self, _freq_hz: f64) {}
    /// The path could not be followed from `from_hz` and was resumed at `to_hz` (Hz).
    fn leap(&mut self, _from_hz: f64, _to_hz: f64) {}
}

/// An observer that does nothing.
pub struct NoObserver;
impl<S: ParametricResidual> Observer<S> for NoObserver {}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSummary {
    /// Converged points, in path order.
    pub points: Vec<PathPoint>,
    /// Frequencies (Hz) of turning points.
    pub turning_points: Vec<f64>,
    /// Rejected steps.
    pub rejected_steps: usize,
    /// Stretches of the path leapt over: (last point before, first point after), Hz.
    pub leaps: Vec<(f64, f64)>,
    /// Why the run stopped.
    pub end: PathEnd,
}

/// Reason a run stopped normally.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathEnd {
    /// Reached the end frequency.
    EndFrequency,
    /// The path turned back below the start frequency.
    LeftRangeBelow,
    /// The point budget was used up.
    MaxPoints,
}

/// Broyden's ("good") updates of a factorised bordered Newton matrix B₀ over the chord steps
/// of one corrector, in inverse product form: H_k = (I + a_{k−1} s_{k−1}ᵀ) ⋯ (I + a₀ s₀ᵀ) B₀⁻¹
/// with s_j the steps taken. Each step needs one solve with B₀ (the same as a plain chord
/// step) and O(n·k) vector work; the secant updates follow the change of the contact
/// Jacobian along the iterates, so the residual falls faster than with B₀ alone.
/// With p = −H_k G(y_{k+1}) and d_k the previous direction, H_k (G_{k+1} − G_k) = d_k − p,
/// so a_k = (s_k − d_k + p) / (s_kᵀ(d_k − p)) and the next direction is p + a_k (s_kᵀ p).
#[derive(Default)]
struct BroydenUpdates {
    /// (a_j, s_j), oldest first.
    pairs: Vec<(Vec<f64>, Vec<f64>)>,
    /// The last direction d_k and the step s_k = α d_k taken along it (None before the step).
    last: Option<(Vec<f64>, Option<Vec<f64>>)>,
}

impl BroydenUpdates {
    /// Forgets the updates (a new base factorisation or border).
    fn clear(&mut self) {
        self.pairs.clear();
        self.last = None;
    }

    /// A new base factorisation whose first direction is `d`.
    fn restart(&mut self, d: &[f64]) {
        self.pairs.clear();
        self.last = Some((d.to_vec(), None));
    }

    /// The step along the last direction was taken with length α (α = 0: not taken).
    fn stepped(&mut self, alpha: f64) {
        if alpha == 0.0 {
            self.clear();
        } else if let Some((d, step)) = &mut self.last {
            *step = Some(d.iter().map(|v| alpha * v).collect());
        }
    }

    /// The next direction from p = −B₀⁻¹ G(y) at the new iterate.
    fn direction(&mut self, mut p: Vec<f64>) -> Vec<f64> {
        for (a, s) in &self.pairs {
            let c = dot(s, &p);
            p.iter_mut().zip(a).for_each(|(v, ai)| *v += ai * c);
        }
        if let Some((d, Some(s))) = self.last.take() {
            let hy: Vec<f64> = d.iter().zip(&p).map(|(di, pi)| di - pi).collect();
            let denominator = dot(s.as_slice(), &hy);
            if denominator.abs() > 1e-12 * norm(&s) * norm(&hy) && denominator.is_finite() {
                let a: Vec<f64> = s
                    .iter()
                    .zip(&hy)
                    .map(|(si, hi)| (si - hi) / denominator)
                    .collect();
                let c = dot(&s, &p);
                p.iter_mut().zip(&a).for_each(|(v, ai)| *v += ai * c);
                self.pairs.push((a, s));
            }
        }
        self.last = Some((p.clone(), None));
        p
    }
}

/// Newton/continuation driver.
pub struct Continuation {
    /// Settings (frequencies in Hz).
    pub analysis: Analysis,
    /// Scale of x in the arc length (m).
    pub x_scale: f64,
    /// Chord corrector only: the factorisation of its last iterate with the tangent row it
    /// was built with, reused for the tangent at the corrected point.
    last_factor: std::cell::RefCell<Option<(Vec<f64>, crate::numerics::jacobian::BorderedFactor)>>,
    /// Chord corrector only: the last factorisation made, and the points since it was made,
    /// for the next corrector to start from (storages whose border is eliminated by blocks).
    carried: std::cell::RefCell<Option<(crate::numerics::jacobian::BorderedFactor, usize)>>,
}

const OMEGA_SCALE: f64 = 2.0 * PI;
/// Leaps tried past a spot the corrector cannot pass, as fractions of the largest step.
const LEAPS: &[f64] = &[0.02, 0.1, 0.5];
/// Chord iterations of the corrector counted as one Newton iteration (for step adaptation and
/// reports), and the factor of the iteration limit allowed with chord iterations.
const CHORD_STEPS_PER_ITERATION: usize = 3;
/// A chord iteration must cut the relative residual at least by this factor, else the
/// Jacobian is recomputed and factorised at the current iterate.
const CHORD_CONTRACTION: f64 = 0.5;
/// Continuation points a factorisation may be carried over to (see [`Continuation::correct`]).
const CARRY_POINTS: usize = 8;
/// Largest turn of the tangent in one step before the step is cut (unless it is a corner).
const MAX_TURN_DEGREES: f64 = 45.0;

impl Continuation {
    /// A driver with these settings and arc-length scale of x (m).
    pub fn new(analysis: Analysis, x_scale: f64) -> Self {
        Self {
            analysis,
            x_scale,
            last_factor: std::cell::RefCell::new(None),
            carried: std::cell::RefCell::new(None),
        }
    }

    /// Keeps the chord corrector's last factorisation for the tangent at its point.
    fn keep_factor(
        &self,
        factor: Option<crate::numerics::jacobian::BorderedFactor>,
        tangent: &[f64],
    ) {
        *self.last_factor.borrow_mut() = factor.map(|f| (tangent.to_vec(), f));
    }

    /// Convergence test of a Newton iterate: the relative residual at tolerance and the scaled
    /// step below its tolerance.
    fn converged(&self, relative_residual: f64, step: f64) -> bool {
        relative_residual <= self.analysis.residual_tolerance
            && step <= self.analysis.step_tolerance.max(1e-14)
    }

    /// The residual at an iterate of a chord iteration, returned relative to the load: with a
    /// kept factorisation only the residual (unless `r_current` says r holds it already), and
    /// the factorisation dropped when the residual fell by less than CHORD_CONTRACTION from
    /// `previous`; without one (or once dropped) the residual with the Jacobian and ∂R/∂ω.
    fn chord_evaluate<S: ParametricResidual>(
        &self,
        system: &mut S,
        (x, omega): (&[f64], f64),
        (r, jac, dr): (&mut [f64], &mut AssembledJacobian, &mut [f64]),
        factor: &mut Option<crate::numerics::jacobian::BorderedFactor>,
        r_current: bool,
        previous: f64,
    ) -> Result<f64, NewtonFailure> {
        let eval_err = |e: S::Error| NewtonFailure::Evaluation(e.to_string());
        let scale = system.residual_scale();
        if factor.is_some() {
            if !r_current {
                system.residual(x, omega, r).map_err(eval_err)?;
            }
            let rel = norm(r) / scale;
            if rel <= CHORD_CONTRACTION * previous || rel <= self.analysis.residual_tolerance {
                return Ok(rel);
            }
            *factor = None;
        }
        system
            .residual_and_jacobian(x, omega, r, jac, dr)
            .map_err(eval_err)?;
        Ok(norm(r) / scale)
    }

    /// Newton at fixed ω from `x0`, with backtracking on the residual norm.
    pub fn solve_fixed<S: ParametricResidual>(
        &self,
        system: &mut S,
        x0: &[f64],
        omega: f64,
    ) -> Result<PathPoint, NewtonFailure> {
        let n = system.dim();
        let scale = system.residual_scale();
        let mut x = x0.to_vec();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        let mut trial = vec![0.0; n];
        let mut rt = vec![0.0; n];
        let eval_err = |e: S::Error| NewtonFailure::Evaluation(e.to_string());
        // Chord steps on large problems, as in the corrector: the factorisation is kept while
        // each step cuts the residual by CHORD_CONTRACTION.
        let chord = n >= self.analysis.chord_min_unknowns;
        let max_iter = self.analysis.max_iterations.max(1)
            * 3
            * if chord { CHORD_STEPS_PER_ITERATION } else { 1 };
        let mut factor: Option<crate::numerics::jacobian::BorderedFactor> = None;
        let (mut factorisations, mut chord_steps) = (0usize, 0usize);
        // Whether r holds the residual at x (the accepted trial of the previous step).
        let mut r_current = false;
        let mut rel = f64::INFINITY;
        for it in 1..=max_iter {
            let previous = rel;
            rel = self.chord_evaluate(
                system,
                (&x, omega),
                (&mut r, &mut jac, &mut dr),
                &mut factor,
                r_current,
                previous,
            )?;
            let at_tolerance = rel <= self.analysis.residual_tolerance;
            let neg: Vec<f64> = r.iter().map(|v| -v).collect();
            let dx = match &factor {
                Some(f) => {
                    chord_steps += 1;
                    let mut rhs = neg;
                    rhs.push(0.0);
                    let mut d = f.solve_chord(&rhs)?;
                    d.truncate(n);
                    d
                }
                None if chord => {
                    // J bordered by a unit row: its factorisation solves J alone.
                    factorisations += 1;
                    let mut row = vec![0.0; n + 1];
                    row[n] = 1.0;
                    let f = jac.factor_bordered(1.0, &vec![0.0; n], &row)?;
                    let mut rhs = neg;
                    rhs.push(0.0);
                    let mut d = f.solve(&rhs)?;
                    d.truncate(n);
                    factor = Some(f);
                    d
                }
                None => jac.solve(&neg)?,
            };
            let step_norm = norm(&dx) / self.x_scale;
            let mut alpha = 1.0;
            let improved = loop {
                for i in 0..n {
                    trial[i] = x[i] + alpha * dx[i];
                }
                system.residual(&trial, omega, &mut rt).map_err(eval_err)?;
                let rel_t = norm(&rt) / scale;
                let improved = rel_t < rel;
                if improved || alpha < 1e-3 || at_tolerance {
                    if improved || !at_tolerance {
                        rel = rel_t;
                    }
                    break improved;
                }
                alpha *= 0.5;
            };
            // At tolerance, a step that does not lower the residual only moves through
            // round-off: keep the current point (see `correct`).
            let stalled_at_tolerance = at_tolerance && !improved;
            if !stalled_at_tolerance {
                x.copy_from_slice(&trial);
                r.copy_from_slice(&rt);
            }
            r_current = true;
            let it = if chord {
                (factorisations + chord_steps / CHORD_STEPS_PER_ITERATION).max(1)
            } else {
                it
            };
            if stalled_at_tolerance || self.converged(rel, alpha * step_norm) {
                // Leave the operator evaluated at the returned point.
                system
                    .residual_and_jacobian(&x, omega, &mut r, &mut jac, &mut dr)
                    .map_err(eval_err)?;
                return Ok(PathPoint {
                    omega,
                    x,
                    iterations: it,
                    residual: norm(&r) / scale,
                    step: 0.0,
                });
            }
        }
        Err(NewtonFailure::MaxIterations {
            iterations: max_iter,
            residual: rel,
        })
    }

    /// Unit tangent in scaled space at a converged point, oriented along `previous` (or
    /// towards increasing ω when there is none).
    fn tangent<S: ParametricResidual>(
        &self,
        system: &mut S,
        point: &PathPoint,
        previous: Option<&[f64]>,
    ) -> Result<Vec<f64>, NewtonFailure> {
        let n = system.dim();
        let mut rhs = vec![0.0; n + 1];
        rhs[n] = 1.0;
        // Chord corrector: the factorisation of its last iterate, built with the same tangent
        // row, gives the tangent without a new Jacobian (its iterate is within the corrector's
        // tolerance of the point, and the tangent only orients the next prediction).
        let kept = self.last_factor.borrow_mut().take();
        if let (Some((row, factor)), Some(p)) = (kept, previous) {
            if row == p {
                let mut t = factor.solve(&rhs)?;
                let nt = norm(&t);
                t.iter_mut().for_each(|v| *v /= nt);
                if dot(&t, p) < 0.0 {
                    t.iter_mut().for_each(|v| *v = -*v);
                }
                return Ok(t);
            }
        }
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        system
            .residual_and_jacobian(&point.x, point.omega, &mut r, &mut jac, &mut dr)
            .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
        let col: Vec<f64> = dr.iter().map(|v| v * OMEGA_SCALE).collect();
        let row = match previous {
            Some(p) => p.to_vec(),
            None => {
                let mut e = vec![0.0; n + 1];
                e[n] = 1.0;
                e
            }
        };
        let mut t = jac.solve_bordered(self.x_scale, &col, &row, &rhs)?;
        let nt = norm(&t);
        t.iter_mut().for_each(|v| *v /= nt);
        let orientation = match previous {
            Some(p) => dot(&t, p),
            None => t[n],
        };
        if orientation < 0.0 {
            t.iter_mut().for_each(|v| *v = -*v);
        }
        Ok(t)
    }

    /// Corrector: Newton on R = 0 and tᵀ(y − y_p) = 0 in scaled space (y = (x / x_scale,
    /// ω / 2π), `tangent` a unit vector); returns the corrected y, the iterations and the
    /// relative residual.
    pub fn correct<S: ParametricResidual>(
        &self,
        system: &mut S,
        predicted: &[f64],
        tangent: &[f64],
    ) -> Result<(Vec<f64>, usize, f64), NewtonFailure> {
        let n = system.dim();
        let scale = system.residual_scale();
        let mut y = predicted.to_vec();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        let mut col = vec![0.0; n];
        let mut x = vec![0.0; n];
        let mut trial = vec![0.0; n];
        let mut first = f64::NAN;
        let mut rel = f64::INFINITY;
        // Chord iterations on large problems: the factorised bordered matrix is reused while
        // the residual keeps falling fast enough (see the module docs).
        let chord = n >= self.analysis.chord_min_unknowns;
        *self.last_factor.borrow_mut() = None;
        let mut factor: Option<crate::numerics::jacobian::BorderedFactor> = None;
        // A factorisation made at an earlier point of the path (at most CARRY_POINTS back),
        // bordered with this tangent, serves for the first chord steps: when the contact
        // states have not moved much, the point converges without a new factorisation.
        let mut from_carried = false;
        // Whether r holds the residual at the current iterate y (the accepted trial of the
        // previous step), so that a chord step need not evaluate it again.
        let mut r_current = false;
        let mut broyden = BroydenUpdates::default();
        if chord {
            let mut carried = self.carried.borrow_mut();
            if let Some((f, age)) = carried.as_mut() {
                if *age < CARRY_POINTS {
                    *age += 1;
                    factor = f.rebordered(tangent);
                    from_carried = factor.is_some();
                    broyden.clear();
                } else {
                    *carried = None;
                }
            }
        }
        let (mut factorisations, mut chord_steps) = (0usize, 0usize);
        let effort = |f: usize, c: usize| (f + c / CHORD_STEPS_PER_ITERATION).max(1);
        let limit = if chord {
            CHORD_STEPS_PER_ITERATION * self.analysis.max_iterations
        } else {
            self.analysis.max_iterations
        };
        for it in 1..=limit {
            for i in 0..n {
                x[i] = y[i] * self.x_scale;
            }
            let omega = y[n] * OMEGA_SCALE;
            let previous = rel;
            rel = self.chord_evaluate(
                system,
                (&x, omega),
                (&mut r, &mut jac, &mut dr),
                &mut factor,
                r_current,
                previous,
            )?;
            if first.is_nan() {
                first = rel;
            } else if rel > 1e4 * first.max(self.analysis.residual_tolerance) {
                return Err(NewtonFailure::Diverged { residual: rel });
            }
            let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            rhs.push(
                -(0..=n)
                    .map(|j| tangent[j] * (y[j] - predicted[j]))
                    .sum::<f64>(),
            );
            let mut dy = match (&factor, chord) {
                (Some(f), _) => {
                    chord_steps += 1;
                    let p = f.solve_chord(&rhs)?;
                    broyden.direction(p)
                }
                (None, _) => {
                    for i in 0..n {
                        col[i] = dr[i] * OMEGA_SCALE;
                    }
                    factorisations += 1;
                    if chord {
                        let f = jac.factor_bordered(self.x_scale, &col, tangent)?;
                        let d = f.solve(&rhs)?;
                        broyden.restart(&d);
                        *self.carried.borrow_mut() = f.rebordered(tangent).map(|c| (c, 0));
                        from_carried = false;
                        factor = Some(f);
                        d
                    } else {
                        jac.solve_bordered(self.x_scale, &col, tangent, &rhs)?
                    }
                }
            };
            let it = if chord {
                effort(factorisations, chord_steps)
            } else {
                it
            };
            if rel <= self.analysis.residual_tolerance {
                // At tolerance, a Newton step that does not lower the residual only moves
                // through round-off (amplified by the Jacobian's condition number near a
                // lightly damped resonance): the point is converged.
                for j in 0..n {
                    trial[j] = (y[j] + dy[j]) * self.x_scale;
                }
                system
                    .residual(&trial, (y[n] + dy[n]) * OMEGA_SCALE, &mut r)
                    .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                if norm(&r) / scale >= rel {
                    self.keep_factor(factor.take(), tangent);
                    return Ok((y, it, rel));
                }
                r_current = true;
            } else {
                // Backtracking: halve the step while it does not reduce the residual (the
                // contact law is only piecewise smooth, and full steps can cycle between
                // contact states). The arc-length equation is linear, so every fraction of
                // the step keeps it.
                let mut alpha = 1.0;
                loop {
                    for j in 0..n {
                        trial[j] = (y[j] + alpha * dy[j]) * self.x_scale;
                    }
                    system
                        .residual(&trial, (y[n] + alpha * dy[n]) * OMEGA_SCALE, &mut r)
                        .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                    if norm(&r) / scale < rel || alpha < 1e-3 {
                        break;
                    }
                    if from_carried {
                        // A factorisation carried from an earlier point that does not lower
                        // the residual with a full step is not worth backtracking on: stay,
                        // and factorise afresh at this iterate.
                        alpha = 0.0;
                        factor = None;
                        from_carried = false;
                        break;
                    }
                    alpha *= 0.5;
                }
                // r now holds the residual at the accepted iterate (not after a rejected
                // carried step, which leaves the iterate where it was).
                r_current = alpha > 0.0;
                dy.iter_mut().for_each(|v| *v *= alpha);
                broyden.stepped(alpha);
            }
            for j in 0..=n {
                y[j] += dy[j];
            }
            let step = norm(&dy);
            if self.converged(rel, step) {
                self.keep_factor(factor.take(), tangent);
                return Ok((y, it, rel));
            }
            if step <= self.analysis.step_tolerance {
                // The step is converged: check the residual at the updated point.
                for i in 0..n {
                    x[i] = y[i] * self.x_scale;
                }
                system
                    .residual(&x, y[n] * OMEGA_SCALE, &mut r)
                    .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                let rel_new = norm(&r) / scale;
                r_current = true;
                if rel_new <= self.analysis.residual_tolerance {
                    self.keep_factor(factor.take(), tangent);
                    return Ok((y, it, rel_new));
                }
            }
        }
        Err(NewtonFailure::MaxIterations {
            iterations: limit,
            residual: rel,
        })
    }

    /// Tries to continue past a spot where the corrector fails at every step down to the
    /// minimum: predictions [`LEAPS`] of the largest step ahead along the tangent, each
    /// corrected to full tolerance; the first whose correction stays within the leap and whose
    /// tangent keeps the direction of travel is returned with its tangent. Steps that land
    /// beyond the end frequency are not tried (the end point is solved separately).
    fn leap<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        tangent: &[f64],
    ) -> Result<Option<(PathPoint, Vec<f64>)>, ContinuationError> {
        let n = y.len() - 1;
        let omega_end = self.analysis.freq_end_hz * OMEGA_SCALE;
        for &fraction in LEAPS {
            let ds = fraction * self.analysis.max_step;
            let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            if predicted[n] * OMEGA_SCALE >= omega_end {
                continue;
            }
            let Ok((yc, it, rel)) = self.correct(system, &predicted, tangent) else {
                continue;
            };
            let Ok((point, t_new, _)) =
                self.corrected_point(system, &yc, it, rel, ds, &predicted, tangent)
            else {
                continue;
            };
            let distance = norm(
                &yc.iter()
                    .zip(&predicted)
                    .map(|(a, b)| a - b)
                    .collect::<Vec<_>>(),
            );
            if distance <= ds && dot(&t_new, tangent) > 0.0 {
                return Ok(Some((point, t_new)));
            }
        }
        Ok(None)
    }

    /// The path point of a corrected y, its tangent, and the step quality (> 1: the corrector
    /// went farther than the step or the tangent turned by more than [`MAX_TURN_DEGREES`]).
    #[allow(clippy::too_many_arguments)]
    fn corrected_point<S: ParametricResidual>(
        &self,
        system: &mut S,
        yc: &[f64],
        iterations: usize,
        residual: f64,
        ds: f64,
        predicted: &[f64],
        tangent: &[f64],
    ) -> Result<(PathPoint, Vec<f64>, f64), NewtonFailure> {
        let n = yc.len() - 1;
        let distance = norm(
            &yc.iter()
                .zip(predicted)
                .map(|(a, b)| a - b)
                .collect::<Vec<_>>(),
        );
        let point = PathPoint {
            omega: yc[n] * OMEGA_SCALE,
            x: yc[..n].iter().map(|v| v * self.x_scale).collect(),
            iterations,
            residual,
            step: ds,
        };
        let t_new = self.tangent(system, &point, Some(tangent))?;
        let degrees = dot(&t_new, tangent).clamp(-1.0, 1.0).acos().to_degrees();
        let quality = (distance / ds).max(degrees / MAX_TURN_DEGREES);
        Ok((point, t_new, quality))
    }

    /// Follows the path from `x_guess` at the start frequency to the end frequency.
    pub fn run<S: ParametricResidual, O: Observer<S>>(
        &self,
        system: &mut S,
        x_guess: &[f64],
        observer: &mut O,
    ) -> Result<PathSummary, ContinuationError> {
        let a = &self.analysis;
        let omega_start = a.freq_start_hz * OMEGA_SCALE;
        let omega_end = a.freq_end_hz * OMEGA_SCALE;
        let n = system.dim();
        let first = self
            .solve_fixed(system, x_guess, omega_start)
            .map_err(|reason| ContinuationError::Start {
                freq_hz: a.freq_start_hz,
                reason,
            })?;
        observer.accepted(system, &first);
        let mut tangent =
            self.tangent(system, &first, None)
                .map_err(|reason| ContinuationError::Start {
                    freq_hz: a.freq_start_hz,
                    reason,
                })?;
        let mut summary = PathSummary {
            points: vec![first],
            turning_points: Vec::new(),
            rejected_steps: 0,
            leaps: Vec::new(),
            end: PathEnd::MaxPoints,
        };
        let mut ds = a.initial_step.clamp(a.min_step, a.max_step);
        let mut previous_quality: Option<f64> = None;
        while summary.points.len() < a.max_points {
            let last = summary.points.last().expect("at least the first point");
            let y: Vec<f64> = last
                .x
                .iter()
                .map(|v| v / self.x_scale)
                .chain(std::iter::once(last.omega / OMEGA_SCALE))
                .collect();
            let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            if predicted[n] * OMEGA_SCALE >= omega_end {
                // Land exactly on the end frequency from the linearly interpolated guess.
                let frac =
                    ((omega_end / OMEGA_SCALE - y[n]) / (predicted[n] - y[n])).clamp(0.0, 1.0);
                let guess: Vec<f64> = (0..n)
                    .map(|j| (y[j] + frac * (predicted[j] - y[j])) * self.x_scale)
                    .collect();
                match self.solve_fixed(system, &guess, omega_end) {
                    Ok(mut p) => {
                        p.step = ds * frac;
                        observer.accepted(system, &p);
                        summary.points.push(p);
                        summary.end = PathEnd::EndFrequency;
                        return Ok(summary);
                    }
                    Err(reason) => {
                        let new_ds = ds * 0.5;
                        observer.rejected(last.freq_hz(), ds, new_ds, &reason);
                        summary.rejected_steps += 1;
                        if new_ds < a.min_step {
                            return Err(ContinuationError::Stalled {
                                freq_hz: last.freq_hz(),
                                step: ds,
                                reason,
                            });
                        }
                        ds = new_ds;
                        continue;
                    }
                }
            }
            let outcome = self
                .correct(system, &predicted, &tangent)
                .and_then(|(yc, it, rel)| {
                    let distance = norm(
                        &yc.iter()
                            .zip(&predicted)
                            .map(|(a, b)| a - b)
                            .collect::<Vec<_>>(),
                    );
                    let point = PathPoint {
                        omega: yc[n] * OMEGA_SCALE,
                        x: yc[..n].iter().map(|v| v * self.x_scale).collect(),
                        iterations: it,
                        residual: rel,
                        step: ds,
                    };
                    let t_new = self.tangent(system, &point, Some(&tangent))?;
                    let degrees = dot(&t_new, &tangent).clamp(-1.0, 1.0).acos().to_degrees();
                    // Step quality: > 1 means the corrector went far or the path turned sharply.
                    let quality = (distance / ds).max(degrees / MAX_TURN_DEGREES);
                    if quality > 1.0 && ds > 2.0 * a.min_step {
                        // A corner of the piecewise-smooth path (a contact changing state) turns
                        // the tangent by the same angle whatever the step; a branch jump does not.
                        let corner = previous_quality.is_some_and(|q| quality >= 0.7 * q);
                        if !corner {
                            previous_quality = Some(quality);
                            return Err(if distance / ds >= degrees / MAX_TURN_DEGREES {
                                NewtonFailure::FarCorrection { distance, step: ds }
                            } else {
                                NewtonFailure::SharpTurn { degrees }
                            });
                        }
                    }
                    Ok((point, t_new))
                });
            match outcome {
                Ok((point, t_new)) => {
                    previous_quality = None;
                    if t_new[n] * tangent[n] < 0.0 {
                        summary.turning_points.push(point.freq_hz());
                        observer.turning_point(point.freq_hz());
                    }
                    let iterations = point.iterations;
                    observer.accepted(system, &point);
                    let below = point.omega < omega_start;
                    summary.points.push(point);
                    tangent = t_new;
                    if below {
                        summary.end = PathEnd::LeftRangeBelow;
                        return Ok(summary);
                    }
                    let factor =
                        (a.target_iterations as f64 / iterations.max(1) as f64).clamp(0.5, 2.0);
                    ds = (ds * factor).clamp(a.min_step, a.max_step);
                }
                Err(reason) => {
                    let new_ds = ds * 0.5;
                    observer.rejected(last.freq_hz(), ds, new_ds, &reason);
                    summary.rejected_steps += 1;
                    if new_ds < a.min_step {
                        // The path cannot be followed through this spot (Newton cycles between
                        // the pieces of the sampled, piecewise-smooth contact law): try to land
                        // on it further on, with a fully converged point, before giving up.
                        let from = last.freq_hz();
                        match self.leap(system, &y, &tangent)? {
                            Some((point, t_new)) => {
                                observer.leap(from, point.freq_hz());
                                summary.leaps.push((from, point.freq_hz()));
                                if t_new[n] * tangent[n] < 0.0 {
                                    summary.turning_points.push(point.freq_hz());
                                    observer.turning_point(point.freq_hz());
                                }
                                observer.accepted(system, &point);
                                let below = point.omega < omega_start;
                                summary.points.push(point);
                                tangent = t_new;
                                previous_quality = None;
                                if below {
                                    summary.end = PathEnd::LeftRangeBelow;
                                    return Ok(summary);
                                }
                                ds = a.initial_step.clamp(a.min_step, a.max_step);
                                continue;
                            }
                            None => {
                                return Err(ContinuationError::Stalled {
                                    freq_hz: from,
                                    step: ds,
                                    reason,
                                })
                            }
                        }
                    }
                    ds = new_ds;
                }
            }
        }
        summary.end = PathEnd::MaxPoints;
        Ok(summary)
    }
}

/// Euclidean norm.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::prelude::Solve;
    use faer::Mat;

    /// On a linear system G(y) = A y − b with a wrong base matrix B₀, Broyden's updates reach
    /// the solution in at most 2n steps (Gay's theorem), where the plain chord iteration with
    /// B₀ is still far off.
    #[test]
    fn broyden_updates_solve_a_linear_system_with_a_wrong_base_matrix() {
        let n = 4;
        let a = Mat::from_fn(n, n, |i, j| {
            [
                [4.0, 1.0, 0.5, 0.0],
                [0.3, 3.0, -1.0, 0.2],
                [0.0, 1.2, 5.0, 1.0],
                [0.7, 0.0, -0.4, 2.0],
            ][i][j]
        });
        let b0 = Mat::from_fn(n, n, |i, j| if i == j { 1.6 * a[(i, i)] } else { 0.0 });
        let lu = b0.partial_piv_lu();
        let rhs = [1.0, -2.0, 0.5, 3.0];
        let residual = |y: &[f64]| -> Vec<f64> {
            (0..n)
                .map(|i| (0..n).map(|j| a[(i, j)] * y[j]).sum::<f64>() - rhs[i])
                .collect()
        };
        let base_step = |g: &[f64]| -> Vec<f64> {
            let x = lu.solve(Mat::from_fn(n, 1, |i, _| -g[i]));
            (0..n).map(|i| x[(i, 0)]).collect()
        };
        let run = |broyden: bool| -> f64 {
            let mut y = vec![0.0; n];
            let mut updates = BroydenUpdates::default();
            let mut d = base_step(&residual(&y));
            updates.restart(&d);
            for _ in 0..2 * n {
                y.iter_mut().zip(&d).for_each(|(v, s)| *v += s);
                updates.stepped(1.0);
                let p = base_step(&residual(&y));
                d = if broyden { updates.direction(p) } else { p };
            }
            norm(&residual(&y))
        };
        let (with, without) = (run(true), run(false));
        assert!(with < 1e-10, "Broyden residual {with:e}");
        assert!(without > 1e-3, "chord residual {without:e}");
    }
}
