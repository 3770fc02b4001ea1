//! Writes the small generated blade pair of `tests/it/error_estimate_fe.rs` (2 contact pairs per
//! side, 8 interior Craig-Bampton modes; [`common::SmallBladePair`]) into a folder, so that
//! `fricbound run` can be pointed at it: its mesh `blade-pair-2d-r1-p2.msh` and its scene
//! `blade-pair.toml`.
//!
//! Run: `cargo run --release --example small_blade_pair_scene -- DIR`, then e.g.
//! `fricbound run DIR/blade-pair.toml --set analysis.freq_start_hz=928 --set
//! analysis.freq_end_hz=936 --set harmonics.samples=128 --set harmonics.max=3`.

mod common;

fn main() {
    let Some(dir) = std::env::args().nth(1) else {
        eprintln!("usage: small_blade_pair_scene DIR");
        std::process::exit(2);
    };
    let dir = std::path::PathBuf::from(dir);
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("{}: {e}", dir.display());
        std::process::exit(1);
    }
    common::write_small_blade_pair(&dir);
    println!("{}", dir.join("blade-pair.toml").display());
}
