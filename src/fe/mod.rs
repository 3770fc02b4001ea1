//! Finite-element input and output: meshes, element assembly, Matrix Market models, contact
//! patches, VTU output and the blade-pair mesh generator.
//!
//! May use `crate::contact` (a contact patch becomes contact points) and no other layer; the
//! model layer above keeps a mesh for results on it ([`crate::model::FeOrigin`]).
//!
//! Two ways lead to a linear FE model ([`FeModel`] / [`FeMatrices`]: sparse K and M in full
//! symmetric storage with a [`DofMap`] naming every row by node id and direction):
//! - a Gmsh mesh ([`read_msh`]) assembled with a material per physical group ([`assemble`]),
//!   clamped by group ([`FeModel::clamp_group`]);
//! - K and M exported by another FE code as Matrix Market files with a DOF map
//!   ([`read_fe_matrices`]).
//!
//! Contacts between a damper and the bodies it touches are node-to-node pairs between two
//! facing physical groups with a local frame per pair ([`pair_patch`]). Results go to ParaView
//! as VTU ([`write_vtu`]). Units are SI throughout (m, kg, N, Pa).
//!
//! ```
//! use std::path::Path;
//! use fricbound::fe::{self, blade_pair::BladePairParams, GroupMaterial, Material};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mesh = fe::read_msh(Path::new("meshes/blade-pair/blade-pair-2d.msh"))?;
//! let steel = Material::steel(0.01); // 10 mm thick plane-stress plates
//! let materials = ["blade1", "blade2", "damper"].map(|g| GroupMaterial::new(g, steel));
//! let model = fe::assemble(&mesh, &materials, fe::PlaneAssumption::Stress)?
//!     .clamp_group(&mesh, "clamp")?;
//! // Contact pairs of the two damper sides, with the DOF rows of the clamped model.
//! for spec in BladePairParams::default().patch_specs()? {
//!     let patch = fe::pair_patch(&mesh, &model.dofs, &spec)?;
//!     assert_eq!(patch.pairs.len(), 7);
//! }
//! // Centrifugal pre-load of 120 N on the damper, and the excitation row.
//! let preload = model.body_force(&mesh, "damper", [0.0, 1.0, 0.0], 120.0)?;
//! let tip_x = model.group_rows(&mesh, "excitation", fe::Direction::X)?[0];
//! assert_eq!(preload.len(), model.dofs.len());
//! assert!(tip_x < model.dofs.len());
//! # Ok(())
//! # }
//! ```

pub mod assembly;
pub mod blade_pair;
pub mod contact_patch;
pub mod dof;
pub mod element;
pub mod material;
pub mod matrix_market;
pub mod mesh;
pub mod msh_read;
pub mod msh_write;
pub mod sparse;
pub mod vtu;

pub use assembly::{assemble, AssemblyError, FeModel, GroupMaterial};
pub use contact_patch::{pair_patch, ContactPair, ContactPatch, ContactPatchError, PatchSpec};
pub use dof::{Direction, Dof, DofMap};
pub use material::{Material, PlaneAssumption};
pub use matrix_market::{
    read_fe_matrices, read_fe_matrices_with_base, FeMatrices, FeMatrixError, DOF_MAP_HEADERS,
};
pub use mesh::{ElementKind, Mesh, MeshError, PhysicalGroup};
pub use msh_read::{read_msh, MshReadError};
pub use msh_write::{write_msh, MshFormat, MshWriteError};
pub use sparse::SparseMatrix;
pub use vtu::{write_vtu, PointField, VtuError};
