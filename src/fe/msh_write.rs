//! Writing a [`Mesh`] as a Gmsh `.msh` 4.1 file, ASCII or binary.
//!
//! Written by hand because the `mshio` crate only reads. The output has the sections Gmsh
//! and mshio need — `$MeshFormat`, `$PhysicalNames`, `$Entities` (bounding boxes from the
//! nodes, no boundary lists), `$Nodes` (each node in one block, on the entity of the first
//! highest-dimensional element that uses it), `$Elements` (one block per entity and type).
//! Binary output is little-endian with 8-byte `size_t`, as Gmsh writes it on x86 and ARM.
//! ASCII coordinates are printed with Rust's shortest round-trip form, so a write/read round
//! trip is exact.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use super::mesh::Mesh;

/// Encoding of a written `.msh` file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MshFormat {
    /// Text.
    Ascii,
    /// Little-endian binary.
    Binary,
}

/// Why a mesh could not be written.
#[derive(Debug, thiserror::Error)]
pub enum MshWriteError {
    /// The file could not be written.
    #[error("{file}: cannot write: {source}")]
    Io {
        /// File.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// The mesh cannot be written as it is.
    #[error("{file}: cannot write mesh {mesh}: {reason}")]
    Invalid {
        /// File.
        file: String,
        /// Mesh source.
        mesh: String,
        /// Why.
        reason: String,
    },
}

/// Writes the mesh to a file.
pub fn write_msh(path: &Path, mesh: &Mesh, format: MshFormat) -> Result<(), MshWriteError> {
    let file = path.display().to_string();
    let bytes = msh_bytes(mesh, format).map_err(|reason| MshWriteError::Invalid {
        file: file.clone(),
        mesh: mesh.source.clone(),
        reason,
    })?;
    let write = || -> std::io::Result<()> {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        out.write_all(&bytes)?;
        out.flush()
    };
    write().map_err(|source| MshWriteError::Io { file, source })
}

/// The file content of the mesh in the given encoding.
pub fn msh_bytes(mesh: &Mesh, format: MshFormat) -> Result<Vec<u8>, String> {
    mesh.validate().map_err(|e| e.to_string())?;
    let mut out = Out {
        bytes: Vec::new(),
        binary: format == MshFormat::Binary,
        line_start: true,
    };
    out.text("$MeshFormat\n");
    if out.binary {
        out.text("4.1 1 8\n");
        out.bytes.extend_from_slice(&1i32.to_le_bytes());
        out.text("\n");
    } else {
        out.text("4.1 0 8\n");
    }
    out.text("$EndMeshFormat\n");

    if !mesh.groups.is_empty() {
        out.text("$PhysicalNames\n");
        out.text(&format!("{}\n", mesh.groups.len()));
        for g in &mesh.groups {
            if g.name.contains('"') || g.name.contains('\n') {
                return Err(format!(
                    "group name `{}` contains a quote or newline",
                    g.name
                ));
            }
            out.text(&format!("{} {} \"{}\"\n", g.dim, g.tag, g.name));
        }
        out.text("$EndPhysicalNames\n");
    }

    write_entities(&mut out, mesh);
    let node_entity = node_entities(mesh)?;
    write_nodes(&mut out, mesh, &node_entity);
    write_elements(&mut out, mesh);
    Ok(out.bytes)
}

/// Token writer: spaces and newlines in ASCII, packed little-endian values in binary.
struct Out {
    bytes: Vec<u8>,
    binary: bool,
    line_start: bool,
}

impl Out {
    fn text(&mut self, s: &str) {
        self.bytes.extend_from_slice(s.as_bytes());
        self.line_start = s.ends_with('\n');
    }
    fn sep(&mut self) {
        if !self.line_start {
            self.bytes.push(b' ');
        }
        self.line_start = false;
    }
    fn size(&mut self, v: usize) {
        if self.binary {
            self.bytes.extend_from_slice(&(v as u64).to_le_bytes());
        } else {
            self.sep();
            self.bytes.extend_from_slice(v.to_string().as_bytes());
        }
    }
    fn int(&mut self, v: i32) {
        if self.binary {
            self.bytes.extend_from_slice(&v.to_le_bytes());
        } else {
            self.sep();
            self.bytes.extend_from_slice(v.to_string().as_bytes());
        }
    }
    fn float(&mut self, v: f64) {
        if self.binary {
            self.bytes.extend_from_slice(&v.to_le_bytes());
        } else {
            self.sep();
            self.bytes.extend_from_slice(format!("{v:?}").as_bytes());
        }
    }
    /// Ends a line of ASCII tokens; nothing in binary.
    fn end_line(&mut self) {
        if !self.binary {
            self.bytes.push(b'\n');
            self.line_start = true;
        }
    }
    /// Closes a section's binary data with the newline Gmsh writes before the end tag.
    fn end_section(&mut self, tag: &str) {
        if self.binary {
            self.bytes.push(b'\n');
        }
        self.text(tag);
    }
}

/// Bounding box of the nodes of an entity's elements (zeros for an empty entity).
fn entity_boxes(mesh: &Mesh) -> BTreeMap<(usize, i32), [f64; 6]> {
    let mut boxes: BTreeMap<(usize, i32), [f64; 6]> = BTreeMap::new();
    for e in &mesh.elements {
        let b = boxes.entry((e.entity_dim, e.entity_tag)).or_insert([
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ]);
        for &n in &e.nodes {
            let c = mesh.nodes[n].coords;
            for k in 0..3 {
                b[k] = b[k].min(c[k]);
                b[k + 3] = b[k + 3].max(c[k]);
            }
        }
    }
    boxes
}

fn write_entities(out: &mut Out, mesh: &Mesh) {
    let boxes = entity_boxes(mesh);
    out.text("$Entities\n");
    for dim in 0..4 {
        out.size(mesh.entities.iter().filter(|e| e.dim == dim).count());
    }
    out.end_line();
    for dim in 0..4 {
        for e in mesh.entities.iter().filter(|e| e.dim == dim) {
            let b = boxes.get(&(dim, e.tag)).copied().unwrap_or([0.0; 6]);
            out.int(e.tag);
            let values = if dim == 0 { &b[..3] } else { &b[..] };
            for &v in values {
                out.float(v);
            }
            out.size(e.physical_tags.len());
            for &t in &e.physical_tags {
                out.int(t);
            }
            if dim > 0 {
                out.size(0); // no bounding entities listed
            }
            out.end_line();
        }
    }
    out.end_section("$EndEntities\n");
}

/// For every node, the entity block it is written in.
fn node_entities(mesh: &Mesh) -> Result<Vec<(usize, i32)>, String> {
    let mut owner: Vec<Option<(usize, i32)>> = vec![None; mesh.nodes.len()];
    let mut order: Vec<&super::mesh::Element> = mesh.elements.iter().collect();
    order.sort_by_key(|e| std::cmp::Reverse(e.kind.dimension()));
    for e in order {
        for &n in &e.nodes {
            owner[n].get_or_insert((e.entity_dim, e.entity_tag));
        }
    }
    let fallback = mesh
        .entities
        .iter()
        .max_by_key(|e| e.dim)
        .map(|e| (e.dim, e.tag));
    owner
        .into_iter()
        .enumerate()
        .map(|(i, o)| {
            o.or(fallback).ok_or_else(|| {
                format!(
                    "node {} belongs to no element and the mesh has no entity to hold it",
                    mesh.nodes[i].id
                )
            })
        })
        .collect()
}

fn write_nodes(out: &mut Out, mesh: &Mesh, node_entity: &[(usize, i32)]) {
    let mut blocks: BTreeMap<(usize, i32), Vec<usize>> = BTreeMap::new();
    for (i, &key) in node_entity.iter().enumerate() {
        blocks.entry(key).or_default().push(i);
    }
    let min_tag = mesh.nodes.iter().map(|n| n.id).min().unwrap_or(0);
    let max_tag = mesh.nodes.iter().map(|n| n.id).max().unwrap_or(0);
    out.text("$Nodes\n");
    out.size(blocks.len());
    out.size(mesh.nodes.len());
    out.size(min_tag as usize);
    out.size(max_tag as usize);
    out.end_line();
    for ((dim, tag), nodes) in &blocks {
        out.int(*dim as i32);
        out.int(*tag);
        out.int(0);
        out.size(nodes.len());
        out.end_line();
        for &n in nodes {
            out.size(mesh.nodes[n].id as usize);
            out.end_line();
        }
        for &n in nodes {
            for c in mesh.nodes[n].coords {
                out.float(c);
            }
            out.end_line();
        }
    }
    out.end_section("$EndNodes\n");
}

fn write_elements(out: &mut Out, mesh: &Mesh) {
    let mut blocks: BTreeMap<(usize, i32, i32), Vec<usize>> = BTreeMap::new();
    for (i, e) in mesh.elements.iter().enumerate() {
        blocks
            .entry((e.entity_dim, e.entity_tag, e.kind.gmsh_type()))
            .or_default()
            .push(i);
    }
    let min_tag = mesh.elements.iter().map(|e| e.id).min().unwrap_or(0);
    let max_tag = mesh.elements.iter().map(|e| e.id).max().unwrap_or(0);
    out.text("$Elements\n");
    out.size(blocks.len());
    out.size(mesh.elements.len());
    out.size(min_tag as usize);
    out.size(max_tag as usize);
    out.end_line();
    for ((dim, tag, code), elements) in &blocks {
        out.int(*dim as i32);
        out.int(*tag);
        out.int(*code);
        out.size(elements.len());
        out.end_line();
        for &i in elements {
            let e = &mesh.elements[i];
            out.size(e.id as usize);
            for &n in &e.nodes {
                out.size(mesh.nodes[n].id as usize);
            }
            out.end_line();
        }
    }
    out.end_section("$EndElements\n");
}
