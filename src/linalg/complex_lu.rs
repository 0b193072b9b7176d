//! Sparse LU with partial pivoting over `c64` (faer, COLAMD column ordering) for the complex
//! stage system of Radau IIA, `(c_m M + c_k K) w = r` with complex coefficients: the matrix is
//! complex symmetric (not Hermitian) and, for the low modes, its real part is indefinite, so
//! neither a Cholesky nor a pivot-free `LDLᵀ` applies. The factorization is done once per step
//! size; solves take their workspace and do not allocate.

use crate::error::{Error, Result};
use crate::linalg::SymmetricCsr;
use faer::c64;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Spec};

/// The LU factor of `a·A + b·B` for two real symmetric sparse matrices `A`, `B` of one dimension
/// and complex `a`, `b`.
pub struct ComplexLu {
    n: usize,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, c64>,
    solve_buffer: MemBuffer,
}

impl ComplexLu {
    /// Factorises `a·lhs + b·rhs` (the union of both patterns; the matrices are symmetric, so
    /// their CSR arrays are the compressed-column arrays too). Error if the matrix is singular
    /// to working precision or holds a non-finite entry.
    pub fn new(a: c64, lhs: &SymmetricCsr, b: c64, rhs: &SymmetricCsr) -> Result<ComplexLu> {
        let pattern_a = SymmetricCsr::linear_combination(1.0, lhs, 0.0, rhs);
        let pattern_b = SymmetricCsr::linear_combination(0.0, lhs, 1.0, rhs);
        let n = pattern_a.n;
        let values: Vec<c64> = pattern_a
            .values
            .iter()
            .zip(&pattern_b.values)
            .map(|(&p, &q)| a * p + b * q)
            .collect();
        if let Some(k) = values
            .iter()
            .position(|v| !(v.re.is_finite() && v.im.is_finite()))
        {
            return Err(Error::new(format!(
                "complex sparse LU: entry {k} of the matrix is not finite"
            )));
        }
        let structure = SymbolicSparseColMatRef::new_checked(
            n,
            n,
            &pattern_a.row_ptr,
            None,
            &pattern_a.col_idx,
        );
        let symbolic =
            factorize_symbolic_lu(structure, LuSymbolicParams::default()).map_err(|e| {
                Error::new(format!(
                    "complex sparse LU: symbolic analysis failed: {e:?}"
                ))
            })?;
        let mut factor_buffer = MemBuffer::new(symbolic.factorize_numeric_lu_scratch::<c64>(
            Par::Seq,
            Spec::<PartialPivLuParams, c64>::default(),
        ));
        let mut numeric = NumericLu::new();
        symbolic
            .factorize_numeric_lu(
                &mut numeric,
                SparseColMatRef::new(structure, &values),
                Par::Seq,
                MemStack::new(&mut factor_buffer),
                Spec::<PartialPivLuParams, c64>::default(),
            )
            .map_err(|e| {
                Error::new(format!(
                    "complex sparse LU: the matrix ({n}×{n}) is singular ({e:?})"
                ))
            })?;
        let solve_buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<c64>(1, Par::Seq));
        Ok(ComplexLu {
            n,
            symbolic,
            numeric,
            solve_buffer,
        })
    }

    /// `rhs ← (a·A + b·B)⁻¹ rhs`, no allocation. Panics if `rhs.len() != self.dim()`.
    pub fn solve_in_place(&mut self, rhs: &mut [c64]) {
        assert_eq!(
            rhs.len(),
            self.n,
            "ComplexLu::solve_in_place: wrong rhs length"
        );
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            MemStack::new(&mut self.solve_buffer),
        );
    }

    /// Dimension of the factored matrix.
    pub fn dim(&self) -> usize {
        self.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_an_indefinite_complex_symmetric_system() {
        // A = tridiag(−1, 2, −1), B = I: (−1 + 2i) I + A has an indefinite real part for the
        // low modes (eigenvalues of A lie in (0, 4)). Residual at round-off.
        let n = 60;
        let a = crate::linalg::sparse::laplacian(n);
        let b = SymmetricCsr::from_triplets(n, &(0..n).map(|i| (i, i, 1.0)).collect::<Vec<_>>());
        let (ca, cb) = (c64::new(1.0, 0.0), c64::new(-1.0, 2.0));
        let mut lu = ComplexLu::new(ca, &a, cb, &b).unwrap();
        assert_eq!(lu.dim(), n);
        let x: Vec<c64> = (0..n)
            .map(|i| c64::new((i as f64).sin(), (i as f64 * 0.3).cos()))
            .collect();
        // b = (A + (−1+2i) I) x
        let mut rhs = vec![c64::new(0.0, 0.0); n];
        for i in 0..n {
            let (cols, vals) = a.row(i);
            for (&j, &v) in cols.iter().zip(vals) {
                rhs[i] += ca * v * x[j];
            }
            rhs[i] += cb * x[i];
        }
        lu.solve_in_place(&mut rhs);
        let err = rhs
            .iter()
            .zip(&x)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "max error {err}");
    }
}
