//! Node-to-node contact pairs between a damper face and the body face it touches.
//!
//! Each face is a physical group of boundary elements one dimension below the mesh (2-node
//! lines in 2D, quadrangles or triangles in 3D). The damper and the body are separate bodies
//! with their own (coincident) nodes on the contact; every damper node is paired with the
//! nearest body node, which must lie within a distance tolerance, and the pairing must be
//! one-to-one and cover both faces. Anything else is an error listing the unmatched nodes and
//! their nearest distances.
//!
//! # Local frame of a pair
//! - normal n: outward from the damper into the body. Each damper face element's normal is
//!   oriented away from the solid element it bounds and weighted by its length or area; the
//!   weighted sum at a node, normalised, is the node normal.
//! - tangent t: in 2D, t = n × ẑ = (n_y, −n_x, 0), along the contact edge (so (t, n, ẑ) is
//!   right-handed); in 3D, the patch's given tangent direction projected onto the plane
//!   normal to n and normalised.
//!
//! The solver forms the relative displacement r = u(damper node) − u(body node) and the local
//! displacements u_t = t·r, u_n = n·r: u_n > 0 is approach (penetration), as
//! `crate::contact` expects.
//!
//! # Area weights and stiffness scaling
//! `area_weight` is the node's tributary area of the damper face (m²): ∫ N_i dA over the face
//! elements (half of each incident edge length times the 2D thickness; a quarter of a
//! parallelogram face, Gauss-integrated for general quadrangles). Contact stiffness given per
//! unit area (N/m³, i.e. Pa/m) becomes a per-pair stiffness kt = kt_area · area_weight,
//! kn = kn_area · area_weight (N/m), see [`ContactPair::stiffness`]; the pairs of a patch then
//! carry the patch's total stiffness in proportion to the surface each represents.

use std::collections::{HashMap, HashSet};

use super::dof::{Direction, DofMap};
use super::mesh::{ElementKind, Mesh, MeshError};

/// What pairs one damper side.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchSpec {
    /// Damper side name (e.g. `left`); every pair of the patch belongs to it.
    pub side: String,
    /// Physical group of the damper's contact face.
    pub damper_group: String,
    /// Physical group of the body's (blade or platform) contact face.
    pub body_group: String,
    /// Largest distance (m) between paired nodes.
    pub tolerance: f64,
    /// 3D: tangential direction of the patch (projected onto each pair's tangent plane).
    /// Ignored in 2D, where the tangent follows the edge.
    pub tangent: Option<[f64; 3]>,
    /// 2D: out-of-plane thickness (m) that turns tributary lengths into areas. Ignored in 3D.
    pub thickness: f64,
}

/// One node-to-node contact: a damper node, the body node it touches and their frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPair {
    /// Name `<side>-<k>`, k = 1, 2, ... along the patch tangent.
    pub name: String,
    /// Damper node id.
    pub damper_node: u64,
    /// Body node id.
    pub body_node: u64,
    /// Model rows of the damper node's translations (x, y[, z]).
    pub damper_dofs: Vec<usize>,
    /// Model rows of the body node's translations (x, y[, z]).
    pub body_dofs: Vec<usize>,
    /// Unit tangent t (global components).
    pub tangent: [f64; 3],
    /// Unit normal n, from the damper into the body.
    pub normal: [f64; 3],
    /// Tributary area of the damper node on the face (m²).
    pub area_weight: f64,
    /// Distance between the two nodes (m) as meshed (0 for coincident nodes; not an initial
    /// contact gap, which the scene sets).
    pub node_distance: f64,
}

impl ContactPair {
    /// Pair stiffness (kt, kn) in N/m from stiffness per unit area (N/m³): each times the
    /// pair's tributary area.
    pub fn stiffness(&self, kt_per_area: f64, kn_per_area: f64) -> (f64, f64) {
        (
            kt_per_area * self.area_weight,
            kn_per_area * self.area_weight,
        )
    }
}

/// The pairs of one damper side.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPatch {
    /// Damper side name.
    pub side: String,
    /// Pairs, ordered along the patch tangent.
    pub pairs: Vec<ContactPair>,
}

impl ContactPatch {
    /// Total tributary area (m²) = area of the damper face.
    pub fn area(&self) -> f64 {
        self.pairs.iter().map(|p| p.area_weight).sum()
    }
}

/// Why a patch could not be paired.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContactPatchError {
    /// A group is missing.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A face group of the wrong dimension or without elements.
    #[error(
        "{mesh}: contact face group `{group}` must hold {expected}D boundary elements of the \
         {dim}D mesh ({found})"
    )]
    NotAFace {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
        /// Required dimension.
        expected: usize,
        /// Mesh dimension.
        dim: usize,
        /// What it holds.
        found: String,
    },
    /// A face element that bounds no solid element.
    #[error(
        "{mesh}: element {element} of contact face `{group}` is not a face of any {dim}D \
         element, so its outward normal is unknown"
    )]
    NotOnBoundary {
        /// Mesh source.
        mesh: String,
        /// Group.
        group: String,
        /// Element id.
        element: u64,
        /// Mesh dimension.
        dim: usize,
    },
    /// Nodes without a partner within the tolerance.
    #[error(
        "{mesh}: side `{side}`: {count} contact node(s) have no partner within {tolerance:e} m: \
         {list}"
    )]
    Unmatched {
        /// Mesh source.
        mesh: String,
        /// Side.
        side: String,
        /// Tolerance (m).
        tolerance: f64,
        /// Number of unmatched nodes.
        count: usize,
        /// `<group> node <id> (nearest <group> node <id> at <d> m)`, comma-separated (the
        /// first ten).
        list: String,
    },
    /// Two damper nodes pair with one body node.
    #[error(
        "{mesh}: side `{side}`: damper nodes {first} and {second} both pair with body node \
         {body_node}: refine the tolerance or check that the faces are meshed node to node"
    )]
    SharedPartner {
        /// Mesh source.
        mesh: String,
        /// Side.
        side: String,
        /// First damper node id.
        first: u64,
        /// Second damper node id.
        second: u64,
        /// Body node id.
        body_node: u64,
    },
    /// A contact node without DOFs in the model.
    #[error(
        "{mesh}: side `{side}`: node {node} of `{group}` has no {direction} DOF in the model \
         (clamped, or not part of an assembled element)"
    )]
    NoDof {
        /// Mesh source.
        mesh: String,
        /// Side.
        side: String,
        /// Node id.
        node: u64,
        /// Group.
        group: String,
        /// Missing direction.
        direction: Direction,
    },
    /// A 3D patch without a usable tangent direction.
    #[error("{mesh}: side `{side}`: {reason}")]
    Tangent {
        /// Mesh source.
        mesh: String,
        /// Side.
        side: String,
        /// Why.
        reason: String,
    },
    /// A bad tolerance or thickness.
    #[error("{mesh}: side `{side}`: {reason}")]
    Spec {
        /// Mesh source.
        mesh: String,
        /// Side.
        side: String,
        /// Why.
        reason: String,
    },
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Per face node: its ∫N_i dA (m² in 3D, m in 2D) and the face's unit normal (unoriented).
fn face_geometry(mesh: &Mesh, kind: ElementKind, nodes: &[usize]) -> (Vec<f64>, [f64; 3]) {
    let p = |k: usize| mesh.nodes[nodes[k]].coords;
    match kind {
        ElementKind::Line2 => {
            let d = sub(p(1), p(0));
            let len = norm(d);
            let n = if len > 0.0 {
                [d[1] / len, -d[0] / len, 0.0]
            } else {
                [0.0; 3]
            };
            (vec![0.5 * len; 2], n)
        }
        ElementKind::Triangle3 => {
            let c = cross(sub(p(1), p(0)), sub(p(2), p(0)));
            let area = 0.5 * norm(c);
            let n = if area > 0.0 {
                scale(c, 0.5 / area)
            } else {
                [0.0; 3]
            };
            (vec![area / 3.0; 3], n)
        }
        ElementKind::Quad4 => {
            const G: f64 = 0.577_350_269_189_625_8;
            let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
            let mut weights = vec![0.0; 4];
            let mut total = [0.0; 3];
            for xi in [-G, G] {
                for eta in [-G, G] {
                    let mut dxi = [0.0; 3];
                    let mut deta = [0.0; 3];
                    let mut shape = [0.0; 4];
                    for (k, [a, b]) in corners.iter().enumerate() {
                        shape[k] = 0.25 * (1.0 + xi * a) * (1.0 + eta * b);
                        let pk = p(k);
                        for c in 0..3 {
                            dxi[c] += 0.25 * a * (1.0 + eta * b) * pk[c];
                            deta[c] += 0.25 * b * (1.0 + xi * a) * pk[c];
                        }
                    }
                    let j = cross(dxi, deta);
                    let det = norm(j);
                    for k in 0..4 {
                        weights[k] += shape[k] * det;
                    }
                    total = [total[0] + j[0], total[1] + j[1], total[2] + j[2]];
                }
            }
            let len = norm(total);
            let n = if len > 0.0 {
                scale(total, 1.0 / len)
            } else {
                [0.0; 3]
            };
            (weights, n)
        }
        _ => (vec![0.0; nodes.len()], [0.0; 3]),
    }
}

fn centroid(mesh: &Mesh, nodes: &[usize]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &n in nodes {
        let p = mesh.nodes[n].coords;
        c = [c[0] + p[0], c[1] + p[1], c[2] + p[2]];
    }
    scale(c, 1.0 / nodes.len() as f64)
}

/// A face group's nodes with their outward normals (summed, weighted) and tributary weights.
struct Face {
    nodes: Vec<usize>,
    normal_sum: HashMap<usize, [f64; 3]>,
    weight: HashMap<usize, f64>,
}

fn face(mesh: &Mesh, group: &str, dim: usize) -> Result<Face, ContactPatchError> {
    let g = mesh.group(group)?;
    let elements = mesh.group_elements(group)?;
    let face_kinds_ok = elements.iter().all(|&e| {
        matches!(
            (dim, mesh.elements[e].kind),
            (2, ElementKind::Line2) | (3, ElementKind::Quad4) | (3, ElementKind::Triangle3)
        )
    });
    if g.dim + 1 != dim || elements.is_empty() || !face_kinds_ok {
        return Err(ContactPatchError::NotAFace {
            mesh: mesh.source.clone(),
            group: group.to_string(),
            expected: dim - 1,
            dim,
            found: if elements.is_empty() {
                format!("dimension {}, no elements", g.dim)
            } else {
                format!(
                    "dimension {}, {} elements such as a {}",
                    g.dim,
                    elements.len(),
                    mesh.elements[elements[0]].kind.name()
                )
            },
        });
    }
    // Solid elements touching the face nodes, to orient each face outward.
    let face_nodes: HashSet<usize> = elements
        .iter()
        .flat_map(|&e| mesh.elements[e].nodes.iter().copied())
        .collect();
    let mut solids_at: HashMap<usize, Vec<usize>> = HashMap::new();
    for (s, el) in mesh.elements.iter().enumerate() {
        if el.kind.dimension() == dim {
            for &n in &el.nodes {
                if face_nodes.contains(&n) {
                    solids_at.entry(n).or_default().push(s);
                }
            }
        }
    }
    let mut normal_sum: HashMap<usize, [f64; 3]> = HashMap::new();
    let mut weight: HashMap<usize, f64> = HashMap::new();
    for &e in &elements {
        let el = &mesh.elements[e];
        let owner = solids_at.get(&el.nodes[0]).and_then(|candidates| {
            candidates
                .iter()
                .copied()
                .find(|&s| el.nodes.iter().all(|n| mesh.elements[s].nodes.contains(n)))
        });
        let Some(owner) = owner else {
            return Err(ContactPatchError::NotOnBoundary {
                mesh: mesh.source.clone(),
                group: group.to_string(),
                element: el.id,
                dim,
            });
        };
        let (weights, mut n) = face_geometry(mesh, el.kind, &el.nodes);
        let outward = sub(
            centroid(mesh, &el.nodes),
            centroid(mesh, &mesh.elements[owner].nodes),
        );
        if dot(n, outward) < 0.0 {
            n = scale(n, -1.0);
        }
        let measure: f64 = weights.iter().sum();
        for (&node, w) in el.nodes.iter().zip(weights) {
            *weight.entry(node).or_insert(0.0) += w;
            let s = normal_sum.entry(node).or_insert([0.0; 3]);
            *s = [
                s[0] + n[0] * measure,
                s[1] + n[1] * measure,
                s[2] + n[2] * measure,
            ];
        }
    }
    let mut nodes: Vec<usize> = face_nodes.into_iter().collect();
    nodes.sort_unstable();
    Ok(Face {
        nodes,
        normal_sum,
        weight,
    })
}

/// Pairs the damper face with the body face of one side (see the module doc).
pub fn pair_patch(
    mesh: &Mesh,
    dofs: &DofMap,
    spec: &PatchSpec,
) -> Result<ContactPatch, ContactPatchError> {
    let dim = mesh.dimension();
    let spec_error = |reason: String| ContactPatchError::Spec {
        mesh: mesh.source.clone(),
        side: spec.side.clone(),
        reason,
    };
    if dim != 2 && dim != 3 {
        return Err(spec_error(format!(
            "mesh dimension {dim}, contact patches need 2 or 3"
        )));
    }
    if !(spec.tolerance.is_finite() && spec.tolerance >= 0.0) {
        return Err(spec_error(format!(
            "tolerance {} m must be finite and >= 0",
            spec.tolerance
        )));
    }
    if dim == 2 && !(spec.thickness.is_finite() && spec.thickness > 0.0) {
        return Err(spec_error(format!(
            "thickness {} m must be finite and > 0 for a 2D patch",
            spec.thickness
        )));
    }
    let damper = face(mesh, &spec.damper_group, dim)?;
    let body = face(mesh, &spec.body_group, dim)?;

    // Nearest body node of each damper node, and nearest damper node of each body node.
    let nearest = |from: usize, candidates: &[usize]| -> (usize, f64) {
        let p = mesh.nodes[from].coords;
        candidates
            .iter()
            .map(|&c| (c, norm(sub(mesh.nodes[c].coords, p))))
            .fold((usize::MAX, f64::INFINITY), |best, cur| {
                if cur.1 < best.1 {
                    cur
                } else {
                    best
                }
            })
    };
    let mut unmatched = Vec::new();
    let mut partner_of_body: HashMap<usize, usize> = HashMap::new();
    let mut matched = Vec::new();
    for &d in &damper.nodes {
        let (b, dist) = nearest(d, &body.nodes);
        if dist > spec.tolerance {
            unmatched.push(format!(
                "{} node {} (nearest {} node {} at {dist:.3e} m)",
                spec.damper_group, mesh.nodes[d].id, spec.body_group, mesh.nodes[b].id
            ));
            continue;
        }
        if let Some(&other) = partner_of_body.get(&b) {
            return Err(ContactPatchError::SharedPartner {
                mesh: mesh.source.clone(),
                side: spec.side.clone(),
                first: mesh.nodes[other].id,
                second: mesh.nodes[d].id,
                body_node: mesh.nodes[b].id,
            });
        }
        partner_of_body.insert(b, d);
        matched.push((d, b, dist));
    }
    for &b in &body.nodes {
        if !partner_of_body.contains_key(&b) {
            let (d, dist) = nearest(b, &damper.nodes);
            unmatched.push(format!(
                "{} node {} (nearest {} node {} at {dist:.3e} m)",
                spec.body_group, mesh.nodes[b].id, spec.damper_group, mesh.nodes[d].id
            ));
        }
    }
    if !unmatched.is_empty() {
        let count = unmatched.len();
        let mut list = unmatched
            .into_iter()
            .take(10)
            .collect::<Vec<_>>()
            .join(", ");
        if count > 10 {
            list.push_str(&format!(" and {} more", count - 10));
        }
        return Err(ContactPatchError::Unmatched {
            mesh: mesh.source.clone(),
            side: spec.side.clone(),
            tolerance: spec.tolerance,
            count,
            list,
        });
    }

    let hint = if dim == 3 {
        let h = spec.tangent.ok_or_else(|| ContactPatchError::Tangent {
            mesh: mesh.source.clone(),
            side: spec.side.clone(),
            reason: "a 3D contact patch needs a tangent direction".into(),
        })?;
        if !(norm(h) > 0.0 && h.iter().all(|c| c.is_finite())) {
            return Err(ContactPatchError::Tangent {
                mesh: mesh.source.clone(),
                side: spec.side.clone(),
                reason: format!("tangent direction {h:?} is not a non-zero vector"),
            });
        }
        Some(scale(h, 1.0 / norm(h)))
    } else {
        None
    };

    let directions = &Direction::TRANSLATIONS[..dim];
    let rows = |node: usize, group: &str| -> Result<Vec<usize>, ContactPatchError> {
        let id = mesh.nodes[node].id;
        directions
            .iter()
            .map(|&direction| {
                dofs.row(id, direction)
                    .ok_or_else(|| ContactPatchError::NoDof {
                        mesh: mesh.source.clone(),
                        side: spec.side.clone(),
                        node: id,
                        group: group.to_string(),
                        direction,
                    })
            })
            .collect()
    };

    let mut pairs = Vec::with_capacity(matched.len());
    for (d, b, dist) in matched {
        let s = damper.normal_sum.get(&d).copied().unwrap_or([0.0; 3]);
        let normal = scale(s, 1.0 / norm(s).max(f64::MIN_POSITIVE));
        let tangent = match hint {
            None => [normal[1], -normal[0], 0.0],
            Some(h) => {
                let t = sub(h, scale(normal, dot(h, normal)));
                if norm(t) < 1e-6 {
                    return Err(ContactPatchError::Tangent {
                        mesh: mesh.source.clone(),
                        side: spec.side.clone(),
                        reason: format!(
                            "tangent direction {h:?} is normal to the face at node {}",
                            mesh.nodes[d].id
                        ),
                    });
                }
                scale(t, 1.0 / norm(t))
            }
        };
        let weight = damper.weight.get(&d).copied().unwrap_or(0.0);
        let area_weight = if dim == 2 {
            weight * spec.thickness
        } else {
            weight
        };
        pairs.push(ContactPair {
            name: String::new(),
            damper_node: mesh.nodes[d].id,
            body_node: mesh.nodes[b].id,
            damper_dofs: rows(d, &spec.damper_group)?,
            body_dofs: rows(b, &spec.body_group)?,
            tangent,
            normal,
            area_weight,
            node_distance: dist,
        });
    }
    // Order along the mean tangent, then name.
    let mean_t = pairs.iter().fold([0.0; 3], |acc, p| {
        [
            acc[0] + p.tangent[0],
            acc[1] + p.tangent[1],
            acc[2] + p.tangent[2],
        ]
    });
    let index = mesh.node_index_map();
    let position = |p: &ContactPair| {
        index
            .get(&p.damper_node)
            .map(|&i| dot(mesh.nodes[i].coords, mean_t))
            .unwrap_or(0.0)
    };
    pairs.sort_by(|a, b| {
        position(a)
            .total_cmp(&position(b))
            .then(a.damper_node.cmp(&b.damper_node))
    });
    for (k, p) in pairs.iter_mut().enumerate() {
        p.name = format!("{}-{}", spec.side, k + 1);
    }
    Ok(ContactPatch {
        side: spec.side.clone(),
        pairs,
    })
}
