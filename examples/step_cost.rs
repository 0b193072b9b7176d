//! Cost of one `fmi2DoStep` against its floor, one forward and one backward triangular solve
//! with the factor of the iteration matrix (the figures of issues 2 and 3).
//!
//! `cargo run --release --example step_cost [-- steps [body.json ...]]` (default: 2000 steps of
//! the default cantilever, the motion-driven cantilever and a pinned variant). For each body and
//! h = 1e-4, 1e-3 s it prints DOF, nnz of K and of the factor, the median time of a solve and of a
//! step, steps per second, iterations per step and the ratio step/solve. The load is B1's: 10 N at
//! the tip; the pinned variant is the cantilever with its root face on a pin under gravity.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use flexbody::solver::generalized_alpha::{GeneralizedAlpha, IterationMatrix};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

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
    vec![
        BodyFile::default_body(),
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
            s.set_by_name("tip.force[2]", -10.0).unwrap();
            if body_file.name.starts_with("pinned") {
                s.set_by_name("gravity[1]", 9.81).unwrap();
            }
            s.exit_initialization_mode().unwrap();

            // The floor: one forward + backward solve with a factor of the same matrix.
            let body = s.body().unwrap();
            let free = s.free_nodes().unwrap();
            let scheme = GeneralizedAlpha::new(s.parameters().rho_inf);
            let matrix = IterationMatrix::new(body, free, &scheme, h, 0.0, 0.0).unwrap();
            let mut ws = matrix.factor.solve_scratch();
            let mut rhs = vec![1.0; free.dof_count()];
            let mut solve = Vec::new();
            for _ in 0..200 {
                rhs.iter_mut().for_each(|v| *v = 1.0);
                let t = Instant::now();
                matrix.factor.solve_in_place(&mut rhs, &mut ws);
                solve.push(t.elapsed().as_secs_f64());
            }
            let solve = median(solve);
            let (dof, free_dof) = (body.reference.len(), free.dof_count());
            let (nnz_k, nnz_l) = (body.stiffness_matrix.nnz(), matrix.factor.factor_nnz());

            let mut times = Vec::with_capacity(steps);
            let mut t = 0.0;
            s.do_step(t, h).unwrap(); // the first step at a step size may factorise
            t += h;
            let (steps0, iterations0) = s.solver_statistics();
            for _ in 0..steps {
                let t1 = Instant::now();
                s.do_step(t, h).unwrap();
                times.push(t1.elapsed().as_secs_f64());
                t += h;
            }
            let (steps1, iterations1) = s.solver_statistics();
            let step = median(times);
            println!(
                "| {} | {h:e} | {dof} ({free_dof}) | {nnz_k} | {nnz_l} | {:.3} | {:.3} | {:.0} | {:.2} | {:.2} |",
                body_file.name,
                1e3 * solve,
                1e3 * step,
                1.0 / step,
                (iterations1 - iterations0) as f64 / (steps1 - steps0) as f64,
                step / solve
            );
        }
    }
}
