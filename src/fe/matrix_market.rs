//! FE matrices exported by other codes: stiffness K and mass M as Matrix Market files, plus a
//! DOF map naming the (node, direction) of every row.
//!
//! # Matrix Market
//! `%%MatrixMarket matrix coordinate real|integer symmetric|general`, 1-based indices as the
//! format defines. A `symmetric` file stores one triangle (FE codes export the lower or the
//! upper one; both are accepted, a file mixing both is rejected because its off-diagonal terms
//! would be counted twice). A `general` file stores every entry and must be symmetric within a
//! relative tolerance (`|a_ij − a_ji| ≤ tol · max|a|`). Units are the model's: K in N/m, M in kg
//! (SI). The result is a faer [`SparseMatrix`] in full symmetric storage.
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

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use faer::sparse::Triplet;

use super::dof::{Direction, Dof, DofMap};
use super::sparse::{self, SparseMatrix};

/// Default relative tolerance of the symmetry check of `general` files.
pub const DEFAULT_SYMMETRY_TOLERANCE: f64 = 1e-8;

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
    fn format(file: &str, line: usize, reason: impl Into<String>) -> FeMatrixError {
        FeMatrixError::Format {
            file: file.to_string(),
            line,
            reason: reason.into(),
        }
    }
}

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

/// Reads a DOF map file (format in the module doc) for matrices with `size` rows.
pub fn read_dof_map(path: &Path, size: usize) -> Result<DofMap, FeMatrixError> {
    read_dof_map_with_base(path, size, None)
}

/// Reads a DOF map whose `row` column counts from `row_base` (0 or 1) when the header says
/// plain `row`; `None` means 1-based. A header `row0`/`index` or `row1` states its own base and
/// must agree with a declared one.
pub fn read_dof_map_with_base(
    path: &Path,
    size: usize,
    row_base: Option<usize>,
) -> Result<DofMap, FeMatrixError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| FeMatrixError::Io {
        file: file.clone(),
        source,
    })?;
    let mut base: Option<usize> = None;
    let mut slots: Vec<Option<(Dof, usize)>> = vec![None; size];
    let mut seen = std::collections::HashMap::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let content = raw.trim();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = content.split(',').map(str::trim).collect();
        let Some(row_base) = base else {
            base = Some(parse_dof_map_header(&fields, row_base).map_err(|reason| {
                FeMatrixError::format(&file, line, format!("{reason}, found `{content}`"))
            })?);
            continue;
        };
        if fields.len() != 3 {
            return Err(FeMatrixError::format(
                &file,
                line,
                format!(
                    "expected 3 fields `node,direction,row`, found {}",
                    fields.len()
                ),
            ));
        }
        let node: u64 = fields[0].parse().map_err(|_| {
            FeMatrixError::format(
                &file,
                line,
                format!("node `{}` is not an unsigned integer", fields[0]),
            )
        })?;
        let direction = parse_direction(fields[1]).ok_or_else(|| {
            FeMatrixError::format(
                &file,
                line,
                format!(
                    "direction `{}` is not one of x, y, z, rx, ry, rz or 1-6",
                    fields[1]
                ),
            )
        })?;
        let written: usize = fields[2].parse().map_err(|_| {
            FeMatrixError::format(
                &file,
                line,
                format!("row `{}` is not an unsigned integer", fields[2]),
            )
        })?;
        if written < row_base || written - row_base >= size {
            return Err(FeMatrixError::DofRowOutOfRange {
                file,
                line,
                row: written,
                size,
                base: row_base,
                first: row_base,
                last: (size + row_base).saturating_sub(1),
            });
        }
        let row = written - row_base;
        let dof = Dof { node, direction };
        if let Some((other, other_line)) = slots[row] {
            return Err(FeMatrixError::format(
                &file,
                line,
                format!("row {written} is given twice: {other} on line {other_line} and {dof}"),
            ));
        }
        if let Some(other_line) = seen.insert(dof, line) {
            return Err(FeMatrixError::format(
                &file,
                line,
                format!("DOF {dof} is given twice (also on line {other_line})"),
            ));
        }
        slots[row] = Some((dof, line));
    }
    if base.is_none() {
        return Err(FeMatrixError::format(
            &file,
            text.lines().count().max(1),
            format!("no header found; {DOF_MAP_HEADERS}"),
        ));
    }
    let missing: Vec<usize> = (0..size).filter(|&r| slots[r].is_none()).collect();
    if !missing.is_empty() {
        let shown: Vec<String> = missing.iter().take(10).map(|r| r.to_string()).collect();
        let more = if missing.len() > 10 {
            format!(" and {} more", missing.len() - 10)
        } else {
            String::new()
        };
        return Err(FeMatrixError::DofRowsMissing {
            file,
            named: size - missing.len(),
            size,
            missing: format!("{}{more}", shown.join(", ")),
        });
    }
    let dofs = slots.into_iter().flatten().map(|(dof, _)| dof).collect();
    // Duplicates were rejected above, so this cannot fail.
    DofMap::new(dofs).map_err(|e| FeMatrixError::format(&file, 0, e.to_string()))
}

/// The DOF map headers accepted, as an error message lists them.
pub const DOF_MAP_HEADERS: &str = "expected a header of three columns `node,direction,row`: \
     node as `node`, `node_id`, `nodeid` or `nid`; direction as `direction`, `dir` or `dof` \
     (values x, y, z, rx, ry, rz or 1-6); row as `row1` (1-based), `row0` or `index` \
     (0-based), or `row` (1-based unless the scene sets model.matrix_market.dof_map_base)";

/// Row base stated by the header fields (`declared` is the scene's base for a plain `row`), or
/// why they are not a DOF map header.
fn parse_dof_map_header(fields: &[&str], declared: Option<usize>) -> Result<usize, String> {
    let lower: Vec<String> = fields.iter().map(|f| f.to_ascii_lowercase()).collect();
    let is_node = |f: &str| matches!(f, "node" | "node_id" | "nodeid" | "nid");
    let is_direction = |f: &str| matches!(f, "direction" | "dir" | "dof");
    if lower.len() != 3 || !is_node(&lower[0]) || !is_direction(&lower[1]) {
        return Err(DOF_MAP_HEADERS.to_string());
    }
    let stated = match lower[2].as_str() {
        "row" => return Ok(declared.unwrap_or(1)),
        "row1" => 1,
        "row0" | "index" => 0,
        _ => return Err(DOF_MAP_HEADERS.to_string()),
    };
    match declared {
        Some(b) if b != stated => Err(format!(
            "the header's `{}` states {stated}-based rows but the scene declares \
             model.matrix_market.dof_map_base = {b}",
            fields[2]
        )),
        _ => Ok(stated),
    }
}

/// A direction as written in DOF maps: a name (`x` .. `rz`) or a component number 1-6.
fn parse_direction(text: &str) -> Option<Direction> {
    match text.trim() {
        "1" => Some(Direction::X),
        "2" => Some(Direction::Y),
        "3" => Some(Direction::Z),
        "4" => Some(Direction::Rx),
        "5" => Some(Direction::Ry),
        "6" => Some(Direction::Rz),
        other => Direction::parse(other),
    }
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

/// Writes a DOF map file with 1-based rows (header `node,direction,row`).
pub fn write_dof_map(path: &Path, dofs: &DofMap) -> io::Result<()> {
    use std::io::Write;
    let mut out = io::BufWriter::new(File::create(path)?);
    writeln!(
        out,
        "# DOF map: matrix row (1-based) of each node id and direction"
    )?;
    writeln!(out, "node,direction,row")?;
    for (row, dof) in dofs.dofs().iter().enumerate() {
        writeln!(out, "{},{},{}", dof.node, dof.direction, row + 1)?;
    }
    out.flush()
}

/// Where [`GuardedLines`] is in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Header,
    Size,
    Entries,
    Done,
}

/// A check failure raised inside the reader; carried through sprs as an `io::Error`.
#[derive(Debug)]
struct GuardFailure(FeMatrixError);

impl std::fmt::Display for GuardFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for GuardFailure {}

/// Hands a Matrix Market file to sprs one checked line at a time (see the module doc).
struct GuardedLines<R> {
    inner: R,
    line_text: String,
    pos: usize,
    /// 1-based number of the last line handed out.
    line: usize,
    section: Section,
    symmetric: bool,
    rows: usize,
    cols: usize,
    entries: usize,
    entries_seen: usize,
    has_lower: bool,
    has_upper: bool,
    failure: Option<FeMatrixError>,
    /// Replacement for the line just checked (the header of an integer file).
    rewrite: Option<String>,
}

impl<R: BufRead> GuardedLines<R> {
    fn new(inner: R) -> Self {
        GuardedLines {
            inner,
            line_text: String::new(),
            pos: 0,
            line: 0,
            section: Section::Header,
            symmetric: false,
            rows: 0,
            cols: 0,
            entries: 0,
            entries_seen: 0,
            has_lower: false,
            has_upper: false,
            failure: None,
            rewrite: None,
        }
    }

    /// Turns an sprs error into one that names the file and line.
    fn explain(&mut self, file: &str, error: sprs::io::IoError) -> FeMatrixError {
        if let Some(failure) = self.failure.take() {
            return with_file(failure, file);
        }
        match error {
            sprs::io::IoError::Io(source) => FeMatrixError::Io {
                file: file.to_string(),
                source,
            },
            other => FeMatrixError::Parse {
                file: file.to_string(),
                line: self.line,
                reason: other.to_string(),
            },
        }
    }

    /// Checks a line before sprs reads it; `Err` stops the read.
    fn check(&mut self, text: &str, at_eof: bool) -> Result<(), FeMatrixError> {
        let line = self.line;
        let fail = |reason: String| FeMatrixError::format("", line, reason);
        match self.section {
            Section::Header => {
                if at_eof {
                    return Err(fail("empty file, expected a %%MatrixMarket header".into()));
                }
                let header = text.trim().to_ascii_lowercase();
                let words: Vec<&str> = header.split_whitespace().collect();
                if words.len() != 5
                    || words[0] != "%%matrixmarket"
                    || words[1] != "matrix"
                    || words[2] != "coordinate"
                {
                    return Err(fail(format!(
                        "expected `%%MatrixMarket matrix coordinate real symmetric|general`, \
                         found `{}`",
                        text.trim()
                    )));
                }
                if words[3] != "real" && words[3] != "integer" {
                    return Err(fail(format!(
                        "field `{}` not supported: K and M must be real (or integer)",
                        words[3]
                    )));
                }
                self.symmetric = match words[4] {
                    "symmetric" => true,
                    "general" => false,
                    other => {
                        return Err(fail(format!(
                            "symmetry `{other}` not supported: K and M must be stored as \
                             `symmetric` (one triangle) or `general`"
                        )))
                    }
                };
                if words[3] == "integer" {
                    // sprs reads integer files only into integer matrices; the values are
                    // exact as f64, so sprs is told the field is real.
                    self.rewrite = Some(format!(
                        "%%MatrixMarket matrix coordinate real {}\n",
                        words[4]
                    ));
                }
                self.section = Section::Size;
            }
            Section::Size => {
                let content = text.trim();
                if at_eof {
                    return Err(fail(
                        "file ends before the size line `rows cols entries`".into(),
                    ));
                }
                if content.is_empty() || content.starts_with('%') {
                    if content.is_empty() {
                        return Err(fail(
                            "blank line before the size line `rows cols entries`".into(),
                        ));
                    }
                    return Ok(());
                }
                let numbers: Vec<Option<usize>> =
                    content.split_whitespace().map(|w| w.parse().ok()).collect();
                match numbers.as_slice() {
                    [Some(r), Some(c), Some(e)] => {
                        self.rows = *r;
                        self.cols = *c;
                        self.entries = *e;
                        self.section = if *e == 0 {
                            Section::Done
                        } else {
                            Section::Entries
                        };
                    }
                    _ => {
                        return Err(fail(format!(
                            "expected the size line `rows cols entries`, found `{content}`"
                        )))
                    }
                }
            }
            Section::Entries => {
                let content = text.trim();
                if at_eof {
                    return Err(fail(format!(
                        "file ends after {} of the {} entries the size line announces",
                        self.entries_seen, self.entries
                    )));
                }
                if content.is_empty() {
                    return Ok(());
                }
                let words: Vec<&str> = content.split_whitespace().collect();
                if words.len() != 3 {
                    return Err(fail(format!(
                        "expected an entry `row col value`, found `{content}`"
                    )));
                }
                let (Ok(row), Ok(col)) = (words[0].parse::<usize>(), words[1].parse::<usize>())
                else {
                    return Err(fail(format!(
                        "row and column must be positive integers, found `{content}`"
                    )));
                };
                if row == 0 || col == 0 || row > self.rows || col > self.cols {
                    return Err(fail(format!(
                        "entry ({row}, {col}) is outside the {} x {} matrix (indices are \
                         1-based)",
                        self.rows, self.cols
                    )));
                }
                let value: f64 = words[2]
                    .parse()
                    .map_err(|_| fail(format!("value `{}` is not a number", words[2])))?;
                if !value.is_finite() {
                    return Err(FeMatrixError::NotFinite {
                        file: String::new(),
                        line,
                        row,
                        col,
                        value,
                    });
                }
                if self.symmetric {
                    self.has_lower |= row > col;
                    self.has_upper |= row < col;
                    if self.has_lower && self.has_upper {
                        return Err(fail(format!(
                            "entry ({row}, {col}) lies in the other triangle than the entries \
                             before it: a `symmetric` file stores one triangle only"
                        )));
                    }
                }
                self.entries_seen += 1;
                if self.entries_seen == self.entries {
                    self.section = Section::Done;
                }
            }
            Section::Done => {}
        }
        Ok(())
    }

    /// Reads and checks the next line into `line_text`.
    fn next_line(&mut self) -> io::Result<()> {
        self.line_text.clear();
        self.pos = 0;
        if self.section == Section::Done {
            return Ok(());
        }
        let n = self.inner.read_line(&mut self.line_text)?;
        self.line += 1;
        let text = std::mem::take(&mut self.line_text);
        let checked = self.check(&text, n == 0);
        self.line_text = self.rewrite.take().unwrap_or(text);
        if let Err(failure) = checked {
            let message = failure.to_string();
            self.failure = Some(failure);
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                GuardFailure(FeMatrixError::format("", self.line, message)),
            ));
        }
        Ok(())
    }
}

/// Puts the file name into an error raised by the line checks.
fn with_file(error: FeMatrixError, file: &str) -> FeMatrixError {
    match error {
        FeMatrixError::Format { line, reason, .. } => FeMatrixError::Format {
            file: file.to_string(),
            line,
            reason,
        },
        FeMatrixError::NotFinite {
            line,
            row,
            col,
            value,
            ..
        } => FeMatrixError::NotFinite {
            file: file.to_string(),
            line,
            row,
            col,
            value,
        },
        other => other,
    }
}

impl<R: BufRead> Read for GuardedLines<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for GuardedLines<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.pos >= self.line_text.len() {
            self.next_line()?;
        }
        Ok(&self.line_text.as_bytes()[self.pos..])
    }

    fn consume(&mut self, amount: usize) {
        self.pos = (self.pos + amount).min(self.line_text.len());
    }
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
