//! FE matrices exported by other codes: stiffness K and mass M as Matrix Market files, plus a
//! DOF map naming the (node, direction) of every row.
//!
//! # Matrix Market
//! `%%MatrixMarket matrix coordinate real|integer symmetric|general`, 1-based indices as the
//! format defines. A `symmetric` file stores one triangle (FE codes export the lower or the
//! upper one; both are accepted, a file mixing both is rejected because its off-diagonal terms
//! would be counted twice). A `general` file stores every entry and must be symmetric within a
//! relative tolerance (`|a_ij − a_ji| ≤ tol · max|a|`). Units are the model's: K in N/m, M in kg
//! (SI). The result is a faer [`SparseMatrix`](faer::sparse::SparseColMat) in full symmetric storage.
//!
//! Parsing and the symmetric expansion are done by `sprs::io::read_matrix_market_from_bufread`.
//! sprs panics on an index outside the declared size, loops forever on a file that ends before
//! its size line, and reports every other problem as "Bad matrix market file" without a line.
//! The file is therefore fed to sprs through `GuardedLines`, a line-by-line reader that checks
//! each line first (indices in range, finite values, entry count, one triangle) and stops with
//! the file, line and reason; sprs never sees a line it could panic on. sprs reads `integer`
//! files only into integer matrices, so their header reaches it as `real` (the values are exact
//! as f64).
//!
//! # DOF map
//! A CSV file, one DOF per line: node, direction, row. `#` starts a comment line; blank lines
//! are skipped. The first other line is the header, three column names in this order, as the
//! exporting codes write them ([`DOF_MAP_HEADERS`]):
//! - node: `node`, `node_id`, `nodeid` or `nid`: the exporting code's node id (unsigned integer);
//! - direction: `direction`, `dir` or `dof`: `x y z rx ry rz` or their numbers `1`-`6`
//!   (the Nastran/Abaqus component numbers: 1-3 translations, 4-6 rotations);
//! - row: `row1` for 1-based rows (the Matrix Market convention), `row0` or `index` for 0-based
//!   rows, `row` for the base the scene declares (`model.matrix_market.dof_map_base`), 1-based
//!   when it declares none.
//!
//! A header that is none of these is refused with the list of accepted names. Every matrix row
//! must be named exactly once.
//!
//! The files: [`error`] (what can be wrong with the files), [`guarded`] (reading lines with
//! limits), [`matrices`] (the K and M files) and [`dof_map`] (the DOF map).

mod dof_map;
mod error;
mod guarded;
mod matrices;

pub use dof_map::{read_dof_map, read_dof_map_with_base, write_dof_map, DOF_MAP_HEADERS};
pub use error::FeMatrixError;
pub use matrices::{
    check_symmetric, read_fe_matrices, read_fe_matrices_with_base, read_symmetric_matrix,
    write_symmetric_matrix, FeMatrices, DEFAULT_SYMMETRY_TOLERANCE,
};
