//! VTU (VTK XML unstructured grid) output for ParaView: the mesh's solid elements with point
//! data such as mode shapes, response amplitudes or contact-state codes.
//!
//! Written with the `vtkio` crate (0.7, XML feature; data arrays are base64-encoded binary,
//! which ParaView reads). Points are all mesh nodes, in mesh order; cells are the elements of
//! the mesh's dimension (triangles/quadrangles in 2D, hexahedra in 3D), with a cell array
//! `physical_tag` (the first physical group tag of the cell's entity, −1 if none) so the bodies
//! can be told apart.

use std::path::Path;

use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version,
    VertexNumbers, Vtk,
};

use super::mesh::{ElementKind, Mesh};

/// Values of a point field, one per mesh node (in mesh node order).
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValues {
    /// 3-vectors, e.g. displacements (m).
    Vectors(Vec<[f64; 3]>),
    /// Scalars, e.g. contact-state codes.
    Scalars(Vec<f64>),
}

impl FieldValues {
    fn len(&self) -> usize {
        match self {
            FieldValues::Vectors(v) => v.len(),
            FieldValues::Scalars(v) => v.len(),
        }
    }
}

/// A named point field.
#[derive(Debug, Clone, PartialEq)]
pub struct PointField {
    /// Name shown in ParaView.
    pub name: String,
    /// Values per node.
    pub values: FieldValues,
}

impl PointField {
    /// A vector field.
    pub fn vectors(name: &str, values: Vec<[f64; 3]>) -> PointField {
        PointField {
            name: name.to_string(),
            values: FieldValues::Vectors(values),
        }
    }

    /// A scalar field.
    pub fn scalars(name: &str, values: Vec<f64>) -> PointField {
        PointField {
            name: name.to_string(),
            values: FieldValues::Scalars(values),
        }
    }
}

/// Errors of VTU output.
#[derive(Debug, thiserror::Error)]
pub enum VtuError {
    /// A field does not have one value per node.
    #[error(
        "{file}: point field `{field}` has {len} values but the mesh {mesh} has {nodes} nodes"
    )]
    FieldSize {
        /// Output file.
        file: String,
        /// Field name.
        field: String,
        /// Values given.
        len: usize,
        /// Mesh source.
        mesh: String,
        /// Nodes in the mesh.
        nodes: usize,
    },
    /// The mesh has nothing to draw.
    #[error("{file}: mesh {mesh} has no 2D or 3D elements to write")]
    NoCells {
        /// Output file.
        file: String,
        /// Mesh source.
        mesh: String,
    },
    /// vtkio failed to write.
    #[error("{file}: cannot write VTU: {reason}")]
    Write {
        /// Output file.
        file: String,
        /// vtkio's reason.
        reason: String,
    },
}

/// Writes the mesh and point fields as a `.vtu` file.
pub fn write_vtu(path: &Path, mesh: &Mesh, fields: &[PointField]) -> Result<(), VtuError> {
    let file = path.display().to_string();
    let bytes = vtu_bytes(mesh, fields, &file)?;
    std::fs::write(path, bytes).map_err(|e| VtuError::Write {
        file,
        reason: e.to_string(),
    })
}

/// The VTU document as bytes; `file` names the output in messages.
pub fn vtu_bytes(mesh: &Mesh, fields: &[PointField], file: &str) -> Result<Vec<u8>, VtuError> {
    for f in fields {
        if f.values.len() != mesh.nodes.len() {
            return Err(VtuError::FieldSize {
                file: file.to_string(),
                field: f.name.clone(),
                len: f.values.len(),
                mesh: mesh.source.clone(),
                nodes: mesh.nodes.len(),
            });
        }
    }
    let dim = mesh.dimension();
    let mut connectivity = Vec::new();
    let mut offsets = Vec::new();
    let mut types = Vec::new();
    let mut tags = Vec::new();
    for el in mesh.elements.iter().filter(|e| e.kind.dimension() == dim) {
        let cell_type = match el.kind {
            ElementKind::Triangle3 => CellType::Triangle,
            ElementKind::Quad4 => CellType::Quad,
            ElementKind::Hexahedron8 => CellType::Hexahedron,
            ElementKind::Line2 => CellType::Line,
            ElementKind::Point => CellType::Vertex,
        };
        connectivity.extend(el.nodes.iter().map(|&n| n as u64));
        offsets.push(connectivity.len() as u64);
        types.push(cell_type);
        let tag = mesh
            .entities
            .iter()
            .find(|e| e.dim == el.entity_dim && e.tag == el.entity_tag)
            .and_then(|e| e.physical_tags.first().copied())
            .unwrap_or(-1);
        tags.push(tag);
    }
    if types.is_empty() || dim < 2 {
        return Err(VtuError::NoCells {
            file: file.to_string(),
            mesh: mesh.source.clone(),
        });
    }
    let points: Vec<f64> = mesh.nodes.iter().flat_map(|n| n.coords).collect();
    let point_data = fields
        .iter()
        .map(|f| match &f.values {
            FieldValues::Vectors(v) => Attribute::vectors(f.name.clone())
                .with_data(v.iter().flatten().copied().collect::<Vec<f64>>()),
            FieldValues::Scalars(v) => Attribute::scalars(f.name.clone(), 1).with_data(v.clone()),
        })
        .collect();
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        byte_order: ByteOrder::LittleEndian,
        title: mesh.source.clone(),
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: points.into(),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity,
                    offsets,
                },
                types,
            },
            data: Attributes {
                point: point_data,
                cell: vec![Attribute::scalars("physical_tag", 1).with_data(tags)],
            },
        }),
    };
    let mut bytes = Vec::new();
    vtk.write_xml(&mut bytes).map_err(|e| VtuError::Write {
        file: file.to_string(),
        reason: e.to_string(),
    })?;
    Ok(bytes)
}
