//! Helpers shared by the integration tests: drive a [`Slave`] by variable name.
#![allow(dead_code)]

pub mod b3;

use flexbody::model::BodyFile;
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
    slave
        .set_by_name(name, value)
        .unwrap_or_else(|e| panic!("{}", e.message));
}

pub fn get(slave: &mut Slave, name: &str) -> f64 {
    slave.get_by_name(name).unwrap()
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

/// The body file at `path`.
pub fn example_body_at(path: &std::path::Path) -> BodyFile {
    BodyFile::from_json(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// B1's static tip deflection on the default mesh (m, negative): the fixed-root default body
/// under 10 N, settled by 0.6 s of heavy damping (β = 2e-2 s, h = 1 ms).
pub fn b1_settled_deflection() -> f64 {
    let h = 1e-3;
    let mut fixed = initialized_default(&[("damping.beta", 2e-2), ("tip.force[2]", -10.0)]);
    let y0 = get(&mut fixed, "tip.position[2]");
    for k in 0..600 {
        fixed.do_step(k as f64 * h, h).unwrap();
    }
    get(&mut fixed, "tip.position[2]") - y0
}
