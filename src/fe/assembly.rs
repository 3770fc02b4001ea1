//! Assembly of the global stiffness K and consistent mass M of a mesh, and Dirichlet clamping.
//!
//! The elements of the mesh's own dimension (triangles and quadrangles in 2D, hexahedra in 3D)
//! are assembled, each with the material of the physical group that holds it; every such
//! element must be in exactly one material group. Lower-dimensional elements (lines, points,
//! boundary faces) only serve as groups.
//!
//! 2D meshes lie in the x-y plane (z is ignored); their triangles and quadrangles may be
//! ordered either way round (clockwise ones are reversed), while hexahedra must have a positive
//! volume in Gmsh's node order. Inverted or degenerate elements are errors naming the element.
//!
//! DOF numbering (one [`DofMap`]): the nodes of the assembled elements in mesh order, node-major,
//! directions x, y (2D) or x, y, z (3D).
//!
//! K and M share one sparsity pattern, built from the node adjacency before any value is
//! computed, and element matrices are added in place. This keeps memory at the size of the
//! result: a triplet list for a 1M-DOF hexahedral model would hold about 200 million entries
//! (5 GB) per matrix before compression.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use rayon::prelude::*;

use super::dof::{Direction, DofMap};
use super::element::{self, DegenerateElement, ElementMatrices};
use super::material::{Material, PlaneAssumption};
use super::mesh::{ElementKind, Mesh, MeshError};
use super::sparse::{self, SparseMatrix};

/// The material of one physical group.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupMaterial {
    /// Physical group name (of the mesh's dimension).
    pub group: String,
    /// Its material.
    pub material: Material,
}

impl GroupMaterial {
    /// Material for a group.
    pub fn new(group: &str, material: Material) -> GroupMaterial {
        GroupMaterial {
            group: group.to_string(),
            material,
        }
    }
}

/// Errors of assembly and clamping; each names the mesh and the group or element.
#[derive(Debug, thiserror::Error)]
pub enum AssemblyError {
    /// A named group is missing or the mesh is inconsistent.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A material value is out of range.
    #[error("{mesh}: material of group `{group}`: {reason}")]
    Material {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
        /// What is wrong.
        reason: String,
    },
    /// A material group holds no element of the mesh's dimension.
    #[error(
        "{mesh}: group `{group}` (dimension {group_dim}) holds no {dim}D element to give a \
         material to"
    )]
    NotASolidGroup {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
        /// Group dimension.
        group_dim: usize,
        /// Mesh dimension.
        dim: usize,
    },
    /// Elements without a material.
    #[error(
        "{mesh}: {count} {dim}D element(s) belong to no material group (first: element \
         {first}); material groups: {groups}"
    )]
    NoMaterial {
        /// Mesh source.
        mesh: String,
        /// Number of such elements.
        count: usize,
        /// Mesh dimension.
        dim: usize,
        /// Id of the first.
        first: u64,
        /// Material groups given.
        groups: String,
    },
    /// An element in two material groups.
    #[error("{mesh}: element {element} is in two material groups, `{first}` and `{second}`")]
    TwoMaterials {
        /// Mesh source.
        mesh: String,
        /// Element id.
        element: u64,
        /// First group.
        first: String,
        /// Second group.
        second: String,
    },
    /// An element kind that cannot be assembled in this dimension.
    #[error("{mesh}: element {element} is a {kind}, which cannot be assembled in a {dim}D mesh")]
    Unsupported {
        /// Mesh source.
        mesh: String,
        /// Element id.
        element: u64,
        /// Kind name.
        kind: &'static str,
        /// Mesh dimension.
        dim: usize,
    },
    /// An inverted or degenerate element.
    #[error("{mesh}: element {element} ({kind}) in group `{group}`: {source}")]
    Degenerate {
        /// Mesh source.
        mesh: String,
        /// Element id.
        element: u64,
        /// Kind name.
        kind: &'static str,
        /// Group.
        group: String,
        /// Details.
        source: DegenerateElement,
    },
    /// The mesh has no element of dimension 2 or 3.
    #[error("{mesh}: no 2D or 3D elements to assemble")]
    Empty {
        /// Mesh source.
        mesh: String,
    },
    /// A group node without the DOF asked for.
    #[error("{mesh}: node {node} of group `{group}` has no {direction} DOF in the model")]
    NoDof {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
        /// Node id.
        node: u64,
        /// Direction.
        direction: Direction,
    },
    /// A load that cannot be applied.
    #[error("{mesh}: load on group `{group}`: {reason}")]
    Load {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
        /// Why.
        reason: String,
    },
    /// A clamp group whose nodes carry no DOF of the model.
    #[error("{mesh}: clamp group `{group}` has no node with a DOF in the model")]
    ClampEmpty {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
    },
}

/// An assembled linear FE model.
#[derive(Debug, Clone)]
pub struct FeModel {
    /// Stiffness matrix K (N/m), full symmetric storage.
    pub stiffness: SparseMatrix,
    /// Consistent mass matrix M (kg), full symmetric storage.
    pub mass: SparseMatrix,
    /// DOF of each row.
    pub dofs: DofMap,
    /// Spatial dimension (2 or 3): DOFs per node.
    pub dimension: usize,
}

impl FeModel {
    /// Translation directions of this model's nodes: x, y (2D) or x, y, z (3D).
    pub fn directions(&self) -> &'static [Direction] {
        &Direction::TRANSLATIONS[..self.dimension]
    }

    /// The model with every DOF of the named group's nodes removed (u = 0 there: a clamp).
    /// Rows and columns are deleted from K and M and the DOF map is renumbered consistently.
    pub fn clamp_group(&self, mesh: &Mesh, group: &str) -> Result<FeModel, AssemblyError> {
        let nodes: std::collections::HashSet<u64> = mesh
            .group_nodes(group)?
            .into_iter()
            .map(|i| mesh.nodes[i].id)
            .collect();
        if !self.dofs.dofs().iter().any(|d| nodes.contains(&d.node)) {
            return Err(AssemblyError::ClampEmpty {
                mesh: mesh.source.clone(),
                group: group.to_string(),
            });
        }
        Ok(self.without_dofs(|d| nodes.contains(&d.node)))
    }

    /// The model with the DOFs for which `remove` is true deleted.
    pub fn without_dofs(&self, remove: impl Fn(super::dof::Dof) -> bool) -> FeModel {
        let (dofs, new_of_old) = self.dofs.retain(|d| !remove(d));
        let n = dofs.len();
        FeModel {
            stiffness: sparse::keep_rows_cols(&self.stiffness, &new_of_old, n),
            mass: sparse::keep_rows_cols(&self.mass, &new_of_old, n),
            dofs,
            dimension: self.dimension,
        }
    }

    /// Rows of the named group's nodes in one direction, in node order; an error if a node of
    /// the group has no such DOF (clamped, or not on an assembled element).
    pub fn group_rows(
        &self,
        mesh: &Mesh,
        group: &str,
        direction: Direction,
    ) -> Result<Vec<usize>, AssemblyError> {
        mesh.group_nodes(group)?
            .into_iter()
            .map(|n| {
                let id = mesh.nodes[n].id;
                self.dofs
                    .row(id, direction)
                    .ok_or_else(|| AssemblyError::NoDof {
                        mesh: mesh.source.clone(),
                        group: group.to_string(),
                        node: id,
                        direction,
                    })
            })
            .collect()
    }

    /// Nodal forces (N, one per model row) equivalent to a uniform body force on the named
    /// group (e.g. the centrifugal pre-load of a damper): total force `total` (N) along the
    /// unit vector `direction`, distributed as f = (total / m_g) · M u, where u is the unit
    /// translation along `direction` of the group's nodes and m_g the group's mass. M u is
    /// ∫ ρ N_i dV per node, so this is the consistent load of a uniform acceleration.
    pub fn body_force(
        &self,
        mesh: &Mesh,
        group: &str,
        direction: [f64; 3],
        total: f64,
    ) -> Result<Vec<f64>, AssemblyError> {
        let len = direction.iter().map(|c| c * c).sum::<f64>().sqrt();
        let bad = |reason: String| AssemblyError::Load {
            mesh: mesh.source.clone(),
            group: group.to_string(),
            reason,
        };
        if !(len.is_finite() && len > 0.0 && total.is_finite()) {
            return Err(bad(format!(
                "body force {total} N along {direction:?} needs a finite total and a non-zero \
                 direction"
            )));
        }
        let nodes: std::collections::HashSet<u64> = mesh
            .group_nodes(group)?
            .into_iter()
            .map(|n| mesh.nodes[n].id)
            .collect();
        let u: Vec<f64> = self
            .dofs
            .dofs()
            .iter()
            .map(|d| {
                if nodes.contains(&d.node) && d.direction.is_translation() {
                    direction[d.direction.axis()] / len
                } else {
                    0.0
                }
            })
            .collect();
        let mu = sparse::mul_vec(&self.mass, &u);
        // Keep only the group's rows (a body coupled to others through shared nodes would
        // otherwise leak load onto them).
        let f: Vec<f64> = self
            .dofs
            .dofs()
            .iter()
            .zip(&mu)
            .map(|(d, &v)| if nodes.contains(&d.node) { v } else { 0.0 })
            .collect();
        let mass: f64 = f.iter().zip(&u).map(|(a, b)| a * b).sum();
        if mass.is_nan() || mass <= 0.0 {
            return Err(bad(
                "the group has no mass in the model (density 0 or clamped)".into(),
            ));
        }
        Ok(f.iter().map(|v| v * total / mass).collect())
    }

    /// Expands a vector over the model's DOFs to one 3-vector per mesh node (zeros where a
    /// node has no DOF, e.g. clamped nodes); for VTU output of mode shapes or responses.
    pub fn node_vectors(&self, mesh: &Mesh, values: &[f64]) -> Vec<[f64; 3]> {
        let index = mesh.node_index_map();
        let mut out = vec![[0.0; 3]; mesh.nodes.len()];
        for (row, dof) in self.dofs.dofs().iter().enumerate() {
            if let (Some(&i), Some(&v)) = (index.get(&dof.node), values.get(row)) {
                if dof.direction.is_translation() {
                    out[i][dof.direction.axis()] = v;
                }
            }
        }
        out
    }
}

/// Assembles K and M of the mesh with a material per group (see the module doc).
pub fn assemble(
    mesh: &Mesh,
    materials: &[GroupMaterial],
    plane: PlaneAssumption,
) -> Result<FeModel, AssemblyError> {
    let source = mesh.source.clone();
    let dim = mesh.dimension();
    if dim < 2 {
        return Err(AssemblyError::Empty { mesh: source });
    }
    // Material of every solid element.
    let mut material_of: Vec<Option<usize>> = vec![None; mesh.elements.len()];
    for (m, gm) in materials.iter().enumerate() {
        gm.material
            .check(dim == 2)
            .map_err(|reason| AssemblyError::Material {
                mesh: source.clone(),
                group: gm.group.clone(),
                reason,
            })?;
        let group = mesh.group(&gm.group)?;
        let elements = mesh.group_elements(&gm.group)?;
        if group.dim != dim || elements.is_empty() {
            return Err(AssemblyError::NotASolidGroup {
                mesh: source.clone(),
                group: gm.group.clone(),
                group_dim: group.dim,
                dim,
            });
        }
        for e in elements {
            if let Some(other) = material_of[e] {
                return Err(AssemblyError::TwoMaterials {
                    mesh: source.clone(),
                    element: mesh.elements[e].id,
                    first: materials[other].group.clone(),
                    second: gm.group.clone(),
                });
            }
            material_of[e] = Some(m);
        }
    }
    let solids: Vec<usize> = (0..mesh.elements.len())
        .filter(|&e| mesh.elements[e].kind.dimension() == dim)
        .collect();
    let unassigned: Vec<usize> = solids
        .iter()
        .copied()
        .filter(|&e| material_of[e].is_none())
        .collect();
    if let Some(&first) = unassigned.first() {
        return Err(AssemblyError::NoMaterial {
            mesh: source,
            count: unassigned.len(),
            dim,
            first: mesh.elements[first].id,
            groups: materials
                .iter()
                .map(|m| m.group.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    for &e in &solids {
        let el = &mesh.elements[e];
        let ok = matches!(
            (dim, el.kind),
            (2, ElementKind::Triangle3) | (2, ElementKind::Quad4) | (3, ElementKind::Hexahedron8)
        );
        if !ok {
            return Err(AssemblyError::Unsupported {
                mesh: source,
                element: el.id,
                kind: el.kind.name(),
                dim,
            });
        }
    }

    let (dofs, dof_node) = numbering(mesh, &solids, dim)?;
    let pattern = Pattern::new(&solids, mesh, &dof_node, dofs.len() / dim, dim);
    let mut kval = vec![0.0; pattern.row_idx.len()];
    let mut mval = vec![0.0; pattern.row_idx.len()];

    // Element matrices in parallel chunks, scattered serially.
    const CHUNK: usize = 2048;
    for chunk in solids.chunks(CHUNK) {
        let computed: Vec<Result<ElementMatrices, AssemblyError>> = chunk
            .par_iter()
            .map(|&e| element_matrices(mesh, e, &materials[material_of[e].unwrap_or(0)], plane))
            .collect();
        for (&e, result) in chunk.iter().zip(computed) {
            let em = result?;
            let nodes: Vec<usize> = oriented_nodes(mesh, e)
                .iter()
                .map(|&n| dof_node[n].unwrap_or(0))
                .collect();
            pattern.scatter(&nodes, &em, &mut kval, &mut mval);
        }
    }

    let n = dofs.len();
    let symbolic =
        SymbolicSparseColMat::<usize>::new_checked(n, n, pattern.col_ptr, None, pattern.row_idx);
    Ok(FeModel {
        stiffness: SparseColMat::new(symbolic.clone(), kval),
        mass: SparseColMat::new(symbolic, mval),
        dofs,
        dimension: dim,
    })
}

/// The DOF map [`assemble`] produces for this mesh, without assembling: the nodes of the
/// elements of the mesh's dimension in mesh order, node-major, x, y[, z].
pub fn dof_map(mesh: &Mesh) -> Result<DofMap, AssemblyError> {
    let dim = mesh.dimension();
    if dim < 2 {
        return Err(AssemblyError::Empty {
            mesh: mesh.source.clone(),
        });
    }
    let solids: Vec<usize> = (0..mesh.elements.len())
        .filter(|&e| mesh.elements[e].kind.dimension() == dim)
        .collect();
    Ok(numbering(mesh, &solids, dim)?.0)
}

/// DOF map and, per mesh node, its position among the DOF-carrying nodes.
fn numbering(
    mesh: &Mesh,
    solids: &[usize],
    dim: usize,
) -> Result<(DofMap, Vec<Option<usize>>), AssemblyError> {
    let mut dof_node: Vec<Option<usize>> = vec![None; mesh.nodes.len()];
    for &e in solids {
        for &n in &mesh.elements[e].nodes {
            dof_node[n] = Some(0);
        }
    }
    let mut node_ids = Vec::new();
    for (n, slot) in dof_node.iter_mut().enumerate() {
        if slot.is_some() {
            *slot = Some(node_ids.len());
            node_ids.push(mesh.nodes[n].id);
        }
    }
    let dofs = DofMap::node_major(&node_ids, &Direction::TRANSLATIONS[..dim]).map_err(|e| {
        AssemblyError::Mesh(MeshError::Invalid {
            source_name: mesh.source.clone(),
            reason: e.to_string(),
        })
    })?;
    Ok((dofs, dof_node))
}

/// Element matrices of mesh element `e` with its group's material.
fn element_matrices(
    mesh: &Mesh,
    e: usize,
    gm: &GroupMaterial,
    plane: PlaneAssumption,
) -> Result<ElementMatrices, AssemblyError> {
    let el = &mesh.elements[e];
    let nodes = oriented_nodes(mesh, e);
    let xy = |k: usize| {
        let c = mesh.nodes[nodes[k]].coords;
        [c[0], c[1]]
    };
    let result = match el.kind {
        ElementKind::Triangle3 => element::triangle3(&[xy(0), xy(1), xy(2)], &gm.material, plane),
        ElementKind::Quad4 => element::quad4(&[xy(0), xy(1), xy(2), xy(3)], &gm.material, plane),
        ElementKind::Hexahedron8 => {
            let xyz: [[f64; 3]; 8] = std::array::from_fn(|k| mesh.nodes[nodes[k]].coords);
            element::hexahedron8(&xyz, &gm.material)
        }
        other => {
            return Err(AssemblyError::Unsupported {
                mesh: mesh.source.clone(),
                element: el.id,
                kind: other.name(),
                dim: mesh.dimension(),
            })
        }
    };
    result.map_err(|source| AssemblyError::Degenerate {
        mesh: mesh.source.clone(),
        element: el.id,
        kind: el.kind.name(),
        group: gm.group.clone(),
        source,
    })
}

/// The element's nodes in the order its matrices use. 2D elements have no intrinsic
/// orientation (Gmsh orders them by the surface's normal, which may point along −z), so a
/// clockwise triangle or quadrangle (negative signed area) is taken in reverse order.
/// Hexahedra keep their order: a negative volume there is a real error.
fn oriented_nodes(mesh: &Mesh, e: usize) -> Vec<usize> {
    let el = &mesh.elements[e];
    let mut nodes = el.nodes.clone();
    if matches!(el.kind, ElementKind::Triangle3 | ElementKind::Quad4) {
        let k = nodes.len();
        let twice_area: f64 = (0..k)
            .map(|i| {
                let (a, b) = (
                    mesh.nodes[nodes[i]].coords,
                    mesh.nodes[nodes[(i + 1) % k]].coords,
                );
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        if twice_area < 0.0 {
            nodes[1..].reverse();
        }
    }
    nodes
}

/// CSC sparsity pattern of K and M: DOF (node a, dir) couples to every DOF of every node that
/// shares an element with a. Columns of one node share its sorted neighbour list, so the rows
/// of neighbour b in any column of a start at `col_ptr + position(b) · dim`.
struct Pattern {
    dim: usize,
    adjacency: Vec<Vec<usize>>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl Pattern {
    fn new(
        solids: &[usize],
        mesh: &Mesh,
        dof_node: &[Option<usize>],
        n_nodes: usize,
        dim: usize,
    ) -> Pattern {
        // Node adjacency (including the node itself), sorted and unique.
        let mut adjacency: Vec<Vec<usize>> = vec![Vec::new(); n_nodes];
        for &e in solids {
            let nodes: Vec<usize> = mesh.elements[e]
                .nodes
                .iter()
                .filter_map(|&n| dof_node[n])
                .collect();
            for &a in &nodes {
                adjacency[a].extend_from_slice(&nodes);
            }
        }
        for list in &mut adjacency {
            list.sort_unstable();
            list.dedup();
        }
        let mut col_ptr = Vec::with_capacity(n_nodes * dim + 1);
        col_ptr.push(0);
        let total: usize = adjacency.iter().map(|l| l.len() * dim * dim).sum();
        let mut row_idx = Vec::with_capacity(total);
        for list in &adjacency {
            for _ in 0..dim {
                for &b in list {
                    for d in 0..dim {
                        row_idx.push(b * dim + d);
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        Pattern {
            dim,
            adjacency,
            col_ptr,
            row_idx,
        }
    }

    /// Adds an element's matrices; `nodes` are the element's nodes as DOF-node numbers.
    fn scatter(&self, nodes: &[usize], em: &ElementMatrices, k: &mut [f64], m: &mut [f64]) {
        let (n, dim) = (em.size, self.dim);
        for (a, &ga) in nodes.iter().enumerate() {
            let neighbours = &self.adjacency[ga];
            for (b, &gb) in nodes.iter().enumerate() {
                // The pattern holds every pair of nodes sharing an element.
                let Ok(position) = neighbours.binary_search(&gb) else {
                    continue;
                };
                for dc in 0..dim {
                    let base = self.col_ptr[ga * dim + dc] + position * dim;
                    let col = a * dim + dc;
                    for dr in 0..dim {
                        let row = b * dim + dr;
                        k[base + dr] += em.stiffness[row * n + col];
                        m[base + dr] += em.mass[row * n + col];
                    }
                }
            }
        }
    }
}
