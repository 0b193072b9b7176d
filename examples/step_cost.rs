//! Cost of one `fmi2DoStep` against its floor, one forward and one backward triangular solve
//! with the factor of the iteration matrix (the figures of issues 2 and 3).
//!
//! `cargo run --release --example step_cost [-- steps [body.json ...]]` (default: 2000 steps of
//! the default cantilever, its reduced body with 8 modes, the motion-driven cantilever and a
//! pinned variant). For each body and
//! h = 1e-4, 1e-3 s it prints DOF, nnz of K and of the factor, the median time of a solve and of a
//! step, steps per second, iterations per step and the ratio step/solve. The load is B1's: 10 N at
//! the tip; the pinned variant is the cantilever with its root face on a pin under gravity.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;

#[path = "support/mod.rs"]
mod support;

fn bodies(paths: &[String]) -> Vec<BodyFile> {
    if !paths.is_empty() {
        return paths
            .iter()
            .map(|p| BodyFile::from_json(&std::fs::read_to_string(p).unwrap()).unwrap())
            .collect();
    }
    let root = env!("CARGO_MANIFEST_DIR");
    let driven =
        std::fs::read_to_string(format!("{root}/examples/driven_cantilever.json")).unwrap();
    let mut pinned = BodyFile::default_body();
    pinned.name = "pinned_cantilever".into();
    pinned.interfaces[0].kind = flexbody::model::InterfaceKind::Pin;
    // The reduced body (issue 8): B1 on 8 fixed-interface modes and the interfaces' modes.
    let mut reduced = BodyFile::default_body();
    reduced.name = "cantilever_modes8".into();
    reduced.model.modes = flexbody::model::body_file::ModesSpec::Count(8);
    vec![
        BodyFile::default_body(),
        reduced,
        BodyFile::from_json(&driven).unwrap(),
        pinned,
    ]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let steps: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(2000);
    let paths: Vec<String> = args.iter().skip(1).cloned().collect();
    println!("| body | h (s) | DOF (free) | nnz(K) | nnz(L) | solve (ms) | step (ms) | steps/s | iterations/step | step/solve |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for body_file in bodies(&paths) {
        for h in [1e-4, 1e-3] {
            let mut s = Slave::from_body(body_file.clone()).unwrap();
            s.setup_experiment(0.0, None, None).unwrap();
            s.enter_initialization_mode().unwrap();
            s.set_by_name("solver.stepSize", h).unwrap();
            // Measured at the fixed step h.
            s.set_by_name("model.accuracy", 0.0).unwrap();
            s.set_by_name("tip.force[2]", -10.0).unwrap();
            if body_file.name.starts_with("pinned") {
                s.set_by_name("gravity[1]", 9.81).unwrap();
            }
            s.exit_initialization_mode().unwrap();

            s.do_step(0.0, h).unwrap(); // the first step at a step size factorises
                                        // The floor: one forward + backward solve with the slave's own factor.
            let solve = support::solve_time(&s, h, 200);
            let (body, free) = (s.body().unwrap(), s.free_nodes().unwrap());
            let (dof, free_dof) = (body.reference.len(), free.dof_count());
            let nnz_k = body.stiffness_matrix.nnz();
            let nnz_l = s.iteration_matrix(h).unwrap().factor.factor_nnz();
            let (step, iterations, _) = support::step_time(&mut s, h, h, steps);
            println!(
                "| {} | {h:e} | {dof} ({free_dof}) | {nnz_k} | {nnz_l} | {:.3} | {:.3} | {:.0} | {:.2} | {:.2} |",
                body_file.name,
                1e3 * solve,
                1e3 * step,
                1.0 / step,
                iterations,
                step / solve
            );
        }
    }
}
