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
//! `--auto-only`: only the `model.auto` table (below).
//!
//! `--quick` (for checking the task): B1 at two step sizes against h = 1e-4 s, B3 over 3 s
//! against `full` at 5e-3 s.
//!
//! Models: `reducedStrain` with `f_nl` off (the default) and on, with `f_nl` and inertial
//! stiffening both forced on (`model.auto = false`) and both allowed under `model.auto`, and
//! `full`; Radau IIA and the reduced body with 8 modes (`OTHERS`). A last table (`model.auto`,
//! issue 8) puts `auto` against `all on`: wall time, time saved, the largest difference of the
//! two (it must stay within the iteration tolerance's reach) and that of `all off` (the effect
//! of the terms) on B1 with 10 N and 0.01 N step loads (h = 1 ms, 0.2 s) and on B3
//! (h = 1e-2 s); its CSV rows have `relative_error` = difference / effect of the terms. Prints
//! Markdown tables; with `--csv FILE` also writes one row per run:
//! `problem,model,h,steps,wall_s,steps_per_s,max_error_m,relative_error` (model quoted).

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::fmt::Write as _;
use std::time::Instant;
#[path = "../tests/common/b3.rs"]
mod b3;

/// Integer/Boolean settings by name, as in `b3_table.rs`.
type Settings = &'static [(&'static str, i32)];

const MODELS: [(&str, Settings); 5] = [
    (
        "reducedStrain, f_nl off",
        &[("model.formulation", 1), ("model.auto", 0)],
    ),
    (
        "reducedStrain, f_nl on",
        &[
            ("model.formulation", 1),
            ("model.nonlinearForces", 1),
            ("model.auto", 0),
        ],
    ),
    (
        "reducedStrain, all on (f_nl, inertial stiffening)",
        &[
            ("model.formulation", 1),
            ("model.nonlinearForces", 1),
            ("model.stiffening", 2),
            ("model.auto", 0),
        ],
    ),
    (
        "reducedStrain, auto (f_nl, inertial stiffening allowed)",
        &[
            ("model.formulation", 1),
            ("model.nonlinearForces", 1),
            ("model.stiffening", 2),
            ("model.auto", 1),
        ],
    ),
    ("full", &[("model.formulation", 2)]),
];

/// The `all on` and `auto` rows, compared with each other in the `model.auto` table.
const ALL_ON: usize = 2;
const AUTO: usize = 3;

/// Other integrators and the reduced body (issues 7 and 8): Radau IIA (order 5,
/// `solver.integrator = radauIIA`; one real and one complex factorization per step size) and
/// the reduced body with 8 fixed-interface modes (`model.modes = 8`, generalized-α).
const OTHERS: [(&str, Settings); 2] = [
    (
        "radauIIA, reducedStrain, f_nl off",
        &[("model.formulation", 1), ("solver.integrator", 3)],
    ),
    (
        "reduced body (modes = 8), f_nl off",
        &[("model.formulation", 1), ("model.modes", 8)],
    ),
];

fn vr(s: &Slave, name: &str) -> u32 {
    s.variables().by_name(name).unwrap().value_reference
}

fn slave(body: &BodyFile, h: f64, settings: &[(&str, i32)]) -> Slave {
    let mut s = Slave::from_body(body.clone()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_by_name("solver.stepSize", h).unwrap();
    // Measured at the fixed step h.
    s.set_by_name("model.accuracy", 0.0).unwrap();
    for (name, value) in settings {
        s.set_by_name(name, f64::from(*value)).unwrap();
    }
    s
}

/// B1: tip y (m) at every communication point (2 ms) and the wall time of the stepping loop.
fn b1(body: &BodyFile, h: f64, settings: &[(&str, i32)], end: f64) -> (Vec<f64>, f64) {
    b1_load(body, h, settings, end, 10.0)
}

/// [`b1`] with a step load of `load` (N, −y).
fn b1_load(
    body: &BodyFile,
    h: f64,
    settings: &[(&str, i32)],
    end: f64,
    load: f64,
) -> (Vec<f64>, f64) {
    let mut s = slave(body, h, settings);
    s.set_real(vr(&s, "tip.force[2]"), -load).unwrap();
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

/// A row of the `model.auto` table: wall times of `all on` and `auto` (s), their largest
/// difference and that of `all off` from `all on` (m), and the iteration tolerance (m).
struct AutoRow {
    label: String,
    h: f64,
    steps: usize,
    walls: [f64; 2],
    difference: f64,
    effect: f64,
    tolerance: f64,
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
    // `--auto-only`: only the model.auto table.
    let auto_only = std::env::args().any(|a| a == "--auto-only");

    if !auto_only {
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
        for &(label, settings) in MODELS.iter().chain(&OTHERS) {
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
    }
    // ---- B3 -------------------------------------------------------------------------------
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/hub_beam.json"
    ))
    .unwrap();
    let body = BodyFile::from_json(&text).unwrap();
    let (end, h_ref) = if quick { (3.0, 5e-3) } else { (20.0, 2.5e-3) };
    if !auto_only {
        let started = Instant::now();
        let (reference, _) = b3(&body, h_ref, MODELS[4].1, end).unwrap();
        let peak = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        println!(
        "\nB3 spin-up: {} s simulated, tip deflection in the hub frame every 20 ms; reference `full` at h = {h_ref:e} s ({:.0} s wall), peak |y| = {peak:.4} m\n",
        end,
        started.elapsed().as_secs_f64()
    );
        println!(
            "| model | h (s) | steps | wall (s) | steps/s | max tip error (m) | error / peak |"
        );
        println!("|---|---|---|---|---|---|---|");
        let steps_b3: &[f64] = if quick {
            &[2e-2, 1e-2]
        } else {
            &[2e-2, 1e-2, 5e-3]
        };
        for &(label, settings) in MODELS.iter().chain(&OTHERS) {
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
    }
    // ---- model.auto ---------------------------------------------------------------------------
    // auto against all features on (both allowed / both forced): the time saved where auto
    // skips a term, and the price of its indicators where it does not; the difference must stay
    // within the iteration tolerance's reach, far below the effect of the terms (all off).
    println!("\nmodel.auto (issue 8): `auto` (f_nl and inertial stiffening allowed) against `all on` (both forced) and `all off`; wall: median of {repeats} runs\n");
    println!("| problem | h (s) | steps | wall all on (ms) | wall auto (ms) | time saved | max abs(auto − all on) (m) | max abs(all off − all on) (m) | tolerance × size (m) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let b1_body = BodyFile::default_body();
    let b1_end = if quick { 0.1 } else { 0.2 };
    let mut rows: Vec<AutoRow> = Vec::new();
    for load in [10.0, 0.01] {
        let h = 1e-3;
        let run = |m: usize| {
            let mut walls = Vec::new();
            let mut y = Vec::new();
            for _ in 0..repeats {
                let (yk, wall) = b1_load(&b1_body, h, MODELS[m].1, b1_end, load);
                y = yk;
                walls.push(wall);
            }
            (y, median(walls))
        };
        let (y_on, w_on) = run(ALL_ON);
        let (y_auto, w_auto) = run(AUTO);
        let (y_off, _) = b1_load(&b1_body, h, MODELS[0].1, b1_end, load);
        rows.push(AutoRow {
            label: format!("auto: B1, {load} N step load, {b1_end} s"),
            h,
            steps: (b1_end / h).round() as usize,
            walls: [w_on, w_auto],
            difference: max_error(&y_auto, &y_on),
            effect: max_error(&y_off, &y_on),
            tolerance: b1_body.solver.tolerance * 1.0004,
        });
    }
    {
        let h = 1e-2;
        let mut walls = [Vec::new(), Vec::new()];
        let mut ys = [Vec::new(), Vec::new()];
        for _ in 0..repeats {
            for (k, m) in [ALL_ON, AUTO].into_iter().enumerate() {
                let (y, wall) = b3(&body, h, MODELS[m].1, end).unwrap();
                ys[k] = y;
                walls[k].push(wall);
            }
        }
        let [w_on, w_auto] = walls.map(median);
        let (y_off, _) = b3(&body, h, MODELS[0].1, end).unwrap();
        rows.push(AutoRow {
            label: format!("auto: B3 spin-up, {end} s"),
            h,
            steps: (end / h).round() as usize,
            walls: [w_on, w_auto],
            difference: max_error(&ys[1], &ys[0]),
            effect: max_error(&y_off, &ys[0]),
            tolerance: body.solver.tolerance * 10.0005,
        });
    }
    for AutoRow {
        label,
        h,
        steps,
        walls: [w_on, w_auto],
        difference: d_auto,
        effect: d_off,
        tolerance,
    } in rows
    {
        println!(
            "| {label} | {h:e} | {steps} | {:.1} | {:.1} | {:.0} % | {d_auto:.2e} | {d_off:.2e} | {tolerance:.1e} |",
            1e3 * w_on,
            1e3 * w_auto,
            100.0 * (1.0 - w_auto / w_on)
        );
        for (model, wall, error) in [("all on", w_on, 0.0), ("auto", w_auto, d_auto)] {
            writeln!(
                csv,
                "\"{label}\",\"{model}\",{h:e},{steps},{wall:.6e},{:.6e},{error:.6e},{:.6e}",
                steps as f64 / wall,
                error / d_off.max(f64::MIN_POSITIVE)
            )
            .unwrap();
        }
    }
    if let Some(path) = csv_path {
        std::fs::write(&path, csv).unwrap();
        println!("\nCSV: {}", path.display());
    }
}
