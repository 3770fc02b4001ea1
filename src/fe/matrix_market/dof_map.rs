//! The DOF map: the (node, direction) of every matrix row, read from and written to its CSV
//! file, with the headers and directions it accepts.

use std::fs::File;
use std::io::{self};
use std::path::Path;

use super::error::FeMatrixError;
use crate::fe::dof::{Direction, Dof, DofMap};

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
