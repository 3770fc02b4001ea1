//! The 3D paper scene (`jenkins-2d` friction, out-of-plane motion constrained) against the
//! planar one: the two scenes, the DOF maps between them, and the comparison of their harmonic
//! coefficients and FRF points.

use fricbound::analysis::frf::{self, FrfPoint, PointSolver, Silent};
use fricbound::model::{Formulation, HarmonicLoad, Problem};

/// The planar paper scene (Fig. 13, 3rd resonance).
pub const PLANAR: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/meshes/paper-wedge/fig13-3rd.toml"
));
/// Its 3D version with 2D friction and the out-of-plane motion constrained.
pub const SPATIAL: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/meshes/paper-wedge-3d/fig13-3rd-3d.toml"
));

/// The planar scene with overrides, its 1D contacts on the event-resolved law like the 3D
/// scene's `jenkins-2d` ones: the two scenes agree to round-off only on the same time
/// resolution (a sampled law differs from the event-resolved ones by its sampling error).
pub fn planar(overrides: &[&str]) -> Problem {
    super::scenes::problem(PLANAR, overrides)
}

/// In-plane DOFs of the 3D scene, in the order of the planar scene's DOFs.
pub const IN_PLANE: [usize; 6] = [0, 1, 3, 4, 6, 7];
/// Out-of-plane DOFs of the 3D scene.
pub const OUT_OF_PLANE: [usize; 3] = [2, 5, 8];

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

/// Solves the planar and the 3D problem at `count − 1` frequencies evenly inside (lo, hi) (Hz),
/// each from the same guess on the planar FRF path, and asserts that the 3D coefficients equal
/// the planar ones to `tolerance` ([`assert_spatial_equals_planar`]) and the contact states
/// agree. Returns the largest in-plane difference relative to the scale and the solution
/// pairs (planar, 3D).
pub fn compare_on_planar_path(
    planar: &Problem,
    spatial: &Problem,
    (lo, hi): (f64, f64),
    count: usize,
    tolerance: f64,
) -> (f64, Vec<(FrfPoint, FrfPoint)>) {
    let run = frf::solve(planar, &mut Silent).unwrap();
    let mut flat = PointSolver::new(planar).unwrap();
    let mut solid = PointSolver::new(spatial).unwrap();
    let mut largest = 0.0_f64;
    let mut pairs = Vec::new();
    for i in 1..count {
        let f = lo + (hi - lo) * i as f64 / count as f64;
        let guess = frf::interpolate_on_path(&run.points, f).unwrap();
        let a = flat.solve(&guess, f).unwrap();
        let b = solid.solve(&to_spatial(&guess), f).unwrap();
        let what = format!("{f:.3} Hz");
        largest = largest.max(assert_spatial_equals_planar(
            &a.coefficients,
            &b.coefficients,
            tolerance,
            &what,
        ));
        assert_eq!(a.states, b.states, "{what}");
        pairs.push((a, b));
    }
    (largest, pairs)
}

/// Overrides of the 3D cases with out-of-plane excitation: 150-185 Hz, H = 3, 128 samples.
pub const OUT_OF_PLANE_RUN: [&str; 4] = [
    "analysis.freq_start_hz=150",
    "analysis.freq_end_hz=185",
    "harmonics.max=3",
    "harmonics.samples=128",
];

/// `p` (the 3D scene) with an out-of-plane load on blade 1 (10 N cos ωt on z₁, DOF 2), which
/// takes the contact paths off the t₁ direction, solved with `formulation`.
pub fn excited_out_of_plane(mut p: Problem, formulation: Formulation) -> Problem {
    p.harmonic_loads.push(HarmonicLoad {
        dof: 2,
        harmonic: 1,
        cos: 10.0,
        sin: 0.0,
    });
    p.analysis.formulation = formulation;
    p
}

/// Solves a point at `freq_hz` from `guess` with the `reference` solver and with a solver of
/// every variant (the same scene in other formulations), and asserts that each gives the
/// reference's coefficients to 1e-8 of their largest and the same contact states. Returns the
/// reference's solution.
pub fn assert_formulations_agree(
    reference: &mut PointSolver,
    variants: &[(&str, Problem)],
    guess: &[f64],
    freq_hz: f64,
) -> FrfPoint {
    let a = reference.solve(guess, freq_hz).unwrap();
    for (name, variant) in variants {
        let b = PointSolver::new(variant)
            .unwrap()
            .solve(guess, freq_hz)
            .unwrap();
        super::points::assert_same_point(&a, &b, &format!("{name} at {freq_hz:.3} Hz"));
    }
    a
}
