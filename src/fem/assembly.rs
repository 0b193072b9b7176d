//! Assembly of the constant FE matrices of a mesh.

use super::{IsotropicMaterial, SymmetricCsr};
use crate::mesh::Mesh;

/// The consistent scalar mass matrix `Ms[i,j] = ∫ ρ N_i N_j dV` (kg), `N × N` for `N` nodes.
/// The mass matrix of the body is `M = Ms ⊗ I3`.
pub fn scalar_mass_matrix(mesh: &Mesh, density: f64) -> SymmetricCsr {
    let _ = (mesh, density);
    todo!()
}

/// The small-strain stiffness `K = ∫ Bᵀ D B dV` (N/m), `3N × 3N`, DOF `3 * node + direction`.
pub fn stiffness_matrix(mesh: &Mesh, material: &IsotropicMaterial) -> SymmetricCsr {
    let _ = (mesh, material);
    todo!()
}

/// HRZ-lumped (diagonal-scaled) nodal masses (kg): `m_i = Ms[i,i] · m_e / Σ_j Ms_e[j,j]` summed
/// over elements; all positive, summing to the total mass `ρV`.
pub fn lumped_masses(mesh: &Mesh, density: f64) -> Vec<f64> {
    let _ = (mesh, density);
    todo!()
}
