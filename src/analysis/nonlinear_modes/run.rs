//! The nonlinear-mode run: settings, the continuation in log amplitude from the linear mode,
//! and what each converged point reports.

use std::f64::consts::{PI, TAU};
use std::time::Instant;

use super::accuracy::{extended_problem, EstimateCounts, ModeAccuracy, ModeEstimator, PointValues};
use super::ends::solve_at_dof_amplitude;
pub use super::error::NonlinearModeError;
use super::operator::{EpmcOperator, LogAmplitude};
use super::start::{linear_start, start_guess, LinearStart};
use crate::contact::harmonic::{Block, HarmonicSet};
use crate::contact::ContactState;
use crate::model::Problem;
use crate::numerics::path::{ContinuationError, Observer, PathPoint};
use crate::numerics::{Continuation, ContinuationSettings, PathEnd};

pub use crate::model::ModeChoice;

/// What a nonlinear-mode run is asked.
#[derive(Debug, Clone, PartialEq)]
pub struct NonlinearModeSettings {
    /// The mode.
    pub mode: ModeChoice,
    /// DOF whose first-harmonic sine is fixed at zero (the phase condition) and whose
    /// first-harmonic amplitude the range is given at.
    pub dof: usize,
    /// First-harmonic amplitude range at `dof` (m), low to high: the first point has the low
    /// end and the last the high end at `dof` (to Newton's tolerance, [`super::ends`]); the
    /// continuation runs in the modal amplitude a between them.
    pub amplitude: [f64; 2],
    /// Most continuation points.
    pub max_points: usize,
}

impl NonlinearModeSettings {
    /// The settings of the problem's nonlinear-mode analysis (scene `analysis.kind =
    /// "nonlinear-modes"`), with the point budget `analysis.max_points`; None for an FRF scene.
    pub fn of_problem(problem: &Problem) -> Option<Self> {
        problem.analysis.nonlinear_modes.map(|m| Self {
            mode: m.mode,
            dof: m.dof,
            amplitude: m.amplitude,
            max_points: problem.analysis.continuation.max_points,
        })
    }
}

/// One converged point of a nonlinear mode.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NonlinearModePoint {
    /// Modal amplitude a (kg^½·m): the first-harmonic part of the motion is a ψ₁ with
    /// ψ₁ᵀ M ψ₁ = 1 (cosine and sine blocks).
    pub modal_amplitude: f64,
    /// First-harmonic amplitude at the settings' DOF (m).
    pub dof_amplitude: f64,
    /// Angular frequency ω (rad/s).
    pub omega: f64,
    /// Frequency ω/2π (Hz).
    pub freq_hz: f64,
    /// Artificial damping ξ (1/s) of M q̈ + (C − ξ M) q̇ + … (Krack 2015).
    pub xi: f64,
    /// Modal damping ratio D = ξ / (2ω) (–).
    pub damping_ratio: f64,
    /// Energy dissipated per cycle by the viscous damping and the contacts (J):
    /// ξ π ω Σ_h h² (q_chᵀ M q_ch + q_shᵀ M q_sh), the energy the artificial damping feeds in.
    pub dissipated_energy: f64,
    /// Of it, the part dissipated by the contacts (J): the above less
    /// π ω Σ_h h² (q_chᵀ C q_ch + q_shᵀ C q_sh).
    pub friction_energy: f64,
    /// Contact state of each contact over the period.
    pub states: Vec<ContactState>,
    /// The motion's Fourier coefficients (m), harmonic-major, as in an FRF point.
    pub coefficients: Vec<f64>,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Final residual relative to the residual scale.
    pub residual: f64,
    /// The error estimate (the changes when the harmonics are raised to 2H + 1,
    /// [`super::accuracy`]); None where the scene switched it off (`accuracy.estimate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<ModeAccuracy>,
}

/// How a nonlinear-mode run ended.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum NonlinearModeEnd {
    /// The continuation reached the highest amplitude asked at the DOF.
    Reached,
    /// The modal amplitude reached its limit ([`MODAL_HEADROOM_DECADES`] past the high end
    /// converted with the linear shape at rest) with the amplitude at the DOF still below the
    /// high end: that amplitude turned back, or grows far more slowly than the modal one.
    ModalLimit,
    /// The point budget ran out first.
    MaxPoints,
    /// The path turned back below the lowest amplitude.
    LeftRange,
    /// The continuation stalled (the reason as text).
    Stalled(String),
}

/// A nonlinear mode: the linear mode it starts from and the converged points, rising in
/// amplitude.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NonlinearModeRun {
    /// The linear mode's number (1-based).
    pub mode: usize,
    /// Its frequency (Hz).
    pub linear_freq_hz: f64,
    /// Its modal damping ratio φᵀCφ / (2ω₀) (–).
    pub linear_damping_ratio: f64,
    /// The first-harmonic amplitude range asked at the DOF (m).
    pub amplitude_range: [f64; 2],
    /// The modal amplitude range of the continuation (kg^½·m): from the first point's, at the
    /// low end of `amplitude_range`, to the limit the path may run to
    /// ([`MODAL_HEADROOM_DECADES`] past the high end converted with the linear shape at rest).
    pub modal_range: [f64; 2],
    /// The points.
    pub points: Vec<NonlinearModePoint>,
    /// How it ended.
    pub end: NonlinearModeEnd,
    /// Wall-clock time (s), the error estimate included.
    pub elapsed_s: f64,
    /// Of it, the error estimate's (s; 0 without it).
    pub estimate_elapsed_s: f64,
    /// How the points' estimates were formed (None without the estimate).
    pub estimate_counts: Option<EstimateCounts>,
}

impl NonlinearModeRun {
    /// Whether the run reached the highest amplitude asked.
    pub fn is_complete(&self) -> bool {
        self.end == NonlinearModeEnd::Reached
    }

    /// Why the run is incomplete, in words, with the amplitude at the DOF it reached; None when
    /// complete.
    pub fn incomplete_reason(&self) -> Option<String> {
        let last = self.points.last().map_or(0.0, |p| p.dof_amplitude);
        let highest = self
            .points
            .iter()
            .map(|p| p.dof_amplitude)
            .fold(0.0, f64::max);
        let high = self.amplitude_range[1];
        match &self.end {
            NonlinearModeEnd::Reached => None,
            NonlinearModeEnd::MaxPoints => Some(format!(
                "point budget used up at amplitude {last:.4e} m at the DOF of {high:.4e} m"
            )),
            NonlinearModeEnd::LeftRange => {
                Some("the path turned back below the lowest amplitude".to_string())
            }
            NonlinearModeEnd::ModalLimit => Some(format!(
                "the amplitude at the DOF reached at most {highest:.4e} m of {high:.4e} m up to \
                 the modal amplitude {:.4e} (its limit)",
                self.modal_range[1]
            )),
            NonlinearModeEnd::Stalled(reason) => Some(format!(
                "continuation stalled at amplitude {last:.4e} m at the DOF of {high:.4e} m: \
                 {reason}"
            )),
        }
    }
}

/// Arc-length step settings (in decades of a, and the scales of [`arc_length_scale`]).
const INITIAL_STEP: f64 = 0.05;
const MIN_STEP: f64 = 1e-6;
const MAX_STEP: f64 = 0.25;

/// Decades the modal amplitude may run past the high end of the range converted with the
/// linear shape at rest (a = A / |φ_dof|) while the amplitude at the DOF has not reached it:
/// the shape's share at the DOF falls as contacts slip and lift off (on the paper's 2nd mode
/// the high end of 10⁻³ m at y2 lies 0.01-0.02 decades past the converted one).
pub const MODAL_HEADROOM_DECADES: f64 = 2.0;

/// The autonomous problem: the same structure, contacts and static loads, no harmonic loads.
pub fn autonomous(problem: &Problem) -> Problem {
    let mut p = problem.clone();
    p.harmonic_loads.clear();
    p
}

/// Computes a nonlinear mode of `problem` by EPMC (module docs): from the point whose
/// amplitude at the DOF is the low end of the range to the one where it is the high end
/// ([`super::ends`]), by continuation in the modal amplitude between them.
pub fn solve(
    problem: &Problem,
    settings: &NonlinearModeSettings,
) -> Result<NonlinearModeRun, NonlinearModeError> {
    let started = Instant::now();
    let [low, high] = settings.amplitude;
    if !(low > 0.0 && high > low && high.is_finite()) {
        return Err(NonlinearModeError::BadRange { low, high });
    }
    let free = autonomous(problem);
    let set = free.unknown_harmonics();
    if set.cos_block(1).is_none() {
        return Err(NonlinearModeError::NoFirstHarmonic);
    }
    let start = linear_start(&free, settings.mode, settings.dof)?;
    let at_dof = start.shape[settings.dof].abs();
    let map = LogAmplitude {
        a_min: low / at_dof,
    };
    let a_limit = high / at_dof * 10f64.powf(MODAL_HEADROOM_DECADES);
    let m_phi = mass_times(&free, &start.shape);
    let row_scale = start.omega * start.omega * crate::numerics::linalg::norm(&m_phi);
    let mut op = EpmcOperator::new(&free, start.statics.clone(), settings.dof, map, row_scale)?;
    let base = problem.analysis.continuation;
    let scale = arc_length_scale(&free, &set, &start);
    let newton = Continuation::new(base, scale.clone());
    let (y0, lambda0) = low_end(&mut op, &newton, settings, start_guess(&free, &set, &start));
    let continuation_settings = ContinuationSettings {
        freq_start_hz: lambda0 / TAU,
        freq_end_hz: map.decade(a_limit),
        initial_step: INITIAL_STEP,
        min_step: MIN_STEP,
        max_step: MAX_STEP,
        max_points: settings.max_points,
        ..base
    };
    let mut continuation = Continuation::new(continuation_settings, scale);
    let mut collect = Collect {
        points: Vec::new(),
        settings,
        crossed: false,
    };
    let outcome = continuation.run(&mut op, &y0, &mut collect);
    let crossed = collect.crossed;
    let mut points = collect.points;
    let end = match outcome {
        Ok(_) if crossed => NonlinearModeEnd::Reached,
        Ok(summary) => match summary.end {
            PathEnd::EndFrequency => NonlinearModeEnd::ModalLimit,
            PathEnd::MaxPoints => NonlinearModeEnd::MaxPoints,
            PathEnd::LeftRangeBelow => NonlinearModeEnd::LeftRange,
        },
        Err(ContinuationError::Start { reason, .. }) => {
            return Err(NonlinearModeError::Start(reason))
        }
        Err(e @ ContinuationError::Stalled { .. })
        | Err(e @ ContinuationError::Interrupted { .. }) => {
            NonlinearModeEnd::Stalled(stall_reason(&e))
        }
    };
    if crossed {
        high_end(&mut op, &newton, settings, &mut points);
    }
    let estimate_started = Instant::now();
    let mut estimate_elapsed_s = 0.0;
    let mut estimate_counts = None;
    if problem.analysis.error_estimate.enabled {
        let extended = extended_problem(&free);
        let mut estimator = ModeEstimator::new(
            &free,
            &extended,
            (start.statics.clone(), settings.dof),
            (map, row_scale),
            &continuation,
        )?;
        for p in &mut points {
            let psi = op.normalised(&p.coefficients, p.modal_amplitude);
            let values = PointValues {
                modal_amplitude: p.modal_amplitude,
                omega: p.omega,
                xi: p.xi,
                damping_ratio: p.damping_ratio,
                dof_amplitude: p.dof_amplitude,
            };
            p.accuracy = Some(estimator.estimate(&values, &psi));
        }
        estimate_counts = Some(estimator.counts);
        estimate_elapsed_s = estimate_started.elapsed().as_secs_f64();
    }
    Ok(NonlinearModeRun {
        mode: start.number,
        linear_freq_hz: start.omega / TAU,
        linear_damping_ratio: start.xi / (2.0 * start.omega),
        amplitude_range: settings.amplitude,
        modal_range: [map.amplitude(lambda0), a_limit],
        points,
        end,
        elapsed_s: started.elapsed().as_secs_f64(),
        estimate_elapsed_s,
        estimate_counts,
    })
}

/// The continuation's first point (ψ, ω, ξ) and its λ: the point whose amplitude at the DOF is
/// the low end of the range, from the linear mode `y0` at the modal amplitude converted with
/// the linear shape (λ = 2π); that point itself where the bordered solve fails.
fn low_end(
    op: &mut EpmcOperator<'_>,
    newton: &Continuation,
    settings: &NonlinearModeSettings,
    y0: Vec<f64>,
) -> (Vec<f64>, f64) {
    let mut guess = y0.clone();
    guess.push(TAU);
    match solve_at_dof_amplitude(op, newton, (settings.dof, settings.amplitude[0]), &guess) {
        Ok(p) => (p.x, p.omega),
        Err(_) => (y0, TAU),
    }
}

/// Replaces the last of `points`, the first whose amplitude at the DOF reached the high end of
/// the range, by the point at exactly the high end: solved on the bordered system from the
/// guess interpolated in ln A between it and the point before, else from it. Where both fail
/// the last point stays (it covers the range, past its end).
fn high_end(
    op: &mut EpmcOperator<'_>,
    newton: &Continuation,
    settings: &NonlinearModeSettings,
    points: &mut [NonlinearModePoint],
) {
    let high = settings.amplitude[1];
    let map = op.map();
    let dim_h = op.harmonic_dim();
    let unknowns = |op: &EpmcOperator<'_>, p: &NonlinearModePoint| {
        let mut z = op.normalised(&p.coefficients, p.modal_amplitude);
        z.truncate(dim_h);
        z.extend([p.omega, p.xi, TAU * map.decade(p.modal_amplitude)]);
        z
    };
    let Some((last, before)) = points.split_last_mut() else {
        return;
    };
    let z_last = unknowns(op, last);
    let mut guesses = Vec::new();
    if let Some(previous) = before.last() {
        let z_prev = unknowns(op, previous);
        let (l0, l1) = (previous.dof_amplitude.ln(), last.dof_amplitude.ln());
        if l1 > l0 {
            let t = ((high.ln() - l0) / (l1 - l0)).clamp(0.0, 1.0);
            guesses.push(
                z_prev
                    .iter()
                    .zip(&z_last)
                    .map(|(a, b)| a + t * (b - a))
                    .collect(),
            );
        }
    }
    guesses.push(z_last);
    for guess in guesses {
        if let Ok(point) = solve_at_dof_amplitude(op, newton, (settings.dof, high), &guess) {
            let states = op.system().states.clone();
            *last = mode_point(op, &point, settings.dof, states);
            return;
        }
    }
}

/// The point of the mode of `problem` (as [`solve`] computes it with `settings`) at the modal
/// amplitude `a` (kg^½·m), by Newton at that amplitude from `near` (a point of the same mode
/// of `problem`, e.g. its nearest continuation point): a point between a run's points, without
/// interpolating them. Its error estimate is not formed.
pub fn point_at(
    problem: &Problem,
    settings: &NonlinearModeSettings,
    a: f64,
    near: &NonlinearModePoint,
) -> Result<NonlinearModePoint, NonlinearModeError> {
    let free = autonomous(problem);
    let set = free.unknown_harmonics();
    if set.cos_block(1).is_none() {
        return Err(NonlinearModeError::NoFirstHarmonic);
    }
    let start = linear_start(&free, settings.mode, settings.dof)?;
    let map = LogAmplitude { a_min: a };
    let m_phi = mass_times(&free, &start.shape);
    let row_scale = start.omega * start.omega * crate::numerics::linalg::norm(&m_phi);
    let mut op = EpmcOperator::new(&free, start.statics.clone(), settings.dof, map, row_scale)?;
    let mut y = op.normalised(&near.coefficients, near.modal_amplitude);
    y.truncate(op.harmonic_dim());
    y.extend([near.omega, near.xi]);
    let newton = Continuation::new(
        problem.analysis.continuation,
        arc_length_scale(&free, &set, &start),
    );
    let lambda = TAU * map.decade(a);
    let solved = newton
        .solve_fixed(&mut op, &y, lambda)
        .map_err(NonlinearModeError::Start)?;
    let states = op.system().states.clone();
    Ok(mode_point(&op, &solved, settings.dof, states))
}

/// The continuation's error in the words of a mode (its "frequency" is the decade of a).
fn stall_reason(e: &ContinuationError) -> String {
    match e {
        ContinuationError::Stalled { step, reason, .. } => {
            format!("step {step:.3e} below minimum: {reason}")
        }
        ContinuationError::Interrupted { .. } => "interrupted".to_string(),
        ContinuationError::Start { reason, .. } => reason.to_string(),
    }
}

/// M v.
fn mass_times(problem: &Problem, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; v.len()];
    problem.model.mass.mul_add(1.0, v, &mut out);
    out
}

/// Scales of the unknowns in the arc length, so that one unit (a decade of a) is also a change
/// of a quarter of the shape's norm in the harmonics h ≥ 1 of ψ, of the shape's norm in its 0th
/// harmonic (the static shift relative to a, which can be many times the motion where the
/// structure is soft against the contacts: a contact that slipped once and stuck again holds
/// an offset of μN over the structure's stiffness), of 5 % of the linear frequency, or of 1 %
/// in the damping ratio (Δξ = 0.02 ω₀).
fn arc_length_scale(problem: &Problem, set: &HarmonicSet, start: &LinearStart) -> Vec<f64> {
    let n = problem.model.n_dofs();
    let norm = crate::numerics::linalg::norm(&start.shape).max(f64::MIN_POSITIVE);
    let mut scale: Vec<f64> = set
        .blocks()
        .iter()
        .flat_map(|b| {
            let s = if *b == Block::Constant {
                norm
            } else {
                0.25 * norm
            };
            std::iter::repeat_n(s, n)
        })
        .collect();
    scale.push(0.05 * start.omega);
    scale.push(0.02 * start.omega);
    scale
}

/// Collects the converged points as [`NonlinearModePoint`]s, and ends the path at the first
/// whose amplitude at the DOF reaches the high end of the range.
struct Collect<'s> {
    points: Vec<NonlinearModePoint>,
    settings: &'s NonlinearModeSettings,
    /// Whether the last point reached the high end.
    crossed: bool,
}

impl<'p> Observer<EpmcOperator<'p>> for Collect<'_> {
    fn accepted(&mut self, op: &mut EpmcOperator<'p>, point: &PathPoint, _normal: Option<&[f64]>) {
        let states = op.system().states.clone();
        let p = mode_point(op, point, self.settings.dof, states);
        self.crossed = p.dof_amplitude >= self.settings.amplitude[1];
        self.points.push(p);
    }

    fn reached_end(&self) -> bool {
        self.crossed
    }
}

/// A converged path point as a mode point.
fn mode_point(
    op: &EpmcOperator<'_>,
    point: &PathPoint,
    dof: usize,
    states: Vec<ContactState>,
) -> NonlinearModePoint {
    let a = op.map().amplitude(point.omega);
    let dim_h = op.harmonic_dim();
    let (omega, xi) = (point.x[dim_h], point.x[dim_h + 1]);
    let x = op.physical(&point.x, a);
    let (cos1, sin1) = op.first_harmonic();
    let n = x.len() / op.unknowns().n_blocks();
    let dof_amplitude = x[cos1 * n + dof].hypot(x[sin1 * n + dof]);
    let (kinetic, viscous) = velocity_norms(op, &x);
    let dissipated = xi * PI * omega * kinetic;
    NonlinearModePoint {
        modal_amplitude: a,
        dof_amplitude,
        omega,
        freq_hz: omega / TAU,
        xi,
        damping_ratio: xi / (2.0 * omega),
        dissipated_energy: dissipated,
        friction_energy: dissipated - PI * omega * viscous,
        states,
        coefficients: x,
        newton_iterations: point.iterations,
        residual: point.residual,
        accuracy: None,
    }
}

/// Σ_h h² (q_chᵀ M q_ch + q_shᵀ M q_sh) and the same with C.
fn velocity_norms(op: &EpmcOperator<'_>, x: &[f64]) -> (f64, f64) {
    let set = op.unknowns().clone();
    let model = &op.problem().model;
    let n = model.n_dofs();
    let (mut m_sum, mut c_sum) = (0.0, 0.0);
    for (j, b) in set.blocks().iter().enumerate() {
        let h = b.harmonic() as f64;
        if h == 0.0 {
            continue;
        }
        let q = &x[j * n..(j + 1) * n];
        let (mut mq, mut cq) = (vec![0.0; n], vec![0.0; n]);
        model.mass.mul_add(1.0, q, &mut mq);
        model.damping.mul_add(1.0, q, &mut cq);
        m_sum += h * h * q.iter().zip(&mq).map(|(a, b)| a * b).sum::<f64>();
        c_sum += h * h * q.iter().zip(&cq).map(|(a, b)| a * b).sum::<f64>();
    }
    (m_sum, c_sum)
}
