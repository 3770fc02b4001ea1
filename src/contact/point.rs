//! Contact points, damper sides, the Jenkins contact law parameters and contact states.
//!
//! A [`ContactPoint`] couples the structure through two scalar relative displacements built
//! from the DOFs by sparse linear rows:
//!
//! * tangential u = Σ aₜ\[i\] q\[i\]            (m)
//! * normal     v = Σ aₙ\[i\] q\[i\] − gap      (m; v > 0 is penetration, i.e. compression)
//!
//! For a damper pressed against a body, aₜ and aₙ are the local frame vectors t, n applied to
//! the relative displacement r = (damper point) − (body point). The contact forces are
//! N = max(kₙ v, 0) and the Jenkins tangential force T (paper Eqs. 4-6), and they enter the
//! equations of motion M q̈ + C q̇ + K q + F_c = F_ex as F_c = aₜ T + aₙ N (virtual work), so
//! the damper is pushed back along −n and the body along +n.
//!
//! A point with the 2D law (`jenkins-2d`) has a second tangential row u₂ = aₜ₂·q along a second
//! tangent t₂ ⟂ t₁, n ([`SecondTangent`]); its tangential force (T₁, T₂) enters as aₜ₁T₁ + aₜ₂T₂.
//!
//! Each point belongs to a [`DamperSide`]; the limit method assigns one initial tangential
//! state m to all points of a side (paper Eqs. 14-15).

use serde::{Deserialize, Serialize};

/// How the normal force evolves over the period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum NormalLoad {
    /// N(τ) = kₙ v(τ) follows the normal relative motion (paper Eq. 4).
    #[default]
    Variable,
    /// N is constant over the period, N = kₙ v₀ from the 0th harmonic of v only.
    Constant,
}

/// Contact-law effects a scene may switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactEffects {
    /// Variable or constant normal load.
    pub normal_load: NormalLoad,
    /// Whether the contact may separate (N = max(kₙv, 0)); without lift-off the normal spring
    /// is bilateral (N = kₙ v may become negative) and friction is limited by μ·max(N, 0).
    pub liftoff: bool,
}

impl ContactEffects {
    /// Normal force N (N) of a spring kₙ (N/m) compressed by v (m), and whether the spring is
    /// active (its force follows v): with lift-off N = max(kₙ v, 0), active only while closed;
    /// without, N = kₙ v always.
    pub fn normal_force(&self, kn: f64, v: f64) -> (f64, bool) {
        let force = kn * v;
        if !self.liftoff || force > 0.0 {
            (force, true)
        } else {
            (0.0, false)
        }
    }
}

impl Default for ContactEffects {
    fn default() -> Self {
        Self {
            normal_load: NormalLoad::Variable,
            liftoff: true,
        }
    }
}

/// Jenkins element parameters of one contact point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JenkinsLaw {
    /// Tangential contact stiffness kₜ (N/m), > 0.
    pub kt: f64,
    /// Normal contact stiffness kₙ (N/m), > 0.
    pub kn: f64,
    /// Friction coefficient μ (–), ≥ 0.
    pub mu: f64,
    /// Initial tangential state m ∈ [−1, 1]: the march starts at T(τ=0) = m μ N(τ=0).
    pub initial_state: f64,
}

/// Parameters of the isotropic 2D Jenkins element of one contact point (marched by
/// [`crate::contact::aft2d`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jenkins2dLaw {
    /// Tangential contact stiffness kₜ (N/m), the same in every in-plane direction, > 0.
    pub kt: f64,
    /// Normal contact stiffness kₙ (N/m), > 0.
    pub kn: f64,
    /// Friction coefficient μ (–), ≥ 0.
    pub mu: f64,
    /// Initial tangential state m in the unit disc, components along t₁, t₂: the march starts
    /// at T(τ=0) = μ N(τ=0) · m.
    pub initial_state: [f64; 2],
}

/// A contact point with its kinematics and law.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPoint {
    /// Name used in outputs (`<name>_state`).
    pub name: String,
    /// Index into the problem's damper sides.
    pub side: usize,
    /// Sparse row (dof index, coefficient) giving u.
    pub tangential: Vec<(usize, f64)>,
    /// Sparse row (dof index, coefficient) giving n·r (before the gap).
    pub normal: Vec<(usize, f64)>,
    /// Initial normal gap g (m): v = aₙ·q − g; negative g is an interference.
    pub gap: f64,
    /// Contact law: its kₜ, kₙ, μ, and the initial state along the first tangent direction.
    pub law: JenkinsLaw,
    /// The second tangent direction of a point with the 2D Jenkins law (`jenkins-2d`), None
    /// for the paper's 1D law (`jenkins-1d`, the default).
    pub second_tangent: Option<SecondTangent>,
    /// How the point's law is resolved in time (events for `jenkins-1d` and `jenkins-2d`,
    /// samples for `jenkins-1d-sampled` and `jenkins-2d-sampled`).
    pub resolution: TimeResolution,
}

/// Which tangential friction law a contact point follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FrictionLaw {
    /// The paper's Jenkins element along one tangent direction (Eqs. 4-6), its transitions
    /// located in continuous time ([`crate::contact::events`]): a C¹ residual.
    #[default]
    #[serde(rename = "jenkins-1d")]
    Jenkins1d,
    /// The same element sampled on `harmonics.samples` instants per period (the paper's AFT,
    /// [`crate::contact::aft`]), for comparison with the paper and with codes that sample.
    #[serde(rename = "jenkins-1d-sampled")]
    Jenkins1dSampled,
    /// The isotropic Jenkins element in the tangent plane, its transitions located in
    /// continuous time and its slip direction integrated as an ODE
    /// ([`crate::contact::events2d`]): a C¹ residual.
    #[serde(rename = "jenkins-2d")]
    Jenkins2d,
    /// The same element sampled on `harmonics.samples` instants per period, radial return
    /// onto the friction circle at each ([`crate::contact::aft2d`]'s march).
    #[serde(rename = "jenkins-2d-sampled")]
    Jenkins2dSampled,
}

impl FrictionLaw {
    /// Whether the law acts in the tangent plane (`jenkins-2d`, `jenkins-2d-sampled`; 3 DOFs
    /// per point).
    pub fn is_2d(self) -> bool {
        matches!(self, FrictionLaw::Jenkins2d | FrictionLaw::Jenkins2dSampled)
    }

    /// How a point with this law resolves its transitions in time.
    pub fn time_resolution(self) -> TimeResolution {
        match self {
            FrictionLaw::Jenkins1dSampled | FrictionLaw::Jenkins2dSampled => {
                TimeResolution::Samples
            }
            FrictionLaw::Jenkins1d | FrictionLaw::Jenkins2d => TimeResolution::Events,
        }
    }

    /// The scene's name of the law.
    pub fn name(self) -> &'static str {
        match self {
            FrictionLaw::Jenkins1d => "jenkins-1d",
            FrictionLaw::Jenkins1dSampled => "jenkins-1d-sampled",
            FrictionLaw::Jenkins2d => "jenkins-2d",
            FrictionLaw::Jenkins2dSampled => "jenkins-2d-sampled",
        }
    }
}

/// How the Jenkins law of a point (1D or 2D) is resolved in time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimeResolution {
    /// Transitions located in continuous time, forces integrated between them (`jenkins-1d`,
    /// `jenkins-2d`).
    #[default]
    Events,
    /// The law marched on the sample grid (`jenkins-1d-sampled`, `jenkins-2d-sampled`; the
    /// paper's AFT).
    Samples,
}

/// The second tangential relative displacement of a 2D-friction point and its share of the
/// initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct SecondTangent {
    /// Sparse row (dof index, coefficient) giving u₂ = t₂·r (m), t₂ orthonormal to t₁ and n.
    pub row: Vec<(usize, f64)>,
    /// Second component m₂ of the initial tangential state m = (m₁, m₂), |m| ≤ 1; m₁ is
    /// [`JenkinsLaw::initial_state`]. The march starts at T(τ=0) = μN(τ=0)·m.
    pub initial_state: f64,
}

impl ContactPoint {
    /// The point's tangential friction law.
    pub fn friction_law(&self) -> FrictionLaw {
        match (&self.second_tangent, self.resolution) {
            (Some(_), TimeResolution::Events) => FrictionLaw::Jenkins2d,
            (Some(_), TimeResolution::Samples) => FrictionLaw::Jenkins2dSampled,
            (None, TimeResolution::Events) => FrictionLaw::Jenkins1d,
            (None, TimeResolution::Samples) => FrictionLaw::Jenkins1dSampled,
        }
    }

    /// The 2D law's parameters (None for a 1D point).
    pub fn law_2d(&self) -> Option<Jenkins2dLaw> {
        self.second_tangent.as_ref().map(|s| Jenkins2dLaw {
            kt: self.law.kt,
            kn: self.law.kn,
            mu: self.law.mu,
            initial_state: [self.law.initial_state, s.initial_state],
        })
    }

    /// The tangential rows: \[aₜ\] for a 1D point, \[aₜ₁, aₜ₂\] for a 2D point.
    pub fn tangential_rows(&self) -> impl Iterator<Item = &[(usize, f64)]> {
        std::iter::once(self.tangential.as_slice())
            .chain(self.second_tangent.as_ref().map(|s| s.row.as_slice()))
    }

    /// All rows in force order: aₜ (, aₜ₂ for a 2D point), aₙ.
    pub fn rows(&self) -> impl Iterator<Item = &[(usize, f64)]> {
        self.tangential_rows()
            .chain(std::iter::once(self.normal.as_slice()))
    }

    /// Every (dof, coefficient) entry of the point's rows (tangential ones, then normal).
    pub fn row_entries(&self) -> impl Iterator<Item = &(usize, f64)> {
        self.tangential_rows().flatten().chain(&self.normal)
    }

    /// u₂ = aₜ₂ · q (0 for a 1D point).
    pub fn second_tangential_of(&self, q: &[f64]) -> f64 {
        self.second_tangent
            .as_ref()
            .map_or(0.0, |s| s.row.iter().map(|&(i, a)| a * q[i]).sum())
    }

    /// u = aₜ · q.
    pub fn tangential_of(&self, q: &[f64]) -> f64 {
        self.tangential.iter().map(|&(i, a)| a * q[i]).sum()
    }

    /// aₙ · q (without the gap).
    pub fn normal_of(&self, q: &[f64]) -> f64 {
        self.normal.iter().map(|&(i, a)| a * q[i]).sum()
    }
}

/// A damper side: the contact points that share one initial tangential state in a limit case.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DamperSide {
    /// Side name from the scene.
    pub name: String,
    /// Indices of the side's contact points.
    pub contacts: Vec<usize>,
}

/// Contact state of a point over one steady-state period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactState {
    /// Stuck at every sample with N > 0: T⁰ is not unique (paper §3.1).
    Stuck,
    /// Alternates stick and slip, always closed.
    StickSlip,
    /// Separates for part of the period (with or without slip).
    StickSlipLiftoff,
    /// Separated over the whole period.
    Open,
}

impl ContactState {
    /// Label used in CSV files.
    pub fn label(self) -> &'static str {
        match self {
            ContactState::Stuck => "stuck",
            ContactState::StickSlip => "stick-slip",
            ContactState::StickSlipLiftoff => "stick-slip-liftoff",
            ContactState::Open => "open",
        }
    }

    /// Whether the tangential force of this state is unique (it slipped or separated).
    pub fn is_unique(self) -> bool {
        !matches!(self, ContactState::Stuck)
    }
}

impl std::fmt::Display for ContactState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}
