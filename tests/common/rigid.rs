//! Bodies and measures shared by the rigid-attachment tests (`rigid_attachment.rs` on the mesh
//! body, `reduced_rigid_attachment.rs` on the reduced body).

use super::*;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::Vector3;

pub fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The largest distance of a node of `set` at `x` from the best rigid motion of the set's
/// reference positions (least squares, equal weights).
pub fn distance_from_rigid(reference: &[f64], x: &[f64], set: &[usize]) -> f64 {
    let p = |v: &[f64], i: usize| Vector3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    let n = set.len() as f64;
    let c0 = set.iter().map(|&i| p(reference, i)).sum::<Vector3<f64>>() / n;
    let c = set.iter().map(|&i| p(x, i)).sum::<Vector3<f64>>() / n;
    let a = set.iter().fold(nalgebra::Matrix3::zeros(), |a, &i| {
        a + (p(x, i) - c) * (p(reference, i) - c0).transpose()
    });
    let r = flexbody::body::frame::nearest_rotation(&a);
    set.iter()
        .map(|&i| (p(x, i) - c - r * (p(reference, i) - c0)).norm())
        .fold(0.0, f64::max)
}

/// The tumbling beam of B2 (free, no supports) with a lumped hub on a rigid face at x = 0.
pub fn free_beam_with_hub(hub: bool) -> BodyFile {
    let hub = if hub {
        r#", "rigid": true, "mass": 2.5, "centerOfMass": [-0.05, 0.01, 0.0],
        "inertia": [[0.02, 0.001, 0.0], [0.001, 0.03, -0.002], [0.0, -0.002, 0.025]]"#
    } else {
        ""
    };
    BodyFile::from_json(&format!(
        r#"{{
  "name": "hub",
  "mesh": {{ "beam": {{ "length": 1.0, "width": 0.02, "height": 0.02, "divisions": [10, 1, 1], "element": "hex20" }} }},
  "material": {{ "youngsModulus": 2.1e11, "poissonRatio": 0.3, "density": 7850.0 }},
  "interfaces": [
    {{ "name": "hub", "kind": "force", "nodes": {{ "plane": {{ "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] }} }}, "referencePoint": [0.0, 0.0, 0.0]{hub} }}
  ],
  "solver": {{ "stepSize": 1e-3, "rhoInf": 1.0, "tolerance": 1e-12, "maxIterations": 50 }}
}}"#
    ))
    .unwrap()
}

pub fn lumped_hub_inertia(settings: &[(&str, f64)]) {
    let omega = Vector3::new(0.3, -1.2, 2.0);
    let mut spin = vec![
        ("initial.angularVelocity[1]", omega.x),
        ("initial.angularVelocity[2]", omega.y),
        ("initial.angularVelocity[3]", omega.z),
    ];
    spin.extend_from_slice(settings);
    let mut with = initialized(free_beam_with_hub(true), &spin);
    let mut without = initialized(free_beam_with_hub(false), &spin);
    let (m, c) = (2.5, Vector3::new(-0.05, 0.01, 0.0));
    let inertia = nalgebra::Matrix3::new(0.02, 0.001, 0.0, 0.001, 0.03, -0.002, 0.0, -0.002, 0.025);
    let energy = get(&mut with, "body.kineticEnergy") - get(&mut without, "body.kineticEnergy");
    let expected = 0.5 * omega.dot(&(inertia * omega));
    let momentum =
        vector(&mut with, "body.linearMomentum") - vector(&mut without, "body.linearMomentum");
    println!("ΔT {energy:.15e} J against {expected:.15e} J; ΔP {momentum:?}");
    assert!(
        (energy - expected).abs() < 1e-12 * expected,
        "{energy} J against {expected} J"
    );
    assert!((momentum - m * omega.cross(&c)).norm() < 1e-12 * m * omega.norm());
}

/// `1 + cos β cosh β + α β (cos β sinh β − sin β cosh β) − κ β³ (cosh β sin β + sinh β cos β)
/// + α κ β⁴ (1 − cos β cosh β) = 0`: the frequency equation of an Euler–Bernoulli cantilever
/// with a tip mass `α ρAL` and rotary inertia `κ ρAL³` (`ω = β² √(EI / ρAL⁴)`); its lowest root
/// by bisection (checked against a shooting solution of `W'''' = β⁴ W` with the tip's shear and
/// moment conditions: 1.24792 for `α = 1, κ = 0`, 1.87510 without a tip body).
pub fn tip_mass_root(alpha: f64, kappa: f64) -> f64 {
    let f = |b: f64| {
        let (c, ch, s, sh) = (b.cos(), b.cosh(), b.sin(), b.sinh());
        1.0 + c * ch + alpha * b * (c * sh - s * ch) - kappa * b.powi(3) * (ch * s + sh * c)
            + alpha * kappa * b.powi(4) * (1.0 - c * ch)
    };
    let (mut lo, mut hi) = (0.1, 1.875104068711961);
    let f_lo = f(lo);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) > 0.0) == (f_lo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// B1 (`examples/cantilever.json`, `ρ∞ = 1`) with a tip body of its own mass (`α = 1`) and
/// rotary inertia `κ = 0.01` (radius of gyration 0.1 m) on its rigid tip face.
pub fn cantilever_with_tip_body() -> BodyFile {
    let (a, l, rho): (f64, f64, f64) = (0.02, 1.0, 7850.0);
    let rho_a = rho * a * a;
    let (mass, j) = (TIP_ALPHA * rho_a * l, TIP_KAPPA * rho_a * l.powi(3));
    let json = std::fs::read_to_string(format!("{}/examples/cantilever.json", env!("CARGO_MANIFEST_DIR")))
        .unwrap()
        .replace(
            r#""referencePoint": [1.0, 0.0, 0.0] }"#,
            &format!(
                r#""referencePoint": [1.0, 0.0, 0.0], "rigid": true, "mass": {mass}, "inertia": [[{j}, 0, 0], [0, {j}, 0], [0, 0, {j}]] }}"#
            ),
        )
        .replace(r#""rhoInf": 0.9"#, r#""rhoInf": 1.0"#);
    assert!(json.contains(r#""mass""#));
    BodyFile::from_json(&json).unwrap()
}

pub const TIP_ALPHA: f64 = 1.0;

pub const TIP_KAPPA: f64 = 0.01;

/// The Euler–Bernoulli period of [`cantilever_with_tip_body`] (s), with the tip body's mass
/// `alpha` and rotary inertia `kappa` in units of the beam's.
pub fn tip_body_period(alpha: f64, kappa: f64) -> f64 {
    let (e, a, l, rho): (f64, f64, f64, f64) = (2.1e11, 0.02, 1.0, 7850.0);
    let (ei, rho_a) = (e * a.powi(4) / 12.0, rho * a * a);
    let beta = tip_mass_root(alpha, kappa);
    2.0 * std::f64::consts::PI / (beta * beta * (ei / (rho_a * l.powi(4))).sqrt())
}

/// The first natural period of `body` (s) with `settings`, measured from the free vibration of
/// its tip after a 1 N step load (mean period between upward crossings of the mid-line over
/// seven periods, 256 steps per period of `expected`, s); the number of periods measured.
pub fn measured_period(body: BodyFile, settings: &[(&str, f64)], expected: f64) -> (f64, usize) {
    let h = expected / 256.0;
    let mut s = initialized(body, settings);
    set(&mut s, "tip.force[2]", -1.0);
    let steps = (8.5 * expected / h) as usize;
    let y: Vec<f64> = (0..steps)
        .map(|k| {
            s.do_step(k as f64 * h, h).unwrap();
            get(&mut s, "tip.position[2]")
        })
        .collect();
    let (lo, hi) = y
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let mid = 0.5 * (lo + hi);
    let crossings: Vec<f64> = (1..steps)
        .filter(|&k| y[k - 1] < mid && y[k] >= mid)
        .map(|k| (k as f64 + (mid - y[k - 1]) / (y[k] - y[k - 1])) * h)
        .collect();
    let periods = crossings.len() - 1;
    (
        (crossings[periods] - crossings[0]) / periods as f64,
        periods,
    )
}

/// The controlled arm of `examples/controlled_arm.json` (its hub on the hinge face) with a beam
/// `stiffer` times stiffer.
pub fn arm_with_hub_on_the_hinge_face(stiffer: f64) -> BodyFile {
    let json = std::fs::read_to_string(format!(
        "{}/examples/controlled_arm.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace(
        r#""youngsModulus": 1.68e9"#,
        &format!(r#""youngsModulus": {}"#, 1.68e9 * stiffer),
    );
    BodyFile::from_json(&json).unwrap()
}

pub fn hinge_on_a_rigid_set(settings: &[(&str, f64)]) {
    // The torque is set in initialization mode, so that the initial acceleration carries it (a
    // jump at the first step would cost generalized-α (1 − γ) h of the acceleration's time: 0.45 %).
    let (torque, h) = (100.0, 5e-3);
    let mut with_torque = vec![("damping.beta", 2e-3), ("hub.torque[3]", torque)];
    with_torque.extend_from_slice(settings);
    let mut s = initialized(arm_with_hub_on_the_hinge_face(1e4), &with_torque);
    for k in 0..100 {
        s.do_step(k as f64 * h, h).unwrap();
    }
    let r = |s: &mut Slave| {
        nalgebra::Matrix3::from_fn(|i, j| get(s, &format!("hub.rotation[{}]", 3 * i + j + 1)))
    };
    let q = r(&mut s);
    let angle = q[(1, 0)].atan2(q[(0, 0)]);
    let expected = 0.5 * torque / 500.0 * 0.5_f64.powi(2);
    println!(
        "angle {angle:.6e} rad against {expected:.6e} rad; tilt {:.3e}",
        q[(2, 2)] - 1.0
    );
    assert!(
        (angle - expected).abs() < 5e-3 * expected,
        "{angle} rad against {expected} rad"
    );
    // Out of the plane: the bearing carries the moment of a load along z.
    let mut damped = vec![("damping.beta", 2e-3)];
    damped.extend_from_slice(settings);
    let mut s = initialized(arm_with_hub_on_the_hinge_face(1e4), &damped);
    set(&mut s, "tip.force[3]", 1.0);
    for k in 0..200 {
        s.do_step(k as f64 * h, h).unwrap();
    }
    let moment = vector(&mut s, "bearing.torque");
    let q = r(&mut s);
    println!(
        "bearing moment {moment:?}; hub rotation about x, y: {:.3e} {:.3e}",
        q[(2, 1)],
        q[(0, 2)]
    );
    assert!(
        (moment.y - 10.0).abs() < 0.01 * 10.0 && moment.x.abs() < 1e-3 && moment.z.abs() < 1e-3,
        "{moment:?}"
    );
    assert!(q[(2, 1)].abs() < 1e-9 && q[(0, 2)].abs() < 1e-9);
}

pub fn saved_arm_continues(settings: &[(&str, f64)]) {
    let arm = || example_body("controlled_arm");
    let mut loaded = vec![("hub.torque[3]", 50.0)];
    loaded.extend_from_slice(settings);
    let mut s = initialized(arm(), &loaded);
    let h = 0.01;
    for k in 0..20 {
        s.do_step(k as f64 * h, h).unwrap();
    }
    let saved = s.get_state();
    let mut bytes = Vec::new();
    saved.write_bytes(&mut bytes);
    let run_on = |s: &mut Slave| -> Vec<f64> {
        (20..40)
            .flat_map(|k| {
                s.do_step(k as f64 * h, h).unwrap();
                let tip = vector(s, "tip.position");
                [
                    tip.x,
                    tip.y,
                    get(s, "bearing.force[1]"),
                    get(s, "bearing.torque[3]"),
                ]
            })
            .collect()
    };
    let expected = run_on(&mut s);
    let mut fresh = initialized(arm(), settings);
    let restored = fresh.state_from_bytes(&bytes).unwrap();
    fresh.set_state(&restored).unwrap();
    assert_eq!(run_on(&mut fresh), expected);
}
