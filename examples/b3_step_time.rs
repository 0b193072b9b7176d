//! B3 through the slave as an importer drives the FMU, for issue 17's bar: 20 s simulated, the
//! hub's inputs set every 10 ms communication step, the stop time defined (as fmpy and
//! OMSimulator define it: the time error control's horizon), the time spent inside `do_step`
//! only (the call `fmi2DoStep` makes), and the tip deflection against `full` on the same mesh.
//!
//! `cargo run --release --example b3_step_time [-- rounds]` (default 5)
//!
//! Rows, each a fresh instance per round, the rounds interleaved (every row once per round,
//! in turn), the median over the rounds; setup (`exit_initialization_mode`: matrices, modes,
//! the first factorization) apart:
//! * the defaults plus `model.modes = auto` (the reduced body; `model.auto` takes its
//!   stiffening from the driving motion);
//! * the same with `model.auto = false` (the reduced body without stiffening, as it stood);
//! * the defaults (the mesh body; `model.auto` takes one slab per element layer);
//! * the mesh body with `model.frames = 10`;
//! * the reduced body with `model.frames = 10` (its slabs on its coordinates).
//!
//! The yardstick: `model.formulation = full` at the fixed step 2.5 ms, sampled every 10 ms.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::time::Instant;
#[path = "../tests/common/b3.rs"]
mod b3;
use b3::HubDrive;

const END: f64 = 20.0;
const H: f64 = 1e-2;

/// A run's tip deflections at every communication point, its setup and `do_step` times (s),
/// and its internal steps.
struct Run {
    tip: Vec<f64>,
    setup: f64,
    stepping: f64,
    steps: u64,
}

fn run(body: &BodyFile, settings: &[(&str, f64)], h_internal: Option<f64>) -> Run {
    let started = Instant::now();
    let mut s = Slave::from_body(body.clone()).unwrap();
    s.setup_experiment(0.0, Some(END), None).unwrap();
    s.enter_initialization_mode().unwrap();
    for &(name, value) in settings {
        s.set_by_name(name, value).unwrap();
    }
    s.exit_initialization_mode().unwrap();
    let setup = started.elapsed().as_secs_f64();
    let drive = HubDrive::new(&s);
    let n = (END / H).round() as usize;
    let mut tip = Vec::with_capacity(n);
    let mut stepping = 0.0;
    let substeps = h_internal.map_or(1, |h| (H / h).round() as usize);
    for k in 0..n {
        let t = k as f64 * H;
        drive.set_hub(&mut s, t).unwrap();
        let started = Instant::now();
        // The reference steps its finer grid between input updates, as an importer with a
        // finer communication step would.
        for j in 0..substeps {
            let hs = H / substeps as f64;
            s.do_step(t + j as f64 * hs, hs).unwrap();
        }
        stepping += started.elapsed().as_secs_f64();
        tip.push(drive.tip_deflection(&mut s, t + H).unwrap());
    }
    Run {
        tip,
        setup,
        stepping,
        steps: s.solver_statistics().0,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() {
    let rounds: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/hub_beam.json"
    ))
    .unwrap();
    let body = BodyFile::from_json(&text).unwrap();
    let reference = run(
        &body,
        &[
            ("model.formulation", 2.0),
            ("model.accuracy", 0.0),
            ("solver.stepSize", H / 4.0),
        ],
        Some(H / 4.0),
    );
    let peak = reference.tip.iter().fold(0.0_f64, |m, y| m.max(y.abs()));
    let rows: [(&str, Vec<(&str, f64)>); 5] = [
        (
            "the defaults + `model.modes = auto`",
            vec![("model.modes", -1.0)],
        ),
        (
            "`model.modes = auto`, `model.auto = false` (no stiffening)",
            vec![("model.modes", -1.0), ("model.auto", 0.0)],
        ),
        ("the defaults (mesh, `model.auto`'s slabs)", vec![]),
        ("mesh, `model.frames = 10`", vec![("model.frames", 10.0)]),
        (
            "`model.modes = auto`, `model.frames = 10` (reduced, the slabs on its coordinates)",
            vec![("model.modes", -1.0), ("model.frames", 10.0)],
        ),
    ];
    let mut times: Vec<(Vec<f64>, Vec<f64>)> = vec![(Vec::new(), Vec::new()); rows.len()];
    let mut results: Vec<Option<(f64, u64)>> = vec![None; rows.len()];
    for _ in 0..rounds {
        for (k, (_, settings)) in rows.iter().enumerate() {
            let r = run(&body, settings, None);
            let error = r
                .tip
                .iter()
                .zip(&reference.tip)
                .fold(0.0_f64, |m, (y, y_ref)| m.max((y - y_ref).abs()))
                / peak;
            times[k].0.push(r.setup);
            times[k].1.push(r.stepping);
            results[k] = Some((error, r.steps));
        }
    }
    println!(
        "B3 ({}), 20 s simulated, hub inputs every 10 ms, stop time defined; `full` at 2.5 ms as the yardstick ({:.1} s of stepping, peak |y| = {peak:.4} m). Median of {rounds} interleaved rounds, release build.\n",
        body.description, reference.stepping
    );
    println!("| model | largest deviation from `full` / peak | internal steps | setup (s) | inside do_step (s) |");
    println!("|---|---|---|---|---|");
    for (k, (label, _)) in rows.iter().enumerate() {
        let (error, steps) = results[k].unwrap();
        println!(
            "| {label} | {error:.2e} | {steps} | {:.3} | {:.3} |",
            median(times[k].0.clone()),
            median(times[k].1.clone())
        );
    }
}
