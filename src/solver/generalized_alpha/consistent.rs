//! Consistent accelerations for generalized-α: at initialization, and after a jump of the loads
//! (the pseudo-acceleration restarted with them).

use super::StepWorkspace;
use crate::body::Body;
use crate::error::Result;
use crate::solver::consistent_acceleration::ConsistentAcceleration;
use crate::solver::problem::{residual, DynamicState, FreeNodes, ResidualWorkspace};

/// Consistent initial acceleration on the free DOFs and multipliers:
/// `M_FF ẍ_F + Cᵀλ = (f_ext − f(x, ẋ) − M_FC ẍ_C)_F`, `C ẍ = 0`, with the clamped nodes'
/// accelerations `ẍ_C` as given in `state` ([`ConsistentAcceleration`]).
pub fn initial_acceleration(
    body: &Body,
    free: &FreeNodes,
    loads: &dyn Fn(&[f64], &mut [f64]),
    state: &mut DynamicState,
    forces: &mut ResidualWorkspace,
    mass: &mut ConsistentAcceleration,
) -> Result<()> {
    for &i in &free.nodes {
        state.acceleration[3 * i..3 * i + 3].fill(0.0);
    }
    state.multipliers.fill(0.0);
    residual(body, free, state, loads, forces);
    forces.internal.iter_mut().for_each(|r| *r = -*r);
    mass.solve(
        free,
        &state.position,
        &forces.internal,
        &mut state.acceleration,
        &mut state.multipliers,
    );
    state
        .pseudo_acceleration
        .copy_from_slice(&state.acceleration);
    Ok(())
}

/// Restarts the scheme after the external loads jumped at `state.time` (held inputs change at a
/// communication point): the accelerations and the pseudo-accelerations of the free nodes gain
/// `Δẍ` and the multipliers `Δλ` from `M_FF Δẍ_F + CᵀΔλ = Δf_ext`, `C Δẍ = 0`, with
/// `Δf_ext = new_loads(x) − old_loads(x)`. Without it the scheme starts the step from the old
/// loads' acceleration (the left limit) and a jump costs an error of order `h`, which made the
/// scheme first order under inputs that change (`tests/convergence_order.rs`). For a linear
/// system this is exact superposition: the jump's response is a fresh start from rest with
/// the consistent acceleration `M⁻¹ Δf` (initialization's `a_0 = ẍ_0`). No allocation without
/// rigid sets (`forces` and `ws` serve as scratch; with them the projection allocates, see
/// [`ConsistentAcceleration`]).
///
/// The slave does not call it: restarting at every jump of held inputs destabilised the
/// iterated coupling of two FMUs (see `Slave::do_step`); it is kept for importers' schemes that
/// want the zero-order-hold response of one FMU to second order.
pub fn restart_for_load_change(
    free: &FreeNodes,
    mass: &mut ConsistentAcceleration,
    old_loads: &dyn Fn(&[f64], &mut [f64]),
    new_loads: &dyn Fn(&[f64], &mut [f64]),
    state: &mut DynamicState,
    forces: &mut ResidualWorkspace,
    ws: &mut StepWorkspace,
) {
    forces.external.fill(0.0);
    new_loads(&state.position, &mut forces.external);
    forces.inertia.fill(0.0);
    old_loads(&state.position, &mut forces.inertia);
    for (new, old) in forces.external.iter_mut().zip(&forces.inertia) {
        *new -= old;
    }
    forces.inertia.fill(0.0);
    mass.solve(
        free,
        &state.position,
        &forces.external,
        &mut forces.inertia,
        &mut ws.multiplier_change,
    );
    for &i in &free.nodes {
        for d in 3 * i..3 * i + 3 {
            state.acceleration[d] += forces.inertia[d];
            state.pseudo_acceleration[d] += forces.inertia[d];
        }
    }
    for (l, dl) in state.multipliers.iter_mut().zip(&ws.multiplier_change) {
        *l += dl;
    }
}
