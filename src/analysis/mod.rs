//! Analyses of one checked problem: what is computed from a [`crate::model::Problem`] once the
//! scene has been read and validated.
//!
//! Today these are the nonlinear frequency response by continuation of the harmonic balance,
//! the linear references (contacts open, contacts stuck), and the paper's limit analysis of the
//! response among multiple steady states (two-point method, Ferhatoglu & Zucca 2021, §3), and
//! the Hill stability of the periodic solutions, and the response envelope over all initial
//! tangential states (`limits::envelope`).
//!
//! Layer: above `hbm`, below `scene`. It uses `hbm` (the harmonic-balance system and
//! operator), `model` (the problem), `contact` (contact states, harmonic sets) and `numerics`
//! (continuation, linear solves); it does not need `fe` directly, and never names a layer above
//! it (only the inline tests build their fixtures from `scene`). Studies over many problems
//! (`study`), file output (`report`) and the command line (`cli`) build on it.
//!
//! Main items:
//! - [`frf::solve`]: the nonlinear FRF over the analysis range by pseudo-arc-length
//!   continuation, as an [`frf::FrfRun`] of [`frf::FrfPoint`]s, reported to an
//!   [`frf::FrfObserver`] as they come.
//! - [`frf::PointSolver`]: single points by Newton, at a fixed frequency or on a path's chord.
//! - [`frf::interpolate_on_path`]: a starting guess at a frequency from a solved path.
//! - [`linear::reference_curve`]: a linear reference ([`linear::LinearCase`]) on a grid, as a
//!   [`linear::LinearCurve`]; [`linear::stuck_guess`] seeds the nonlinear solve.
//! - [`peaks::path_peaks`]: every resonance peak of every output along a path, told from the
//!   sampled law's wiggles by its prominence and refined along the path ([`peaks::Peak`]).
//! - [`peaks::path_extrema`]: the same for resonances and anti-resonances (local minima) of
//!   every output of an FRF run, with the path points they were refined from
//!   ([`peaks::PathExtremum`]); a failed refinement reports the path point, never an error.
//!   Resonances that stand out only toward a break between branches are added, marked
//!   `at_branch_end` ([`peaks::branch_end_peak_indices`]).
//! - [`modes::natural_modes`], [`modes::damped_modes`]: natural frequencies and shapes of the
//!   linear structure with contacts open or stuck (dense or Lanczos with a Sturm check), damped
//!   eigenvalues and modal damping ratios.
//! - [`limits::analyse`]: the limit analysis (limit, intermediate and scanned curves, grid
//!   classification, bound check, hysteresis loops) as a [`limits::LimitAnalysis`].
//! - [`limits::solve_case`]: one case's curve and its refined resonance peak.
//! - [`limits::envelope()`], [`limits::envelope_at`]: the largest and smallest amplitude over
//!   m ∈ [−1, 1]^k per side or point, by bounded optimisation with dA/dm from
//!   [`limits::amplitude_sensitivity`] (implicit-function theorem).
//! - [`limits::LimitAnalysis::variability`]: the size of the variability between the limits.
//! - [`error_estimate::ErrorEstimator`]: the a-posteriori truncation and sampling error
//!   estimate of every converged continuation point ([`error_estimate::PointAccuracy`]).
//! - [`estimate_pool::EstimatePool`]: those estimates on worker threads, so that an FRF run's
//!   continuation goes on while its accepted points are estimated.
//! - [`stability::point_stability`]: Hill stability of a converged point (Floquet exponents
//!   from the quadratic Hill eigenvalue problem, [`stability::PointStability`]); computed on
//!   every FRF point when the scene sets `analysis.stability`.
//! - [`stability_sparse::floquet_exponents_shift_invert`]: the exponents near their estimates
//!   by shift-invert Arnoldi on the sparse Hill pencil, with a coverage statement; used by runs
//!   above the dense limit (`analysis.hill_solver`, [`stability_sparse::point_stability_with`]).
//! - [`verify::verify_point`]: time integration (Newmark, implicit contact return mapping) from
//!   a harmonic-balance point to its steady state, with a dt check ([`verify::PointVerification`]).
//! - [`nonlinear_modes::solve`]: a nonlinear mode by EPMC (backbone frequency, modal damping
//!   ratio and shape against the modal amplitude, Krack 2015) as a
//!   [`nonlinear_modes::NonlinearModeRun`].
//! - [`monodromy::monodromy_stability`]: Floquet multipliers of the time integration's periodic
//!   orbit (shooting, monodromy matrix by central differences of the period map, sliders as
//!   state), the independent check of Hill's verdict ([`monodromy::MonodromyStability`]).

pub mod error_estimate;
pub mod estimate_pool;
pub mod frf;
pub mod limits;
pub mod linear;
pub mod modes;
pub mod monodromy;
pub mod nonlinear_modes;
pub mod peaks;
pub mod stability;
pub mod stability_sparse;
pub mod verify;
