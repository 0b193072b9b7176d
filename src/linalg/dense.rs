//! Dense symmetric matrices for the hot-path products of a reduced body (`model.modes`), whose
//! projected mass `Sᵀ Ms S` and stiffness `K_r` are full: a column-major faer matrix and its
//! SIMD matrix–vector product replace the compressed storage of the mesh matrices, whose index
//! per entry costs more than the product when every entry is stored (at `3s = 168`: 4.3 µs
//! against 8.3 µs of [`super::sparse::BlockCsr3::mul_vec`], 1.5 µs against 5.2 µs for `Ms ⊗ I3`).

use super::SymmetricCsr;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// A dense symmetric `n × n` matrix.
#[derive(Debug, Clone)]
pub struct DenseSymmetric {
    matrix: Mat<f64>,
}

impl DenseSymmetric {
    /// The dense form of `a` (entries it does not store are zero).
    pub fn from_csr(a: &SymmetricCsr) -> DenseSymmetric {
        let mut matrix = Mat::<f64>::zeros(a.n, a.n);
        for i in 0..a.n {
            let (cols, values) = a.row(i);
            for (&j, &v) in cols.iter().zip(values) {
                matrix[(i, j)] = v;
            }
        }
        DenseSymmetric { matrix }
    }

    /// The dense matrix `m` (square, symmetric by the caller's construction).
    pub fn new(matrix: Mat<f64>) -> DenseSymmetric {
        assert_eq!(matrix.nrows(), matrix.ncols(), "DenseSymmetric: not square");
        DenseSymmetric { matrix }
    }

    /// The matrix, to overwrite in place (the caller keeps it symmetric).
    pub fn as_mut(&mut self) -> MatMut<'_, f64> {
        self.matrix.as_mut()
    }

    /// Dimension `n`.
    pub fn dim(&self) -> usize {
        self.matrix.nrows()
    }

    /// `y = A x` (length `n`). No allocation. `A` is symmetric, so its column-major storage
    /// is `Aᵀ` row-major: faer multiplies that with its dot-product kernel (each row against
    /// `x`, the sums in registers) instead of the column kernel, which reads and writes all of
    /// `y` once per column. B1's reduced linear step (`3s` = 129 and 138) takes 0.89 of the
    /// time it took (median of 6 interleaved runs, bench/results/2026-11-27-paired-2.md).
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        let n = self.dim();
        matmul(
            MatMut::from_column_major_slice_mut(y, n, 1),
            Accum::Replace,
            self.matrix.as_ref().transpose(),
            MatRef::from_column_major_slice(x, n, 1),
            1.0,
            Par::Seq,
        );
    }

    /// `y = A[:, columns] x` (`x` of the columns' length, `y` of `n`): one SIMD product with
    /// the contiguous block of columns. No allocation.
    pub fn mul_columns(&self, columns: std::ops::Range<usize>, x: &[f64], y: &mut [f64]) {
        let n = self.dim();
        let block = self.matrix.as_ref().subcols(columns.start, columns.len());
        matmul(
            MatMut::from_column_major_slice_mut(y, n, 1),
            Accum::Replace,
            block,
            MatRef::from_column_major_slice(x, columns.len(), 1),
            1.0,
            Par::Seq,
        );
    }

    /// `y = (A ⊗ I3) x` for flat vectors of `n` nodes (length `3n`): `y_i = Σ_j A_ij x_j` for
    /// the 3-vectors `x_j`, one product of `A` with the `n × 3` matrix of the nodes. No
    /// allocation.
    pub fn mul_nodes(&self, x: &[f64], y: &mut [f64]) {
        mul_nodes(self.matrix.as_ref(), x, y);
    }
}

/// `y = (A ⊗ I3) x` for a dense `n × n` matrix `A` and flat vectors of `n` nodes: one SIMD
/// product of `A` with the `n × 3` (row-major) matrix of the nodes. No allocation.
pub(crate) fn mul_nodes(a: MatRef<'_, f64>, x: &[f64], y: &mut [f64]) {
    let n = a.nrows();
    matmul(
        MatMut::from_row_major_slice_mut(y, n, 3),
        Accum::Replace,
        a,
        MatRef::from_row_major_slice(x, n, 3),
        1.0,
        Par::Seq,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize) -> SymmetricCsr {
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if (i + j) % 3 != 1 {
                    t.push((i, j, 1.0 / (1.0 + i as f64 + j as f64)));
                }
            }
        }
        SymmetricCsr::from_triplets(n, &t)
    }

    #[test]
    fn products_match_the_compressed_ones() {
        // Same sums in another order: equal to round-off (entries ≤ 1, n terms).
        let a = sample(12);
        let dense = DenseSymmetric::from_csr(&a);
        let x: Vec<f64> = (0..12).map(|i| (i as f64).sin()).collect();
        let (mut y, mut z) = (vec![0.0; 12], vec![0.0; 12]);
        a.mul_vec(&x, &mut y);
        dense.mul_vec(&x, &mut z);
        for (p, q) in y.iter().zip(&z) {
            assert!((p - q).abs() < 1e-14, "{p} {q}");
        }
        // A block of columns against the full product of a vector zero outside them.
        let mut x_block = vec![0.0; 12];
        x_block[3..7].copy_from_slice(&x[3..7]);
        a.mul_vec(&x_block, &mut y);
        dense.mul_columns(3..7, &x[3..7], &mut z);
        for (p, q) in y.iter().zip(&z) {
            assert!((p - q).abs() < 1e-14, "{p} {q}");
        }
        // (A ⊗ I3) x against the Kronecker product in compressed form.
        let x3: Vec<f64> = (0..36).map(|i| (0.3 * i as f64).cos()).collect();
        let (mut y3, mut z3) = (vec![0.0; 36], vec![0.0; 36]);
        a.kron_i3().mul_vec(&x3, &mut y3);
        dense.mul_nodes(&x3, &mut z3);
        for (p, q) in y3.iter().zip(&z3) {
            assert!((p - q).abs() < 1e-14, "{p} {q}");
        }
    }
}
