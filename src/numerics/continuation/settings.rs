//! What a continuation is set up with: the settings of a range and of Newton, the scales of
//! the arc length, and the rules a caller may add (amplitude steps, adaptive scale, stagnation).

use std::f64::consts::PI;

use crate::numerics::jacobian::BorderedFactor;

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
    pub(super) last_factor: std::cell::RefCell<Option<(Vec<f64>, BorderedFactor)>>,
    /// Chord corrector only: the last factorisation made, and the points since it was made,
    /// for the next corrector to start from (storages whose border is eliminated by blocks).
    pub(super) carried: std::cell::RefCell<Option<(BorderedFactor, usize)>>,
    /// How the scale follows the response along the path, if it does.
    pub(super) adaptive: Option<AdaptiveScale>,
    /// Groups of unknowns whose norm (an output's amplitude) the step length watches.
    pub(super) amplitudes: Vec<Vec<usize>>,
    /// Newton gives up once its residual stagnates, if set (see
    /// [`Continuation::with_stagnation_exit`]).
    pub(super) stagnation: Option<StagnationExit>,
    /// The path's orientation: the sign of det [J; tᵀ] (scaled unknowns, ω last) at its last
    /// accepted point, where the factorisation gives it (see [`Continuation::tangent`]).
    pub(super) orientation: Option<f64>,
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
///
/// Still needed with the event-resolved laws: without it the error estimate's solves of the
/// paper's 2nd nonlinear mode that it gives up go on and converge, some on another of the
/// extended system's solutions, and the largest estimates at H = 3 exceed those at H = 1
/// (0.055 against 0.019 and 2.14 against 1.26;
/// `nonlinear_modes::checks::error_estimate_sizes_the_change_at_higher_harmonics`).
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

/// Groups of unknowns whose arc-length scale grows with the response along the path.
///
/// A scale fixed from a first estimate of the response (e.g. the stuck linear one) becomes far
/// too small where the nonlinear response is much larger (a damper bouncing at a low
/// pre-load): the arc length is then spent on the change of x and the path crawls in
/// frequency, thousands of steps for a few hertz. With groups, after each accepted point the
/// scale of group g becomes ‖x_g‖ / `climb` wherever that is more than twice the current one
/// (scales only grow, so the path's resolution where the response is small is kept).
///
/// Still needed with the event-resolved laws: without it the paper's system at a pre-load of
/// 1 N (`hard_cases::low_preloads_cover_the_range`) uses up its 5000 points by 16.85 Hz, and
/// the 3D paper system under an out-of-plane load
/// (`friction_2d::formulations_agree_and_jacobians_match_central_differences_with_out_of_plane_motion`)
/// stalls at 160.0984 Hz.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveScale {
    /// The group of each unknown (0-based).
    pub group_of: Vec<usize>,
    /// Arc length (Hz-equivalent) over which the response climbs from zero to its norm.
    pub climb: f64,
}

pub(super) const OMEGA_SCALE: f64 = 2.0 * PI;

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
            stagnation: None,
            orientation: None,
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

    /// This driver with steps that also follow the amplitudes ‖x_g‖ of these groups of unknowns
    /// (e.g. the first-harmonic cosine and sine of each output DOF): a step over which one changed
    /// by more than [`TARGET_LOG_AMPLITUDE_CHANGE`](super::predictor::TARGET_LOG_AMPLITUDE_CHANGE)
    /// in ln is followed by a shorter one. Near an anti-resonance an output's coefficients are
    /// small and add almost nothing to the arc length, so without this the path crosses the dip in
    /// full steps and the plotted curve cuts through it.
    pub fn with_amplitude_steps(mut self, groups: Vec<Vec<usize>>) -> Self {
        self.amplitudes = groups;
        self
    }

    /// This driver with scales that grow with the response along the path (see
    /// [`AdaptiveScale`]).
    pub fn with_adaptive_scale(mut self, adaptive: AdaptiveScale) -> Self {
        self.adaptive = Some(adaptive);
        self
    }
}
