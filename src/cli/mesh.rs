//! `fricbound mesh`: generate the blade-pair mesh, or summarise a Gmsh file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::fe::assembly::{self, AssemblyError};
use crate::fe::blade_pair::{self, BladePairError, BladePairParams};
use crate::fe::contact_patch::{pair_patch, ContactPatchError};
use crate::fe::mesh::Mesh;
use crate::fe::msh_read::{read_msh, MshReadError};
use crate::fe::msh_write::{write_msh, MshFormat, MshWriteError};
use crate::fe::vtu::{write_vtu, PointField, VtuError};

/// Mesh subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum MeshCommand {
    /// Two clamped blades with platforms and a wedge damper between them (2D quadrangles, or
    /// 3D hexahedra with --3d); see meshes/blade-pair/README.md.
    BladePair(BladePairArgs),
    /// Summarise a Gmsh .msh 4.1 file: nodes, elements, physical groups, DOFs.
    Info {
        /// Mesh file.
        file: PathBuf,
    },
}

/// Options of `fricbound mesh blade-pair`. Lengths in metres, angles in degrees.
#[derive(Debug, Clone, clap::Args)]
pub struct BladePairArgs {
    /// Refinement: element size = blade width / (5 N).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub refine: usize,
    /// Extra refinement of the contact faces and the damper (more contact pairs per side on
    /// the same blades).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub contact_refine: usize,
    /// Node pairs per contact face (2 or more), instead of the count the refinement gives
    /// (with --contact-refine 1).
    #[arg(long, value_name = "N")]
    pub contact_pairs: Option<usize>,
    /// Apical angle of the wedge damper (degrees, 30..170).
    #[arg(long, default_value_t = 120.0, value_name = "DEG")]
    pub beta: f64,
    /// Platform width along x from the blade face (m) [default: 0.01].
    #[arg(long, value_name = "M")]
    pub platform_width: Option<f64>,
    /// Out-of-plane thickness (2D) or extrusion depth (3D) (m) [default: 0.01].
    #[arg(long, value_name = "M")]
    pub thickness: Option<f64>,
    /// Output mesh file [default: blade-pair-2d.msh or blade-pair-3d.msh].
    #[arg(long, value_name = "FILE.msh")]
    pub out: Option<PathBuf>,
    /// Extrude to 3D hexahedra.
    #[arg(long = "3d")]
    pub three_d: bool,
    /// Write the .msh file in binary instead of ASCII.
    #[arg(long)]
    pub binary: bool,
    /// Also write the mesh as VTU for ParaView (with the contact pairs marked).
    #[arg(long, value_name = "FILE.vtu")]
    pub vtu: Option<PathBuf>,
}

/// Errors of the mesh command.
#[derive(Debug, thiserror::Error)]
pub enum MeshCommandError {
    /// Bad generator parameters.
    #[error(transparent)]
    Params(#[from] BladePairError),
    /// Writing the mesh failed.
    #[error(transparent)]
    Write(#[from] MshWriteError),
    /// Reading a mesh failed.
    #[error(transparent)]
    Read(#[from] MshReadError),
    /// DOF numbering failed.
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    /// Contact pairing failed.
    #[error(transparent)]
    Contact(Box<ContactPatchError>),
    /// VTU output failed.
    #[error(transparent)]
    Vtu(#[from] VtuError),
}

impl From<ContactPatchError> for MeshCommandError {
    fn from(e: ContactPatchError) -> Self {
        MeshCommandError::Contact(Box::new(e))
    }
}

/// Runs a mesh subcommand and returns what to print.
pub fn run(command: &MeshCommand) -> Result<String, MeshCommandError> {
    match command {
        MeshCommand::BladePair(args) => blade_pair_command(args),
        MeshCommand::Info { file } => {
            let mesh = read_msh(file)?;
            summary(&mesh)
        }
    }
}

/// Generator parameters from the command-line options.
pub fn params(args: &BladePairArgs) -> BladePairParams {
    let defaults = BladePairParams::default();
    BladePairParams {
        refine: args.refine,
        contact_refine: args.contact_refine,
        contact_pairs: args.contact_pairs,
        beta_deg: args.beta,
        platform_width: args.platform_width.unwrap_or(defaults.platform_width),
        thickness: args.thickness.unwrap_or(defaults.thickness),
        three_d: args.three_d,
        ..defaults
    }
}

/// `fricbound mesh blade-pair`: generates the blade-pair mesh, writes it as Gmsh `.msh` (and
/// the contact patches as VTU if asked) and returns a summary of the mesh and its contact sides.
fn blade_pair_command(args: &BladePairArgs) -> Result<String, MeshCommandError> {
    let params = params(args);
    let mesh = blade_pair::generate(&params)?;
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from(if params.three_d {
            "blade-pair-3d.msh"
        } else {
            "blade-pair-2d.msh"
        })
    });
    let format = if args.binary {
        MshFormat::Binary
    } else {
        MshFormat::Ascii
    };
    write_msh(&out, &mesh, format)?;
    let mut text = format!("wrote {}\n", out.display());
    if let Some(vtu) = &args.vtu {
        write_contact_vtu(vtu, &mesh, &params)?;
        let _ = writeln!(text, "wrote {}", vtu.display());
    }
    text.push_str(&summary(&mesh)?);
    let dofs = assembly::dof_map(&mesh)?;
    for spec in params.patch_specs()? {
        let patch = pair_patch(&mesh, &dofs, &spec)?;
        let first = &patch.pairs[0];
        let _ = writeln!(
            text,
            "contact side {:<5} {} pairs, area {:.3e} m^2, normal ({:.4}, {:.4}, {:.4}), tangent \
             ({:.4}, {:.4}, {:.4})",
            patch.side,
            patch.pairs.len(),
            patch.area(),
            first.normal[0],
            first.normal[1],
            first.normal[2],
            first.tangent[0],
            first.tangent[1],
            first.tangent[2]
        );
    }
    Ok(text)
}

/// VTU of the mesh with a point scalar `contact_side` (1 left, 2 right, 0 elsewhere).
fn write_contact_vtu(
    path: &Path,
    mesh: &Mesh,
    params: &BladePairParams,
) -> Result<(), MeshCommandError> {
    let mut side = vec![0.0; mesh.nodes.len()];
    for (k, spec) in params.patch_specs()?.iter().enumerate() {
        for group in [&spec.damper_group, &spec.body_group] {
            for n in mesh
                .group_nodes(group)
                .map_err(|e| MeshCommandError::from(ContactPatchError::from(e)))?
            {
                side[n] = (k + 1) as f64;
            }
        }
    }
    write_vtu(path, mesh, &[PointField::scalars("contact_side", side)])?;
    Ok(())
}

/// Nodes, elements, groups and DOFs of a mesh.
pub fn summary(mesh: &Mesh) -> Result<String, MeshCommandError> {
    let mut s = String::new();
    let _ = writeln!(s, "mesh         {}", mesh.source);
    let _ = writeln!(
        s,
        "nodes        {} ({}D)",
        mesh.nodes.len(),
        mesh.dimension()
    );
    let counts: Vec<String> = mesh
        .element_counts()
        .iter()
        .map(|(k, n)| format!("{n} {}", k.name()))
        .collect();
    let _ = writeln!(s, "elements     {}", counts.join(", "));
    if mesh.dimension() >= 2 {
        let dofs = assembly::dof_map(mesh)?;
        let _ = writeln!(s, "DOFs         {} (before clamping)", dofs.len());
    }
    let _ = writeln!(s, "groups");
    for g in &mesh.groups {
        let elements = mesh.group_elements(&g.name).map(|e| e.len()).unwrap_or(0);
        let nodes = mesh.group_nodes(&g.name).map(|n| n.len()).unwrap_or(0);
        let _ = writeln!(
            s,
            "  {:<16} dim {} tag {:<3} {:>8} elements {:>8} nodes",
            g.name, g.dim, g.tag, elements, nodes
        );
    }
    Ok(s)
}
