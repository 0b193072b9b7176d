//! A body far from the origin: its positions carry the round-off of their magnitude, not of
//! its size, and the error control must still end every step (docs/formulation.md, "The
//! iteration's tolerance"). B2 (`examples/tumbling.json`, softened to E = 2.1e8 Pa so that it
//! deforms, a tip interface) tumbles at `model.accuracy = 1e-4`, at the origin and placed
//! 100 m and 1 km away; its tip's motion relative to its body frame is the same.

mod common;
use common::*;
use flexbody::slave::Slave;
use nalgebra::{Matrix3, Vector3};

/// The tip relative to the body's frame, in it, every 10 ms up to `end`, with the solver's
/// statistics (internal steps, iterations) and whether the iteration's tolerance followed the
/// error control.
fn tumbling_tip(offset: f64, end: f64) -> (Vec<Vector3<f64>>, (u64, u64), bool) {
    let mut file = example_body("tumbling");
    let tip = r#"{ "name": "tip", "kind": "force", "nodes": { "plane": { "point": [1.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] } }, "referencePoint": [1.0, 0.0, 0.0] }"#;
    file.interfaces.push(serde_json::from_str(tip).unwrap());
    let mut s = Slave::from_body(file).unwrap();
    s.setup_experiment(0.0, Some(end), None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.accuracy", 1e-4);
    set(&mut s, "material.youngsModulus", 2.1e8);
    // Spinning about an axis through the body's point (0.5, 0, 0), placed `offset` along x.
    let w = Vector3::new(0.5, 3.0, 7.0);
    let v = -w.cross(&Vector3::new(0.5, 0.0, 0.0));
    for k in 0..3 {
        set(&mut s, &format!("initial.angularVelocity[{}]", k + 1), w[k]);
        set(&mut s, &format!("initial.velocity[{}]", k + 1), v[k]);
    }
    set(&mut s, "initial.position[1]", offset);
    s.exit_initialization_mode().unwrap();
    let local_tip = |s: &mut Slave| {
        let r = Matrix3::from_fn(|i, j| get(s, &format!("body.rotation[{}]", 3 * i + j + 1)));
        r.transpose() * (vector(s, "tip.position") - vector(s, "body.position"))
    };
    let start = local_tip(&mut s);
    let dt = 1e-2;
    let mut tips = Vec::new();
    let mut followed = false;
    for k in 0..(end / dt).round() as usize {
        s.do_step(k as f64 * dt, dt)
            .unwrap_or_else(|e| panic!("{offset} m away, the step from {}: {e:?}", k as f64 * dt));
        tips.push(local_tip(&mut s) - start);
        followed |= s
            .drain_events()
            .any(|e| e.message.contains("the iteration's tolerance follows"));
    }
    (tips, s.solver_statistics(), followed)
}

/// Over 0.2 s (the iteration's tolerance follows the allowance from 0.05 s, where B2's
/// deformation scale settles), every step ends, and the tip's motion in the body frame agrees
/// with the run at the origin within the accuracy asked: `1e-4` of its peak for each run
/// against the converged motion, so `2e-4` between them.
#[test]
fn a_body_far_from_the_origin_steps_to_the_accuracy_asked() {
    let end = 0.2;
    let (at_origin, statistics, followed) = tumbling_tip(0.0, end);
    let peak = at_origin.iter().map(|t| t.amax()).fold(0.0, f64::max);
    println!("at the origin: {statistics:?}, peak {peak:.3e} m");
    assert!(followed, "the tolerance follows the error control");
    for offset in [100.0, 1000.0] {
        let (away, statistics, followed) = tumbling_tip(offset, end);
        assert!(
            followed,
            "{offset} m away, the tolerance follows the error control"
        );
        let difference = at_origin
            .iter()
            .zip(&away)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max);
        println!(
            "{offset} m away: {statistics:?}, {:.3e} of the peak from the run at the origin",
            difference / peak
        );
        assert!(
            difference <= 2e-4 * peak,
            "{offset} m away: {difference:.3e} m from the run at the origin (peak {peak:.3e} m)"
        );
    }
}
