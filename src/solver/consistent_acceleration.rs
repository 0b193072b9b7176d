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
//!
//! Rigid sets (`C = Vᵀ hR_sᵀ` on their nodes, [`super::constraints::RigidConstraint`]) keep
//! `(Ms⁻¹ ⊗ I3) V` (a uniform rotation commutes with `Ms⁻¹ ⊗ I3`); with them the Schur
//! complement of all constraints is formed at each solve (the rows depend on the sets'
//! rotations), which allocates: a solve with rigid sets belongs to initialization only. The
//! constraint is `C ẍ = 0`: the sets' centripetal term `−Ċ ẋ` is left to the first step, whose
//! positions satisfy the constraint exactly.

use super::problem::FreeNodes;
use crate::body::frame::node;
use crate::error::{Error, Result};
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

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
    /// `(Ms⁻¹ ⊗ I3) V_j` for each rigid set's columns, on the free DOFs (`3 N_F` each).
    rigid_columns: Vec<Vec<f64>>,
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
        let projection = if free.rigid.is_empty() {
            b.try_inverse()
                .ok_or_else(|| Error::new("the pin constraints are redundant"))?
        } else {
            DMatrix::zeros(m, m)
        };
        let mut column = vec![0.0; nf];
        let mut rigid_columns = Vec::new();
        for set in &free.rigid {
            for j in 0..set.rows() {
                let v = set.column(j);
                let mut w = vec![0.0; 3 * nf];
                for d in 0..3 {
                    column.fill(0.0);
                    for (k, &row) in set.free_rows.iter().enumerate() {
                        column[row / 3] = v[3 * k + d];
                    }
                    factor.solve_in_place(&mut column, &mut workspace);
                    for (q, value) in column.iter().enumerate() {
                        w[3 * q + d] = *value;
                    }
                }
                rigid_columns.push(w);
            }
        }
        Ok(ConsistentAcceleration {
            factor,
            workspace,
            inverse_weights,
            projection,
            column,
            multipliers: vec![0.0; m],
            rigid_columns,
        })
    }

    /// Overwrites the free nodes' entries of `a` (flat `3N`) with `M_FF⁻¹ r_F` projected on
    /// `C a = 0` (the constrained nodes' other entries of `a`, e.g. prescribed accelerations, enter
    /// `C a`), and `lambda` (3 per constraint, then `k` per rigid set) with the multipliers. `r`
    /// and the positions `x` are flat `3N`.
    pub fn solve(
        &mut self,
        free: &FreeNodes,
        x: &[f64],
        r: &[f64],
        a: &mut [f64],
        lambda: &mut [f64],
    ) {
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
        if !free.rigid.is_empty() {
            self.project_with_rigid_sets(free, x, a, lambda);
            return;
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

    /// `a ← a − M⁻¹ Cᵀ λ`, `λ = (C M⁻¹ Cᵀ)⁺ C a` with the point constraints' and the rigid sets'
    /// rows at positions `x` (a pseudo-inverse, for rows that are dependent at this
    /// configuration). Allocates (initialization only).
    fn project_with_rigid_sets(
        &mut self,
        free: &FreeNodes,
        x: &[f64],
        a: &mut [f64],
        lambda: &mut [f64],
    ) {
        let nf = free.nodes.len();
        // The columns M⁻¹ Cᵀ on the free DOFs, global.
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for weights in &self.inverse_weights {
            for d in 0..3 {
                let mut w = vec![0.0; 3 * nf];
                for k in 0..nf {
                    w[3 * k + d] = weights[k];
                }
                columns.push(w);
            }
        }
        let rotations: Vec<Matrix3<f64>> = free.rigid.iter().map(|set| set.rotation(x)).collect();
        let mut rigid = self.rigid_columns.iter();
        for (set, r) in free.rigid.iter().zip(&rotations) {
            for _ in 0..set.rows() {
                let w = rigid.next().expect("one column per multiplier");
                let mut rotated = vec![0.0; 3 * nf];
                for k in 0..nf {
                    let v = r * node(w, k);
                    rotated[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
                }
                columns.push(rotated);
            }
        }
        // Row i of C applied to a free-DOF vector y (global).
        let apply = |i: usize, y: &dyn Fn(usize) -> Vector3<f64>| -> f64 {
            let points = 3 * free.constraints.len();
            if i < points {
                let c = &free.constraints[i / 3];
                c.free_rows
                    .iter()
                    .zip(&c.weights)
                    .map(|(&row, &w)| w * y(row / 3)[i % 3])
                    .sum()
            } else {
                let mut row = points;
                for (set, r) in free.rigid.iter().zip(&rotations) {
                    if i < row + set.rows() {
                        let rt = r.transpose();
                        let v = set.column(i - row);
                        return set
                            .free_rows
                            .iter()
                            .enumerate()
                            .map(|(k, &fr)| {
                                Vector3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2])
                                    .dot(&(rt * y(fr / 3)))
                            })
                            .sum();
                    }
                    row += set.rows();
                }
                unreachable!("row {i} beyond the constraints")
            }
        };
        let m = columns.len();
        let b = DMatrix::from_fn(m, m, |i, j| apply(i, &|k| node(&columns[j], k)));
        let b = (&b + b.transpose()) * 0.5;
        let free_a: Vec<f64> = free
            .nodes
            .iter()
            .flat_map(|&i| [a[3 * i], a[3 * i + 1], a[3 * i + 2]])
            .collect();
        let ca = DVector::from_fn(m, |i, _| apply(i, &|k| node(&free_a, k)));
        let eigen = b.symmetric_eigen();
        let largest = eigen.eigenvalues.amax();
        let inverse = eigen
            .eigenvalues
            .map(|v| if v > 1e-10 * largest { 1.0 / v } else { 0.0 });
        let l = &eigen.eigenvectors
            * DMatrix::from_diagonal(&inverse)
            * eigen.eigenvectors.transpose()
            * ca;
        lambda[..m].copy_from_slice(l.as_slice());
        for (j, column) in columns.iter().enumerate() {
            for (k, &i) in free.nodes.iter().enumerate() {
                for d in 0..3 {
                    a[3 * i + d] -= column[3 * k + d] * l[j];
                }
            }
        }
    }
}
