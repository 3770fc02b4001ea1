//! What an error estimate says of a point: the estimate per output and how it was formed, and
//! where on the path the point lies (for the estimate across the path).

/// The error estimate of one converged point, per output DOF (relative to its first-harmonic
/// amplitude; NaN where the estimate could not be formed).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PointAccuracy {
    /// Harmonic-truncation estimate per output DOF (relative).
    pub truncation: Vec<f64>,
    /// AFT-sampling estimate per output DOF (relative).
    pub sampling: Vec<f64>,
    /// True when the reported estimates are the steps across the path (bordered with the
    /// path's normal), false when at a fixed frequency (see the module docs and
    /// [`PathSwitch`]).
    pub across_path: bool,
    /// The hyperplane the across-path steps stay in (on a path point): the covector on the
    /// point's full coefficients (harmonic-major, as `FrfPoint::coefficients`) followed by
    /// the one on ω (rad/s); zero on coefficients the run's formulation eliminates. A
    /// reference path crossing this hyperplane gives the true error at the same place along
    /// the path (`crate::analysis::frf::amplitude_across_path`).
    #[serde(skip)]
    pub path_normal: Option<Vec<f64>>,
    /// On a path point, both truncation estimates per output: at the fixed frequency and
    /// across the path (the reported one is chosen by [`PathSwitch`]); empty elsewhere.
    #[serde(skip)]
    pub both_truncation: Option<(Vec<f64>, Vec<f64>)>,
    /// On a path point, the arc length (scaled, Hz-equivalent, as the continuation's steps)
    /// that the fixed-frequency truncation step slides along the path beyond the step across
    /// it, and the continuation step that reached the point; NaN elsewhere.
    #[serde(skip)]
    pub slide_and_step: (f64, f64),
    /// Highest harmonic of the extended set the reported truncation estimate comes from:
    /// 2H + 1, or the wider set's 4H + 3 where the first extension had not converged in its
    /// own harmonics ([`TailTest`](super::TailTest)); 0 where no estimate was formed.
    pub estimate_harmonic: usize,
    /// Whether a contact's regime at the point moved by the reported truncation step (on the
    /// first extension) differs from the point's own: the step crosses a stick-slip or
    /// lift-off transition, outside the range where its linearisation holds.
    pub step_changes_regime: bool,
    /// The reported truncation step's contraction of the extended residual
    /// ([`LinearRange`](super::LinearRange)); NaN where not formed.
    #[serde(skip)]
    pub contraction: f64,
    /// How the truncation estimate was formed: one Newton step, the extended system solved to
    /// convergence, or not sizeable ([`EstimateMethod`]).
    pub method: EstimateMethod,
}

impl PointAccuracy {
    /// The estimate of a point where none could be formed: NaN for each of `outputs` output
    /// DOFs, no method.
    pub fn not_formed(outputs: usize) -> Self {
        Self {
            truncation: vec![f64::NAN; outputs],
            sampling: vec![f64::NAN; outputs],
            across_path: false,
            path_normal: None,
            both_truncation: None,
            slide_and_step: (f64::NAN, f64::NAN),
            estimate_harmonic: 0,
            step_changes_regime: false,
            contraction: f64::NAN,
            method: EstimateMethod::None,
        }
    }
}

/// Where the path is at a converged point, for the estimate across it: the hyperplane normal
/// to the path (see [`crate::numerics::Observer::accepted`]) and the arc-length step
/// (Hz-equivalent) that reached the point.
#[derive(Debug, Clone, Copy)]
pub struct PathPlace<'a> {
    /// Covector on the run operator's unknowns, then on ω (rad/s).
    pub normal: &'a [f64],
    /// The continuation step that reached the point (scaled arc length).
    pub step: f64,
}

/// Which step a path point reports: the fixed-frequency one, unless it slides along the path
/// (beyond the step across it) by more than [`Self::SLIDE_STEPS`] continuation steps. The
/// fixed-frequency step is the across-path one plus a slide along the path's tangent back onto
/// the point's frequency; next to a fold the tangent's frequency component vanishes, the
/// fixed-frequency Jacobian is singular and the slide unbounded, far beyond the stretch of path
/// where the tangent holds (the continuation turns its tangent by about 10° per step).
///
/// The threshold is set from measurements: on the paper case's steep flank below its 2nd
/// resonance (H = 1, `zoom-2nd.toml`) the slide reaches 21 steps while the fixed-frequency
/// estimate still tracks the error at a fixed frequency (within the criteria, see
/// `tests/it/error_estimate.rs`), so the switch sits above that.
pub struct PathSwitch;

impl PathSwitch {
    /// Continuation steps the fixed-frequency step may slide along the path.
    pub const SLIDE_STEPS: f64 = 32.0;

    /// True when the across-path step is reported (not at a path's first point, solved at a
    /// fixed frequency, whose `step` is 0).
    pub fn across(slide: f64, step: f64) -> bool {
        // A slide that is not a number (the path's direction has no frequency component: at
        // the fold itself) counts as beyond.
        step > 0.0 && (slide.is_nan() || slide > Self::SLIDE_STEPS * step)
    }
}

/// How a point's truncation estimate was formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EstimateMethod {
    /// One Newton step of the extended system (the default, within its linear range).
    Step,
    /// The extended system solved to convergence at the point's frequency, or across the path
    /// where the point reports the across-path step (the step left its linear range,
    /// [`LinearRange`](super::LinearRange)).
    Solved,
    /// Not sizeable: the step left its linear range and the extended system has no converged
    /// solution at the point's frequency (or, where the point reports the across-path step,
    /// across the path). The estimate is the step's and is not to be read as a size: the run
    /// warns.
    Unsized,
    /// Not sized: the step left its linear range and the scene asked not to solve the
    /// extended system there (`accuracy.beyond_linear_range = "flag"`). The estimate is the
    /// step's and is not to be read as a size: the run warns, as for [`Self::Unsized`].
    Unsolved,
    /// The point padded with zero harmonics already solves the extended system, and the
    /// harmonic balance at twice the samples, within the run's Newton tolerance
    /// (`solves_padded`): both estimates are 0 (below what the run resolves), formed from
    /// two residuals without a Newton step (e.g. every contact stuck or open all period,
    /// where the contact forces hold no harmonic the point lacks).
    Converged,
    /// No estimate formed (NaN).
    None,
}

impl EstimateMethod {
    /// The label written in the output files.
    pub fn label(self) -> &'static str {
        match self {
            Self::Step => "step",
            Self::Solved => "solved",
            Self::Unsized => "unsized",
            Self::Unsolved => "unsolved",
            Self::Converged => "converged",
            Self::None => "none",
        }
    }
}
