//! B2: a free-floating tumbling beam (softened to E = 2.1e8 Pa so that it deforms visibly),
//! spinning about its centre of mass with ω = (0.5, 3, 7) rad/s.

mod common;
use common::*;
use flexbody::slave::Slave;
use nalgebra::Vector3;

const E_SOFT: f64 = 2.1e8;

fn tumbling(nonlinear_forces: bool, h: f64) -> Slave {
    // Spin about the centre of mass (0.5, 0, 0): the centre of mass stays at rest.
    let w = Vector3::new(0.5, 3.0, 7.0);
    let v = -w.cross(&Vector3::new(0.5, 0.0, 0.0));
    initialized(
        example_body("tumbling"),
        &[
            ("initial.angularVelocity[1]", w.x),
            ("initial.angularVelocity[2]", w.y),
            ("initial.angularVelocity[3]", w.z),
            ("initial.velocity[1]", v.x),
            ("initial.velocity[2]", v.y),
            ("initial.velocity[3]", v.z),
            (
                "model.nonlinearForces",
                if nonlinear_forces { 1.0 } else { 0.0 },
            ),
            ("solver.stepSize", h),
            // The drift's order in h is measured with the fixed step.
            ("model.accuracy", 0.0),
            ("material.youngsModulus", E_SOFT),
        ],
    )
}

fn momenta(s: &mut Slave) -> (Vector3<f64>, Vector3<f64>) {
    let p = Vector3::from_fn(|k, _| get(s, &format!("body.linearMomentum[{}]", k + 1)));
    let l = Vector3::from_fn(|k, _| get(s, &format!("body.angularMomentum[{}]", k + 1)));
    (p, l)
}

/// Largest relative change of the angular momentum over 0.5 s at step `h`, and the largest linear
/// momentum relative to m |ω| L/2.
fn angular_momentum_drift(nonlinear_forces: bool, h: f64) -> (f64, f64) {
    let mut s = tumbling(nonlinear_forces, h);
    let (_, l0) = momenta(&mut s);
    let (mut worst_l, mut worst_p) = (0.0_f64, 0.0_f64);
    for k in 0..(0.5 / h).round() as usize {
        s.do_step(k as f64 * h, h).unwrap();
        let (p, l) = momenta(&mut s);
        worst_l = worst_l.max((l - l0).norm() / l0.norm());
        // |p| relative to the momentum scale of the rotation: m · |ω| · L/2
        // mass ρ a b L = 3.14 kg, |ω| = 7.6 rad/s, L/2 = 0.5 m
        worst_p = worst_p.max(p.norm() / (7850.0 * 0.02 * 0.02 * 7.6 * 0.5));
    }
    (worst_l, worst_p)
}

/// Linear momentum is conserved to round-off by the scheme (constant mass matrix, internal forces
/// with no net force). Angular momentum is conserved by the equations of motion (with `f_nl`
/// the internal forces have no net moment: `tests/body_internal_force.rs`), but the trapezoidal
/// rule (generalized-α with ρ∞ = 1, equilibrium at t_{n+1}) conserves it only to its own
/// truncation error: the drift must fall as h² (factor 4 per halving), which shows it is the
/// integrator's and not the model's.
#[test]
fn free_body_conserves_linear_momentum_and_angular_momentum_to_second_order() {
    let (coarse, p_coarse) = angular_momentum_drift(true, 1e-3);
    let (fine, p_fine) = angular_momentum_drift(true, 5e-4);
    assert!(
        p_coarse < 1e-12 && p_fine < 1e-12,
        "linear momentum {p_coarse:e} {p_fine:e}"
    );
    let ratio = coarse / fine;
    assert!(
        (3.6..4.4).contains(&ratio),
        "angular momentum drift {coarse:e} at h = 1e-3, {fine:e} at h = 5e-4: ratio {ratio}"
    );
}
