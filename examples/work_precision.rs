//! Run time against error (issue 7): each formulation at several step sizes against a fine
//! reference, through `flexbody::slave::Slave` as an importer would drive the FMU.
//!
//! `cargo run --release --example work_precision -- [--quick] [--csv FILE]`
//!
//! * **B1 dynamic**: the default cantilever (`examples/cantilever.json`, hex20 20×2×2), 10 N step
//!   load in −y on `tip` at t = 0, no damping, ρ∞ of the body file (0.9), 0.1 s. Communication step
//!   2 ms, internal steps h ∈ {2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4} s. Error: the largest |Δ tip y| over
//!   the 2 ms samples against `reducedStrain` at h = 2.5e-5 s on the same mesh (its trajectory is
//!   written to `<FILE stem>_b1_reference.csv` for the peers of `bench/peers.py`; `full` at the
//!   coarser steps lands on the same errors, so the model difference is far below them). Wall
//!   time: the median of three runs of the stepping loop (the factorisation of the first step
//!   included; one run for `full`, whose runs take seconds).
//! * **B3**: `examples/hub_beam.json` spun up by the hub schedule (`tests/common/b3.rs`) for 20 s,
//!   tip deflection in the hub frame sampled every 20 ms, h ∈ {2e-2, 1e-2, 5e-3} s against `full`
//!   at h = 2.5e-3 s (one run each).
//!
//! `--quick` (for checking the task): B1 at two step sizes against h = 1e-4 s, B3 over 3 s
//! against `full` at 5e-3 s.
//!
//! Models: `reducedStrain` with `f_nl` off (the default) and on, and `full`, all with
//! generalized-α, and Radau IIA (`radauIIA, reducedStrain, f_nl off`). Prints Markdown
//! tables; with `--csv FILE` also writes one row per run:
//! `problem,model,h,steps,wall_s,steps_per_s,max_error_m,relative_error` (model quoted).

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::fmt::Write as _;
use std::time::Instant;
#[path = "../tests/common/b3.rs"]
mod b3;

/// Integer/Boolean settings by name, as in `b3_table.rs`.
type Settings = &'static [(&'static str, i32)];

const MODELS: [(&str, Settings); 3] = [
    ("reducedStrain, f_nl off", &[("model.formulation", 1)]),
    (
        "reducedStrain, f_nl on",
        &[("model.formulation", 1), ("model.nonlinearForces", 1)],
    ),
    ("full", &[("model.formulation", 2)]),
];

/// Other integrators on the reduced-strain body (issue 7): Radau IIA (order 5,
/// `solver.integrator = radauIIA`; one real and one complex factorization per step size).
const INTEGRATORS: [(&str, Settings); 1] = [(
    "radauIIA, reducedStrain, f_nl off",
    &[("model.formulation", 1), ("solver.integrator", 3)],
)];

fn vr(s: &Slave, name: &str) -> u32 {
    s.variables().by_name(name).unwrap().value_reference
}

fn slave(body: &BodyFile, h: f64, settings: &[(&str, i32)]) -> Slave {
    let mut s = Slave::from_body(body.clone()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_by_name("solver.stepSize", h).unwrap();
    for (name, value) in settings {
        s.set_by_name(name, f64::from(*value)).unwrap();
    }
    s
}

/// B1: tip y (m) at every communication point (2 ms) and the wall time of the stepping loop.
fn b1(body: &BodyFile, h: f64, settings: &[(&str, i32)], end: f64) -> (Vec<f64>, f64) {
    let mut s = slave(body, h, settings);
    s.set_real(vr(&s, "tip.force[2]"), -10.0).unwrap();
    s.exit_initialization_mode().unwrap();
    let tip = vr(&s, "tip.position[2]");
    let y0 = s.get_real(tip).unwrap();
    let dt = 2e-3;
    let n = (end / dt).round() as usize;
    let mut y = Vec::with_capacity(n + 1);
    y.push(0.0);
    let started = Instant::now();
    for k in 0..n {
        s.do_step(k as f64 * dt, dt).unwrap();
        y.push(s.get_real(tip).unwrap() - y0);
    }
    (y, started.elapsed().as_secs_f64())
}

/// B3: tip deflection in the hub frame (m) every 20 ms and the wall time.
fn b3(
    body: &BodyFile,
    h: f64,
    settings: &[(&str, i32)],
    end: f64,
) -> Result<(Vec<f64>, f64), String> {
    let mut s = slave(body, h, settings);
    s.exit_initialization_mode().map_err(|e| e.message)?;
    let drive = b3::HubDrive::new(&s);
    let steps = (end / h).round() as usize;
    let every = (2e-2 / h).round() as usize;
    let mut y = vec![0.0];
    let started = Instant::now();
    for k in 0..steps {
        let t = k as f64 * h;
        let yk = drive
            .step(&mut s, t, h)
            .map_err(|e| format!("t = {t}: {}", e.message))?;
        if (k + 1) % every == 0 {
            y.push(yk);
        }
    }
    Ok((y, started.elapsed().as_secs_f64()))
}

fn max_error(y: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(y.len(), reference.len());
    y.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

#[path = "support/mod.rs"]
mod support;
use support::median;

fn main() {
    let support::BenchArgs {
        quick,
        csv: csv_path,
    } = support::BenchArgs::parse();
    let mut csv =
        String::from("problem,model,h,steps,wall_s,steps_per_s,max_error_m,relative_error\n");
    let repeats = if quick { 1 } else { 3 };

    // ---- B1 -------------------------------------------------------------------------------
    let end = 0.1;
    let body = BodyFile::default_body();
    let h_ref = if quick { 1e-4 } else { 2.5e-5 };
    let (reference, _) = b1(&body, h_ref, MODELS[0].1, end);
    let peak = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if let Some(path) = &csv_path {
        let mut text = String::from("t,tip_y\n");
        for (k, y) in reference.iter().enumerate() {
            writeln!(text, "{},{y:.12e}", k as f64 * 2e-3).unwrap();
        }
        let stem = path.with_extension("");
        std::fs::write(format!("{}_b1_reference.csv", stem.display()), text).unwrap();
    }
    println!(
        "B1 dynamic: {} ({} s, 10 N step load, ρ∞ = {}, communication step 2 ms); reference `reducedStrain` at h = {h_ref:e} s, peak |tip y| = {peak:.4e} m\n",
        body.name,
        end,
        body.solver.rho_inf,
    );
    println!("| model | h (s) | steps | wall (ms, median of {repeats}; `full`: 1 run) | steps/s | max tip error (m) | error / peak |");
    println!("|---|---|---|---|---|---|---|");
    let steps_b1: &[f64] = if quick {
        &[2e-3, 5e-4]
    } else {
        &[2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4]
    };
    for &(label, settings) in MODELS.iter().chain(&INTEGRATORS) {
        for &h in steps_b1 {
            let mut walls = Vec::new();
            let mut error = 0.0;
            let runs = if label == "full" { 1 } else { repeats };
            for _ in 0..runs {
                let (y, wall) = b1(&body, h, settings, end);
                error = max_error(&y, &reference);
                walls.push(wall);
            }
            let wall = median(walls);
            let steps = (end / h).round() as usize;
            println!(
                "| {label} | {h:e} | {steps} | {:.1} | {:.0} | {error:.3e} | {:.2e} |",
                1e3 * wall,
                steps as f64 / wall,
                error / peak
            );
            writeln!(
                csv,
                "B1,\"{label}\",{h:e},{steps},{wall:.6e},{:.6e},{error:.6e},{:.6e}",
                steps as f64 / wall,
                error / peak
            )
            .unwrap();
        }
    }

    // ---- B3 -------------------------------------------------------------------------------
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/hub_beam.json"
    ))
    .unwrap();
    let body = BodyFile::from_json(&text).unwrap();
    let (end, h_ref) = if quick { (3.0, 5e-3) } else { (20.0, 2.5e-3) };
    let started = Instant::now();
    let (reference, _) = b3(&body, h_ref, MODELS[2].1, end).unwrap();
    let peak = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    println!(
        "\nB3 spin-up: {} s simulated, tip deflection in the hub frame every 20 ms; reference `full` at h = {h_ref:e} s ({:.0} s wall), peak |y| = {peak:.4} m\n",
        end,
        started.elapsed().as_secs_f64()
    );
    println!("| model | h (s) | steps | wall (s) | steps/s | max tip error (m) | error / peak |");
    println!("|---|---|---|---|---|---|---|");
    let steps_b3: &[f64] = if quick {
        &[2e-2, 1e-2]
    } else {
        &[2e-2, 1e-2, 5e-3]
    };
    for &(label, settings) in MODELS.iter().chain(&INTEGRATORS) {
        for &h in steps_b3 {
            let steps = (end / h).round() as usize;
            match b3(&body, h, settings, end) {
                Ok((y, wall)) => {
                    let error = max_error(&y, &reference);
                    println!(
                        "| {label} | {h:e} | {steps} | {wall:.2} | {:.0} | {error:.3e} | {:.2e} |",
                        steps as f64 / wall,
                        error / peak
                    );
                    writeln!(
                        csv,
                        "B3,\"{label}\",{h:e},{steps},{wall:.6e},{:.6e},{error:.6e},{:.6e}",
                        steps as f64 / wall,
                        error / peak
                    )
                    .unwrap();
                }
                Err(e) => println!("| {label} | {h:e} | {steps} | not run: {e} | | | |"),
            }
        }
    }
    if let Some(path) = csv_path {
        std::fs::write(&path, csv).unwrap();
        println!("\nCSV: {}", path.display());
    }
}
