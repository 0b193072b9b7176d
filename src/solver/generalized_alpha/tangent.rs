//! Newton's iteration matrix of the full formulation (`model.formulation = full`), refactorised
//! at every iteration (docs/formulation.md, "The full formulation").

use crate::body::Body;
use crate::error::{Error, Result};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::SymmetricCsr;
use crate::solver::problem::FreeNodes;

/// Newton's iteration matrix of the full formulation, `S = c_m' M + c_k K_T(x)` on the free DOFs
/// (`c_m' = c_m + c_d α`, `c_k = 1 + c_d β`: the damping enters with the linear `K`'s
/// coefficients), reassembled from the tangent `K_T` at every iteration.
pub struct TangentMatrix {
    tangent: SymmetricCsr,
    iteration: SymmetricCsr,
    /// For each entry of `iteration`: its index in `tangent` and in `FreeNodes::mass` (or
    /// `usize::MAX` where `M` has none).
    tangent_index: Vec<usize>,
    mass_index: Vec<usize>,
    mass_coefficient: f64,
    stiffness_coefficient: f64,
}

impl TangentMatrix {
    pub(super) fn new(
        body: &Body,
        free: &FreeNodes,
        pattern: SymmetricCsr,
        mass_coefficient: f64,
        stiffness_coefficient: f64,
    ) -> TangentMatrix {
        let full = body.full.as_ref().expect("the full formulation");
        let tangent = full.tangent_pattern();
        let dofs = free.dofs();
        let find = |m: &SymmetricCsr, row: usize, col: usize| {
            let range = m.row_ptr[row]..m.row_ptr[row + 1];
            m.col_idx[range.clone()]
                .binary_search(&col)
                .map(|k| range.start + k)
                .unwrap_or(usize::MAX)
        };
        let mut tangent_index = Vec::with_capacity(pattern.nnz());
        let mut mass_index = Vec::with_capacity(pattern.nnz());
        for row in 0..pattern.n {
            for k in pattern.row_ptr[row]..pattern.row_ptr[row + 1] {
                let col = pattern.col_idx[k];
                tangent_index.push(find(&tangent, dofs[row], dofs[col]));
                mass_index.push(find(&free.mass, row, col));
            }
        }
        TangentMatrix {
            tangent,
            iteration: pattern,
            tangent_index,
            mass_index,
            mass_coefficient,
            stiffness_coefficient,
        }
    }

    /// Assembles `S` at positions `x` and refactorises `factor` numerically (symbolic reused).
    pub(super) fn refactor(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        x: &[f64],
        factor: &mut SparseCholesky,
    ) -> Result<()> {
        let full = body.full.as_ref().expect("the full formulation");
        full.tangent_stiffness(x, &mut self.tangent);
        self.fill(free);
        if factor.refactor(&self.iteration).is_ok() {
            return Ok(());
        }
        // An iterate far from equilibrium (e.g. the first one after a step load) can make the
        // St. Venant–Kirchhoff tangent indefinite: this iteration uses the linear K instead
        // (a modified-Newton step); the next one tries the tangent again.
        self.tangent
            .values
            .copy_from_slice(&body.stiffness_matrix.values);
        self.fill(free);
        factor.refactor(&self.iteration).map_err(|e| {
            Error::discard(format!(
                "the iteration matrix of the full formulation is not positive definite ({})",
                e.message
            ))
        })
    }

    /// `S = c_m' M + c_k K_T` on the free DOFs from the current `tangent`.
    fn fill(&mut self, free: &FreeNodes) {
        for (k, value) in self.iteration.values.iter_mut().enumerate() {
            let t = self.tangent_index[k];
            let m = self.mass_index[k];
            *value = self.stiffness_coefficient
                * if t == usize::MAX {
                    0.0
                } else {
                    self.tangent.values[t]
                }
                + self.mass_coefficient
                    * if m == usize::MAX {
                        0.0
                    } else {
                        free.mass.values[m]
                    };
        }
    }
}
