//! Helpers shared by the test crates that compare the 3D paper scene (`jenkins-2d` friction,
//! out-of-plane motion constrained) with the planar one: the two scenes, the DOF maps between
//! them, and the comparison of their harmonic coefficients. Each test crate uses a part of it.
#![allow(dead_code)]

use fricbound::model::Problem;
use fricbound::scene;

/// The planar paper scene (Fig. 13, 3rd resonance).
pub const PLANAR: &str = include_str!("../../meshes/paper-wedge/fig13-3rd.toml");
/// Its 3D version with 2D friction and the out-of-plane motion constrained.
pub const SPATIAL: &str = include_str!("../../meshes/paper-wedge-3d/fig13-3rd-3d.toml");

/// In-plane DOFs of the 3D scene, in the order of the planar scene's DOFs.
pub const IN_PLANE: [usize; 6] = [0, 1, 3, 4, 6, 7];
/// Out-of-plane DOFs of the 3D scene.
pub const OUT_OF_PLANE: [usize; 3] = [2, 5, 8];

/// A validated scene with `--set`-style overrides.
pub fn problem(text: &str, overrides: &[&str]) -> Problem {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::parse(text, "scene", &o)
        .unwrap()
        .validate("scene")
        .unwrap()
}

/// Planar coefficients (6 DOFs per block) placed on the 3D layout (9 DOFs per block, z = 0).
pub fn to_spatial(x: &[f64]) -> Vec<f64> {
    let blocks = x.len() / 6;
    let mut out = vec![0.0; 9 * blocks];
    for j in 0..blocks {
        for (k, &d) in IN_PLANE.iter().enumerate() {
            out[9 * j + d] = x[6 * j + k];
        }
    }
    out
}

/// Asserts that the 3D coefficients equal the planar ones in plane to `tolerance` of the
/// largest planar coefficient and vanish out of plane (to 10⁻¹² of it); returns the largest
/// in-plane difference relative to that scale. `what` names the point in failure messages.
pub fn assert_spatial_equals_planar(
    planar: &[f64],
    spatial: &[f64],
    tolerance: f64,
    what: &str,
) -> f64 {
    let scale = planar.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut largest = 0.0_f64;
    for j in 0..planar.len() / 6 {
        for (k, &d) in IN_PLANE.iter().enumerate() {
            let diff = (planar[6 * j + k] - spatial[9 * j + d]).abs();
            largest = largest.max(diff / scale);
            assert!(
                diff <= tolerance * scale,
                "{what}, block {j}, DOF {d}: {diff:.3e} (scale {scale:.3e})"
            );
        }
        for &d in &OUT_OF_PLANE {
            assert!(
                spatial[9 * j + d].abs() <= 1e-12 * scale,
                "{what}, block {j}, out-of-plane DOF {d}: {:.3e}",
                spatial[9 * j + d]
            );
        }
    }
    largest
}
