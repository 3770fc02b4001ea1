//! Newton's method with pseudo-arc-length continuation in the frequency (paper Eqs. 8-9).
//!
//! The path y(s) = (x(s), ω(s)) is followed in a scaled space where one unit of ω is 1 Hz
//! (ω/2π) and one unit of xᵢ is `x_scale[i]` (m), so step sizes read as "Hz-equivalent" arc
//! length. The scale is per unknown so that no block of unknowns (e.g. a large static part)
//! dominates the arc length and hides the change of the others.
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
//! traversed. Where the corrector fails at every step down to the minimum (a contact sample
//! changing state: the residual is only piecewise smooth), the path is resumed past the spot
//! by [`Continuation::corner`] (along the outgoing piece) or [`Continuation::leap`] (further
//! ahead), never on the path already followed: a point found behind the incoming direction
//! is kept only when a look-ahead step from it leaves that path (a sharp fold), since at a
//! contact transition such a point can lead straight back onto the incoming branch, which the
//! path would then retrace (and loop: back along the followed path and on again through the
//! same corners). "On the path" means near the polyline through all the points followed so far
//! and the same solution as the path's own at that frequency, by Newton: the other side of a
//! sharp fold may run within a fraction of a per cent of the side followed, and a branch may
//! come back onto a stretch followed long before. When neither is found, the path is taken on from its last point over a
//! narrow window around the spot, with the arc-length scales of a range that narrow, and past
//! the window with the range's again ([`Continuation::run`]). The spot is instead a *dead
//! end*, where the run ends with [`PathEnd::DeadEnd`] for the caller to go on past the highest
//! frequency reached (as after a path that wandered without progress), when it lies below that
//! frequency (behind a fold), or when a way back along the followed path was refused and either
//! no window is left to try or the frequency turned back and forth over the last points (the
//! path bouncing between corners of the sampled law, see `frequency_reversals`). A window
//! taken where a way back was refused holds its points back from the observer until the path
//! leaves it; a point of it that lands back on the path already followed, or the window
//! failing, drops them and ends the path at that dead end. A stall with no window left ends
//! the run with [`ContinuationError::Stalled`]. The last point is solved at exactly the end
//! frequency. A path runs down in
//! frequency when the end frequency is below the start (e.g. to fill in, back toward a fold, a
//! branch found past it).
//!
//! On large problems (at least [`ContinuationSettings::chord_min_unknowns`] unknowns) the corrector takes
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

use crate::numerics::broyden::BroydenUpdates;
use crate::numerics::jacobian::{AssembledJacobian, BorderedFactor};
use crate::numerics::linalg::{dot, norm};
use crate::numerics::path::{
    ContinuationError, NewtonFailure, Observer, PathEnd, PathPoint, PathSummary,
};
use crate::numerics::residual::ParametricResidual;

/// Continuation and Newton settings. The parameter λ is an angular frequency ω (rad/s) and
/// is given in Hz here; arc-length steps are measured in the scaled space where a unit of
/// frequency is 1 Hz (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuationSettings {
    /// Start frequency (Hz), > 0.
    pub freq_start_hz: f64,
    /// End frequency (Hz), > start.
    pub freq_end_hz: f64,
    /// First arc-length step (Hz-equivalent).
    pub initial_step: f64,
    /// Smallest step before continuation gives up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most continuation points.
    pub max_points: usize,
    /// Newton iterations aimed at per point; steps grow below and shrink above it.
    pub target_iterations: usize,
    /// Newton iterations before a point fails.
    pub max_iterations: usize,
    /// Convergence: ‖R‖ ≤ residual_tolerance · (the operator's residual scale).
    pub residual_tolerance: f64,
    /// Convergence: scaled Newton step norm ≤ step_tolerance.
    pub step_tolerance: f64,
    /// Unknowns from which the corrector takes chord iterations (see the module docs).
    pub chord_min_unknowns: usize,
}

/// Newton/continuation driver.
pub struct Continuation {
    /// Settings (frequencies in Hz).
    pub settings: ContinuationSettings,
    /// Scale of x in the arc length (m).
    pub x_scale: Vec<f64>,
    /// Chord corrector only: the factorisation of its last iterate with the tangent row it
    /// was built with, reused for the tangent at the corrected point.
    last_factor: std::cell::RefCell<Option<(Vec<f64>, BorderedFactor)>>,
    /// Chord corrector only: the last factorisation made, and the points since it was made,
    /// for the next corrector to start from (storages whose border is eliminated by blocks).
    carried: std::cell::RefCell<Option<(BorderedFactor, usize)>>,
    /// How the scale follows the response along the path, if it does.
    adaptive: Option<AdaptiveScale>,
    /// Groups of unknowns whose norm (an output's amplitude) the step length watches.
    amplitudes: Vec<Vec<usize>>,
    /// The narrow-window pass under way, if any (see [`Continuation::enter_narrow`]).
    narrow: Option<NarrowPass>,
    /// Newton gives up once its residual stagnates, if set (see
    /// [`Continuation::with_stagnation_exit`]).
    stagnation: Option<StagnationExit>,
}

/// Newton's exit on a stagnating residual: once past its first [`Self::after`] iterations, a
/// solve whose relative residual has not fallen below [`Self::FACTOR`] of its value
/// [`Self::WINDOW`] iterations before is given up, as one at its iteration limit (the limit
/// stays as it is).
///
/// On the sampled Jenkins law the residual is only piecewise smooth, and a solve that does not
/// converge mostly cycles between contact regimes at a constant residual; one that does
/// converge mostly falls steadily, or after a plateau of a few iterations. Measured on the
/// error estimate's solves of the 2D blade pair at H = 1 (2057 that converge within their
/// limits, 787 that do not): the failing fixed-frequency solves spent all their 36 iterations
/// at a residual of 0.07-0.2; with the exit after 12 iterations, a window of 8 and a factor
/// of 1/2, 3 of the 2057 converging ones were given up, and 20 of 476 on the paper case at a
/// low pre-load (H = 1), whose converging solves fall slowly over long stretches; with the
/// factor 0.9 none and 10 (docs/accuracy.md, "What the estimate costs").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StagnationExit {
    /// Iterations a solve always gets: the exit applies from the next one on.
    pub after: usize,
}

impl StagnationExit {
    /// Iterations over which the residual must fall by [`Self::FACTOR`].
    pub const WINDOW: usize = 8;
    /// Fraction the residual must fall to over [`Self::WINDOW`] iterations.
    pub const FACTOR: f64 = 0.9;

    /// Whether the solve with relative residuals `history` (one per iteration, the last the
    /// current one) has stagnated.
    pub fn stagnated(&self, history: &[f64]) -> bool {
        if history.len() <= self.after {
            return false;
        }
        match history.len().checked_sub(Self::WINDOW + 1) {
            Some(before) => history[history.len() - 1] > Self::FACTOR * history[before],
            None => false,
        }
    }
}

/// A pass over a narrow window around a spot where the path stalled: the response's arc-length
/// scale (and that of the adaptive scale's climb) is that of a range a fraction
/// [`NARROW_WINDOW_FRACTIONS`] of the path's own, so that the response weighs that much more
/// against the frequency in the arc length; the step bounds stay the range's.
#[derive(Debug, Clone, Copy, PartialEq)]
struct NarrowPass {
    /// Frequency of the last point before the stall this window starts from (Hz).
    from_hz: f64,
    /// Frequency of the last point before the first stall of this pass (Hz): `from_hz` unless
    /// the path stalled inside a narrower window first.
    stalled_hz: f64,
    /// Half width of the window (Hz): the pass ends at the first point farther than this from
    /// `from_hz`, either way.
    half_width_hz: f64,
    /// Factor applied to the scales (the window's width over the range).
    factor: f64,
    /// Index of `factor` in [`NARROW_WINDOW_FRACTIONS`].
    attempt: usize,
}

/// A narrow-window pass taken from a dead end, whose points are held back from the observer
/// until the path leaves the window: the state of the path at the dead end (to end there, as
/// if no window had been tried, when the window fails) and what the observer is owed.
#[derive(Debug, Clone)]
struct HeldBack {
    /// Points of the path at the dead end.
    points: usize,
    /// Turning points of the path at the dead end.
    turning_points: usize,
    /// Leaps of the path at the dead end.
    leaps: usize,
    /// Rejected steps of the path at the dead end.
    rejected_steps: usize,
    /// Arc-length scales at the dead end (m).
    x_scale: Vec<f64>,
    /// Adaptive scale at the dead end.
    adaptive: Option<AdaptiveScale>,
    /// Narrow-window pass under way at the dead end.
    narrow: Option<NarrowPass>,
    /// Observer calls owed since the dead end, in order.
    events: Vec<HeldEvent>,
}

/// An observer call held back (see [`HeldBack`]).
#[derive(Debug, Clone)]
enum HeldEvent {
    /// [`Observer::accepted`] for the path point of this index, with this normal (the operator
    /// is evaluated at the point again before the call).
    Accepted(usize, Vec<f64>),
    /// Any other call.
    Call(ObserverCall),
}

/// An observer call that needs nothing but its arguments, reported at once or held back with
/// a window's points ([`report`]).
#[derive(Debug, Clone)]
enum ObserverCall {
    /// [`Observer::rejected`]: frequency (Hz), step, new step, reason.
    Rejected(f64, f64, f64, NewtonFailure),
    /// [`Observer::turning_point`] (Hz).
    TurningPoint(f64),
    /// [`Observer::leap`] from, to (Hz).
    Leap(f64, f64),
}

impl ObserverCall {
    /// Makes the call.
    fn send<S: ParametricResidual, O: Observer<S>>(self, observer: &mut O) {
        match self {
            Self::Rejected(freq_hz, step, new_step, reason) => {
                observer.rejected(freq_hz, step, new_step, &reason)
            }
            Self::TurningPoint(freq_hz) => observer.turning_point(freq_hz),
            Self::Leap(from_hz, to_hz) => observer.leap(from_hz, to_hz),
        }
    }
}

/// Makes `call` on `observer`, or keeps it with the calls of the window held back (`held`).
fn report<S: ParametricResidual, O: Observer<S>>(
    held: &mut Option<HeldBack>,
    observer: &mut O,
    call: ObserverCall,
) {
    match held {
        Some(h) => h.events.push(HeldEvent::Call(call)),
        None => call.send(observer),
    }
}

/// Groups of unknowns whose arc-length scale grows with the response along the path.
///
/// A scale fixed from a first estimate of the response (e.g. the stuck linear one) becomes far
/// too small where the nonlinear response is much larger (a damper bouncing at a low
/// pre-load): the arc length is then spent on the change of x and the path crawls in
/// frequency, thousands of steps for a few hertz. With groups, after each accepted point the
/// scale of group g becomes ‖x_g‖ / `climb` wherever that is more than twice the current one
/// (scales only grow, so the path's resolution where the response is small is kept).
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveScale {
    /// The group of each unknown (0-based).
    pub group_of: Vec<usize>,
    /// Arc length (Hz-equivalent) over which the response climbs from zero to its norm.
    pub climb: f64,
}

const OMEGA_SCALE: f64 = 2.0 * PI;
/// Leaps tried past a spot the corrector cannot pass, as fractions of the largest step.
const LEAPS: &[f64] = &[0.02, 0.1, 0.5];
/// Chord iterations of the corrector counted as one Newton iteration (for step adaptation and
/// reports), and the factor of the iteration limit allowed with chord iterations.
const CHORD_STEPS_PER_ITERATION: usize = 3;
/// Newton accepts a residual within this many times the operator's round-off level (see
/// `Continuation::tolerance_at`): iterates at that level only move through rounding errors.
const ROUND_OFF_FACTOR: f64 = 4.0;
/// Relative residual below which the round-off level is looked at; a level above it would be
/// a badly scaled residual, not round-off.
const ROUND_OFF_CHECK_BELOW: f64 = 1e-6;
/// A chord iteration must cut the relative residual at least by this factor, else the
/// Jacobian is recomputed and factorised at the current iterate.
const CHORD_CONTRACTION: f64 = 0.5;
/// Continuation points a factorisation may be carried over to (see [`Continuation::correct`]).
const CARRY_POINTS: usize = 8;
/// Change of ln(amplitude) of a watched output per step the step length aims at (see
/// [`Continuation::with_amplitude_steps`]): about 10 %.
const TARGET_LOG_AMPLITUDE_CHANGE: f64 = 0.1;
/// Steps tried to turn a sharp corner of the path, as multiples of the minimum step (see
/// [`Continuation::corner`]).
const CORNER_STEPS: &[f64] = &[4.0, 64.0, 1024.0];
/// Fewest points a path may take without progress before it is given up (see
/// [`Continuation::stagnation_points`]).
const MIN_STAGNATION_POINTS: usize = 200;

/// The ground a path has covered, for its no-progress test ([`Continuation::stagnation_points`]):
/// the cells of frequency ([`Self::FREQUENCY_CELLS`] across the range) and of the size of the
/// unknowns (ln ‖x‖ in steps of [`Self::SIZE_CELL`]) its points have entered. A path makes
/// progress where a point enters a cell no point entered before: a branch climbing toward the
/// end frequency, and as well one running back after a fold toward a resonance below it (the
/// middle branch of the 2D blade pair runs down from a fold at 878.9 Hz to its peak at
/// 865.3 Hz over about 2000 points, the corners of its 14 contact points making the steps
/// short), or climbing from it on the upper branch; a path wandering back and forth over the
/// same stretch, or going round a loop it went round before, enters none. (Counting only a new
/// highest frequency as progress gave that middle branch up at 866.9 Hz, above its peak.)
struct VisitedGround {
    cells: std::collections::HashSet<(i64, i64)>,
    cell_hz: f64,
}

impl VisitedGround {
    /// Frequency cells across the run's range.
    const FREQUENCY_CELLS: f64 = 4000.0;
    /// Width of a size cell in ln ‖x‖ (about 5 %).
    const SIZE_CELL: f64 = 0.05;

    fn new(freq_start_hz: f64, freq_end_hz: f64) -> Self {
        let range = (freq_end_hz - freq_start_hz).abs();
        Self {
            cells: std::collections::HashSet::new(),
            cell_hz: if range > 0.0 {
                range / Self::FREQUENCY_CELLS
            } else {
                1.0
            },
        }
    }

    /// Whether the point at `freq_hz` with unknowns `x` enters a cell no point entered before
    /// (and marks it entered).
    fn enters_new(&mut self, freq_hz: f64, x: &[f64]) -> bool {
        let size = norm(x);
        let size_cell = if size > 0.0 && size.is_finite() {
            (size.ln() / Self::SIZE_CELL).floor() as i64
        } else {
            i64::MIN
        };
        let freq_cell = (freq_hz / self.cell_hz).floor() as i64;
        self.cells.insert((freq_cell, size_cell))
    }
}
/// A point found past a corner whose chord from the corner makes a cosine above this with the
/// reversed incoming tangent, and whose tangent makes a cosine above
/// [`CORNER_SAME_PIECE_COSINE`] with the incoming one, lies back on the incoming piece of the
/// path and is rejected.
const CORNER_BACKWARD_COSINE: f64 = 0.95;
/// See [`CORNER_BACKWARD_COSINE`] (cos 0.5°).
const CORNER_SAME_PIECE_COSINE: f64 = 0.999_96;
/// Accepted points (the last ones of the path) that a corner point found behind the incoming
/// direction is checked against (see [`Continuation::runs_back_along`]).
const RETRACE_HISTORY: usize = 64;
/// Look-ahead steps from a corner point found behind the incoming direction, as fractions of
/// the first step (the initial step, at most half the extent of the checked points), tried in
/// turn until one converges (see [`Continuation::runs_back_along`]).
const RETRACE_LOOKAHEADS: &[f64] = &[1.0, 0.25, 0.0625];
/// A look-ahead point closer to the path already followed than this fraction of its distance
/// from the corner (about 3°) lies on it: the corner point would resume the incoming branch
/// backwards (see [`Continuation::runs_back_along`]).
const RETRACE_FRACTION: f64 = 0.05;
/// Relative distance ‖x − x'‖ / ‖x‖ on the unknowns within which two solutions converged by
/// Newton at one frequency are the same solution. Measured: the same solution reached from two
/// starts differs by 3·10⁻¹⁶ to 5·10⁻¹⁴ on the paper's system at F0 = 1 and 5 N, and by
/// 5·10⁻¹¹ to 4.5·10⁻¹⁰ on the 3D blade pair (schur); the two sides of a fold of the paper's
/// system at F0 = 1 N one step out of it differ by 5.1·10⁻⁷ (19.7275 Hz) to 10⁻².
pub const SAME_SOLUTION_TOLERANCE: f64 = 1e-8;
/// Widths of the window of a narrow-window pass past a stall, as fractions of the range, tried
/// in turn, each from the last point reached, while the path stalls inside the window (see
/// [`Continuation::enter_narrow`]). On the 3D blade pair's limit curves over 845-900 Hz a
/// hundredth passed the stall of m = +1 at 852.78 Hz, and a thousandth or a tenth that of
/// m = −1 at 852.74 Hz, where a hundredth stalled again (benches/README.md).
const NARROW_WINDOW_FRACTIONS: &[f64] = &[0.01, 0.001, 0.1];
/// Most narrow-window passes in one run.
const MAX_NARROW_PASSES: usize = 8;
/// Largest turn of the tangent in one step before the step is cut (unless it is a corner).
const MAX_TURN_DEGREES: f64 = 45.0;
/// Turn of the tangent per step the step length aims at: a step that turned the tangent by
/// more is followed by a shorter one (at most halved), one that turned it by less may grow (at
/// most doubled), as Newton's iteration count allows.
const TARGET_TURN_DEGREES: f64 = 10.0;

impl Continuation {
    /// A driver with these settings and arc-length scale of x (m).
    pub fn new(settings: ContinuationSettings, x_scale: Vec<f64>) -> Self {
        Self {
            settings,
            x_scale,
            last_factor: std::cell::RefCell::new(None),
            carried: std::cell::RefCell::new(None),
            adaptive: None,
            amplitudes: Vec::new(),
            narrow: None,
            stagnation: None,
        }
    }

    /// This driver with Newton giving up a solve whose residual stagnates
    /// ([`StagnationExit`]) before its iteration limit: for solves where many do not converge
    /// and a failure only costs the answer (the error estimate's solves on an extended
    /// harmonic set), not for the path's own points.
    pub fn with_stagnation_exit(mut self, exit: StagnationExit) -> Self {
        self.stagnation = Some(exit);
        self
    }

    /// Whether the solve with relative residuals `history` (one per step) is to be given up for
    /// stagnation. With `chord` steps [`CHORD_STEPS_PER_ITERATION`] of them count as one
    /// iteration of [`StagnationExit::after`] and of its window, as of the iteration limit.
    fn stagnates(&self, history: &[f64], chord: bool) -> bool {
        self.stagnation.is_some_and(|exit| {
            if chord {
                // Every third step back from the current one.
                let iterations: Vec<f64> = history
                    .iter()
                    .rev()
                    .step_by(CHORD_STEPS_PER_ITERATION)
                    .rev()
                    .copied()
                    .collect();
                exit.stagnated(&iterations)
            } else {
                exit.stagnated(history)
            }
        })
    }

    /// This driver with steps that also follow the amplitudes ‖x_g‖ of these groups of
    /// unknowns (e.g. the first-harmonic cosine and sine of each output DOF): a step over which
    /// one changed by more than [`TARGET_LOG_AMPLITUDE_CHANGE`] in ln is followed by a shorter
    /// one. Near an anti-resonance an output's coefficients are small and add almost nothing
    /// to the arc length, so without this the path crosses the dip in full steps and the
    /// plotted curve cuts through it.
    pub fn with_amplitude_steps(mut self, groups: Vec<Vec<usize>>) -> Self {
        self.amplitudes = groups;
        self
    }

    /// The largest |ln(a_after / a_before)| over the watched amplitudes (0 without any).
    fn log_amplitude_change(&self, before: &[f64], after: &[f64]) -> f64 {
        let amplitude = |x: &[f64], g: &[usize]| g.iter().map(|&i| x[i] * x[i]).sum::<f64>();
        self.amplitudes
            .iter()
            .map(|g| {
                let (a, b) = (amplitude(before, g), amplitude(after, g));
                if a > 0.0 && b > 0.0 {
                    0.5 * (b / a).ln().abs()
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
    }

    /// This driver with scales that grow with the response along the path (see
    /// [`AdaptiveScale`]).
    pub fn with_adaptive_scale(mut self, adaptive: AdaptiveScale) -> Self {
        self.adaptive = Some(adaptive);
        self
    }

    /// Grows the scale of each group whose norm at `x` (m) has outgrown it (see
    /// [`AdaptiveScale`]) and carries the unit tangent over to the new scaled space. Kept
    /// factorisations are dropped: they were built in the old one.
    fn adapt_scale(&mut self, x: &[f64], tangent: &mut [f64]) {
        let Some(adaptive) = &self.adaptive else {
            return;
        };
        let groups = adaptive.group_of.iter().copied().max().map_or(0, |g| g + 1);
        let mut norms = vec![0.0_f64; groups];
        let mut current = vec![0.0_f64; groups];
        for (i, &g) in adaptive.group_of.iter().enumerate() {
            norms[g] += x[i] * x[i];
            current[g] = current[g].max(self.x_scale[i]);
        }
        let wanted: Vec<f64> = norms.iter().map(|v| v.sqrt() / adaptive.climb).collect();
        if !(0..groups).any(|g| wanted[g] > 2.0 * current[g]) {
            return;
        }
        for (i, &g) in adaptive.group_of.iter().enumerate() {
            if wanted[g] > 2.0 * current[g] {
                let new = wanted[g];
                tangent[i] *= self.x_scale[i] / new;
                self.x_scale[i] = new;
            }
        }
        let length = norm(tangent);
        tangent.iter_mut().for_each(|v| *v /= length);
        *self.last_factor.borrow_mut() = None;
        *self.carried.borrow_mut() = None;
    }

    /// Multiplies the scale of every unknown (and the adaptive scale's climb) by `factor` and
    /// carries the unit tangent over to the new scaled space as the same direction. Kept
    /// factorisations are dropped: they were built in the old one.
    fn rescale(&mut self, factor: f64, tangent: &mut [f64]) {
        let n = self.x_scale.len();
        self.x_scale.iter_mut().for_each(|s| *s *= factor);
        if let Some(adaptive) = &mut self.adaptive {
            adaptive.climb *= factor;
        }
        tangent[..n].iter_mut().for_each(|v| *v /= factor);
        let length = norm(tangent);
        tangent.iter_mut().for_each(|v| *v /= length);
        *self.last_factor.borrow_mut() = None;
        *self.carried.borrow_mut() = None;
    }

    /// Starts a narrow-window pass from the last point before a stall, at `from_hz` (the
    /// path having first stalled after `stalled_hz`): the scales and the climb become those of
    /// a range the fraction `NARROW_WINDOW_FRACTIONS[attempt]` of this one's, until a point
    /// lands farther than half that width from `from_hz` ([`Self::leave_narrow`]). The step
    /// bounds stay the scene's (its `min_step` is where the path gives up).
    ///
    /// Why: the response's arc-length scale is set from the range (a climb to the response
    /// costs a quarter of it), so over a wide range the response weighs little against the
    /// frequency in the arc length. It is that scale which decides whether the corrector gets
    /// across some contact transitions: over 845-900 Hz the 3D blade pair's m = +1 limit curve
    /// stalls at 852.78 Hz with the range's scale, whether the steps are the range's or a
    /// hundredth of them, and passes with a hundredth of the scale, whether the steps are the
    /// range's or a hundredth of them (benches/README.md).
    fn enter_narrow(&mut self, from_hz: f64, stalled_hz: f64, attempt: usize, tangent: &mut [f64]) {
        let range = (self.settings.freq_end_hz - self.settings.freq_start_hz).abs();
        let factor = NARROW_WINDOW_FRACTIONS[attempt];
        self.narrow = Some(NarrowPass {
            from_hz,
            stalled_hz,
            half_width_hz: 0.5 * factor * range,
            factor,
            attempt,
        });
        self.rescale(factor, tangent);
    }

    /// Ends the narrow-window pass under way, if any: the scales and climb of the range again
    /// (a scale the adaptive scale grew during the pass keeps its growth). Returns the
    /// frequency of the last point before the pass's first stall (Hz).
    fn leave_narrow(&mut self, tangent: &mut [f64]) -> Option<f64> {
        let pass = self.narrow.take()?;
        self.rescale(1.0 / pass.factor, tangent);
        Some(pass.stalled_hz)
    }

    /// Whether a narrow-window pass is under way and `freq_hz` lies outside its window.
    fn past_narrow_window(&self, freq_hz: f64) -> bool {
        self.narrow
            .is_some_and(|pass| (freq_hz - pass.from_hz).abs() > pass.half_width_hz)
    }

    /// The hyperplane normal to the path of the unit tangent `t` (scaled space), as a covector
    /// on the unknowns (x, ω in rad/s): tᵢ / x_scaleᵢ and t_ω / 2π (see
    /// [`Observer::accepted`]).
    fn path_normal(&self, t: &[f64]) -> Vec<f64> {
        let n = self.x_scale.len();
        (0..=n)
            .map(|i| {
                if i < n {
                    t[i] / self.x_scale[i]
                } else {
                    t[n] / OMEGA_SCALE
                }
            })
            .collect()
    }

    /// Keeps the chord corrector's last factorisation for the tangent at its point.
    fn keep_factor(&self, factor: Option<BorderedFactor>, tangent: &[f64]) {
        *self.last_factor.borrow_mut() = factor.map(|f| (tangent.to_vec(), f));
    }

    /// The residual tolerance at the iterate (x, ω), relative to the residual scale: the
    /// settings' `residual_tolerance`, raised to [`ROUND_OFF_FACTOR`] times the operator's
    /// round-off level ([`ParametricResidual::round_off`]) where that is larger, since no
    /// Newton step can bring the residual below it. The level is looked at only while the
    /// residual `rel` is above the tolerance and below [`ROUND_OFF_CHECK_BELOW`].
    fn tolerance_at<S: ParametricResidual>(
        &self,
        system: &mut S,
        (x, omega): (&[f64], f64),
        rel: f64,
    ) -> f64 {
        let tolerance = self.settings.residual_tolerance;
        if rel <= tolerance || rel > ROUND_OFF_CHECK_BELOW {
            return tolerance;
        }
        tolerance.max(ROUND_OFF_FACTOR * system.round_off(x, omega) / system.residual_scale())
    }

    /// Convergence test of a Newton iterate: the relative residual at tolerance and the scaled
    /// step below its tolerance.
    fn converged(&self, relative_residual: f64, step: f64, tolerance: f64) -> bool {
        relative_residual <= tolerance && step <= self.settings.step_tolerance.max(1e-14)
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
        factor: &mut Option<BorderedFactor>,
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
            if rel <= CHORD_CONTRACTION * previous || rel <= self.settings.residual_tolerance {
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
        let chord = n >= self.settings.chord_min_unknowns;
        let max_iter = self.settings.max_iterations.max(1)
            * 3
            * if chord { CHORD_STEPS_PER_ITERATION } else { 1 };
        let mut factor: Option<BorderedFactor> = None;
        let (mut factorisations, mut chord_steps) = (0usize, 0usize);
        // Whether r holds the residual at x (the accepted trial of the previous step).
        let mut r_current = false;
        let mut rel = f64::INFINITY;
        let mut history = Vec::new();
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
            let tolerance = self.tolerance_at(system, (&x, omega), rel);
            let at_tolerance = rel <= tolerance;
            history.push(rel);
            if !at_tolerance && self.stagnates(&history, chord) {
                return Err(NewtonFailure::MaxIterations {
                    iterations: it,
                    residual: rel,
                });
            }
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
                    let f = jac.factor_bordered(&vec![1.0; n], &vec![0.0; n], &row)?;
                    let mut rhs = neg;
                    rhs.push(0.0);
                    let mut d = f.solve(&rhs)?;
                    d.truncate(n);
                    factor = Some(f);
                    d
                }
                None => jac.solve(&neg)?,
            };
            let step_norm = scaled_norm(&dx, &self.x_scale);
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
            if stalled_at_tolerance || self.converged(rel, alpha * step_norm, tolerance) {
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
    /// towards the end frequency when there is none).
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
        let mut t = jac.solve_bordered(&self.x_scale, &col, &row, &rhs)?;
        let nt = norm(&t);
        t.iter_mut().for_each(|v| *v /= nt);
        let orientation = match previous {
            Some(p) => dot(&t, p),
            None => self.direction() * t[n],
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
        let mut history = Vec::new();
        // Chord iterations on large problems: the factorised bordered matrix is reused while
        // the residual keeps falling fast enough (see the module docs).
        let chord = n >= self.settings.chord_min_unknowns;
        *self.last_factor.borrow_mut() = None;
        let mut factor: Option<BorderedFactor> = None;
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
            CHORD_STEPS_PER_ITERATION * self.settings.max_iterations
        } else {
            self.settings.max_iterations
        };
        for it in 1..=limit {
            for i in 0..n {
                x[i] = y[i] * self.x_scale[i];
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
            let tolerance = self.tolerance_at(system, (&x, omega), rel);
            if first.is_nan() {
                first = rel;
            } else if rel > 1e4 * first.max(self.settings.residual_tolerance) {
                return Err(NewtonFailure::Diverged { residual: rel });
            }
            history.push(rel);
            if rel > tolerance && self.stagnates(&history, chord) {
                return Err(NewtonFailure::MaxIterations {
                    iterations: it,
                    residual: rel,
                });
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
                        let f = jac.factor_bordered(&self.x_scale, &col, tangent)?;
                        let d = f.solve(&rhs)?;
                        broyden.restart(&d);
                        *self.carried.borrow_mut() = f.rebordered(tangent).map(|c| (c, 0));
                        from_carried = false;
                        factor = Some(f);
                        d
                    } else {
                        jac.solve_bordered(&self.x_scale, &col, tangent, &rhs)?
                    }
                }
            };
            let it = if chord {
                effort(factorisations, chord_steps)
            } else {
                it
            };
            if rel <= tolerance {
                // At tolerance, a Newton step that does not lower the residual only moves
                // through round-off (amplified by the Jacobian's condition number near a
                // lightly damped resonance): the point is converged.
                for j in 0..n {
                    trial[j] = (y[j] + dy[j]) * self.x_scale[j];
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
                        trial[j] = (y[j] + alpha * dy[j]) * self.x_scale[j];
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
            if self.converged(rel, step, tolerance) {
                self.keep_factor(factor.take(), tangent);
                return Ok((y, it, rel));
            }
            if step <= self.settings.step_tolerance {
                // The step is converged: check the residual at the updated point.
                for i in 0..n {
                    x[i] = y[i] * self.x_scale[i];
                }
                system
                    .residual(&x, y[n] * OMEGA_SCALE, &mut r)
                    .map_err(|e| NewtonFailure::Evaluation(e.to_string()))?;
                let rel_new = norm(&r) / scale;
                r_current = true;
                if rel_new <= tolerance {
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
    /// corrected to full tolerance; the first whose correction stays within the leap, whose
    /// tangent keeps the direction of travel and which does not land on the path already
    /// followed ([`Continuation::on_followed_path`]) is returned with its tangent. Steps
    /// that land beyond the end frequency are not tried (the end point is solved separately).
    fn leap<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        tangent: &[f64],
        followed: &[PathPoint],
        refused_retrace: &mut bool,
    ) -> Result<Option<(PathPoint, Vec<f64>)>, ContinuationError> {
        let n = y.len() - 1;
        for &fraction in LEAPS {
            let ds = fraction * self.settings.max_step;
            let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            if self.past_end(&predicted) {
                continue;
            }
            let Ok((yc, it, rel)) = self.correct(system, &predicted, tangent) else {
                continue;
            };
            let Ok((point, t_new, _, _)) =
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
            let reach = norm(&yc.iter().zip(y).map(|(a, b)| a - b).collect::<Vec<_>>());
            if distance <= ds && dot(&t_new, tangent) > 0.0 {
                if !self.on_followed_path(system, &yc, reach, followed) {
                    // The test evaluated the operator elsewhere: the observer expects it
                    // evaluated at the point.
                    let mut r = vec![0.0; n];
                    if system.residual(&point.x, point.omega, &mut r).is_ok() {
                        return Ok(Some((point, t_new)));
                    }
                    continue;
                }
                *refused_retrace = true;
            }
        }
        Ok(None)
    }

    /// Points of the path in the scaled space (x / x_scale, ω / 2π).
    fn scaled_points(&self, points: &[PathPoint]) -> Vec<Vec<f64>> {
        points
            .iter()
            .map(|p| {
                p.x.iter()
                    .zip(&self.x_scale)
                    .map(|(v, s)| v / s)
                    .chain(std::iter::once(p.omega / OMEGA_SCALE))
                    .collect()
            })
            .collect()
    }

    /// Tries to turn a corner of the piecewise-smooth path at `y`, where the corrector fails at
    /// every step down to the minimum because the path leaves `y` in a direction far from the
    /// incoming tangent (a contact sample changing state at `y`: the sampled Jenkins law makes
    /// the residual only piecewise smooth, and at a sharp corner, e.g. a fold whose two
    /// branches meet at an angle, the hyperplane normal to the incoming tangent does not meet
    /// the outgoing branch at all).
    ///
    /// Past the corner (at `y + ds·t_in`) the Jacobian is that of the outgoing piece; its null
    /// direction t_out is the outgoing tangent up to sign. Both signs are corrected on the
    /// hyperplane normal to them at `y ± ds·t_out`; a corrected point that lies back along the
    /// incoming branch (its chord from `y` within [`CORNER_BACKWARD_COSINE`] of −t_in, with the
    /// incoming tangent) or further than the step from its prediction is rejected, and so is
    /// one behind the incoming direction (chord · t_in < 0) from which the path runs back onto
    /// the path already followed (`followed`, [`Continuation::runs_back_along`]): only a sharp
    /// fold's outgoing piece may leave a corner backwards. Returns the point and its tangent
    /// oriented along the chord from `y`.
    fn corner<S: ParametricResidual>(
        &self,
        system: &mut S,
        y: &[f64],
        tangent: &[f64],
        followed: &[PathPoint],
        refused_retrace: &mut bool,
    ) -> Result<Option<(PathPoint, Vec<f64>)>, ContinuationError> {
        let n = y.len() - 1;
        for &multiple in CORNER_STEPS {
            let ds = (multiple * self.settings.min_step).min(self.settings.max_step);
            let beyond: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            let probe = PathPoint {
                omega: beyond[n] * OMEGA_SCALE,
                x: (0..n).map(|j| beyond[j] * self.x_scale[j]).collect(),
                iterations: 0,
                residual: f64::NAN,
                step: ds,
            };
            let Ok(outgoing) = self.tangent(system, &probe, Some(tangent)) else {
                continue;
            };
            for sign in [1.0, -1.0] {
                let direction: Vec<f64> = outgoing.iter().map(|v| sign * v).collect();
                let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * direction[j]).collect();
                if self.past_end(&predicted) {
                    continue;
                }
                let Ok((yc, it, rel)) = self.correct(system, &predicted, &direction) else {
                    continue;
                };
                let chord: Vec<f64> = yc.iter().zip(y).map(|(a, b)| a - b).collect();
                let length = norm(&chord);
                let off = norm(
                    &yc.iter()
                        .zip(&predicted)
                        .map(|(a, b)| a - b)
                        .collect::<Vec<_>>(),
                );
                if length == 0.0 || off > ds {
                    continue;
                }
                let chord: Vec<f64> = chord.iter().map(|v| v / length).collect();
                let Ok((point, t_new, _, _)) =
                    self.corrected_point(system, &yc, it, rel, ds, &predicted, &chord)
                else {
                    continue;
                };
                // Back along the incoming piece: the chord points back and the tangent there
                // is the incoming one. A sharp fold's outgoing piece may run back close to
                // the incoming one, but with its own tangent.
                if -dot(&chord, tangent) > CORNER_BACKWARD_COSINE
                    && dot(&t_new, tangent).abs() > CORNER_SAME_PIECE_COSINE
                {
                    continue;
                }
                // Behind the incoming direction: a sharp fold's outgoing piece, or a piece that
                // leads back onto the incoming branch (its tangent there need not be the
                // incoming one, which the test above relies on). Look ahead along it.
                if dot(&chord, tangent) < 0.0 {
                    if self.runs_back_along(system, (&yc, &t_new), y, followed) {
                        *refused_retrace = true;
                        continue;
                    }
                    // The look-ahead evaluated the operator elsewhere: the observer expects it
                    // evaluated at the point.
                    let mut r = vec![0.0; n];
                    if system.residual(&point.x, point.omega, &mut r).is_err() {
                        continue;
                    }
                }
                return Ok(Some((point, t_new)));
            }
        }
        Ok(None)
    }

    /// Whether the path from a corner point `from` (scaled y) along its tangent `t` runs back
    /// onto the path already followed (`followed`, the accepted points, the corner `y` last).
    /// One step is taken along `t` ([`RETRACE_LOOKAHEADS`] of the initial step, at most half
    /// the extent of the last [`RETRACE_HISTORY`] points from `y`) and corrected; the point
    /// reached is tested by [`Continuation::on_followed_path`]. At a contact transition of the
    /// sampled contact law, a piece found behind the incoming direction can lead straight back
    /// onto the incoming branch (the run would then retrace it downwards), or onto an earlier
    /// stretch of the path (the run would then go round the same loop again and again: the m =
    /// −1 limit curve of the 3D blade pair, whose branch coming down from a fold at 868.68 Hz
    /// met the branch that had risen to it at 854.62 Hz and turned up it again, seven times). A
    /// sharp fold's outgoing piece leaves the followed path, however close to it, and is kept.
    /// When no look-ahead step converges there is no evidence either way and the point is kept.
    fn runs_back_along<S: ParametricResidual>(
        &self,
        system: &mut S,
        (from, t): (&[f64], &[f64]),
        y: &[f64],
        followed: &[PathPoint],
    ) -> bool {
        let n = y.len() - 1;
        let recent = &followed[followed.len().saturating_sub(RETRACE_HISTORY)..];
        let distance = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(p, q)| (p - q) * (p - q))
                .sum::<f64>()
                .sqrt()
        };
        let extent = self
            .scaled_points(recent)
            .iter()
            .map(|p| distance(p, y))
            .fold(0.0, f64::max);
        let first = self.settings.initial_step.min(0.5 * extent);
        if first <= 0.0 {
            return false;
        }
        for &fraction in RETRACE_LOOKAHEADS {
            let h = fraction * first;
            let predicted: Vec<f64> = (0..=n).map(|j| from[j] + h * t[j]).collect();
            let Ok((q, _, _)) = self.correct(system, &predicted, t) else {
                continue;
            };
            if distance(&q, &predicted) > h {
                continue;
            }
            return self.on_followed_path(system, &q, distance(&q, y), followed);
        }
        false
    }

    /// Whether a converged point `q` (scaled y) at distance `reach` from where the path is
    /// lies on the path already followed (`followed`, all its points): closer to the polyline
    /// through them than [`RETRACE_FRACTION`] of `reach` (about 3°), and the same solution as
    /// the path's own at q's frequency ([`Continuation::apart_from_path`] within
    /// [`SAME_SOLUTION_TOLERANCE`], or not resolved by Newton). The polyline alone cannot tell
    /// a retrace from the other side of a sharp fold that runs within a fraction of a per cent
    /// of the side followed (the 3D blade pair's fold at 874.57 Hz: 4·10⁻² of the reach off the
    /// polyline, 2.3·10⁻² apart by Newton; a retrace at 886.69 Hz: 7·10⁻⁴ off, 1.2·10⁻¹⁰ apart).
    fn on_followed_path<S: ParametricResidual>(
        &self,
        system: &mut S,
        q: &[f64],
        reach: f64,
        followed: &[PathPoint],
    ) -> bool {
        let path = self.scaled_points(followed);
        if distance_to_polyline(q, &path) > RETRACE_FRACTION * reach {
            return false;
        }
        !self
            .apart_from_path(system, q, &path)
            .is_some_and(|d| d > SAME_SOLUTION_TOLERANCE)
    }

    /// How far a converged point `q` (scaled y) near the polyline through `path` (scaled
    /// points) lies from the solution the path itself has at q's frequency: Newton at that
    /// frequency, started from the path's point there (interpolated along the polyline segment
    /// nearest to q, or that segment's nearer end where it does not span the frequency), and
    /// ‖x_N − x_q‖ / ‖x_q‖ on the unknowns. Near a sharp fold of the path the other side runs
    /// within a fraction of a per cent of the side followed (measured on the 3D blade pair at
    /// 873.56 Hz: 2·10⁻⁴ apart in amplitude 0.01 Hz from the fold), closer than the polyline
    /// can resolve, but it is another solution: above [`SAME_SOLUTION_TOLERANCE`]. None when
    /// Newton does not converge.
    fn apart_from_path<S: ParametricResidual>(
        &self,
        system: &mut S,
        q: &[f64],
        path: &[Vec<f64>],
    ) -> Option<f64> {
        let n = q.len() - 1;
        let segment = path
            .windows(2)
            .min_by(|a, b| distance_to_polyline(q, a).total_cmp(&distance_to_polyline(q, b)))?;
        let (a, b) = (&segment[0], &segment[1]);
        let guess_scaled: Vec<f64> = if (a[n] - q[n]) * (b[n] - q[n]) <= 0.0 && a[n] != b[n] {
            let t = (q[n] - a[n]) / (b[n] - a[n]);
            a.iter().zip(b).map(|(u, v)| u + t * (v - u)).collect()
        } else if (a[n] - q[n]).abs() <= (b[n] - q[n]).abs() {
            a.clone()
        } else {
            b.clone()
        };
        let guess: Vec<f64> = (0..n).map(|j| guess_scaled[j] * self.x_scale[j]).collect();
        let solved = self.solve_fixed(system, &guess, q[n] * OMEGA_SCALE).ok()?;
        let xq: Vec<f64> = (0..n).map(|j| q[j] * self.x_scale[j]).collect();
        let apart: Vec<f64> = solved.x.iter().zip(&xq).map(|(u, v)| u - v).collect();
        Some(norm(&apart) / norm(&xq))
    }

    /// Whether `point` lies back on the path already followed (`points`, the last
    /// [`RETRACE_HISTORY`] of them looked at): closer to the polyline through them than
    /// [`RETRACE_FRACTION`] of its distance from the last one, as in
    /// [`Continuation::runs_back_along`]. A step that goes on from the last point has its
    /// distance from the polyline equal to its distance from that point.
    fn retraces(&self, point: &PathPoint, points: &[PathPoint]) -> bool {
        let recent = &points[points.len().saturating_sub(RETRACE_HISTORY)..];
        let path = self.scaled_points(recent);
        let (Some(last), Some(q)) = (
            path.last(),
            self.scaled_points(std::slice::from_ref(point)).pop(),
        ) else {
            return false;
        };
        let reach = norm(&q.iter().zip(last).map(|(a, b)| a - b).collect::<Vec<_>>());
        distance_to_polyline(&q, &path) <= RETRACE_FRACTION * reach
    }

    /// The path point of a corrected y, its tangent, the distance of the correction relative
    /// to the step, and the angle (degrees) the tangent turned by over the step.
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
    ) -> Result<(PathPoint, Vec<f64>, f64, f64), NewtonFailure> {
        let n = yc.len() - 1;
        let distance = norm(
            &yc.iter()
                .zip(predicted)
                .map(|(a, b)| a - b)
                .collect::<Vec<_>>(),
        );
        let point = PathPoint {
            omega: yc[n] * OMEGA_SCALE,
            x: yc[..n]
                .iter()
                .zip(&self.x_scale)
                .map(|(v, s)| v * s)
                .collect(),
            iterations,
            residual,
            step: ds,
        };
        let t_new = self.tangent(system, &point, Some(tangent))?;
        let degrees = dot(&t_new, tangent).clamp(-1.0, 1.0).acos().to_degrees();
        Ok((point, t_new, distance / ds, degrees))
    }

    /// Whether the path has left the range for good behind the start frequency. A path that
    /// turns back behind the start (a fold: the response overhangs) is followed on, within the
    /// point budget, since it usually turns again and comes back; only one that runs on to
    /// half the range behind the start (or, running up, to a tenth of the start frequency) is
    /// given up.
    fn left_range(&self, point: &PathPoint) -> bool {
        let a = &self.settings;
        let behind = self.direction() * (a.freq_start_hz - point.freq_hz());
        let range = (a.freq_end_hz - a.freq_start_hz).abs();
        behind > 0.5 * range || (self.direction() > 0.0 && point.freq_hz() < 0.1 * a.freq_start_hz)
    }

    /// +1 when the path runs up in frequency (end above start), −1 when it runs down.
    fn direction(&self) -> f64 {
        if self.settings.freq_end_hz < self.settings.freq_start_hz {
            -1.0
        } else {
            1.0
        }
    }

    /// Whether a predicted y (scaled, ω last) lands at or past the end frequency in the
    /// direction of travel.
    fn past_end(&self, predicted: &[f64]) -> bool {
        let n = predicted.len() - 1;
        self.direction() * (predicted[n] - self.settings.freq_end_hz) >= 0.0
    }

    /// Points a path may take without entering ground it had not covered ([`VisitedGround`])
    /// before it is given up as wandering ([`PathEnd::NoProgress`]): a fifth of the point
    /// budget, at least [`MIN_STAGNATION_POINTS`].
    fn stagnation_points(&self) -> usize {
        (self.settings.max_points / 5).max(MIN_STAGNATION_POINTS)
    }

    /// Takes a converged point with its tangent onto the path: reports it (and a turning point
    /// when dω/ds changed sign from `tangent`), makes its tangent the current one and lets the
    /// scale follow the response. Returns true when the point left the range for good (the
    /// summary's end is then set).
    /// With a window's points held back (`held`), the observer calls are kept in it instead.
    #[allow(clippy::too_many_arguments)]
    fn accept<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        point: PathPoint,
        t_new: Vec<f64>,
        tangent: &mut Vec<f64>,
    ) -> bool {
        let n = t_new.len() - 1;
        if t_new[n] * tangent[n] < 0.0 {
            summary.turning_points.push(point.freq_hz());
            report(held, observer, ObserverCall::TurningPoint(point.freq_hz()));
        }
        let normal = self.path_normal(&t_new);
        match held {
            Some(h) => h
                .events
                .push(HeldEvent::Accepted(summary.points.len(), normal)),
            None => observer.accepted(system, &point, Some(&normal)),
        }
        let left = self.left_range(&point);
        *tangent = t_new;
        self.adapt_scale(&point.x, tangent);
        summary.points.push(point);
        if left {
            summary.end = PathEnd::LeftRangeBelow;
        }
        left
    }

    /// Starts holding back the points of a narrow window taken from a dead end: the path's
    /// state there.
    fn hold_back(&self, summary: &PathSummary) -> HeldBack {
        HeldBack {
            points: summary.points.len(),
            turning_points: summary.turning_points.len(),
            leaps: summary.leaps.len(),
            rejected_steps: summary.rejected_steps,
            x_scale: self.x_scale.clone(),
            adaptive: self.adaptive.clone(),
            narrow: self.narrow,
            events: Vec::new(),
        }
    }

    /// Takes a converged point onto the path. A point of a held-back window that lands back on
    /// the path already followed drops the window ([`Self::drop_held`]: the path ends at the
    /// dead end the window was taken from); any other point is accepted ([`Self::accept`]),
    /// and when that ends the path a held-back window is released or dropped
    /// ([`Self::release_or_end`]). True when the path ends here.
    #[allow(clippy::too_many_arguments)]
    fn take_point<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        point: PathPoint,
        t_new: Vec<f64>,
        tangent: &mut Vec<f64>,
    ) -> bool {
        if held.is_some() && self.narrow.is_some() && self.retraces(&point, &summary.points) {
            if let Some(h) = held.take() {
                self.drop_held(h, summary);
                return true;
            }
        }
        if self.accept(system, observer, held, summary, point, t_new, tangent) {
            if let Some(h) = held.take() {
                self.release_or_end(system, observer, h, summary);
            }
            return true;
        }
        false
    }

    /// Drops a held-back window: the path and the scales as they were at the dead end it was
    /// taken from, and the path ends there ([`PathEnd::DeadEnd`]), as without the window.
    fn drop_held(&mut self, held: HeldBack, summary: &mut PathSummary) {
        summary.points.truncate(held.points);
        summary.turning_points.truncate(held.turning_points);
        summary.leaps.truncate(held.leaps);
        summary.leap_landings.truncate(held.leaps);
        summary.rejected_steps = held.rejected_steps;
        self.x_scale = held.x_scale;
        self.adaptive = held.adaptive;
        self.narrow = held.narrow;
        *self.last_factor.borrow_mut() = None;
        *self.carried.borrow_mut() = None;
        summary.end = PathEnd::DeadEnd;
    }

    /// Ends the path with `end`, or, with a window held back (`held`), drops the window and
    /// ends it at the dead end the window was taken from ([`Self::drop_held`]).
    fn end_path(&mut self, held: &mut Option<HeldBack>, summary: &mut PathSummary, end: PathEnd) {
        match held.take() {
            Some(h) => self.drop_held(h, summary),
            None => summary.end = end,
        }
    }

    /// Leaves the narrow window the path has passed at `freq_hz` (Hz): the range's scales
    /// again ([`Self::leave_narrow`]), a held-back window's calls handed over
    /// ([`Self::release_or_end`]) and the pass reported. True when handing them over ended the
    /// path.
    fn leave_window<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: &mut Option<HeldBack>,
        summary: &mut PathSummary,
        tangent: &mut [f64],
        freq_hz: f64,
    ) -> bool {
        let left = self.leave_narrow(tangent);
        if let Some(h) = held.take() {
            if self.release_or_end(system, observer, h, summary) {
                return true;
            }
        }
        if let Some(from_hz) = left {
            observer.narrow_pass(from_hz, freq_hz);
        }
        false
    }

    /// Hands a held-back window's observer calls over, in order, the operator evaluated at
    /// each point again before it is reported (as [`Observer::accepted`] expects). Returns
    /// true when such an evaluation fails: the path then ends at the last point reported, as
    /// at a dead end (the summary's end is set).
    fn release_or_end<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        observer: &mut O,
        held: HeldBack,
        summary: &mut PathSummary,
    ) -> bool {
        let n = system.dim();
        let mut r = vec![0.0; n];
        let mut dr = vec![0.0; n];
        let mut jac = system.new_jacobian();
        for event in held.events {
            match event {
                HeldEvent::Accepted(index, normal) => {
                    let Some(point) = summary.points.get(index) else {
                        continue;
                    };
                    if system
                        .residual_and_jacobian(&point.x, point.omega, &mut r, &mut jac, &mut dr)
                        .is_err()
                    {
                        summary.points.truncate(index);
                        // The leaps whose landing was dropped with it go too.
                        let kept = summary.leap_landings.iter().filter(|&&l| l < index).count();
                        summary.leaps.truncate(kept);
                        summary.leap_landings.truncate(kept);
                        summary.end = PathEnd::DeadEnd;
                        return true;
                    }
                    observer.accepted(system, point, Some(&normal));
                }
                HeldEvent::Call(call) => call.send(observer),
            }
        }
        false
    }

    /// Follows the path from `x_guess` at the start frequency to the end frequency.
    ///
    /// Where the path stalls (see the module docs), it is taken on from the last point before
    /// the stall over a narrow window around it ([`Self::enter_narrow`]) and, once a point lies
    /// outside that window, on over the range with the range's scales and steps, as one path;
    /// each such pass is reported to the observer ([`Observer::narrow_pass`]). A stall inside a
    /// narrow window ends the run as a stall. The scales the run ends with ([`Self::x_scale`])
    /// are the range's.
    pub fn run<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        x_guess: &[f64],
        observer: &mut O,
    ) -> Result<PathSummary, ContinuationError> {
        let outcome = self.run_path(system, x_guess, observer);
        let mut tangent = vec![0.0; self.x_scale.len() + 1];
        tangent[self.x_scale.len()] = 1.0;
        self.leave_narrow(&mut tangent);
        outcome
    }

    /// [`Self::run`] itself.
    fn run_path<S: ParametricResidual, O: Observer<S>>(
        &mut self,
        system: &mut S,
        x_guess: &[f64],
        observer: &mut O,
    ) -> Result<PathSummary, ContinuationError> {
        let a = self.settings;
        let mut narrow_passes = 0usize;
        // A narrow-window pass taken where the path had met a dead end (see below): its points
        // are held back from the observer until the path leaves the window, and dropped, the
        // path ending at that dead end, when one lands back on the path already followed or
        // the window fails.
        let mut held: Option<HeldBack> = None;
        let omega_start = a.freq_start_hz * OMEGA_SCALE;
        let omega_end = a.freq_end_hz * OMEGA_SCALE;
        let n = system.dim();
        let first = self
            .solve_fixed(system, x_guess, omega_start)
            .map_err(|reason| ContinuationError::Start {
                freq_hz: a.freq_start_hz,
                reason,
            })?;
        let mut tangent =
            self.tangent(system, &first, None)
                .map_err(|reason| ContinuationError::Start {
                    freq_hz: a.freq_start_hz,
                    reason,
                })?;
        // The tangent evaluated the operator at the first point, as the observer expects.
        observer.accepted(system, &first, Some(&self.path_normal(&tangent)));
        let mut summary = PathSummary {
            points: vec![first],
            turning_points: Vec::new(),
            rejected_steps: 0,
            leaps: Vec::new(),
            leap_landings: Vec::new(),
            end: PathEnd::MaxPoints,
        };
        let mut ds = a.initial_step.clamp(a.min_step, a.max_step);
        let mut previous_quality: Option<f64> = None;
        // The frequency furthest toward the end reached (times the direction), and the point
        // count when the path last entered ground it had not covered ([`VisitedGround`]).
        let dir = self.direction();
        let mut furthest = dir * a.freq_start_hz;
        let mut ground = VisitedGround::new(a.freq_start_hz, a.freq_end_hz);
        let mut progressed_at = 1usize;
        while summary.points.len() < a.max_points {
            if crate::numerics::interrupt::requested() {
                let last = summary.points.last().expect("at least the first point");
                return Err(ContinuationError::Interrupted {
                    freq_hz: last.freq_hz(),
                });
            }
            let last = summary.points.last().expect("at least the first point");
            if ground.enters_new(last.freq_hz(), &last.x) {
                progressed_at = summary.points.len();
            }
            if summary.points.len() - progressed_at > self.stagnation_points() {
                self.end_path(&mut held, &mut summary, PathEnd::NoProgress);
                return Ok(summary);
            }
            furthest = furthest.max(dir * last.freq_hz());
            let y: Vec<f64> = last
                .x
                .iter()
                .zip(&self.x_scale)
                .map(|(v, s)| v / s)
                .chain(std::iter::once(last.omega / OMEGA_SCALE))
                .collect();
            let predicted: Vec<f64> = (0..=n).map(|j| y[j] + ds * tangent[j]).collect();
            if self.past_end(&predicted) {
                // Land exactly on the end frequency from the linearly interpolated guess.
                let frac =
                    ((omega_end / OMEGA_SCALE - y[n]) / (predicted[n] - y[n])).clamp(0.0, 1.0);
                let guess: Vec<f64> = (0..n)
                    .map(|j| (y[j] + frac * (predicted[j] - y[j])) * self.x_scale[j])
                    .collect();
                match self.solve_fixed(system, &guess, omega_end) {
                    Ok(mut p) => {
                        if let Some(h) = held.take() {
                            if self.release_or_end(system, observer, h, &mut summary) {
                                return Ok(summary);
                            }
                        }
                        p.step = ds * frac;
                        observer.accepted(system, &p, None);
                        summary.points.push(p);
                        summary.end = PathEnd::EndFrequency;
                        return Ok(summary);
                    }
                    Err(reason) => {
                        let new_ds = ds * 0.5;
                        let call =
                            ObserverCall::Rejected(last.freq_hz(), ds, new_ds, reason.clone());
                        report(&mut held, observer, call);
                        summary.rejected_steps += 1;
                        if new_ds < a.min_step {
                            if let Some(h) = held.take() {
                                self.drop_held(h, &mut summary);
                                return Ok(summary);
                            }
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
                    let (point, t_new, far, degrees) =
                        self.corrected_point(system, &yc, it, rel, ds, &predicted, &tangent)?;
                    // Step quality: > 1 means the corrector went far or the path turned sharply.
                    let quality = far.max(degrees / MAX_TURN_DEGREES);
                    if quality > 1.0 && ds > 2.0 * a.min_step {
                        // A corner of the piecewise-smooth path (a contact changing state) turns
                        // the tangent by the same angle whatever the step; a branch jump does not.
                        let corner = previous_quality.is_some_and(|q| quality >= 0.7 * q);
                        if !corner {
                            previous_quality = Some(quality);
                            return Err(if far >= degrees / MAX_TURN_DEGREES {
                                NewtonFailure::FarCorrection {
                                    distance: far * ds,
                                    step: ds,
                                }
                            } else {
                                NewtonFailure::SharpTurn { degrees }
                            });
                        }
                    }
                    Ok((point, t_new, degrees))
                });
            match outcome {
                Ok((point, t_new, degrees)) => {
                    previous_quality = None;
                    let iterations = point.iterations;
                    if self.take_point(
                        system,
                        observer,
                        &mut held,
                        &mut summary,
                        point,
                        t_new,
                        &mut tangent,
                    ) {
                        return Ok(summary);
                    }
                    // The next step: shorter where Newton needed many iterations, and where
                    // the path bends (the tangent turned by more than TARGET_TURN_DEGREES over
                    // this step), so that peaks and anti-resonances get points on their flanks.
                    let by_iterations = a.target_iterations as f64 / iterations.max(1) as f64;
                    let by_turn = TARGET_TURN_DEGREES / degrees.max(1e-3);
                    let by_amplitude = match &summary.points[..] {
                        [.., before, after] => {
                            TARGET_LOG_AMPLITUDE_CHANGE
                                / self.log_amplitude_change(&before.x, &after.x).max(1e-6)
                        }
                        _ => f64::INFINITY,
                    };
                    let factor = by_iterations.min(by_turn).min(by_amplitude).clamp(0.5, 2.0);
                    ds = (ds * factor).clamp(a.min_step, a.max_step);
                    let freq_hz = summary.points.last().map_or(f64::NAN, |p| p.freq_hz());
                    if self.past_narrow_window(freq_hz) {
                        if self.leave_window(
                            system,
                            observer,
                            &mut held,
                            &mut summary,
                            &mut tangent,
                            freq_hz,
                        ) {
                            return Ok(summary);
                        }
                        ds = a.initial_step.clamp(a.min_step, a.max_step);
                    }
                }
                Err(reason) => {
                    let new_ds = ds * 0.5;
                    let call = ObserverCall::Rejected(last.freq_hz(), ds, new_ds, reason.clone());
                    report(&mut held, observer, call);
                    summary.rejected_steps += 1;
                    if new_ds < a.min_step {
                        // The path cannot be followed through this spot (Newton cycles between
                        // the pieces of the sampled, piecewise-smooth contact law): try to land
                        // on it further on, with a fully converged point, before giving up.
                        let from = last.freq_hz();
                        let followed = &summary.points;
                        let recent = &followed[followed.len().saturating_sub(RETRACE_HISTORY)..];
                        let mut refused_retrace = false;
                        let resumed = match self.corner(
                            system,
                            &y,
                            &tangent,
                            followed,
                            &mut refused_retrace,
                        )? {
                            Some(found) => Some(found),
                            None => {
                                let leapt = self.leap(
                                    system,
                                    &y,
                                    &tangent,
                                    followed,
                                    &mut refused_retrace,
                                )?;
                                if let Some((point, _)) = &leapt {
                                    let call = ObserverCall::Leap(from, point.freq_hz());
                                    report(&mut held, observer, call);
                                    summary.leaps.push((from, point.freq_hz()));
                                    summary.leap_landings.push(summary.points.len());
                                }
                                leapt
                            }
                        };
                        let Some((point, t_new)) = resumed else {
                            // The next window: the first for a new stall, the next width for
                            // one inside a window.
                            let next = match self.narrow {
                                None => (narrow_passes < MAX_NARROW_PASSES).then_some(0),
                                Some(pass) => Some(pass.attempt + 1)
                                    .filter(|&k| k < NARROW_WINDOW_FRACTIONS.len()),
                            };
                            // Where the only way on found was back along the path already
                            // followed (refused: the path would retrace itself and loop through
                            // the same corners until `stagnation_points` ended it), or behind
                            // the highest frequency reached (the path turned back at a fold),
                            // the spot is a dead end: the path ends for the caller to go on
                            // past the highest frequency reached, as it would after that loop.
                            // At the highest frequency reached, where the path came to the
                            // spot monotone in frequency over its last RETRACE_HISTORY points
                            // (a single transition met head-on), the narrow windows are tried
                            // first (on the 3D blade pair they pass such a spot at 886.685 Hz
                            // onto the middle branch), their points held back until the path
                            // leaves the window; a point of theirs that lands back on the path
                            // already followed, or a window that fails, drops them and ends
                            // the path at the dead end, as without the windows. Where the
                            // frequency turned back and forth among those points, the path is
                            // bouncing between corners of the sampled law (the loop the dead
                            // end is there to end) and ends there without windows (see
                            // `frequency_reversals`). Otherwise it is a stall.
                            let behind = dir * from < furthest - a.min_step;
                            let dead_end = refused_retrace || behind;
                            let bouncing = held.is_none() && frequency_reversals(recent) > 0;
                            if dead_end && (behind || next.is_none() || bouncing) {
                                self.end_path(&mut held, &mut summary, PathEnd::DeadEnd);
                                return Ok(summary);
                            }
                            if let Some(attempt) = next {
                                if attempt == 0 {
                                    narrow_passes += 1;
                                }
                                if dead_end && held.is_none() {
                                    held = Some(self.hold_back(&summary));
                                }
                                let stalled = self.leave_narrow(&mut tangent).unwrap_or(from);
                                self.enter_narrow(from, stalled, attempt, &mut tangent);
                                ds = a.initial_step.clamp(a.min_step, a.max_step);
                                previous_quality = None;
                                continue;
                            }
                            if let Some(h) = held.take() {
                                self.drop_held(h, &mut summary);
                                return Ok(summary);
                            }
                            return Err(ContinuationError::Stalled {
                                freq_hz: from,
                                step: ds,
                                reason,
                            });
                        };
                        previous_quality = None;
                        let freq_hz = point.freq_hz();
                        if self.take_point(
                            system,
                            observer,
                            &mut held,
                            &mut summary,
                            point,
                            t_new,
                            &mut tangent,
                        ) {
                            return Ok(summary);
                        }
                        if self.past_narrow_window(freq_hz)
                            && self.leave_window(
                                system,
                                observer,
                                &mut held,
                                &mut summary,
                                &mut tangent,
                                freq_hz,
                            )
                        {
                            return Ok(summary);
                        }
                        ds = a.initial_step.clamp(a.min_step, a.max_step);
                        continue;
                    }
                    ds = new_ds;
                }
            }
        }
        self.end_path(&mut held, &mut summary, PathEnd::MaxPoints);
        Ok(summary)
    }
}

/// How many times the frequency of consecutive `points` changes direction (steps that leave
/// the frequency unchanged are skipped): 0 on a stretch monotone in frequency.
///
/// Decides whether a dead end at the highest frequency reached gets the narrow windows (see
/// [`Continuation::run`]): only with no reversal among the last [`RETRACE_HISTORY`] points.
/// Why, measured (benches/README.md, "Narrow windows at dead ends"): the 3D blade pair's dead
/// end at 886.6853 Hz (840-900 Hz and 884-944 Hz) is met on a stretch rising monotonically from
/// 884 Hz (0 reversals), and a window passes it onto the middle branch of the bending pair's
/// resonance. The paper's system at F0 = 1 N meets its dead end at 151.8405 Hz after bouncing
/// between corners of the sampled law (6 reversals in the last 64 points, turning points every
/// 0.03-0.1 Hz over 147.7-151.8 Hz); a window there stepped over the turning points the run
/// finds at 152.1-153.1 Hz (151.84 → 152.42 → 153.88 Hz in two points), and the path beyond was
/// not the one the run follows with the jump past the dead end (it ended at a dead end at
/// 241.65 Hz that Newton cannot go past). The stall signature does not tell the two apart:
/// at both the corrector's residual after 12 iterations falls in proportion to the step over the
/// halvings (a kink), and the corner search ends on a point leading back onto the path.
fn frequency_reversals(points: &[PathPoint]) -> usize {
    let mut last_sign = 0.0;
    let mut count = 0;
    for pair in points.windows(2) {
        if pair[1].omega == pair[0].omega {
            continue;
        }
        let sign = (pair[1].omega - pair[0].omega).signum();
        if last_sign != 0.0 && sign != last_sign {
            count += 1;
        }
        last_sign = sign;
    }
    count
}

/// Euclidean distance from `q` to the polyline through `points` (to the point itself when
/// there is one; infinite when there is none).
fn distance_to_polyline(q: &[f64], points: &[Vec<f64>]) -> f64 {
    let distance_to_segment = |a: &[f64], b: &[f64]| {
        let ab: Vec<f64> = b.iter().zip(a).map(|(u, v)| u - v).collect();
        let aq: Vec<f64> = q.iter().zip(a).map(|(u, v)| u - v).collect();
        let length2 = dot(&ab, &ab);
        let s = if length2 > 0.0 {
            (dot(&aq, &ab) / length2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        aq.iter()
            .zip(&ab)
            .map(|(u, v)| (u - s * v) * (u - s * v))
            .sum::<f64>()
            .sqrt()
    };
    match points {
        [] => f64::INFINITY,
        [only] => distance_to_segment(only, only),
        _ => points
            .windows(2)
            .map(|w| distance_to_segment(&w[0], &w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

/// Norm of v scaled per entry: ‖(vᵢ / sᵢ)‖.
fn scaled_norm(v: &[f64], scale: &[f64]) -> f64 {
    v.iter()
        .zip(scale)
        .map(|(a, s)| (a / s) * (a / s))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::path::NoObserver;

    /// New ground is a frequency cell (a 4000th of the range) or a size cell (5 % in ‖x‖) no
    /// point entered before: a path running back down a stretch at a growing size (a middle
    /// branch toward a resonance below its fold) enters new cells; one going back and forth
    /// over a stretch it covered does not.
    #[test]
    fn new_ground_is_a_frequency_or_size_no_point_reached() {
        let mut ground = VisitedGround::new(100.0, 140.0);
        // Cells of 0.01 Hz; up the range at one size.
        for k in 0..10 {
            assert!(ground.enters_new(120.0 + 0.01 * f64::from(k) + 0.005, &[1.0]));
        }
        // Back down the same frequencies at the same size: covered ground.
        for k in (0..10).rev() {
            assert!(!ground.enters_new(120.0 + 0.01 * f64::from(k) + 0.002, &[1.0, 0.0]));
        }
        // Back down at a size 6 % larger each step: new ground at every point.
        for k in (0..10).rev() {
            let size = 1.06_f64.powi(10 - k);
            assert!(ground.enters_new(120.0 + 0.01 * f64::from(k) + 0.005, &[0.0, size]));
        }
        // 1 % larger than a size entered at that frequency, in the same size cell: covered.
        assert!(!ground.enters_new(120.005, &[1.06_f64.powi(10) * 1.01]));
        // A point without a finite size has a cell of its own.
        assert!(ground.enters_new(120.005, &[f64::NAN]));
        assert!(!ground.enters_new(120.005, &[f64::NAN]));
    }

    /// R(x, ω) = ω/2π − g(x): a path whose frequency is the piecewise-linear g of the single
    /// unknown x. g rises to 15 Hz at x = 1, falls steeply to 13 Hz at x = 1.2 and rises on:
    /// a Z with two folds that are sharp corners (the tangent turns by about 163°), as a
    /// contact sample opening or closing makes them in the sampled contact law.
    struct ZPath;

    fn g(x: f64) -> (f64, f64) {
        if x < 1.0 {
            (10.0 + 5.0 * x, 5.0)
        } else if x < 1.2 {
            (15.0 - 10.0 * (x - 1.0), -10.0)
        } else {
            (13.0 + 5.0 * (x - 1.2), 5.0)
        }
    }

    #[derive(Debug, Clone, thiserror::Error)]
    #[error("never")]
    struct Never;

    impl ParametricResidual for ZPath {
        type Error = Never;
        fn dim(&self) -> usize {
            1
        }
        fn residual_scale(&self) -> f64 {
            1.0
        }
        fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
            r[0] = omega / OMEGA_SCALE - g(x[0]).0;
            Ok(())
        }
        fn new_jacobian(&mut self) -> AssembledJacobian {
            AssembledJacobian::dense(1)
        }
        fn residual_and_jacobian(
            &mut self,
            x: &[f64],
            omega: f64,
            r: &mut [f64],
            jac: &mut AssembledJacobian,
            dr: &mut [f64],
        ) -> Result<(), Never> {
            self.residual(x, omega, r)?;
            jac.clear();
            let slot = jac.slot(0, 0);
            jac.add_at(slot, -g(x[0]).1);
            dr[0] = 1.0 / OMEGA_SCALE;
            Ok(())
        }
    }

    fn settings(start: f64, end: f64) -> ContinuationSettings {
        ContinuationSettings {
            freq_start_hz: start,
            freq_end_hz: end,
            initial_step: 0.05,
            min_step: 1e-4,
            max_step: 0.2,
            max_points: 2000,
            target_iterations: 4,
            max_iterations: 12,
            residual_tolerance: 1e-12,
            step_tolerance: 1e-10,
            chord_min_unknowns: usize::MAX,
        }
    }

    /// A solve that does not converge because the residual has no root nearby (on the Z at
    /// 16 Hz from x = 1.1 Newton creeps toward the fold at x = 1, where |R| has a kink minimum
    /// of 1): without the exit it spends the fixed-frequency limit (three times
    /// `max_iterations`); with it, it is given up once past the iterations it always gets,
    /// when its residual has not fallen by a tenth over the window. A solve that converges is
    /// not touched by the exit.
    #[test]
    fn a_stagnating_solve_is_given_up_after_its_guaranteed_iterations() {
        let omega = 16.0 * OMEGA_SCALE;
        let plain = Continuation::new(settings(10.0, 20.0), vec![1.0]);
        match plain.solve_fixed(&mut ZPath, &[1.1], omega) {
            Err(NewtonFailure::MaxIterations {
                iterations,
                residual,
            }) => {
                assert_eq!(iterations, 36);
                assert!(residual > 0.99 && residual < 1.2, "{residual}");
            }
            other => panic!("expected the iteration limit, got {other:?}"),
        }
        let exit = StagnationExit { after: 12 };
        let stopping =
            Continuation::new(settings(10.0, 20.0), vec![1.0]).with_stagnation_exit(exit);
        match stopping.solve_fixed(&mut ZPath, &[1.1], omega) {
            Err(NewtonFailure::MaxIterations { iterations, .. }) => {
                assert_eq!(
                    iterations, 13,
                    "given up at the first iteration past the 12th"
                );
            }
            other => panic!("expected the stagnation exit, got {other:?}"),
        }
        // With chord steps (three to an iteration) the guaranteed iterations count three steps
        // each, as the limit does.
        let mut chord_settings = settings(10.0, 20.0);
        chord_settings.chord_min_unknowns = 1;
        let chord = Continuation::new(chord_settings, vec![1.0]);
        let chord_stopping =
            Continuation::new(chord_settings, vec![1.0]).with_stagnation_exit(exit);
        match (
            chord.solve_fixed(&mut ZPath, &[1.1], omega),
            chord_stopping.solve_fixed(&mut ZPath, &[1.1], omega),
        ) {
            (
                Err(NewtonFailure::MaxIterations {
                    iterations: all, ..
                }),
                Err(NewtonFailure::MaxIterations {
                    iterations: given_up,
                    ..
                }),
            ) => {
                assert_eq!(all, 108);
                assert_eq!(given_up, 37, "given up at the first step past the 36th");
            }
            other => panic!("expected both to fail, got {other:?}"),
        }
        // A converging solve on the third piece (g = 16 at x = 1.8) is the same either way.
        let a = plain
            .solve_fixed(&mut ZPath, &[1.5], omega)
            .expect("converges");
        let b = stopping
            .solve_fixed(&mut ZPath, &[1.5], omega)
            .expect("converges");
        assert_eq!(a, b);
        assert!((a.x[0] - 1.8).abs() < 1e-12);
        // The rule itself: a fall to 0.9 of the value 8 iterations before is progress.
        let exit = StagnationExit { after: 0 };
        let falling: Vec<f64> = (0..9).map(|k| 0.986_f64.powi(k)).collect();
        assert!(!exit.stagnated(&falling), "0.986⁸ = 0.893, below 0.9");
        let slower: Vec<f64> = (0..9).map(|k| 0.987_f64.powi(k)).collect();
        assert!(exit.stagnated(&slower), "0.987⁸ = 0.901, above 0.9");
        let flat = vec![0.2; 9];
        assert!(exit.stagnated(&flat));
        assert!(!exit.stagnated(&flat[..8]), "the window is not full yet");
        assert!(!StagnationExit { after: 9 }.stagnated(&flat));
    }

    /// Both sharp folds of the Z are turned: the path reaches the end, passing through the
    /// steep middle piece, with a turning point at each fold, every point on the path.
    #[test]
    fn sharp_corner_folds_are_turned() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![1.0]);
        let summary = c.run(&mut ZPath, &[0.0], &mut NoObserver).unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(
            summary.turning_points.len(),
            2,
            "{:?}",
            summary.turning_points
        );
        assert!(summary
            .points
            .iter()
            .any(|p| p.x[0] > 1.01 && p.x[0] < 1.19));
        for p in &summary.points {
            assert!((p.freq_hz() - g(p.x[0]).0).abs() < 1e-9);
        }
        let last = summary.points.last().unwrap();
        assert_eq!(last.freq_hz(), 18.0);
        assert!((last.x[0] - 2.2).abs() < 1e-9);
    }

    /// With the end below the start the path runs down in frequency, through the same folds,
    /// and ends exactly at the end frequency.
    #[test]
    fn a_path_runs_down_when_the_end_is_below_the_start() {
        let mut c = Continuation::new(settings(18.0, 10.0), vec![1.0]);
        let summary = c.run(&mut ZPath, &[2.2], &mut NoObserver).unwrap();
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert_eq!(summary.turning_points.len(), 2);
        let last = summary.points.last().unwrap();
        assert_eq!(last.freq_hz(), 10.0);
        assert!(last.x[0].abs() < 1e-9);
    }

    /// A path that ends at a contact transition it cannot pass (a dead end of the sampled
    /// contact law's piecewise-smooth residual): two unknowns, R₁ = ω/2π − 10 − 5x₁ and, up to
    /// x₁ = 1 (15 Hz), R₂ = x₂ − 5(x₁ − 1)² (the incoming branch, curved in x₂), beyond it
    /// R₂ = 1 + |x₂|, which has no zero. Past the end the Jacobian's null direction is the
    /// incoming tangent, so the corner search's points behind the corner lie on the incoming
    /// branch, where its curvature turns the tangent by more than the same-piece test allows
    /// at the largest corner step.
    struct DeadEnd;

    impl DeadEnd {
        fn second(x: &[f64]) -> (f64, f64, f64) {
            if x[0] <= 1.0 {
                let d = x[0] - 1.0;
                (x[1] - 5.0 * d * d, -10.0 * d, 1.0)
            } else {
                (1.0 + x[1].abs(), 0.0, if x[1] < 0.0 { -1.0 } else { 1.0 })
            }
        }
    }

    impl ParametricResidual for DeadEnd {
        type Error = Never;
        fn dim(&self) -> usize {
            2
        }
        fn residual_scale(&self) -> f64 {
            1.0
        }
        fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
            r[0] = omega / OMEGA_SCALE - 10.0 - 5.0 * x[0];
            r[1] = Self::second(x).0;
            Ok(())
        }
        fn new_jacobian(&mut self) -> AssembledJacobian {
            AssembledJacobian::dense(2)
        }
        fn residual_and_jacobian(
            &mut self,
            x: &[f64],
            omega: f64,
            r: &mut [f64],
            jac: &mut AssembledJacobian,
            dr: &mut [f64],
        ) -> Result<(), Never> {
            self.residual(x, omega, r)?;
            let (_, d1, d2) = Self::second(x);
            jac.clear();
            let slot = jac.slot(0, 0);
            jac.add_at(slot, -5.0);
            let slot = jac.slot(1, 0);
            jac.add_at(slot, d1);
            let slot = jac.slot(1, 1);
            jac.add_at(slot, d2);
            dr[0] = 1.0 / OMEGA_SCALE;
            dr[1] = 0.0;
            Ok(())
        }
    }

    /// At the dead end the corrector fails at every step; the corner search must not resume on
    /// the incoming branch backwards (it used to: a point 0.1 back on it, whose tangent differs
    /// from the incoming one by 2°, was taken and the path ran back down below its start). With
    /// nothing ahead but the way back (refused), the path ends there as [`PathEnd::DeadEnd`]
    /// (for the FRF to go on past it), every point on the incoming branch in rising frequency.
    #[test]
    fn a_corner_never_resumes_on_the_incoming_branch_backwards() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(12.0, 20.0), vec![1.0, 1.0]);
        let outcome = c.run(&mut DeadEnd, &[0.4, 1.8], &mut Collect(&mut points));
        let freqs: Vec<f64> = points.iter().map(|p| p.freq_hz()).collect();
        assert!(
            freqs.windows(2).all(|w| w[1] > w[0]),
            "the path turned back: {:?}",
            &freqs[freqs.len().saturating_sub(8)..]
        );
        match outcome {
            Ok(summary) => {
                assert_eq!(summary.end, PathEnd::DeadEnd);
                let last = freqs.last().unwrap();
                assert!((last - 15.0).abs() < 1e-3, "ended at {last} Hz");
            }
            other => panic!("expected the path to end at the dead end, got {other:?}"),
        }
        for p in &points {
            assert!(p.x[0] <= 1.0 && (p.freq_hz() - 10.0 - 5.0 * p.x[0]).abs() < 1e-9);
        }
    }

    /// Collects the accepted points of a run.
    struct Collect<'a>(&'a mut Vec<PathPoint>);

    impl<S: ParametricResidual> Observer<S> for Collect<'_> {
        fn accepted(&mut self, _: &mut S, p: &PathPoint, _: Option<&[f64]>) {
            self.0.push(p.clone());
        }
    }

    /// The dead end of [`DeadEnd`] met behind a fold, as the 1D paths of the sampled contact
    /// law meet theirs (`tests/hard_cases.rs` at F₀ = 1 N, 18.78 Hz, and
    /// `tests/data/liftoff-fold.toml`, 32.52 Hz, both below a fold they turned back at): the
    /// frequency 15 − 5(x₁ − 1)² rises to a smooth fold at 15 Hz (x₁ = 1) and falls to 10 Hz at
    /// x₁ = 2, where the path ends (R₂ = x₂ − 5(x₁ − 2)² up to x₁ = 2, 1 + |x₂| beyond, which
    /// has no zero).
    struct FoldThenDeadEnd;

    impl FoldThenDeadEnd {
        fn second(x: &[f64]) -> (f64, f64, f64) {
            if x[0] <= 2.0 {
                let d = x[0] - 2.0;
                (x[1] - 5.0 * d * d, -10.0 * d, 1.0)
            } else {
                (1.0 + x[1].abs(), 0.0, if x[1] < 0.0 { -1.0 } else { 1.0 })
            }
        }

        fn freq_hz(x: &[f64]) -> f64 {
            15.0 - 5.0 * (x[0] - 1.0) * (x[0] - 1.0)
        }
    }

    impl ParametricResidual for FoldThenDeadEnd {
        type Error = Never;
        fn dim(&self) -> usize {
            2
        }
        fn residual_scale(&self) -> f64 {
            1.0
        }
        fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
            r[0] = omega / OMEGA_SCALE - Self::freq_hz(x);
            r[1] = Self::second(x).0;
            Ok(())
        }
        fn new_jacobian(&mut self) -> AssembledJacobian {
            AssembledJacobian::dense(2)
        }
        fn residual_and_jacobian(
            &mut self,
            x: &[f64],
            omega: f64,
            r: &mut [f64],
            jac: &mut AssembledJacobian,
            dr: &mut [f64],
        ) -> Result<(), Never> {
            self.residual(x, omega, r)?;
            let (_, d1, d2) = Self::second(x);
            jac.clear();
            let slot = jac.slot(0, 0);
            jac.add_at(slot, 10.0 * (x[0] - 1.0));
            let slot = jac.slot(1, 0);
            jac.add_at(slot, d1);
            let slot = jac.slot(1, 1);
            jac.add_at(slot, d2);
            dr[0] = 1.0 / OMEGA_SCALE;
            dr[1] = 0.0;
            Ok(())
        }
    }

    /// The reversals that keep the narrow windows from a dead end: none on a monotone stretch
    /// (steps at an unchanged frequency, e.g. a creep toward a kink, skipped), one per change
    /// of direction on a stretch bouncing between corners.
    #[test]
    fn frequency_reversals_count_the_changes_of_direction() {
        let at = |hz: &[f64]| -> Vec<PathPoint> {
            hz.iter()
                .map(|&f| PathPoint {
                    omega: f * OMEGA_SCALE,
                    x: vec![0.0],
                    iterations: 1,
                    residual: 0.0,
                    step: 0.0,
                })
                .collect()
        };
        assert_eq!(frequency_reversals(&at(&[])), 0);
        assert_eq!(frequency_reversals(&at(&[1.0, 2.0, 2.0, 2.0, 3.0])), 0);
        assert_eq!(frequency_reversals(&at(&[3.0, 2.0, 1.0])), 0);
        assert_eq!(frequency_reversals(&at(&[1.0, 2.0, 2.0, 1.5, 1.7, 1.6])), 3);
    }

    /// Behind the highest frequency reached, a dead end past which only the path already
    /// followed lies ends the path as [`PathEnd::DeadEnd`] (for the FRF to go on past the
    /// fold), not as a stall: the path rises to the fold, turns once and runs down to the dead
    /// end at 10 Hz, never back up along itself, every point on the path.
    #[test]
    fn a_dead_end_behind_a_fold_ends_the_path_for_the_caller_to_jump() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(14.0, 30.0), vec![1.0, 1.0]);
        let summary = c
            .run(
                &mut FoldThenDeadEnd,
                &[0.55, 10.5],
                &mut Collect(&mut points),
            )
            .expect("the dead end behind the fold is not a stall");
        assert_eq!(summary.end, PathEnd::DeadEnd);
        assert_eq!(
            summary.turning_points.len(),
            1,
            "{:?}",
            summary.turning_points
        );
        assert!((summary.turning_points[0] - 15.0).abs() < 0.01);
        let freqs: Vec<f64> = points.iter().map(|p| p.freq_hz()).collect();
        let top = freqs
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(k, _)| k)
            .unwrap();
        assert!(freqs[..=top].windows(2).all(|w| w[1] > w[0]));
        assert!(
            freqs[top..].windows(2).all(|w| w[1] < w[0]),
            "the path turned back up: {:?}",
            &freqs[freqs.len().saturating_sub(8)..]
        );
        let last = points.last().unwrap();
        assert!(
            (last.freq_hz() - 10.0).abs() < 1e-3,
            "ended at {} Hz",
            last.freq_hz()
        );
        for p in &points {
            let mut r = [0.0; 2];
            FoldThenDeadEnd.residual(&p.x, p.omega, &mut r).unwrap();
            assert!(
                p.x[0] <= 2.0 && r[0].abs() < 1e-9 && r[1].abs() < 1e-9,
                "{p:?}"
            );
        }
    }

    /// A corner in the response coefficients whose outgoing piece leaves behind the incoming
    /// direction while the frequency keeps rising (as at the 3D blade pair's contact transitions
    /// at 882-885 Hz): y = (x₁, x₂, ω/2π) runs along piece A, c + s·(1, 0, 0.1) for s ≤ 0, then
    /// along piece B, c + s·(−0.5, 1, 0.1) for s > 0, with c = (1, 0, 10.1) (their chords make a
    /// cosine of −0.35). R = L±·(y − c), piecewise linear and continuous across the plane
    /// x₁ + x₂ = 1: L⁻ has null vector A's direction, L⁺ = L⁻ + a·(1, 1, 0)ᵀ that of B.
    struct CoefficientCorner;

    impl CoefficientCorner {
        const CORNER: [f64; 3] = [1.0, 0.0, 10.1];

        fn operator(x: &[f64]) -> [[f64; 3]; 2] {
            if x[0] + x[1] <= 1.0 {
                [[-0.1, 0.0, 1.0], [0.0, 1.0, 0.0]]
            } else {
                [[-0.4, -0.3, 1.0], [-2.0, -1.0, 0.0]]
            }
        }
    }

    impl ParametricResidual for CoefficientCorner {
        type Error = Never;
        fn dim(&self) -> usize {
            2
        }
        fn residual_scale(&self) -> f64 {
            1.0
        }
        fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
            let y = [x[0], x[1], omega / OMEGA_SCALE];
            for (ri, row) in r.iter_mut().zip(Self::operator(x)) {
                *ri = (0..3).map(|j| row[j] * (y[j] - Self::CORNER[j])).sum();
            }
            Ok(())
        }
        fn new_jacobian(&mut self) -> AssembledJacobian {
            AssembledJacobian::dense(2)
        }
        fn residual_and_jacobian(
            &mut self,
            x: &[f64],
            omega: f64,
            r: &mut [f64],
            jac: &mut AssembledJacobian,
            dr: &mut [f64],
        ) -> Result<(), Never> {
            self.residual(x, omega, r)?;
            jac.clear();
            for (i, row) in Self::operator(x).iter().enumerate() {
                for (j, value) in row[..2].iter().enumerate() {
                    let slot = jac.slot(i, j);
                    jac.add_at(slot, *value);
                }
                dr[i] = row[2] / OMEGA_SCALE;
            }
            Ok(())
        }
    }

    /// The corner search keeps a genuine outgoing piece found behind the incoming direction:
    /// the path turns from A onto B (no leap, no turning point), runs up to the end frequency
    /// with every point on A or B, and never back along A.
    #[test]
    fn a_corner_keeps_an_outgoing_piece_behind_the_incoming_direction() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(10.0, 11.0), vec![1.0, 1.0]);
        let summary = c
            .run(
                &mut CoefficientCorner,
                &[0.0, 0.0],
                &mut Collect(&mut points),
            )
            .expect("the corner is turned");
        assert_eq!(summary.end, PathEnd::EndFrequency);
        assert!(
            summary.turning_points.is_empty(),
            "{:?}",
            summary.turning_points
        );
        assert!(summary.leaps.is_empty(), "{:?}", summary.leaps);
        let freqs: Vec<f64> = points.iter().map(|p| p.freq_hz()).collect();
        assert!(freqs.windows(2).all(|w| w[1] > w[0]), "{freqs:?}");
        for p in &points {
            let f = p.freq_hz();
            let on_a = p.x[0] <= 1.0 + 1e-9
                && p.x[1].abs() < 1e-9
                && (f - 10.0 - 0.1 * p.x[0]).abs() < 1e-9;
            let s = p.x[1];
            let on_b = s > 0.0
                && (p.x[0] - 1.0 + 0.5 * s).abs() < 1e-9
                && (f - 10.1 - 0.1 * s).abs() < 1e-9;
            assert!(on_a || on_b, "off the path: {p:?}");
        }
        let last = points.last().unwrap();
        assert!((last.freq_hz() - 11.0).abs() < 1e-12);
        assert!((last.x[0] + 3.5).abs() < 1e-9 && (last.x[1] - 9.0).abs() < 1e-9);
    }

    /// A sharp fold at a corner whose outgoing side runs back within 1.6° of the incoming one
    /// (as the 3D blade pair's fold at 874.57 Hz, whose sides lie 2.3 % apart 0.02 Hz from
    /// it): y = (x₁, x₂, ω/2π) comes up along A, c + σ·a with a = (−1, −ε, −1) and σ ≥ 0, and
    /// leaves along B, c + σ·b with b = (−1, ε, −1), c = (1, 0, 10.5), ε = 0.02. R = L±·(y − c)
    /// is piecewise linear and continuous across the plane x₂ = 0 (L⁻ has null vector a, L⁺ =
    /// L⁻ − 2·e₂·(0, 1, 0)ᵀ has b), so below 10.5 Hz both sides are solutions, 2εσ apart in x₂,
    /// and above it none.
    struct Hairpin;

    impl Hairpin {
        const CORNER: [f64; 3] = [1.0, 0.0, 10.5];
        const EPS: f64 = 0.02;

        fn operator(x: &[f64]) -> [[f64; 3]; 2] {
            if x[1] <= 0.0 {
                [[1.0, 0.0, -1.0], [0.0, 1.0, -Self::EPS]]
            } else {
                [[1.0, 0.0, -1.0], [0.0, -1.0, -Self::EPS]]
            }
        }
    }

    impl ParametricResidual for Hairpin {
        type Error = Never;
        fn dim(&self) -> usize {
            2
        }
        fn residual_scale(&self) -> f64 {
            1.0
        }
        fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), Never> {
            let y = [x[0], x[1], omega / OMEGA_SCALE];
            for (ri, row) in r.iter_mut().zip(Self::operator(x)) {
                *ri = (0..3).map(|j| row[j] * (y[j] - Self::CORNER[j])).sum();
            }
            Ok(())
        }
        fn new_jacobian(&mut self) -> AssembledJacobian {
            AssembledJacobian::dense(2)
        }
        fn residual_and_jacobian(
            &mut self,
            x: &[f64],
            omega: f64,
            r: &mut [f64],
            jac: &mut AssembledJacobian,
            dr: &mut [f64],
        ) -> Result<(), Never> {
            self.residual(x, omega, r)?;
            jac.clear();
            for (i, row) in Self::operator(x).iter().enumerate() {
                for (j, value) in row[..2].iter().enumerate() {
                    let slot = jac.slot(i, j);
                    jac.add_at(slot, *value);
                }
                dr[i] = row[2] / OMEGA_SCALE;
            }
            Ok(())
        }
    }

    /// The outgoing side of a sharp fold that hugs the incoming side closer than the look-ahead's
    /// polyline test resolves (1.4 % of its reach against [`RETRACE_FRACTION`]) is told from
    /// the path already followed by Newton at the look-ahead's frequency, which lands on the
    /// incoming side 2εσ away: the path turns the fold (one turning point, at 10.5 Hz) and
    /// runs down along B until it leaves the range below the start, every point on A or B;
    /// before, the corner was refused as a retrace and the path ended at a dead end there.
    #[test]
    fn a_sharp_fold_whose_sides_nearly_touch_is_turned() {
        let mut points = Vec::new();
        let mut c = Continuation::new(settings(10.0, 11.0), vec![1.0, 1.0]);
        let summary = c
            .run(&mut Hairpin, &[0.5, -0.01], &mut Collect(&mut points))
            .expect("the fold is turned");
        assert_eq!(summary.end, PathEnd::LeftRangeBelow, "{summary:?}");
        assert_eq!(
            summary.turning_points.len(),
            1,
            "{:?}",
            summary.turning_points
        );
        assert!((summary.turning_points[0] - 10.5).abs() < 1e-3);
        assert!(summary.leaps.is_empty(), "{:?}", summary.leaps);
        let fold = points
            .iter()
            .position(|p| p.x[1] > 0.0)
            .expect("a point on the outgoing side");
        for (k, p) in points.iter().enumerate() {
            let sigma = 10.5 - p.freq_hz();
            let side = if k < fold { -1.0 } else { 1.0 };
            assert!(
                sigma >= -1e-9
                    && (p.x[0] - 1.0 + sigma).abs() < 1e-9
                    && (p.x[1] - side * Hairpin::EPS * sigma).abs() < 1e-9,
                "point {k} off its side: {p:?}"
            );
        }
        assert!(points.last().unwrap().freq_hz() < 9.5);
    }

    /// The path already followed is the whole path, not its last [`RETRACE_HISTORY`] points: a
    /// point back on a stretch followed long before (side A, 150 points back) is on it, and a
    /// point of the other side of the fold beyond the stretch of it followed, 2εσ from A, is
    /// not, though the polyline through A passes within 4 % of its reach.
    #[test]
    fn the_followed_path_reaches_back_to_its_first_point() {
        let c = Continuation::new(settings(10.0, 11.0), vec![1.0, 1.0]);
        let on = |side: f64, f: f64| {
            let sigma = 10.5 - f;
            PathPoint {
                omega: f * OMEGA_SCALE,
                x: vec![1.0 - sigma, side * Hairpin::EPS * sigma],
                iterations: 1,
                residual: 0.0,
                step: 0.0,
            }
        };
        // Up side A from 10.0 to 10.5 Hz, then down side B to 10.35 Hz.
        let mut followed: Vec<PathPoint> = (0..=150)
            .map(|k| on(-1.0, 10.0 + k as f64 / 300.0))
            .collect();
        followed.extend((1..=50).map(|k| on(1.0, 10.5 - 0.003 * k as f64)));
        let scaled = |p: &PathPoint| c.scaled_points(std::slice::from_ref(p)).pop().unwrap();
        let last = scaled(followed.last().unwrap());
        let reach = |q: &[f64]| norm(&q.iter().zip(&last).map(|(a, b)| a - b).collect::<Vec<_>>());
        let back_on_a = scaled(&on(-1.0, 10.2));
        assert!(c.on_followed_path(&mut Hairpin, &back_on_a, reach(&back_on_a), &followed));
        let below_on_b = scaled(&on(1.0, 10.0));
        assert!(!c.on_followed_path(&mut Hairpin, &below_on_b, reach(&below_on_b), &followed));
        // Only the last RETRACE_HISTORY points, as before: A is out of sight there.
        let recent = &followed[followed.len() - RETRACE_HISTORY..];
        assert!(!c.on_followed_path(&mut Hairpin, &back_on_a, reach(&back_on_a), recent));
    }

    /// The scale of a group grows with its norm along the path and the tangent is carried over
    /// to the new scaled space as the same direction.
    #[test]
    fn adaptive_scale_grows_and_keeps_the_tangent_direction() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![1.0, 1.0]).with_adaptive_scale(
            AdaptiveScale {
                group_of: vec![0, 1],
                climb: 1.0,
            },
        );
        let mut t = vec![0.6, 0.0, 0.8];
        let raw = |c: &Continuation, t: &[f64]| (t[0] * c.x_scale[0], t[2]);
        let before = raw(&c, &t);
        c.adapt_scale(&[10.0, 1.5], &mut t);
        assert_eq!(c.x_scale, vec![10.0, 1.0]);
        let after = raw(&c, &t);
        assert!((before.0 / before.1 - after.0 / after.1).abs() < 1e-12);
        assert!((norm(&t) - 1.0).abs() < 1e-12);
    }

    /// A narrow-window pass makes the scales and the adaptive climb those of a range a
    /// hundredth as wide, keeps the tangent's direction and the step bounds, spans half that
    /// width on each side of the stall, and its end restores the range's scales.
    #[test]
    fn a_narrow_pass_scales_the_arc_length_to_its_window_and_restores_it() {
        let mut c = Continuation::new(settings(10.0, 18.0), vec![2.0, 0.5]).with_adaptive_scale(
            AdaptiveScale {
                group_of: vec![0, 1],
                climb: 2.0,
            },
        );
        let range = c.settings;
        let mut t = vec![0.6, 0.0, 0.8];
        let raw = |c: &Continuation, t: &[f64]| (t[0] * c.x_scale[0], t[2]);
        let before = raw(&c, &t);
        c.enter_narrow(12.0, 12.0, 0, &mut t);
        let f = NARROW_WINDOW_FRACTIONS[0];
        assert_eq!(c.x_scale, vec![2.0 * f, 0.5 * f]);
        assert_eq!(c.adaptive.as_ref().unwrap().climb, 2.0 * f);
        assert_eq!(c.settings, range);
        let inside = raw(&c, &t);
        assert!((before.0 / before.1 - inside.0 / inside.1).abs() < 1e-12);
        assert!((norm(&t) - 1.0).abs() < 1e-12);
        // The window: 0.08 Hz wide (a hundredth of 8 Hz) around 12 Hz.
        assert!(!c.past_narrow_window(12.039) && !c.past_narrow_window(11.961));
        assert!(c.past_narrow_window(12.041) && c.past_narrow_window(11.959));
        assert_eq!(c.leave_narrow(&mut t), Some(12.0));
        assert_eq!(c.settings, range);
        for (s, s0) in c.x_scale.iter().zip([2.0, 0.5]) {
            assert!((s / s0 - 1.0).abs() < 1e-14, "{s}");
        }
        assert!((c.adaptive.as_ref().unwrap().climb / 2.0 - 1.0).abs() < 1e-14);
        let after = raw(&c, &t);
        assert!((before.0 / before.1 - after.0 / after.1).abs() < 1e-12);
        assert!(!c.past_narrow_window(100.0));
        assert_eq!(c.leave_narrow(&mut t), None);
    }
}
