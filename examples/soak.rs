//! Soak run of the default body (issue 6): many steps, energy and memory watched.
//!
//! `cargo run --release --example soak [-- steps]` (default 1 000 000 steps of 1 ms, 1000 s of
//! simulated time; the energy is sampled every 10th step); `tests/soak.rs` runs 10⁴ steps with
//! the energy after every step and the same assertions.
//!
//! The case: B1 (the default cantilever) undamped, `solver.rhoInf = 1` (the trapezoidal rule:
//! no numerical dissipation), under a constant tip load of 10 N applied from t = 0, so the beam
//! swings about its static deflection for ever. The energy `E = T + V − F·(p − p₀)` (kinetic plus
//! strain energy minus the work of the constant tip load; the tip's reference point is the
//! weighted centroid of its face, where the load's power is exactly `F·ṗ`) is an invariant of the
//! motion. The trapezoidal rule conserves the discrete energy of a linear system exactly; what is
//! left is the iteration's tolerance (positions to 1e-10 of the body size per step) and the
//! co-rotated model's small non-linearity. Drift is judged against the error over the first tenth
//! of the run: if the error grew with time, the later windows would exceed it.
//!
//! Memory: the resident set size (`/proc/self/statm`) after the first 1 % of the steps and at the
//! end; `fmi2DoStep` allocates nothing (`tests/no_allocation.rs`), so it must stay flat.

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::time::Instant;

/// What a soak run measured.
#[derive(Debug, Clone)]
pub struct SoakReport {
    pub steps: usize,
    pub seconds: f64,
    /// `F δ`: the work scale of the load (J): 10 N × the tip's peak travel.
    pub energy_scale: f64,
    /// Largest `|E − E₀|` over the first 10 % of the steps and over each later tenth (J).
    pub first_window: f64,
    pub later_windows: Vec<f64>,
    /// `E − E₀` at the end (J).
    pub final_error: f64,
    /// Resident set size after 1 % of the steps and at the end (bytes).
    pub rss_start: u64,
    pub rss_end: u64,
    pub tip_range: (f64, f64),
}

fn rss_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: u64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    pages * 4096
}

fn vr(s: &Slave, name: &str) -> u32 {
    s.variables().by_name(name).unwrap().value_reference
}

/// `steps` steps of 1 ms of the case above; the energy is evaluated after every
/// `sample_every`-th step (reading the outputs costs about a quarter of a step).
pub fn soak(steps: usize, sample_every: usize) -> SoakReport {
    const LOAD: f64 = -10.0;
    const H: f64 = 1e-3;
    let mut s = Slave::from_body(BodyFile::default_body()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_real(vr(&s, "solver.rhoInf"), 1.0).unwrap();
    // The scheme's own drift at the fixed step.
    s.set_by_name("model.accuracy", 0.0).unwrap();
    s.set_real(vr(&s, "tip.force[3]"), LOAD).unwrap();
    s.exit_initialization_mode().unwrap();
    let (kinetic, strain, tip) = (
        vr(&s, "body.kineticEnergy"),
        vr(&s, "body.strainEnergy"),
        vr(&s, "tip.position[3]"),
    );
    let z0 = s.get_real(tip).unwrap();
    let energy = |s: &mut Slave| {
        let z = s.get_real(tip).unwrap();
        (
            s.get_real(kinetic).unwrap() + s.get_real(strain).unwrap() - LOAD * (z - z0),
            z - z0,
        )
    };
    let (e0, _) = energy(&mut s);
    let tenth = (steps / 10).max(1);
    let mut windows = vec![0.0_f64; steps.div_ceil(tenth)];
    let mut tip_range = (0.0_f64, 0.0_f64);
    let mut rss_start = rss_bytes();
    let started = Instant::now();
    for k in 0..steps {
        // Times as k h (no accumulation): what a careful importer sends.
        s.do_step(k as f64 * H, H).unwrap();
        if (k + 1) % sample_every != 0 {
            continue;
        }
        let (e, dz) = energy(&mut s);
        let w = &mut windows[k / tenth];
        *w = w.max((e - e0).abs());
        if (k + 1) % tenth < sample_every && steps >= 100_000 {
            // Progress of a long run: the tenth just completed.
            println!(
                "soak: {} steps, {:.0} s, max |E - E0| in this tenth {:.3e} J, RSS {} kB",
                k + 1,
                started.elapsed().as_secs_f64(),
                *w,
                rss_bytes() / 1024
            );
        }
        tip_range = (tip_range.0.min(dz), tip_range.1.max(dz));
        if (k + 1) / sample_every == (steps / 100).max(1) / sample_every {
            rss_start = rss_bytes();
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    let (e_end, _) = energy(&mut s);
    SoakReport {
        steps,
        seconds,
        energy_scale: LOAD.abs() * (tip_range.1 - tip_range.0),
        first_window: windows[0],
        later_windows: windows[1..].to_vec(),
        final_error: e_end - e0,
        rss_start,
        rss_end: rss_bytes(),
        tip_range,
    }
}

/// The assertions of the soak run (shared with `tests/soak.rs`).
pub fn check(r: &SoakReport) {
    // The motion is the expected one: the tip swings between 0 and twice the static deflection
    // (1.19 mm under 10 N, Timoshenko), so its range is about 2.4 mm.
    let range = r.tip_range.1 - r.tip_range.0;
    assert!((2.2e-3..2.6e-3).contains(&range), "tip range {range:e} m");
    // Energy: bounded by 5e-4 of the load's work scale over the whole run, and no window later
    // in the run exceeds twice the first one plus a tenth of that bound: a drift (an error
    // growing with time) would. The bound: without f_nl the co-rotated internal force is the
    // gradient of the strain energy only to first order in the frame's rotation (here about
    // 2e-3 rad), so E oscillates by a few 1e-4 of the scale (measured 1.3e-4, flat over 10⁴ and
    // 10⁶ steps).
    let bound = 5e-4 * r.energy_scale;
    let worst = r
        .later_windows
        .iter()
        .fold(r.first_window, |m, &w| m.max(w));
    assert!(worst <= bound, "energy error {worst:e} J > {bound:e} J");
    for (i, &w) in r.later_windows.iter().enumerate() {
        assert!(
            w <= 2.0 * r.first_window + 0.1 * bound,
            "window {}: energy error {w:e} J vs first window {:e} J: drift",
            i + 2,
            r.first_window
        );
    }
    // Memory flat: the resident set may grow by at most 1 MiB (page-granular noise) after the
    // first 1 % of the steps.
    assert!(
        r.rss_end <= r.rss_start + (1 << 20),
        "RSS grew from {} to {} bytes",
        r.rss_start,
        r.rss_end
    );
}

pub fn print(r: &SoakReport) {
    println!(
        "soak: {} steps of 1 ms in {:.1} s ({:.3} ms/step); tip range {:.4e} m; energy scale {:.4e} J; |E - E0| first tenth {:.3e} J, later tenths max {:.3e} J, final {:+.3e} J ({:.2e} of the scale); RSS {} kB after 1 % of the steps, {} kB at the end",
        r.steps,
        r.seconds,
        1e3 * r.seconds / r.steps as f64,
        r.tip_range.1 - r.tip_range.0,
        r.energy_scale,
        r.first_window,
        r.later_windows.iter().fold(0.0_f64, |m, &w| m.max(w)),
        r.final_error,
        r.final_error.abs() / r.energy_scale,
        r.rss_start / 1024,
        r.rss_end / 1024
    );
    println!(
        "soak: per tenth of the run, max |E - E0| (J): {:.3e} {:?}",
        r.first_window,
        r.later_windows
            .iter()
            .map(|w| format!("{w:.3e}"))
            .collect::<Vec<_>>()
    );
}

#[allow(dead_code)]
fn main() {
    let steps = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().expect("steps"));
    let r = soak(steps, 10);
    print(&r);
    check(&r);
    println!("soak: passed");
}
