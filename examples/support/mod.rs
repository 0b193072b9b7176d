//! What the cost-measuring examples share (included with `#[path]`; not an example itself).
#![allow(dead_code)]

use flexbody::slave::Slave;
use std::time::Instant;

/// The median of a sample (upper median for an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// `--quick` and `--csv FILE` of the bench examples.
pub struct BenchArgs {
    pub quick: bool,
    pub csv: Option<std::path::PathBuf>,
}

impl BenchArgs {
    pub fn parse() -> BenchArgs {
        let args: Vec<String> = std::env::args().skip(1).collect();
        BenchArgs {
            quick: args.iter().any(|a| a == "--quick"),
            csv: args
                .iter()
                .position(|a| a == "--csv")
                .map(|k| std::path::PathBuf::from(&args[k + 1])),
        }
    }
}

/// The floor of a step: the median time (s) of one forward + backward solve with the slave's own
/// factorization for internal step `h` (a step of that size must have been taken), `repeats`
/// times.
pub fn solve_time(s: &Slave, h: f64, repeats: usize) -> f64 {
    let matrix = s
        .iteration_matrix(h)
        .expect("a step of this size factorised the iteration matrix");
    let mut ws = matrix.factor.solve_scratch();
    let mut rhs = vec![1.0; s.free_nodes().unwrap().dof_count()];
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        rhs.iter_mut().for_each(|v| *v = 1.0);
        let t = Instant::now();
        matrix.factor.solve_in_place(&mut rhs, &mut ws);
        times.push(t.elapsed().as_secs_f64());
    }
    median(times)
}

/// `steps` steps of `h` from `t`: the median step time (s), iterations per step and the end time.
pub fn step_time(s: &mut Slave, mut t: f64, h: f64, steps: usize) -> (f64, f64, f64) {
    let (steps0, iterations0) = s.solver_statistics();
    let mut times = Vec::with_capacity(steps);
    for _ in 0..steps {
        let started = Instant::now();
        s.do_step(t, h).unwrap();
        times.push(started.elapsed().as_secs_f64());
        t += h;
    }
    let (steps1, iterations1) = s.solver_statistics();
    let iterations = (iterations1 - iterations0) as f64 / (steps1 - steps0) as f64;
    (median(times), iterations, t)
}
