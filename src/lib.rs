//! fricbound: steady-state forced response of structures with dry-friction contacts, by
//! harmonic balance with alternating frequency/time contact forces, and the limits of that
//! response among the multiple steady states friction allows (Ferhatoglu & Zucca, JSV 2021).

// Matrix and block loops index several arrays with the same DOF or block index; iterator
// rewrites would hide the maths.
#![allow(clippy::needless_range_loop)]

pub mod analysis;
pub mod cli;
pub mod contact;
pub mod fe;
pub mod hbm;
pub mod model;
pub mod numerics;
pub mod report;
pub mod scene;
pub mod study;
