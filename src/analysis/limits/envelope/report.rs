//! What the response envelope reports: the bounds at each frequency with the states that reach
//! them, at the peaks, and how the envelope compares with the limit curves.

use crate::contact::ContactState;
use crate::model::Problem;

/// Which initial states the envelope varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvelopeMode {
    /// One m per damper side (every point of a side shares it).
    Sides,
    /// One m per contact point.
    Points,
}

impl EnvelopeMode {
    /// The groups of contacts sharing one m: names and contact indices.
    pub fn groups(self, problem: &Problem) -> (Vec<String>, Vec<Vec<usize>>) {
        match self {
            EnvelopeMode::Sides => problem
                .sides
                .iter()
                .map(|s| (s.name.clone(), s.contacts.clone()))
                .unzip(),
            EnvelopeMode::Points => problem
                .contacts
                .iter()
                .enumerate()
                .map(|(c, k)| (k.name.clone(), vec![c]))
                .unzip(),
        }
    }
}

/// One bound of the envelope: the amplitude and the state attaining it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopeBound {
    /// First-harmonic amplitude (m).
    pub amplitude: f64,
    /// m of each search variable attaining it: one per group (side or point), two (m₁, m₂)
    /// for a group with 2D-friction points ([`Envelope::groups`] names them).
    pub m: Vec<f64>,
    /// Contact states there.
    pub states: Vec<ContactState>,
    /// Full Fourier coefficients of that state (not written to files).
    #[serde(skip)]
    pub coefficients: Vec<f64>,
}

/// The envelope at one frequency.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopePoint {
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Smallest amplitude of each output DOF (`None`: no state could be solved).
    pub min: Vec<Option<EnvelopeBound>>,
    /// Largest amplitude of each output DOF.
    pub max: Vec<Option<EnvelopeBound>>,
    /// Whether each variable's m acted at some state solved here (stuck over the whole period);
    /// variables that never did were dropped from the search at this frequency.
    pub acting: Vec<bool>,
    /// Newton solves (each with its sensitivity) spent here.
    pub solves: usize,
}

/// The envelope at a limit curve's resonance peak.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopeAtPeak {
    /// Limit curve whose peak frequency this is.
    pub case: String,
    /// The limit curve's peak amplitude (m).
    pub limit_amplitude: f64,
    /// The envelope there.
    pub point: EnvelopePoint,
}

/// Where and by how much the two limit curves fail to bound the envelope (first output DOF).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopeCheck {
    /// Grid frequencies compared (band and envelope both exist).
    pub compared: usize,
    /// Largest (envelope max − upper limit) / upper limit over the grid (≥ 0).
    pub max_excess_above: f64,
    /// Frequency (Hz) and m of that excess.
    pub above_at: Option<(f64, Vec<f64>)>,
    /// Largest (lower limit − envelope min) / lower limit (≥ 0).
    pub max_excess_below: f64,
    /// Frequency (Hz) and m of that excess.
    pub below_at: Option<(f64, Vec<f64>)>,
    /// Grid frequencies where the envelope max exceeds the upper limit by more than 10⁻⁶.
    pub points_above: usize,
    /// Grid frequencies where the envelope min lies below the lower limit by more than 10⁻⁶.
    pub points_below: usize,
    /// Largest envelope max at the limit peaks relative to the larger limit peak, minus 1.
    pub peak_excess_above: f64,
}

/// The envelope over the grid and at the limit peaks.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Envelope {
    /// Sides or points.
    pub mode: EnvelopeMode,
    /// Name of each search variable, the order of every `m` vector: the group's (side or
    /// contact) name for m₁, `<group>_m2` for the second component of a group with 2D points.
    pub groups: Vec<String>,
    /// One point per grid frequency.
    pub points: Vec<EnvelopePoint>,
    /// At each limit curve's peak.
    pub peaks: Vec<EnvelopeAtPeak>,
    /// How the band of the limit curves compares.
    pub check: EnvelopeCheck,
    /// Newton solves in all.
    pub solves: usize,
    /// Grid frequencies where no state could be solved (no bound).
    pub unsolved: usize,
    /// Wall time (s).
    pub elapsed_s: f64,
}

impl EnvelopePoint {
    /// The point at `freq_hz` where no state could be solved (k groups, `outputs` output DOFs).
    pub fn unsolved(freq_hz: f64, k: usize, outputs: usize) -> Self {
        Self {
            freq_hz,
            min: vec![None; outputs],
            max: vec![None; outputs],
            acting: vec![false; k],
            solves: 0,
        }
    }
}
