//! Helpers shared by the integration tests: drive a [`Slave`] by variable name.
#![allow(dead_code)]

pub mod b3;
pub mod reduced_b1;
pub mod rigid;

use flexbody::body::{Body, BodyOptions};
use flexbody::fem::{self, IsotropicMaterial};
use flexbody::mesh::{generator, ElementKind, Mesh, NodeSelector};
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Timoshenko tip deflection of B1 under 10 N (docs/benchmarks.md), m.
pub const B1_TIMOSHENKO_DEFLECTION: f64 = 1.19084e-3;
/// First bending frequency of B1 (Euler–Bernoulli), Hz.
pub const B1_FIRST_FREQUENCY: f64 = 16.710;

/// The B1-like steel cantilever of the library-level tests (1 m × 20 mm × 20 mm, hex20
/// 10×1×1, not yet clamped), its mesh and its body with `options`.
pub fn steel_beam(options: BodyOptions) -> (Mesh, Body) {
    let mesh = generator::beam(1.0, 0.02, 0.02, [10, 1, 1], ElementKind::Hex20).unwrap();
    let material = IsotropicMaterial::STEEL;
    let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
    let body = Body::new(
        reference,
        fem::scalar_mass_matrix(&mesh, material.density),
        fem::stiffness_matrix(&mesh, &material),
        fem::lumped_masses(&mesh, material.density),
        options,
    );
    (mesh, body)
}

/// The nodes of `mesh` on the plane `x = const` (a face of the beam).
pub fn face(mesh: &Mesh, x: f64) -> Vec<usize> {
    NodeSelector::Plane {
        point: [x, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
        tolerance: None,
    }
    .select(mesh)
    .unwrap()
}

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

/// The error with which `body` refuses to leave initialization with `settings`.
pub fn refused(body: BodyFile, settings: &[(&str, f64)]) -> flexbody::error::Error {
    let mut slave = Slave::from_body(body).unwrap();
    slave.setup_experiment(0.0, None, None).unwrap();
    slave.enter_initialization_mode().unwrap();
    for (name, value) in settings {
        set(&mut slave, name, *value);
    }
    slave.exit_initialization_mode().unwrap_err()
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

/// The three components `name[1..3]` as a vector.
pub fn vector(s: &mut Slave, name: &str) -> Vector3<f64> {
    Vector3::from_fn(|k, _| get(s, &format!("{name}[{}]", k + 1)))
}

/// Sets the rotation matrix `name[1..9]` (row-major).
pub fn set_rotation(s: &mut Slave, name: &str, q: &Matrix3<f64>) {
    for k in 0..9 {
        set(s, &format!("{name}[{}]", k + 1), q[(k / 3, k % 3)]);
    }
}

/// B4: the root of `s` (motion interface `root`) turned about z at `omega` for 6 s in steps of
/// `h`, B1's 10 N tip load turning with it. Returns the largest deviation of the tip deflection
/// in the root frame from B1's clamped static value ([`b1_settled_deflection`]) over the last
/// 2 s, relative to it (the start-up transient has decayed by then).
pub fn b4_deviation_from_static(s: &mut Slave, h: f64, omega: f64) -> f64 {
    let static_deflection = b1_settled_deflection();
    let mut worst: f64 = 0.0;
    for k in 0..(6.0 / h).round() as usize {
        let t = k as f64 * h;
        let q = *Rotation3::from_axis_angle(&Vector3::z_axis(), omega * t).matrix();
        set_rotation(s, "root.rotation", &q);
        let load = q * Vector3::new(0.0, -10.0, 0.0);
        for c in 0..3 {
            set(s, &format!("tip.force[{}]", c + 1), load[c]);
        }
        s.do_step(t, h).unwrap();
        if t + h >= 4.0 {
            let q_end = *Rotation3::from_axis_angle(&Vector3::z_axis(), omega * (t + h)).matrix();
            let local =
                q_end.transpose() * (vector(s, "tip.position") - vector(s, "root.position"));
            worst = worst.max((local.y - static_deflection).abs() / static_deflection.abs());
        }
    }
    worst
}

/// The pendulum body of the pin tests (B1's section, 1 m, 100× steel's stiffness: nearly rigid,
/// pinned at the centre of its root face, a force interface at the tip) with `solver`, the body
/// file's `"solver"` object.
pub fn pendulum_json(solver: &str) -> String {
    format!(
        r#"{{
  "name": "pendulum",
  "mesh": {{ "beam": {{ "length": 1.0, "width": 0.02, "height": 0.02, "divisions": [10, 1, 1], "element": "hex20" }} }},
  "material": {{ "youngsModulus": 2.1e13, "poissonRatio": 0.3, "density": 7850.0 }},
  "interfaces": [
    {{ "name": "pivot", "kind": "pin", "nodes": {{ "plane": {{ "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] }} }} }},
    {{ "name": "tip", "kind": "force", "nodes": {{ "plane": {{ "point": [1.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0] }} }}, "referencePoint": [1.0, 0.0, 0.0] }}
  ],
  "solver": {solver}
}}"#
    )
}
