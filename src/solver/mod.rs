//! Time integration: the constant iteration matrix and its sparse Cholesky factor,
//! generalized-α, Radau IIA and central difference.

pub mod anderson;
pub mod central_difference;
pub mod consistent_acceleration;
pub mod constraints;
pub mod generalized_alpha;
pub mod radau;
pub mod woodbury;
