//! The local error estimate of a generalized-α step (docs/formulation.md, "Time error
//! control": the estimate), filtered with the step's own factor.

use super::{step_change, IterationMatrix, StepWorkspace};
use crate::body::frame::{add_node, nearest_rigid_field, node, set_node};
use crate::body::Body;
use crate::linalg::dot;
use crate::solver::problem::{DynamicState, FreeNodes, ResidualWorkspace};
use nalgebra::Matrix3;

impl IterationMatrix {
    /// The local error estimate of a converged step (docs/formulation.md, "Time error
    /// control"), in metres as a mass-weighted RMS over the body:
    ///
    /// ```text
    /// d = (β − 1/6) h² (a_{n+1} − a_n)              (free DOFs; the clamped ones are prescribed)
    /// e = (hR S̄ hRᵀ)⁻¹ c M d,   c = c_m + c_d α     (the filter)
    /// error = √(eᵀ M d / m)
    /// ```
    ///
    /// `d` is the leading term of the position error of a generalized-α step (Géradin &
    /// Cardona, *Flexible multibody dynamics*, 2001, §8.4), third order in `h`. Unfiltered it
    /// grows like `(ω h)²` times the amplitude of a mode that the step does not resolve, whose
    /// true error cannot exceed about its amplitude: the filter, one solve with the step's own
    /// factor (Hairer & Wanner's filter of Radau5's estimate, IV.8), multiplies mode `j` by
    /// `c / (c + ω_j²)`, 1 for the resolved modes and `≈ 1 / (β' ω_j² h²)` for the others.
    /// `eᵀ M d = eᵀ (M + K'/c) e ≥ eᵀ M e` is a norm of `e`, and `≤ dᵀ M d`: when the
    /// unfiltered `√(dᵀ M d / m)` is already below `enough` it is returned without the solve
    /// (a quiet step costs one product with `M` and O(N)). Allocates nothing.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn local_error(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        frame: &Matrix3<f64>,
        state: &DynamicState,
        ws: &mut StepWorkspace,
        forces: &ResidualWorkspace,
        enough: f64,
    ) -> f64 {
        let h = self.step_size;
        let coefficient = (self.scheme.beta - 1.0 / 6.0) * h * h;
        ws.error.fill(0.0);
        for &i in &free.nodes {
            for d in 3 * i..3 * i + 3 {
                ws.error[d] = coefficient
                    * (state.pseudo_acceleration[d] - ws.previous.pseudo_acceleration[d]);
            }
        }
        // The error relative to the body's rigid motion (docs/formulation.md, "Time error
        // control"): on a body without prescribed nodes the rigid field nearest to `d`; on one
        // with them the jerk of its rigid motion as a spin (`rigid_jerk`, exact for a steady
        // spin), whose error the supports take. The rigid field is affine in the position, so a
        // reduced body's coordinates take it as a field's coefficients do, `e_k t + B (q_k −
        // e_k x_c)` (`e_k` the constant field's coefficients, 1 for a node); a reduced body
        // without prescribed fields keeps `d` as it is (its nearest rigid field is not a sum
        // over nodes).
        let rigid = if !free.clamped.is_empty() {
            let (jerk, omega, centre) = step_change::rigid_jerk(body, state);
            let h3 = coefficient * h;
            Some((centre, h3 * jerk, -h3 * omega.norm_squared() * omega))
        } else if body.reduction.is_none() {
            Some(nearest_rigid_field(
                &free.nodes,
                |k| body.mass_row_sums[free.nodes[k]],
                &state.position,
                |i| node(&ws.error, i),
            ))
        } else {
            None
        };
        if let Some((centre, translation, rotation)) = rigid {
            let unit = |i: usize| body.frame_weights.unit(i);
            for &i in &free.nodes {
                let rigid = unit(i) * translation
                    + rotation.cross(&(node(&state.position, i) - unit(i) * centre));
                add_node(&mut ws.error, i, &-rigid);
            }
        }
        body.mass_times(&ws.error, &mut ws.error_mass);
        let unfiltered = (dot(&ws.error, &ws.error_mass).max(0.0) / body.total_mass).sqrt();
        if unfiltered <= enough {
            return unfiltered;
        }
        let rotation = self.node_rotation(body, frame, forces);
        let c = self.mass_coefficient;
        for (k, &i) in free.nodes.iter().enumerate() {
            let r = rotation(i).transpose() * node(&ws.error_mass, i) * c;
            set_node(&mut ws.reduced, k, &r);
        }
        self.factor
            .solve_in_place(&mut ws.reduced, &mut self.workspace);
        let rotation = self.node_rotation(body, frame, forces);
        let mut squared = 0.0;
        for (k, &i) in free.nodes.iter().enumerate() {
            let e = rotation(i) * node(&ws.reduced, k);
            squared += e.dot(&node(&ws.error_mass, i));
        }
        (squared.max(0.0) / body.total_mass).sqrt()
    }
}
