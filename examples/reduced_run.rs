//! One side of `bench/paired.py`'s interleaved comparison with Exudyn: B1 with the reduced body
//! (`model.modes`), fixed internal step, through `flexbody::slave::Slave` as an importer drives
//! the FMU. Prints one JSON line with the setup and stepping wall times of a short and a long
//! run, each on a fresh instance, so that the caller can take the per-step cost from their
//! difference (which cancels what a run costs once: the first factorization, the first
//! residual).
//!
//! `cargo run --release --example reduced_run -- [--h 1e-3] [--modes 8|auto|0] [--short 2]
//! [--long 10] [--linear 1]`
//!
//! `--linear 1`: the linear body (`model.linear`, docs/formulation.md, "The linear body").
//! `--modes auto`: the count `model.modes = auto` chooses; `--modes 0`: the mesh body (the
//! yardstick of the reduced bodies' error). `--long 0` skips the long run. `tip_y_samples`: the
//! short run's tip y at every communication point (m), for the caller to compare sides.
//!
//! B1 as `bench/peers.py`: the default cantilever, 10 N in −y on `tip` from t = 0, no damping,
//! ρ∞ = 0.9, communication step 2 ms (the peers' sensor period). `setup_s`: from the body file to
//! the end of `exit_initialization_mode` (mesh, matrices, modes, factorization of the first
//! step size); `steps_s`: the stepping loop.

use flexbody::model::body_file::MODES_AUTO;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::time::Instant;

const SAMPLE: f64 = 2e-3;

struct Timing {
    setup: f64,
    stepping: f64,
    steps: usize,
    tip_y: Vec<f64>,
}

fn run(h: f64, modes: i32, linear: bool, end: f64) -> Timing {
    let started = Instant::now();
    let mut s = Slave::from_body(BodyFile::default_body()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_by_name("model.modes", f64::from(modes)).unwrap();
    s.set_by_name("model.linear", f64::from(u8::from(linear)))
        .unwrap();
    s.set_by_name("model.accuracy", 0.0).unwrap();
    s.set_by_name("solver.stepSize", h).unwrap();
    s.set_by_name("tip.force[2]", -10.0).unwrap();
    s.exit_initialization_mode().unwrap();
    let setup = started.elapsed().as_secs_f64();
    let samples = (end / SAMPLE).round() as usize;
    let mut tip_y = Vec::with_capacity(samples);
    let mut stepping = 0.0;
    for k in 0..samples {
        let started = Instant::now();
        s.do_step(k as f64 * SAMPLE, SAMPLE).unwrap();
        stepping += started.elapsed().as_secs_f64();
        tip_y.push(s.get_by_name("tip.position[2]").unwrap());
    }
    Timing {
        setup,
        stepping,
        steps: (end / h).round() as usize,
        tip_y,
    }
}

fn main() {
    let mut h = 1e-3;
    let mut modes = 8;
    let mut linear = false;
    let (mut short, mut long) = (2.0, 10.0);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let value = args.next().expect("every option takes a value");
        match arg.as_str() {
            "--h" => h = value.parse().unwrap(),
            "--modes" => {
                modes = if value == "auto" {
                    MODES_AUTO
                } else {
                    value.parse().unwrap()
                }
            }
            "--linear" => linear = value == "1" || value == "true",
            "--short" => short = value.parse().unwrap(),
            "--long" => long = value.parse().unwrap(),
            other => panic!("unknown option {other}"),
        }
    }
    let a = run(h, modes, linear, short);
    let b = if long > 0.0 {
        run(h, modes, linear, long)
    } else {
        Timing {
            setup: 0.0,
            stepping: 0.0,
            steps: 0,
            tip_y: Vec::new(),
        }
    };
    let samples: Vec<String> = a.tip_y.iter().map(|y| format!("{y:e}")).collect();
    println!(
        "{{\"setup_s\": {:e}, \"setup_long_s\": {:e}, \"short_s\": {:e}, \"short_steps\": {}, \"long_s\": {:e}, \"long_steps\": {}, \"tip_y_short\": {:e}, \"tip_y_samples\": [{}]}}",
        a.setup,
        b.setup,
        a.stepping,
        a.steps,
        b.stepping,
        b.steps,
        a.tip_y.last().copied().unwrap_or(f64::NAN),
        samples.join(", ")
    );
}
