//! Anderson acceleration of a preconditioned fixed-point iteration (type II; Walker & Ni,
//! SIAM J. Numer. Anal. 49 (2011) 1715).
//!
//! The step's iteration is `z ← z + g(z)` with `g(z) = −P⁻¹ r(z)`, `P` the constant (rotated)
//! iteration matrix. Where `P` misses part of the Jacobian `J` of `r` (the patches' rotations
//! relative to the frame that rotates `P`, the stiffening or `f_nl` terms), the plain iteration
//! contracts with the spectral radius of `I − P⁻¹ J`, which can approach 1. Anderson's method
//! keeps the last `m` differences `Δz_j`, `Δg_j` and takes
//!
//! `γ = argmin ‖g_k − ΔG γ‖₂`, `z_{k+1} = z_k + g_k − (ΔZ + ΔG) γ`,
//!
//! which is GMRES on the linearised problem (for `m` ≥ the iterations, in exact arithmetic)
//! without a single Jacobian product: it costs `O(m n)` per iteration next to a solve's
//! `O(nnz(L))`. The least squares fit uses the first `fit` entries of `g` only (the positions,
//! in metres), the mixing applies to all entries (positions and multipliers alike).

use crate::linalg::dot;
use nalgebra::{SMatrix, SVector};

/// The largest history depth (the small least-squares system lives on the stack).
pub const MAX_DEPTH: usize = 8;

/// Default history depth of the acceleration of the schemes' fixed-point iterations: 5 columns cost 10 vectors of the free DOFs and `O(5 n)` per
/// iteration; on B3 with patches deeper histories gave no fewer iterations
/// (`examples/iteration_policy.rs`).
pub const DEFAULT_DEPTH: usize = 5;

/// History and workspace of Anderson's method for vectors of length `n`; allocated once.
#[derive(Debug, Clone)]
pub struct Anderson {
    depth: usize,
    n: usize,
    fit: usize,
    /// Ring of `Δz_j` and `Δg_j`, `depth` columns of length `n`.
    dz: Vec<f64>,
    dg: Vec<f64>,
    z_previous: Vec<f64>,
    g_previous: Vec<f64>,
    /// Stored history columns and the next slot.
    stored: usize,
    next: usize,
    /// Iterations since [`Self::reset`].
    iterations: usize,
}

impl Anderson {
    /// History of `depth` (clamped to [`MAX_DEPTH`]; 0 disables the acceleration) for vectors
    /// of length `n` whose first `fit` entries enter the least-squares fit.
    pub fn new(depth: usize, n: usize, fit: usize) -> Anderson {
        let depth = depth.min(MAX_DEPTH);
        Anderson {
            depth,
            n,
            fit: fit.min(n),
            dz: vec![0.0; depth * n],
            dg: vec![0.0; depth * n],
            z_previous: vec![0.0; if depth > 0 { n } else { 0 }],
            g_previous: vec![0.0; if depth > 0 { n } else { 0 }],
            stored: 0,
            next: 0,
            iterations: 0,
        }
    }

    /// The history depth.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Forgets the history (at the start of every step: the fixed-point map changes).
    pub fn reset(&mut self) {
        self.stored = 0;
        self.next = 0;
        self.iterations = 0;
    }

    /// Replaces the plain update `g` at the iterate `z` by the accelerated one, so that the next
    /// iterate is `z + g`. No allocation.
    pub fn accelerate(&mut self, z: &[f64], g: &mut [f64]) {
        if self.depth == 0 {
            return;
        }
        let n = self.n;
        assert_eq!(z.len(), n, "Anderson::accelerate: z has the wrong length");
        assert_eq!(g.len(), n, "Anderson::accelerate: g has the wrong length");
        if self.iterations > 0 {
            let col = self.next * n;
            for k in 0..n {
                self.dz[col + k] = z[k] - self.z_previous[k];
                self.dg[col + k] = g[k] - self.g_previous[k];
            }
            self.next = (self.next + 1) % self.depth;
            self.stored = (self.stored + 1).min(self.depth);
        }
        self.iterations += 1;
        self.z_previous.copy_from_slice(z);
        self.g_previous.copy_from_slice(g);
        let m = self.stored;
        if m == 0 {
            return;
        }
        // Normal equations (ΔGᵀΔG + εI) γ = ΔGᵀ g over the fitted entries, padded to
        // MAX_DEPTH with the identity (so the unused γ are zero) and solved on the stack.
        let fit = self.fit;
        let column = |j: usize| j * n..j * n + fit;
        let mut a = SMatrix::<f64, MAX_DEPTH, MAX_DEPTH>::identity();
        let mut b = SVector::<f64, MAX_DEPTH>::zeros();
        for i in 0..m {
            let gi = &self.dg[column(i)];
            for j in 0..=i {
                let gij = dot(gi, &self.dg[column(j)]);
                a[(i, j)] = gij;
                a[(j, i)] = gij;
            }
            b[i] = dot(gi, &g[..fit]);
        }
        let trace: f64 = (0..m).map(|i| a[(i, i)]).sum();
        if !(trace > 0.0 && trace.is_finite()) {
            self.reset_keeping_current();
            return;
        }
        for i in 0..m {
            a[(i, i)] += 1e-12 * trace;
        }
        let Some(cholesky) = a.cholesky() else {
            self.reset_keeping_current();
            return;
        };
        let gamma = cholesky.solve(&b);
        for (j, &gj) in gamma.iter().enumerate().take(m) {
            let (dz, dg) = (&self.dz[j * n..(j + 1) * n], &self.dg[j * n..(j + 1) * n]);
            for ((gk, zk), hk) in g.iter_mut().zip(dz).zip(dg) {
                *gk -= gj * (zk + hk);
            }
        }
    }

    /// Drops the history but keeps the current iterate as the start of a new one.
    fn reset_keeping_current(&mut self) {
        self.stored = 0;
        self.next = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain iteration `z ← z − P⁻¹ (J z − c)` with `P = I` on a diagonal `J` whose
    /// spectrum spans (0.05, 1.95): contraction 0.95 per iteration.
    fn run(depth: usize) -> (usize, f64) {
        let n = 40;
        let j: Vec<f64> = (0..n)
            .map(|k| 0.05 + 1.9 * k as f64 / (n - 1) as f64)
            .collect();
        let c: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin()).collect();
        let exact: Vec<f64> = c.iter().zip(&j).map(|(c, j)| c / j).collect();
        let mut z = vec![0.0; n];
        let mut g = vec![0.0; n];
        let mut anderson = Anderson::new(depth, n, n);
        for it in 1..=2000 {
            for k in 0..n {
                g[k] = -(j[k] * z[k] - c[k]);
            }
            let plain = g.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            if plain < 1e-12 {
                let err = z
                    .iter()
                    .zip(&exact)
                    .fold(0.0_f64, |a, (z, e)| a.max((z - e).abs()));
                return (it, err);
            }
            anderson.accelerate(&z, &mut g);
            for k in 0..n {
                z[k] += g[k];
            }
        }
        (usize::MAX, f64::NAN)
    }

    #[test]
    fn accelerates_a_slowly_contracting_linear_iteration() {
        let (plain, plain_error) = run(0);
        let (accelerated, error) = run(5);
        // Plain: 0.95^k < 1e-12 needs ≈ 540 iterations.
        assert!((500..600).contains(&plain), "plain took {plain}");
        assert!(plain_error < 1e-10 && error < 1e-10);
        // Anderson(5) ~ restarted GMRES(5) on a spectrum of condition 39: far fewer.
        assert!(accelerated < plain / 4, "accelerated took {accelerated}");
    }

    #[test]
    fn exact_in_one_dimension_after_one_secant() {
        // g(z) = −(3z − 1)·0.1 (contraction 0.7); one secant gives z = 1/3 exactly.
        let mut a = Anderson::new(3, 1, 1);
        let mut z = [0.0];
        let mut g = [0.0];
        for _ in 0..2 {
            g[0] = -0.1 * (3.0 * z[0] - 1.0);
            a.accelerate(&z, &mut g);
            z[0] += g[0];
        }
        // Exact but for the Tikhonov shift 1e-12·trace of the normal equations: the secant
        // step is scaled by 1/(1 + 1e-12), an error of 1e-12 × |step| ≈ 3e-13.
        assert!((z[0] - 1.0 / 3.0).abs() < 1e-12, "{}", z[0]);
    }
}
