//! Result files and figures.

pub mod plot;
pub mod files;
