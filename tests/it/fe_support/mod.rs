//! Shared helpers of the FE tests: structured test meshes, a sparse static solve and the
//! lowest generalized eigenvalues (subspace iteration on sparse Cholesky factors).
// Not every test file uses every helper; grid loops index several arrays by node position.
#![allow(dead_code, clippy::needless_range_loop)]

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use fricbound::fe::mesh::{ElementKind, Mesh, MeshBuilder};
use fricbound::fe::sparse::{self, SparseMatrix};

/// Element family of a structured test mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    Quads,
    Triangles,
    Hexes,
}

/// Deterministic pseudo-random numbers in [-1, 1) (no extra dependency).
pub struct Lcg(u64);

impl Lcg {
    pub fn new(seed: u64) -> Lcg {
        Lcg(seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407))
    }
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A box [0, lx] × [0, ly] (× [0, lz] for hexes) with n divisions per axis. Groups: `solid`,
/// `root` (x = 0 face/edge), `tip` (x = lx face/edge). `distortion` moves every interior node
/// by up to that fraction of the local spacing (boundary nodes stay, so the volume is exact).
pub fn box_mesh(family: Family, size: [f64; 3], n: [usize; 3], distortion: f64, seed: u64) -> Mesh {
    let mut b = MeshBuilder::new(&format!("test box {family:?} {n:?}"));
    let three_d = family == Family::Hexes;
    let nz = if three_d { n[2] } else { 0 };
    let mut rng = Lcg::new(seed);
    let mut id = vec![vec![vec![0usize; nz + 1]; n[1] + 1]; n[0] + 1];
    for k in 0..=nz {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                let h = [
                    size[0] / n[0] as f64,
                    size[1] / n[1] as f64,
                    if three_d { size[2] / n[2] as f64 } else { 0.0 },
                ];
                let mut p = [i as f64 * h[0], j as f64 * h[1], k as f64 * h[2]];
                let interior =
                    i > 0 && i < n[0] && j > 0 && j < n[1] && (!three_d || (k > 0 && k < nz));
                if interior {
                    for c in 0..3 {
                        p[c] += distortion * h[c] * rng.next();
                    }
                }
                id[i][j][k] = b.add_node(p);
            }
        }
    }
    let mut solids = Vec::new();
    let mut root = Vec::new();
    let mut tip = Vec::new();
    match family {
        Family::Quads | Family::Triangles => {
            for j in 0..n[1] {
                for i in 0..n[0] {
                    let (a, bb, c, d) = (
                        id[i][j][0],
                        id[i + 1][j][0],
                        id[i + 1][j + 1][0],
                        id[i][j + 1][0],
                    );
                    if family == Family::Quads {
                        solids.push(vec![a, bb, c, d]);
                    } else {
                        solids.push(vec![a, bb, c]);
                        solids.push(vec![a, c, d]);
                    }
                }
                root.push(vec![id[0][j][0], id[0][j + 1][0]]);
                tip.push(vec![id[n[0]][j][0], id[n[0]][j + 1][0]]);
            }
            let kind = if family == Family::Quads {
                ElementKind::Quad4
            } else {
                ElementKind::Triangle3
            };
            b.add_group("solid", kind, &solids);
            b.add_group("root", ElementKind::Line2, &root);
            b.add_group("tip", ElementKind::Line2, &tip);
        }
        Family::Hexes => {
            for k in 0..nz {
                for j in 0..n[1] {
                    for i in 0..n[0] {
                        let q = |di: usize, dj: usize, dk: usize| id[i + di][j + dj][k + dk];
                        solids.push(vec![
                            q(0, 0, 0),
                            q(1, 0, 0),
                            q(1, 1, 0),
                            q(0, 1, 0),
                            q(0, 0, 1),
                            q(1, 0, 1),
                            q(1, 1, 1),
                            q(0, 1, 1),
                        ]);
                    }
                    let (i0, i1) = (0, n[0]);
                    root.push(vec![
                        id[i0][j][k],
                        id[i0][j + 1][k],
                        id[i0][j + 1][k + 1],
                        id[i0][j][k + 1],
                    ]);
                    tip.push(vec![
                        id[i1][j][k],
                        id[i1][j + 1][k],
                        id[i1][j + 1][k + 1],
                        id[i1][j][k + 1],
                    ]);
                }
            }
            b.add_group("solid", ElementKind::Hexahedron8, &solids);
            b.add_group("root", ElementKind::Quad4, &root);
            b.add_group("tip", ElementKind::Quad4, &tip);
        }
    }
    b.finish()
}

/// Solves K u = f for SPD K (sparse Cholesky).
pub fn solve(k: &SparseMatrix, f: &[f64]) -> Vec<f64> {
    let llt = k
        .sp_cholesky(Side::Lower)
        .expect("K must be positive definite");
    let mut rhs = Mat::from_fn(f.len(), 1, |i, _| f[i]);
    llt.solve_in_place(rhs.as_mut());
    (0..f.len()).map(|i| rhs[(i, 0)]).collect()
}

/// The `count` lowest eigenvalues λ of K φ = λ M φ (K positive definite), by subspace
/// iteration with 2·count + 4 vectors to a relative change below 1e-9 (round-off
/// of stiff clamped models is about 1e-11).
pub fn lowest_eigenvalues(k: &SparseMatrix, m: &SparseMatrix, count: usize) -> Vec<f64> {
    let n = k.nrows();
    let p = (2 * count + 4).min(n);
    let llt = k
        .sp_cholesky(Side::Lower)
        .expect("K must be positive definite");
    let mut rng = Lcg::new(7);
    let mut x: Vec<Vec<f64>> = (0..p)
        .map(|_| (0..n).map(|_| rng.next()).collect())
        .collect();
    let mut previous = vec![f64::INFINITY; count];
    for _ in 0..200 {
        // Y = K⁻¹ M X
        let mut rhs = Mat::from_fn(n, p, |i, j| 0.0 * x[j][i]);
        for j in 0..p {
            let mx = sparse::mul_vec(m, &x[j]);
            for i in 0..n {
                rhs[(i, j)] = mx[i];
            }
        }
        llt.solve_in_place(rhs.as_mut());
        let y: Vec<Vec<f64>> = (0..p)
            .map(|j| (0..n).map(|i| rhs[(i, j)]).collect())
            .collect();
        let ky: Vec<Vec<f64>> = y.iter().map(|v| sparse::mul_vec(k, v)).collect();
        let my: Vec<Vec<f64>> = y.iter().map(|v| sparse::mul_vec(m, v)).collect();
        let dotp = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
        let kr = Mat::from_fn(p, p, |a, b| dotp(&y[a], &ky[b]));
        let mr = Mat::from_fn(p, p, |a, b| dotp(&y[a], &my[b]));
        // Reduced problem: Mr = V D Vᵀ, W = V D^-1/2, A = Wᵀ Kr W = Q Λ Qᵀ.
        let me = mr.self_adjoint_eigen(Side::Lower).expect("reduced mass");
        let w = Mat::from_fn(p, p, |a, b| me.U()[(a, b)] / me.S()[b].sqrt());
        let a = w.transpose() * &kr * &w;
        let ae = a
            .self_adjoint_eigen(Side::Lower)
            .expect("reduced stiffness");
        let q = &w * ae.U();
        let lambdas: Vec<f64> = (0..p).map(|i| ae.S()[i]).collect();
        x = (0..p)
            .map(|j| {
                (0..n)
                    .map(|i| (0..p).map(|l| y[l][i] * q[(l, j)]).sum())
                    .collect()
            })
            .collect();
        let converged = (0..count).all(|i| ((lambdas[i] - previous[i]) / lambdas[i]).abs() < 1e-9);
        previous.copy_from_slice(&lambdas[..count]);
        if converged {
            break;
        }
    }
    previous
}

/// Natural frequencies (Hz) from eigenvalues ω².
pub fn hz(lambdas: &[f64]) -> Vec<f64> {
    lambdas
        .iter()
        .map(|l| l.sqrt() / (2.0 * std::f64::consts::PI))
        .collect()
}
