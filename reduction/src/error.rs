//! Error type of the reduction crate.

use thiserror::Error;

/// Everything that can go wrong in a reduction or an eigen solve.
///
/// Every variant names the offending item (matrix, index, value) and why it is
/// rejected, so that a message can be shown to a user as it is.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ReductionError {
    /// A matrix is not square or does not have the size of the model.
    #[error("{matrix} is {rows} × {cols}, expected {expected} × {expected} (square, the size of the model)")]
    BadShape {
        /// `"K"`, `"M"`, `"K_r"`, ...
        matrix: &'static str,
        /// rows found
        rows: usize,
        /// columns found
        cols: usize,
        /// expected number of rows and columns
        expected: usize,
    },
    /// A stored value is NaN or infinite.
    #[error("{matrix} has a non-finite value {value} at row {row}, column {col}")]
    NonFinite {
        /// matrix name
        matrix: &'static str,
        /// row (full index)
        row: usize,
        /// column (full index)
        col: usize,
        /// the value
        value: f64,
    },
    /// The matrix is not symmetric (both triangles must be stored).
    #[error(
        "{matrix} is not symmetric: entry ({row}, {col}) = {a_ij:e} but ({col}, {row}) = {a_ji:e} \
         (both triangles must be stored, relative tolerance {tolerance:e} of the largest entry)"
    )]
    NotSymmetric {
        /// matrix name
        matrix: &'static str,
        /// row
        row: usize,
        /// column
        col: usize,
        /// value at (row, col)
        a_ij: f64,
        /// value at (col, row)
        a_ji: f64,
        /// relative tolerance used
        tolerance: f64,
    },
    /// A boundary or recovery index is outside `0..n`.
    #[error(
        "{list} index {index} (position {position}) is out of range for a model with {n} DOFs"
    )]
    IndexOutOfRange {
        /// `"boundary"` or `"recover"`
        list: &'static str,
        /// the index
        index: usize,
        /// position in the list
        position: usize,
        /// number of DOFs of the model
        n: usize,
    },
    /// A boundary index appears twice.
    #[error("boundary DOF {index} is listed twice (positions {first} and {second})")]
    RepeatedBoundary {
        /// the index
        index: usize,
        /// first position
        first: usize,
        /// second position
        second: usize,
    },
    /// Invalid option or argument.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The matrix to factor is not positive definite.
    #[error(
        "{matrix} is not positive definite at {context} DOF {local} (full index {full}): pivot ratio {ratio:e}; \
         a body is not held by any boundary DOF (free body without boundary), a DOF has no stiffness, \
         or the matrix is indefinite (for a shifted matrix K − σM: σ is not below the lowest eigenvalue)"
    )]
    NotPositiveDefinite {
        /// `"K_II"` or `"K − σM"`
        matrix: &'static str,
        /// `"interior"` or `"model"`
        context: &'static str,
        /// index in the factored matrix
        local: usize,
        /// full-model index
        full: usize,
        /// pivot / diagonal ratio found (≤ 0 when the pivot was not positive)
        ratio: f64,
    },
    /// The eigen solver did not converge.
    #[error(
        "eigen solver: {converged} of {wanted} eigenpairs converged after {restarts} restarts \
         (largest relative residual {residual:e})"
    )]
    EigenNotConverged {
        /// wanted pairs
        wanted: usize,
        /// converged pairs
        converged: usize,
        /// restarts done
        restarts: usize,
        /// largest residual among wanted pairs
        residual: f64,
    },
    /// The Sturm-sequence count shows eigenvalues the eigen solver missed.
    #[error(
        "eigen solver missed eigenvalues: {found} eigenvalues of the fixed-interface problem lie \
         below {shift_hz} Hz (Sturm count), only {computed} were found"
    )]
    MissedEigenvalues {
        /// eigenvalues found below the shift
        computed: usize,
        /// eigenvalues below the shift by the inertia of K − σM
        found: usize,
        /// the shift, Hz
        shift_hz: f64,
    },
    /// The mass matrix (or its interior part) is not positive definite on the
    /// subspace where it is needed.
    #[error("{matrix} is not positive definite ({detail})")]
    MassNotPositive {
        /// matrix name
        matrix: &'static str,
        /// detail
        detail: String,
    },
    /// Too many eigenpairs asked for the size of the problem.
    #[error("{asked} modes asked but the {what} has only {available} DOFs")]
    TooManyModes {
        /// modes asked
        asked: usize,
        /// DOFs available
        available: usize,
        /// what is reduced
        what: &'static str,
    },
    /// A graph is too large for METIS' 32-bit indices, or METIS failed.
    #[error("ordering failed: {0}")]
    Ordering(String),
    /// Failure reported by faer (out of memory, index overflow, dense eigen solver).
    #[error("linear algebra failure in {0}")]
    LinearAlgebra(String),
}
