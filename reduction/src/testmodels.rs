//! Synthetic FE models for the tests, the scale example and the benches:
//! structured meshes of bilinear plane-stress quadrilaterals (2D, 2 DOFs per
//! node) or trilinear hexahedra (3D, 3 DOFs per node), consistent mass,
//! optional clamping of the face `x = 0`, several bodies side by side in one
//! model and linear springs between DOFs. This is not the project's FE
//! assembly (that lives in the main crate); it only makes FE-shaped matrices
//! of any size, assembled straight into CSC form (memory `≈ 16 B × nnz`).

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// Isotropic linear elastic material, SI units.
#[derive(Clone, Copy, Debug)]
pub struct Material {
    /// Young's modulus, Pa
    pub young: f64,
    /// Poisson's ratio
    pub poisson: f64,
    /// density, kg/m³
    pub density: f64,
    /// thickness of 2D (plane-stress) bodies, m
    pub thickness: f64,
}

impl Default for Material {
    /// Steel, 10 mm thick.
    fn default() -> Self {
        Material {
            young: 2.1e11,
            poisson: 0.3,
            density: 7850.0,
            thickness: 0.01,
        }
    }
}

/// A rectangular (2D, `nz == 0`) or box-shaped (3D) body meshed with
/// `nx × ny (× nz)` equal elements.
#[derive(Clone, Copy, Debug)]
pub struct GridBody {
    /// elements along x
    pub nx: usize,
    /// elements along y
    pub ny: usize,
    /// elements along z (0: 2D plane stress)
    pub nz: usize,
    /// size along x, m
    pub lx: f64,
    /// size along y, m
    pub ly: f64,
    /// size along z, m (ignored in 2D)
    pub lz: f64,
    /// clamp every node of the face x = 0 (the DOFs are removed)
    pub clamp_x0: bool,
}

/// DOF numbering of one body inside an assembled model.
#[derive(Clone, Debug)]
pub struct BodyDofs {
    /// nodes along x, y, z (`nz + 1 == 1` in 2D)
    pub nodes: [usize; 3],
    /// DOFs per node (2 or 3)
    pub dofs_per_node: usize,
    map: Vec<usize>,
}

impl BodyDofs {
    /// Global DOF of component `comp` of node `(ix, iy, iz)`, `None` if clamped.
    pub fn dof(&self, ix: usize, iy: usize, iz: usize, comp: usize) -> Option<usize> {
        let [nx, ny, _] = self.nodes;
        let d = self.map[(ix + nx * (iy + ny * iz)) * self.dofs_per_node + comp];
        (d != usize::MAX).then_some(d)
    }

    /// All free DOFs of the node.
    pub fn node_dofs(&self, ix: usize, iy: usize, iz: usize) -> Vec<usize> {
        (0..self.dofs_per_node)
            .filter_map(|c| self.dof(ix, iy, iz, c))
            .collect()
    }

    /// All free DOFs of the body.
    pub fn all_dofs(&self) -> Vec<usize> {
        self.map
            .iter()
            .copied()
            .filter(|&d| d != usize::MAX)
            .collect()
    }
}

/// An assembled model.
pub struct Mesh {
    /// stiffness, N/m, both triangles
    pub k: SparseColMat<usize, f64>,
    /// consistent mass, kg, both triangles
    pub m: SparseColMat<usize, f64>,
    /// DOF numbering per body, in the order given
    pub bodies: Vec<BodyDofs>,
}

impl Mesh {
    /// Number of DOFs.
    pub fn n(&self) -> usize {
        self.k.nrows()
    }
}

/// A linear spring of stiffness `k` (N/m) between two DOFs.
#[derive(Clone, Copy, Debug)]
pub struct Spring {
    /// first DOF
    pub a: usize,
    /// second DOF
    pub b: usize,
    /// stiffness, N/m
    pub k: f64,
}

fn gauss() -> [f64; 2] {
    let g = 1.0 / 3f64.sqrt();
    [-g, g]
}

/// Element stiffness and mass of a rectangular Q4 (plane stress) element.
fn q4(hx: f64, hy: f64, mat: &Material) -> (Vec<f64>, Vec<f64>) {
    let (e, nu, t) = (mat.young, mat.poisson, mat.thickness);
    let c = e / (1.0 - nu * nu);
    let d = [
        [c, c * nu, 0.0],
        [c * nu, c, 0.0],
        [0.0, 0.0, c * (1.0 - nu) / 2.0],
    ];
    let xi = [-1.0, 1.0, 1.0, -1.0];
    let eta = [-1.0, -1.0, 1.0, 1.0];
    let mut ke = vec![0.0; 64];
    let mut me = vec![0.0; 64];
    let detj = hx * hy / 4.0;
    for &gx in &gauss() {
        for &gy in &gauss() {
            let mut n = [0.0; 4];
            let mut dx = [0.0; 4];
            let mut dy = [0.0; 4];
            for a in 0..4 {
                n[a] = 0.25 * (1.0 + xi[a] * gx) * (1.0 + eta[a] * gy);
                dx[a] = 0.25 * xi[a] * (1.0 + eta[a] * gy) * 2.0 / hx;
                dy[a] = 0.25 * eta[a] * (1.0 + xi[a] * gx) * 2.0 / hy;
            }
            // B: 3 × 8
            let mut b = [[0.0; 8]; 3];
            for a in 0..4 {
                b[0][2 * a] = dx[a];
                b[1][2 * a + 1] = dy[a];
                b[2][2 * a] = dy[a];
                b[2][2 * a + 1] = dx[a];
            }
            for i in 0..8 {
                for j in 0..8 {
                    let mut s = 0.0;
                    for p in 0..3 {
                        for q in 0..3 {
                            s += b[p][i] * d[p][q] * b[q][j];
                        }
                    }
                    ke[i + 8 * j] += s * t * detj;
                }
            }
            for a in 0..4 {
                for bb in 0..4 {
                    let v = mat.density * t * n[a] * n[bb] * detj;
                    for c in 0..2 {
                        me[(2 * a + c) + 8 * (2 * bb + c)] += v;
                    }
                }
            }
        }
    }
    (ke, me)
}

/// Element stiffness and mass of a box-shaped H8 element.
fn h8(hx: f64, hy: f64, hz: f64, mat: &Material) -> (Vec<f64>, Vec<f64>) {
    let (e, nu) = (mat.young, mat.poisson);
    let l = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let mut d = [[0.0; 6]; 6];
    for i in 0..3 {
        d[i][..3].fill(l);
        d[i][i] = l + 2.0 * mu;
        d[i + 3][i + 3] = mu;
    }
    let off = [
        [-1.0, -1.0, -1.0],
        [1.0, -1.0, -1.0],
        [1.0, 1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
        [1.0, -1.0, 1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
    ];
    let mut ke = vec![0.0; 576];
    let mut me = vec![0.0; 576];
    let detj = hx * hy * hz / 8.0;
    for &g0 in &gauss() {
        for &g1 in &gauss() {
            for &g2 in &gauss() {
                let mut n = [0.0; 8];
                let mut dn = [[0.0; 3]; 8];
                for a in 0..8 {
                    let (s0, s1, s2) = (
                        1.0 + off[a][0] * g0,
                        1.0 + off[a][1] * g1,
                        1.0 + off[a][2] * g2,
                    );
                    n[a] = 0.125 * s0 * s1 * s2;
                    dn[a][0] = 0.125 * off[a][0] * s1 * s2 * 2.0 / hx;
                    dn[a][1] = 0.125 * off[a][1] * s0 * s2 * 2.0 / hy;
                    dn[a][2] = 0.125 * off[a][2] * s0 * s1 * 2.0 / hz;
                }
                let mut b = [[0.0; 24]; 6];
                for a in 0..8 {
                    let [x, y, z] = dn[a];
                    b[0][3 * a] = x;
                    b[1][3 * a + 1] = y;
                    b[2][3 * a + 2] = z;
                    b[3][3 * a] = y;
                    b[3][3 * a + 1] = x;
                    b[4][3 * a + 1] = z;
                    b[4][3 * a + 2] = y;
                    b[5][3 * a] = z;
                    b[5][3 * a + 2] = x;
                }
                let mut db = [[0.0; 24]; 6];
                for p in 0..6 {
                    for j in 0..24 {
                        db[p][j] = (0..6).map(|q| d[p][q] * b[q][j]).sum();
                    }
                }
                for i in 0..24 {
                    for j in 0..24 {
                        let s: f64 = (0..6).map(|p| b[p][i] * db[p][j]).sum();
                        ke[i + 24 * j] += s * detj;
                    }
                }
                for a in 0..8 {
                    for bb in 0..8 {
                        let v = mat.density * n[a] * n[bb] * detj;
                        for c in 0..3 {
                            me[(3 * a + c) + 24 * (3 * bb + c)] += v;
                        }
                    }
                }
            }
        }
    }
    (ke, me)
}

/// Assemble the bodies (DOFs numbered body after body, node by node) and
/// the springs into one model.
pub fn assemble(bodies: &[GridBody], springs: &[Spring], mat: &Material) -> Mesh {
    // numbering
    let mut next = 0usize;
    let mut dofs = Vec::new();
    for b in bodies {
        let three_d = b.nz > 0;
        let dpn = if three_d { 3 } else { 2 };
        let nodes = [b.nx + 1, b.ny + 1, if three_d { b.nz + 1 } else { 1 }];
        let n_nodes = nodes[0] * nodes[1] * nodes[2];
        let mut map = vec![usize::MAX; n_nodes * dpn];
        for iz in 0..nodes[2] {
            for iy in 0..nodes[1] {
                for ix in 0..nodes[0] {
                    if b.clamp_x0 && ix == 0 {
                        continue;
                    }
                    let node = ix + nodes[0] * (iy + nodes[1] * iz);
                    for c in 0..dpn {
                        map[node * dpn + c] = next;
                        next += 1;
                    }
                }
            }
        }
        dofs.push(BodyDofs {
            nodes,
            dofs_per_node: dpn,
            map,
        });
    }
    let n = next;
    // pattern: per column, free DOFs of the neighbouring nodes (sorted), plus springs
    let mut spring_cols: Vec<Vec<usize>> = vec![Vec::new(); n];
    for s in springs {
        spring_cols[s.a].push(s.b);
        spring_cols[s.b].push(s.a);
    }
    let mut col_ptr = vec![0usize; n + 1];
    let mut row_idx: Vec<usize> = Vec::new();
    let mut col_of_dof_written = 0usize;
    for bd in dofs.iter() {
        let [nx, ny, nz] = bd.nodes;
        for iz in 0..nz {
            for iy in 0..ny {
                for ix in 0..nx {
                    for c in 0..bd.dofs_per_node {
                        let Some(d) = bd.dof(ix, iy, iz, c) else {
                            continue;
                        };
                        debug_assert_eq!(d, col_of_dof_written);
                        let mut rows: Vec<usize> = Vec::with_capacity(81);
                        for jz in iz.saturating_sub(1)..(iz + 2).min(nz) {
                            for jy in iy.saturating_sub(1)..(iy + 2).min(ny) {
                                for jx in ix.saturating_sub(1)..(ix + 2).min(nx) {
                                    rows.extend(bd.node_dofs(jx, jy, jz));
                                }
                            }
                        }
                        rows.extend_from_slice(&spring_cols[d]);
                        rows.sort_unstable();
                        rows.dedup();
                        row_idx.extend_from_slice(&rows);
                        col_ptr[d + 1] = row_idx.len();
                        col_of_dof_written += 1;
                    }
                }
            }
        }
    }
    drop(spring_cols);
    let nnz = row_idx.len();
    let mut kv = vec![0.0; nnz];
    let mut mv = vec![0.0; nnz];
    let find = |row_idx: &[usize], col_ptr: &[usize], i: usize, j: usize| -> usize {
        let r = &row_idx[col_ptr[j]..col_ptr[j + 1]];
        col_ptr[j] + r.binary_search(&i).expect("pattern holds the entry")
    };
    for (b, bd) in bodies.iter().zip(&dofs) {
        let three_d = b.nz > 0;
        let dpn = bd.dofs_per_node;
        let (hx, hy) = (b.lx / b.nx as f64, b.ly / b.ny as f64);
        let (ke, me, offs): (Vec<f64>, Vec<f64>, Vec<[usize; 3]>) = if three_d {
            let (ke, me) = h8(hx, hy, b.lz / b.nz as f64, mat);
            let offs = vec![
                [0, 0, 0],
                [1, 0, 0],
                [1, 1, 0],
                [0, 1, 0],
                [0, 0, 1],
                [1, 0, 1],
                [1, 1, 1],
                [0, 1, 1],
            ];
            (ke, me, offs)
        } else {
            let (ke, me) = q4(hx, hy, mat);
            (ke, me, vec![[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
        };
        let ne = offs.len() * dpn;
        let ez = if three_d { b.nz } else { 1 };
        let mut gd = vec![None; ne];
        for iz in 0..ez {
            for iy in 0..b.ny {
                for ix in 0..b.nx {
                    for (a, o) in offs.iter().enumerate() {
                        for c in 0..dpn {
                            gd[a * dpn + c] = bd.dof(ix + o[0], iy + o[1], iz + o[2], c);
                        }
                    }
                    for (j, gj) in gd.iter().enumerate() {
                        let Some(gj) = *gj else { continue };
                        for (i, gi) in gd.iter().enumerate() {
                            let Some(gi) = *gi else { continue };
                            let p = find(&row_idx, &col_ptr, gi, gj);
                            kv[p] += ke[i + ne * j];
                            mv[p] += me[i + ne * j];
                        }
                    }
                }
            }
        }
    }
    for s in springs {
        for (i, j, v) in [
            (s.a, s.a, s.k),
            (s.b, s.b, s.k),
            (s.a, s.b, -s.k),
            (s.b, s.a, -s.k),
        ] {
            let p = find(&row_idx, &col_ptr, i, j);
            kv[p] += v;
        }
    }
    let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    let k = SparseColMat::new(sym.clone(), kv);
    let m = SparseColMat::new(sym, mv);
    Mesh { k, m, bodies: dofs }
}

/// A 2D cantilever strip `lx × ly` clamped at x = 0 with about `target_dofs`
/// DOFs and `nx ≈ aspect · ny`.
pub fn cantilever_2d(target_dofs: usize, aspect: f64) -> Mesh {
    // dofs ≈ 2 nx (ny + 1) with nx = aspect ny
    let ny = ((target_dofs as f64 / (2.0 * aspect)).sqrt().round() as usize).max(1);
    let nx = ((aspect * ny as f64).round() as usize).max(1);
    let h = 1e-3;
    assemble(
        &[GridBody {
            nx,
            ny,
            nz: 0,
            lx: nx as f64 * h,
            ly: ny as f64 * h,
            lz: 0.0,
            clamp_x0: true,
        }],
        &[],
        &Material::default(),
    )
}

/// A 3D hexahedral bar clamped at x = 0 with about `target_dofs` DOFs,
/// `nx ≈ aspect · ny`, `nz = ny`.
pub fn cantilever_3d(target_dofs: usize, aspect: f64) -> Mesh {
    // dofs ≈ 3 nx (ny + 1)^2
    let ny = ((target_dofs as f64 / (3.0 * aspect)).cbrt().round() as usize).max(1);
    let nx = ((aspect * ny as f64).round() as usize).max(1);
    let h = 1e-3;
    assemble(
        &[GridBody {
            nx,
            ny,
            nz: ny,
            lx: nx as f64 * h,
            ly: ny as f64 * h,
            lz: ny as f64 * h,
            clamp_x0: true,
        }],
        &[],
        &Material::default(),
    )
}

/// A small bladed-disk-like test model: two identical clamped 2D "blades"
/// (`nx × ny` elements, 100 mm × 20 mm) and, optionally, a free "damper"
/// block (`nx/5 × ny/3` elements, 20 mm × 6 mm) between their tips. Returns
/// the mesh and the contact DOFs: the last `n_contact` nodes of the top edge
/// of blade 0, the same nodes of blade 1 and the bottom-edge nodes of the
/// damper (both components). With `contact_stiffness`, springs join
/// blade 0's contact DOFs to the damper's (a stuck contact); otherwise the
/// damper is free.
pub fn blades_and_damper(
    nx: usize,
    ny: usize,
    damper: bool,
    n_contact: usize,
    contact_stiffness: Option<f64>,
) -> (Mesh, Vec<usize>) {
    let blade = GridBody {
        nx,
        ny,
        nz: 0,
        lx: 0.1,
        ly: 0.02,
        lz: 0.0,
        clamp_x0: true,
    };
    let dx = (nx / 5).max(1);
    let dy = (ny / 3).max(1);
    let mut bodies = vec![blade, blade];
    if damper {
        bodies.push(GridBody {
            nx: dx,
            ny: dy,
            nz: 0,
            lx: 0.02,
            ly: 0.006,
            lz: 0.0,
            clamp_x0: false,
        });
    }
    // numbering does not depend on springs: assemble once to get the maps
    let probe = assemble(&bodies, &[], &Material::default());
    let nc = n_contact.min(nx + 1);
    let mut contact = Vec::new();
    let mut b0 = Vec::new();
    for body in 0..2 {
        let bd = &probe.bodies[body];
        for ix in nx + 1 - nc..=nx {
            let d = bd.node_dofs(ix, ny, 0);
            if body == 0 {
                b0.extend_from_slice(&d);
            }
            contact.extend(d);
        }
    }
    let mut damper_dofs = Vec::new();
    if damper {
        let bd = &probe.bodies[2];
        for ix in 0..=dx {
            damper_dofs.extend(bd.node_dofs(ix, 0, 0));
        }
        contact.extend_from_slice(&damper_dofs);
    }
    match (damper, contact_stiffness) {
        (true, Some(ks)) => {
            let springs: Vec<Spring> = b0
                .iter()
                .zip(&damper_dofs)
                .map(|(&a, &b)| Spring { a, b, k: ks })
                .collect();
            (assemble(&bodies, &springs, &Material::default()), contact)
        }
        _ => (probe, contact),
    }
}
