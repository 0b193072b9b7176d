//! Symmetric sparse matrices in compressed-row storage (both triangles stored), the storage of
//! `Ms` and `K`, with an allocation-free product.

use faer::MatRef;
use nalgebra::DMatrix;

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
    /// Panics if an index is out of range.
    pub fn from_triplets(n: usize, triplets: &[(usize, usize, f64)]) -> SymmetricCsr {
        let mut sorted: Vec<(usize, usize, f64)> = triplets.to_vec();
        for &(r, c, _) in &sorted {
            assert!(
                r < n && c < n,
                "SymmetricCsr::from_triplets: ({r}, {c}) outside {n}×{n}"
            );
        }
        sorted.sort_unstable_by_key(|&(r, c, _)| (r, c));
        let mut row_ptr = vec![0usize; n + 1];
        let mut col_idx = Vec::with_capacity(sorted.len());
        let mut values: Vec<f64> = Vec::with_capacity(sorted.len());
        let mut last: Option<(usize, usize)> = None;
        for (r, c, v) in sorted {
            if last == Some((r, c)) {
                *values.last_mut().expect("a previous entry exists") += v;
            } else {
                col_idx.push(c);
                values.push(v);
                row_ptr[r + 1] += 1;
                last = Some((r, c));
            }
        }
        for i in 0..n {
            row_ptr[i + 1] += row_ptr[i];
        }
        SymmetricCsr {
            n,
            row_ptr,
            col_idx,
            values,
        }
    }

    /// The matrix with `diagonal.len()` more rows and columns, each holding only its diagonal
    /// entry `diagonal[k]` (a zero keeps the row empty): the extra nodes of a body without
    /// stiffness and with a point mass.
    pub fn extended(&self, diagonal: &[f64]) -> SymmetricCsr {
        let mut extended = self.clone();
        for (k, &d) in diagonal.iter().enumerate() {
            if d != 0.0 {
                extended.col_idx.push(self.n + k);
                extended.values.push(d);
            }
            extended.row_ptr.push(extended.col_idx.len());
        }
        extended.n += diagonal.len();
        extended
    }

    /// `y = A x`. No allocation. Panics if the lengths are not `n`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(
            x.len(),
            self.n,
            "SymmetricCsr::mul_vec: x has the wrong length"
        );
        assert_eq!(
            y.len(),
            self.n,
            "SymmetricCsr::mul_vec: y has the wrong length"
        );
        for (i, yi) in y.iter_mut().enumerate() {
            let range = self.row_ptr[i]..self.row_ptr[i + 1];
            *yi = if range.len() == self.n {
                // A full row (a reduced body's dense matrices): no indices to follow.
                dense_dot(&self.values[range], x)
            } else {
                self.col_idx[range.clone()]
                    .iter()
                    .zip(&self.values[range])
                    .map(|(&j, &a)| a * x[j])
                    .sum()
            };
        }
    }

    /// `y = (A ⊗ I3) x` for flat vectors of `n` nodes (length `3n`): `y_i = Σ_j A_ij x_j` for
    /// the 3-vectors `x_j`. A matrix with every entry stored (a reduced body's scalar `G_r` of
    /// `K_G = G_r ⊗ I3`) is taken as the row-major `n × n` matrix it is, in one SIMD product with
    /// the `n × 3` matrix of the nodes; a sparse one row by row. No allocation.
    ///
    /// Panics if `x` or `y` is not `3n` long.
    pub fn mul_nodes(&self, x: &[f64], y: &mut [f64]) {
        let n = self.n;
        assert_eq!(
            x.len(),
            3 * n,
            "SymmetricCsr::mul_nodes: x has the wrong length"
        );
        assert_eq!(
            y.len(),
            3 * n,
            "SymmetricCsr::mul_nodes: y has the wrong length"
        );
        if self.values.len() == n * n {
            return super::dense::mul_nodes(MatRef::from_row_major_slice(&self.values, n, n), x, y);
        }
        for (i, yi) in y.chunks_exact_mut(3).enumerate() {
            let (cols, values) = self.row(i);
            let mut sum = [0.0; 3];
            for (&j, &a) in cols.iter().zip(values) {
                for d in 0..3 {
                    sum[d] += a * x[3 * j + d];
                }
            }
            yi.copy_from_slice(&sum);
        }
    }

    /// Number of stored entries (both triangles).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Column indices and values of row `i`.
    pub fn row(&self, i: usize) -> (&[usize], &[f64]) {
        let range = self.row_ptr[i]..self.row_ptr[i + 1];
        (&self.col_idx[range.clone()], &self.values[range])
    }

    /// The diagonal entries (0 where none is stored).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n)
            .map(|i| {
                let (cols, vals) = self.row(i);
                cols.binary_search(&i).map(|k| vals[k]).unwrap_or(0.0)
            })
            .collect()
    }

    /// The principal submatrix `A[keep, keep]`: row/column `k` of the result is row/column
    /// `keep[k]` of `self` (e.g. the free DOFs after removing clamped ones). `keep` must hold
    /// distinct indices `< n`.
    pub fn submatrix(&self, keep: &[usize]) -> SymmetricCsr {
        let mut new_index = vec![usize::MAX; self.n];
        for (k, &old) in keep.iter().enumerate() {
            assert!(
                old < self.n,
                "SymmetricCsr::submatrix: index {old} ≥ {}",
                self.n
            );
            assert_eq!(
                new_index[old],
                usize::MAX,
                "SymmetricCsr::submatrix: {old} repeated"
            );
            new_index[old] = k;
        }
        let mut row_ptr = Vec::with_capacity(keep.len() + 1);
        row_ptr.push(0);
        let mut col_idx = Vec::with_capacity(self.nnz());
        let mut values = Vec::with_capacity(self.nnz());
        let mut row_entries: Vec<(usize, f64)> = Vec::new();
        for &old in keep {
            row_entries.clear();
            let (cols, vals) = self.row(old);
            for (&c, &v) in cols.iter().zip(vals) {
                if new_index[c] != usize::MAX {
                    row_entries.push((new_index[c], v));
                }
            }
            // Already ordered when `keep` is ascending (the usual free-DOF list).
            if !row_entries.is_sorted_by_key(|e| e.0) {
                row_entries.sort_unstable_by_key(|e| e.0);
            }
            for &(c, v) in &row_entries {
                col_idx.push(c);
                values.push(v);
            }
            row_ptr.push(col_idx.len());
        }
        SymmetricCsr {
            n: keep.len(),
            row_ptr,
            col_idx,
            values,
        }
    }

    /// The Kronecker product `A ⊗ I3` (`3n × 3n`): entry `(3i+d, 3j+d) = A[i,j]`, DOF `3*i + d`.
    pub fn kron_i3(&self) -> SymmetricCsr {
        let n3 = 3 * self.n;
        let mut row_ptr = Vec::with_capacity(n3 + 1);
        row_ptr.push(0);
        let mut col_idx = Vec::with_capacity(3 * self.nnz());
        let mut values = Vec::with_capacity(3 * self.nnz());
        for i in 0..self.n {
            let (cols, vals) = self.row(i);
            for d in 0..3 {
                for (&c, &v) in cols.iter().zip(vals) {
                    col_idx.push(3 * c + d);
                    values.push(v);
                }
                row_ptr.push(col_idx.len());
            }
        }
        SymmetricCsr {
            n: n3,
            row_ptr,
            col_idx,
            values,
        }
    }

    /// `a A + b B` on the union of the two patterns (same dimension required), e.g. the iteration
    /// matrix `c_m M + K`.
    pub fn linear_combination(
        a: f64,
        lhs: &SymmetricCsr,
        b: f64,
        rhs: &SymmetricCsr,
    ) -> SymmetricCsr {
        assert_eq!(
            lhs.n, rhs.n,
            "SymmetricCsr::linear_combination: dimensions differ"
        );
        let n = lhs.n;
        let mut row_ptr = Vec::with_capacity(n + 1);
        row_ptr.push(0);
        let mut col_idx = Vec::with_capacity(lhs.nnz().max(rhs.nnz()));
        let mut values = Vec::with_capacity(lhs.nnz().max(rhs.nnz()));
        for i in 0..n {
            let (ca, va) = lhs.row(i);
            let (cb, vb) = rhs.row(i);
            let (mut p, mut q) = (0, 0);
            while p < ca.len() || q < cb.len() {
                let next_a = ca.get(p).copied().unwrap_or(usize::MAX);
                let next_b = cb.get(q).copied().unwrap_or(usize::MAX);
                if next_a < next_b {
                    col_idx.push(next_a);
                    values.push(a * va[p]);
                    p += 1;
                } else if next_b < next_a {
                    col_idx.push(next_b);
                    values.push(b * vb[q]);
                    q += 1;
                } else {
                    col_idx.push(next_a);
                    values.push(a * va[p] + b * vb[q]);
                    p += 1;
                    q += 1;
                }
            }
            row_ptr.push(col_idx.len());
        }
        SymmetricCsr {
            n,
            row_ptr,
            col_idx,
            values,
        }
    }

    /// The dense matrix (for tests and small problems).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.n, self.n);
        for i in 0..self.n {
            let (cols, vals) = self.row(i);
            for (&c, &v) in cols.iter().zip(vals) {
                m[(i, c)] += v;
            }
        }
        m
    }
}

/// A `3N × 3N` matrix stored by 3×3 blocks (block compressed rows, both triangles): the storage
/// of the stiffness `K` for the hot-path product. One column index serves nine values, and each
/// block is a small dense product, which halves the memory traffic of [`SymmetricCsr::mul_vec`].
#[derive(Debug, Clone, PartialEq)]
pub struct BlockCsr3 {
    /// Block rows (nodes).
    pub n: usize,
    pub row_ptr: Vec<usize>,
    pub col_idx: Vec<usize>,
    /// Row-major 3×3 blocks.
    pub blocks: Vec<[f64; 9]>,
}

impl BlockCsr3 {
    /// The block form of `a` (dimension a multiple of 3); entries of a block that `a` does not
    /// store are zero.
    pub fn from_csr(a: &SymmetricCsr) -> BlockCsr3 {
        assert_eq!(
            a.n % 3,
            0,
            "BlockCsr3::from_csr: dimension not a multiple of 3"
        );
        let n = a.n / 3;
        let mut row_ptr = vec![0; n + 1];
        let mut col_idx = Vec::new();
        let mut blocks: Vec<[f64; 9]> = Vec::new();
        for bi in 0..n {
            // Block columns of the three rows, merged in ascending order.
            let start = col_idx.len();
            for r in 0..3 {
                let i = 3 * bi + r;
                for k in a.row_ptr[i]..a.row_ptr[i + 1] {
                    let (bj, c) = (a.col_idx[k] / 3, a.col_idx[k] % 3);
                    let slot = match col_idx[start..].binary_search(&bj) {
                        Ok(p) => start + p,
                        Err(p) => {
                            col_idx.insert(start + p, bj);
                            blocks.insert(start + p, [0.0; 9]);
                            start + p
                        }
                    };
                    blocks[slot][3 * r + c] += a.values[k];
                }
            }
            row_ptr[bi + 1] = col_idx.len();
        }
        BlockCsr3 {
            n,
            row_ptr,
            col_idx,
            blocks,
        }
    }

    /// `y = A x` (length `3N`). No allocation.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(
            x.len(),
            3 * self.n,
            "BlockCsr3::mul_vec: x has the wrong length"
        );
        assert_eq!(
            y.len(),
            3 * self.n,
            "BlockCsr3::mul_vec: y has the wrong length"
        );
        for (bi, yi) in y.chunks_exact_mut(3).enumerate() {
            let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
            let range = self.row_ptr[bi]..self.row_ptr[bi + 1];
            for (&bj, m) in self.col_idx[range.clone()].iter().zip(&self.blocks[range]) {
                let (x0, x1, x2) = (x[3 * bj], x[3 * bj + 1], x[3 * bj + 2]);
                a += m[0] * x0 + m[1] * x1 + m[2] * x2;
                b += m[3] * x0 + m[4] * x1 + m[5] * x2;
                c += m[6] * x0 + m[7] * x1 + m[8] * x2;
            }
            yi[0] = a;
            yi[1] = b;
            yi[2] = c;
        }
    }
}

/// `Σ a_j x_j` in four independent sums (which the compiler vectorizes).
fn dense_dot(a: &[f64], x: &[f64]) -> f64 {
    let mut sums = [0.0; 4];
    let (a4, x4) = (a.chunks_exact(4), x.chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(x4.remainder())
        .map(|(a, x)| a * x)
        .sum();
    for (a, x) in a4.zip(x4) {
        for k in 0..4 {
            sums[k] += a[k] * x[k];
        }
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail
}

/// The 1D Laplacian tridiag(−1, 2, −1) of size `n` (SPD; eigenvalues `4 sin²(iπ / (2(n+1)))`):
/// the known matrix of the solver tests.
#[cfg(test)]
pub(crate) fn laplacian(n: usize) -> SymmetricCsr {
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 2.0));
        if i + 1 < n {
            t.push((i, i + 1, -1.0));
            t.push((i + 1, i, -1.0));
        }
    }
    SymmetricCsr::from_triplets(n, &t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [[4, 1, 0], [1, 3, 2], [0, 2, 5]] from triplets with a split duplicate.
    fn sample() -> SymmetricCsr {
        SymmetricCsr::from_triplets(
            3,
            &[
                (2, 2, 5.0),
                (0, 0, 3.0),
                (0, 1, 1.0),
                (1, 0, 1.0),
                (1, 1, 3.0),
                (0, 0, 1.0),
                (1, 2, 2.0),
                (2, 1, 2.0),
            ],
        )
    }

    /// `(A ⊗ I3) x` node by node equals the product with the expanded `3n × 3n` matrix, for a
    /// sparse `A` and for one with every entry stored (the SIMD path).
    #[test]
    fn node_products_are_the_kronecker_products() {
        let dense = SymmetricCsr::from_triplets(
            5,
            &(0..25)
                .map(|k| {
                    let (i, j) = (k / 5, k % 5);
                    (i, j, 1.0 / (1.0 + i as f64 + j as f64))
                })
                .collect::<Vec<_>>(),
        );
        for a in [sample(), dense] {
            let n = a.n;
            let mut expanded = Vec::new();
            for i in 0..n {
                let (cols, values) = a.row(i);
                for (&j, &v) in cols.iter().zip(values) {
                    expanded.extend((0..3).map(|d| (3 * i + d, 3 * j + d, v)));
                }
            }
            let expanded = SymmetricCsr::from_triplets(3 * n, &expanded);
            let x: Vec<f64> = (0..3 * n).map(|k| (k as f64 * 0.7).sin()).collect();
            let (mut y, mut expected) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
            a.mul_nodes(&x, &mut y);
            expanded.mul_vec(&x, &mut expected);
            for (y, e) in y.iter().zip(&expected) {
                assert!((y - e).abs() <= 1e-15 * e.abs().max(1.0), "{y} against {e}");
            }
        }
    }

    #[test]
    fn triplets_sum_duplicates_and_sort_rows() {
        let a = sample();
        assert_eq!(a.row_ptr, vec![0, 2, 5, 7]);
        assert_eq!(a.col_idx, vec![0, 1, 0, 1, 2, 1, 2]);
        assert_eq!(a.values, vec![4.0, 1.0, 1.0, 3.0, 2.0, 2.0, 5.0]);
        let mut y = [0.0; 3];
        a.mul_vec(&[1.0, -1.0, 2.0], &mut y);
        assert_eq!(y, [3.0, 2.0, 8.0]);
        assert_eq!(a.diagonal(), vec![4.0, 3.0, 5.0]);
    }

    #[test]
    fn submatrix_kron_and_linear_combination_match_dense() {
        let a = sample();
        let dense = a.to_dense();
        let sub = a.submatrix(&[2, 0]);
        let ds = sub.to_dense();
        assert_eq!(ds[(0, 0)], dense[(2, 2)]);
        assert_eq!(ds[(0, 1)], dense[(2, 0)]);
        assert_eq!(ds[(1, 1)], dense[(0, 0)]);
        assert_eq!(sub.nnz(), 2); // (2,0) is structurally absent

        let k = a.kron_i3().to_dense();
        let expected = dense.kronecker(&DMatrix::<f64>::identity(3, 3));
        assert_eq!(k, expected);

        let b = SymmetricCsr::from_triplets(3, &[(0, 2, 1.0), (2, 0, 1.0), (1, 1, 1.0)]);
        let c = SymmetricCsr::linear_combination(2.0, &a, -3.0, &b);
        assert_eq!(c.to_dense(), dense * 2.0 - b.to_dense() * 3.0);
        for i in 0..3 {
            let (cols, _) = c.row(i);
            assert!(cols.windows(2).all(|w| w[0] < w[1]));
        }
    }

    #[test]
    fn block_product_equals_the_scalar_product() {
        // a 6×6 symmetric matrix with a missing entry inside a block
        let mut t = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                if (i, j) != (0, 4) && (i, j) != (4, 0) && (i + j) % 5 != 3 {
                    t.push((i, j, 1.0 + (i * 7 + j * 7) as f64 * 0.1 + (i * j) as f64));
                }
            }
        }
        let a = SymmetricCsr::from_triplets(6, &t);
        let b = BlockCsr3::from_csr(&a);
        let x: Vec<f64> = (0..6).map(|k| (k as f64).sin() + 2.0).collect();
        let (mut y1, mut y2) = (vec![0.0; 6], vec![0.0; 6]);
        a.mul_vec(&x, &mut y1);
        b.mul_vec(&x, &mut y2);
        for (p, q) in y1.iter().zip(&y2) {
            assert!((p - q).abs() < 1e-13 * p.abs().max(1.0), "{y1:?} {y2:?}");
        }
    }
}
