//! Scenes into validated problems, with `--set`-style overrides; any error panics with its
//! message (file, field and reason).

use fricbound::model::Problem;
use fricbound::scene;
use std::path::Path;

/// Overrides that put the paper scene's two contacts on the sampled law
/// (`jenkins-1d-sampled`): for the tests of what its corners make (dead ends, leaps, jumps)
/// and of its equivalence with the sampled 2D law.
pub const SAMPLED_PAPER: [&str; 2] = [
    "contacts.0.law=\"jenkins-1d-sampled\"",
    "contacts.1.law=\"jenkins-1d-sampled\"",
];

/// A validated problem from scene text with `--set`-style overrides.
pub fn problem(text: &str, overrides: &[&str]) -> Problem {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::parse(text, "scene", &o)
        .and_then(|s| s.validate("scene"))
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The paper's lumped wedge-damper scene ([`scene::paper_wedge_scene`]) with overrides.
pub fn paper(overrides: &[&str]) -> Problem {
    problem(scene::paper_wedge_scene(), overrides)
}

/// A validated problem from the scene file at `path` (relative to the crate's folder, e.g.
/// `meshes/paper-wedge/fig13-3rd.toml`) with overrides; a mesh the scene names is read
/// relative to the scene file.
pub fn load(path: &str, overrides: &[&str]) -> Problem {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    scene::load_problem(&path, &o)
        .unwrap_or_else(|e| panic!("{e}"))
        .1
}

/// The single-DOF oscillator of `docs/scene.md` (m = 1 kg, k = 1e4 N/m, c = 2 N·s/m, a Jenkins
/// contact to the ground with kₜ = 1e5 N/m, μN₀ = 3 N, F = 5 N) at H = 1 with a constant
/// normal load; also the scene of the `oscillator_frf` benchmark (`benches/paper_frf.rs`).
pub const JENKINS_OSCILLATOR: &str = include_str!("jenkins-oscillator.toml");
