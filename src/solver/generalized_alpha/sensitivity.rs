//! The step Jacobian's propagation (docs/formulation.md, "The step Jacobian"): one internal step
//! of generalized-α linearised about a converged state, applied to a perturbation `δs` of the
//! state and to a seed of the inputs.
//!
//! The step solves `r(x_{n+1}) = M ẍ + f(x, ẋ) − f_ext(x) = 0` with `ẋ`, `ẍ` tied to `x` by the
//! update formulas. Linearised, with `δs_pred` the predictor of `δs_n` (the clamped nodes
//! following the seed) and `δf` the seed's load:
//!
//! ```text
//! r'(δs) = ∂r/∂x δx + ∂r/∂ẋ δẋ + M δẍ − δf = 0,     δs = δs_pred + (1, c_d, c_m) δΔ  (free nodes)
//! ```
//!
//! solved like the step itself: `δΔ ← δΔ − S⁻¹ r'`, `S = hR S̄ hRᵀ` the factor the step iterated
//! with, until the correction is below [`RELATIVE_TOLERANCE`] of the perturbation. The
//! directional derivative `r'` is the caller's (the slave takes central differences of the
//! residual itself), so the result is the derivative of the discrete step of whatever the
//! body's internal force is (one frame or slabs, `f_nl`, stiffening, damping); the iteration
//! converges as fast as the step's own (the first correction already carries all but the
//! frames' part).

use super::{
    follow_prescribed_positions, predict_free, update_pseudo_acceleration, IterationMatrix,
};
use crate::body::frame::{node, set_node};
use crate::body::Body;
use crate::error::{Error, Result};
use crate::solver::problem::{DynamicState, FreeNodes, ResidualWorkspace};
use nalgebra::Matrix3;

/// The linear iteration stops when its largest position correction is below this fraction of
/// the largest position perturbation: the derivative is then exact to about that, far below what
/// a coupling iteration can use, and above the noise of the residual's differences (about 1e-9:
/// B1's corrections stall at 5e-10 of the perturbation from the third iteration on).
pub const RELATIVE_TOLERANCE: f64 = 1e-8;

/// A linear iteration whose correction stops shrinking (by half per iteration) below this
/// fraction of the perturbation has reached the noise of the residual's differences.
pub const NOISE_FLOOR: f64 = 1e-6;

/// The linear iteration's limit: it contracts like the step's own iteration (one frame: a
/// correction or two; slabs: a few).
pub const MAX_LINEAR_ITERATIONS: usize = 50;

/// `derivative(δs, r', g')`: the residual's directional derivative along `δs` less the seed's
/// load (full `3N`), and the constraints' (one per multiplier); see [`linear_step`].
pub type ResidualDerivative<'a> = dyn FnMut(&DynamicState, &mut [f64], &mut [f64]) + 'a;

/// The vectors of [`linear_step`] besides the perturbation itself (allocated once).
pub struct SensitivityWorkspace {
    previous: DynamicState,
    /// The residual's directional derivative (full `3N`).
    derivative: Vec<f64>,
    /// The constraints' directional derivatives (one per multiplier).
    constraint_values: Vec<f64>,
    /// `δλ` before a correction (to judge the multipliers' convergence).
    multipliers: Vec<f64>,
    /// The free rows of `r'` in the nodes' frames, then `S̄⁻¹` of them.
    reduced: Vec<f64>,
}

impl SensitivityWorkspace {
    pub fn new(body: &Body, free: &FreeNodes) -> SensitivityWorkspace {
        let n3 = body.reference.len();
        SensitivityWorkspace {
            previous: DynamicState::zeros(n3, free.multiplier_count()),
            derivative: vec![0.0; n3],
            constraint_values: vec![0.0; free.multiplier_count()],
            multipliers: vec![0.0; free.multiplier_count()],
            reduced: vec![0.0; free.dof_count()],
        }
    }
}

/// One internal step of length `h` (with the factor `matrix` of `h`) applied to the perturbation
/// `ds` (positions, velocities, accelerations, pseudo-accelerations; `ds.time` is the time
/// since the communication point): `prescribe(τ, ds)` sets the clamped nodes' position
/// perturbation at the step's end `τ`, `derivative(ds, r', g')` the residual's directional
/// derivative along `ds` less the seed's load (full `3N`) and the constraints' (a multiplier's
/// worth each: the point constraints' `C δx`, the rigid sets' `h'(δx)`). `base` is the state the
/// step is linearised about, `frame` its co-moving frame; `forces` holds its slabs' frames (the
/// iteration matrix's rotations). With constraints the correction is the constrained one, and
/// `ds.multipliers` carries `δλ`. Returns the linear iterations taken. No allocation.
#[allow(clippy::too_many_arguments)]
pub fn linear_step(
    matrix: &mut IterationMatrix,
    body: &Body,
    free: &FreeNodes,
    base: &DynamicState,
    frame: &Matrix3<f64>,
    forces: &ResidualWorkspace,
    h: f64,
    prescribe: &dyn Fn(f64, &mut DynamicState),
    derivative: &mut ResidualDerivative,
    ds: &mut DynamicState,
    ws: &mut SensitivityWorkspace,
) -> Result<usize> {
    let scheme = matrix.scheme;
    ws.previous.copy_from(ds);
    predict_free(&scheme, free, h, &ws.previous, ds);
    ds.time = ws.previous.time + h;
    prescribe(ds.time, ds);
    follow_prescribed_positions(&scheme, free, h, &ws.previous, ds);
    let constrained = matrix.constraint.is_some();
    let rotation = |i: usize| node_rotation(constrained, body, frame, forces, i);
    let c_m = scheme.mass_coefficient(h);
    let c_d = scheme.damping_coefficient(h);
    let mut previous = f64::INFINITY;
    let mut reach: f64 = 0.0;
    let mut multiplier_reach: f64 = 0.0;
    for iteration in 1..=MAX_LINEAR_ITERATIONS {
        derivative(ds, &mut ws.derivative, &mut ws.constraint_values);
        for (k, &i) in free.nodes.iter().enumerate() {
            let r = rotation(i).transpose() * node(&ws.derivative, i);
            set_node(&mut ws.reduced, k, &r);
        }
        matrix
            .factor
            .solve_in_place(&mut ws.reduced, &mut matrix.workspace);
        ws.multipliers.copy_from_slice(&ds.multipliers);
        if let Some(constraint) = &mut matrix.constraint {
            constraint.correct_linear(
                &free.constraints,
                &free.rigid,
                &base.position,
                &ws.constraint_values,
                frame,
                &mut ws.reduced,
                &mut ds.multipliers,
            );
        }
        // The perturbation's size, or the largest correction so far where the answer is near
        // zero (a load the constraints take).
        reach = reach.max(ds.position.iter().fold(0.0_f64, |m, x| m.max(x.abs())));
        let scale = reach;
        let mut largest: f64 = 0.0;
        for (k, &i) in free.nodes.iter().enumerate() {
            let dx = -(rotation(i) * node(&ws.reduced, k));
            for (d, &value) in dx.iter().enumerate() {
                let j = 3 * i + d;
                ds.position[j] += value;
                ds.velocity[j] += c_d * value;
                ds.acceleration[j] += c_m * value;
                largest = largest.max(value.abs());
            }
        }
        if !largest.is_finite() {
            break;
        }
        // Converged, or stalled at the differences' noise within NOISE_FLOOR.
        let stalled = largest > 0.5 * previous && largest <= NOISE_FLOOR * scale;
        reach = reach.max(largest);
        // The multipliers' correction, against theirs (a load the constraints take is all in
        // them).
        let multiplier_change = ds
            .multipliers
            .iter()
            .zip(&ws.multipliers)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        multiplier_reach =
            multiplier_reach.max(ds.multipliers.iter().fold(0.0_f64, |m, x| m.max(x.abs())));
        let multipliers_settled = multiplier_change <= RELATIVE_TOLERANCE * multiplier_reach;
        if (largest <= RELATIVE_TOLERANCE * scale && multipliers_settled) || stalled {
            update_pseudo_acceleration(&scheme, free, &ws.previous, ds);
            return Ok(iteration);
        }
        previous = largest;
    }
    Err(Error::new(format!(
        "the linearised step (h = {h:e} s) did not converge in {MAX_LINEAR_ITERATIONS} iterations"
    )))
}

/// The frame of node `i`'s rows in the iteration matrix (`IterationMatrix::node_rotation`; the
/// lumped bodies' mass points, which have no stiffness, take the body's frame, and so do a
/// reduced body's coordinates, which belong to no patch).
fn node_rotation(
    constrained: bool,
    body: &Body,
    frame: &Matrix3<f64>,
    forces: &ResidualWorkspace,
    i: usize,
) -> Matrix3<f64> {
    let patches = body
        .patches
        .as_ref()
        .filter(|_| !constrained && body.reduction.is_none());
    match patches {
        Some(p) if i < p.node_patch.len() => forces.force_scratch.patch_rotation(p.node_patch[i]),
        _ => *frame,
    }
}
