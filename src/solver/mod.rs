//! Time integration: the constant iteration matrix and its sparse Cholesky factor, generalized-α.

pub mod anderson;
pub mod cholesky;
pub mod constraints;
pub mod generalized_alpha;
pub mod woodbury;

pub use cholesky::SparseCholesky;
