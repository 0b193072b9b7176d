//! Generalized-α across a change of step length (docs/formulation.md, "Generalized-α across a
//! change of step"): the velocities carried over from the lag of the old step to that of the new.

use super::GeneralizedAlpha;
use crate::body::frame::{nearest_rigid_field, node};
use crate::body::Body;
use crate::solver::problem::{DynamicState, FreeNodes};
use nalgebra::Vector3;

/// Carries a state made by steps of `h` (`state.step_size`) over to steps of `h'`
/// (docs/formulation.md, "Generalized-α across a change of step"). On a smooth motion the
/// scheme's velocities lag by an amount that depends on the step, `v ≈ ẋ − c_v h² ⃛x` with
/// `c_v = β − γ/2 + 1/12` (the steady discrete rotation: `v = ẋ (1 + c_v (ωh)²)`). The free
/// nodes' velocities become
///
/// `v ← v − c_v (h'² − h²) ⃛x`,
///
/// with the jerk `⃛x` of the body's rigid motion ([`rigid_jerk`]): the lag that matters is the
/// one of the large rigid velocities, and it is the one that can be read without
/// differentiating (elastic content the step does not resolve has no such expansion). Without
/// it a spinning body's velocities kept the old lag, `c_v (ωh)²` of its rigid velocity, against
/// a support that took the new one: B3 halved from 10 ms to 5 ms at 15 s rang at 0.59 % of the
/// peak. The pseudo-accelerations' lag `(α_m − α_f) h ⃛x` is left as it is: carrying it over
/// changed B3 by 0.6 % of that error and disturbed the unresolved modes of a body ringing under
/// a step load, where `a − ẍ` is not a lag. The jerk field is affine in the position,
/// `⃛x = j_c + B (x − x_c)`, so a reduced body's coordinates take it as a field's coefficients
/// do: `Δv_k ∝ e_k j_c + B (q_k − e_k x_c)` (`e_k` the constant field's coefficients, 1 for a
/// node); without it the reduced B3 rang at 0.4 % of the peak after the error control's
/// refinement from 10 ms to 0.31 ms at 15 s.
pub(super) fn change_step(
    scheme: &GeneralizedAlpha,
    body: &Body,
    free: &FreeNodes,
    h_new: f64,
    state: &mut DynamicState,
) {
    let h = state.step_size;
    // Another iteration matrix: its contraction is measured again.
    state.iteration_error_ratio = f64::INFINITY;
    let c_v = scheme.beta - scheme.gamma / 2.0 + 1.0 / 12.0;
    let (j_c, omega, centre) = rigid_jerk(body, state);
    let scale = -c_v * (h_new * h_new - h * h);
    let unit = |i: usize| body.frame_weights.unit(i);
    for &i in &free.nodes {
        let r = node(&state.position, i) - unit(i) * centre;
        let dv = scale * (unit(i) * j_c + omega.cross(&omega.cross(&omega.cross(&r))));
        for k in 0..3 {
            state.velocity[3 * i + k] += dv[k];
        }
    }
}

/// The jerk of the body's rigid motion as a spin `ω` whose velocity and acceleration turn
/// with it: `⃛x_i = ω × a_c + ω × (ω × (ω × (x_i − x_c)))`, with `x_c`, `a_c` the weighted
/// centroid and its acceleration and `ω` the least-squares angular velocity of the nodes
/// about it (`I ω = Σ w r × (v − v_c)`, weights: the frame weights, the nodes' lumped masses;
/// directions with no inertia get none). Returns `(ω × a_c, ω, x_c)`. Exact for a steady spin
/// about a fixed axis (B3 after its spin-up) and for a free body tumbling about its centroid
/// at a constant rate; a load that jumps moves `a_c`, not `ω`.
pub(super) fn rigid_jerk(
    body: &Body,
    state: &DynamicState,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let weights = &body.frame_weights;
    if body.reduction.is_some() {
        // A reduced body's coordinates are fields' coefficients: the centroid and its
        // acceleration are the frame's linear sums, and `ω` the co-moving frame's.
        let (frame, omega_body) = weights.moving_frame(&state.position, &state.velocity);
        let omega = frame.rotation * omega_body;
        let acceleration = weights.centroid(&state.acceleration);
        return (omega.cross(&acceleration), omega, frame.origin);
    }
    let (centre, _, omega) = nearest_rigid_field(
        &weights.nodes,
        |k| weights.weights[k],
        &state.position,
        |i| node(&state.velocity, i),
    );
    let (mut total, mut acceleration) = (0.0, Vector3::zeros());
    for (&i, &w) in weights.nodes.iter().zip(&weights.weights) {
        total += w;
        acceleration += w * node(&state.acceleration, i);
    }
    if total > 0.0 {
        acceleration /= total;
    }
    (omega.cross(&acceleration), omega, centre)
}
