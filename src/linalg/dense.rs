//! Dense symmetric matrices for the hot-path products of a reduced body (`model.modes`), whose
//! projected mass `Sᵀ Ms S` and stiffness `K_r` are full: a column-major faer matrix and its
//! SIMD matrix–vector product replace the compressed storage of the mesh matrices, whose index
//! per entry costs more than the product when every entry is stored (at `3s = 168`: 4.3 µs
//! against 8.3 µs of [`super::sparse::BlockCsr3::mul_vec`], 1.5 µs against 5.2 µs for `Ms ⊗ I3`).
//!
//! `y = A x` itself reads only the upper triangle ([`UpperPanels`]): at these sizes the matrix
//! lives in the L2 cache and the full product is bound by reading it, so reading half of it,
//! each entry serving `y_i` and `y_j`, takes about half the time.

use super::SymmetricCsr;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use pulp::{Arch, Simd, WithSimd};

/// A dense symmetric `n × n` matrix.
#[derive(Debug, Clone)]
pub struct DenseSymmetric {
    matrix: Mat<f64>,
    /// The upper triangle of `matrix`, for [`Self::mul_vec`].
    upper: UpperPanels,
    /// The SIMD instruction set found at run time (`pulp`, faer's SIMD layer).
    arch: Arch,
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
        DenseSymmetric::new(matrix)
    }

    /// The dense matrix `m` (square, symmetric by the caller's construction).
    pub fn new(matrix: Mat<f64>) -> DenseSymmetric {
        assert_eq!(matrix.nrows(), matrix.ncols(), "DenseSymmetric: not square");
        let upper = UpperPanels::new(matrix.as_ref());
        DenseSymmetric {
            matrix,
            upper,
            arch: Arch::new(),
        }
    }

    /// Overwrite the matrix with the symmetric `(m + mᵀ)/2` of a square `m` of the same
    /// dimension. No allocation.
    pub fn assign_symmetrised(&mut self, m: MatRef<'_, f64>) {
        let n = self.dim();
        assert!(
            m.nrows() == n && m.ncols() == n,
            "DenseSymmetric: dimension"
        );
        for j in 0..n {
            for i in 0..n {
                self.matrix[(i, j)] = 0.5 * (m[(i, j)] + m[(j, i)]);
            }
        }
        self.upper.assign(self.matrix.as_ref());
    }

    /// Dimension `n`.
    pub fn dim(&self) -> usize {
        self.matrix.nrows()
    }

    /// `y = A x` (length `n`). No allocation. Reads the upper triangle once
    /// ([`UpperPanels::mul_vec`]): B1's reduced solve with `A⁻¹` (`n` = 129) takes 1.0 µs
    /// against 1.6 µs of faer's product with the whole matrix (a 200 000-fold loop, best of 5).
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        self.upper.mul_vec(self.arch, x, y);
    }

    /// `y = A[:, columns] x` (`x` of the columns' length, `y` of `n`): the contiguous columns
    /// four at a time, each block of `y` loaded and stored once per four columns (SIMD, `pulp`).
    /// No allocation. B1's reduced held block (129 × 12) took about half of faer's general
    /// product's time, which is sized for larger blocks.
    pub fn mul_columns(&self, columns: std::ops::Range<usize>, x: &[f64], y: &mut [f64]) {
        assert!(
            x.len() == columns.len() && y.len() == self.dim() && columns.end <= self.dim(),
            "DenseSymmetric::mul_columns: lengths"
        );
        self.arch.dispatch(ColumnsProduct {
            matrix: &self.matrix,
            first: columns.start,
            x,
            y,
        });
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

/// The upper triangle of a symmetric `n × n` matrix `A`, stored for the product `y = A x` in
/// panels of four rows: panel `p` holds rows `4p..4p + 4` from column `4p` to `n`, each row
/// contiguous, with the entries left of the diagonal zero and the diagonal halved. Then the
/// panel `B` (`4 × (n − 4p)`) gives `y_{4p..} += B x_{4p..}` (row sums) and
/// `y_{4p..} += Bᵀ x_{4p..4p+4}` (the same entries read once for the symmetric half), and the
/// two together add `A`'s rows `4p..4p+4` and their mirrored columns exactly once: the halved
/// diagonal counted twice, the zeros not at all. Rows past `n` (the last panel's) are zero.
#[derive(Debug, Clone)]
struct UpperPanels {
    n: usize,
    /// The panels one after another; panel `p` starts at `offsets[p]`.
    entries: Vec<f64>,
    offsets: Vec<usize>,
}

/// Rows per panel of [`UpperPanels`]: four accumulators and four broadcast values stay in
/// registers beside the loaded column block.
const PANEL_ROWS: usize = 4;

impl UpperPanels {
    fn new(a: MatRef<'_, f64>) -> UpperPanels {
        let n = a.nrows();
        let panels = n.div_ceil(PANEL_ROWS);
        let mut offsets = Vec::with_capacity(panels);
        let mut length = 0;
        for p in 0..panels {
            offsets.push(length);
            length += PANEL_ROWS * (n - PANEL_ROWS * p);
        }
        let mut upper = UpperPanels {
            n,
            entries: vec![0.0; length],
            offsets,
        };
        upper.assign(a);
        upper
    }

    /// Take the upper triangle of `a` (same dimension). No allocation.
    fn assign(&mut self, a: MatRef<'_, f64>) {
        let n = self.n;
        for (p, &offset) in self.offsets.iter().enumerate() {
            let start = PANEL_ROWS * p;
            let width = n - start;
            for r in 0..PANEL_ROWS {
                let row = &mut self.entries[offset + r * width..offset + (r + 1) * width];
                let i = start + r;
                for (k, entry) in row.iter_mut().enumerate() {
                    let j = start + k;
                    *entry = if i >= n || j < i {
                        0.0
                    } else if j == i {
                        0.5 * a[(i, i)]
                    } else {
                        a[(i, j)]
                    };
                }
            }
        }
    }

    /// `y = A x`, each stored entry read once, with the SIMD instructions of `arch`. No
    /// allocation.
    fn mul_vec(&self, arch: Arch, x: &[f64], y: &mut [f64]) {
        assert!(
            x.len() == self.n && y.len() == self.n,
            "UpperPanels: length"
        );
        arch.dispatch(PanelProduct { upper: self, x, y });
    }
}

/// [`UpperPanels::mul_vec`] for one SIMD instruction set.
struct PanelProduct<'a> {
    upper: &'a UpperPanels,
    x: &'a [f64],
    y: &'a mut [f64],
}

impl WithSimd for PanelProduct<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let PanelProduct { upper, x, y } = self;
        let n = upper.n;
        y.fill(0.0);
        for (p, &offset) in upper.offsets.iter().enumerate() {
            let start = PANEL_ROWS * p;
            let width = n - start;
            let panel = &upper.entries[offset..offset + PANEL_ROWS * width];
            let (row0, rest) = panel.split_at(width);
            let (row1, rest) = rest.split_at(width);
            let (row2, row3) = rest.split_at(width);
            let rows = [row0, row1, row2, row3];
            // x_i of the panel's rows (0 past n).
            let x_row: [f64; PANEL_ROWS] =
                std::array::from_fn(|r| x.get(start + r).copied().unwrap_or(0.0));
            let x_splat = x_row.map(|v| simd.splat_f64s(v));
            let mut sums = [simd.splat_f64s(0.0); PANEL_ROWS];
            let (x_blocks, x_tail) = S::as_simd_f64s(&x[start..]);
            let (y_blocks, y_tail) = S::as_mut_simd_f64s(&mut y[start..]);
            let blocks = x_blocks.len();
            let row_blocks = rows.map(|row| S::as_simd_f64s(row));
            for k in 0..blocks {
                let xk = x_blocks[k];
                let mut yk = y_blocks[k];
                for r in 0..PANEL_ROWS {
                    let a = row_blocks[r].0[k];
                    sums[r] = simd.mul_add_e_f64s(a, xk, sums[r]);
                    yk = simd.mul_add_e_f64s(a, x_splat[r], yk);
                }
                y_blocks[k] = yk;
            }
            let mut tail_sums = [0.0; PANEL_ROWS];
            for (t, (&xj, yj)) in x_tail.iter().zip(y_tail.iter_mut()).enumerate() {
                for r in 0..PANEL_ROWS {
                    let a = row_blocks[r].1[t];
                    tail_sums[r] += a * xj;
                    *yj += a * x_row[r];
                }
            }
            for r in 0..PANEL_ROWS.min(n - start) {
                y[start + r] += simd.reduce_sum_f64s(sums[r]) + tail_sums[r];
            }
        }
    }
}

/// [`DenseSymmetric::mul_columns`] for one SIMD instruction set.
struct ColumnsProduct<'a> {
    matrix: &'a Mat<f64>,
    first: usize,
    x: &'a [f64],
    y: &'a mut [f64],
}

impl WithSimd for ColumnsProduct<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let ColumnsProduct {
            matrix,
            first,
            x,
            y,
        } = self;
        y.fill(0.0);
        let column = |c: usize| matrix.col_as_slice(first + c);
        let mut c = 0;
        while c < x.len() {
            let width = (x.len() - c).min(4);
            let cols: [&[f64]; 4] = std::array::from_fn(|k| column(c + k.min(width - 1)));
            // Columns past the block repeat its last with a zero factor.
            let factors: [f64; 4] = std::array::from_fn(|k| if k < width { x[c + k] } else { 0.0 });
            let splat = factors.map(|v| simd.splat_f64s(v));
            let blocks = cols.map(|col| S::as_simd_f64s(col));
            let (y_blocks, y_tail) = S::as_mut_simd_f64s(y);
            for (k, yk) in y_blocks.iter_mut().enumerate() {
                let mut acc = *yk;
                for j in 0..4 {
                    acc = simd.mul_add_e_f64s(blocks[j].0[k], splat[j], acc);
                }
                *yk = acc;
            }
            for (t, yt) in y_tail.iter_mut().enumerate() {
                for j in 0..4 {
                    *yt += blocks[j].1[t] * factors[j];
                }
            }
            c += width;
        }
    }
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
    fn the_upper_panels_product_is_the_full_product() {
        // Every remainder of n by the panel's four rows and the SIMD width, and an update of the
        // values: equal to faer's product with the whole matrix to round-off (n terms ≤ 1).
        for n in 1..=19 {
            let a = DenseSymmetric::from_csr(&sample(n));
            let x: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).cos()).collect();
            let mut expected = vec![0.0; n];
            matmul(
                MatMut::from_column_major_slice_mut(&mut expected, n, 1),
                Accum::Replace,
                a.matrix.as_ref(),
                MatRef::from_column_major_slice(&x, n, 1),
                1.0,
                Par::Seq,
            );
            let mut y = vec![f64::NAN; n];
            a.mul_vec(&x, &mut y);
            for (p, q) in expected.iter().zip(&y) {
                assert!((p - q).abs() < 1e-14, "n = {n}: {p} {q}");
            }
            // Blocks of columns of every width up to six (four at a time, and the rest).
            for start in 0..n {
                for end in start + 1..=(start + 6).min(n) {
                    let mut z = vec![f64::NAN; n];
                    a.mul_columns(start..end, &x[start..end], &mut z);
                    for (i, zi) in z.iter().enumerate() {
                        let direct: f64 = (start..end).map(|j| a.matrix[(i, j)] * x[j]).sum();
                        assert!((direct - zi).abs() < 1e-14, "n = {n}, {start}..{end}");
                    }
                }
            }
            let mut b = a.clone();
            let twice = Mat::<f64>::from_fn(n, n, |i, j| 2.0 * a.matrix[(i, j)]);
            b.assign_symmetrised(twice.as_ref());
            b.mul_vec(&x, &mut y);
            for (p, q) in expected.iter().zip(&y) {
                assert!((2.0 * p - q).abs() < 2e-14, "n = {n}: {p} {q}");
            }
        }
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
