//! The static responses a reduction adds to its basis (docs/formulation.md, "The reduced
//! body"): the attachment modes of the force interfaces, and with several frames the modal
//! derivatives of the modes, the basis's second order in the slabs' own force.

use super::construction::InteriorSolve;
use super::{RigidModes, SecondOrderForce};
use crate::body::NodeSet;
use nalgebra::Vector3;

/// The attachment modes of the force interfaces `loaded` (unit forces and torques distributed
/// as the interface distributes them; inertia relief for an unsupported body), appended to
/// `vectors`.
pub(super) fn attachment_modes(
    solve: &mut InteriorSolve,
    reference: &[f64],
    lumped: &[f64],
    loaded: &[&NodeSet],
    vectors: &mut Vec<Vec<f64>>,
) {
    // 4. Attachment modes.
    let rigid_modes = solve
        .free_body()
        .then(|| RigidModes::new(reference, solve.mass(), lumped));
    for set in loaded {
        for j in 0..6 {
            let unit = Vector3::ith(j % 3, 1.0);
            let (force, torque) = if j < 3 {
                (unit, Vector3::zeros())
            } else {
                (Vector3::zeros(), unit)
            };
            let mut load = vec![0.0; solve.dof_count()];
            set.distribute(reference, &force, &torque, &mut load);
            if let Some(r) = &rigid_modes {
                r.relieve(&mut load);
            }
            vectors.push(solve.static_response(&load));
        }
    }
}

/// The static modal derivatives of the vector modes `vectors[first..]` (the fixed-interface and
/// attachment modes), appended to `vectors`: for each mode `φ` the second-order static response
/// `ψ = −K_ii⁻¹ f₂(φ)` with the boundary held, `f₂` the part of the slabs' elastic force quadratic
/// in the displacement (`second_order_force`). It holds what goes with `φ` at second order in
/// the slab model, the axial shortening of a bending shape: each slab turns with the body's
/// bending, and a basis without it strains the body along its axis when the slabs turn
/// (docs/formulation.md, "The reduced body": several frames). An unsupported
/// body gets none (its solve is shifted; a free body's slabs are not measured).
pub(super) fn modal_derivatives(
    solve: &mut InteriorSolve,
    second_order_force: &SecondOrderForce<'_>,
    first: usize,
    vectors: &mut Vec<Vec<f64>>,
) {
    if solve.free_body() {
        return;
    }
    let mut force = vec![0.0; solve.dof_count()];
    for k in first..vectors.len() {
        second_order_force(&vectors[k], &mut force);
        force.iter_mut().for_each(|f| *f = -*f);
        vectors.push(solve.static_response(&force));
    }
}
