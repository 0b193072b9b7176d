//! Lowest eigenpairs of `K φ = ω² M φ` on the free DOFs (subspace iteration on the sparse
//! Cholesky factor of `K`).
//!
//! Subspace iteration (Bathe & Wilson): with `q = min(n, max(2p, p + 8))` vectors for `p`
//! wanted pairs, repeat
//!
//! 1. `K X̄ = M X` (one factorization of `K`, `q` solves);
//! 2. Rayleigh–Ritz on span `X̄`: `K_r = X̄ᵀ K X̄ = X̄ᵀ (M X)`, `M_r = X̄ᵀ M X̄`, solve the dense
//!    `K_r Q = M_r Q Λ` (Cholesky of `M_r`, symmetric eigen-decomposition), `X ← X̄ Q`;
//!
//! until the `p` lowest Ritz values change by less than `tolerance` relative between two
//! iterations. Vector `i` converges like `(λ_i / λ_{q+1})^k`; a Ritz value's error is of the order
//! of the square of its vector's error, so `tolerance = 1e-10` gives eigenvalues to about 1e-10
//! and modes to about 1e-5 (relative). Requires `K` positive definite (constrained body) and `M`
//! positive definite.

use crate::error::{Error, Result};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::SymmetricCsr;
use nalgebra::DMatrix;

/// The lowest generalized eigenpairs.
#[derive(Debug, Clone)]
pub struct EigenPairs {
    /// `ω²` (1/s²), ascending.
    pub eigenvalues: Vec<f64>,
    /// Mode shapes `φ_i`, mass-normalized (`φ_iᵀ M φ_j = δ_ij`).
    pub modes: Vec<Vec<f64>>,
    /// Subspace iterations used.
    pub iterations: usize,
}

impl EigenPairs {
    /// Natural frequencies `f_i = ω_i / (2π)` (Hz).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }
}

/// The `count` lowest eigenpairs of `K φ = ω² M φ` (both `n × n`, already restricted to the free
/// DOFs), converged to `tolerance` (relative change of the Ritz values between iterations),
/// within `max_iterations` subspace iterations; error otherwise or if `K` is not positive definite.
pub fn lowest_eigenpairs(
    k: &SymmetricCsr,
    m: &SymmetricCsr,
    count: usize,
    tolerance: f64,
    max_iterations: usize,
) -> Result<EigenPairs> {
    let n = k.n;
    if m.n != n {
        return Err(Error::new(format!(
            "modal analysis: K is {n}×{n} but M is {}×{}",
            m.n, m.n
        )));
    }
    if count == 0 || count > n {
        return Err(Error::invalid_value(
            "modal.count",
            count,
            &format!("must lie in 1..={n}"),
        ));
    }
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(Error::invalid_value(
            "modal.tolerance",
            tolerance,
            "must be positive",
        ));
    }
    let q = n.min((2 * count).max(count + 8));
    let factor = SparseCholesky::new(k)
        .map_err(|e| Error::new(format!("modal analysis: K must be positive definite: {e}")))?;
    let mut workspace = factor.solve_scratch();

    // Start vectors: diag(M)-weighted deterministic pseudo-random columns (a linear congruential
    // generator; any start not M-orthogonal to the wanted modes works).
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let mut x = DMatrix::<f64>::from_fn(n, q, |_, _| next());
    let mut mx = DMatrix::<f64>::zeros(n, q);
    for j in 0..q {
        let (col, out) = (
            &x.as_slice()[j * n..(j + 1) * n],
            &mut mx.as_mut_slice()[j * n..(j + 1) * n],
        );
        m.mul_vec(col, out);
    }
    let mut xbar = DMatrix::<f64>::zeros(n, q);
    let mut mxbar = DMatrix::<f64>::zeros(n, q);
    let mut previous: Option<Vec<f64>> = None;
    for iteration in 1..=max_iterations {
        xbar.copy_from(&mx);
        for j in 0..q {
            factor.solve_in_place(&mut xbar.as_mut_slice()[j * n..(j + 1) * n], &mut workspace);
            m.mul_vec(
                &xbar.as_slice()[j * n..(j + 1) * n],
                &mut mxbar.as_mut_slice()[j * n..(j + 1) * n],
            );
        }
        let mut kr = symmetrize(xbar.transpose() * &mx);
        let chol = match symmetrize(xbar.transpose() * &mxbar).cholesky() {
            Some(chol) => chol,
            None => {
                // `K⁻¹ M` scales mode j by 1/λ_j: with the shifted rigid modes of a free body
                // (λ = σ, small) every column is nearly in their span and `M_r` is too
                // ill-conditioned to factor. Make the columns M-orthonormal (Gram–Schmidt
                // twice), which keeps the span, and form the Ritz matrices again.
                m_orthonormalize(m, &mut xbar, &mut mx, &mut mxbar);
                kr = symmetrize(xbar.transpose() * &mx);
                symmetrize(xbar.transpose() * &mxbar)
                    .cholesky()
                    .ok_or_else(|| {
                        Error::new(
                            "modal analysis: the Ritz basis lost independence (M_r not positive definite)",
                        )
                    })?
            }
        };
        let l_inv = chol
            .l()
            .solve_lower_triangular(&DMatrix::identity(q, q))
            .ok_or_else(|| Error::new("modal analysis: singular Ritz mass matrix"))?;
        let c = symmetrize(&l_inv * &kr * l_inv.transpose());
        let eigen = c.symmetric_eigen();
        let mut order: Vec<usize> = (0..q).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        let values: Vec<f64> = order.iter().map(|&i| eigen.eigenvalues[i]).collect();
        let v = DMatrix::from_fn(q, q, |r, col| eigen.eigenvectors[(r, order[col])]);
        // Q = L⁻ᵀ V is M_r-orthonormal.
        let ritz = l_inv.transpose() * v;
        x = &xbar * &ritz;
        mx = &mxbar * &ritz;
        let converged = previous.as_ref().is_some_and(|old| {
            (0..count).all(|i| (values[i] - old[i]).abs() <= tolerance * values[i].abs())
        });
        if converged {
            let modes = (0..count)
                .map(|j| x.as_slice()[j * n..(j + 1) * n].to_vec())
                .collect();
            return Ok(EigenPairs {
                eigenvalues: values[..count].to_vec(),
                modes,
                iterations: iteration,
            });
        }
        previous = Some(values);
    }
    Err(Error::new(format!(
        "modal analysis: subspace iteration did not converge to {tolerance:e} in {max_iterations} iterations"
    )))
}

/// Makes the columns of `x` (n × q) M-orthonormal by modified Gram–Schmidt, twice, applying the
/// same column operations to `k_x = K x` (known only as the products it stands for: the
/// operations are linear) and recomputing `m_x = M x`.
fn m_orthonormalize(
    m: &SymmetricCsr,
    x: &mut DMatrix<f64>,
    k_x: &mut DMatrix<f64>,
    m_x: &mut DMatrix<f64>,
) {
    let (n, q) = x.shape();
    for _ in 0..2 {
        for j in 0..q {
            let (xs, ms) = (x.as_mut_slice(), m_x.as_mut_slice());
            m.mul_vec(&xs[j * n..(j + 1) * n], &mut ms[j * n..(j + 1) * n]);
            for i in 0..j {
                let c = crate::linalg::dot(
                    &x.as_slice()[i * n..(i + 1) * n],
                    &m_x.as_slice()[j * n..(j + 1) * n],
                );
                for r in 0..n {
                    x[(r, j)] -= c * x[(r, i)];
                    m_x[(r, j)] -= c * m_x[(r, i)];
                    k_x[(r, j)] -= c * k_x[(r, i)];
                }
            }
            let norm = crate::linalg::dot(
                &x.as_slice()[j * n..(j + 1) * n],
                &m_x.as_slice()[j * n..(j + 1) * n],
            )
            .max(f64::MIN_POSITIVE)
            .sqrt();
            for r in 0..n {
                x[(r, j)] /= norm;
                m_x[(r, j)] /= norm;
                k_x[(r, j)] /= norm;
            }
        }
    }
}

/// `(A + Aᵀ) / 2`.
fn symmetrize(a: DMatrix<f64>) -> DMatrix<f64> {
    let t = a.transpose();
    (a + t) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spring_chain_matches_the_analytic_spectrum() {
        // Fixed–fixed chain of n unit masses and unit springs: K = tridiag(−1, 2, −1), M = I,
        // eigenvalues 4 sin²(iπ / (2(n+1))).
        let n = 60;
        let k = crate::linalg::sparse::laplacian(n);
        let m = SymmetricCsr::from_triplets(n, &(0..n).map(|i| (i, i, 1.0)).collect::<Vec<_>>());
        let pairs = lowest_eigenpairs(&k, &m, 3, 1e-12, 200).unwrap();
        for (i, lambda) in pairs.eigenvalues.iter().enumerate() {
            let exact = 4.0
                * ((i + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64))
                    .sin()
                    .powi(2);
            assert!(
                (lambda - exact).abs() < 1e-9 * exact,
                "λ_{i} = {lambda} vs {exact}"
            );
            // Residual ‖Kφ − λMφ‖ small and mass normalization.
            let phi = &pairs.modes[i];
            let mut kphi = vec![0.0; n];
            k.mul_vec(phi, &mut kphi);
            let res = kphi
                .iter()
                .zip(phi)
                .map(|(a, b)| (a - lambda * b).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(res < 1e-4 * lambda, "residual {res}");
            let norm: f64 = phi.iter().map(|v| v * v).sum();
            assert!((norm - 1.0).abs() < 1e-10);
        }
    }

    #[test]
    fn rejects_bad_arguments() {
        let k = SymmetricCsr::from_triplets(2, &[(0, 0, 1.0), (1, 1, -1.0)]);
        let m = SymmetricCsr::from_triplets(2, &[(0, 0, 1.0), (1, 1, 1.0)]);
        assert!(lowest_eigenpairs(&k, &m, 1, 1e-10, 10)
            .unwrap_err()
            .message
            .contains("positive definite"));
        assert!(lowest_eigenpairs(&m, &m, 3, 1e-10, 10).is_err());
    }
}
