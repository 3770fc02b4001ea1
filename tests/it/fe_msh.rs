//! Gmsh 4.1 input and output: files written by Gmsh itself (ASCII and binary, in
//! tests/fe_data, made from the .geo files there), write/read round trips of the hand-written
//! writer, node tags out of order, and bad files.

use std::path::{Path, PathBuf};

use fricbound::fe::assembly::{assemble, GroupMaterial};
use fricbound::fe::blade_pair::{self, BladePairParams};
use fricbound::fe::material::{Material, PlaneAssumption};
use fricbound::fe::mesh::{ElementKind, Mesh, MeshBuilder};
use fricbound::fe::msh_read::{read_msh, read_msh_bytes};
use fricbound::fe::msh_write::{msh_bytes, write_msh, MshFormat};
use fricbound::fe::sparse;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fe_data")
        .join(name)
}

/// A mesh's content independent of storage order: nodes by id, elements by id with node ids,
/// entities and groups sorted.
#[derive(Debug, PartialEq)]
struct Canonical {
    nodes: Vec<(u64, [f64; 3])>,
    elements: Vec<(u64, ElementKind, Vec<u64>, usize, i32)>,
    entities: Vec<(usize, i32, Vec<i32>)>,
    groups: Vec<(String, usize, i32)>,
}

fn canonical(mesh: &Mesh) -> Canonical {
    let mut nodes: Vec<(u64, [f64; 3])> = mesh.nodes.iter().map(|n| (n.id, n.coords)).collect();
    nodes.sort_by_key(|n| n.0);
    let mut elements: Vec<_> = mesh
        .elements
        .iter()
        .map(|e| {
            let ids = e.nodes.iter().map(|&n| mesh.nodes[n].id).collect();
            (e.id, e.kind, ids, e.entity_dim, e.entity_tag)
        })
        .collect();
    elements.sort_by_key(|e| e.0);
    let mut entities: Vec<_> = mesh
        .entities
        .iter()
        .map(|e| (e.dim, e.tag, e.physical_tags.clone()))
        .collect();
    entities.sort();
    let mut groups: Vec<_> = mesh
        .groups
        .iter()
        .map(|g| (g.name.clone(), g.dim, g.tag))
        .collect();
    groups.sort();
    Canonical {
        nodes,
        elements,
        entities,
        groups,
    }
}

/// Asserts equal content, coordinates within `tolerance` (m); reports the first difference.
fn assert_same_mesh(a: &Mesh, b: &Mesh, tolerance: f64) {
    let (ca, cb) = (canonical(a), canonical(b));
    assert_eq!(
        ca.nodes.len(),
        cb.nodes.len(),
        "node counts {} / {}",
        a.source,
        b.source
    );
    for (na, nb) in ca.nodes.iter().zip(&cb.nodes) {
        assert_eq!(na.0, nb.0, "node ids differ");
        for c in 0..3 {
            assert!(
                (na.1[c] - nb.1[c]).abs() <= tolerance,
                "node {} coordinates {:?} vs {:?}",
                na.0,
                na.1,
                nb.1
            );
        }
    }
    assert_eq!(ca.elements.len(), cb.elements.len(), "element counts");
    for (ea, eb) in ca.elements.iter().zip(&cb.elements) {
        assert_eq!(ea, eb, "elements differ");
    }
    assert_eq!(ca.entities, cb.entities, "entities differ");
    assert_eq!(ca.groups, cb.groups, "groups differ");
}

fn count(mesh: &Mesh, kind: ElementKind) -> usize {
    mesh.elements.iter().filter(|e| e.kind == kind).count()
}

#[test]
fn gmsh_ascii_plate_is_read_with_groups() {
    let mesh = read_msh(&data("plate-ascii.msh")).unwrap();
    assert_eq!(mesh.nodes.len(), 60);
    assert_eq!(count(&mesh, ElementKind::Quad4), 24);
    assert_eq!(count(&mesh, ElementKind::Triangle3), 38);
    assert_eq!(count(&mesh, ElementKind::Line2), 6);
    assert_eq!(count(&mesh, ElementKind::Point), 1);
    assert_eq!(mesh.dimension(), 2);
    let names = mesh.group_names();
    for name in ["quads", "triangles", "clamp", "tip_edge", "corner"] {
        assert!(
            names.contains(&name.to_string()),
            "{name} missing from {names:?}"
        );
    }
    let quads = mesh.group("quads").unwrap();
    assert_eq!((quads.dim, quads.tag), (2, 1));
    assert_eq!(mesh.group_elements("quads").unwrap().len(), 24);
    assert_eq!(mesh.group_elements("triangles").unwrap().len(), 38);
    // The clamp is the edge x = 0 with 4 nodes; the corner point is (0.2, 0.05).
    let clamp = mesh.group_nodes("clamp").unwrap();
    assert_eq!(clamp.len(), 4);
    assert!(clamp.iter().all(|&n| mesh.nodes[n].coords[0] == 0.0));
    let corner = mesh.group_nodes("corner").unwrap();
    assert_eq!(mesh.nodes[corner[0]].coords, [0.2, 0.05, 0.0]);
    let tip = mesh.group_nodes("tip_edge").unwrap();
    assert!(tip.iter().all(|&n| mesh.nodes[n].coords[0] == 0.2));
}

#[test]
fn gmsh_binary_plate_equals_ascii_plate() {
    let ascii = read_msh(&data("plate-ascii.msh")).unwrap();
    let binary = read_msh(&data("plate-binary.msh")).unwrap();
    // Gmsh prints 16 significant digits in ASCII; binary holds the exact doubles.
    assert_same_mesh(&ascii, &binary, 1e-16);
}

#[test]
fn gmsh_binary_hex_box_is_read_and_assembles() {
    let mesh = read_msh(&data("box-hex-binary.msh")).unwrap();
    assert_eq!(mesh.nodes.len(), 54);
    assert_eq!(count(&mesh, ElementKind::Hexahedron8), 20);
    assert_eq!(mesh.dimension(), 3);
    let root = mesh.group_nodes("root").unwrap();
    assert_eq!(root.len(), 9);
    assert!(root.iter().all(|&n| mesh.nodes[n].coords[0] == 0.0));
    let end = mesh.group_nodes("end").unwrap();
    assert!(end
        .iter()
        .all(|&n| (mesh.nodes[n].coords[0] - 0.1).abs() < 1e-15));
    let steel = Material::steel(0.0);
    let model = assemble(
        &mesh,
        &[GroupMaterial::new("solid", steel)],
        PlaneAssumption::Stress,
    )
    .unwrap();
    assert_eq!(model.dofs.len(), 162);
    let ones_y: Vec<f64> = model
        .dofs
        .dofs()
        .iter()
        .map(|d| if d.direction.axis() == 1 { 1.0 } else { 0.0 })
        .collect();
    let mass = sparse::quadratic_form(&model.mass, &ones_y);
    let expected = 7850.0 * 0.1 * 0.02 * 0.01;
    assert!(
        (mass - expected).abs() < 1e-12 * expected,
        "{mass} vs {expected}"
    );
    let clamped = model.clamp_group(&mesh, "root").unwrap();
    assert_eq!(clamped.dofs.len(), 162 - 27);
}

#[test]
fn writer_round_trip_ascii_and_binary() {
    let plate = read_msh(&data("plate-ascii.msh")).unwrap();
    let generated = blade_pair::generate(&BladePairParams::default()).unwrap();
    let generated_3d = blade_pair::generate(&BladePairParams {
        three_d: true,
        ..BladePairParams::default()
    })
    .unwrap();
    for mesh in [plate, generated, generated_3d] {
        for format in [MshFormat::Ascii, MshFormat::Binary] {
            let bytes = msh_bytes(&mesh, format).unwrap();
            let back = read_msh_bytes(&bytes, "round trip").unwrap();
            assert_same_mesh(&back, &mesh, 0.0);
        }
    }
}

#[test]
fn written_file_reads_back_from_disk() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("pair.msh");
    let mesh = blade_pair::generate(&BladePairParams::default()).unwrap();
    write_msh(&path, &mesh, MshFormat::Binary).unwrap();
    let back = read_msh(&path).unwrap();
    assert_eq!(back.source, path.display().to_string());
    assert_same_mesh(&back, &mesh, 0.0);
}

/// A unit square of two triangles whose node ids are given.
fn square_with_ids(ids: [u64; 4]) -> Mesh {
    let mut b = MeshBuilder::new("ids");
    for p in [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] {
        b.add_node([p[0], p[1], 0.0]);
    }
    b.add_group(
        "solid",
        ElementKind::Triangle3,
        &[vec![0, 1, 2], vec![0, 2, 3]],
    );
    let mut mesh = b.finish();
    for (node, id) in mesh.nodes.iter_mut().zip(ids) {
        node.id = id;
    }
    mesh
}

#[test]
fn node_tags_out_of_file_order_are_honoured() {
    // Contiguous tags 1..4 listed in the order 3, 1, 4, 2 (mshio drops contiguous tags; the
    // reader recovers them), and sparse tags.
    for ids in [[3, 1, 4, 2], [40, 10, 30, 20]] {
        let mesh = square_with_ids(ids);
        for format in [MshFormat::Ascii, MshFormat::Binary] {
            let back = read_msh_bytes(&msh_bytes(&mesh, format).unwrap(), "ids").unwrap();
            let by_id = |id: u64| back.nodes[back.node_index(id).unwrap()].coords;
            assert_eq!(by_id(ids[2]), [1.0, 1.0, 0.0], "{ids:?} {format:?}");
            assert_eq!(by_id(ids[1]), [1.0, 0.0, 0.0], "{ids:?} {format:?}");
            let first = &back.elements[0];
            let corners: Vec<[f64; 3]> =
                first.nodes.iter().map(|&n| back.nodes[n].coords).collect();
            assert_eq!(
                corners,
                vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
            );
        }
    }
}

const TET: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n\
$EndEntities\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n\
$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";

#[test]
fn unsupported_element_type_is_named() {
    let err = read_msh_bytes(TET.as_bytes(), "tet.msh").unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.starts_with("tet.msh: element 1 (entity dim 3, tag 1) has Gmsh type 4 (Tet4)"),
        "{msg}"
    );
}

#[test]
fn element_with_unknown_node_is_an_error() {
    let text = TET
        .replace("3 1 4 1\n1 1 2 3 4", "2 1 2 1\n1 1 2 9")
        .replace("0 0 0 1\n1 0 0 0 1 1 1 0 0", "0 0 1 0\n1 0 0 0 1 1 1 0 0");
    let text = text.replace("3 1 0 4", "2 1 0 4");
    let err = read_msh_bytes(text.as_bytes(), "bad.msh").unwrap_err();
    assert!(
        err.to_string()
            .contains("element 1 refers to node 9, which is not in $Nodes"),
        "{err}"
    );
}

#[test]
fn malformed_and_old_files_are_rejected_with_position() {
    let err = read_msh_bytes(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", "old.msh").unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.starts_with("old.msh: not a valid Gmsh 4.1 mesh"),
        "{msg}"
    );
    assert!(
        msg.contains("Only the MSH file format specification of revision 4.1"),
        "{msg}"
    );

    for header in ["4.1 0 3", "4.1 2 8", "4.1 0 99999999999999999999999"] {
        let text = TET.replace("4.1 0 8", header);
        let msg = read_msh_bytes(text.as_bytes(), "odd.msh")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains(&format!("$MeshFormat line `{header}`: expected `4.1 0 8`")),
            "{msg}"
        );
    }
    let msg = read_msh_bytes(b"hello", "text.msh")
        .unwrap_err()
        .to_string();
    assert!(msg.contains("does not start with $MeshFormat"), "{msg}");

    let broken = TET.replace("0 1 0\n", "0 one 0\n");
    let msg = read_msh_bytes(broken.as_bytes(), "broken.msh")
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with("broken.msh: not a valid Gmsh 4.1 mesh (near byte"),
        "{msg}"
    );
    assert!(msg.contains("line 1"), "{msg}");
}

#[test]
fn missing_file_is_named() {
    let err = read_msh(Path::new("/nonexistent/blade.msh")).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("/nonexistent/blade.msh: cannot read:"),
        "{err}"
    );
}

#[test]
fn unnamed_physical_group_gets_a_name_and_unknown_group_lists_names() {
    // One line element on a curve entity carrying physical tag 7, no $PhysicalNames.
    let lines = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 1 0 0\n\
1 0 0 0 1 0 0 1 7 0\n$EndEntities\n$Nodes\n1 2 1 2\n1 1 0 2\n1\n2\n0 0 0\n1 0 0\n$EndNodes\n\
$Elements\n1 1 1 1\n1 1 1 1\n1 1 2\n$EndElements\n";
    let mesh = read_msh_bytes(lines.as_bytes(), "lines.msh").unwrap();
    assert_eq!(mesh.group_names(), vec!["group_1_7".to_string()]);
    assert_eq!(mesh.group_nodes("group_1_7").unwrap().len(), 2);
    let err = mesh.group_nodes("clamp").unwrap_err();
    assert_eq!(
        err.to_string(),
        "lines.msh: no physical group named `clamp` (groups: group_1_7)"
    );
}

#[test]
fn truncated_files_are_errors_not_panics() {
    for name in ["plate-ascii.msh", "plate-binary.msh", "box-hex-binary.msh"] {
        let bytes = std::fs::read(data(name)).unwrap();
        for cut in (0..bytes.len()).step_by(7) {
            if let Err(e) = read_msh_bytes(&bytes[..cut], name) {
                assert!(
                    !e.to_string().contains("(mshio) failed"),
                    "{name} cut at {cut}: the parser panicked"
                );
            }
        }
    }
}
