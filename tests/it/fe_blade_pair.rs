//! The blade-pair generator: counts against the divisions, groups, contact pairs on both damper
//! sides, clamping, the free damper's rigid-body modes, 3D extrusion, VTU output and the
//! `mesh` command.

use faer::{Mat, Side};
use fricbound::cli::mesh::{run, BladePairArgs, MeshCommand};
use fricbound::fe::assembly::{assemble, dof_map, FeModel, GroupMaterial};
use fricbound::fe::blade_pair::{generate, BladePairParams, CONTACT_FRACTION};
use fricbound::fe::contact_patch::pair_patch;
use fricbound::fe::material::{Material, PlaneAssumption};
use fricbound::fe::mesh::{ElementKind, Mesh};
use fricbound::fe::msh_read::read_msh;
use fricbound::fe::sparse;
use fricbound::fe::vtu::{write_vtu, PointField};
use fricbound::fe::Direction;

fn materials(thickness: f64) -> Vec<GroupMaterial> {
    ["blade1", "blade2", "damper"]
        .iter()
        .map(|g| GroupMaterial::new(g, Material::steel(thickness)))
        .collect()
}

fn assembled(params: &BladePairParams) -> (Mesh, FeModel) {
    let mesh = generate(params).unwrap();
    let model = assemble(&mesh, &materials(params.thickness), PlaneAssumption::Stress).unwrap();
    (mesh, model)
}

fn count(mesh: &Mesh, kind: ElementKind) -> usize {
    mesh.elements.iter().filter(|e| e.kind == kind).count()
}

#[test]
fn node_and_element_counts_follow_the_divisions() {
    let cases = [
        (1, None),
        (2, None),
        (3, None),
        (1, Some(2)),
        (2, Some(3)),
        (2, Some(11)),
    ];
    for (refine, contact_pairs) in cases {
        let params = BladePairParams {
            refine,
            contact_pairs,
            ..BladePairParams::default()
        };
        let d = params.divisions().unwrap();
        let mesh = generate(&params).unwrap();
        let [n1, nt, n3] = d.blade_y;
        let ny = n1 + nt + n3;
        let platform_x = d.platform_free + d.contact;
        // Per blade: blade grid plus the platform grid minus its shared root column.
        let blade_nodes = (d.blade_x + 1) * (ny + 1) + platform_x * (nt + 1);
        let blade_quads = d.blade_x * ny + platform_x * nt;
        // Damper: two x×y patches and one y×y patch, sharing three edges (x, y, y
        // divisions) and the centroid.
        let [x, y] = d.damper;
        let damper_nodes = 2 * (x + 1) * (y + 1) + (y + 1) * (y + 1) - (x + 1) - 2 * (y + 1) + 1;
        assert_eq!(
            mesh.nodes.len(),
            2 * blade_nodes + damper_nodes,
            "refine {refine}"
        );
        assert_eq!(
            count(&mesh, ElementKind::Quad4),
            2 * blade_quads + 2 * x * y + y * y
        );
        if let Some(pairs) = contact_pairs {
            assert_eq!(d.contact, pairs - 1);
            assert_eq!(x, pairs - 1, "the face splits at the contact end");
        }
        assert_eq!(
            count(&mesh, ElementKind::Line2),
            2 * d.blade_x + 4 * d.contact,
            "clamp lines and four contact faces"
        );
        assert_eq!(count(&mesh, ElementKind::Point), 2);
        assert_eq!(dof_map(&mesh).unwrap().len(), 2 * mesh.nodes.len());
    }
}

#[test]
fn dof_counts_in_the_module_doc() {
    // The doc table of fricbound::fe::blade_pair quotes these.
    let dofs = |refine, three_d| {
        let mesh = generate(&BladePairParams {
            refine,
            three_d,
            ..BladePairParams::default()
        })
        .unwrap();
        dof_map(&mesh).unwrap().len()
    };
    assert_eq!(dofs(1, false), 1586);
    assert_eq!(dofs(2, false), 5046);
    assert_eq!(dofs(3, false), 11474);
    assert_eq!(dofs(1, true), 16653);
}

#[test]
fn groups_are_present_with_their_dimensions() {
    for three_d in [false, true] {
        let mesh = generate(&BladePairParams {
            three_d,
            ..BladePairParams::default()
        })
        .unwrap();
        let solid = if three_d { 3 } else { 2 };
        for (name, dim) in [
            ("blade1", solid),
            ("blade2", solid),
            ("damper", solid),
            ("clamp", solid - 1),
            ("damper_left", solid - 1),
            ("platform_left", solid - 1),
            ("damper_right", solid - 1),
            ("platform_right", solid - 1),
            ("excitation", 0),
            ("response", 0),
        ] {
            let g = mesh.group(name).unwrap();
            assert_eq!(g.dim, dim, "{name} (3d {three_d})");
            assert!(!mesh.group_elements(name).unwrap().is_empty(), "{name}");
        }
        // Clamp nodes at the roots, tips at the blade length, mirror images of each other.
        let params = BladePairParams::default();
        assert!(mesh
            .group_nodes("clamp")
            .unwrap()
            .iter()
            .all(|&n| mesh.nodes[n].coords[1] == 0.0));
        let exc = mesh.nodes[mesh.group_nodes("excitation").unwrap()[0]].coords;
        let resp = mesh.nodes[mesh.group_nodes("response").unwrap()[0]].coords;
        assert_eq!(exc[1], params.blade_length);
        assert_eq!(exc[0], params.blade_width / 2.0);
        assert_eq!(resp[1], params.blade_length);
        if three_d {
            assert!((exc[2] - params.thickness / 2.0).abs() < 1e-15);
        }
    }
}

#[test]
fn contact_pairs_on_both_sides_2d() {
    let params = BladePairParams {
        refine: 2,
        ..BladePairParams::default()
    };
    let (mesh, model) = assembled(&params);
    let d = params.divisions().unwrap();
    let alpha = (180.0 - params.beta_deg).to_radians() / 2.0;
    let face = (params.damper_width / 2.0) / alpha.cos();
    let specs = params.patch_specs().unwrap();
    let mut counts = Vec::new();
    for (spec, sign) in specs.iter().zip([-1.0, 1.0]) {
        let patch = pair_patch(&mesh, &model.dofs, spec).unwrap();
        assert_eq!(patch.side, spec.side);
        assert_eq!(patch.pairs.len(), d.contact + 1);
        counts.push(patch.pairs.len());
        // Total area = contact length × thickness.
        let area = CONTACT_FRACTION * face * params.thickness;
        assert!(
            (patch.area() - area).abs() < 1e-12 * area,
            "{} vs {area}",
            patch.area()
        );
        for (k, pair) in patch.pairs.iter().enumerate() {
            assert_eq!(pair.name, format!("{}-{}", spec.side, k + 1));
            assert!(
                pair.node_distance < 1e-15,
                "pair {} distance {}",
                pair.name,
                pair.node_distance
            );
            assert_ne!(pair.damper_node, pair.body_node);
            // Normal outward from the damper into the platform: up and away from the centre.
            let n = [sign * alpha.sin(), alpha.cos(), 0.0];
            for (got, want) in pair.normal.iter().zip(n) {
                assert!(
                    (got - want).abs() < 1e-12,
                    "{}: {:?}",
                    pair.name,
                    pair.normal
                );
            }
            assert!((pair.tangent[0] - pair.normal[1]).abs() < 1e-15);
            assert!((pair.tangent[1] + pair.normal[0]).abs() < 1e-15);
            // DOFs are the nodes' x, y rows.
            assert_eq!(
                pair.damper_dofs,
                model
                    .dofs
                    .node_rows(pair.damper_node, &[Direction::X, Direction::Y])
                    .unwrap()
            );
            assert_eq!(
                pair.body_dofs,
                model
                    .dofs
                    .node_rows(pair.body_node, &[Direction::X, Direction::Y])
                    .unwrap()
            );
            let (kt, kn) = pair.stiffness(1e12, 2e12);
            assert_eq!((kt, kn), (1e12 * pair.area_weight, 2e12 * pair.area_weight));
        }
        // End nodes carry half the weight of inner nodes.
        let w: Vec<f64> = patch.pairs.iter().map(|p| p.area_weight).collect();
        assert!((w[0] - 0.5 * w[1]).abs() < 1e-12 * w[1]);
        // Damper nodes are in the damper, body nodes in the blade of that side.
        let damper = mesh.group_nodes("damper").unwrap();
        let blade = mesh
            .group_nodes(if spec.side == "left" {
                "blade1"
            } else {
                "blade2"
            })
            .unwrap();
        for pair in &patch.pairs {
            assert!(damper.contains(&mesh.node_index(pair.damper_node).unwrap()));
            assert!(blade.contains(&mesh.node_index(pair.body_node).unwrap()));
        }
    }
    assert_eq!(counts[0], counts[1]);
}

#[test]
fn contact_pairs_3d_use_the_in_plane_tangent() {
    let params = BladePairParams {
        three_d: true,
        ..BladePairParams::default()
    };
    let mesh = generate(&params).unwrap();
    let dofs = dof_map(&mesh).unwrap();
    let d = params.divisions().unwrap();
    let alpha = (180.0 - params.beta_deg).to_radians() / 2.0;
    for (spec, sign) in params.patch_specs().unwrap().iter().zip([-1.0, 1.0]) {
        let patch = pair_patch(&mesh, &dofs, spec).unwrap();
        assert_eq!(patch.pairs.len(), (d.contact + 1) * (d.layers + 1));
        let face = (params.damper_width / 2.0) / alpha.cos();
        let area = CONTACT_FRACTION * face * params.thickness;
        assert!((patch.area() - area).abs() < 1e-12 * area);
        for pair in &patch.pairs {
            assert_eq!(pair.damper_dofs.len(), 3);
            let n = [sign * alpha.sin(), alpha.cos(), 0.0];
            let t = [alpha.cos(), -sign * alpha.sin(), 0.0];
            for c in 0..3 {
                assert!((pair.normal[c] - n[c]).abs() < 1e-12, "{:?}", pair.normal);
                assert!((pair.tangent[c] - t[c]).abs() < 1e-12, "{:?}", pair.tangent);
            }
        }
    }
}

#[test]
fn unmatched_patch_nodes_are_listed_with_distances() {
    let params = BladePairParams::default();
    let mut mesh = generate(&params).unwrap();
    let dofs = dof_map(&mesh).unwrap();
    let spec = &params.patch_specs().unwrap()[0];
    // Move one platform contact node 0.1 mm off the face.
    let moved = mesh.group_nodes("platform_left").unwrap()[1];
    mesh.nodes[moved].coords[1] += 1e-4;
    let id = mesh.nodes[moved].id;
    let err = pair_patch(&mesh, &dofs, spec).unwrap_err().to_string();
    assert!(
        err.contains("side `left`: 2 contact node(s) have no partner within"),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "platform_left node {id} (nearest damper_left node"
        )),
        "{err}"
    );
    assert!(err.contains("at 1.000e-4 m)"), "{err}");
}

#[test]
fn contact_errors_name_groups_and_nodes() {
    let params = BladePairParams::default();
    let mesh = generate(&params).unwrap();
    let dofs = dof_map(&mesh).unwrap();
    let mut spec = params.patch_specs().unwrap()[0].clone();
    spec.body_group = "platform_top".into();
    let err = pair_patch(&mesh, &dofs, &spec).unwrap_err().to_string();
    assert!(
        err.contains("no physical group named `platform_top`"),
        "{err}"
    );
    spec.body_group = "blade1".into();
    let err = pair_patch(&mesh, &dofs, &spec).unwrap_err().to_string();
    assert!(
        err.contains("contact face group `blade1` must hold 1D boundary elements"),
        "{err}"
    );
    // A clamped contact node has no DOF.
    let spec = params.patch_specs().unwrap()[0].clone();
    let (dofs_without, _) = dofs.retain(|d| {
        let first = mesh.nodes[mesh.group_nodes("platform_left").unwrap()[0]].id;
        d.node != first
    });
    let err = pair_patch(&mesh, &dofs_without, &spec)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("of `platform_left` has no x DOF in the model"),
        "{err}"
    );
}

#[test]
fn clamp_removes_root_dofs() {
    let (mesh, model) = assembled(&BladePairParams::default());
    let clamped = model.clamp_group(&mesh, "clamp").unwrap();
    let root = mesh.group_nodes("clamp").unwrap();
    assert_eq!(clamped.dofs.len(), model.dofs.len() - 2 * root.len());
    assert_eq!(clamped.stiffness.nrows(), clamped.dofs.len());
    for &n in &root {
        assert!(clamped.dofs.row(mesh.nodes[n].id, Direction::X).is_none());
        assert!(clamped.dofs.row(mesh.nodes[n].id, Direction::Y).is_none());
    }
    // Contacts can still be paired on the clamped model.
    for spec in BladePairParams::default().patch_specs().unwrap() {
        pair_patch(&mesh, &clamped.dofs, &spec).unwrap();
    }
}

/// Eigenvalues of the stiffness block of the damper's DOFs, ascending.
fn damper_spectrum(mesh: &Mesh, model: &FeModel) -> Vec<f64> {
    let nodes: Vec<u64> = mesh
        .group_nodes("damper")
        .unwrap()
        .into_iter()
        .map(|n| mesh.nodes[n].id)
        .collect();
    let rows: Vec<usize> = nodes
        .iter()
        .flat_map(|&id| model.dofs.node_rows(id, model.directions()).unwrap())
        .collect();
    let k = Mat::from_fn(rows.len(), rows.len(), |i, j| {
        sparse::get(&model.stiffness, rows[i], rows[j])
    });
    k.self_adjoint_eigenvalues(Side::Lower).unwrap()
}

#[test]
fn damper_is_a_free_body() {
    // The damper shares no node with the blades: its stiffness has exactly 3 rigid-body
    // modes in 2D (6 in 3D), and it is decoupled from the rest of K.
    for (three_d, rigid) in [(false, 3), (true, 6)] {
        let params = BladePairParams {
            three_d,
            ..BladePairParams::default()
        };
        let (mesh, model) = assembled(&params);
        let eig = damper_spectrum(&mesh, &model);
        let scale = eig.last().unwrap().abs();
        let zero = eig.iter().filter(|&&l| l.abs() < 1e-10 * scale).count();
        assert_eq!(
            zero,
            rigid,
            "3d {three_d}: spectrum starts {:?}",
            &eig[..rigid + 2]
        );
        assert!(eig[rigid] > 1e-6 * scale);
        let damper: std::collections::HashSet<u64> = mesh
            .group_nodes("damper")
            .unwrap()
            .into_iter()
            .map(|n| mesh.nodes[n].id)
            .collect();
        sparse::for_each_entry(&model.stiffness, |r, c, v| {
            let (a, b) = (model.dofs.dof(r).unwrap(), model.dofs.dof(c).unwrap());
            if damper.contains(&a.node) != damper.contains(&b.node) {
                assert_eq!(v, 0.0, "damper coupled to a blade at {a} / {b}");
            }
        });
    }
}

/// `contact_refine` multiplies the contact divisions alone: 3·refine·N + 1 pairs per side, the
/// blades keep their divisions, every pair is coincident and the contact area is unchanged.
#[test]
fn contact_refinement_multiplies_the_pairs_only() {
    let base = BladePairParams {
        refine: 2,
        ..BladePairParams::default()
    };
    let fine = BladePairParams {
        contact_refine: 5,
        ..base.clone()
    };
    let (d0, d1) = (base.divisions().unwrap(), fine.divisions().unwrap());
    assert_eq!(d1.contact, 5 * d0.contact);
    assert_eq!(d1.damper, [5 * d0.damper[0], 5 * d0.damper[1]]);
    assert_eq!(
        (d1.blade_x, d1.blade_y, d1.platform_free),
        (d0.blade_x, d0.blade_y, d0.platform_free)
    );
    let (mesh, model) = assembled(&fine);
    for spec in fine.patch_specs().unwrap() {
        let patch = pair_patch(&mesh, &model.dofs, &spec).unwrap();
        assert_eq!(patch.pairs.len(), 3 * 2 * 5 + 1);
        assert!(patch.pairs.iter().all(|p| p.node_distance < 1e-15));
        let (m0, b0) = assembled(&base);
        let coarse = pair_patch(&m0, &b0.dofs, &spec).unwrap();
        assert!((patch.area() - coarse.area()).abs() < 1e-12 * coarse.area());
    }
}

/// `contact_pairs` gives exactly that many coincident pairs per side over the same contact
/// area, from 2 up, in 2D and 3D; the blades keep their divisions and the damper stays one
/// free body of well-shaped elements (positive definite mass, three rigid-body modes).
#[test]
fn contact_pairs_set_the_count_directly() {
    let base = BladePairParams {
        refine: 2,
        ..BladePairParams::default()
    };
    let (m0, b0) = assembled(&base);
    for (pairs, three_d) in [(2, false), (3, false), (5, false), (200, false), (2, true)] {
        let params = BladePairParams {
            contact_pairs: Some(pairs),
            three_d,
            ..base.clone()
        };
        let d = params.divisions().unwrap();
        let d0 = base.divisions().unwrap();
        assert_eq!(
            (d.blade_x, d.blade_y, d.platform_free),
            (d0.blade_x, d0.blade_y, d0.platform_free)
        );
        let (mesh, model) = assembled(&params);
        for spec in params.patch_specs().unwrap() {
            let patch = pair_patch(&mesh, &model.dofs, &spec).unwrap();
            let per_layer = if three_d { d.layers + 1 } else { 1 };
            assert_eq!(
                patch.pairs.len(),
                pairs * per_layer,
                "{pairs} pairs, 3d {three_d}"
            );
            assert!(patch.pairs.iter().all(|p| p.node_distance < 1e-15));
            if !three_d {
                let coarse = pair_patch(&m0, &b0.dofs, &spec).unwrap();
                assert!((patch.area() - coarse.area()).abs() < 1e-12 * coarse.area());
            }
        }
        if !three_d && pairs <= 5 {
            let eig = damper_spectrum(&mesh, &model);
            let scale = eig.last().unwrap().abs();
            let zero = eig.iter().filter(|&&l| l.abs() < 1e-10 * scale).count();
            assert_eq!(zero, 3, "{pairs} pairs: spectrum starts {:?}", &eig[..5]);
        }
    }
}

#[test]
fn bad_parameters_are_rejected() {
    let bad = |p: BladePairParams| generate(&p).unwrap_err().to_string();
    let msg = bad(BladePairParams {
        beta_deg: 175.0,
        ..BladePairParams::default()
    });
    assert!(
        msg.contains("beta = 175 degrees must lie in [30, 170]"),
        "{msg}"
    );
    let msg = bad(BladePairParams {
        platform_width: 0.004,
        ..BladePairParams::default()
    });
    assert!(
        msg.contains("platform_width = 0.004 m must exceed"),
        "{msg}"
    );
    let msg = bad(BladePairParams {
        refine: 0,
        ..BladePairParams::default()
    });
    assert!(msg.contains("refine = 0"), "{msg}");
    let msg = bad(BladePairParams {
        contact_refine: 0,
        ..BladePairParams::default()
    });
    assert!(
        msg.contains("contact_refine = 0 must lie in 1..=1000"),
        "{msg}"
    );
    let msg = bad(BladePairParams {
        contact_pairs: Some(1),
        ..BladePairParams::default()
    });
    assert!(
        msg.contains("contact_pairs = 1 must lie in 2..=3001"),
        "{msg}"
    );
    let msg = bad(BladePairParams {
        contact_pairs: Some(4),
        contact_refine: 2,
        ..BladePairParams::default()
    });
    assert!(
        msg.contains(
            "contact_pairs = 4 sets the contact divisions itself: contact_refine must be 1, not 2"
        ),
        "{msg}"
    );
    let msg = bad(BladePairParams {
        thickness: f64::NAN,
        ..BladePairParams::default()
    });
    assert!(
        msg.contains("thickness = NaN m must be finite and > 0"),
        "{msg}"
    );
}

#[test]
fn other_angles_mesh_and_pair() {
    for beta in [60.0, 90.0, 150.0, 170.0] {
        let params = BladePairParams {
            beta_deg: beta,
            ..BladePairParams::default()
        };
        let (mesh, model) = assembled(&params);
        for spec in params.patch_specs().unwrap() {
            let patch = pair_patch(&mesh, &model.dofs, &spec).unwrap();
            assert!(
                patch.pairs.len() >= 4,
                "beta {beta}: {} pairs",
                patch.pairs.len()
            );
        }
    }
}

#[test]
fn vtu_output_parses_back() {
    let params = BladePairParams::default();
    let (mesh, model) = assembled(&params);
    // A displacement field (rows 0.. as values) and contact-state codes at contact nodes.
    let values: Vec<f64> = (0..model.dofs.len()).map(|r| r as f64 * 1e-6).collect();
    let vectors = model.node_vectors(&mesh, &values);
    let mut state = vec![-1.0; mesh.nodes.len()];
    for n in mesh.group_nodes("damper_left").unwrap() {
        state[n] = 2.0;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("pair.vtu");
    write_vtu(
        &path,
        &mesh,
        &[
            PointField::vectors("displacement", vectors.clone()),
            PointField::scalars("contact_state", state.clone()),
        ],
    )
    .unwrap();
    let piece = crate::support::vtu_piece(&path);
    assert_eq!(piece.num_points(), mesh.nodes.len());
    assert_eq!(piece.cells.types.len(), count(&mesh, ElementKind::Quad4));
    let points: Vec<f64> = piece.points.cast_into().unwrap();
    assert_eq!(points[3..6], mesh.nodes[1].coords);
    let arrays = crate::support::vtu_point_arrays(&piece);
    let names: Vec<&String> = arrays.keys().collect();
    assert_eq!(names, ["contact_state", "displacement"]);
    assert_eq!(arrays["displacement"].len(), 3 * mesh.nodes.len());
    assert_eq!(arrays["displacement"][3..6], vectors[1]);
    assert_eq!(arrays["contact_state"], state);
    // Wrong field length is an error naming the field.
    let err = write_vtu(&path, &mesh, &[PointField::scalars("short", vec![0.0; 3])]).unwrap_err();
    assert!(
        err.to_string()
            .contains("point field `short` has 3 values but the mesh"),
        "{err}"
    );
}

#[test]
fn mesh_command_writes_a_readable_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pair.msh");
    let vtu = dir.path().join("pair.vtu");
    let args = BladePairArgs {
        refine: 1,
        contact_refine: 2,
        contact_pairs: None,
        beta: 90.0,
        platform_width: None,
        thickness: Some(0.02),
        out: Some(out.clone()),
        three_d: false,
        binary: true,
        vtu: Some(vtu.clone()),
    };
    let two_pairs = BladePairArgs {
        contact_refine: 1,
        contact_pairs: Some(2),
        vtu: None,
        ..args.clone()
    };
    let text = run(&MeshCommand::BladePair(two_pairs)).unwrap();
    assert!(text.contains("contact side left  2 pairs"), "{text}");
    assert!(text.contains("contact side right 2 pairs"), "{text}");
    let text = run(&MeshCommand::BladePair(args)).unwrap();
    assert!(text.contains("contact side left"), "{text}");
    assert!(text.contains("DOFs"), "{text}");
    assert!(vtu.exists());
    let mesh = read_msh(&out).unwrap();
    assert!(mesh.group("damper_right").is_ok());
    let info = run(&MeshCommand::Info { file: out }).unwrap();
    assert!(info.contains("damper_left"), "{info}");
}

#[test]
fn committed_meshes_are_what_the_generator_writes() {
    use fricbound::fe::msh_write::{msh_bytes, MshFormat};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/blade-pair");
    for (file, params) in [
        (
            "blade-pair-2d.msh",
            BladePairParams {
                refine: 2,
                ..BladePairParams::default()
            },
        ),
        (
            "blade-pair-3d.msh",
            BladePairParams {
                three_d: true,
                ..BladePairParams::default()
            },
        ),
    ] {
        let committed = std::fs::read(dir.join(file)).unwrap();
        let fresh = msh_bytes(&generate(&params).unwrap(), MshFormat::Ascii).unwrap();
        assert!(
            committed == fresh,
            "{file} differs from the generator's output: regenerate it (see meshes/blade-pair/README.md)"
        );
    }
}
