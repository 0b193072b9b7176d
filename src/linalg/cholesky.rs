//! Sparse Cholesky `A = L Lᵀ` (faer, supernodal, AMD ordering): the symbolic analysis once per
//! pattern, the numeric factorization once per step size, and solves that take their workspace so
//! that a time step does not allocate.
//!
//! A dense matrix of moderate size (a reduced body's) also keeps its
//! explicit inverse `A⁻¹ = L⁻ᵀ L⁻¹`, computed from the factor: a solve is then one SIMD
//! matrix–vector product instead of two triangular solves, whose dependency chain dominates at
//! this size (n = 168: 4.3 µs against 11.4 µs). The iterations that use the solve converge to
//! the same solution either way (they only apply `A⁻¹` to a residual).

use crate::error::{Error, Result};
use crate::linalg::dense::DenseSymmetric;
use crate::linalg::SymmetricCsr;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltParams;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, Par, Side, Spec};

/// A dense matrix up to this dimension keeps its explicit inverse for the solves (its `n²`
/// doubles: 8 MB at this size; a reduced body has `3s` ≲ 300).
pub const DENSE_INVERSE_LIMIT: usize = 1000;

/// The factor of a symmetric positive definite matrix.
pub struct SparseCholesky {
    n: usize,
    /// Compressed-column pattern of the lower triangle of the factored matrix (row `i ≥ j` in
    /// column `j`); for a symmetric CSR matrix it is the upper part of each CSR row.
    lower_col_ptr: Vec<usize>,
    lower_row_idx: Vec<usize>,
    /// The values of that lower triangle (scratch reused by [`Self::refactor`]).
    lower_values: Vec<f64>,
    symbolic: SymbolicCholesky<usize>,
    /// Numeric values of `L`, `symbolic.len_val()` of them.
    factor_values: Vec<f64>,
    /// Workspace of the numeric factorization.
    factor_workspace: MemBuffer,
    /// `A⁻¹` when `A` is dense and at most [`DENSE_INVERSE_LIMIT`] in dimension.
    inverse: Option<DenseSymmetric>,
    /// The unit-vector solves behind `inverse` and their workspace (kept for refactorizations).
    inverse_workspace: Option<(Mat<f64>, MemBuffer)>,
}

/// Workspace for [`SparseCholesky::solve_in_place`], sized by [`SparseCholesky::solve_scratch`].
pub struct SolveWorkspace {
    buffer: MemBuffer,
    /// The right-hand side while `A⁻¹` multiplies it (length `n` with an explicit inverse).
    rhs: Vec<f64>,
}

impl SparseCholesky {
    /// Symbolic analysis of the pattern of `matrix` (its lower triangle is used) and the numeric
    /// factorization of its values. Error if the matrix is not positive definite, i.e. if a pivot
    /// is not positive. A singular matrix (e.g. the stiffness of an unsupported body) usually
    /// produces such a pivot, but round-off may leave a tiny positive one instead: supports are to
    /// be checked where they are defined, not inferred from this factorization.
    pub fn new(matrix: &SymmetricCsr) -> Result<SparseCholesky> {
        let n = matrix.n;
        let mut lower_col_ptr = Vec::with_capacity(n + 1);
        lower_col_ptr.push(0);
        let mut lower_row_idx = Vec::new();
        for i in 0..n {
            let (cols, _) = matrix.row(i);
            lower_row_idx.extend(cols.iter().copied().filter(|&c| c >= i));
            lower_col_ptr.push(lower_row_idx.len());
        }
        let pattern =
            SymbolicSparseColMatRef::new_checked(n, n, &lower_col_ptr, None, &lower_row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                // faer's default picks the simplicial factor where the supernodal one saves
                // few flops in the factorization, as on a slender beam's banded matrix. The
                // steps do not factorize: they solve, and the supernodal solve works on dense
                // column blocks. B3 on the mesh (40 hex20, 1 440 free unknowns): 0.93 of the time
                // over 20 s, 0.88 in the spin-up (paired runs; the connecting rod, which faer
                // already took supernodal, 0.98; the cantilever B1 the same).
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(|e| Error::new(format!("sparse Cholesky: symbolic analysis failed: {e:?}")))?;
        let factor_workspace = MemBuffer::new(
            symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::<LltParams, f64>::default()),
        );
        let mut this = SparseCholesky {
            n,
            lower_values: vec![0.0; lower_row_idx.len()],
            factor_values: vec![0.0; symbolic.len_val()],
            lower_col_ptr,
            lower_row_idx,
            symbolic,
            factor_workspace,
            inverse: None,
            inverse_workspace: None,
        };
        this.refactor(matrix)?;
        Ok(this)
    }

    /// Numeric factorization of new values on the same pattern (the symbolic analysis is reused).
    /// Error if the pattern differs from the one analysed or the matrix is not positive definite
    /// (the factor is then unusable until a successful `refactor`).
    pub fn refactor(&mut self, matrix: &SymmetricCsr) -> Result<()> {
        if matrix.n != self.n {
            return Err(Error::new(format!(
                "sparse Cholesky: matrix dimension {} differs from the analysed {}",
                matrix.n, self.n
            )));
        }
        let mut k = 0;
        for i in 0..self.n {
            let (cols, vals) = matrix.row(i);
            let expected = &self.lower_row_idx[self.lower_col_ptr[i]..self.lower_col_ptr[i + 1]];
            let mut m = 0;
            for (&c, &v) in cols.iter().zip(vals) {
                if c < i {
                    continue;
                }
                if expected.get(m) != Some(&c) {
                    return Err(Error::new(format!(
                        "sparse Cholesky: the sparsity pattern of row {i} differs from the analysed one"
                    )));
                }
                if !v.is_finite() {
                    return Err(Error::new(format!(
                        "sparse Cholesky: entry ({i}, {c}) = {v} is not finite"
                    )));
                }
                self.lower_values[k] = v;
                k += 1;
                m += 1;
            }
            if m != expected.len() {
                return Err(Error::new(format!(
                    "sparse Cholesky: the sparsity pattern of row {i} differs from the analysed one"
                )));
            }
        }
        let pattern = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.lower_col_ptr,
            None,
            &self.lower_row_idx,
        );
        let a = SparseColMatRef::new(pattern, &self.lower_values);
        // A failed factorization must not leave the previous matrix's inverse answering solves.
        let had_inverse = self.inverse.take();
        let result = self.symbolic.factorize_numeric_llt::<f64>(
            &mut self.factor_values,
            a,
            Side::Lower,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.factor_workspace),
            Spec::<LltParams, f64>::default(),
        );
        let dense = self.lower_values.len() == self.n * (self.n + 1) / 2;
        match result {
            Ok(_) => {
                self.inverse = had_inverse;
                if dense && self.n <= DENSE_INVERSE_LIMIT {
                    self.update_inverse();
                }
                Ok(())
            }
            Err(e) => Err(Error::new(format!(
                "sparse Cholesky: the matrix ({n}×{n}) is not positive definite ({e:?}, index in the AMD-permuted order)",
                n = self.n
            ))),
        }
    }

    /// `A⁻¹` from the factor: the solves of the `n` unit vectors, symmetrised (as `A⁻¹` is).
    /// Allocates at the first factorization only; a refactorization (Newton's, every
    /// iteration) reuses the storage.
    fn update_inverse(&mut self) {
        let n = self.n;
        let symbolic = &self.symbolic;
        let (solves, buffer) = self.inverse_workspace.get_or_insert_with(|| {
            (
                Mat::<f64>::zeros(n, n),
                MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(n, Par::Seq)),
            )
        });
        solves.fill(0.0);
        solves.diagonal_mut().fill(1.0);
        LltRef::<'_, usize, f64>::new(symbolic, &self.factor_values).solve_in_place_with_conj(
            Conj::No,
            solves.as_mut(),
            Par::Seq,
            MemStack::new(buffer),
        );
        self.inverse
            .get_or_insert_with(|| DenseSymmetric::new(Mat::zeros(n, n)))
            .assign_symmetrised(solves.as_ref());
    }

    /// Workspace for [`Self::solve_in_place`] (allocate once, reuse for every solve).
    pub fn solve_scratch(&self) -> SolveWorkspace {
        SolveWorkspace {
            buffer: MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
            rhs: vec![0.0; if self.inverse.is_some() { self.n } else { 0 }],
        }
    }

    /// `rhs ← A⁻¹ rhs`: one forward and one backward triangular solve (or the product with the
    /// explicit inverse of a dense matrix), no allocation.
    /// Panics if `rhs.len() != self.dim()` or the workspace belongs to another factor size.
    pub fn solve_in_place(&self, rhs: &mut [f64], workspace: &mut SolveWorkspace) {
        assert_eq!(
            rhs.len(),
            self.n,
            "SparseCholesky::solve_in_place: wrong rhs length"
        );
        if let Some(inverse) = &self.inverse {
            workspace.rhs.copy_from_slice(rhs);
            inverse.mul_vec(&workspace.rhs, rhs);
            return;
        }
        let llt = LltRef::<'_, usize, f64>::new(&self.symbolic, &self.factor_values);
        let rhs = MatMut::from_column_major_slice_mut(rhs, self.n, 1);
        llt.solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut workspace.buffer),
        );
    }

    /// Dimension of the factored matrix.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Stored nonzeros of the factor `L`.
    pub fn factor_nnz(&self) -> usize {
        self.factor_values.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::linalg::sparse::laplacian;

    #[test]
    fn solves_a_known_system() {
        // A x = b with x_i = sin(i) + 1; residual relative to ‖b‖ at round-off level: the
        // condition number of the 200-point Laplacian is ≈ 1.6e4, so the error ≲ 1e4 · 1e-16.
        let n = 200;
        let a = laplacian(n);
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 1.0).collect();
        let mut b = vec![0.0; n];
        a.mul_vec(&x, &mut b);
        let llt = SparseCholesky::new(&a).unwrap();
        assert_eq!(llt.dim(), n);
        assert!(llt.factor_nnz() >= 2 * n - 1);
        let mut ws = llt.solve_scratch();
        let mut sol = b.clone();
        llt.solve_in_place(&mut sol, &mut ws);
        let err = x
            .iter()
            .zip(&sol)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-10, "max error {err}");
    }

    #[test]
    fn a_dense_matrix_solves_with_its_inverse() {
        // A = B + n I with B_ij = 1/(1 + |i − j|): dense, SPD, condition number < 10, so
        // A⁻¹ b has round-off error ≲ 1e-15 relative; refactor updates the inverse.
        let n = 40;
        let entry = |i: usize, j: usize| {
            1.0 / (1.0 + (i as f64 - j as f64).abs()) + if i == j { n as f64 } else { 0.0 }
        };
        let t: Vec<_> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j, entry(i, j))))
            .collect();
        let a = SymmetricCsr::from_triplets(n, &t);
        let mut llt = SparseCholesky::new(&a).unwrap();
        assert!(llt.inverse.is_some(), "a dense matrix keeps its inverse");
        let x: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        for scale in [1.0, 3.0] {
            let mut scaled = a.clone();
            scaled.values.iter_mut().for_each(|v| *v *= scale);
            llt.refactor(&scaled).unwrap();
            let mut b = vec![0.0; n];
            scaled.mul_vec(&x, &mut b);
            let mut ws = llt.solve_scratch();
            llt.solve_in_place(&mut b, &mut ws);
            let err = x
                .iter()
                .zip(&b)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-13, "scale {scale}: max error {err}");
        }
        assert!(SparseCholesky::new(&laplacian(n))
            .unwrap()
            .inverse
            .is_none());
    }

    #[test]
    fn refactor_reuses_the_pattern() {
        let n = 50;
        let a = laplacian(n);
        let mut llt = SparseCholesky::new(&a).unwrap();
        // 2A: the solution halves.
        let mut a2 = a.clone();
        a2.values.iter_mut().for_each(|v| *v *= 2.0);
        llt.refactor(&a2).unwrap();
        let x = vec![1.0; n];
        let mut b = vec![0.0; n];
        a2.mul_vec(&x, &mut b);
        let mut ws = llt.solve_scratch();
        llt.solve_in_place(&mut b, &mut ws);
        assert!(b.iter().all(|v| (v - 1.0).abs() < 1e-12));
        // A different pattern is rejected.
        let e = llt.refactor(&SymmetricCsr::from_triplets(
            n,
            &(0..n).map(|i| (i, i, 1.0)).collect::<Vec<_>>(),
        ));
        assert!(e.unwrap_err().message.contains("pattern"));
    }

    #[test]
    fn reports_a_non_positive_definite_matrix() {
        // tridiag(−1, 2, −1) − 3 I has negative eigenvalues; a zero matrix is singular.
        let mut a = laplacian(10);
        for i in 0..10 {
            let (cols, _) = a.row(i);
            let k = a.row_ptr[i] + cols.binary_search(&i).unwrap();
            a.values[k] -= 3.0;
        }
        let e = SparseCholesky::new(&a)
            .err()
            .expect("indefinite matrix must be rejected");
        assert!(e.message.contains("not positive definite"), "{}", e.message);
        let singular =
            SymmetricCsr::from_triplets(2, &[(0, 0, 1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0)]);
        assert!(SparseCholesky::new(&singular).is_err());
    }
}
