//! Motion interfaces (issue 3): a node set clamped to a driving frame given as input, the
//! constraint load as output, consistent initialization, B4.

mod common;
use common::*;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::{Matrix3, Vector3};

fn driven(settings: &[(&str, f64)]) -> Slave {
    initialized(example_body("driven_cantilever"), settings)
}

/// A root held still by a motion interface is a clamp: the same deflection as the fixed support
/// of the default body, and after settling (β = 20 ms: every mode decays at least like
/// e^{−t/β}) the constraint load balances the tip load (with `f_nl` the internal forces have no
/// net moment, so the moment balances too). The tolerance, 1e-7 of the load, sits just above the
/// round-off floor of absolute coordinates: positions of O(1 m) carry errors of ε·1 m ≈ 2e-16 m,
/// which the stiffness (≈ 2e9 N/m per node here) and c_m M (4e6 1/s² × 3 kg) turn into nodal
/// force errors of 1e-9 to 1e-7 N; measured: 4e-9 to 1.5e-8 of the load depending on the
/// summation order (the 1e-9 of issue 3 is below this floor).
#[test]
fn held_still_motion_interface_is_a_clamp_and_reports_the_reaction() {
    // A reaction to 1e-9 of 10 N needs the accelerations to 1e-9 m/s²: with c_m = 4/h² = 4e6 1/s²
    // that is a converged position to ~1e-15 m, so the iteration tolerance is tightened here.
    let settings = [
        ("solver.tolerance", 1e-15),
        ("damping.beta", 2e-2),
        ("tip.force[2]", -10.0),
        ("model.nonlinearForces", 1.0),
        // Forced: model.auto keeps f_nl off on a supported body with one frame.
        ("model.auto", 0.0),
    ];
    let mut driven = driven(&settings);
    let mut fixed = initialized_default(&settings);
    let y0 = get(&mut driven, "tip.position[2]");
    let h = 1e-3;
    for k in 0..1000 {
        driven.do_step(k as f64 * h, h).unwrap();
        fixed.do_step(k as f64 * h, h).unwrap();
    }
    let d_driven = get(&mut driven, "tip.position[2]") - y0;
    let d_fixed = get(&mut fixed, "tip.position[2]") - y0;
    assert!(
        (d_driven - d_fixed).abs() < 1e-9 * d_fixed.abs(),
        "{d_driven:e} vs {d_fixed:e}"
    );
    assert!((d_fixed + B1_TIMOSHENKO_DEFLECTION).abs() < 0.01 * B1_TIMOSHENKO_DEFLECTION);
    // The load on the tip, moved to the root's reference point (0,0,0), is (0,−10,0) and
    // (1,0,0) × (0,−10,0) = (0,0,−10) at the undeformed tip; the deformed tip lever is measured.
    let tip = vector(&mut driven, "tip.position");
    let applied_force = Vector3::new(0.0, -10.0, 0.0);
    let applied_moment = tip.cross(&applied_force);
    let force = vector(&mut driven, "root.force");
    let torque = vector(&mut driven, "root.torque");
    assert!(
        (force + applied_force).norm() < 1e-7 * 10.0,
        "root.force = {force:?}"
    );
    assert!(
        (torque + applied_moment).norm() < 1e-7 * applied_moment.norm(),
        "root.torque = {torque:?}, applied moment {applied_moment:?}"
    );
}

/// B4: the root frame turns about z at π rad/s for three turns; the tip load turns with it.
/// The tip deflection seen in the root frame stays at the clamped static value (0.5 %).
#[test]
fn b4_tip_deflection_in_the_rotating_frame_equals_the_static_value() {
    let omega = std::f64::consts::PI;
    let h: f64 = 1e-3;
    let mut s = driven(&[
        ("damping.beta", 2e-3),
        ("tip.force[2]", -10.0),
        ("root.angularVelocity[3]", omega),
    ]);
    // The static value of this mesh is the fixed-root default body's; the last turn starts
    // after the start-up transient (ζ₁ ≈ 0.1) has decayed by e^{-40}.
    let worst = b4_deviation_from_static(&mut s, h, omega);
    assert!(
        worst < 5e-3,
        "largest deviation from the static deflection: {:.3} %",
        100.0 * worst
    );
}

#[test]
fn rotation_inputs_are_orthonormalised_or_rejected() {
    let mut s = driven(&[]);
    // Slightly off (1e-5): accepted and orthonormalised.
    let mut q = Matrix3::identity();
    q[(0, 1)] = 1e-5;
    set_rotation(&mut s, "root.rotation", &q);
    s.do_step(0.0, 1e-3).unwrap();
    // Far off: an error naming the variable; the state is unchanged.
    q[(0, 1)] = 0.2;
    set_rotation(&mut s, "root.rotation", &q);
    let t = s.time();
    let e = s.do_step(t, 1e-3).unwrap_err();
    assert!(e.message.contains("root.rotation"), "{e}");
    assert_eq!(s.time(), t);
}

#[test]
fn two_motion_interfaces_that_disagree_with_a_rigid_placement_are_an_error() {
    let mut body = BodyFile::from_json(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/driven_cantilever.json"
        ))
        .unwrap(),
    )
    .unwrap();
    body.interfaces[1].kind = flexbody::model::InterfaceKind::Motion;
    let mut s = Slave::from_body(body).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    // Both at their body-file places: consistent.
    s.exit_initialization_mode().unwrap();
    s.reset();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "tip.position[2]", 0.01); // the tip 1 cm off the rigid placement
    let e = s.exit_initialization_mode().unwrap_err();
    assert!(e.message.contains("'root' and 'tip' disagree"), "{e}");
}

/// Outputs are computed in groups on their first read (docs/fmu.md, "Variables"): whatever is
/// read first, and whether the rest is read at all, every output of a state is the same number,
/// bit for bit, as when everything is read in the model description's order. The reaction of the
/// motion interface and the body's strain energy come from one residual; the tip's motion does
/// not take it.
#[test]
fn outputs_read_in_any_order_are_the_same_numbers() {
    let settings = [("tip.force[2]", -10.0), ("damping.beta", 2e-3)];
    let names = [
        "root.force[1]",
        "root.torque[3]",
        "tip.position[2]",
        "tip.angularVelocity[3]",
        "body.strainEnergy",
        "body.angularMomentum[3]",
    ];
    let orders: [&[usize]; 4] = [&[0, 1, 2, 3, 4, 5], &[2, 3], &[4, 0, 2], &[3, 5, 1]];
    let mut runs: Vec<Slave> = orders.iter().map(|_| driven(&settings)).collect();
    let h = 1e-3;
    for k in 0..40 {
        let mut reference = [f64::NAN; 6];
        for (run, order) in runs.iter_mut().zip(orders) {
            run.do_step(k as f64 * h, h).unwrap();
            for &i in order {
                let value = get(run, names[i]);
                if reference[i].is_nan() {
                    reference[i] = value;
                }
                assert_eq!(
                    value.to_bits(),
                    reference[i].to_bits(),
                    "{} at step {k}",
                    names[i]
                );
            }
        }
    }
    // The runs read different outputs: their states are still the same.
    let tip: Vec<f64> = runs.iter_mut().map(|r| get(r, "tip.position[2]")).collect();
    assert!(
        tip.iter().all(|&y| y.to_bits() == tip[0].to_bits()),
        "{tip:?}"
    );
}

/// An output that cannot be computed is an error at every read, not a panic at the second
/// (a review found the reactions read again from an empty residual): loads of 1e300 on the tip
/// are finite inputs whose reactions overflow.
#[test]
fn a_reaction_that_overflows_is_an_error_at_every_read() {
    let mut s = Slave::from_body(example_body("driven_cantilever")).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    for name in ["tip.force", "tip.torque"] {
        for k in 1..=3 {
            s.set_by_name(&format!("{name}[{k}]"), 1e300).unwrap();
        }
    }
    for name in [
        "root.force[1]",
        "root.force[1]",
        "root.torque[2]",
        "body.strainEnergy",
    ] {
        let read = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| s.get_by_name(name)));
        match read {
            Ok(Err(e)) => assert!(e.to_string().contains("not finite"), "{name}: {e}"),
            Ok(Ok(v)) => panic!("{name} read {v}"),
            Err(_) => panic!("{name}: the read panicked"),
        }
    }
}

/// In initialization mode the outputs are those of the inputs as they are: a read, an input
/// set, and a read again give what a fresh instance reads with that input (a review found the
/// first read's placement served again).
#[test]
fn outputs_in_initialization_mode_follow_the_inputs_set_after_a_read() {
    let start = |force: Option<f64>| {
        let mut s = Slave::from_body(example_body("driven_cantilever")).unwrap();
        s.setup_experiment(0.0, None, None).unwrap();
        s.enter_initialization_mode().unwrap();
        if let Some(f) = force {
            s.set_by_name("tip.force[2]", f).unwrap();
        }
        s
    };
    let mut read_first = start(None);
    let before = get(&mut read_first, "tip.acceleration[2]");
    read_first.set_by_name("tip.force[2]", -10.0).unwrap();
    let after = get(&mut read_first, "tip.acceleration[2]");
    let fresh = get(&mut start(Some(-10.0)), "tip.acceleration[2]");
    assert_eq!(after.to_bits(), fresh.to_bits(), "{before} {after} {fresh}");
    assert!(after < -1.0 && before.abs() < 1e-3, "{before} {after}");
}
