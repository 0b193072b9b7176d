//! Sparse Cholesky `A = L Lᵀ` (faer, supernodal, AMD ordering): the symbolic analysis once per
//! pattern, the numeric factorization once per step size, and solves that take their workspace so
//! that a time step does not allocate.

use crate::error::Result;
use crate::fem::SymmetricCsr;

/// The factor of a symmetric positive definite matrix.
pub struct SparseCholesky {
    // faer symbolic factor, numeric values
}

/// Workspace for [`SparseCholesky::solve_in_place`], sized by [`SparseCholesky::solve_scratch`].
pub struct SolveWorkspace {
    // faer MemBuffer
}

impl SparseCholesky {
    /// Symbolic analysis of the pattern of `matrix` (its lower triangle is used) and the numeric
    /// factorization of its values. Error if the matrix is not positive definite.
    pub fn new(matrix: &SymmetricCsr) -> Result<SparseCholesky> {
        let _ = matrix;
        todo!()
    }

    /// Numeric factorization of new values on the same pattern (the symbolic analysis is reused).
    pub fn refactor(&mut self, matrix: &SymmetricCsr) -> Result<()> {
        let _ = matrix;
        todo!()
    }

    /// Workspace for [`Self::solve_in_place`] (allocate once, reuse for every solve).
    pub fn solve_scratch(&self) -> SolveWorkspace {
        todo!()
    }

    /// `rhs ← A⁻¹ rhs`: one forward and one backward triangular solve, no allocation.
    pub fn solve_in_place(&self, rhs: &mut [f64], workspace: &mut SolveWorkspace) {
        let _ = (rhs, workspace);
        todo!()
    }

    /// Dimension of the factored matrix.
    pub fn dim(&self) -> usize {
        todo!()
    }

    /// Stored nonzeros of the factor `L`.
    pub fn factor_nnz(&self) -> usize {
        todo!()
    }
}
