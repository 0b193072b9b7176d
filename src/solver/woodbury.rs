//! The rank-3 (Woodbury) correction of the constant iteration matrix for the nonlinear force
//! `f_nl` (docs/formulation.md, "The fixed-point iteration").
//!
//! In the co-moving frame `f̄_nl = B z` with the constant `B_i = −w_i [X̄_i]×` (3N × 3) and
//! `z = H⁻ᵀ m̄`, `m̄ = Σ ū_i × g_i`, `g = K ū`. Its Jacobian with respect to the local
//! displacement, with `H` held,
//!
//! ```text
//! ∂f̄_nl/∂ū = B H⁻ᵀ A,   A δū = Σ_i δū_i × g_i + Σ_i ū_i × (K δū)_i
//!                          = Σ_i δū_i × g_i − [δūᵀ K c_1, δūᵀ K c_2, δūᵀ K c_3],
//! ```
//!
//! with `c_k,i = ū_i × e_k`, is of rank 3 and scales with `K |ū|`: the term that made the plain
//! constant-matrix iteration diverge on B3. Woodbury's identity keeps the constant factor:
//!
//! ```text
//! (S̄ + B H⁻ᵀ A)⁻¹ r = y − Y (I + H⁻ᵀ A Y)⁻¹ H⁻ᵀ A y,   y = S̄⁻¹ r,   Y = S̄⁻¹ B
//! ```
//!
//! `Y` (three solves) is computed with the factorization, once per step size; `K c_k` (three
//! block products) and the 3×3 `(I + H⁻ᵀ A Y)⁻¹` once per step, at the predictor; each iteration
//! then adds O(N) work to its one solve.

use super::problem::FreeNodes;
use crate::body::frame::node;
use crate::body::Body;
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use nalgebra::{Matrix3, Vector3};

/// `Y = S̄⁻¹ B` for one factorization, and the per-step data of the correction.
#[derive(Debug, Clone)]
pub struct NonlinearForceCorrection {
    /// `Y`, free DOFs × 3, column-major.
    y: Vec<f64>,
    /// `K c_k` on the free DOFs (free DOFs × 3, column-major), per step.
    kc: Vec<f64>,
    /// `g = K ū` on the free DOFs, per step.
    g: Vec<f64>,
    /// `H⁻ᵀ` and `(I + H⁻ᵀ A Y)⁻¹`, per step.
    h_inv_t: Matrix3<f64>,
    small_inverse: Matrix3<f64>,
    /// Scratch `c_k` and `K c_k` on all DOFs (3N).
    c_full: Vec<f64>,
    kc_full: Vec<f64>,
    active: bool,
}

impl NonlinearForceCorrection {
    /// `Y = S̄⁻¹ B` (three solves with `factor`).
    pub fn new(
        body: &Body,
        free: &FreeNodes,
        factor: &SparseCholesky,
        workspace: &mut SolveWorkspace,
    ) -> NonlinearForceCorrection {
        let n = free.dof_count();
        let fw = &body.frame_weights;
        let mut y = vec![0.0; 3 * n];
        for j in 0..3 {
            let column = &mut y[j * n..(j + 1) * n];
            let e = Vector3::ith(j, 1.0);
            for (k, &i) in free.nodes.iter().enumerate() {
                let b = -fw.arms[i].cross(&e);
                column[3 * k..3 * k + 3].copy_from_slice(b.as_slice());
            }
            factor.solve_in_place(column, workspace);
        }
        let n3 = body.reference.len();
        NonlinearForceCorrection {
            y,
            kc: vec![0.0; 3 * n],
            g: vec![0.0; n],
            h_inv_t: Matrix3::zeros(),
            small_inverse: Matrix3::identity(),
            c_full: vec![0.0; n3],
            kc_full: vec![0.0; n3],
            active: false,
        }
    }

    /// `A v` for a free-DOF vector `v` (with the per-step `g` and `K c_k`).
    fn apply_a(&self, v: &[f64]) -> Vector3<f64> {
        let n = v.len();
        let mut a = Vector3::zeros();
        for k in 0..n / 3 {
            a += node(v, k).cross(&node(&self.g, k));
        }
        for j in 0..3 {
            let kc = &self.kc[j * n..(j + 1) * n];
            a[j] -= v.iter().zip(kc).map(|(p, q)| p * q).sum::<f64>();
        }
        a
    }

    /// The per-step data at the local deformation `ubar`, elastic force `g = K ubar` (flat 3N)
    /// and `H⁻¹` of the current frame. Allocation-free.
    pub fn update(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        ubar: &[f64],
        g: &[f64],
        h_inv: &Matrix3<f64>,
    ) {
        let n = free.dof_count();
        for (k, &i) in free.nodes.iter().enumerate() {
            self.g[3 * k..3 * k + 3].copy_from_slice(&g[3 * i..3 * i + 3]);
        }
        for j in 0..3 {
            let e = Vector3::ith(j, 1.0);
            for i in 0..body.node_count() {
                let c = node(ubar, i).cross(&e);
                self.c_full[3 * i..3 * i + 3].copy_from_slice(c.as_slice());
            }
            body.stiffness_product(&self.c_full, &mut self.kc_full);
            for (k, &i) in free.nodes.iter().enumerate() {
                self.kc[j * n + 3 * k..j * n + 3 * k + 3]
                    .copy_from_slice(&self.kc_full[3 * i..3 * i + 3]);
            }
        }
        self.h_inv_t = h_inv.transpose();
        let mut ay = Matrix3::zeros();
        for j in 0..3 {
            let column = self.apply_a(&self.y[j * n..(j + 1) * n]);
            ay.set_column(j, &column);
        }
        self.small_inverse = (Matrix3::identity() + self.h_inv_t * ay)
            .try_inverse()
            .unwrap_or_else(Matrix3::identity);
        self.active = true;
    }

    /// `y ← y − Y (I + H⁻ᵀ A Y)⁻¹ H⁻ᵀ A y` for `y = S̄⁻¹ r` (free DOFs, co-moving frame).
    pub fn correct(&self, y: &mut [f64]) {
        if !self.active {
            return;
        }
        let n = y.len();
        let coefficients = self.small_inverse * (self.h_inv_t * self.apply_a(y));
        for j in 0..3 {
            let column = &self.y[j * n..(j + 1) * n];
            for (v, c) in y.iter_mut().zip(column) {
                *v -= c * coefficients[j];
            }
        }
    }
}
