//! Linear algebra, the ground floor: the symmetric sparse matrix of assembly ([`SymmetricCsr`]),
//! dense symmetric matrices and their faer products ([`dense`]), the sparse Cholesky factor of
//! a symmetric positive definite matrix ([`SparseCholesky`], with an explicit inverse for dense
//! matrices of moderate size) and the complex sparse LU of Radau IIA's complex stage matrix
//! ([`complex_lu`]). Knows nothing of meshes, bodies or schemes.

pub mod cholesky;
pub mod complex_lu;
pub mod dense;
pub mod sparse;

pub use cholesky::SparseCholesky;
pub use sparse::SymmetricCsr;

/// The Euclidean inner product `aᵀ b` of two vectors of equal length.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
