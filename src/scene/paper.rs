//! The built-in scene: the paper's wedge-damper problem shipped in the binary as TOML text,
//! used when no scene file is given and as the reference problem of tests, benchmarks and docs.

use std::path::PathBuf;

/// The paper's default scene (β = 120°, F0 = 120 N, full range), shipped in the binary.
pub const PAPER_DEFAULT_SCENE: &str = include_str!("../../meshes/paper-wedge/full-range.toml");

/// The paper's wedge-damper scene (β = 120°, F₀ = 120 N, full range) as TOML text: the
/// reference problem shared by tests, benchmarks and docs.
pub fn paper_wedge_scene() -> &'static str {
    PAPER_DEFAULT_SCENE
}

/// Path label used for the built-in default scene in messages.
pub fn default_scene_label() -> PathBuf {
    PathBuf::from("meshes/paper-wedge/full-range.toml")
}
