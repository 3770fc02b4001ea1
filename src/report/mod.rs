//! Result files and figures.

pub mod files;
pub mod plot;
