//! B3 (Kane's beam spun up on a hub) through the slave for each model choice: the table of
//! issue 4. `cargo run --release --example b3_table [-- h [filter]]` (default h = 1e-2 s; `full`
//! is also run at h/4 as the yardstick; `filter` keeps the rows whose label contains it).
//!
//! Columns: tip deflection in the hub frame (m) at t = 2, 4, 6, 7, 8, 10, 12, 14 s, the peak and
//! its time, the largest |deflection| after T_s = 15 s, iterations per step and wall time.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::time::Instant;
#[path = "../tests/common/b3.rs"]
mod b3;
use b3::HubDrive;

/// A row of the table: label, step size and the Integer/Boolean settings.
type Case = (String, f64, Vec<(&'static str, i32)>);

struct Run {
    samples: Vec<f64>,
    peak: (f64, f64),
    late: f64,
    iterations: f64,
    wall: f64,
}

fn run(body: &BodyFile, h: f64, settings: &[(&str, i32)]) -> Result<Run, String> {
    let mut s = Slave::from_body(body.clone()).map_err(|e| e.message)?;
    s.setup_experiment(0.0, None, None).map_err(|e| e.message)?;
    s.enter_initialization_mode().map_err(|e| e.message)?;
    s.set_by_name("solver.stepSize", h).map_err(|e| e.message)?;
    // Measured at the fixed step h.
    s.set_by_name("model.accuracy", 0.0)
        .map_err(|e| e.message)?;
    for (name, value) in settings {
        s.set_by_name(name, f64::from(*value))
            .map_err(|e| e.message)?;
    }
    s.exit_initialization_mode().map_err(|e| e.message)?;
    let drive = HubDrive::new(&s);
    let times = [2.0, 4.0, 6.0, 7.0, 8.0, 10.0, 12.0, 14.0];
    let mut samples = vec![f64::NAN; times.len()];
    let (mut peak, mut late) = ((0.0, 0.0_f64), 0.0_f64);
    let steps = (20.0 / h).round() as usize;
    let started = Instant::now();
    for k in 0..steps {
        let t = k as f64 * h;
        let y = drive
            .step(&mut s, t, h)
            .map_err(|e| format!("t = {t}: {}", e.message))?;
        let t1 = t + h;
        for (j, &ts) in times.iter().enumerate() {
            if (t1 - ts).abs() < 0.5 * h {
                samples[j] = y;
            }
        }
        if y.abs() > peak.1.abs() {
            peak = (t1, y);
        }
        if t1 > 15.0 {
            late = late.max(y.abs());
        }
    }
    let wall = started.elapsed().as_secs_f64();
    let (internal, iterations) = s.solver_statistics();
    Ok(Run {
        samples,
        peak,
        late,
        iterations: iterations as f64 / internal as f64,
        wall,
    })
}

fn main() {
    let h: f64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1e-2);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/hub_beam.json"
    ))
    .unwrap();
    let body = BodyFile::from_json(&text).unwrap();
    println!("B3, {} (h = {h} s unless stated)\n", body.description);
    println!("| model | h (s) | y(2) | y(4) | y(6) | y(7) | y(8) | y(10) | y(12) | y(14) | peak (m) at t (s) | max after 15 s | iterations/step | wall (s) |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let stiffening = ["none", "inertial", "stress"];
    let mut cases: Vec<Case> = Vec::new();
    for f_nl in [0, 1] {
        for (k, name) in stiffening.iter().enumerate() {
            cases.push((
                format!(
                    "reduced strain, f_nl {}, stiffening {name}",
                    if f_nl == 1 { "on" } else { "off" }
                ),
                h,
                vec![
                    ("model.nonlinearForces", f_nl),
                    ("model.stiffening", k as i32 + 1),
                    ("model.auto", 0),
                ],
            ));
        }
    }
    for frames in [2, 5, 10, 20, 40] {
        for f_nl in [0, 1] {
            cases.push((
                format!(
                    "reduced strain, {frames} frames, f_nl {}",
                    if f_nl == 1 { "on" } else { "off" }
                ),
                h,
                vec![("model.nonlinearForces", f_nl), ("model.frames", frames)],
            ));
        }
    }
    // model.auto with both terms allowed (issue 8): switched on when their indicators say so.
    cases.push((
        "reducedStrain, auto (f_nl, inertial stiffening allowed)".into(),
        h,
        vec![
            ("model.nonlinearForces", 1),
            ("model.stiffening", 2),
            ("model.auto", 1),
        ],
    ));
    // The same with the plain fixed-point iteration (no Anderson acceleration).
    for (label, settings) in [
        ("f_nl off", vec![("model.auto", 0)]),
        (
            "f_nl on",
            vec![("model.nonlinearForces", 1), ("model.auto", 0)],
        ),
        (
            "stiffening stress",
            vec![("model.stiffening", 3), ("model.auto", 0)],
        ),
        (
            "40 frames, f_nl on",
            vec![("model.nonlinearForces", 1), ("model.frames", 40)],
        ),
    ] {
        let mut settings = settings;
        settings.push(("solver.andersonDepth", 0));
        cases.push((
            format!("reduced strain, {label}, plain iteration"),
            h,
            settings,
        ));
    }
    cases.push(("full".into(), h, vec![("model.formulation", 2)]));
    cases.push((
        "full (yardstick)".into(),
        h / 4.0,
        vec![("model.formulation", 2)],
    ));
    let filter = std::env::args().nth(2).unwrap_or_default();
    for (label, h, settings) in cases.into_iter().filter(|c| c.0.contains(&filter)) {
        match run(&body, h, &settings) {
            Ok(r) => {
                let y: Vec<String> = r.samples.iter().map(|v| format!("{v:+.4}")).collect();
                println!(
                    "| {label} | {h} | {} | {:+.4} at {:.2} | {:.4} | {:.2} | {:.1} |",
                    y.join(" | "),
                    r.peak.1,
                    r.peak.0,
                    r.late,
                    r.iterations,
                    r.wall
                );
            }
            Err(e) => println!("| {label} | {h} | not run: {e} |"),
        }
    }
}
