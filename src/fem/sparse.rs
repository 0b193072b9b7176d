//! Symmetric sparse matrices in compressed-row storage (both triangles stored), the storage of
//! `Ms` and `K`, with an allocation-free product.

/// A symmetric `n × n` sparse matrix, both triangles stored, rows sorted by column.
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetricCsr {
    pub n: usize,
    pub row_ptr: Vec<usize>,
    pub col_idx: Vec<usize>,
    pub values: Vec<f64>,
}

impl SymmetricCsr {
    /// From (row, col, value) triplets of the full matrix (both triangles); duplicates are summed.
    pub fn from_triplets(n: usize, triplets: &[(usize, usize, f64)]) -> SymmetricCsr {
        let _ = (n, triplets);
        todo!()
    }

    /// `y = A x`. No allocation.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        let _ = (x, y);
        todo!()
    }

    /// Rows/cols `keep`, in that order.
    pub fn submatrix(&self, keep: &[usize]) -> SymmetricCsr {
        let _ = keep;
        todo!()
    }

    /// `A ⊗ I3`.
    pub fn kron_i3(&self) -> SymmetricCsr {
        todo!()
    }

    /// `a A + b B` on the union pattern.
    pub fn linear_combination(a: f64, m: &SymmetricCsr, b: f64, k: &SymmetricCsr) -> SymmetricCsr {
        let _ = (a, m, b, k);
        todo!()
    }

    /// Number of stored entries (both triangles).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }
}
