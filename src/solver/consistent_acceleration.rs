//! Accelerations consistent with given forces: the constant-mass solve
//!
//! `M_FF ẍ_F + C_Fᵀ λ = r_F`, `C ẍ = 0`
//!
//! on the free DOFs, with `M = Ms ⊗ I3` and the point constraints `C` (pins, hinges). One
//! factorization of `Ms_FF` (scalar, `N_F × N_F`) per model; with `s_p` the weights of constraint
//! `p` on the free nodes, `C M⁻¹ Cᵀ = B ⊗ I3` with the scalar `B_pq = s_pᵀ Ms⁻¹ s_q`, whose
//! inverse and the vectors `Ms⁻¹ s_p` are kept. A solve then costs three scalar triangular
//! solve pairs and `O(m N_F)`; no allocation.
//!
//! It serves the initial acceleration and the restart of the scheme when the held inputs jump
//! at a communication point (generalized-α's `restart_for_load_change`).

use super::problem::FreeNodes;
use crate::error::{Error, Result};
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use nalgebra::DMatrix;

/// The factor of `Ms_FF` and the constraint projection.
pub struct ConsistentAcceleration {
    factor: SparseCholesky,
    workspace: SolveWorkspace,
    /// `Ms⁻¹ s_p` for each point constraint (length `N_F`).
    inverse_weights: Vec<Vec<f64>>,
    /// `B⁻¹` (m × m).
    projection: DMatrix<f64>,
    column: Vec<f64>,
    multipliers: Vec<f64>,
}

impl ConsistentAcceleration {
    pub fn new(free: &FreeNodes) -> Result<ConsistentAcceleration> {
        let factor = SparseCholesky::new(&free.scalar_mass)?;
        let mut workspace = factor.solve_scratch();
        let nf = free.nodes.len();
        let m = free.constraints.len();
        let mut inverse_weights = vec![vec![0.0; nf]; m];
        for (p, c) in free.constraints.iter().enumerate() {
            for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                inverse_weights[p][row / 3] = w;
            }
            factor.solve_in_place(&mut inverse_weights[p], &mut workspace);
        }
        let b = DMatrix::from_fn(m, m, |p, q| {
            free.constraints[p]
                .free_rows
                .iter()
                .zip(&free.constraints[p].weights)
                .map(|(&row, &w)| w * inverse_weights[q][row / 3])
                .sum::<f64>()
        });
        let projection = b
            .try_inverse()
            .ok_or_else(|| Error::new("the pin constraints are redundant"))?;
        Ok(ConsistentAcceleration {
            factor,
            workspace,
            inverse_weights,
            projection,
            column: vec![0.0; nf],
            multipliers: vec![0.0; m],
        })
    }

    /// Overwrites the free nodes' entries of `a` (flat `3N`) with `M_FF⁻¹ r_F` projected on
    /// `C a = 0` (the constrained nodes' other entries of `a`, e.g. prescribed accelerations, enter
    /// `C a`), and `lambda` (3 per constraint) with the multipliers. `r` is flat `3N`.
    pub fn solve(&mut self, free: &FreeNodes, r: &[f64], a: &mut [f64], lambda: &mut [f64]) {
        for d in 0..3 {
            for (k, &i) in free.nodes.iter().enumerate() {
                self.column[k] = r[3 * i + d];
            }
            self.factor
                .solve_in_place(&mut self.column, &mut self.workspace);
            for (k, &i) in free.nodes.iter().enumerate() {
                a[3 * i + d] = self.column[k];
            }
        }
        let m = free.constraints.len();
        for d in 0..3 {
            // λ_d = B⁻¹ (C a)_d, a_d ← a_d − Σ_p Ms⁻¹ s_p λ_pd.
            for (p, c) in free.constraints.iter().enumerate() {
                self.multipliers[p] = c
                    .nodes
                    .iter()
                    .zip(&c.weights)
                    .map(|(&n, &w)| w * a[3 * n + d])
                    .sum::<f64>();
            }
            for p in 0..m {
                let lp: f64 = (0..m)
                    .map(|q| self.projection[(p, q)] * self.multipliers[q])
                    .sum();
                lambda[3 * p + d] = lp;
            }
            for p in 0..m {
                let lp = lambda[3 * p + d];
                for (k, &i) in free.nodes.iter().enumerate() {
                    a[3 * i + d] -= self.inverse_weights[p][k] * lp;
                }
            }
        }
    }
}
