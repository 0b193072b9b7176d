//! Isotropic linear elasticity.

use crate::error::{Error, Result};

/// Isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsotropicMaterial {
    /// Young's modulus `E` (Pa), > 0.
    pub youngs_modulus: f64,
    /// Poisson's ratio `ν`, in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Density `ρ` (kg/m³), > 0.
    pub density: f64,
}

impl IsotropicMaterial {
    /// Structural steel as in the benchmarks (docs/benchmarks.md, B1): E = 2.1e11 Pa, ν = 0.3,
    /// ρ = 7850 kg/m³.
    pub const STEEL: IsotropicMaterial = IsotropicMaterial {
        youngs_modulus: 2.1e11,
        poisson_ratio: 0.3,
        density: 7850.0,
    };

    /// Checks the ranges; the error names the parameter (`material.youngsModulus`, ...), the value
    /// and the reason.
    pub fn validate(&self) -> Result<()> {
        let e = self.youngs_modulus;
        if !e.is_finite() || e <= 0.0 {
            return Err(Error::invalid_value(
                "material.youngsModulus",
                e,
                "must be positive and finite",
            ));
        }
        let nu = self.poisson_ratio;
        if !nu.is_finite() || nu <= -1.0 || nu >= 0.5 {
            return Err(Error::invalid_value(
                "material.poissonRatio",
                nu,
                "must lie in (-1, 0.5) for a stable isotropic material",
            ));
        }
        let rho = self.density;
        if !rho.is_finite() || rho <= 0.0 {
            return Err(Error::invalid_value(
                "material.density",
                rho,
                "must be positive and finite",
            ));
        }
        Ok(())
    }

    /// Lamé's first parameter `λ = E ν / ((1 + ν)(1 − 2ν))` (Pa).
    pub fn lame_lambda(&self) -> f64 {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    }

    /// The shear modulus `μ = G = E / (2 (1 + ν))` (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// The 6×6 elasticity matrix `D` in Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear
    /// strains, so that `σ = D ε` (Pa): `D = λ 1 1ᵀ + 2μ` on the normal block, `μ` on the shear
    /// diagonal.
    pub fn elasticity_matrix(&self) -> [[f64; 6]; 6] {
        let lambda = self.lame_lambda();
        let mu = self.shear_modulus();
        let mut d = [[0.0; 6]; 6];
        for (i, row) in d.iter_mut().enumerate().take(3) {
            for (j, entry) in row.iter_mut().enumerate().take(3) {
                *entry = lambda + if i == j { 2.0 * mu } else { 0.0 };
            }
        }
        for (i, row) in d.iter_mut().enumerate().skip(3) {
            row[i] = mu;
        }
        d
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices
mod tests {
    use super::*;

    #[test]
    fn valid_material_passes() {
        assert!(IsotropicMaterial::STEEL.validate().is_ok());
    }

    #[test]
    fn rejections_name_parameter_value_and_reason() {
        let mut m = IsotropicMaterial::STEEL;
        m.youngs_modulus = -1.0;
        let msg = m.validate().unwrap_err().message;
        assert!(
            msg.starts_with("material.youngsModulus = -1 rejected: must be positive"),
            "{msg}"
        );
        for nu in [0.5, -1.0, f64::NAN, 0.7] {
            let mut m = IsotropicMaterial::STEEL;
            m.poisson_ratio = nu;
            let msg = m.validate().unwrap_err().message;
            assert!(
                msg.starts_with(&format!("material.poissonRatio = {nu} rejected")),
                "{msg}"
            );
        }
        for rho in [0.0, f64::INFINITY] {
            let mut m = IsotropicMaterial::STEEL;
            m.density = rho;
            let msg = m.validate().unwrap_err().message;
            assert!(msg.starts_with("material.density = "), "{msg}");
        }
    }

    #[test]
    fn uniaxial_stress_gives_youngs_modulus_and_poisson_contraction() {
        // Invert D for ε under σ = (σ_xx, 0, ...): ε_xx = σ/E, ε_yy = ε_zz = −ν σ/E; shear: G.
        let m = IsotropicMaterial::STEEL;
        let d = m.elasticity_matrix();
        let e = m.youngs_modulus;
        let nu = m.poisson_ratio;
        let strain = [1.0 / e, -nu / e, -nu / e, 0.0, 0.0, 0.0];
        let mut stress = [0.0; 6];
        for i in 0..6 {
            for j in 0..6 {
                stress[i] += d[i][j] * strain[j];
            }
        }
        assert!((stress[0] - 1.0).abs() < 1e-12);
        assert!(stress[1].abs() < 1e-12 && stress[2].abs() < 1e-12);
        assert!((d[3][3] - e / (2.0 * (1.0 + nu))).abs() < 1e-3);
        for i in 0..6 {
            for j in 0..6 {
                assert_eq!(d[i][j], d[j][i]);
            }
        }
    }
}
