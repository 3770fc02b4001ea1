//! The generated blade pairs of the FE tests, written into a test's temporary folder.

use fricbound::fe::blade_pair::{generate, BladePairParams};
use fricbound::fe::msh_write::{write_msh, MshFormat};
use fricbound::model::Problem;
use fricbound::scene;
use fricbound::study::scaling::{self, blade_pair_scene};
use std::path::Path;

/// Scene text of the reduced 2D blade pair (mesh written into `dir`):
/// [`scaling::small_reduced_blade_pair_scene`].
pub fn reduced_blade_pair_2d(dir: &Path) -> String {
    scaling::small_reduced_blade_pair_scene(dir).expect("blade pair mesh")
}

/// The unreduced blade pair on the generator's coarsest mesh (2D, or 3D with `three_d`), 2
/// node pairs per side, written into `dir`, with the fields `patch_fields` (TOML lines, each
/// ending in a newline) added to every contact patch; the scene's errors as text.
pub fn coarse_blade_pair(dir: &Path, three_d: bool, patch_fields: &str) -> Result<Problem, String> {
    let mesh = generate(&BladePairParams {
        three_d,
        refine: 1,
        contact_pairs: Some(2),
        ..BladePairParams::default()
    })
    .unwrap();
    let file = dir.join("blade-pair.msh");
    write_msh(&file, &mesh, MshFormat::Binary).unwrap();
    // Named relative to the scene's folder (`dir`), where both live.
    let base = blade_pair_scene(Path::new("blade-pair.msh"), three_d, 1);
    let anchor = "tolerance = 1e-6\n";
    assert_eq!(base.matches(anchor).count(), 2, "one anchor per patch");
    let text = base.replace(anchor, &format!("{anchor}{patch_fields}"));
    let label = dir.join("scene.toml").display().to_string();
    scene::parse(&text, &label, &[])
        .and_then(|s| s.validate(&label))
        .map_err(|e| e.to_string())
}
