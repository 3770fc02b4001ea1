//! Linear elastic isotropic materials and their constitutive matrices.
//!
//! Units SI: Young's modulus E in Pa, density ρ in kg/m³, thickness t in m (2D elements only:
//! the out-of-plane thickness that turns the plane model into a body).

/// A linear elastic isotropic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E (Pa), > 0.
    pub young_modulus: f64,
    /// Poisson's ratio ν, in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Density ρ (kg/m³), ≥ 0.
    pub density: f64,
    /// Out-of-plane thickness t (m) of 2D elements, > 0; ignored by 3D elements.
    pub thickness: f64,
}

/// Plane assumption of 2D elements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlaneAssumption {
    /// σ_zz = 0: thin plates loaded in their plane (blades, dampers cut by a plane).
    #[default]
    Stress,
    /// ε_zz = 0: long bodies of constant section.
    Strain,
}

impl Material {
    /// Structural steel: E = 210 GPa, ν = 0.3, ρ = 7850 kg/m³, with the given thickness (m).
    pub fn steel(thickness: f64) -> Material {
        Material {
            young_modulus: 210e9,
            poisson_ratio: 0.3,
            density: 7850.0,
            thickness,
        }
    }

    /// Checks the values; the message names the first bad one.
    pub fn check(&self, needs_thickness: bool) -> Result<(), String> {
        let Material {
            young_modulus: e,
            poisson_ratio: nu,
            density: rho,
            thickness: t,
        } = *self;
        if !(e.is_finite() && e > 0.0) {
            return Err(format!("Young's modulus {e} Pa must be finite and > 0"));
        }
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(format!("Poisson's ratio {nu} must lie in (-1, 0.5)"));
        }
        if !(rho.is_finite() && rho >= 0.0) {
            return Err(format!("density {rho} kg/m^3 must be finite and >= 0"));
        }
        if needs_thickness && !(t.is_finite() && t > 0.0) {
            return Err(format!(
                "thickness {t} m must be finite and > 0 for 2D elements"
            ));
        }
        Ok(())
    }

    /// Shear modulus G = E / (2 (1 + ν)) (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Plane constitutive matrix D (Pa) relating (σxx, σyy, τxy) to (εxx, εyy, γxy).
    pub fn plane_matrix(&self, plane: PlaneAssumption) -> [[f64; 3]; 3] {
        let e = self.young_modulus;
        let nu = self.poisson_ratio;
        let g = self.shear_modulus();
        match plane {
            PlaneAssumption::Stress => {
                let c = e / (1.0 - nu * nu);
                [[c, c * nu, 0.0], [c * nu, c, 0.0], [0.0, 0.0, g]]
            }
            PlaneAssumption::Strain => {
                let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
                [
                    [c * (1.0 - nu), c * nu, 0.0],
                    [c * nu, c * (1.0 - nu), 0.0],
                    [0.0, 0.0, g],
                ]
            }
        }
    }

    /// 3D constitutive matrix D (Pa) relating (σxx, σyy, σzz, τxy, τyz, τzx) to
    /// (εxx, εyy, εzz, γxy, γyz, γzx).
    pub fn solid_matrix(&self) -> [[f64; 6]; 6] {
        let e = self.young_modulus;
        let nu = self.poisson_ratio;
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = self.shear_modulus();
        let mut d = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                d[i][j] = lambda;
            }
            d[i][i] = lambda + 2.0 * mu;
            d[i + 3][i + 3] = mu;
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_stress_uniaxial_gives_young_modulus() {
        // εyy chosen so that σyy = 0: εyy = −ν εxx; then σxx = E εxx.
        let m = Material::steel(0.01);
        let d = m.plane_matrix(PlaneAssumption::Stress);
        let (exx, eyy) = (1e-3, -0.3e-3);
        let sxx = d[0][0] * exx + d[0][1] * eyy;
        let syy = d[1][0] * exx + d[1][1] * eyy;
        assert!((sxx - 210e9 * 1e-3).abs() < 1e-3);
        assert!(syy.abs() < 1e-3);
    }

    #[test]
    fn bad_values_are_named() {
        let mut m = Material::steel(0.01);
        m.poisson_ratio = 0.5;
        assert!(m.check(true).unwrap_err().contains("Poisson"));
        m = Material::steel(0.0);
        assert!(m.check(true).unwrap_err().contains("thickness"));
        assert!(m.check(false).is_ok());
    }
}
