//! Cost of one `fmi2DoStep` of the default body against its floor, one forward and one backward
//! triangular solve with the factor of the iteration matrix (issue 2's figures).
//!
//! `cargo run --release --example step_cost [-- steps]`: prints DOF, nnz of K and of the factor,
//! the median time of a solve, and for h = 1e-4 and 1e-3 the median time per step, steps per second,
//! iterations per step and the ratio step/solve. The load is B1's step load (10 N at the tip).

use flexbody::model::{BodyFile, VariableType};
use flexbody::slave::Slave;
use flexbody::solver::generalized_alpha::{FreeNodes, GeneralizedAlpha, IterationMatrix};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn set(s: &mut Slave, name: &str, value: f64) {
    let v = s.variables().by_name(name).unwrap().clone();
    assert_eq!(v.ty, VariableType::Real);
    s.set_real(v.value_reference, value).unwrap();
}

fn main() {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2000);
    let body_file = BodyFile::default_body();
    println!("body: {} ({})", body_file.name, body_file.description);

    for h in [1e-4, 1e-3] {
        let mut s = Slave::from_body(body_file.clone()).unwrap();
        s.setup_experiment(0.0, None, None).unwrap();
        s.enter_initialization_mode().unwrap();
        set(&mut s, "solver.stepSize", h);
        set(&mut s, "tip.force[2]", -10.0);
        let t0 = Instant::now();
        s.exit_initialization_mode().unwrap();
        let init = t0.elapsed().as_secs_f64();

        // The floor: one forward + backward solve with the same factor.
        let body = s.body().unwrap();
        // nodes at x = 0 are the root support of the default body
        let clamped: Vec<bool> = (0..body.node_count())
            .map(|i| body.reference[3 * i].abs() < 1e-12)
            .collect();
        let free = FreeNodes::new(body, &clamped);
        let scheme = GeneralizedAlpha::new(s.parameters().rho_inf);
        let mut matrix = IterationMatrix::new(&free, &scheme, h, 0.0, 0.0).unwrap();
        let (dof, nnz_k) = (body.reference.len(), body.stiffness_matrix.nnz());
        let mut ws = matrix.factor.solve_scratch();
        let mut rhs = vec![1.0; free.dof_count()];
        let mut solve = Vec::new();
        for _ in 0..50 {
            let t = Instant::now();
            matrix.factor.solve_in_place(&mut rhs, &mut ws);
            solve.push(t.elapsed().as_secs_f64());
            rhs.iter_mut().for_each(|v| *v = 1.0);
        }
        let _ = &mut matrix;
        let solve = median(solve);

        let mut times = Vec::with_capacity(steps);
        let mut t = 0.0;
        for _ in 0..steps {
            let t1 = Instant::now();
            s.do_step(t, h).unwrap();
            times.push(t1.elapsed().as_secs_f64());
            t += h;
        }
        let step = median(times[1..].to_vec());
        let (internal_steps, iterations) = s.solver_statistics();
        println!(
            "h = {h:e}: DOF {dof} (free {}), nnz(K) {nnz_k}, nnz(L) {}, init {:.3} s, solve {:.3} ms, step {:.3} ms ({:.0} steps/s), {:.2} iterations/step, step/solve {:.2}",
            free.dof_count(),
            matrix.factor.factor_nnz(),
            init,
            1e3 * solve,
            1e3 * step,
            1.0 / step,
            iterations as f64 / internal_steps as f64,
            step / solve
        );
    }
}
