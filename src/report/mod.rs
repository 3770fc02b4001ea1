//! Result files and figures.

pub mod plot;
