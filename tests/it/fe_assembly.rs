//! Element assembly checked against exact and analytic results: patch tests on distorted
//! meshes, rigid-body modes, mass totals, cantilever deflection and frequencies against beam
//! theory, clamping and bad input.

use crate::fe_support;

use fe_support::{box_mesh, hz, lowest_eigenvalues, solve, Family};
use fricbound::fe::assembly::{assemble, AssemblyError, FeModel, GroupMaterial};
use fricbound::fe::material::{Material, PlaneAssumption};
use fricbound::fe::mesh::{ElementKind, Mesh, MeshBuilder};
use fricbound::fe::sparse;

const E: f64 = 210e9;
const NU: f64 = 0.3;
const RHO: f64 = 7850.0;

fn steel(t: f64) -> Material {
    Material {
        young_modulus: E,
        poisson_ratio: NU,
        density: RHO,
        thickness: t,
    }
}

fn model(mesh: &Mesh, plane: PlaneAssumption) -> FeModel {
    assemble(mesh, &[GroupMaterial::new("solid", steel(0.02))], plane).unwrap()
}

/// A linear displacement field with all strain components non-zero.
fn linear_field(p: [f64; 3], dim: usize) -> [f64; 3] {
    let u = [
        1e-3 + 2e-3 * p[0] - 1e-3 * p[1] + 0.5e-3 * p[2],
        -2e-3 + 0.7e-3 * p[0] + 1.5e-3 * p[1] - 0.4e-3 * p[2],
        0.3e-3 + 0.2e-3 * p[0] + 0.9e-3 * p[1] + 1.1e-3 * p[2],
    ];
    if dim == 2 {
        [u[0], u[1], 0.0]
    } else {
        u
    }
}

/// Patch test: the linear field imposed on the boundary nodes is reproduced exactly at the
/// (distorted) interior nodes.
fn patch_test(family: Family, plane: PlaneAssumption) {
    let n = if family == Family::Hexes {
        [3, 3, 3]
    } else {
        [4, 3, 1]
    };
    let mesh = box_mesh(family, [1.0, 0.8, 0.6], n, 0.3, 11);
    let full = model(&mesh, plane);
    let dim = full.dimension;
    let index = mesh.node_index_map();
    let pos = |node: u64| mesh.nodes[index[&node]].coords;
    let on_boundary = |p: [f64; 3]| {
        let size = [1.0, 0.8, 0.6];
        (0..dim).any(|c| p[c].abs() < 1e-12 || (p[c] - size[c]).abs() < 1e-12)
    };
    let exact: Vec<f64> = full
        .dofs
        .dofs()
        .iter()
        .map(|d| linear_field(pos(d.node), dim)[d.direction.axis()])
        .collect();
    let prescribed: Vec<f64> = full
        .dofs
        .dofs()
        .iter()
        .zip(&exact)
        .map(|(d, &u)| if on_boundary(pos(d.node)) { u } else { 0.0 })
        .collect();
    let reaction = sparse::mul_vec(&full.stiffness, &prescribed);
    let interior = full.without_dofs(|d| on_boundary(pos(d.node)));
    assert!(
        interior.dofs.len() >= dim * 2,
        "the patch needs interior nodes"
    );
    let rhs: Vec<f64> = interior
        .dofs
        .dofs()
        .iter()
        .map(|d| -reaction[full.dofs.row(d.node, d.direction).unwrap()])
        .collect();
    let u = solve(&interior.stiffness, &rhs);
    for (row, d) in interior.dofs.dofs().iter().enumerate() {
        let want = exact[full.dofs.row(d.node, d.direction).unwrap()];
        assert!(
            (u[row] - want).abs() < 1e-12,
            "{family:?} {plane:?}: DOF {d}: {} vs exact {want}",
            u[row]
        );
    }
}

#[test]
fn patch_test_quads_distorted() {
    patch_test(Family::Quads, PlaneAssumption::Stress);
    patch_test(Family::Quads, PlaneAssumption::Strain);
}

#[test]
fn patch_test_triangles_distorted() {
    patch_test(Family::Triangles, PlaneAssumption::Stress);
    patch_test(Family::Triangles, PlaneAssumption::Strain);
}

#[test]
fn patch_test_hexes_distorted() {
    patch_test(Family::Hexes, PlaneAssumption::Stress);
}

/// A rigid-body displacement field u(x).
type RigidMode = Box<dyn Fn([f64; 3]) -> [f64; 3]>;

#[test]
fn rigid_body_modes_give_zero_forces() {
    for family in [Family::Quads, Family::Triangles, Family::Hexes] {
        let mesh = box_mesh(family, [1.0, 0.5, 0.4], [4, 3, 2], 0.3, 5);
        let m = model(&mesh, PlaneAssumption::Stress);
        let dim = m.dimension;
        let index = mesh.node_index_map();
        let scale = sparse::max_abs(&m.stiffness);
        // Translations, then rotations about z (and x, y in 3D): u = ω × x.
        let mut modes: Vec<RigidMode> = Vec::new();
        for c in 0..dim {
            modes.push(Box::new(move |_| {
                let mut u = [0.0; 3];
                u[c] = 1.0;
                u
            }));
        }
        modes.push(Box::new(|p| [-p[1], p[0], 0.0]));
        if dim == 3 {
            modes.push(Box::new(|p| [0.0, -p[2], p[1]]));
            modes.push(Box::new(|p| [p[2], 0.0, -p[0]]));
        }
        for (k, mode) in modes.iter().enumerate() {
            let u: Vec<f64> = m
                .dofs
                .dofs()
                .iter()
                .map(|d| mode(mesh.nodes[index[&d.node]].coords)[d.direction.axis()])
                .collect();
            let f = sparse::mul_vec(&m.stiffness, &u);
            let worst = f.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            assert!(
                worst < 1e-12 * scale,
                "{family:?} rigid mode {k}: force {worst:e} (scale {scale:e})"
            );
        }
    }
}

#[test]
fn mass_total_equals_density_times_volume() {
    let size = [0.3, 0.2, 0.1];
    for family in [Family::Quads, Family::Triangles, Family::Hexes] {
        let mesh = box_mesh(family, size, [5, 4, 3], 0.3, 9);
        let m = model(&mesh, PlaneAssumption::Stress);
        let dim = m.dimension;
        let volume = if dim == 2 {
            size[0] * size[1] * 0.02
        } else {
            size[0] * size[1] * size[2]
        };
        for c in 0..dim {
            let u: Vec<f64> = m
                .dofs
                .dofs()
                .iter()
                .map(|d| if d.direction.axis() == c { 1.0 } else { 0.0 })
                .collect();
            let total = sparse::quadratic_form(&m.mass, &u);
            assert!(
                (total - RHO * volume).abs() < 1e-12 * RHO * volume,
                "{family:?} direction {c}: {total} kg vs rho V = {} kg",
                RHO * volume
            );
        }
        // Exactly symmetric, not only to round-off.
        assert!(
            sparse::worst_asymmetry(&m.mass).is_none(),
            "{family:?} mass"
        );
        assert!(
            sparse::worst_asymmetry(&m.stiffness).is_none(),
            "{family:?} stiffness"
        );
    }
}

/// Cantilever clamped at x = 0 with a transverse tip force P (N) spread over the tip nodes by
/// their tributary length/area; returns the tip deflection (m) of the mid-height node(s).
fn cantilever_tip(
    family: Family,
    size: [f64; 3],
    n: [usize; 3],
    force: f64,
) -> (f64, FeModel, Mesh) {
    let mesh = box_mesh(family, size, n, 0.0, 1);
    let full = assemble(
        &mesh,
        &[GroupMaterial::new("solid", steel(size[2]))],
        PlaneAssumption::Stress,
    )
    .unwrap();
    let clamped = full.clamp_group(&mesh, "root").unwrap();
    let tip_nodes = mesh.group_nodes("tip").unwrap();
    // Tributary weights on the tip face: product of 1D trapezoid weights.
    let weight = |p: [f64; 3]| {
        let edge = |x: f64, len: f64, div: usize| {
            if x.abs() < 1e-12 || (x - len).abs() < 1e-12 {
                0.5 / div as f64
            } else {
                1.0 / div as f64
            }
        };
        let wy = edge(p[1], size[1], n[1]);
        if family == Family::Hexes {
            wy * edge(p[2], size[2], n[2])
        } else {
            wy
        }
    };
    let mut f = vec![0.0; clamped.dofs.len()];
    for &i in &tip_nodes {
        let node = &mesh.nodes[i];
        let row = clamped
            .dofs
            .row(node.id, fricbound::fe::Direction::Y)
            .unwrap();
        f[row] += force * weight(node.coords);
    }
    let u = solve(&clamped.stiffness, &f);
    // Mean deflection of the tip nodes on the mid-height line.
    let mid: Vec<f64> = tip_nodes
        .iter()
        .filter(|&&i| (mesh.nodes[i].coords[1] - size[1] / 2.0).abs() < 1e-12)
        .map(|&i| {
            u[clamped
                .dofs
                .row(mesh.nodes[i].id, fricbound::fe::Direction::Y)
                .unwrap()]
        })
        .collect();
    let tip = mid.iter().sum::<f64>() / mid.len() as f64;
    (tip, clamped, mesh)
}

/// Timoshenko beam tip deflection under a tip force: P L³/(3 E I) + P L/(κ G A), with Cowper's
/// shear coefficient κ = 10 (1 + ν)/(12 + 11 ν) for a rectangle.
fn timoshenko_tip(force: f64, length: f64, height: f64, width: f64) -> f64 {
    let i = width * height.powi(3) / 12.0;
    let a = width * height;
    let g = E / (2.0 * (1.0 + NU));
    let kappa = 10.0 * (1.0 + NU) / (12.0 + 11.0 * NU);
    force * length.powi(3) / (3.0 * E * i) + force * length / (kappa * g * a)
}

fn check_convergence(label: &str, errors: &[f64], tolerance: f64) {
    for w in errors.windows(2) {
        assert!(w[1] < w[0], "{label}: error does not decrease: {errors:?}");
    }
    let last = *errors.last().unwrap();
    assert!(
        last < tolerance,
        "{label}: final error {last:.4} above {tolerance}: {errors:?}"
    );
}

#[test]
fn cantilever_tip_deflection_converges_quads_and_triangles() {
    // L/h = 40, plane stress, thickness 0.01 m.
    let size = [0.4, 0.01, 0.01];
    let p = 10.0;
    let reference = timoshenko_tip(p, size[0], size[1], size[2]);
    for (family, tolerance) in [(Family::Quads, 0.01), (Family::Triangles, 0.03)] {
        let levels: &[usize] = if family == Family::Quads {
            &[2, 4, 8]
        } else {
            &[2, 4, 8, 16]
        };
        let errors: Vec<f64> = levels
            .iter()
            .map(|&ny| {
                let (tip, _, _) = cantilever_tip(family, size, [40 * ny, ny, 1], p);
                (tip - reference).abs() / reference
            })
            .collect();
        println!(
            "{family:?} tip deflection relative errors {errors:?} (reference {reference:e} m)"
        );
        check_convergence(&format!("{family:?} tip deflection"), &errors, tolerance);
    }
}

#[test]
fn cantilever_tip_deflection_converges_hexes() {
    // L/h = 20, 3D, width 0.02 m (z), bending in y.
    let size = [0.2, 0.01, 0.02];
    let p = 10.0;
    let reference = timoshenko_tip(p, size[0], size[1], size[2]);
    let errors: Vec<f64> = [1usize, 2, 4]
        .iter()
        .map(|&k| {
            let (tip, _, _) = cantilever_tip(Family::Hexes, size, [40 * k, 2 * k, 2 * k], p);
            (tip - reference).abs() / reference
        })
        .collect();
    println!("Hexes tip deflection relative errors {errors:?} (reference {reference:e} m)");
    // Beam theory leaves out the 3D effects of a short (L/h = 20), wide (b = 2h) beam with a
    // fully clamped root section, which stiffen it by about a percent.
    check_convergence("hex tip deflection", &errors, 0.025);
}

/// Euler-Bernoulli cantilever bending frequencies (Hz): (β_i L)² / (2π L²) √(E I / (ρ A)).
fn euler_bernoulli_hz(length: f64, height: f64, mode: usize) -> f64 {
    let beta_l = [1.875_104_068_711_961, 4.694_091_132_974_175][mode];
    let ei_over_rho_a = E * height * height / (12.0 * RHO);
    beta_l * beta_l / (2.0 * std::f64::consts::PI * length * length) * ei_over_rho_a.sqrt()
}

#[test]
fn cantilever_bending_frequencies_converge_quads() {
    // L/h = 40: shear and rotary inertia lower the 2nd frequency by about 0.25 % against
    // Euler-Bernoulli; the tolerance allows for that.
    let size = [0.4, 0.01, 0.01];
    let mut errors = [Vec::new(), Vec::new()];
    for ny in [2usize, 4, 8] {
        let (_, clamped, _) = cantilever_tip(Family::Quads, size, [40 * ny, ny, 1], 0.0);
        let f = hz(&lowest_eigenvalues(&clamped.stiffness, &clamped.mass, 2));
        for mode in 0..2 {
            let reference = euler_bernoulli_hz(size[0], size[1], mode);
            errors[mode].push((f[mode] - reference).abs() / reference);
        }
        println!("ny {ny}: {f:?} Hz");
    }
    check_convergence("quad mode 1", &errors[0], 0.01);
    check_convergence("quad mode 2", &errors[1], 0.015);
}

#[test]
fn cantilever_bending_frequencies_converge_hexes() {
    // 3D beam of width 2h: the lowest modes are the 1st bending in y, then the 1st in z
    // (twice the frequency, since the width is twice the height).
    let size = [0.2, 0.01, 0.02];
    let mut errors = [Vec::new(), Vec::new()];
    for k in [1usize, 2, 4] {
        let (_, clamped, _) = cantilever_tip(Family::Hexes, size, [40 * k, 2 * k, 2 * k], 0.0);
        let f = hz(&lowest_eigenvalues(&clamped.stiffness, &clamped.mass, 2));
        let references = [
            euler_bernoulli_hz(size[0], size[1], 0),
            euler_bernoulli_hz(size[0], size[2], 0),
        ];
        for mode in 0..2 {
            errors[mode].push((f[mode] - references[mode]).abs() / references[mode]);
        }
        println!("k {k}: {f:?} Hz vs {references:?}");
    }
    check_convergence("hex 1st y-bending", &errors[0], 0.025);
    check_convergence("hex 1st z-bending", &errors[1], 0.025);
}

#[test]
fn clamping_removes_the_group_dofs_and_renumbers() {
    let mesh = box_mesh(Family::Quads, [1.0, 0.2, 0.0], [5, 2, 1], 0.0, 1);
    let full = model(&mesh, PlaneAssumption::Stress);
    let clamped = full.clamp_group(&mesh, "root").unwrap();
    let root = mesh.group_nodes("root").unwrap();
    assert_eq!(clamped.dofs.len(), full.dofs.len() - 2 * root.len());
    assert_eq!(clamped.stiffness.nrows(), clamped.dofs.len());
    assert_eq!(clamped.mass.ncols(), clamped.dofs.len());
    for &i in &root {
        assert!(clamped
            .dofs
            .row(mesh.nodes[i].id, fricbound::fe::Direction::X)
            .is_none());
    }
    // Every kept entry is the same entry of the full matrices.
    for (r, dr) in clamped.dofs.dofs().iter().enumerate() {
        for (c, dc) in clamped.dofs.dofs().iter().enumerate() {
            let (fr, fc) = (
                full.dofs.row(dr.node, dr.direction).unwrap(),
                full.dofs.row(dc.node, dc.direction).unwrap(),
            );
            assert_eq!(
                sparse::get(&clamped.stiffness, r, c),
                sparse::get(&full.stiffness, fr, fc)
            );
        }
    }
    let err = full.clamp_group(&mesh, "nowhere").unwrap_err();
    assert!(
        err.to_string()
            .contains("no physical group named `nowhere`"),
        "{err}"
    );
}

#[test]
fn element_without_material_is_an_error() {
    let mut b = MeshBuilder::new("two parts");
    let n: Vec<usize> = [
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [2.0, 0.0],
        [2.0, 1.0],
    ]
    .iter()
    .map(|p| b.add_node([p[0], p[1], 0.0]))
    .collect();
    b.add_group("left", ElementKind::Quad4, &[vec![n[0], n[1], n[2], n[3]]]);
    b.add_group("right", ElementKind::Quad4, &[vec![n[1], n[4], n[5], n[2]]]);
    b.add_group("edge", ElementKind::Line2, &[vec![n[0], n[3]]]);
    let mesh = b.finish();
    let err = assemble(
        &mesh,
        &[GroupMaterial::new("left", steel(0.01))],
        PlaneAssumption::Stress,
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "two parts: 1 2D element(s) belong to no material group (first: element 2); material \
         groups: left"
    );
    let err = assemble(
        &mesh,
        &[GroupMaterial::new("edge", steel(0.01))],
        PlaneAssumption::Stress,
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("group `edge` (dimension 1) holds no 2D element"),
        "{err}"
    );
    let err = assemble(
        &mesh,
        &[
            GroupMaterial::new("left", steel(0.01)),
            GroupMaterial::new("right", steel(0.01)),
            GroupMaterial::new("blade", steel(0.01)),
        ],
        PlaneAssumption::Stress,
    )
    .unwrap_err();
    assert!(matches!(err, AssemblyError::Mesh(_)));
    assert!(err
        .to_string()
        .contains("no physical group named `blade` (groups: left, right, edge)"));
    let mut bad = steel(0.01);
    bad.young_modulus = f64::NAN;
    let err = assemble(
        &mesh,
        &[
            GroupMaterial::new("left", bad),
            GroupMaterial::new("right", steel(0.01)),
        ],
        PlaneAssumption::Stress,
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("material of group `left`: Young's modulus NaN"),
        "{err}"
    );
}

#[test]
fn self_intersecting_element_is_named() {
    let mut b = MeshBuilder::new("bow-tie");
    let n: Vec<usize> = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]
        .iter()
        .map(|p| b.add_node([p[0], p[1], 0.0]))
        .collect();
    b.add_group("solid", ElementKind::Quad4, &[n]);
    let err = assemble(
        &b.finish(),
        &[GroupMaterial::new("solid", steel(0.01))],
        PlaneAssumption::Stress,
    )
    .unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.starts_with(
            "bow-tie: element 1 (4-node quadrangle) in group `solid`: Jacobian determinant -"
        ),
        "{msg}"
    );
}

#[test]
fn clockwise_2d_elements_assemble_like_counter_clockwise_ones() {
    for family in [Family::Quads, Family::Triangles] {
        let mesh = box_mesh(family, [1.0, 0.5, 0.0], [3, 2, 1], 0.2, 3);
        let mut flipped = mesh.clone();
        for e in &mut flipped.elements {
            if e.kind.dimension() == 2 {
                e.nodes.reverse();
            }
        }
        let (a, b) = (
            model(&mesh, PlaneAssumption::Stress),
            model(&flipped, PlaneAssumption::Stress),
        );
        assert_eq!(a.dofs, b.dofs);
        for (x, y) in [(&a.stiffness, &b.stiffness), (&a.mass, &b.mass)] {
            sparse::for_each_entry(x, |r, c, v| {
                assert!((sparse::get(y, r, c) - v).abs() <= 1e-9 * v.abs().max(1.0));
            });
        }
    }
}

#[test]
fn body_force_is_the_consistent_load_of_a_uniform_acceleration() {
    let mesh = box_mesh(Family::Quads, [0.4, 0.1, 0.0], [8, 2, 1], 0.25, 4);
    let m = model(&mesh, PlaneAssumption::Stress);
    let f = m
        .body_force(&mesh, "solid", [0.0, 2.0, 0.0], 120.0)
        .unwrap();
    // Total 120 N along +y, nothing along x.
    let total = |axis: usize| -> f64 {
        f.iter()
            .zip(m.dofs.dofs())
            .filter(|(_, d)| d.direction.axis() == axis)
            .map(|(v, _)| v)
            .sum()
    };
    assert!((total(1) - 120.0).abs() < 1e-9);
    assert!(total(0).abs() < 1e-12);
    // Its moment about the origin is that of 120 N at the centroid x = 0.2 m.
    let index = mesh.node_index_map();
    let moment: f64 = f
        .iter()
        .zip(m.dofs.dofs())
        .map(|(v, d)| {
            v * mesh.nodes[index[&d.node]].coords[0] * (d.direction.axis() == 1) as u8 as f64
        })
        .sum();
    assert!((moment - 120.0 * 0.2).abs() < 1e-9, "{moment}");
    let rows = m
        .group_rows(&mesh, "tip", fricbound::fe::Direction::X)
        .unwrap();
    assert_eq!(rows.len(), 3);
    let err = m.body_force(&mesh, "solid", [0.0; 3], 1.0).unwrap_err();
    assert!(err.to_string().contains("non-zero direction"), "{err}");
    let clamped = m.clamp_group(&mesh, "root").unwrap();
    let err = clamped
        .group_rows(&mesh, "root", fricbound::fe::Direction::Y)
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("of group `root` has no y DOF in the model"),
        "{err}"
    );
}
