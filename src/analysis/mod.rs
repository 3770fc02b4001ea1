//! Analyses of one problem: FRF runs, linear references, the limit analysis.

pub mod frf;
pub mod limits;
pub mod linear;
