//! An unstructured FE mesh as Gmsh describes it: nodes, elements classified on geometric
//! entities, and named physical groups that collect entities of one dimension.
//!
//! Coordinates are in metres. Node and element ids are the file's tags (labels); everything
//! else refers to nodes and elements by index into [`Mesh::nodes`] and [`Mesh::elements`].
//! A physical group holds the elements of every entity of its dimension that lists the group's
//! tag, and the nodes of those elements — the way Gmsh defines group membership.

use std::collections::HashMap;

/// Element types read and written: the solid elements assembled by [`crate::fe::assembly`]
/// and the lower-dimensional ones used for boundary groups (clamps, contact faces, load points).
/// Node order is Gmsh's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ElementKind {
    /// 1-node point (Gmsh type 15).
    Point,
    /// 2-node line (Gmsh type 1).
    Line2,
    /// 3-node triangle (Gmsh type 2), counter-clockwise in the x-y plane for 2D solids.
    Triangle3,
    /// 4-node quadrangle (Gmsh type 3), counter-clockwise in the x-y plane for 2D solids.
    Quad4,
    /// 8-node hexahedron (Gmsh type 5): nodes 0-3 one face, 4-7 the opposite face.
    Hexahedron8,
}

impl ElementKind {
    /// Gmsh element type number.
    pub fn gmsh_type(self) -> i32 {
        match self {
            ElementKind::Point => 15,
            ElementKind::Line2 => 1,
            ElementKind::Triangle3 => 2,
            ElementKind::Quad4 => 3,
            ElementKind::Hexahedron8 => 5,
        }
    }

    /// Kind of a Gmsh element type number, if supported.
    pub fn from_gmsh_type(code: i32) -> Option<ElementKind> {
        match code {
            15 => Some(ElementKind::Point),
            1 => Some(ElementKind::Line2),
            2 => Some(ElementKind::Triangle3),
            3 => Some(ElementKind::Quad4),
            5 => Some(ElementKind::Hexahedron8),
            _ => None,
        }
    }

    /// Number of nodes.
    pub fn node_count(self) -> usize {
        match self {
            ElementKind::Point => 1,
            ElementKind::Line2 => 2,
            ElementKind::Triangle3 => 3,
            ElementKind::Quad4 => 4,
            ElementKind::Hexahedron8 => 8,
        }
    }

    /// Topological dimension.
    pub fn dimension(self) -> usize {
        match self {
            ElementKind::Point => 0,
            ElementKind::Line2 => 1,
            ElementKind::Triangle3 | ElementKind::Quad4 => 2,
            ElementKind::Hexahedron8 => 3,
        }
    }

    /// Name for messages.
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Point => "point",
            ElementKind::Line2 => "2-node line",
            ElementKind::Triangle3 => "3-node triangle",
            ElementKind::Quad4 => "4-node quadrangle",
            ElementKind::Hexahedron8 => "8-node hexahedron",
        }
    }
}

/// A node: file id and coordinates (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Node tag (id) as in the file.
    pub id: u64,
    /// x, y, z (m); z = 0 in 2D meshes.
    pub coords: [f64; 3],
}

/// A geometric entity (Gmsh point, curve, surface or volume) and the physical groups that
/// contain it.
#[derive(Debug, Clone, PartialEq)]
pub struct Entity {
    /// Dimension 0-3.
    pub dim: usize,
    /// Entity tag (unique per dimension).
    pub tag: i32,
    /// Tags of the physical groups (of this dimension) holding the entity.
    pub physical_tags: Vec<i32>,
}

/// An element: file id, kind, nodes (indices into [`Mesh::nodes`]) and the entity it is
/// classified on.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Element tag (id) as in the file.
    pub id: u64,
    /// Kind.
    pub kind: ElementKind,
    /// Node indices (not ids), in Gmsh order; `kind.node_count()` of them.
    pub nodes: Vec<usize>,
    /// Dimension of its entity (= `kind.dimension()`).
    pub entity_dim: usize,
    /// Tag of its entity.
    pub entity_tag: i32,
}

/// A named physical group of one dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalGroup {
    /// Name (unique in the mesh).
    pub name: String,
    /// Dimension 0-3.
    pub dim: usize,
    /// Physical tag (unique per dimension).
    pub tag: i32,
}

/// Why a mesh query or construction failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// No physical group of that name.
    #[error("{source_name}: no physical group named `{name}` (groups: {available})")]
    UnknownGroup {
        /// Mesh source (file name or generator).
        source_name: String,
        /// Name asked for.
        name: String,
        /// Names present, comma-separated.
        available: String,
    },
    /// The mesh is inconsistent.
    #[error("{source_name}: {reason}")]
    Invalid {
        /// Mesh source.
        source_name: String,
        /// What is wrong.
        reason: String,
    },
}

/// A mesh with its physical groups.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Where the mesh came from (file path or generator name), for messages.
    pub source: String,
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Elements of every dimension.
    pub elements: Vec<Element>,
    /// Geometric entities.
    pub entities: Vec<Entity>,
    /// Named physical groups.
    pub groups: Vec<PhysicalGroup>,
}

impl Mesh {
    /// Checks internal consistency: node ids unique, element node indices valid and of the
    /// right count, element entities present, group names unique, every physical tag of an
    /// entity named by a group.
    pub fn validate(&self) -> Result<(), MeshError> {
        let invalid = |reason: String| MeshError::Invalid {
            source_name: self.source.clone(),
            reason,
        };
        let mut ids = HashMap::with_capacity(self.nodes.len());
        for (i, node) in self.nodes.iter().enumerate() {
            if let Some(j) = ids.insert(node.id, i) {
                return Err(invalid(format!(
                    "node id {} appears twice (positions {j} and {i})",
                    node.id
                )));
            }
            if node.coords.iter().any(|c| !c.is_finite()) {
                return Err(invalid(format!(
                    "node {} has a non-finite coordinate {:?}",
                    node.id, node.coords
                )));
            }
        }
        let entity_keys: std::collections::HashSet<(usize, i32)> =
            self.entities.iter().map(|e| (e.dim, e.tag)).collect();
        for element in &self.elements {
            if element.nodes.len() != element.kind.node_count() {
                return Err(invalid(format!(
                    "element {} ({}) has {} nodes",
                    element.id,
                    element.kind.name(),
                    element.nodes.len()
                )));
            }
            if let Some(&bad) = element.nodes.iter().find(|&&n| n >= self.nodes.len()) {
                return Err(invalid(format!(
                    "element {} refers to node index {bad} beyond the {} nodes",
                    element.id,
                    self.nodes.len()
                )));
            }
            if !entity_keys.contains(&(element.entity_dim, element.entity_tag)) {
                return Err(invalid(format!(
                    "element {} is classified on entity (dim {}, tag {}) that is not defined",
                    element.id, element.entity_dim, element.entity_tag
                )));
            }
        }
        let mut names = std::collections::HashSet::new();
        for group in &self.groups {
            if !names.insert(group.name.as_str()) {
                return Err(invalid(format!(
                    "physical group name `{}` is used twice",
                    group.name
                )));
            }
        }
        Ok(())
    }

    /// Dimension of the mesh: the highest element dimension (0 for an empty mesh).
    pub fn dimension(&self) -> usize {
        self.elements
            .iter()
            .map(|e| e.kind.dimension())
            .max()
            .unwrap_or(0)
    }

    /// Group by name, or an error listing the groups present.
    pub fn group(&self, name: &str) -> Result<&PhysicalGroup, MeshError> {
        self.groups
            .iter()
            .find(|g| g.name == name)
            .ok_or_else(|| MeshError::UnknownGroup {
                source_name: self.source.clone(),
                name: name.to_string(),
                available: self.group_names().join(", "),
            })
    }

    /// Names of all physical groups.
    pub fn group_names(&self) -> Vec<String> {
        self.groups.iter().map(|g| g.name.clone()).collect()
    }

    /// Indices of the elements in the named group.
    pub fn group_elements(&self, name: &str) -> Result<Vec<usize>, MeshError> {
        let group = self.group(name)?;
        let entities: std::collections::HashSet<i32> = self
            .entities
            .iter()
            .filter(|e| e.dim == group.dim && e.physical_tags.contains(&group.tag))
            .map(|e| e.tag)
            .collect();
        Ok(self
            .elements
            .iter()
            .enumerate()
            .filter(|(_, e)| e.entity_dim == group.dim && entities.contains(&e.entity_tag))
            .map(|(i, _)| i)
            .collect())
    }

    /// Indices of the nodes of the named group's elements, sorted, each once.
    pub fn group_nodes(&self, name: &str) -> Result<Vec<usize>, MeshError> {
        let mut nodes: Vec<usize> = self
            .group_elements(name)?
            .into_iter()
            .flat_map(|e| self.elements[e].nodes.iter().copied())
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        Ok(nodes)
    }

    /// Index of a node by id.
    pub fn node_index(&self, id: u64) -> Option<usize> {
        self.nodes.iter().position(|n| n.id == id)
    }

    /// Map node id → index (build once for many look-ups).
    pub fn node_index_map(&self) -> HashMap<u64, usize> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(i, n)| (n.id, i))
            .collect()
    }

    /// Number of elements of each kind, in a fixed kind order.
    pub fn element_counts(&self) -> Vec<(ElementKind, usize)> {
        [
            ElementKind::Point,
            ElementKind::Line2,
            ElementKind::Triangle3,
            ElementKind::Quad4,
            ElementKind::Hexahedron8,
        ]
        .into_iter()
        .map(|k| (k, self.elements.iter().filter(|e| e.kind == k).count()))
        .filter(|&(_, n)| n > 0)
        .collect()
    }
}

/// Builds a mesh body by body: adds nodes, elements, and groups backed by one entity each.
/// Used by the generators and by tests; the readers fill [`Mesh`] directly.
#[derive(Debug, Clone, Default)]
pub struct MeshBuilder {
    mesh: Mesh,
    next_entity_tag: [i32; 4],
}

impl MeshBuilder {
    /// Starts an empty mesh with a source name for messages.
    pub fn new(source: &str) -> MeshBuilder {
        MeshBuilder {
            mesh: Mesh {
                source: source.to_string(),
                ..Mesh::default()
            },
            next_entity_tag: [1; 4],
        }
    }

    /// Adds a node with the next id (1-based, in order) and returns its index.
    pub fn add_node(&mut self, coords: [f64; 3]) -> usize {
        let index = self.mesh.nodes.len();
        self.mesh.nodes.push(Node {
            id: index as u64 + 1,
            coords,
        });
        index
    }

    /// Number of nodes so far.
    pub fn node_count(&self) -> usize {
        self.mesh.nodes.len()
    }

    /// Coordinates of a node added before.
    pub fn coords(&self, node: usize) -> [f64; 3] {
        self.mesh.nodes[node].coords
    }

    /// Adds a physical group of the given name holding one new entity of dimension `dim` with
    /// these elements (node index lists of `kind`). Adding to an existing group name of the
    /// same dimension adds another entity to it.
    pub fn add_group(&mut self, name: &str, kind: ElementKind, elements: &[Vec<usize>]) {
        let dim = kind.dimension();
        let tag = match self.mesh.groups.iter().find(|g| g.name == name) {
            Some(g) => {
                assert_eq!(g.dim, dim, "group {name} exists with another dimension");
                g.tag
            }
            None => {
                let tag = self.mesh.groups.iter().filter(|g| g.dim == dim).count() as i32 + 1;
                self.mesh.groups.push(PhysicalGroup {
                    name: name.to_string(),
                    dim,
                    tag,
                });
                tag
            }
        };
        let entity_tag = self.next_entity_tag[dim];
        self.next_entity_tag[dim] += 1;
        self.mesh.entities.push(Entity {
            dim,
            tag: entity_tag,
            physical_tags: vec![tag],
        });
        for nodes in elements {
            let id = self.mesh.elements.len() as u64 + 1;
            self.mesh.elements.push(Element {
                id,
                kind,
                nodes: nodes.clone(),
                entity_dim: dim,
                entity_tag,
            });
        }
    }

    /// The finished mesh.
    pub fn finish(self) -> Mesh {
        self.mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_collect_elements_and_nodes() {
        let mut b = MeshBuilder::new("test");
        let n: Vec<usize> = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
            .iter()
            .map(|p| b.add_node([p[0], p[1], 0.0]))
            .collect();
        b.add_group("plate", ElementKind::Quad4, std::slice::from_ref(&n));
        b.add_group("edge", ElementKind::Line2, &[vec![n[0], n[1]]]);
        b.add_group("edge", ElementKind::Line2, &[vec![n[1], n[2]]]);
        let mesh = b.finish();
        mesh.validate().unwrap();
        assert_eq!(mesh.dimension(), 2);
        assert_eq!(mesh.group_elements("edge").unwrap().len(), 2);
        assert_eq!(mesh.group_nodes("edge").unwrap(), vec![0, 1, 2]);
        let err = mesh.group_nodes("clamp").unwrap_err();
        assert_eq!(
            err.to_string(),
            "test: no physical group named `clamp` (groups: plate, edge)"
        );
    }
}
