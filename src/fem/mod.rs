//! Finite elements: quadrature, shape functions, the isotropic material, sparse assembly of the
//! scalar mass matrix `Ms` (`M = Ms ⊗ I3`), the small-strain stiffness `K` and lumped masses.
//! DOF numbering everywhere: `3 * node + direction`.

pub mod assembly;
pub mod geometric;
pub mod material;
pub mod modal;
pub mod nonlinear;
pub mod stress;

pub use assembly::{
    lumped_masses, lumped_masses_of, scalar_mass_matrix, scalar_mass_matrix_of, stiffness_matrix,
    stiffness_matrix_of,
};
pub use material::IsotropicMaterial;
