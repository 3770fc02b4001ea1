//! Result files and figures.

pub mod files;
pub mod limit_files;
pub mod limit_plots;
pub mod mesh_modes;
pub mod mesh_results;
pub mod plot;
