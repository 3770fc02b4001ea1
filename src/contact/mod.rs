//! Contact: the Jenkins law, contact points and damper sides, harmonic sets and sampled
//! Fourier bases, the AFT with its analytic Jacobian.

pub mod aft;
pub mod describing_function;
pub mod harmonic;
pub mod point;

pub use describing_function::jenkins_describing_function;
pub use point::{ContactEffects, ContactPoint, ContactState, DamperSide, JenkinsLaw, NormalLoad};
