//! The same numbers in every importer (docs/fmu.md, "The same numbers in every importer"):
//! importers that agree on the inputs and the communication step compute the step differently
//! (fmpy as the difference of two grid times, a loop with exact steps, OMSimulator by adding the
//! step to its time), and the fixed-point iteration's stopping point moved with the last bit
//! (2.5e-13 m and 1.9e-7 N apart on B1). A step within a few ulps of the last one, or of a whole
//! number of `solver.stepSize`, is taken as that step, so the trajectories are equal bit for bit.

mod common;
use common::*;

/// B1 under a 10 N step load for `steps` communication steps of `big_h`, the step given by
/// `step(k)` at the time given by `time(k)`; the tip deflection and the root reaction after each.
fn run(
    big_h: f64,
    steps: usize,
    time: impl Fn(usize) -> f64,
    step: impl Fn(usize) -> f64,
) -> Vec<(u64, u64)> {
    let mut s = initialized_default(&[("tip.force[2]", -10.0)]);
    (0..steps)
        .map(|k| {
            let h = step(k);
            assert!((h - big_h).abs() <= 4.0 * f64::EPSILON * (k as f64 + 1.0) * big_h);
            s.do_step(time(k), h).unwrap();
            (
                get(&mut s, "tip.position[2]").to_bits(),
                get(&mut s, "root.force[2]").to_bits(),
            )
        })
        .collect()
}

fn agree(big_h: f64, steps: usize) {
    let exact = run(big_h, steps, |k| k as f64 * big_h, |_| big_h);
    // fmpy: the grid t_k = k H, the step t_{k+1} − t_k.
    let fmpy = run(
        big_h,
        steps,
        |k| k as f64 * big_h,
        |k| (k + 1) as f64 * big_h - k as f64 * big_h,
    );
    // OMSimulator: t += H, the step exact, the time accumulated.
    let accumulated: Vec<f64> = (0..steps)
        .scan(0.0, |t, _| {
            let now = *t;
            *t += big_h;
            Some(now)
        })
        .collect();
    let oms = run(big_h, steps, |k| accumulated[k], |_| big_h);
    let jittered = (0..steps)
        .filter(|&k| (k + 1) as f64 * big_h - k as f64 * big_h != big_h)
        .count();
    assert!(
        jittered > 0,
        "the fmpy grid has no jittered step at H = {big_h}"
    );
    assert!(
        exact == fmpy,
        "fmpy's steps give other bits than exact steps"
    );
    assert!(
        exact == oms,
        "accumulated time gives other bits than exact steps"
    );
}

#[test]
fn a_grid_step_gives_the_same_bits_however_it_is_computed() {
    // H = solver.stepSize (1 ms): one internal step per communication step.
    agree(1e-3, 300);
}

#[test]
fn a_step_off_the_internal_grid_gives_the_same_bits_however_it_is_computed() {
    // H = 2.5 ms: three internal steps of 0.8333 ms, snapped to the last step taken.
    agree(2.5e-3, 120);
}
