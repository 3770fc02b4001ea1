//! Element stiffness and consistent mass matrices of linear elastic solids.
//!
//! - 3-node triangle (constant strain), plane stress or plane strain, closed form;
//! - 4-node quadrangle, bilinear isoparametric, 2×2 Gauss (full integration);
//! - 8-node hexahedron, trilinear isoparametric, 2×2×2 Gauss (full integration).
//!
//! Matrices are dense, row-major, with DOFs ordered node by node (ux, uy[, uz] per node, nodes
//! in Gmsh order). Stiffness in N/m, mass in kg. Gauss rules are exact for the consistent mass
//! of any (straight-edged) element of these kinds, since det J is at most trilinear.
//! Full integration of bilinear/trilinear elements is stiff in bending (parasitic shear): it
//! converges with refinement, as the cantilever tests show, but needs a few elements through
//! the thickness of thin parts.

use super::material::{Material, PlaneAssumption};

/// A dense element matrix pair.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementMatrices {
    /// Number of element DOFs n (nodes × DOFs per node).
    pub size: usize,
    /// Stiffness, n×n row-major (N/m).
    pub stiffness: Vec<f64>,
    /// Consistent mass, n×n row-major (kg).
    pub mass: Vec<f64>,
}

impl ElementMatrices {
    fn zeros(size: usize) -> ElementMatrices {
        ElementMatrices {
            size,
            stiffness: vec![0.0; size * size],
            mass: vec![0.0; size * size],
        }
    }
}

/// An element whose mapping is inverted or degenerate (det J ≤ 0 somewhere), usually from a
/// clockwise node order or collapsed nodes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "Jacobian determinant {det:e} at {location} (element inverted, degenerate or wrongly ordered)"
)]
pub struct DegenerateElement {
    /// The determinant found.
    pub det: f64,
    /// Where: a corner or Gauss point.
    pub location: String,
}

const GAUSS_2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];

/// Quadrangle corner coordinates in the reference square, Gmsh order.
const QUAD_CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Hexahedron corner coordinates in the reference cube, Gmsh order.
const HEX_CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Adds `factor · Bᵀ D B` (B: R × N, D: R × R) to the N×N row-major `k`.
fn add_btdb<const R: usize, const N: usize>(
    k: &mut [f64],
    b: &[[f64; N]; R],
    d: &[[f64; R]; R],
    factor: f64,
) {
    // DB = D · B, stored by column of B.
    let mut db = [[0.0; R]; N];
    for col in 0..N {
        for i in 0..R {
            let mut s = 0.0;
            for j in 0..R {
                s += d[i][j] * b[j][col];
            }
            db[col][i] = s;
        }
    }
    // Upper triangle, mirrored, so that element (and assembled) matrices are exactly
    // symmetric rather than symmetric to round-off.
    for a in 0..N {
        for c in a..N {
            let mut s = 0.0;
            for i in 0..R {
                s += b[i][a] * db[c][i];
            }
            k[a * N + c] += factor * s;
            if c != a {
                k[c * N + a] += factor * s;
            }
        }
    }
}

/// Adds `factor · N Nᵀ` to each translation block of the mass matrix.
fn add_mass(m: &mut [f64], shape: &[f64], dofs_per_node: usize, factor: f64) {
    let n = shape.len() * dofs_per_node;
    for (i, ni) in shape.iter().enumerate() {
        for (j, nj) in shape.iter().enumerate() {
            let v = factor * (ni * nj); // (ni nj) first keeps M exactly symmetric
            for d in 0..dofs_per_node {
                m[(i * dofs_per_node + d) * n + j * dofs_per_node + d] += v;
            }
        }
    }
}

/// 3-node constant-strain triangle, counter-clockwise nodes in the x-y plane.
pub fn triangle3(
    xy: &[[f64; 2]; 3],
    material: &Material,
    plane: PlaneAssumption,
) -> Result<ElementMatrices, DegenerateElement> {
    let [[x1, y1], [x2, y2], [x3, y3]] = *xy;
    let det = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1);
    if det.is_nan() || det <= 0.0 {
        return Err(DegenerateElement {
            det,
            location: "the element (twice its signed area)".into(),
        });
    }
    let area = 0.5 * det;
    // dN/dx, dN/dy of the linear shape functions.
    let dndx = [(y2 - y3) / det, (y3 - y1) / det, (y1 - y2) / det];
    let dndy = [(x3 - x2) / det, (x1 - x3) / det, (x2 - x1) / det];
    let mut b = [[0.0; 6]; 3];
    for i in 0..3 {
        b[0][2 * i] = dndx[i];
        b[1][2 * i + 1] = dndy[i];
        b[2][2 * i] = dndy[i];
        b[2][2 * i + 1] = dndx[i];
    }
    let mut out = ElementMatrices::zeros(6);
    let t = material.thickness;
    add_btdb(
        &mut out.stiffness,
        &b,
        &material.plane_matrix(plane),
        t * area,
    );
    // Consistent mass: ρ t A / 12 · [2 1 1; 1 2 1; 1 1 2] per direction.
    let c = material.density * t * area / 12.0;
    for i in 0..3 {
        for j in 0..3 {
            let v = if i == j { 2.0 * c } else { c };
            for d in 0..2 {
                out.mass[(2 * i + d) * 6 + 2 * j + d] = v;
            }
        }
    }
    Ok(out)
}

/// Shape functions and their reference derivatives of the bilinear quadrangle at (ξ, η).
fn quad_shape(xi: f64, eta: f64) -> ([f64; 4], [[f64; 4]; 2]) {
    let mut n = [0.0; 4];
    let mut d = [[0.0; 4]; 2];
    for (i, [xi_i, eta_i]) in QUAD_CORNERS.iter().enumerate() {
        n[i] = 0.25 * (1.0 + xi * xi_i) * (1.0 + eta * eta_i);
        d[0][i] = 0.25 * xi_i * (1.0 + eta * eta_i);
        d[1][i] = 0.25 * eta_i * (1.0 + xi * xi_i);
    }
    (n, d)
}

/// Jacobian determinant and physical shape derivatives of the quadrangle.
fn quad_map(xy: &[[f64; 2]; 4], d: &[[f64; 4]; 2]) -> (f64, [[f64; 4]; 2]) {
    let mut j = [[0.0; 2]; 2];
    for i in 0..4 {
        for r in 0..2 {
            j[r][0] += d[r][i] * xy[i][0];
            j[r][1] += d[r][i] * xy[i][1];
        }
    }
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let mut dx = [[0.0; 4]; 2];
    for i in 0..4 {
        dx[0][i] = (j[1][1] * d[0][i] - j[0][1] * d[1][i]) / det;
        dx[1][i] = (-j[1][0] * d[0][i] + j[0][0] * d[1][i]) / det;
    }
    (det, dx)
}

/// 4-node bilinear quadrangle, counter-clockwise nodes in the x-y plane, 2×2 Gauss.
pub fn quad4(
    xy: &[[f64; 2]; 4],
    material: &Material,
    plane: PlaneAssumption,
) -> Result<ElementMatrices, DegenerateElement> {
    for (c, [xi, eta]) in QUAD_CORNERS.iter().enumerate() {
        let (det, _) = quad_map(xy, &quad_shape(*xi, *eta).1);
        if det.is_nan() || det <= 0.0 {
            return Err(DegenerateElement {
                det,
                location: format!("corner {}", c + 1),
            });
        }
    }
    let d = material.plane_matrix(plane);
    let t = material.thickness;
    let mut out = ElementMatrices::zeros(8);
    for &xi in &GAUSS_2 {
        for &eta in &GAUSS_2 {
            let (n, dref) = quad_shape(xi, eta);
            let (det, dx) = quad_map(xy, &dref);
            if det.is_nan() || det <= 0.0 {
                return Err(DegenerateElement {
                    det,
                    location: format!("Gauss point ({xi:.3}, {eta:.3})"),
                });
            }
            let mut b = [[0.0; 8]; 3];
            for i in 0..4 {
                b[0][2 * i] = dx[0][i];
                b[1][2 * i + 1] = dx[1][i];
                b[2][2 * i] = dx[1][i];
                b[2][2 * i + 1] = dx[0][i];
            }
            add_btdb(&mut out.stiffness, &b, &d, t * det);
            add_mass(&mut out.mass, &n, 2, material.density * t * det);
        }
    }
    Ok(out)
}

/// Shape functions and reference derivatives of the trilinear hexahedron.
fn hex_shape(p: [f64; 3]) -> ([f64; 8], [[f64; 8]; 3]) {
    let mut n = [0.0; 8];
    let mut d = [[0.0; 8]; 3];
    for (i, c) in HEX_CORNERS.iter().enumerate() {
        let f = [1.0 + p[0] * c[0], 1.0 + p[1] * c[1], 1.0 + p[2] * c[2]];
        n[i] = 0.125 * f[0] * f[1] * f[2];
        d[0][i] = 0.125 * c[0] * f[1] * f[2];
        d[1][i] = 0.125 * c[1] * f[0] * f[2];
        d[2][i] = 0.125 * c[2] * f[0] * f[1];
    }
    (n, d)
}

/// Jacobian determinant and physical shape derivatives of the hexahedron.
fn hex_map(xyz: &[[f64; 3]; 8], d: &[[f64; 8]; 3]) -> (f64, [[f64; 8]; 3]) {
    let mut j = [[0.0; 3]; 3];
    for i in 0..8 {
        for r in 0..3 {
            for c in 0..3 {
                j[r][c] += d[r][i] * xyz[i][c];
            }
        }
    }
    let cof = [
        [
            j[1][1] * j[2][2] - j[1][2] * j[2][1],
            j[0][2] * j[2][1] - j[0][1] * j[2][2],
            j[0][1] * j[1][2] - j[0][2] * j[1][1],
        ],
        [
            j[1][2] * j[2][0] - j[1][0] * j[2][2],
            j[0][0] * j[2][2] - j[0][2] * j[2][0],
            j[0][2] * j[1][0] - j[0][0] * j[1][2],
        ],
        [
            j[1][0] * j[2][1] - j[1][1] * j[2][0],
            j[0][1] * j[2][0] - j[0][0] * j[2][1],
            j[0][0] * j[1][1] - j[0][1] * j[1][0],
        ],
    ];
    let det = j[0][0] * cof[0][0] + j[0][1] * cof[1][0] + j[0][2] * cof[2][0];
    // dN/dx = J⁻¹ dN/dξ with J⁻¹ = adj(J)/det, adj = cofᵀ arranged above as inverse rows.
    let mut dx = [[0.0; 8]; 3];
    for i in 0..8 {
        for r in 0..3 {
            dx[r][i] = (cof[r][0] * d[0][i] + cof[r][1] * d[1][i] + cof[r][2] * d[2][i]) / det;
        }
    }
    (det, dx)
}

/// 8-node trilinear hexahedron (Gmsh node order, positive volume), 2×2×2 Gauss.
pub fn hexahedron8(
    xyz: &[[f64; 3]; 8],
    material: &Material,
) -> Result<ElementMatrices, DegenerateElement> {
    for (c, corner) in HEX_CORNERS.iter().enumerate() {
        let (det, _) = hex_map(xyz, &hex_shape(*corner).1);
        if det.is_nan() || det <= 0.0 {
            return Err(DegenerateElement {
                det,
                location: format!("corner {}", c + 1),
            });
        }
    }
    let (lambda, mu) = lame(material);
    let mut out = ElementMatrices::zeros(24);
    for &a in &GAUSS_2 {
        for &b in &GAUSS_2 {
            for &c in &GAUSS_2 {
                let (n, dref) = hex_shape([a, b, c]);
                let (det, dx) = hex_map(xyz, &dref);
                if det.is_nan() || det <= 0.0 {
                    return Err(DegenerateElement {
                        det,
                        location: format!("Gauss point ({a:.3}, {b:.3}, {c:.3})"),
                    });
                }
                add_isotropic_solid(&mut out.stiffness, &dx, lambda, mu, det);
                add_mass(&mut out.mass, &n, 3, material.density * det);
            }
        }
    }
    Ok(out)
}

/// Lamé constants (λ, μ) of the material (Pa).
fn lame(material: &Material) -> (f64, f64) {
    let (e, nu) = (material.young_modulus, material.poisson_ratio);
    (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        material.shear_modulus(),
    )
}

/// Adds `factor · Bᵀ D B` of an isotropic 3D solid node block by node block:
/// K_ab\[i\]\[j\] = λ g_a\[i\] g_b\[j\] + μ g_a\[j\] g_b\[i\] + μ δ_ij g_a·g_b with g = ∇N. Equal to the
/// B-matrix product for isotropic D (a unit test checks), with about a quarter of the work.
fn add_isotropic_solid(k: &mut [f64], dx: &[[f64; 8]; 3], lambda: f64, mu: f64, factor: f64) {
    const N: usize = 24;
    let g = |node: usize| [dx[0][node], dx[1][node], dx[2][node]];
    for a in 0..8 {
        let ga = g(a);
        for b in a..8 {
            let gb = g(b);
            let dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
            for i in 0..3 {
                for j in 0..3 {
                    let mut v = lambda * (ga[i] * gb[j]) + mu * (ga[j] * gb[i]);
                    if i == j {
                        v += mu * dot;
                    }
                    let v = factor * v;
                    let (row, col) = (3 * a + i, 3 * b + j);
                    if a == b && j < i {
                        continue; // the diagonal block's lower part is mirrored below
                    }
                    k[row * N + col] += v;
                    if row != col {
                        k[col * N + row] += v;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum(m: &[f64]) -> f64 {
        m.iter().sum()
    }

    fn max_asym(m: &[f64], n: usize) -> f64 {
        let mut worst = 0.0_f64;
        for i in 0..n {
            for j in 0..n {
                worst = worst.max((m[i * n + j] - m[j * n + i]).abs());
            }
        }
        worst
    }

    #[test]
    fn single_element_mass_totals_and_symmetry() {
        let mat = Material::steel(0.01);
        let quad = quad4(
            &[[0.0, 0.0], [2.0, 0.1], [2.2, 1.0], [0.1, 1.2]],
            &mat,
            PlaneAssumption::Stress,
        )
        .unwrap();
        // Area of the quadrangle by the shoelace formula.
        let pts = [[0.0, 0.0], [2.0, 0.1], [2.2, 1.0], [0.1, 1.2]];
        let area: f64 = 0.5
            * (0..4)
                .map(|i| {
                    let (a, b) = (pts[i], pts[(i + 1) % 4]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>();
        let expected = 2.0 * mat.density * mat.thickness * area; // two directions
        assert!((sum(&quad.mass) - expected).abs() < 1e-10 * expected);
        assert_eq!(max_asym(&quad.stiffness, 8), 0.0);

        let tri = triangle3(
            &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            &mat,
            PlaneAssumption::Strain,
        )
        .unwrap();
        let expected = 2.0 * mat.density * mat.thickness * 0.5;
        assert!((sum(&tri.mass) - expected).abs() < 1e-10 * expected);
    }

    #[test]
    fn clockwise_quad_is_rejected() {
        let mat = Material::steel(0.01);
        let err = quad4(
            &[[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]],
            &mat,
            PlaneAssumption::Stress,
        )
        .unwrap_err();
        assert!(err.to_string().contains("corner 1"), "{err}");
        let err = triangle3(
            &[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]],
            &mat,
            PlaneAssumption::Stress,
        )
        .unwrap_err();
        assert!(err.det == 0.0);
    }

    #[test]
    fn isotropic_hex_blocks_equal_the_b_matrix_product() {
        let mat = Material::steel(0.0);
        let xyz = [
            [0.0, 0.0, 0.0],
            [1.1, 0.1, 0.0],
            [1.0, 0.9, 0.1],
            [-0.1, 1.0, 0.0],
            [0.1, 0.0, 1.2],
            [1.0, -0.1, 1.0],
            [1.2, 1.1, 0.9],
            [0.0, 0.9, 1.0],
        ];
        let fast = hexahedron8(&xyz, &mat).unwrap();
        let d = mat.solid_matrix();
        let mut reference = vec![0.0; 24 * 24];
        for &a in &GAUSS_2 {
            for &b in &GAUSS_2 {
                for &c in &GAUSS_2 {
                    let (_, dref) = hex_shape([a, b, c]);
                    let (det, dx) = hex_map(&xyz, &dref);
                    let mut bm = [[0.0; 24]; 6];
                    for i in 0..8 {
                        let (nx, ny, nz) = (dx[0][i], dx[1][i], dx[2][i]);
                        bm[0][3 * i] = nx;
                        bm[1][3 * i + 1] = ny;
                        bm[2][3 * i + 2] = nz;
                        bm[3][3 * i] = ny;
                        bm[3][3 * i + 1] = nx;
                        bm[4][3 * i + 1] = nz;
                        bm[4][3 * i + 2] = ny;
                        bm[5][3 * i] = nz;
                        bm[5][3 * i + 2] = nx;
                    }
                    add_btdb(&mut reference, &bm, &d, det);
                }
            }
        }
        let scale = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (f, r) in fast.stiffness.iter().zip(&reference) {
            assert!((f - r).abs() < 1e-12 * scale, "{f} vs {r}");
        }
        assert_eq!(max_asym(&fast.stiffness, 24), 0.0);
    }

    #[test]
    fn unit_cube_hex_mass_and_rigid_translation() {
        let mat = Material::steel(0.0);
        let xyz = HEX_CORNERS.map(|c| [0.5 * (c[0] + 1.0), 0.5 * (c[1] + 1.0), 0.5 * (c[2] + 1.0)]);
        let hex = hexahedron8(&xyz, &mat).unwrap();
        assert!((sum(&hex.mass) - 3.0 * mat.density).abs() < 1e-9 * mat.density);
        let u: Vec<f64> = (0..24)
            .map(|k| if k % 3 == 1 { 1.0 } else { 0.0 })
            .collect();
        let scale = hex.stiffness[0].abs();
        for i in 0..24 {
            let f: f64 = (0..24).map(|j| hex.stiffness[i * 24 + j] * u[j]).sum();
            assert!(f.abs() < 1e-9 * scale);
        }
    }
}
