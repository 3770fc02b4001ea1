//! What can be wrong with exported FE matrices and their DOF map: typed errors that name the
//! file, the line and the field.

use std::io::{self};

/// Errors of reading FE matrices and DOF maps. Each names the file and, where there is one,
/// the line or the entry.
#[derive(Debug, thiserror::Error)]
pub enum FeMatrixError {
    /// The file could not be opened or read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// File.
        file: String,
        /// Cause.
        source: io::Error,
    },
    /// The file does not follow the format.
    #[error("{file}: line {line}: {reason}")]
    Format {
        /// File.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// sprs rejected the file at or before the given line.
    #[error("{file}: line {line}: not a valid Matrix Market entry ({reason})")]
    Parse {
        /// File.
        file: String,
        /// Last line read.
        line: usize,
        /// sprs's message.
        reason: String,
    },
    /// A NaN or infinite value.
    #[error("{file}: line {line}: entry ({row}, {col}) is {value}, not a finite number")]
    NotFinite {
        /// File.
        file: String,
        /// 1-based line number.
        line: usize,
        /// 1-based row as in the file.
        row: usize,
        /// 1-based column as in the file.
        col: usize,
        /// The value read.
        value: f64,
    },
    /// The matrix is not square.
    #[error("{file}: matrix is {rows} x {cols}, a stiffness or mass matrix must be square")]
    NotSquare {
        /// File.
        file: String,
        /// Rows.
        rows: usize,
        /// Columns.
        cols: usize,
    },
    /// A `general` matrix is not symmetric within the tolerance.
    #[error(
        "{file}: matrix is not symmetric: entry ({row}, {col}) = {value:e} but ({col}, {row}) = \
         {transposed:e} (1-based; relative tolerance {tolerance:e} of max |a| = {max_abs:e})"
    )]
    NotSymmetric {
        /// File.
        file: String,
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// a_ij.
        value: f64,
        /// a_ji.
        transposed: f64,
        /// Relative tolerance used.
        tolerance: f64,
        /// Largest |a|.
        max_abs: f64,
    },
    /// K and M have different sizes.
    #[error(
        "{mass_file}: mass matrix is {mass_size} x {mass_size} but the stiffness matrix \
         {stiffness_file} is {stiffness_size} x {stiffness_size}"
    )]
    SizeMismatch {
        /// Stiffness file.
        stiffness_file: String,
        /// Its size.
        stiffness_size: usize,
        /// Mass file.
        mass_file: String,
        /// Its size.
        mass_size: usize,
    },
    /// The DOF map names a row outside the matrices.
    #[error(
        "{file}: line {line}: row {row} is outside the matrices ({size} rows, {base}-based rows \
         {first}..={last})"
    )]
    DofRowOutOfRange {
        /// DOF map file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// Row as written.
        row: usize,
        /// Matrix size.
        size: usize,
        /// Row base of the file (0 or 1).
        base: usize,
        /// First valid row as written.
        first: usize,
        /// Last valid row as written.
        last: usize,
    },
    /// Matrix rows that the DOF map does not name.
    #[error(
        "{file}: the DOF map names {named} of the {size} matrix rows; rows without a DOF \
         (0-based): {missing}"
    )]
    DofRowsMissing {
        /// DOF map file.
        file: String,
        /// Rows named.
        named: usize,
        /// Matrix size.
        size: usize,
        /// First missing rows, listed.
        missing: String,
    },
}

impl FeMatrixError {
    pub(super) fn format(file: &str, line: usize, reason: impl Into<String>) -> FeMatrixError {
        FeMatrixError::Format {
            file: file.to_string(),
            line,
            reason: reason.into(),
        }
    }
}
