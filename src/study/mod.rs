//! Studies over many scenes: parameter sweeps of scene fields, the scaling study.

pub mod scaling;
pub mod sweep;
