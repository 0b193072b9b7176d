//! Time integration: the constant iteration matrix and its sparse Cholesky factor, generalized-α.

pub mod anderson;
pub mod central_difference;
pub mod cholesky;
pub mod consistent_acceleration;
pub mod constraints;
pub mod generalized_alpha;
pub mod woodbury;

pub use cholesky::SparseCholesky;
