//! fricbound: steady-state forced response of structures with dry-friction contacts, by
//! harmonic balance with alternating frequency/time contact forces, and the limits of that
//! response among the multiple steady states friction allows (Ferhatoglu & Zucca, JSV 2021).

// Matrix and block loops index several arrays with the same DOF or block index; iterator
// rewrites would hide the maths.
#![allow(clippy::needless_range_loop)]

pub mod aft;
pub mod commands;
pub mod condensed;
pub mod contact;
pub mod continuation;
pub mod fe;
pub mod fe_scene;
pub mod frf;
pub mod harmonic;
pub mod hbm;
pub mod jacobian;
pub mod limits;
pub mod linalg;
pub mod linear;
pub mod matrix;
pub mod model;
pub mod operator;
pub mod pattern;
pub mod reduce;
pub mod reference;
pub mod report;
pub mod scaling;
pub mod scene;
pub mod schur;
pub mod sweep;
