//! B2 (free tumbling beam, ρ∞ = 1): drift of angular momentum and energy over 10 s with and
//! without the nonlinear force `f_nl`, with one and with four co-moving frames (issue 4). `cargo run --release --example b2_drift [-- h]`.
//! The beam (examples/tumbling.json, softened to E = 2.1e8 Pa so that it deforms visibly) spins
//! about its centre of mass with ω = (0.5, 3, 7) rad/s.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::Vector3;

fn get(s: &mut Slave, name: &str) -> f64 {
    s.get_by_name(name).unwrap()
}

fn main() {
    let h: f64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1e-3);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/tumbling.json"
    ))
    .unwrap();
    println!("| frames | f_nl | h (s) | max |ΔL|/|L| over 10 s | max |ΔE|/E over 10 s | iterations/step | wall (s) |");
    println!("|---|---|---|---|---|---|---|");
    for (frames, f_nl) in [(1, false), (1, true), (4, false), (4, true)] {
        let mut s = Slave::from_body(BodyFile::from_json(&text).unwrap()).unwrap();
        s.setup_experiment(0.0, None, None).unwrap();
        s.enter_initialization_mode().unwrap();
        let w = Vector3::new(0.5, 3.0, 7.0);
        let v = -w.cross(&Vector3::new(0.5, 0.0, 0.0));
        let set = |s: &mut Slave, name: &str, value: f64| s.set_by_name(name, value).unwrap();
        for k in 0..3 {
            set(&mut s, &format!("initial.angularVelocity[{}]", k + 1), w[k]);
            set(&mut s, &format!("initial.velocity[{}]", k + 1), v[k]);
        }
        set(&mut s, "solver.stepSize", h);
        // Measured at the fixed step h.
        set(&mut s, "model.accuracy", 0.0);
        set(&mut s, "material.youngsModulus", 2.1e8);
        set(&mut s, "model.nonlinearForces", f64::from(u8::from(f_nl)));
        set(&mut s, "model.frames", f64::from(frames));
        s.exit_initialization_mode().unwrap();
        let momentum = |s: &mut Slave| {
            Vector3::from_fn(|k, _| get(s, &format!("body.angularMomentum[{}]", k + 1)))
        };
        let energy = |s: &mut Slave| get(s, "body.kineticEnergy") + get(s, "body.strainEnergy");
        let (l0, e0) = (momentum(&mut s), energy(&mut s));
        let (mut dl, mut de) = (0.0_f64, 0.0_f64);
        let started = std::time::Instant::now();
        let steps = (10.0 / h).round() as usize;
        for k in 0..steps {
            s.do_step(k as f64 * h, h).unwrap();
            dl = dl.max((momentum(&mut s) - l0).norm() / l0.norm());
            de = de.max((energy(&mut s) - e0).abs() / e0);
        }
        let (internal, iterations) = s.solver_statistics();
        println!(
            "| {frames} | {} | {h} | {dl:.3e} | {de:.3e} | {:.2} | {:.1} |",
            if f_nl { "on" } else { "off" },
            iterations as f64 / internal as f64,
            started.elapsed().as_secs_f64()
        );
    }
}
