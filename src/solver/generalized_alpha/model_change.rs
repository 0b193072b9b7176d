//! A change of the elastic force at one state (`model.auto`'s slabs put in place of the one
//! co-moving frame): the state carried over to the new force without setting the modes above
//! the lowest ringing (docs/formulation.md, "The slabs' switch").

use super::{IterationMatrix, StepWorkspace};
use crate::body::Body;
use crate::solver::problem::{DynamicState, FreeNodes, ResidualWorkspace};

/// Most corrections of [`carry_over_force_change`]: each takes a mode's remaining shift by the
/// factor `c_m / (ω² + c_m)`, so the modes well above `√c_m` are done in a few and the ones
/// near the lowest kept modes in a few dozen.
pub const MAX_CORRECTIONS: usize = 50;

/// Carries `state` over from the internal force `old_force` (flat `3N`: `f_old(x, ẋ)` of the
/// model before the change, at this state) to `body`'s current one, `f_new`: the positions of
/// the free nodes move by the static response `δ` to the force difference in every mode but
/// the lowest, so that `f_new(x + δ, ẋ) − f_old` has no part above them:
///
/// `δ ← δ − P S⁻¹ (f_new(x + δ, ẋ) − f_old)`, with the iteration matrix `S` of the next step
/// (`hR (c_m M + c_d D + K) hRᵀ`) and `P` = `remove_lowest`, which takes a field's part in the
/// lowest modes out (flat `3N`, global), until a correction is below `tolerance` (m) or after
/// [`MAX_CORRECTIONS`]. The velocities, accelerations and multipliers stay: a mode above the
/// lowest keeps its vibration about an equilibrium shifted by the two models' difference, and
/// the lowest take that difference as a step load, as the first step's residual.
///
/// The two models' forces differ most in the stiff modes: the one frame's linear strain of a
/// slab turned by `θ` against it holds a spurious `θ²/2`, an axial force `EA θ²/2`, which its
/// state balances by a stretch the slabs do not have; put in place as it is, the slabs spring
/// back from it at the stiff modes' periods. Returns the largest and the last correction (m)
/// and their number. No allocation.
///
/// Unconstrained bodies only (no pins, hinges or rigid sets): the lowest modes are those of the
/// free DOFs without the constraints, so taking them out of a correction would leave the
/// constraints (and a hinge's free turn is no mode at all).
#[allow(clippy::too_many_arguments)]
pub fn carry_over_force_change(
    body: &Body,
    free: &FreeNodes,
    matrix: &mut IterationMatrix,
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
    forces: &mut ResidualWorkspace,
    old_force: &[f64],
    remove_lowest: &dyn Fn(&mut [f64]),
    tolerance: f64,
) -> Carried {
    debug_assert!(!free.is_constrained());
    // Another internal force: the iteration's contraction is measured again.
    state.iteration_error_ratio = f64::INFINITY;
    let mut carried = Carried {
        largest: 0.0,
        last: 0.0,
        corrections: 0,
    };
    for _ in 0..MAX_CORRECTIONS {
        let kin = body.internal_force(
            &state.position,
            &state.velocity,
            forces.geometric_stiffness.as_ref(),
            &mut forces.force_scratch,
            &mut forces.internal,
        );
        for (r, old) in forces.internal.iter_mut().zip(old_force) {
            *r -= old;
        }
        // (The body has no multipliers for the plain update to set.)
        matrix.plain_update(body, free, &kin.frame.rotation, state, ws, forces, false);
        let correction = &mut forces.external;
        correction.fill(0.0);
        for (k, &i) in free.nodes.iter().enumerate() {
            correction[3 * i..3 * i + 3].copy_from_slice(&ws.update[3 * k..3 * k + 3]);
        }
        remove_lowest(correction);
        let mut change = 0.0_f64;
        for &i in &free.nodes {
            let moved = &correction[3 * i..3 * i + 3];
            for (x, dx) in state.position[3 * i..3 * i + 3].iter_mut().zip(moved) {
                *x += dx;
                change = change.max(dx.abs());
            }
        }
        carried.largest = carried.largest.max(change);
        carried.last = change;
        carried.corrections += 1;
        if change <= tolerance {
            break;
        }
    }
    carried
}

/// What [`carry_over_force_change`] did: the largest correction and the last (m), and how many.
#[derive(Debug, Clone, Copy)]
pub struct Carried {
    pub largest: f64,
    pub last: f64,
    pub corrections: usize,
}
