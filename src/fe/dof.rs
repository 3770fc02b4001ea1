//! Degrees of freedom of an FE model: which (node, direction) each matrix row belongs to.
//!
//! One [`DofMap`] type serves both sources of FE matrices — assembled from a mesh
//! ([`crate::fe::assembly`]) and read from Matrix Market files with a DOF map file
//! ([`crate::fe::matrix_market`]) — so that contacts, loads and outputs name DOFs the same way:
//! by the FE node id (the mesh's or the exporting code's node label) and a direction.
//! Rows are 0-based everywhere in the API.

use std::collections::HashMap;
use std::fmt;

/// Direction of a nodal DOF: translations along the global axes (m) and, for models exported
/// from codes with beam/shell elements, rotations about them (rad).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Direction {
    /// Translation along x.
    X,
    /// Translation along y.
    Y,
    /// Translation along z.
    Z,
    /// Rotation about x.
    Rx,
    /// Rotation about y.
    Ry,
    /// Rotation about z.
    Rz,
}

impl Direction {
    /// The translations in axis order, as used by solid elements.
    pub const TRANSLATIONS: [Direction; 3] = [Direction::X, Direction::Y, Direction::Z];

    /// Every direction, translations then rotations.
    pub const ALL: [Direction; 6] = [
        Direction::X,
        Direction::Y,
        Direction::Z,
        Direction::Rx,
        Direction::Ry,
        Direction::Rz,
    ];

    /// Parses `x`, `y`, `z`, `rx`, `ry`, `rz` (case-insensitive).
    pub fn parse(text: &str) -> Option<Direction> {
        match text.trim().to_ascii_lowercase().as_str() {
            "x" => Some(Direction::X),
            "y" => Some(Direction::Y),
            "z" => Some(Direction::Z),
            "rx" => Some(Direction::Rx),
            "ry" => Some(Direction::Ry),
            "rz" => Some(Direction::Rz),
            _ => None,
        }
    }

    /// Lower-case name as written in DOF map files.
    pub fn name(self) -> &'static str {
        match self {
            Direction::X => "x",
            Direction::Y => "y",
            Direction::Z => "z",
            Direction::Rx => "rx",
            Direction::Ry => "ry",
            Direction::Rz => "rz",
        }
    }

    /// Axis index 0, 1, 2 of a translation (or of the rotation axis).
    pub fn axis(self) -> usize {
        match self {
            Direction::X | Direction::Rx => 0,
            Direction::Y | Direction::Ry => 1,
            Direction::Z | Direction::Rz => 2,
        }
    }

    /// Whether this is a translation.
    pub fn is_translation(self) -> bool {
        matches!(self, Direction::X | Direction::Y | Direction::Z)
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One DOF: an FE node id and a direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Dof {
    /// Node id as in the mesh or the exporting code (not an index).
    pub node: u64,
    /// Direction.
    pub direction: Direction,
}

impl fmt::Display for Dof {
    /// `node.direction`, e.g. `42.y`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.node, self.direction)
    }
}

/// Why a [`DofMap`] could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DofMapError {
    /// The same (node, direction) was given two rows.
    #[error("DOF {dof} is given two rows ({first} and {second})")]
    DuplicateDof {
        /// The repeated DOF.
        dof: Dof,
        /// Its first row (0-based).
        first: usize,
        /// Its second row (0-based).
        second: usize,
    },
}

/// Bijection between matrix rows (0-based) and DOFs (node id, direction).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DofMap {
    dofs: Vec<Dof>,
    rows: HashMap<Dof, usize>,
}

impl DofMap {
    /// Builds the map from the DOF of each row, in row order.
    pub fn new(dofs: Vec<Dof>) -> Result<DofMap, DofMapError> {
        let mut rows = HashMap::with_capacity(dofs.len());
        for (row, &dof) in dofs.iter().enumerate() {
            if let Some(first) = rows.insert(dof, row) {
                return Err(DofMapError::DuplicateDof {
                    dof,
                    first,
                    second: row,
                });
            }
        }
        Ok(DofMap { dofs, rows })
    }

    /// Node-major numbering: for each node in the given order, one row per direction.
    pub fn node_major(nodes: &[u64], directions: &[Direction]) -> Result<DofMap, DofMapError> {
        let dofs = nodes
            .iter()
            .flat_map(|&node| {
                directions
                    .iter()
                    .map(move |&direction| Dof { node, direction })
            })
            .collect();
        DofMap::new(dofs)
    }

    /// Number of DOFs (matrix rows).
    pub fn len(&self) -> usize {
        self.dofs.len()
    }

    /// Whether the map has no DOFs.
    pub fn is_empty(&self) -> bool {
        self.dofs.is_empty()
    }

    /// The DOF of a row.
    pub fn dof(&self, row: usize) -> Option<Dof> {
        self.dofs.get(row).copied()
    }

    /// The DOFs in row order.
    pub fn dofs(&self) -> &[Dof] {
        &self.dofs
    }

    /// The row of a DOF.
    pub fn row(&self, node: u64, direction: Direction) -> Option<usize> {
        self.rows.get(&Dof { node, direction }).copied()
    }

    /// Rows of a node's DOFs in the given directions; `None` if any is missing.
    pub fn node_rows(&self, node: u64, directions: &[Direction]) -> Option<Vec<usize>> {
        directions.iter().map(|&d| self.row(node, d)).collect()
    }

    /// The map after keeping only the DOFs for which `keep` is true, in their old order, and
    /// for every old row its new row (`None` where removed).
    pub fn retain(&self, mut keep: impl FnMut(Dof) -> bool) -> (DofMap, Vec<Option<usize>>) {
        let mut new_of_old = Vec::with_capacity(self.dofs.len());
        let mut dofs = Vec::with_capacity(self.dofs.len());
        for &dof in &self.dofs {
            if keep(dof) {
                new_of_old.push(Some(dofs.len()));
                dofs.push(dof);
            } else {
                new_of_old.push(None);
            }
        }
        let rows = dofs.iter().enumerate().map(|(r, &d)| (d, r)).collect();
        (DofMap { dofs, rows }, new_of_old)
    }

    /// DOF names `node.direction` in row order (the form scenes use to name DOFs).
    pub fn names(&self) -> Vec<String> {
        self.dofs.iter().map(|d| d.to_string()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_major_rows_and_retain() {
        let map = DofMap::node_major(&[7, 3], &[Direction::X, Direction::Y]).unwrap();
        assert_eq!(map.len(), 4);
        assert_eq!(map.row(3, Direction::X), Some(2));
        assert_eq!(map.dof(1).unwrap().to_string(), "7.y");
        let (kept, new_of_old) = map.retain(|d| d.node != 7);
        assert_eq!(kept.len(), 2);
        assert_eq!(new_of_old, vec![None, None, Some(0), Some(1)]);
        assert_eq!(kept.row(3, Direction::Y), Some(1));
        assert_eq!(kept.row(7, Direction::Y), None);
    }

    #[test]
    fn duplicate_dof_is_an_error() {
        let d = Dof {
            node: 1,
            direction: Direction::Z,
        };
        let err = DofMap::new(vec![d, d]).unwrap_err();
        assert_eq!(err.to_string(), "DOF 1.z is given two rows (0 and 1)");
    }

    #[test]
    fn direction_names_parse_back() {
        for d in Direction::ALL {
            assert_eq!(Direction::parse(&d.name().to_uppercase()), Some(d));
        }
        assert_eq!(Direction::parse("w"), None);
    }
}
