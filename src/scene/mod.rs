//! The scene layer: what a user asks for, read from a TOML scene file and checked at the door.
//!
//! It holds the TOML schema (every table rejects unknown fields; the field reference with units
//! is `docs/scene.md`), the `--set FIELD=VALUE` overrides applied to a scene before it is
//! checked, and the validation that turns a scene into a checked [`Problem`](crate::model::Problem)
//! plus the analysis settings the scene asks for (the limit analysis of a `[limits]` table).
//! Every value is checked there, and an error names the file, the field (dotted path, e.g.
//! `contacts[1].mu`) and the reason: ranges and consistency, the physical conditions a solve
//! needs (a free body pressed onto its contacts, contact stiffnesses and frequencies the model
//! resolves), and the scene at every point of a `[sweep]`. FE scene input (meshes, Matrix
//! Market files, contact patches, group loads, Craig-Bampton reduction) is in [`fe_input`].
//!
//! Layers used: `analysis` (limit settings, contact stiffness of the stuck check), `hbm` (the
//! Schur formulation check), `model`, `fe`, `contact` and `numerics` (continuation settings).
//!
//! Main types and functions:
//! - [`Scene`]: the whole scene file; [`Scene::validate`] and [`Scene::validate_with_limits`]
//!   check it into a problem (and limit settings).
//! - [`ModelSpec`], [`ContactSpec`], [`StaticLoadSpec`], [`HarmonicLoadSpec`],
//!   [`HarmonicsSpec`], [`EffectsSpec`], [`AnalysisSpec`], [`OutputSpec`]: its tables.
//! - [`LimitsSpec`]: the `[limits]` table of the limit analysis (two-point method).
//! - [`SweepSpec`]: the `[sweep]` table, one parameter (and an optional [`SeriesSpec`]) moving
//!   scene fields through [`SweepTarget`]s; [`SweepOutput`] says what each value computes.
//! - [`SceneError`]: a scene that cannot be read, does not parse, or holds a bad value.
//! - [`load`], [`parse`], [`apply_override`]: reading a scene with `--set` overrides.
//! - [`load_problem`]: load and validate in one go.
//! - [`PAPER_DEFAULT_SCENE`], [`paper_wedge_scene`], [`default_scene_label`]: the built-in
//!   paper scene.
//! - [`MAX_SAMPLES`], [`MAX_POINTS`]: the largest sampling and point counts a scene may ask for;
//!   [`MAX_MAGNITUDE`], [`MAX_CONTACT_STIFFNESS_RATIO`], [`MAX_INERTIA_RATIO`]: the bounds on
//!   the magnitude of any number, on contact stiffnesses and on frequencies.

mod check_analysis;
mod check_bodies;
mod check_contacts;
mod check_limits;
mod check_loads;
mod check_model;
mod check_modes;
mod check_sweep;
mod checker;
mod cone;
pub mod error;
pub mod fe_input;
pub mod limits_schema;
pub mod overrides;
pub mod paper;
pub mod schema;
pub mod validate;

pub use check_analysis::{MAX_INERTIA_RATIO, MAX_POINTS, MODE_RANGE_END, MODE_RANGE_START};
pub use check_loads::MAX_SAMPLES;
pub use checker::{MAX_CONTACT_STIFFNESS_RATIO, MAX_MAGNITUDE};
pub use error::SceneError;
pub use limits_schema::{
    HysteresisSpec, LimitCaseSpec, LimitsSpec, SeriesSpec, SweepOutput, SweepSpec, SweepTarget,
};
pub use overrides::{apply_override, load, parse};
pub use paper::{default_scene_label, paper_wedge_scene, PAPER_DEFAULT_SCENE};
pub use schema::{
    AccuracySpec, AnalysisSpec, ContactSpec, EffectsSpec, GroupDirectionSpec, HarmonicLoadSpec,
    HarmonicsSpec, ModelSpec, OutputSpec, Scene, StaticLoadSpec,
};
pub use validate::load_problem;
