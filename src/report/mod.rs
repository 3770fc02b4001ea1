//! Result files and figures, written from the results of the analyses and studies.
//!
//! This layer writes what the layers below computed; the only computing here is what a file
//! itself needs (the stuck-contact modes of `modes_stuck.vtu`, the layout of a figure). It may
//! use every layer below it (`numerics`, `contact`, `fe`, `model`, `hbm`, `analysis`, `scene`,
//! `study`) and is used by `cli` only.
//!
//! - [`files`]: CSV and JSON of one FRF ([`files::FrfWriter`], streamed as points converge),
//!   the linear references, [`files::RunInfo`] and [`files::write_atomic`];
//! - [`owned`]: the result files a run owns in its output folder, removed before it starts
//!   ([`owned::clear_results`]);
//! - [`limit_files`]: the tables of a limit analysis (limit curves on the grid, peaks,
//!   hysteresis loops);
//! - [`plot`]: the figures as PNG and SVG ([`plot::plot_frf`], [`plot::plot_limits`],
//!   [`plot::plot_sweep`], [`plot::plot_hysteresis`], [`plot::plot_lines`]);
//! - [`mesh_results`]: a converged point's response on the FE mesh (VTU);
//! - [`mesh_modes`]: the stuck-contact modes on the FE mesh (VTU);
//! - [`modes_files`]: the files of `fricbound modes` (frequencies of the full and reduced
//!   models side by side, damped modes, mode shapes, `modes.json`);
//! - [`modes_nl_files`]: the files of a nonlinear-mode run (`modes_nl.csv`, `modes_nl.json`,
//!   the band of its limit cases, the backbone figures);
//! - [`reduced_files`]: the files of `fricbound reduce` (K_r, M_r, C_r as Matrix Market, the
//!   reduced DOF map, the recovery rows) and the reduction report in JSON.
//! - [`stability_columns`]: the Hill-stability columns of `frf.csv` and `curve_*.csv`.

pub mod files;
pub mod limit_files;
pub mod mesh_modes;
pub mod mesh_results;
pub mod modes_files;
pub mod modes_nl_files;
pub mod owned;
pub mod plot;
pub mod reduced_files;
pub mod stability_columns;
