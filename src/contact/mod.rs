//! Contact: the friction law at one contact point and its harmonic-balance forces.
//!
//! Uses no other layer of the crate (only std, realfft and faer). Above it,
//! `crate::fe` pairs mesh nodes into contact points, `crate::model` groups them in a problem and
//! `crate::hbm` assembles their forces into the residual.
//!
//! | module | main types | job |
//! |---|---|---|
//! | [`point`] | [`ContactPoint`], [`DamperSide`], [`JenkinsLaw`], [`Jenkins2dLaw`], [`FrictionLaw`], [`SecondTangent`], [`ContactState`] | contact points (relative displacement rows, frame, gap, 1D or 2D friction), damper sides, the Jenkins law's parameters, contact states |
//! | [`harmonic`] | `HarmonicSet`, `Block`, `SampleBasis` | real Fourier basis, unknown ordering (harmonic-major), time sampling |
//! | [`aft`] | `AftWorkspace`, `MarchSettings`, `AftError` | the alternating frequency/time march of the Jenkins law (paper Eqs. 4-6) and its analytic Jacobian |
//! | [`aft2d`] | `Aft2dWorkspace` | the isotropic 2D Jenkins element in a contact's tangent plane: its sampled march (radial return onto the friction circle, `jenkins-2d-sampled`) and the event-resolved evaluation (`jenkins-2d`, [`events2d`]), each with its analytic Jacobian through the periodic steady state |
//! | [`events`] | `EventSolver`, `march::periodic_orbit` | the event-resolved Jenkins law: stick, slip, opening and closing located in continuous time, forces integrated exactly between them (a C¹ residual), and its analytic Jacobian |
//! | [`events2d`] | `march::PeriodMarch`, `dopri::Dopri` | the event-resolved 2D Jenkins law: one period of stick, slip (the slip angle's ODE by Dormand–Prince 8(5,3) with dense output and forward sensitivities), opening and closing located in continuous time; the periodic state and the outputs are `Aft2dWorkspace::evaluate_events` |
//! | [`describing_function`] | [`jenkins_describing_function`] | the exact first harmonic under constant normal load (paper Eqs. 17-18), the AFT's reference |

pub mod aft;
pub mod aft2d;
pub mod describing_function;
pub mod events;
pub mod events2d;
pub mod harmonic;
pub mod point;

pub use describing_function::jenkins_describing_function;
pub use point::{
    ContactEffects, ContactPoint, ContactState, DamperSide, FrictionLaw, Jenkins2dLaw, JenkinsLaw,
    NormalLoad, SecondTangent, TimeResolution,
};
