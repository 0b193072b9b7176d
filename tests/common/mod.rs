//! Helpers shared by the integration tests: drive a [`Slave`] by variable name.
#![allow(dead_code)]

pub mod b3;

use flexbody::model::{BodyFile, VariableType};
use flexbody::slave::Slave;

/// Timoshenko tip deflection of B1 under 10 N (BENCHMARKS.md), m.
pub const B1_TIMOSHENKO_DEFLECTION: f64 = 1.19084e-3;
/// First bending frequency of B1 (Euler–Bernoulli), Hz.
pub const B1_FIRST_FREQUENCY: f64 = 16.710;

pub fn vr(slave: &Slave, name: &str) -> u32 {
    slave
        .variables()
        .by_name(name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .value_reference
}

pub fn set(slave: &mut Slave, name: &str, value: f64) {
    let v = slave.variables().by_name(name).unwrap().clone();
    match v.ty {
        VariableType::Real => slave.set_real(v.value_reference, value).unwrap(),
        VariableType::Integer => slave.set_integer(v.value_reference, value as i32).unwrap(),
        VariableType::Boolean => slave.set_boolean(v.value_reference, value != 0.0).unwrap(),
        VariableType::String => panic!("{name} is a String: use Slave::set_string"),
    }
}

pub fn get(slave: &mut Slave, name: &str) -> f64 {
    let r = vr(slave, name);
    slave.get_real(r).unwrap()
}

/// The body file `examples/<name>.json`.
pub fn example_body(name: &str) -> BodyFile {
    let path = format!("{}/examples/{name}.json", env!("CARGO_MANIFEST_DIR"));
    BodyFile::from_json(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// `body` instantiated, with `settings` applied in initialization mode, initialized at t = 0.
pub fn initialized(body: BodyFile, settings: &[(&str, f64)]) -> Slave {
    let mut slave = Slave::from_body(body).unwrap();
    slave.setup_experiment(0.0, None, None).unwrap();
    slave.enter_initialization_mode().unwrap();
    for (name, value) in settings {
        set(&mut slave, name, *value);
    }
    slave.exit_initialization_mode().unwrap();
    slave
}

/// The default body (B1), initialized with `settings`.
pub fn initialized_default(settings: &[(&str, f64)]) -> Slave {
    initialized(BodyFile::default_body(), settings)
}

/// One B3 step: the hub's rotation and rate of the schedule at `t` as inputs of the motion
/// interface `hub`, a step of `h`, and the tip deflection in the hub frame at `t + h` (m).
pub fn b3_step(slave: &mut Slave, t: f64, h: f64) -> f64 {
    use nalgebra::{Rotation3, Vector3};
    let (theta, rate) = b3::hub(t);
    let q = *Rotation3::from_axis_angle(&Vector3::z_axis(), theta).matrix();
    for c in 0..9 {
        set(
            slave,
            &format!("hub.rotation[{}]", c + 1),
            q[(c / 3, c % 3)],
        );
    }
    set(slave, "hub.angularVelocity[3]", rate);
    slave.do_step(t, h).unwrap();
    let q1 = Rotation3::from_axis_angle(&Vector3::z_axis(), b3::hub(t + h).0);
    let tip = Vector3::from_fn(|c, _| get(slave, &format!("tip.position[{}]", c + 1)));
    (q1.inverse() * tip).y
}

/// The body file at `path`.
pub fn example_body_at(path: &std::path::Path) -> BodyFile {
    BodyFile::from_json(&std::fs::read_to_string(path).unwrap()).unwrap()
}
