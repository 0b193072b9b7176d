//! Point constraints with Lagrange multipliers (seed paper eq. 9) and their Schur complement.
//!
//! A point constraint (a `pin` support) holds the weighted centroid of a node set at a point:
//! `c_p(x) = Σ_i ŵ_i x_i − d_p = 0` with `ŵ_i = w_i / Σ w`. Stacked, `C x = d` with a constant
//! Jacobian `C = (ŵ ⊗ I3)` per constraint, which commutes with the block rotation:
//! `C hR = hR_c C` (`hR_c = diag(R, …)` on the constraint rows). With `S = hR S̄ hRᵀ` the Schur
//! complement is therefore constant in the co-moving frame (docs/formulation.md, "One factorization per step size"):
//!
//! ```text
//! C S⁻¹ Cᵀ = hR_c Ā hR_cᵀ,   Ā = C Z,   Z = S̄⁻¹ Cᵀ   (3m columns, one solve each, once per h)
//! ```
//!
//! A modified-Newton iteration of `r(x) + Cᵀλ = 0`, `C x = d` is then: the unconstrained
//! correction `Δx_u = −hR S̄⁻¹ hRᵀ (r + Cᵀλ)` (the one sparse solve), the constraint error
//! `e = C (x + Δx_u) − d`, `μ = Ā⁻¹ hR_cᵀ e` (a small dense product), `Δλ = hR_c μ` and
//! `Δx = Δx_u − hR Z μ`. After each iteration `C x = d` holds to round-off: the constraints do
//! not drift (index 3, solved exactly for the multipliers; no stabilisation needed).

use crate::body::frame::node;
use crate::error::{Error, Result};
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use nalgebra::{DMatrix, Matrix3, Vector3};

/// One point constraint: the weighted centroid of `nodes` held at `target` (m).
#[derive(Debug, Clone)]
pub struct PointConstraint {
    /// Global node indices.
    pub nodes: Vec<usize>,
    /// Normalised weights `ŵ_i` (sum 1).
    pub weights: Vec<f64>,
    /// Rows of the free DOF vector of each node (`3k` for free node `k`).
    pub free_rows: Vec<usize>,
    pub target: Vector3<f64>,
}

impl PointConstraint {
    /// `Σ ŵ_i x_i`.
    pub fn centroid(&self, x: &[f64]) -> Vector3<f64> {
        let mut c = Vector3::zeros();
        for (&n, &w) in self.nodes.iter().zip(&self.weights) {
            c += w * node(x, n);
        }
        c
    }

    /// Row `e` of the constraint on a free-DOF column: `Σ ŵ_i v[row_i + e]` (real or complex).
    pub fn free_sum<T>(&self, column: &[T], e: usize) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::iter::Sum<T>,
    {
        self.free_rows
            .iter()
            .zip(&self.weights)
            .map(|(&row, &w)| column[row + e] * w)
            .sum()
    }
}

/// The constraint-dependent part of one iteration matrix: `Z = S̄⁻¹ Cᵀ` (free DOFs × 3m,
/// column-major) and `Ā⁻¹` (3m × 3m).
#[derive(Debug, Clone)]
pub struct ConstraintFactor {
    pub z: Vec<f64>,
    pub schur_inverse: DMatrix<f64>,
    /// Scratch: `hR_cᵀ e` and `μ` (3m each).
    pub error: Vec<f64>,
    pub mu: Vec<f64>,
}

impl ConstraintFactor {
    /// `Z` and `Ā⁻¹` for the factor of `S̄` (3m solves; at factorization time only).
    pub fn new(
        constraints: &[PointConstraint],
        factor: &SparseCholesky,
        workspace: &mut SolveWorkspace,
    ) -> Result<ConstraintFactor> {
        let n = factor.dim();
        let m = 3 * constraints.len();
        let mut z = vec![0.0; n * m];
        for (p, c) in constraints.iter().enumerate() {
            for d in 0..3 {
                let column = &mut z[(3 * p + d) * n..(3 * p + d + 1) * n];
                for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                    column[row + d] = w;
                }
                factor.solve_in_place(column, workspace);
            }
        }
        // Ā = C Z: row (q, e) of C picks Σ ŵ_i over constraint q's nodes at direction e.
        let mut a: DMatrix<f64> = DMatrix::zeros(m, m);
        for col in 0..m {
            let column = &z[col * n..(col + 1) * n];
            for (q, c) in constraints.iter().enumerate() {
                for e in 0..3 {
                    a[(3 * q + e, col)] = c.free_sum(column, e);
                }
            }
        }
        let a = (&a + a.transpose()) * 0.5;
        let schur_inverse = a.cholesky().map(|c| c.inverse()).ok_or_else(|| {
            Error::new(
                "the pin constraints are redundant (their Schur complement is singular): two pins on the same nodes?",
            )
        })?;
        Ok(ConstraintFactor {
            z,
            schur_inverse,
            error: vec![0.0; m],
            mu: vec![0.0; m],
        })
    }

    /// One constrained correction, in place. On entry `reduced` holds `y = S̄⁻¹ hRᵀ (r + Cᵀλ)`
    /// on the free DOFs (the unconstrained correction is `Δx_u = −hR y`); on return it holds
    /// `y + Z μ`, so that the constrained correction is `Δx = −hR (y + Z μ)`, and `multipliers`
    /// has been increased by `Δλ = hR_c μ` (global). `x` are the current positions, `r` the
    /// rotation of the co-moving frame.
    pub fn correct(
        &mut self,
        constraints: &[PointConstraint],
        x: &[f64],
        r: &Matrix3<f64>,
        reduced: &mut [f64],
        multipliers: &mut [f64],
    ) {
        let n = reduced.len();
        let m = self.error.len();
        // e = C (x + Δx_u) − d, rotated into the frame: hR_cᵀ e = Rᵀ (C x − d) − C y.
        let rt = r.transpose();
        for (p, c) in constraints.iter().enumerate() {
            let mut cu = Vector3::zeros();
            for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                cu += w * Vector3::new(reduced[row], reduced[row + 1], reduced[row + 2]);
            }
            let e = rt * (c.centroid(x) - c.target) - cu;
            self.error[3 * p..3 * p + 3].copy_from_slice(e.as_slice());
        }
        for i in 0..m {
            self.mu[i] = (0..m)
                .map(|j| self.schur_inverse[(i, j)] * self.error[j])
                .sum();
        }
        for (col, &mu) in self.mu.iter().enumerate() {
            let column = &self.z[col * n..(col + 1) * n];
            for (u, zc) in reduced.iter_mut().zip(column) {
                *u += zc * mu;
            }
        }
        for p in 0..constraints.len() {
            let dl = r * Vector3::new(self.mu[3 * p], self.mu[3 * p + 1], self.mu[3 * p + 2]);
            for d in 0..3 {
                multipliers[3 * p + d] += dl[d];
            }
        }
    }
}

/// Adds the constraint forces `Cᵀλ` to `f` (flat `3N`).
pub fn add_constraint_forces(constraints: &[PointConstraint], multipliers: &[f64], f: &mut [f64]) {
    for (p, c) in constraints.iter().enumerate() {
        for (&n, &w) in c.nodes.iter().zip(&c.weights) {
            for d in 0..3 {
                f[3 * n + d] += w * multipliers[3 * p + d];
            }
        }
    }
}
