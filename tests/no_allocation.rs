//! The hot path: after the first step at a step size, `do_step` and reading the outputs allocate
//! nothing (docs/architecture.md, "Rules of the house"). A counting global allocator watches this test binary.

mod common;
use common::*;
use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};
use std::alloc::System;

// Counts every allocation of this test binary (the `stats_alloc` crate: no `unsafe` of ours).
#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// One test function: the counting allocator sees every thread of the binary, so the cases run
/// one after the other.
#[test]
fn do_step_does_not_allocate_after_the_first_step() {
    steps_do_not_allocate(&[("model.nonlinearForces", 1.0)]);
    steps_do_not_allocate(&[("model.nonlinearForces", 1.0), ("model.frames", 5.0)]);
    steps_do_not_allocate(&[("solver.andersonDepth", 0.0)]);
    steps_do_not_allocate(&[("model.nonlinearForces", 1.0), ("model.modes", 4.0)]);
    // A reduced body's slabs act on its coordinates, in the patch scratch.
    steps_do_not_allocate(&[("model.modes", 4.0), ("model.frames", 5.0)]);
    // Radau IIA: the real Cholesky and the complex LU solves take their workspaces.
    steps_do_not_allocate(&[("solver.integrator", 3.0)]);
    steps_do_not_allocate(&[("solver.integrator", 3.0), ("model.stiffening", 2.0)]);
    steps_do_not_allocate(&[
        ("solver.integrator", 3.0),
        ("model.nonlinearForces", 1.0),
        ("model.frames", 5.0),
    ]);
    // model.auto (the default) with both terms allowed: the indicators run every step.
    steps_do_not_allocate(&[("model.nonlinearForces", 1.0), ("model.stiffening", 2.0)]);
    pinned_radau_steps_do_not_allocate();
    reduced_stiffened_steps_do_not_allocate();
    controlled_steps_do_not_allocate();
    step_jacobians_do_not_allocate_after_the_first(&[]);
    // Stiffening on (model.auto off): its K_G is copied into the Jacobian's workspace.
    step_jacobians_do_not_allocate_after_the_first(&[
        ("model.auto", 0.0),
        ("model.stiffening", 2.0),
    ]);
}

/// The step Jacobian (`Slave::step_jacobian`) allocates its vectors on its first call; later
/// calls and the steps between them allocate nothing (a force and a motion interface's seeds,
/// on the driven cantilever turning at 1 rad/s: its steps allocated the rotation input's name
/// for an error message until this test).
fn step_jacobians_do_not_allocate_after_the_first(extra: &[(&str, f64)]) {
    let mut settings = vec![("root.angularVelocity[3]", 1.0), ("tip.force[2]", -1.0)];
    settings.extend_from_slice(extra);
    let mut s = initialized(example_body("driven_cantilever"), &settings);
    let outputs = [vr(&s, "tip.position[2]"), vr(&s, "root.torque[3]")];
    let inputs = [vr(&s, "tip.force[2]"), vr(&s, "root.angularVelocity[3]")];
    let mut jacobian = [0.0; 4];
    let h = 1e-3;
    for k in 0..3 {
        s.do_step(k as f64 * h, h).unwrap();
        s.step_jacobian(&outputs, &inputs, &mut jacobian).unwrap();
    }
    s.drain_events().for_each(drop);
    let region = Region::new(GLOBAL);
    for k in 3..10 {
        s.do_step(k as f64 * h, h).unwrap();
        s.step_jacobian(&outputs, &inputs, &mut jacobian).unwrap();
    }
    let stats = region.change();
    assert_eq!(
        (stats.allocations, stats.reallocations),
        (0, 0),
        "step Jacobians allocated: {stats:?}"
    );
}

/// The time error control (`model.accuracy`, default): once the rung has settled, a step with
/// its estimates (the filtered solve, the deformation scale) allocates nothing; a change of
/// rung is a log message (and, on a rung not seen before, a factorization).
fn controlled_steps_do_not_allocate() {
    let mut s = initialized_default(&[
        ("tip.force[2]", -10.0),
        ("damping.beta", 1e-4),
        ("model.accuracy", 1e-2),
    ]);
    let tip = vr(&s, "tip.position[2]");
    let h = 2e-3;
    // Warm-up: the step load rings the mesh; the rung settles as the damping takes the ringing.
    for k in 0..100 {
        s.do_step(k as f64 * h, h).unwrap();
    }
    s.drain_events().for_each(drop);
    let region = Region::new(GLOBAL);
    for k in 100..120 {
        s.do_step(k as f64 * h, h).unwrap();
        s.get_real(tip).unwrap();
    }
    let stats = region.change();
    assert_eq!(
        s.drain_events().count(),
        0,
        "the rung did not settle in the warm-up"
    );
    assert_eq!(
        stats.allocations + stats.reallocations,
        0,
        "allocations in 20 controlled steps: {stats:?}"
    );
}

/// Radau with a pin: the stage multipliers and both Schur complements (real and complex).
fn pinned_radau_steps_do_not_allocate() {
    let body = flexbody::model::BodyFile::from_json(
        r#"{
  "name": "pendulum",
  "mesh": { "beam": { "length": 1.0, "width": 0.02, "height": 0.02, "divisions": [10, 1, 1], "element": "hex20" } },
  "material": { "youngsModulus": 2.1e11, "poissonRatio": 0.3, "density": 7850.0 },
  "interfaces": [
    { "name": "pivot", "kind": "pin", "nodes": { "plane": { "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] } } }
  ],
  "solver": { "integrator": "radauIIA" }
}"#,
    )
    .unwrap();
    let mut s = initialized(body, &[("gravity[2]", -9.81)]);
    let h = 1e-3;
    let reaction = vr(&s, "pivot.force[2]");
    s.do_step(0.0, h).unwrap();
    let region = Region::new(GLOBAL);
    for k in 1..21 {
        s.do_step(k as f64 * h, h).unwrap();
        s.get_real(reaction).unwrap();
    }
    let stats = region.change();
    assert_eq!(
        stats.allocations + stats.reallocations,
        0,
        "allocations in 20 pinned Radau steps: {stats:?}"
    );
}

/// Steps of the default body with damping, gravity, a tip load and `settings`.
fn steps_do_not_allocate(settings: &[(&str, f64)]) {
    let mut all = vec![
        ("damping.alpha", 1.0),
        ("damping.beta", 1e-4),
        ("gravity[3]", -9.81),
        ("tip.force[2]", -10.0),
        // The fixed internal step: the steps alternate between two communication step sizes
        // on one internal step size (the error control's rungs are tested in
        // tests/time_error_control.rs).
        ("model.accuracy", 0.0),
    ];
    all.extend_from_slice(settings);
    let mut s = initialized_default(&all);
    let names: Vec<u32> = s
        .variables()
        .iter()
        .filter(|v| v.causality == flexbody::model::Causality::Output)
        .map(|v| v.value_reference)
        .collect();
    let force_x = vr(&s, "tip.force[1]");
    let tip_x = vr(&s, "tip.position[1]");
    let h = 1e-3;
    // First step at this communication step size (factorization allowed), then a step split into
    // two internal steps (another factorization allowed).
    s.do_step(0.0, h).unwrap();
    s.do_step(h, 2.0 * h).unwrap();
    s.drain_events().for_each(drop);
    // model.auto's decisions are log messages (formatted: one string each, plus its growth);
    // they happen when a term is switched, not every step.
    let mut decisions = 0;
    let region = Region::new(GLOBAL);
    let mut t = 3.0 * h;
    for k in 0..20 {
        let big = if k % 2 == 0 { h } else { 2.0 * h };
        s.do_step(t, big).unwrap();
        t += big;
        s.set_real(force_x, k as f64).unwrap();
        // Force inputs extrapolated over the step (fmi2SetRealInputDerivatives).
        s.set_real_input_derivatives(&[force_x, force_x], &[1, 2], &[k as f64, -2.0 * k as f64])
            .unwrap();
        s.get_real_output_derivative(tip_x, 1).unwrap();
        s.get_real_output_derivative(tip_x, 2).unwrap();
        for &vr in &names {
            s.get_real(vr).unwrap();
        }
        decisions += s
            .drain_events()
            .filter(|e| e.message.starts_with("model.auto: at t"))
            .count();
    }
    let stats = region.change();
    assert!(
        stats.allocations + stats.reallocations <= 2 * decisions,
        "allocations in 20 steps with {settings:?}: {stats:?}, {decisions} decisions logged"
    );
}

/// A reduced body's inertial stiffening (B3: its prestress from the hub's driving motion) sums
/// its unit cases into `K_G` in place; forced at the fixed step, and with the defaults, where
/// `model.auto` decides it every step (on from about 2.45 s) and the error control runs.
fn reduced_stiffened_steps_do_not_allocate() {
    let forced = [
        ("model.modes", 4.0),
        ("model.stiffening", 2.0),
        ("model.auto", 0.0),
        ("model.accuracy", 0.0),
    ];
    for (settings, warm_up) in [(&forced[..], 3), (&[("model.modes", -1.0)][..], 260)] {
        let mut s = initialized(example_body("hub_beam"), settings);
        let drive = common::b3::HubDrive::new(&s);
        let h = 1e-2;
        for k in 0..warm_up {
            drive.step(&mut s, k as f64 * h, h).unwrap();
        }
        let log: Vec<String> = s.drain_events().map(|e| e.message).collect();
        if warm_up > 3 {
            assert!(
                log.iter().any(|m| m.contains("switched on")),
                "the stiffening is on before the steps counted: {log:?}"
            );
        }
        let region = Region::new(GLOBAL);
        for k in warm_up..warm_up + 20 {
            drive.step(&mut s, k as f64 * h, h).unwrap();
        }
        let stats = region.change();
        assert!(
            stats.allocations + stats.reallocations == 0,
            "allocations in 20 steps of the reduced B3 with stiffening, {settings:?}: {stats:?}"
        );
    }
}
