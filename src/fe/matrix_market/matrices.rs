//! The stiffness and mass matrices as symmetric Matrix Market files: reading them (checked for
//! symmetry and size) with their DOF map, and writing them.

use std::fs::File;
use std::io::{self, BufReader};
use std::path::Path;

use faer::sparse::Triplet;

use super::dof_map::read_dof_map_with_base;
use super::error::FeMatrixError;
use super::guarded::GuardedLines;
use crate::fe::dof::{Dof, DofMap};
use crate::fe::sparse::{self, SparseMatrix};

/// Default relative tolerance of the symmetry check of `general` files.
pub const DEFAULT_SYMMETRY_TOLERANCE: f64 = 1e-8;

/// K, M and the DOF of each row, checked against each other.
#[derive(Debug, Clone)]
pub struct FeMatrices {
    /// Stiffness matrix K (N/m), full symmetric storage.
    pub stiffness: SparseMatrix,
    /// Mass matrix M (kg), full symmetric storage.
    pub mass: SparseMatrix,
    /// DOF of each row.
    pub dofs: DofMap,
}

impl FeMatrices {
    /// The matrices with the DOFs for which `remove` is true deleted (e.g. a clamp given as a
    /// list of nodes), rows, columns and DOF map renumbered consistently.
    pub fn without_dofs(&self, remove: impl Fn(Dof) -> bool) -> FeMatrices {
        let (dofs, new_of_old) = self.dofs.retain(|d| !remove(d));
        let n = dofs.len();
        FeMatrices {
            stiffness: sparse::keep_rows_cols(&self.stiffness, &new_of_old, n),
            mass: sparse::keep_rows_cols(&self.mass, &new_of_old, n),
            dofs,
        }
    }
}

/// Reads K, M and the DOF map and checks that they fit: both matrices square, of one size,
/// symmetric (relative `symmetry_tolerance` for `general` files), finite; the map names every
/// row once.
pub fn read_fe_matrices(
    stiffness_path: &Path,
    mass_path: &Path,
    dof_map_path: &Path,
    symmetry_tolerance: f64,
) -> Result<FeMatrices, FeMatrixError> {
    read_fe_matrices_with_base(
        stiffness_path,
        mass_path,
        dof_map_path,
        symmetry_tolerance,
        None,
    )
}

/// [`read_fe_matrices`] with the row base of a DOF map whose header says `row` (0 or 1; see
/// [`read_dof_map_with_base`]).
pub fn read_fe_matrices_with_base(
    stiffness_path: &Path,
    mass_path: &Path,
    dof_map_path: &Path,
    symmetry_tolerance: f64,
    row_base: Option<usize>,
) -> Result<FeMatrices, FeMatrixError> {
    let stiffness = read_symmetric_matrix(stiffness_path, symmetry_tolerance)?;
    let mass = read_symmetric_matrix(mass_path, symmetry_tolerance)?;
    if stiffness.nrows() != mass.nrows() {
        return Err(FeMatrixError::SizeMismatch {
            stiffness_file: stiffness_path.display().to_string(),
            stiffness_size: stiffness.nrows(),
            mass_file: mass_path.display().to_string(),
            mass_size: mass.nrows(),
        });
    }
    let dofs = read_dof_map_with_base(dof_map_path, stiffness.nrows(), row_base)?;
    Ok(FeMatrices {
        stiffness,
        mass,
        dofs,
    })
}

/// Reads one square, symmetric, finite Matrix Market matrix into full storage.
pub fn read_symmetric_matrix(path: &Path, tolerance: f64) -> Result<SparseMatrix, FeMatrixError> {
    let file = path.display().to_string();
    let handle = File::open(path).map_err(|source| FeMatrixError::Io {
        file: file.clone(),
        source,
    })?;
    let mut guarded = GuardedLines::new(BufReader::new(handle));
    let read: Result<sprs::TriMatI<f64, usize>, _> =
        sprs::io::read_matrix_market_from_bufread(&mut guarded);
    let triplets = match read {
        Ok(t) => t,
        Err(e) => return Err(guarded.explain(&file, e)),
    };
    let (rows, cols) = (triplets.rows(), triplets.cols());
    if rows != cols {
        return Err(FeMatrixError::NotSquare { file, rows, cols });
    }
    let entries: Vec<Triplet<usize, usize, f64>> = triplets
        .row_inds()
        .iter()
        .zip(triplets.col_inds())
        .zip(triplets.data())
        .map(|((&r, &c), &v)| Triplet::new(r, c, v))
        .collect();
    let matrix = sparse::from_triplets(rows, cols, &entries).map_err(|e| {
        FeMatrixError::format(&file, guarded.line, format!("cannot build matrix: {e:?}"))
    })?;
    if !guarded.symmetric {
        check_symmetric(&matrix, &file, tolerance)?;
    }
    Ok(matrix)
}

/// Fails with [`FeMatrixError::NotSymmetric`] if `|a_ij − a_ji| > tolerance · max|a|`
/// anywhere. `file` names the matrix in the message.
pub fn check_symmetric(
    matrix: &SparseMatrix,
    file: &str,
    tolerance: f64,
) -> Result<(), FeMatrixError> {
    let max_abs = sparse::max_abs(matrix);
    if let Some((row, col, value, transposed)) = sparse::worst_asymmetry(matrix) {
        let defect = (value - transposed).abs();
        if defect.is_nan() || defect > tolerance * max_abs {
            return Err(FeMatrixError::NotSymmetric {
                file: file.to_string(),
                row: row + 1,
                col: col + 1,
                value,
                transposed,
                tolerance,
                max_abs,
            });
        }
    }
    Ok(())
}

/// Writes a matrix as a `symmetric` Matrix Market file (lower triangle, 1-based), the form FE
/// codes export, through sprs. The caller guarantees symmetry.
pub fn write_symmetric_matrix(path: &Path, matrix: &SparseMatrix) -> io::Result<()> {
    let n = matrix.nrows();
    let mut tri = sprs::TriMatI::<f64, usize>::new((n, matrix.ncols()));
    sparse::for_each_entry(matrix, |row, col, val| tri.add_triplet(row, col, val));
    let csc: sprs::CsMatI<f64, usize> = tri.to_csc();
    sprs::io::write_matrix_market_sym(path, &csc, sprs::io::SymmetryMode::Symmetric)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<SparseMatrix, FeMatrixError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.mtx");
        std::fs::write(&path, text).unwrap();
        read_symmetric_matrix(&path, DEFAULT_SYMMETRY_TOLERANCE)
    }

    #[test]
    fn symmetric_upper_triangle_is_expanded() {
        let a = read_text(
            "%%MatrixMarket matrix coordinate real symmetric\n% upper\n2 2 3\n1 1 4\n1 2 -1\n2 2 3\n",
        )
        .unwrap();
        assert_eq!(sparse::get(&a, 1, 0), -1.0);
        assert_eq!(sparse::get(&a, 0, 1), -1.0);
        assert_eq!(sparse::get(&a, 1, 1), 3.0);
    }

    #[test]
    fn truncated_file_does_not_hang() {
        let e = read_text("%%MatrixMarket matrix coordinate real general\n% only comments\n")
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("line 3: file ends before the size line"),
            "{e}"
        );
        let e =
            read_text("%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1\n").unwrap_err();
        assert!(e.to_string().contains("after 1 of the 3 entries"), "{e}");
    }

    #[test]
    fn index_outside_declared_size_is_an_error_not_a_panic() {
        let e = read_text("%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1.0\n")
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("line 3: entry (3, 1) is outside the 2 x 2"),
            "{e}"
        );
    }

    #[test]
    fn both_triangles_in_symmetric_file_rejected() {
        let e =
            read_text("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 1.0\n1 2 1.0\n")
                .unwrap_err();
        assert!(e.to_string().contains("line 4"), "{e}");
        assert!(e.to_string().contains("one triangle"), "{e}");
    }
}
