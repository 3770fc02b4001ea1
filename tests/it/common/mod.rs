//! Helpers shared by the test modules (`use crate::common;`), one job per file:
//!
//! | module | what |
//! |---|---|
//! | [`scenes`] | scene text or files into a validated `Problem`, with `--set`-style overrides |
//! | [`paper_3d`] | the 3D paper scene (`jenkins-2d`, out-of-plane motion constrained) against the planar one: scenes, DOF maps, coefficient comparison |
//! | [`linear`] | linear references: the damped eigenvalues of a problem's structure |
//! | [`envelope`] | the m = ±1 limit states at given frequencies, seeds of the response envelope |
//! | [`points`] | solved points compared: coefficients to 1e-8 of their largest, contact states |
//! | [`blade_pair`] | the generated blade pairs of the FE tests: the reduced 2D one with 2 pairs per side, the coarse 2D or 3D one with fields added to its patches |
//!
//! Each test module uses a part of it.
#![allow(dead_code)]

pub mod blade_pair;
pub mod envelope;
pub mod linear;
pub mod paper_3d;
pub mod points;
pub mod scenes;

// The names the 3D-against-planar tests take from `common` itself; not every crate uses them.
#[allow(unused_imports)]
pub use paper_3d::*;
#[allow(unused_imports)]
pub use scenes::problem;
