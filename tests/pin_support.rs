//! Pin supports (issue 3): a Lagrange-multiplier point constraint solved through the Schur
//! complement that is constant in the co-moving frame. A pinned beam under gravity is a physical
//! pendulum.

mod common;
use common::*;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::Vector3;

/// The pendulum with generalized-α.
fn pendulum() -> String {
    pendulum_json(r#"{ "stepSize": 1e-3, "rhoInf": 0.9, "tolerance": 1e-10, "maxIterations": 25 }"#)
}

/// A steel-dense beam, 100 times stiffer than steel (nearly rigid), pinned at the centre of its
/// root face, released 0.05 rad from hanging: period `2π sqrt(I_pivot / (m g d))` with
/// `I_pivot = m (L²/3 + a²/12)`, `d = L/2`, within 0.5 % (the finite amplitude adds θ₀²/16 =
/// 1.6e-4, the elasticity (ω_p/ω₁)² ≈ 1e-5; measured: +0.016 %). The pin does not drift
/// (measured: 2e-18 m).
#[test]
fn pinned_beam_swings_as_a_physical_pendulum() {
    let (g, theta0) = (9.81, 0.05_f64);
    let mut s = Slave::from_body(BodyFile::from_json(&pendulum()).unwrap()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    // Gravity at θ₀ from the beam axis: the beam starts 0.05 rad from hanging straight.
    set(&mut s, "gravity[1]", g * theta0.cos());
    set(&mut s, "gravity[2]", g * theta0.sin());
    s.exit_initialization_mode().unwrap();

    let (l, a) = (1.0, 0.02);
    let period = 2.0 * std::f64::consts::PI * ((l * l / 3.0 + a * a / 12.0) / (g * l / 2.0)).sqrt();
    let h = 1e-3;
    let steps = (2.5 * period / h) as usize;
    let mut angles = Vec::with_capacity(steps);
    let mut worst_drift: f64 = 0.0;
    let mut mean_reaction = Vector3::zeros();
    for k in 0..steps {
        s.do_step(k as f64 * h, h).unwrap();
        mean_reaction += vector(&mut s, "pivot.force") / steps as f64;
        let tip = vector(&mut s, "tip.position");
        angles.push(tip.y.atan2(tip.x) - theta0);
        // The pin holds the root face's centroid at the origin.
        let state = s.dynamic_state().unwrap();
        let mut c = Vector3::zeros();
        let mut w_total = 0.0;
        let body = s.body().unwrap();
        for i in 0..body.node_count() {
            if body.reference[3 * i].abs() < 1e-12 {
                let w = body.frame_weights.weights[i];
                c += w * Vector3::new(
                    state.position[3 * i],
                    state.position[3 * i + 1],
                    state.position[3 * i + 2],
                );
                w_total += w;
            }
        }
        worst_drift = worst_drift.max((c / w_total).norm());
    }
    let crossings: Vec<f64> = (1..angles.len())
        .filter(|&k| angles[k - 1] < 0.0 && angles[k] >= 0.0)
        .map(|k| (k as f64 - 1.0 + -angles[k - 1] / (angles[k] - angles[k - 1])) * h + h)
        .collect();
    assert!(crossings.len() >= 2, "{crossings:?}");
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    assert!(
        (measured - period).abs() < 5e-3 * period,
        "period {measured} s, expected {period} s"
    );
    assert!(worst_drift < 1e-9, "the pin drifted by {worst_drift:e} m");
    // The reaction carries the weight plus the centripetal force: its mean over the run is
    // close to m g (pointing against gravity).
    let f = vector(&mut s, "pivot.force");
    let m = 7850.0 * a * a * l;
    assert!(
        (f.norm() - m * g).abs() < 0.01 * m * g,
        "pivot force {f:?}, weight {}",
        m * g
    );
}

/// The same beam on a hinge about z through the centre of its root face, with gravity tilted out
/// of the x-y plane (g_z = 3 m/s²): it swings in the plane with the in-plane period, while the
/// hinge carries the out-of-plane weight (a pin would let it swing out of plane). The tip leaves
/// the plane only by the elastic sag of the stiff beam, ρ A g_z L⁴ / (8 E I) ≈ 4e-6 m.
#[test]
fn hinged_beam_swings_in_its_plane() {
    let (g, g_z, theta0) = (9.81, 3.0, 0.05_f64);
    let body = pendulum().replace(
        r#""name": "pivot", "kind": "pin","#,
        r#""name": "pivot", "kind": "hinge", "axis": [0.0, 0.0, 1.0],"#,
    );
    let mut s = Slave::from_body(BodyFile::from_json(&body).unwrap()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "gravity[1]", g * theta0.cos());
    set(&mut s, "gravity[2]", g * theta0.sin());
    set(&mut s, "gravity[3]", g_z);
    s.exit_initialization_mode().unwrap();
    let (l, a) = (1.0, 0.02);
    let period = 2.0 * std::f64::consts::PI * ((l * l / 3.0 + a * a / 12.0) / (g * l / 2.0)).sqrt();
    let h = 1e-3;
    let steps = (2.5 * period / h) as usize;
    let (mut angles, mut out_of_plane) = (Vec::with_capacity(steps), 0.0_f64);
    let mut mean_reaction_z = 0.0;
    for k in 0..steps {
        s.do_step(k as f64 * h, h).unwrap();
        let tip = vector(&mut s, "tip.position");
        angles.push(tip.y.atan2(tip.x) - theta0);
        out_of_plane = out_of_plane.max(tip.z.abs());
        mean_reaction_z += get(&mut s, "pivot.force[3]") / steps as f64;
    }
    assert!(
        out_of_plane < 2e-5,
        "the tip left the hinge plane by {out_of_plane:e} m"
    );
    let crossings: Vec<f64> = (1..angles.len())
        .filter(|&k| angles[k - 1] < 0.0 && angles[k] >= 0.0)
        .map(|k| (k as f64 - 1.0 + -angles[k - 1] / (angles[k] - angles[k - 1])) * h + h)
        .collect();
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    assert!(
        (measured - period).abs() < 5e-3 * period,
        "period {measured} s, expected {period} s"
    );
    // The hinge carries the out-of-plane weight: on average (the sudden load excites the stiff
    // beam's z-bending, which only the reaction sees) its z component balances m g_z.
    let m = 7850.0 * a * a * l;
    assert!(
        (mean_reaction_z + m * g_z).abs() < 0.01 * m * g_z,
        "mean pivot.force[3] = {mean_reaction_z}, expected {}",
        -m * g_z
    );
}
