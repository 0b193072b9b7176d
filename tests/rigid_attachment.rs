//! Rigid attachments (issue 19, item 1): `"rigid": true` makes an interface's node set move as
//! one rigid body, exactly, through Lagrange multipliers (docs/formulation.md, "Rigid
//! attachments").

mod common;
use common::rigid::*;
use common::*;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::Vector3;

/// B1's cantilever (1 m × 20 mm × 20 mm, hex20, clamped at x = 0) whose last `block` metres carry
/// the force interface `tip`: rigid (`stiffness = None`) or a material region of Young's modulus
/// `stiffness` (Pa) with the tip interface on its end face.
fn cantilever_with_block(block: f64, stiffness: Option<f64>) -> BodyFile {
    let start = 1.0 - block;
    let (tip_nodes, rigid, regions) = match stiffness {
        None => (
            format!(r#"{{ "box": {{ "min": [{start}, -1.0, -1.0], "max": [1.0, 1.0, 1.0] }} }}"#),
            r#", "rigid": true"#,
            String::new(),
        ),
        Some(e) => (
            r#"{ "plane": { "point": [1.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] } }"#.to_string(),
            "",
            format!(
                r#""regions": [ {{ "name": "block", "elements": {{ "box": {{ "min": [{start}, -1.0, -1.0], "max": [1.0, 1.0, 1.0] }} }}, "youngsModulus": {e} }} ],"#
            ),
        ),
    };
    BodyFile::from_json(&format!(
        r#"{{
  "name": "rigid-block",
  "mesh": {{ "beam": {{ "length": 1.0, "width": 0.02, "height": 0.02, "divisions": [20, 2, 2], "element": "hex20" }} }},
  "material": {{ "youngsModulus": 2.1e11, "poissonRatio": 0.3, "density": 7850.0 }},
  {regions}
  "interfaces": [
    {{ "name": "root", "kind": "fixed", "nodes": {{ "plane": {{ "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] }} }} }},
    {{ "name": "tip", "kind": "force", "nodes": {tip_nodes}, "referencePoint": [1.0, 0.0, 0.0]{rigid} }}
  ],
  "solver": {{ "stepSize": 1e-4, "rhoInf": 0.9, "tolerance": 1e-12, "maxIterations": 50 }},
  "model": {{ "nonlinearForces": false }}
}}"#
    ))
    .unwrap()
}

/// The tip's transverse displacement every step over `steps` steps of `h` under a 10 N step
/// load at the tip.
fn tip_history(body: BodyFile, h: f64, steps: usize) -> Vec<f64> {
    // The same model for the rigid and the stiff block: model.auto would take the linear body
    // for the stiff ones (held by a fixed support) and not for the rigid one (its set's
    // constraint is geometrically exact), and the two models differ at second order in the
    // rotation (3e-12 m here), the size of the difference measured at r = 1e3.
    let mut s = initialized(body, &[("model.auto", 0.0)]);
    set(&mut s, "tip.force[2]", -0.01);
    (0..steps)
        .map(|k| {
            s.do_step(k as f64 * h, h).unwrap();
            get(&mut s, "tip.position[2]")
        })
        .collect()
}

/// A rigid block is the limit of a stiff one: a region `r` times stiffer than the beam deforms
/// by `1/r` of what the beam's compliance puts on it, so the stiff block's tip motion approaches
/// the rigid block's at first order in `1/r`. Over the first 20 ms of a 0.01 N step load at the
/// tip (a quarter of the first period; small, so that second-order effects of the rotation stay
/// below the iteration's tolerance). Measured: 2.6e-11 m at `r` = 1e2, 2.1e-12 m at 1e3 (1.2e-6
/// of the peak); at 1e4 the difference is the iteration's tolerance (1e-12 × 1 m). Under 10 N
/// the two differ by 3.1e-8 and 7.0e-9 m (4e-6 of the peak).
#[test]
fn a_rigid_block_is_the_limit_of_a_stiff_one() {
    let (h, steps, block) = (1e-4, 200, 0.1);
    let rigid = tip_history(cantilever_with_block(block, None), h, steps);
    let stiff2 = tip_history(cantilever_with_block(block, Some(2.1e13)), h, steps);
    let stiff3 = tip_history(cantilever_with_block(block, Some(2.1e14)), h, steps);
    let peak = rigid.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let (d2, d3) = (
        largest_difference(&rigid, &stiff2),
        largest_difference(&rigid, &stiff3),
    );
    println!("peak {peak:.4e} m; rigid − stiff: r = 1e2 {d2:.3e} m, r = 1e3 {d3:.3e} m");
    assert!(peak > 1e-6, "the tip moves: {peak:e} m");
    assert!(d3 < 0.2 * d2, "first order in 1/r: {d2:e} → {d3:e}");
    assert!(d3 < 1e-5 * peak, "{d3:e} m against the peak {peak:e} m");
}

/// The pinned pendulum of `pin_support.rs` with its pivot face rigid, released 1 rad from
/// hanging: the face keeps its shape through the swing (every node within 1e-9 m of the rigid
/// motion of the set), and the swing is the physical pendulum's (the first half-period of the
/// large-amplitude pendulum, `T/2 (1 + θ₀²/16 + 11 θ₀⁴/3072)`, within 0.5 %).
#[test]
fn a_rigid_pivot_face_keeps_its_shape_through_a_large_swing() {
    let json = pendulum_json(
        r#"{ "stepSize": 1e-3, "rhoInf": 0.9, "tolerance": 1e-10, "maxIterations": 25 }"#,
    )
    .replace(r#""kind": "pin","#, r#""kind": "pin", "rigid": true,"#);
    let mut s = Slave::from_body(BodyFile::from_json(&json).unwrap()).unwrap();
    let (g, theta0) = (9.81, 1.0_f64);
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "gravity[1]", g * theta0.cos());
    set(&mut s, "gravity[2]", g * theta0.sin());
    s.exit_initialization_mode().unwrap();
    let face: Vec<usize> = {
        let body = s.body().unwrap();
        (0..body.node_count())
            .filter(|&i| body.reference[3 * i].abs() < 1e-12)
            .collect()
    };
    let (l, a) = (1.0, 0.02);
    let period = 2.0 * std::f64::consts::PI * ((l * l / 3.0 + a * a / 12.0) / (g * l / 2.0)).sqrt();
    let half = 0.5 * period * (1.0 + theta0.powi(2) / 16.0 + 11.0 * theta0.powi(4) / 3072.0);
    let h = 1e-3;
    let mut worst_shape: f64 = 0.0;
    let mut previous = 0.0;
    let mut crossing = None;
    for k in 0..(0.75 * half / h) as usize {
        s.do_step(k as f64 * h, h).unwrap();
        let tip = vector(&mut s, "tip.position");
        let angle = tip.y.atan2(tip.x) - theta0;
        if k > 0 && crossing.is_none() && previous < 0.0 && angle >= 0.0 {
            crossing = Some((k as f64 + -previous / (angle - previous)) * h);
        }
        previous = angle;
        let body = s.body().unwrap();
        let x = &s.dynamic_state().unwrap().position;
        worst_shape = worst_shape.max(distance_from_rigid(&body.reference, x, &face));
    }
    println!(
        "worst shape error {worst_shape:.3e} m; crossing {crossing:?} s, half period {half} s"
    );
    assert!(worst_shape < 1e-9, "the face deformed by {worst_shape:e} m");
    // The beam starts θ₀ from hanging and hangs straight a quarter of the large-amplitude
    // period later.
    let t = crossing.expect("the pendulum swings through its centre");
    assert!(
        (t - 0.5 * half).abs() < 5e-3 * half,
        "{t} s against {} s",
        0.5 * half
    );
}

/// A lumped hub's inertia adds to the body's exactly: the body placed spinning at `ω` about
/// the body file's origin has the kinetic energy and linear momentum of the beam plus
/// `½ ωᵀ I_O ω` and `m ω × x_c` of the hub (`I_O` its inertia about the origin, which is the
/// hub's reference point here): its six mass points carry its mass, centre and inertia.
#[test]
fn a_lumped_hub_adds_its_inertia_exactly() {
    lumped_hub_inertia(&[]);
}

/// B1 with a tip body of its own mass (`α = 1`) and rotary inertia `κ = 0.01` (radius of
/// gyration 0.1 m) on its rigid tip face: the first natural period is the Euler–Bernoulli
/// beam's with a tip mass and rotary inertia within 0.5 %. Measured from the free vibration after
/// a 1 N step load (`ρ∞ = 1`, 256 steps per period: the scheme's period error is 5e-5): 0.32 %
/// short; bare B1 measured the same way is 0.36 % short of its Euler–Bernoulli period (the hex20
/// mesh and its clamped root face are a little stiff). Without the rotary inertia the analytic
/// period would be 0.88 % shorter, without the tip mass 2.3 times shorter.
#[test]
fn a_cantilever_with_a_rigid_tip_mass_has_the_analytic_frequency() {
    let period = tip_body_period(TIP_ALPHA, TIP_KAPPA);
    let (measured, periods) = measured_period(cantilever_with_tip_body(), &[], period);
    println!(
        "period {period:.6e} s (α = 0: {:.6e} s, κ = 0: {:.6e} s); measured {measured:.6e} s over {periods} periods ({:+.3} %)",
        tip_body_period(0.0, 0.0),
        tip_body_period(TIP_ALPHA, 0.0),
        100.0 * (measured / period - 1.0)
    );
    assert!(periods >= 7, "{periods} periods");
    assert!(
        (measured - period).abs() < 5e-3 * period,
        "{measured} s against {period} s"
    );
}

/// A hinge on a rigid set holds the set's centroid and locks its rotation to the axis (two
/// rows, not the two half-centroids, which would hold the rigid distance between them twice).
/// The arm made 10⁴ times stiffer (nearly rigid: first frequency about 380 rad/s) under a hub
/// torque of 100 N m spins up as one rigid body about the hinge, `θ = ½ (τ / J) t²` with
/// `J = J_hub + ρA L³/3 = 500 kg m²`, within 1e-4 at 0.5 s (measured 2e-5; 100 times stiffer
/// the hub leads by the root's bending, 0.4 %); a 1 N tip load along z (out of the hinge's plane)
/// is carried by the bearing's moment, `bearing.torque[2] = F L` after a damped second within
/// 1 %, while the hub turns about no other axis than z.
#[test]
fn a_hinge_on_a_rigid_set_locks_it_to_its_axis() {
    hinge_on_a_rigid_set(&[]);
}

/// The driven cantilever (root clamped to the motion interface `root`) with or without a lumped
/// hub on its root: 2 kg, centre 0.05 m behind the root face, inertia about the root point.
fn driven_with_hub(hub: bool) -> BodyFile {
    let json = std::fs::read_to_string(format!(
        "{}/examples/driven_cantilever.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    if !hub {
        return BodyFile::from_json(&json).unwrap();
    }
    BodyFile::from_json(&json.replace(
        r#""referencePoint": [0.0, 0.0, 0.0] }"#,
        r#""referencePoint": [0.0, 0.0, 0.0], "mass": 2.0, "centerOfMass": [-0.05, 0.0, 0.0], "inertia": [[0.01, 0, 0], [0, 0.015, 0], [0, 0, 0.015]] }"#,
    ))
    .unwrap()
}

/// A lumped hub on a motion interface is part of what the driving frame carries: turned at a
/// steady ω about z, the frame's load on the body gains the hub's centripetal force
/// `m a_c = −m ω² R d` (`d` the centre's offset from the root point) and no torque (`ω` is along
/// a principal axis, so `ω × I ω = 0`, and the moment `R d × m a_c` of the force about the root
/// point vanishes). The clamped mass points' accelerations come from the scheme's update
/// formulas, whose steady rotation is exact to `(ωh)²` = 4e-6 here. Measured: 2e-6 of the force.
#[test]
fn a_hub_on_a_motion_interface_loads_the_driving_frame_with_its_inertia() {
    let (omega, h) = (2.0_f64, 1e-3);
    let spin = [("initial.angularVelocity[3]", omega)];
    let mut loads = Vec::new();
    for hub in [false, true] {
        let mut s = initialized(driven_with_hub(hub), &spin);
        set(&mut s, "root.angularVelocity[3]", omega);
        for k in 0..500 {
            let t = k as f64 * h;
            let q = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), omega * t);
            set_rotation(&mut s, "root.rotation", q.matrix());
            s.do_step(t, h).unwrap();
        }
        loads.push((vector(&mut s, "root.force"), vector(&mut s, "root.torque")));
    }
    let t = 500.0 * h;
    let q = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), omega * t);
    let (m, d) = (2.0, Vector3::new(-0.05, 0.0, 0.0));
    // The frame's load on the body grows by what the hub needs: m a_c = −m ω² R d.
    let expected = -m * omega * omega * (q * d);
    let (force, torque) = (loads[1].0 - loads[0].0, loads[1].1 - loads[0].1);
    println!("Δforce {force:?} against {expected:?}; Δtorque {torque:?}");
    assert!(
        (force - expected).norm() < 1e-4 * expected.norm(),
        "{force:?} against {expected:?}"
    );
    assert!(torque.norm() < 1e-4 * expected.norm() * d.norm());
}

/// Two pins on one rigid set hold the distance between them twice: refused, naming them.
#[test]
fn two_pins_on_a_rigid_set_are_refused_by_name() {
    let json = std::fs::read_to_string(format!(
        "{}/examples/controlled_arm.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace(
        r#""kind": "hinge", "axis": [0.0, 0.0, 1.0], "nodes": { "plane": { "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] } } },"#,
        r#""kind": "pin", "nodes": { "plane": { "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] } } },
    { "name": "second", "kind": "pin", "nodes": { "plane": { "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] } } },"#,
    );
    assert!(json.contains("second"));
    let mut s = Slave::from_body(BodyFile::from_json(&json).unwrap()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    let e = s.exit_initialization_mode().unwrap_err();
    assert!(
        e.message.contains("interface 'hub'")
            && e.message.contains("'bearing'")
            && e.message.contains("'second'"),
        "{}",
        e.message
    );
}

/// The FMU state carries the rigid sets' and the axis lock's multipliers and the lumped body's
/// mass points: the controlled arm saved under a torque, serialized into a fresh instance and
/// stepped on continues bit for bit.
#[test]
fn a_saved_state_with_rigid_sets_and_a_lumped_body_continues_bit_for_bit() {
    saved_arm_continues(&[]);
}

/// The tip's y after 0.6 s under a tip torque about z ramped to `torque` in 0.1 s (damping
/// β = 5 ms), with the defaults (one co-moving frame until the strain watch asks for slabs).
fn tip_under_torque(body: BodyFile, torque: f64) -> f64 {
    let mut s = initialized(body, &[("damping.beta", 5e-3)]);
    let h = 1e-3;
    for k in 0..600 {
        let t = k as f64 * h;
        set(&mut s, "tip.torque[3]", torque * (t / 0.1).min(1.0));
        s.do_step(t, h).unwrap();
    }
    get(&mut s, "tip.position[2]")
}

/// A rigid tip block turned against the one co-moving frame: the elements inside it carry no
/// stiffness, so their linear strain of that rotation (second order in it, and not relieved by
/// stretching as in a flexible block) does not stiffen the beam. Under a 100 N m tip torque
/// (tip slope 0.04 rad, where that strain exceeds the bending strain of this slender beam) the
/// rigid block bends the beam as a block 100 times stiffer does, within 2 % (measured 0.9 %, what
/// is left of one frame's strain error next to the block; before the fix the rigid block was
/// 22 % stiffer, found by review).
#[test]
fn a_rigid_block_turned_against_the_frame_does_not_stiffen_the_beam() {
    let rigid = tip_under_torque(cantilever_with_block(0.1, None), 100.0);
    let stiff = tip_under_torque(cantilever_with_block(0.1, Some(2.1e13)), 100.0);
    println!("tip y: rigid block {rigid:.5e} m, stiff block {stiff:.5e} m");
    assert!(
        (rigid - stiff).abs() < 1e-2 * stiff.abs(),
        "{rigid} m against {stiff} m"
    );
}

/// A lumped body does not move the interface's default reference point (the weighted centroid of
/// the set's mesh nodes), and without `inertia` it is a point mass at its centre of mass, however
/// far that is from the reference point (an inertia of zero about the reference point would be
/// refused as no rigid body's): B1's tip with 1 kg 5 cm beyond its face reports the face's
/// centre.
#[test]
fn a_lumped_point_mass_off_the_reference_point_keeps_the_interface_where_it_was() {
    let json = std::fs::read_to_string(format!(
        "{}/examples/cantilever.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace(
        r#", "referencePoint": [1.0, 0.0, 0.0] }"#,
        r#", "rigid": true, "mass": 1.0, "centerOfMass": [1.05, 0.0, 0.0] }"#,
    );
    assert!(json.contains(r#""mass": 1.0"#));
    let mut s = initialized(BodyFile::from_json(&json).unwrap(), &[]);
    let p = vector(&mut s, "tip.position");
    assert!((p - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-12, "{p:?}");
}

/// Several frames on a body with a rigid block: the slabs' elements wholly inside the block
/// carry no stiffness, as the body's elastic force and iteration matrix have it
/// (docs/formulation.md, "Several frames"). For a small displacement `u` (1e-7 m, rotations
/// 1e-7 rad) the slabs' internal force is `Σ_p K_p u` up to second order (1e-7 relative), so
/// it must equal the body's `K u` (measured 6.3e-6 N of 12.6 N): with the block's elements
/// stiff in the slabs it differs by their `K u`, of the order of the whole (12.5 N; `u` is not
/// rigid inside the block).
#[test]
fn the_slabs_stiffness_is_the_bodys_with_a_rigid_block() {
    let s = initialized(
        cantilever_with_block(0.1, None),
        &[("model.auto", 0.0), ("model.frames", 4.0)],
    );
    let body = s.body().unwrap();
    assert!(body.patches.is_some());
    let reference = &body.reference;
    let u: Vec<f64> = (0..reference.len())
        .map(|d| 1e-7 * (3.1 * reference[d - d % 3] + 1.3 * (d % 3) as f64).sin())
        .collect();
    let x: Vec<f64> = reference.iter().zip(&u).map(|(r, u)| r + u).collect();
    let mut scratch = body.force_scratch();
    let mut slabs = vec![0.0; x.len()];
    body.internal_force(&x, &vec![0.0; x.len()], None, &mut scratch, &mut slabs);
    let mut linear = vec![0.0; x.len()];
    body.stiffness_product(&u, &mut linear);
    let size = linear.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
    let difference = largest_difference(&slabs, &linear);
    println!("|K u| {size:.3e} N, slabs against K u {difference:.3e} N");
    assert!(difference <= 1e-5 * size, "{difference:e} of {size:e}");
}
