//! Set-ups shared by the examples (`mod common;`): examples cannot use `tests/it/common`, and
//! `estimate_misses` and `upper_branch_states` study the same scene (the one of
//! `tests/it/error_estimate_fe.rs`). Cargo does not build this folder as an example of its own: it
//! has no `main.rs`.
//!
//! | item | what |
//! |---|---|
//! | [`SmallBladePair`], [`write_small_blade_pair`] | the generated 2D blade pair with 2 contact pairs per side, 8 interior modes (Craig-Bampton), written into a temporary folder; its problem with `--set`-style overrides |
//! | [`describe`] | per contact: state, T̂⁰, origin of a stuck state, smallest friction margin, open samples |
//!
//! Each example uses a part of it.
#![allow(dead_code)]

use fricbound::contact::ContactState;
use fricbound::hbm::system::HbmSystem;
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::study::scaling;

/// The small generated blade pair (the generator's coarsest 2D mesh, 2 contact pairs per side,
/// 8 interior Craig-Bampton modes, 0.2 % modal damping; resonance near 918-934 Hz), as the
/// scene file `blade-pair.toml` in a temporary folder that lives as long as this value.
pub struct SmallBladePair {
    dir: tempfile::TempDir,
}

impl SmallBladePair {
    /// Writes the mesh and the scene into a new temporary folder ([`write_small_blade_pair`]).
    pub fn new() -> Self {
        let dir = tempfile::tempdir().expect("temporary directory");
        write_small_blade_pair(dir.path());
        Self { dir }
    }

    /// The scene's checked problem with `overrides` (`--set` syntax, e.g.
    /// `harmonics.max=3`).
    pub fn problem(&self, overrides: &[String]) -> Problem {
        let path = self.dir.path().join("blade-pair.toml");
        scene::load_problem(&path, overrides)
            .expect("scene is valid")
            .1
    }
}

impl Default for SmallBladePair {
    fn default() -> Self {
        Self::new()
    }
}

/// Writes the small blade pair's mesh (`blade-pair-2d-r1-p2.msh`) and scene
/// (`blade-pair.toml`: [`scaling::small_reduced_blade_pair_scene`]) into `dir`.
pub fn write_small_blade_pair(dir: &std::path::Path) {
    let text = scaling::small_reduced_blade_pair_scene(dir).expect("mesh");
    std::fs::write(dir.join("blade-pair.toml"), text).expect("scene file");
}

/// Per contact of the point `x` (full coefficients of `system`'s problem): its state over the
/// period, its constant tangential force T̂⁰ (N), whether a stuck contact still keeps the
/// march's initial condition T(0) = m μ N(0) (`ic`) or forgot it in a slip (`hist`), its
/// smallest friction margin min (μN − |T|)/(μ max N) over the closed samples (0 where it
/// slips), and its open samples.
pub fn describe(system: &mut HbmSystem, problem: &Problem, x: &[f64]) -> String {
    let mut line = String::new();
    for c in 0..problem.contacts.len() {
        let Ok(state) = system.contact_forces(c, x, false) else {
            line.push_str(" | (march failed)");
            continue;
        };
        let law = system.law(c);
        let (t0, _n0) = system.last_constant_forces(c);
        let aft = system.aft();
        let keeps_ic = aft.initial_state_derivative(&law) != 0.0;
        let nmax = aft.n.iter().fold(0.0_f64, |m, &x| m.max(x));
        let margin = aft
            .n
            .iter()
            .zip(&aft.t)
            .filter(|(n, _)| **n > 0.0)
            .map(|(n, t)| (law.mu * n - t.abs()) / (law.mu * nmax))
            .fold(f64::INFINITY, f64::min);
        let open = aft.n.iter().filter(|n| **n <= 0.0).count();
        let origin = match state {
            ContactState::Stuck if keeps_ic => "ic",
            ContactState::Stuck => "hist",
            _ => "-",
        };
        line.push_str(&format!(
            " | {} T0 {t0:+.4e} {origin} margin {margin:.2e} open {open}",
            state.label()
        ));
    }
    line
}
