//! FE matrices from Matrix Market files with a DOF map: symmetric and general storage, 0- and
//! 1-based maps, a write/read round trip of an assembled model, and every kind of bad input
//! with its message.

use std::path::{Path, PathBuf};

use fricbound::fe::assembly::{assemble, GroupMaterial};
use fricbound::fe::material::{Material, PlaneAssumption};
use fricbound::fe::matrix_market::{
    read_fe_matrices, read_symmetric_matrix, write_dof_map, write_symmetric_matrix, FeMatrixError,
    DEFAULT_SYMMETRY_TOLERANCE,
};
use fricbound::fe::msh_read::read_msh;
use fricbound::fe::sparse;
use fricbound::fe::Direction;

/// K of a 3-DOF spring chain (N/m), stored as its lower triangle.
const K_SYM: &str = "%%MatrixMarket matrix coordinate real symmetric\n\
% 3-DOF chain, lower triangle\n\
3 3 5\n\
1 1 2000.0\n\
2 1 -1000.0\n\
2 2 2000.0\n\
3 2 -1000.0\n\
3 3 1000.0\n";

/// M (kg), general storage, diagonal.
const M_GEN: &str =
    "%%MatrixMarket matrix coordinate real general\n3 3 3\n1 1 1.5\n2 2 1.5\n3 3 0.75\n";

const MAP_1: &str =
    "# node, direction, row (1-based)\nnode,direction,row\n10,x,1\n10,y,2\n11,x,3\n";

struct Files {
    _dir: tempfile::TempDir,
    k: PathBuf,
    m: PathBuf,
    map: PathBuf,
}

fn files(k: &str, m: &str, map: &str) -> Files {
    let dir = tempfile::tempdir().unwrap();
    let (kp, mp, mapp) = (
        dir.path().join("K.mtx"),
        dir.path().join("M.mtx"),
        dir.path().join("dofs.csv"),
    );
    std::fs::write(&kp, k).unwrap();
    std::fs::write(&mp, m).unwrap();
    std::fs::write(&mapp, map).unwrap();
    Files {
        _dir: dir,
        k: kp,
        m: mp,
        map: mapp,
    }
}

fn read(f: &Files) -> Result<fricbound::fe::FeMatrices, FeMatrixError> {
    read_fe_matrices(&f.k, &f.m, &f.map, DEFAULT_SYMMETRY_TOLERANCE)
}

fn message(k: &str, m: &str, map: &str) -> (String, Files) {
    let f = files(k, m, map);
    let msg = read(&f).unwrap_err().to_string();
    (msg, f)
}

fn name(p: &Path) -> String {
    p.display().to_string()
}

#[test]
fn symmetric_and_general_files_with_one_based_map() {
    let f = files(K_SYM, M_GEN, MAP_1);
    let fe = read(&f).unwrap();
    assert_eq!(fe.stiffness.nrows(), 3);
    // Full symmetric storage: both triangles present.
    assert_eq!(sparse::get(&fe.stiffness, 0, 1), -1000.0);
    assert_eq!(sparse::get(&fe.stiffness, 1, 0), -1000.0);
    assert_eq!(sparse::get(&fe.stiffness, 2, 2), 1000.0);
    assert_eq!(sparse::get(&fe.mass, 2, 2), 0.75);
    assert_eq!(fe.dofs.row(10, Direction::Y), Some(1));
    assert_eq!(fe.dofs.row(11, Direction::X), Some(2));
    assert_eq!(fe.dofs.dof(0).unwrap().to_string(), "10.x");
    // Clamping node 10 leaves the last DOF.
    let clamped = fe.without_dofs(|d| d.node == 10);
    assert_eq!(clamped.dofs.len(), 1);
    assert_eq!(clamped.dofs.row(11, Direction::X), Some(0));
    assert_eq!(sparse::get(&clamped.stiffness, 0, 0), 1000.0);
    assert_eq!(sparse::get(&clamped.mass, 0, 0), 0.75);
}

#[test]
fn zero_based_map_and_integer_field() {
    let k = K_SYM.replace("real", "integer").replace(".0", "");
    let map = "node,direction,row0\n10,x,0\n10,y,1\n11,X,2\n";
    let f = files(&k, M_GEN, map);
    let fe = read(&f).unwrap();
    assert_eq!(sparse::get(&fe.stiffness, 1, 2), -1000.0);
    assert_eq!(fe.dofs.row(11, Direction::X), Some(2));
}

#[test]
fn assembled_model_round_trips_through_matrix_market() {
    let mesh =
        read_msh(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fe_data/plate-ascii.msh"))
            .unwrap();
    let steel = Material::steel(0.01);
    let model = assemble(
        &mesh,
        &[
            GroupMaterial::new("quads", steel),
            GroupMaterial::new("triangles", steel),
        ],
        PlaneAssumption::Stress,
    )
    .unwrap()
    .clamp_group(&mesh, "clamp")
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (k, m, map) = (
        dir.path().join("K.mtx"),
        dir.path().join("M.mtx"),
        dir.path().join("dofs.csv"),
    );
    write_symmetric_matrix(&k, &model.stiffness).unwrap();
    write_symmetric_matrix(&m, &model.mass).unwrap();
    write_dof_map(&map, &model.dofs).unwrap();
    assert!(std::fs::read_to_string(&k)
        .unwrap()
        .starts_with("%%MatrixMarket matrix coordinate real symmetric"));
    let back = read_fe_matrices(&k, &m, &map, DEFAULT_SYMMETRY_TOLERANCE).unwrap();
    assert_eq!(back.dofs, model.dofs);
    for (a, b) in [
        (&back.stiffness, &model.stiffness),
        (&back.mass, &model.mass),
    ] {
        assert_eq!(a.nrows(), b.nrows());
        let mut count = 0;
        sparse::for_each_entry(b, |r, c, v| {
            assert_eq!(sparse::get(a, r, c), v, "entry ({r}, {c})");
            count += 1;
        });
        assert_eq!(a.val().len(), count);
    }
}

#[test]
fn size_mismatch_between_k_and_m() {
    let m = "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0\n2 2 1.0\n";
    let (msg, f) = message(K_SYM, m, MAP_1);
    assert_eq!(
        msg,
        format!(
            "{}: mass matrix is 2 x 2 but the stiffness matrix {} is 3 x 3",
            name(&f.m),
            name(&f.k)
        )
    );
}

#[test]
fn dof_map_row_outside_the_matrices() {
    let map = "node,direction,row\n10,x,1\n10,y,2\n11,x,4\n";
    let (msg, f) = message(K_SYM, M_GEN, map);
    assert_eq!(
        msg,
        format!(
            "{}: line 4: row 4 is outside the matrices (3 rows, 1-based rows 1..=3)",
            name(&f.map)
        )
    );
}

#[test]
fn dof_map_missing_rows() {
    let map = "node,direction,row\n10,x,1\n";
    let (msg, f) = message(K_SYM, M_GEN, map);
    assert_eq!(
        msg,
        format!(
            "{}: the DOF map names 1 of the 3 matrix rows; rows without a DOF (0-based): 1, 2",
            name(&f.map)
        )
    );
}

#[test]
fn dof_map_duplicates_and_bad_fields() {
    let (msg, _) = message(K_SYM, M_GEN, "node,direction,row\n10,x,1\n10,y,1\n11,x,3\n");
    assert!(
        msg.ends_with("line 3: row 1 is given twice: 10.x on line 2 and 10.y"),
        "{msg}"
    );
    let (msg, _) = message(K_SYM, M_GEN, "node,direction,row\n10,x,1\n10,x,2\n11,x,3\n");
    assert!(
        msg.ends_with("line 3: DOF 10.x is given twice (also on line 2)"),
        "{msg}"
    );
    let (msg, _) = message(K_SYM, M_GEN, "node,direction,row\n10,w,1\n");
    assert!(
        msg.ends_with("line 2: direction `w` is not one of x, y, z, rx, ry, rz or 1-6"),
        "{msg}"
    );
    // `node,dof,row` is an accepted variant now; a header naming no known column is not.
    let (msg, _) = message(K_SYM, M_GEN, "node,axis,row\n10,x,1\n");
    assert!(
        msg.contains("line 1: expected a header of three columns `node,direction,row`"),
        "{msg}"
    );
    let (msg, _) = message(K_SYM, M_GEN, "node,direction,row\n-3,x,1\n");
    assert!(
        msg.ends_with("line 2: node `-3` is not an unsigned integer"),
        "{msg}"
    );
}

#[test]
fn non_symmetric_general_stiffness() {
    let k = "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 2.0\n1 2 -1.0\n2 1 -1.5\n3 3 1.0\n";
    let (msg, f) = message(k, M_GEN, MAP_1);
    assert!(
        msg.starts_with(&format!(
            "{}: matrix is not symmetric: entry (2, 1) = -1.5e0 but (1, 2) = -1e0",
            name(&f.k)
        )),
        "{msg}"
    );
    // Within the tolerance it is accepted.
    let k = k.replace("-1.5", "-1.000000000001");
    assert!(read(&files(&k, M_GEN, MAP_1)).is_ok());
}

#[test]
fn nan_entry() {
    let k = K_SYM.replace("3 2 -1000.0", "3 2 NaN");
    let (msg, f) = message(&k, M_GEN, MAP_1);
    assert_eq!(
        msg,
        format!(
            "{}: line 7: entry (3, 2) is NaN, not a finite number",
            name(&f.k)
        )
    );
    let m = M_GEN.replace("0.75", "inf");
    let (msg, _) = message(K_SYM, &m, MAP_1);
    assert!(
        msg.ends_with("line 5: entry (3, 3) is inf, not a finite number"),
        "{msg}"
    );
}

#[test]
fn missing_file() {
    let f = files(K_SYM, M_GEN, MAP_1);
    let err = read_fe_matrices(
        Path::new("/nonexistent/K.mtx"),
        &f.m,
        &f.map,
        DEFAULT_SYMMETRY_TOLERANCE,
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .starts_with("/nonexistent/K.mtx: cannot read:"),
        "{err}"
    );
    let err = read_fe_matrices(&f.k, &f.m, Path::new("/nonexistent/dofs.csv"), 1e-8).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("/nonexistent/dofs.csv: cannot read:"),
        "{err}"
    );
}

#[test]
fn malformed_matrix_files() {
    let cases = [
        (
            "%%MatrixMarket matrix array real general\n3 3\n",
            "line 1: expected `%%MatrixMarket matrix coordinate",
        ),
        (
            "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n",
            "line 1: field `complex` not supported",
        ),
        (
            "%%MatrixMarket matrix coordinate real skew-symmetric\n1 1 0\n",
            "line 1: symmetry `skew-symmetric` not supported",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n3 3\n",
            "line 2: expected the size line `rows cols entries`, found `3 3`",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n3 3 1\n1 x 1.0\n",
            "line 3: row and column must be positive integers",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 one\n",
            "line 3: value `one` is not a number",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n3 3 1\n0 1 1.0\n",
            "line 3: entry (0, 1) is outside the 3 x 3 matrix",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n3 2 1\n1 1 1.0\n",
            "matrix is 3 x 2, a stiffness or mass matrix must be square",
        ),
    ];
    for (text, expected) in cases {
        let (msg, _) = message(text, M_GEN, MAP_1);
        assert!(msg.contains(expected), "expected `{expected}` in `{msg}`");
    }
}

#[test]
fn single_matrix_reader_is_usable_alone() {
    let f = files(K_SYM, M_GEN, MAP_1);
    let k = read_symmetric_matrix(&f.k, 1e-8).unwrap();
    assert_eq!(sparse::quadratic_form(&k, &[1.0, 1.0, 1.0]), 1000.0);
}
