//! Isotropic linear elasticity.

use crate::error::Result;

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
    /// Checks the ranges; the error names the parameter (`material.youngsModulus`, ...), the value
    /// and the reason.
    pub fn validate(&self) -> Result<()> {
        todo!()
    }

    /// The 6×6 elasticity matrix `D` in Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear
    /// strains, so that `σ = D ε` (Pa).
    pub fn elasticity_matrix(&self) -> [[f64; 6]; 6] {
        todo!()
    }
}
