//! Scene input for finite-element models: a Gmsh mesh assembled with materials per physical
//! group, or K and M exported as Matrix Market files with a DOF map; contact patches paired
//! node to node between facing groups; loads and outputs on physical groups; Craig-Bampton
//! reduction settings.
//!
//! This module turns those scene tables into the pieces [`crate::scene`] assembles into a
//! [`crate::model::Problem`]: a sparse [`LinearModel`] whose DOFs are named `<node>.<dir>`
//! (e.g. `123.y`), the contact points of every patch, and DOF/weight lists for group loads.
//! File paths are relative to the scene file's folder.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::contact::{ContactPoint, FrictionLaw, JenkinsLaw, SecondTangent};
use crate::fe::{
    self, Direction, DofMap, GroupMaterial, Material, Mesh, PatchSpec, PlaneAssumption,
};
use crate::model::matrix::StructuralMatrix;
use crate::model::LinearModel;
use crate::scene::error::SceneError;

/// Plane assumption of 2D meshes, as written in scenes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum PlaneSpec {
    /// Plane stress (thin bodies loaded in their plane).
    #[default]
    Stress,
    /// Plane strain.
    Strain,
}

/// `[[model.materials]]`: the material of one physical group of the mesh.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Physical group (of the mesh's dimension).
    pub group: String,
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Poisson's ratio ν (–).
    pub poisson: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Out-of-plane thickness (m) of 2D meshes.
    #[serde(default)]
    pub thickness: Option<f64>,
}

/// `[model.matrix_market]`: K and M exported by another FE code.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MatrixMarketSpec {
    /// Stiffness matrix file (N/m).
    pub stiffness: PathBuf,
    /// Mass matrix file (kg).
    pub mass: PathBuf,
    /// DOF map (CSV `node,direction,row`; header variants in [`crate::fe::matrix_market`]).
    pub dof_map: PathBuf,
    /// Row base (0 or 1) of a DOF map whose header names the row column plain `row`;
    /// absent: 1-based (headers `row0`/`index` and `row1` state their own base).
    #[serde(default)]
    pub dof_map_base: Option<usize>,
    /// Relative tolerance of the symmetry check of `general` files.
    #[serde(default = "default_symmetry_tolerance")]
    pub symmetry_tolerance: f64,
}

fn default_symmetry_tolerance() -> f64 {
    1e-8
}

/// `[reduction]`: Craig-Bampton reduction of an FE model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReductionSpec {
    /// Fixed-interface modes kept.
    pub modes: usize,
    /// Modal damping ratio of the fixed-interface modes (–).
    #[serde(default)]
    pub modal_damping: f64,
    /// Ordering of the interior Cholesky factorisation: `metis` (default) or `amd`.
    #[serde(default)]
    pub ordering: OrderingSpec,
    /// DOFs kept physical beyond the contact and output DOFs.
    #[serde(default)]
    pub boundary: BoundarySpec,
}

/// `[reduction.boundary]`: extra DOFs kept as physical coordinates of the reduced model (e.g.
/// where a reduced model is to be coupled to another one, or checked against a test).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// DOFs by name (`<node>.<dir>`, e.g. `12.x`).
    #[serde(default)]
    pub dofs: Vec<String>,
    /// Mesh physical groups: every DOF of their nodes.
    #[serde(default)]
    pub groups: Vec<String>,
}

/// Fill-reducing ordering, as written in scenes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum OrderingSpec {
    /// METIS nested dissection.
    #[default]
    Metis,
    /// Approximate minimum degree.
    Amd,
}

impl OrderingSpec {
    /// The reduction crate's ordering.
    pub fn ordering(self) -> fricbound_reduction::Ordering {
        match self {
            OrderingSpec::Metis => fricbound_reduction::Ordering::Metis,
            OrderingSpec::Amd => fricbound_reduction::Ordering::Amd,
        }
    }
}

/// `[[contact_patches]]`: one damper side paired node to node with the body it touches.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactPatchSpec {
    /// Damper side; the points are named `<side>-1`, `<side>-2`, ... along the patch.
    pub side: String,
    /// Physical group of the damper's contact face.
    pub damper: String,
    /// Physical group of the body's contact face.
    pub body: String,
    /// Tangential contact stiffness of the whole patch (N/m), shared among the pairs in
    /// proportion to their tributary areas; one number, isotropic in the tangent plane of a
    /// `jenkins-2d` patch (an array is refused: `schema::one_tangential_stiffness`).
    #[serde(deserialize_with = "crate::scene::schema::one_tangential_stiffness")]
    pub kt: f64,
    /// Normal contact stiffness of the whole patch (N/m), shared likewise.
    pub kn: f64,
    /// Friction coefficient (–).
    pub mu: f64,
    /// Initial normal gap added to the meshed one (m); negative for an interference.
    #[serde(default)]
    pub gap: f64,
    /// Initial tangential state m ∈ [−1, 1] of every point (its component m₁ along the
    /// patch tangent for `jenkins-2d`).
    #[serde(default)]
    pub initial_state: f64,
    /// `jenkins-2d` only: component m₂ of every point's initial state along its second
    /// tangent t₂ = n × t, with (m₁, m₂) in the unit disc (T(0) = μN(0)·m); default 0.
    #[serde(default)]
    pub initial_state2: f64,
    /// Largest distance (m) between paired nodes.
    #[serde(default = "default_pair_tolerance")]
    pub tolerance: f64,
    /// 3D meshes: tangential direction of the patch (projected on each pair's tangent plane).
    #[serde(default)]
    pub tangent: Option<[f64; 3]>,
    /// Tangential friction law of every point: `"jenkins-1d"` (default, along `tangent`) or
    /// `"jenkins-2d"` (3D meshes: isotropic friction in each pair's tangent plane, second
    /// tangent t₂ = n × t, initial state m = (`initial_state`, `initial_state2`)).
    #[serde(default)]
    pub law: FrictionLaw,
}

fn default_pair_tolerance() -> f64 {
    1e-9
}

/// A linear FE structure ready for a scene.
#[derive(Debug, Clone)]
pub struct FeStructure {
    /// Sparse K, M and C = αM + βK; DOFs named `<node>.<dir>`.
    pub model: LinearModel,
    /// DOF of each row.
    pub dofs: DofMap,
    /// The mesh, when the model came from one.
    pub mesh: Option<Mesh>,
    /// Out-of-plane thickness of 2D meshes (m), for contact areas.
    pub thickness: f64,
    /// Row of each DOF name.
    pub index: HashMap<String, usize>,
}

/// Resolves a path relative to the scene file's folder.
pub fn resolve(scene_file: &str, path: &Path) -> PathBuf {
    if path.is_absolute() {
        return path.to_path_buf();
    }
    Path::new(scene_file)
        .parent()
        .map(|d| d.join(path))
        .unwrap_or_else(|| path.to_path_buf())
}

/// Builds the FE structure of `[model]` from a mesh (`mesh`, `materials`, `plane`, `clamp`)
/// or from Matrix Market files (`matrix_market`), with Rayleigh damping (α 1/s, β s).
#[allow(clippy::too_many_arguments)]
pub fn build_structure(
    file: &str,
    mesh_path: Option<&Path>,
    materials: &[MaterialSpec],
    plane: PlaneSpec,
    clamp: &[String],
    matrix_market: Option<&MatrixMarketSpec>,
    rayleigh: (f64, f64),
) -> Result<FeStructure, SceneError> {
    let (stiffness, mass, dofs, mesh, thickness) = match (mesh_path, matrix_market) {
        (Some(path), None) => {
            let full = resolve(file, path);
            let mesh = fe::read_msh(&full)
                .map_err(|e| SceneError::invalid(file, "model.mesh", e.to_string()))?;
            if materials.is_empty() {
                return Err(SceneError::invalid(
                    file,
                    "model.materials",
                    "a mesh needs at least one [[model.materials]] entry (group, young, poisson, density)",
                ));
            }
            let needs_thickness = mesh.dimension() == 2;
            let mut groups = Vec::new();
            let mut thickness = 1.0;
            for (i, m) in materials.iter().enumerate() {
                let t = match (needs_thickness, m.thickness) {
                    (true, Some(t)) => t,
                    (true, None) => {
                        return Err(SceneError::invalid(
                            file,
                            format!("model.materials[{i}].thickness"),
                            "2D meshes need the out-of-plane thickness (m)",
                        ))
                    }
                    (false, t) => t.unwrap_or(1.0),
                };
                check_material(file, i, m)?;
                let material = Material {
                    young_modulus: m.young,
                    poisson_ratio: m.poisson,
                    density: m.density,
                    thickness: t,
                };
                material
                    .check(needs_thickness)
                    .map_err(|r| SceneError::invalid(file, format!("model.materials[{i}]"), r))?;
                if i == 0 {
                    thickness = t;
                }
                groups.push(GroupMaterial::new(&m.group, material));
            }
            let plane = match plane {
                PlaneSpec::Stress => PlaneAssumption::Stress,
                PlaneSpec::Strain => PlaneAssumption::Strain,
            };
            let mut model = fe::assemble(&mesh, &groups, plane)
                .map_err(|e| SceneError::invalid(file, "model.materials", e.to_string()))?;
            for (i, g) in clamp.iter().enumerate() {
                model = model.clamp_group(&mesh, g).map_err(|e| {
                    SceneError::invalid(file, format!("model.clamp[{i}]"), e.to_string())
                })?;
            }
            (
                model.stiffness,
                model.mass,
                model.dofs,
                Some(mesh),
                thickness,
            )
        }
        (None, Some(mm)) => {
            if let Some(b) = mm.dof_map_base.filter(|b| *b > 1) {
                return Err(SceneError::invalid(
                    file,
                    "model.matrix_market.dof_map_base",
                    format!("{b} is not a row base: give 0 (0-based rows) or 1 (1-based)"),
                ));
            }
            let m = fe::read_fe_matrices_with_base(
                &resolve(file, &mm.stiffness),
                &resolve(file, &mm.mass),
                &resolve(file, &mm.dof_map),
                mm.symmetry_tolerance,
                mm.dof_map_base,
            )
            .map_err(|e| SceneError::invalid(file, "model.matrix_market", e.to_string()))?;
            (m.stiffness, m.mass, m.dofs, None, 1.0)
        }
        (Some(_), Some(_)) => {
            return Err(SceneError::invalid(
                file,
                "model",
                "give either `mesh` or `matrix_market`, not both",
            ))
        }
        (None, None) => {
            return Err(SceneError::invalid(
                file,
                "model",
                "needs inline matrices (`dofs`, `mass`, `stiffness`), a `mesh`, or `matrix_market`",
            ))
        }
    };
    let n = dofs.len();
    if n == 0 {
        return Err(SceneError::invalid(
            file,
            "model",
            "the FE model has no free DOF",
        ));
    }
    let names = dofs.names();
    let index: HashMap<String, usize> = names
        .iter()
        .cloned()
        .enumerate()
        .map(|(i, s)| (s, i))
        .collect();
    let (alpha, beta) = rayleigh;
    let stiffness = StructuralMatrix::Sparse(stiffness);
    let mass = StructuralMatrix::Sparse(mass);
    let mut c = Vec::new();
    if alpha != 0.0 {
        mass.for_each_nonzero(|i, j, v| c.push((i, j, alpha * v)));
    }
    if beta != 0.0 {
        stiffness.for_each_nonzero(|i, j, v| c.push((i, j, beta * v)));
    }
    let damping = StructuralMatrix::sparse_from_triplets(n, &c);
    Ok(FeStructure {
        model: LinearModel {
            dof_names: names,
            mass,
            damping,
            stiffness,
        },
        dofs,
        mesh,
        thickness,
        index,
    })
}

/// The contact points of one patch: one Jenkins element per node pair, frame from the pair,
/// stiffness shared by tributary area. `side` is the index of the patch's damper side.
pub fn patch_contacts(
    file: &str,
    field: &str,
    structure: &FeStructure,
    spec: &ContactPatchSpec,
    side: usize,
) -> Result<Vec<ContactPoint>, SceneError> {
    let Some(mesh) = &structure.mesh else {
        return Err(SceneError::invalid(
            file,
            field,
            "contact patches need a mesh (`model.mesh`); with Matrix Market models list the \
             contact points in [[contacts]]",
        ));
    };
    let patch = fe::pair_patch(
        mesh,
        &structure.dofs,
        &PatchSpec {
            side: spec.side.clone(),
            damper_group: spec.damper.clone(),
            body_group: spec.body.clone(),
            tolerance: spec.tolerance,
            tangent: spec.tangent,
            thickness: structure.thickness,
        },
    )
    .map_err(|e| SceneError::invalid(file, field, e.to_string()))?;
    let area = patch.area();
    if patch.pairs.is_empty() || area <= 0.0 {
        return Err(SceneError::invalid(
            file,
            field,
            "the patch has no node pair",
        ));
    }
    if spec.law.is_2d() {
        if let Some(pair) = patch.pairs.iter().find(|p| p.damper_dofs.len() != 3) {
            return Err(SceneError::invalid(
                file,
                format!("{field}.law"),
                format!(
                    "`jenkins-2d` friction needs a 3D mesh; the pair `{}` has {} DOFs per node: \
                     a planar mesh uses `jenkins-1d`",
                    pair.name,
                    pair.damper_dofs.len()
                ),
            ));
        }
    }
    let node_index = mesh.node_index_map();
    let position = |id: u64| mesh.nodes[node_index[&id]].coords;
    Ok(patch
        .pairs
        .iter()
        .map(|pair| {
            let share = pair.area_weight / area;
            let row = |v: &[f64; 3]| -> Vec<(usize, f64)> {
                let mut r = Vec::new();
                for (k, (&d, &b)) in pair.damper_dofs.iter().zip(&pair.body_dofs).enumerate() {
                    if v[k] != 0.0 {
                        r.push((d, v[k]));
                        r.push((b, -v[k]));
                    }
                }
                r
            };
            ContactPoint {
                name: pair.name.clone(),
                side,
                tangential: row(&pair.tangent),
                normal: row(&pair.normal),
                // Signed meshed gap: how far the body node lies beyond the damper node along n.
                gap: {
                    let (xd, xb) = (position(pair.damper_node), position(pair.body_node));
                    (0..3)
                        .map(|k| pair.normal[k] * (xb[k] - xd[k]))
                        .sum::<f64>()
                        + spec.gap
                },
                law: JenkinsLaw {
                    kt: spec.kt * share,
                    kn: spec.kn * share,
                    mu: spec.mu,
                    initial_state: spec.initial_state,
                },
                second_tangent: spec.law.is_2d().then(|| {
                    let (n, t) = (&pair.normal, &pair.tangent);
                    let t2 = [
                        n[1] * t[2] - n[2] * t[1],
                        n[2] * t[0] - n[0] * t[2],
                        n[0] * t[1] - n[1] * t[0],
                    ];
                    SecondTangent {
                        row: row(&t2),
                        initial_state: spec.initial_state2,
                    }
                }),
                resolution: spec.law.time_resolution(),
            }
        })
        .collect())
}

/// The DOFs of a group's nodes in one direction with weights summing to 1, proportional to
/// the row sums of M (a uniform body force, e.g. centrifugal, distributes that way); equal
/// weights when the group carries no mass.
pub fn group_load(
    file: &str,
    field: &str,
    structure: &FeStructure,
    group: &str,
    direction: &str,
) -> Result<Vec<(usize, f64)>, SceneError> {
    let Some(mesh) = &structure.mesh else {
        return Err(SceneError::invalid(
            file,
            field,
            "loads on groups need a mesh (`model.mesh`); name a DOF (`dof = \"<node>.<dir>\"`) instead",
        ));
    };
    let dir = Direction::parse(direction).ok_or_else(|| {
        SceneError::invalid(
            file,
            format!("{field}.direction"),
            format!("unknown direction `{direction}` (x, y or z)"),
        )
    })?;
    let nodes = mesh
        .group_nodes(group)
        .map_err(|e| SceneError::invalid(file, format!("{field}.group"), e.to_string()))?;
    let rows: Vec<usize> = nodes
        .iter()
        .filter_map(|&i| structure.dofs.row(mesh.nodes[i].id, dir))
        .collect();
    if rows.is_empty() {
        return Err(SceneError::invalid(
            file,
            format!("{field}.group"),
            format!("group `{group}` has no free DOF in direction {direction} (clamped?)"),
        ));
    }
    let mut row_mass: HashMap<usize, f64> = rows.iter().map(|&r| (r, 0.0)).collect();
    structure.model.mass.for_each_nonzero(|i, _, v| {
        if let Some(m) = row_mass.get_mut(&i) {
            *m += v;
        }
    });
    let total: f64 = rows.iter().map(|r| row_mass[r]).sum();
    Ok(rows
        .iter()
        .map(|&r| {
            let w = if total > 0.0 {
                row_mass[&r] / total
            } else {
                1.0 / rows.len() as f64
            };
            (r, w)
        })
        .collect())
}

/// Every free DOF of a group's nodes (all directions), for DOFs kept physical in a reduction.
pub fn group_dofs(
    file: &str,
    field: &str,
    structure: &FeStructure,
    group: &str,
) -> Result<Vec<usize>, SceneError> {
    let Some(mesh) = &structure.mesh else {
        return Err(SceneError::invalid(
            file,
            field,
            "groups need an FE mesh (`model.mesh`)",
        ));
    };
    let nodes = mesh
        .group_nodes(group)
        .map_err(|e| SceneError::invalid(file, field, e.to_string()))?;
    let rows: Vec<usize> = nodes
        .iter()
        .flat_map(|&i| {
            let id = mesh.nodes[i].id;
            Direction::ALL
                .into_iter()
                .filter_map(move |d| structure.dofs.row(id, d))
        })
        .collect();
    if rows.is_empty() {
        return Err(SceneError::invalid(
            file,
            field,
            format!("group `{group}` has no free DOF (clamped?)"),
        ));
    }
    Ok(rows)
}

/// Range of Young's modulus accepted for a solid (Pa): from soft foams and gels (1 kPa) to
/// above diamond (1.2 TPa). Values outside are a unit error or a typo (SI units: Pa).
pub const YOUNG_RANGE_PA: (f64, f64) = (1e3, 1e13);

/// Range of a non-zero density accepted for a solid (kg/m³): from aerogels (1 kg/m³, with
/// margin) to above osmium (22 590 kg/m³). Zero is allowed (a massless group).
pub const DENSITY_RANGE: (f64, f64) = (0.1, 1e5);

/// Checks one `[[model.materials]]` entry's physical bounds, naming the field: Young's modulus
/// in [`YOUNG_RANGE_PA`], Poisson's ratio in (−1, 0.5) (the elastic energy is positive
/// definite only there), density 0 or in [`DENSITY_RANGE`].
fn check_material(file: &str, i: usize, m: &MaterialSpec) -> Result<(), SceneError> {
    let field = |name: &str| format!("model.materials[{i}].{name}");
    let (e_lo, e_hi) = YOUNG_RANGE_PA;
    if !(m.young.is_finite() && m.young >= e_lo && m.young <= e_hi) {
        return Err(SceneError::invalid(
            file,
            field("young"),
            format!(
                "Young's modulus {:e} Pa is outside the range of solids, {e_lo:e} .. {e_hi:e} Pa \
                 (SI units: steel is 2.1e11 Pa)",
                m.young
            ),
        ));
    }
    if !(m.poisson.is_finite() && m.poisson > -1.0 && m.poisson < 0.5) {
        return Err(SceneError::invalid(
            file,
            field("poisson"),
            format!(
                "Poisson's ratio {} must lie in (-1, 0.5): at 0.5 the material is incompressible \
                 and at -1 it has no shear stiffness, and outside the elastic energy is not \
                 positive",
                m.poisson
            ),
        ));
    }
    let (r_lo, r_hi) = DENSITY_RANGE;
    if !(m.density.is_finite() && (m.density == 0.0 || (m.density >= r_lo && m.density <= r_hi))) {
        return Err(SceneError::invalid(
            file,
            field("density"),
            format!(
                "density {:e} kg/m^3 must be 0 (massless) or within {r_lo} .. {r_hi:e} kg/m^3 (SI \
                 units: steel is 7850 kg/m^3)",
                m.density
            ),
        ));
    }
    Ok(())
}
