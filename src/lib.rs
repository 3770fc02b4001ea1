//! fricbound: steady-state forced response of structures with dry-friction contacts, by
//! harmonic balance with alternating frequency/time contact forces, and the limits of that
//! response among the multiple steady states friction allows (Ferhatoglu & Zucca, JSV 2021).
//!
//! # Layers
//!
//! Data flows scene → problem → harmonic-balance operator → numerics → analyses → reports.
//! Each layer is a folder and uses only the layers listed before it here (checked by
//! `tests/it/architecture.rs`):
//!
//! 1. [`numerics`]: linear solves, Newton, pseudo-arc-length continuation ([`numerics::ParametricResidual`]);
//! 2. [`contact`]: the Jenkins law at a contact point, harmonic sets, the AFT;
//! 3. [`fe`]: meshes, elements, assembly, Matrix Market, contact patches, VTU;
//! 4. [`model`]: the checked [`model::Problem`], Craig-Bampton reduction of a problem;
//! 5. [`hbm`]: the harmonic-balance residual, its Jacobian and formulations;
//! 6. [`analysis`]: frequency-response runs, linear references, the limit analysis;
//! 7. [`scene`]: scene files into a problem and analysis settings;
//! 8. [`study`]: sweeps over scene fields, the scaling study;
//! 9. [`report`]: result files and figures;
//! 10. [`cli`]: the commands.

// Matrix and block loops index several arrays with the same DOF or block index; iterator
// rewrites would hide the maths.
#![allow(clippy::needless_range_loop)]

pub mod numerics;

pub mod contact;

pub mod fe;

pub mod model;

pub mod hbm;

pub mod analysis;

pub mod scene;

pub mod study;

pub mod report;

pub mod cli;
