//! Inputs are samples in time (README, "Inputs are samples in time"): inputs set at time
//! `t_s` describe the interface at `t_s` and are extrapolated from there, however many steps the
//! importer takes before it sets them again. An importer that steps twice on one input update
//! (OMSimulator's `stepUntil` does when its accumulated time falls an ulp short) must get the
//! answer of one step over both.

mod common;
use common::b3::HubDrive;
use common::*;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// B3 with `settings` for `steps` communication steps of 10 ms, once whole and once as two
/// half steps per input update: per update, `each(slave split in halves, its tip deflection,
/// the whole-step tip deflection, the time)`; the two slaves at the end (whole, split).
fn whole_and_split(
    settings: &[(&str, f64)],
    steps: usize,
    mut each: impl FnMut(&mut flexbody::slave::Slave, &mut flexbody::slave::Slave, f64, f64, f64),
) -> (flexbody::slave::Slave, flexbody::slave::Slave) {
    let mut whole = initialized(example_body("hub_beam"), settings);
    let mut split = initialized(example_body("hub_beam"), settings);
    let drive = HubDrive::new(&whole);
    let big_h = 1e-2;
    for k in 0..steps {
        let t = k as f64 * big_h;
        let y_whole = drive.step(&mut whole, t, big_h).unwrap();
        drive.set_hub(&mut split, t).unwrap();
        split.do_step(t, 0.5 * big_h).unwrap();
        split.do_step(t + 0.5 * big_h, 0.5 * big_h).unwrap();
        let y_split = drive.tip_deflection(&mut split, t + big_h).unwrap();
        each(&mut split, &mut whole, y_split, y_whole, t);
    }
    (whole, split)
}

/// B3 spun up for 8 s (the peak of the lag is at about 7 s) with the hub inputs set once per
/// H = 0.01 s: once with one step of H per update, once with two steps of H/2 per update. The
/// internal step is H/2 in both runs (solver.stepSize = 0.005), so both solve the same discrete
/// equations and differ only by rounding and by where the fixed-point iteration stops (its
/// tolerance is 1e-10 × 10 m per step, some 1e-9 m over 1600 steps): the tip curves must agree to
/// 1e-6 m, against a peak of about 0.5 m. Before the inputs were samples in time, the second
/// half-step restarted the hub's frame from the pose given for the first and the curve left by
/// tens of per cent of the peak.
#[test]
fn b3_with_two_steps_per_input_update_follows_b3_with_one() {
    // One model throughout (model.accuracy = 0: no error control and no model.auto slabs, whose
    // switch would fall on different communication points in the two runs).
    let settings = [("solver.stepSize", 5e-3), ("model.accuracy", 0.0)];
    let (mut worst, mut peak) = (0.0_f64, 0.0_f64);
    whole_and_split(&settings, 800, |_, _, y_split, y_whole, _| {
        worst = worst.max((y_split - y_whole).abs());
        peak = peak.max(y_whole.abs());
    });
    println!("peak {peak:.4} m, largest difference {worst:.3e} m");
    assert!(peak > 0.3, "the spin-up bends the beam: peak {peak} m");
    assert!(
        worst < 1e-6,
        "split steps leave the whole-step curve by {worst:e} m"
    );
}

/// The driven cantilever's root turned at ω = 1 rad/s about z: once with the angular velocity
/// set at t = 0 only (the pose is the FMU's extrapolation), once with the rotation of the same
/// schedule set before every step. The two describe the same driving frame, so the runs solve the
/// same equations up to the rounding of `exp([ω]× τ)` composed over the steps: the body's
/// rotation agrees to 1e-9 (its angle is 1 rad at the end).
#[test]
fn a_motion_input_set_once_goes_on_along_its_velocity() {
    let omega = 1.0;
    let start = [("root.angularVelocity[3]", omega)];
    let mut once = initialized(example_body("driven_cantilever"), &start);
    let mut every = initialized(example_body("driven_cantilever"), &start);
    let h = 1e-2;
    for k in 0..100 {
        let t = k as f64 * h;
        let q = *Rotation3::from_axis_angle(&Vector3::z_axis(), omega * t).matrix();
        set_rotation(&mut every, "root.rotation", &q);
        once.do_step(t, h).unwrap();
        every.do_step(t, h).unwrap();
    }
    let rotation = |s: &mut flexbody::slave::Slave| {
        Matrix3::from_fn(|r, c| get(s, &format!("body.rotation[{}]", 3 * r + c + 1)))
    };
    let (q_once, q_every) = (rotation(&mut once), rotation(&mut every));
    let angle = q_once[(1, 0)].atan2(q_once[(0, 0)]);
    assert!(
        (angle - omega * 1.0).abs() < 1e-3,
        "the root turned by {angle} rad in 1 s at 1 rad/s"
    );
    let difference = (q_once - q_every).amax();
    assert!(difference < 1e-9, "the two runs differ by {difference:e}");
}

/// The driven cantilever's root turned by `θ = t²/2` about z for 0.4 s with internal steps of
/// 2.5 ms (`model.accuracy = 0`): its pose and angular velocity set at t = 0, then from 10 ms on
/// every `every` seconds (`pose_once`: the pose only at t = 0, then only the angular velocity);
/// `angular(t)` gives the angular velocity set at `t`. Returns the tip's position at the end.
fn root_turned(every: f64, pose_once: bool, angular: impl Fn(f64) -> f64) -> Vector3<f64> {
    let settings = [("model.accuracy", 0.0), ("solver.stepSize", 2.5e-3)];
    let mut s = initialized(example_body("driven_cantilever"), &settings);
    let first = 1e-2;
    let updates = (0..1)
        .map(|_| 0.0)
        .chain((0..((0.4 - first) / every).round() as usize).map(|k| first + k as f64 * every));
    for t in updates {
        if t == 0.0 || !pose_once {
            let q = *Rotation3::from_axis_angle(&Vector3::z_axis(), 0.5 * t * t).matrix();
            set_rotation(&mut s, "root.rotation", &q);
        }
        set(&mut s, "root.angularVelocity[3]", angular(t));
        let step = if t == 0.0 { first } else { every };
        s.do_step(t, step).unwrap();
    }
    vector(&mut s, "tip.position")
}

/// Velocities given with the pose are samples of the motion, so between updates the frame
/// follows their rates (docs/fmu.md, "Inputs are samples in time"): the root turned by
/// `θ = t²/2` with `ω = t` given every 10 ms is extrapolated exactly from the second update on
/// (`θ + ω τ + τ²/2`; the first 10 ms, before a rate is known, are held alike in both runs), so
/// the run is the run with inputs every 2.5 ms to the iteration's tolerance (the same internal
/// steps; 1e-10 × 1 m per step; measured 1e-13 m). Held at constant velocities between updates
/// the two were 5.6e-5 m apart (the tip deflects about 1e-4 m). Taken for samples too, secant
/// velocities put a jump at every update (1.9e-3 m at the tip). A master that gives secant velocities instead,
/// `(θ_{k+1} − θ_k)/H` (docs/coupling.md), puts its next pose where the held path ends: the FMU
/// holds them, and the run with the pose set at every update is the run with the pose set once,
/// to the rounding of the composed turns.
#[test]
fn velocities_given_with_the_pose_are_followed_with_their_rates_and_secants_are_held() {
    let point = |t: f64| t;
    let (coarse, fine) = (
        root_turned(1e-2, false, point),
        root_turned(2.5e-3, false, point),
    );
    let apart = (coarse - fine).norm();
    println!("point velocities every 10 ms against every 2.5 ms: {apart:.3e} m");
    assert!(apart < 1e-9, "{apart:e} m");
    let h = 1e-2;
    let secant = move |t: f64| ((t + h) * (t + h) - t * t) / (2.0 * h);
    let (every, once) = (root_turned(h, false, secant), root_turned(h, true, secant));
    let apart = (every - once).norm();
    println!("secant velocities, the pose set every step against once: {apart:.3e} m");
    assert!(apart < 1e-9, "{apart:e} m");
}

/// A sampled motion whose angular velocity turns (`ω` not parallel to `α`): the root turned by
/// `Q(t) = R_z(t²) R_x(t)` (`ω = 2t e_z + R_z e_x`), pose and angular velocity given every
/// 10 ms, stepped once or as two halves per update with the same internal steps of 5 ms. The
/// frame is one path from each update (`DrivingFrame`), so the halves' second step takes the
/// frame the whole step takes at the same time: the tips agree to the iteration's tolerance
/// (1e-10 × 1 m per step; measured 2e-13 m). Carried from half step to half step instead
/// (its turns composed, its rates measured from the half step) it was 7.9e-6 m off.
#[test]
fn a_turning_axis_sampled_at_every_update_is_one_path_however_it_is_stepped() {
    let pose = |t: f64| {
        *(Rotation3::from_axis_angle(&Vector3::z_axis(), t * t)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), t))
        .matrix()
    };
    let omega = |t: f64| {
        Vector3::new(0.0, 0.0, 2.0 * t)
            + Rotation3::from_axis_angle(&Vector3::z_axis(), t * t) * Vector3::new(1.0, 0.0, 0.0)
    };
    let run = |halves: bool| {
        let settings = [("model.accuracy", 0.0), ("solver.stepSize", 5e-3)];
        let mut s = initialized(example_body("driven_cantilever"), &settings);
        let h = 1e-2;
        for k in 0..40 {
            let t = k as f64 * h;
            set_rotation(&mut s, "root.rotation", &pose(t));
            let w = omega(t);
            for (c, name) in [
                "root.angularVelocity[1]",
                "root.angularVelocity[2]",
                "root.angularVelocity[3]",
            ]
            .iter()
            .enumerate()
            {
                set(&mut s, name, w[c]);
            }
            if halves {
                s.do_step(t, 0.5 * h).unwrap();
                s.do_step(t + 0.5 * h, 0.5 * h).unwrap();
            } else {
                s.do_step(t, h).unwrap();
            }
        }
        vector(&mut s, "tip.position")
    };
    let (whole, halves) = (run(false), run(true));
    let apart = (whole - halves).norm();
    println!("one step per update against two: {apart:.3e} m");
    assert!(apart < 1e-9, "{apart:e} m");
}

/// A force ramp given by its derivative once, at t = 0, over ten steps, against the same ramp
/// given as value and derivative before every step: both describe the load `u'·t`, so the runs
/// solve the same equations and the tip agrees to the iteration's tolerance (solver.tolerance ×
/// the body's size, 1e-10 m; the motion is 1e-4 m). A derivative
/// set later without a value continues the load from where it is: the value is moved to the new
/// sample time first (−1 N at 0.01 s), which the input reads back.
#[test]
fn a_force_derivative_set_once_is_relative_to_when_it_was_set() {
    let mut once = initialized_default(&[]);
    let mut every = initialized_default(&[]);
    let force = vr(&once, "tip.force[2]");
    let h = 1e-3;
    let y0 = get(&mut once, "tip.position[2]");
    once.set_real_input_derivatives(&[force], &[1], &[-100.0])
        .unwrap();
    for k in 0..10 {
        let t = k as f64 * h;
        every.set_real(force, -100.0 * t).unwrap();
        every
            .set_real_input_derivatives(&[force], &[1], &[-100.0])
            .unwrap();
        once.do_step(t, h).unwrap();
        every.do_step(t, h).unwrap();
    }
    // At t = 0.01 s the ramp has reached −1 N; a new slope from there on, no jump.
    once.set_real_input_derivatives(&[force], &[1], &[50.0])
        .unwrap();
    let load = once.get_real(force).unwrap();
    assert!((load + 1.0).abs() < 1e-12, "the load at 0.01 s is {load} N");
    every.set_real(force, -1.0).unwrap();
    every
        .set_real_input_derivatives(&[force], &[1], &[50.0])
        .unwrap();
    for k in 10..20 {
        once.do_step(k as f64 * h, h).unwrap();
        every.do_step(k as f64 * h, h).unwrap();
    }
    let (y_once, y_every) = (
        get(&mut once, "tip.position[2]") - y0,
        get(&mut every, "tip.position[2]") - y0,
    );
    assert!(y_every.abs() > 1e-7, "the ramp moves the tip: {y_every} m");
    assert!(
        (y_once - y_every).abs() < 1e-10,
        "derivative set once: tip at {y_once} m; ramp set every step: {y_every} m"
    );
}

/// The sample times are part of the FMU state: a state saved between two input updates and
/// restored after later updates gives the steps it gave before, bit for bit.
#[test]
fn the_sample_times_are_part_of_the_fmu_state() {
    let mut s = initialized(example_body("hub_beam"), &[]);
    let drive = HubDrive::new(&s);
    let big_h = 1e-2;
    for k in 0..50 {
        drive.step(&mut s, k as f64 * big_h, big_h).unwrap();
    }
    // Inputs set at 0.5 s, one step taken: the state at 0.51 s has inputs sampled at 0.5 s.
    drive.set_hub(&mut s, 0.5).unwrap();
    s.do_step(0.5, big_h).unwrap();
    let saved = s.get_state();
    s.do_step(0.51, big_h).unwrap();
    let expected = drive.tip_deflection(&mut s, 0.52).unwrap();
    // Later updates move the sample time on; restoring must bring 0.5 s back.
    drive.set_hub(&mut s, 0.52).unwrap();
    s.do_step(0.52, big_h).unwrap();
    drive.set_hub(&mut s, 0.53).unwrap();
    s.set_state(&saved).unwrap();
    s.do_step(0.51, big_h).unwrap();
    assert_eq!(drive.tip_deflection(&mut s, 0.52).unwrap(), expected);
    // And through the byte form, into a fresh instance.
    let mut bytes = Vec::new();
    saved.write_bytes(&mut bytes);
    let mut fresh = initialized(example_body("hub_beam"), &[]);
    let restored = fresh.state_from_bytes(&bytes).unwrap();
    fresh.set_state(&restored).unwrap();
    fresh.do_step(0.51, big_h).unwrap();
    assert_eq!(drive.tip_deflection(&mut fresh, 0.52).unwrap(), expected);
}

/// B3 at `model.accuracy = 1e-3` for 3 s, its hub inputs set every 10 ms, once with one step
/// per input update and once with two half steps. The internal steps after a motion input's
/// jump are not estimated (`MOTION_RINGING_STEPS`: the kink of the hub's sampled motion rings in
/// the held coordinates' accelerations, which the estimate reads as error), so the split run is
/// judged as the whole one: it refines no further than the whole run (2.5 ms at the slabs'
/// switch, both) and takes at most twice its internal steps (688 against 428). Before, its
/// second half steps were estimated on that ringing: it refined to 0.16 ms at the slabs'
/// switch and took 4 094 internal steps against 300 over these 3 s (13.6 times), and over 20 s
/// 479 460 against 3 506. (Its half steps then kept the top rung, 10 ms, which takes a 5 ms
/// step whole as the 5 ms rung does: a refinement from it changed nothing, and the estimate
/// floor took that for noise. A refinement now counts from the rung of the step taken.)
#[test]
fn an_importer_that_splits_steps_is_judged_as_one_that_steps_once() {
    let settings = [("model.accuracy", 1e-3)];
    let (mut worst, mut finest, mut finest_whole) = (0.0_f64, f64::INFINITY, f64::INFINITY);
    let (whole, split) = whole_and_split(&settings, 300, |split, whole, y_split, y_whole, _| {
        worst = worst.max((y_split - y_whole).abs());
        finest = finest.min(split.controlled_step_size());
        finest_whole = finest_whole.min(whole.controlled_step_size());
    });
    let (split_steps, whole_steps) = (split.solver_statistics().0, whole.solver_statistics().0);
    println!(
        "finest rung {finest:e} s (whole steps {finest_whole:e} s); internal steps split {split_steps}, whole {whole_steps}; largest difference {worst:.3e} m"
    );
    assert!(
        finest >= finest_whole,
        "the split run refined further than the whole one"
    );
    // Two half steps per update, each one internal step; a few redone (the first steps, before
    // any input jumps, are estimated).
    assert!(
        split_steps <= 2 * whole_steps + 20,
        "the split run took {split_steps} internal steps against {whole_steps}"
    );
    assert!(
        worst < 2.0e-3 * 0.571,
        "split steps leave the whole-step curve by {worst:e} m"
    );
}

/// Whether a step's inputs jump is told against the driving frames of the step before, which
/// are part of the FMU state: a state saved after a jump of the root's angular velocity and
/// restored after a later, different jump gives the steps it gave before, bit for bit and with
/// the same internal steps (the error control does not estimate the step after a jump, so a
/// stale frame made the restored step look like one: docs/fmu.md, "Inputs are samples in time").
#[test]
fn the_driving_frames_of_the_last_step_are_part_of_the_fmu_state() {
    let mut s = initialized(
        example_body("driven_cantilever"),
        &[("model.accuracy", 1e-3), ("solver.stepSize", 1e-2)],
    );
    let h = 1e-2;
    let omega = |s: &mut flexbody::slave::Slave, w: f64| set(s, "root.angularVelocity[3]", w);
    for k in 0..5 {
        s.do_step(k as f64 * h, h).unwrap();
    }
    omega(&mut s, 2.0);
    s.do_step(5.0 * h, h).unwrap();
    let saved = s.get_state();
    let steps = s.solver_statistics().0;
    s.do_step(6.0 * h, h).unwrap();
    let taken = s.solver_statistics().0 - steps;
    let expected = get(&mut s, "tip.position[2]");
    // A later jump, then back to the saved state.
    omega(&mut s, 3.0);
    s.do_step(7.0 * h, h).unwrap();
    s.set_state(&saved).unwrap();
    s.do_step(6.0 * h, h).unwrap();
    println!("internal steps {taken}, tip y {expected:e}");
    // The jump came after a calm stretch (a step of the driving velocity, not a sampled motion):
    // only its first internal step goes unestimated, and the control refines for the body's
    // response (35 internal steps; 8 unestimated steps would take one and end 6 % off).
    assert!(taken > 1, "the step after a jump from calm was not refined");
    assert_eq!(s.solver_statistics().0 - steps, taken);
    assert_eq!(get(&mut s, "tip.position[2]").to_bits(), expected.to_bits());
    // Through the byte form into a fresh instance.
    let mut bytes = Vec::new();
    saved.write_bytes(&mut bytes);
    let mut fresh = initialized(
        example_body("driven_cantilever"),
        &[("model.accuracy", 1e-3), ("solver.stepSize", 1e-2)],
    );
    let restored = fresh.state_from_bytes(&bytes).unwrap();
    fresh.set_state(&restored).unwrap();
    fresh.do_step(6.0 * h, h).unwrap();
    assert_eq!(fresh.solver_statistics().0 - steps, taken);
    assert_eq!(
        get(&mut fresh, "tip.position[2]").to_bits(),
        expected.to_bits()
    );
}

/// Where a sampled motion's ringing stands is part of the FMU state (the internal steps since its
/// last jump and whether it is sampled, `MOTION_RINGING_STEPS`): B3 at `model.accuracy = 1e-3`
/// as two half steps per input update, saved after the first half step of an update (inside the
/// window, where the second half step is not estimated) and restored into a fresh instance
/// through the byte form, takes the same internal steps to the same bits. Restored without them
/// (the window closed) the second half step would be estimated on the ringing and refined.
#[test]
fn a_sampled_motions_ringing_is_part_of_the_fmu_state() {
    let settings = [("model.accuracy", 1e-3)];
    let mut s = initialized(example_body("hub_beam"), &settings);
    let drive = HubDrive::new(&s);
    let h = 1e-2;
    for k in 0..150 {
        let t = k as f64 * h;
        drive.set_hub(&mut s, t).unwrap();
        s.do_step(t, 0.5 * h).unwrap();
        s.do_step(t + 0.5 * h, 0.5 * h).unwrap();
    }
    let t = 150.0 * h;
    drive.set_hub(&mut s, t).unwrap();
    s.do_step(t, 0.5 * h).unwrap();
    let saved = s.get_state();
    let steps = s.solver_statistics().0;
    s.do_step(t + 0.5 * h, 0.5 * h).unwrap();
    let taken = s.solver_statistics().0 - steps;
    let expected = drive.tip_deflection(&mut s, t + h).unwrap();
    let mut bytes = Vec::new();
    saved.write_bytes(&mut bytes);
    let mut fresh = initialized(example_body("hub_beam"), &settings);
    let restored = fresh.state_from_bytes(&bytes).unwrap();
    fresh.set_state(&restored).unwrap();
    fresh.do_step(t + 0.5 * h, 0.5 * h).unwrap();
    println!("internal steps {taken}, tip deflection {expected:e} m");
    assert_eq!(fresh.solver_statistics().0 - steps, taken);
    assert_eq!(
        drive.tip_deflection(&mut fresh, t + h).unwrap().to_bits(),
        expected.to_bits()
    );
}

/// The root of the driven cantilever turned by `θ = t³` (a constant jerk, 6 rad/s³) in internal
/// steps of `h = 10 ms / 64`, one communication step each, its reaction torque `T_k` read after
/// every one; the pose and angular velocity given at every step for the first 10 ms, then every
/// `n` steps (samples `S = n h` apart, followed with their rates). At each update the rates'
/// path bends by `O(jerk S³)` in the pose. Jumped, that bend `δ` was an acceleration
/// `δ/(β h²)` of the root face's nodes over the next internal step, ringing in the scheme's update
/// formulas (docs/formulation.md, "Time error control"); carried off over the next `S`
/// (`DrivingFrame`, the offset), the path's acceleration is off the sampled rates' by
/// `O(jerk S)`. So the largest second difference `T_{k+1} − 2 T_k + T_{k−1}` (the beam damped,
/// `damping.alpha = 100`, and read from 0.15 s on) grows at most like `S` from `n = 4` to
/// `n = 32` (8 × the interval: 3.1 × measured) where the jump grew like `S³` (171 ×, from 2.9e-4
/// to 5.0e-2 N m against a peak torque of 1.9 N m). `n = 64`, where the updates come at the
/// beam's second bending frequency, is left out.
#[test]
fn a_sampled_motions_bend_is_carried_off_without_a_kick() {
    let h = 1e-2 / 64.0;
    let largest_second_difference = |every: usize| {
        let settings = [
            ("model.accuracy", 0.0),
            ("solver.stepSize", h),
            ("damping.alpha", 100.0),
        ];
        let mut s = initialized(example_body("driven_cantilever"), &settings);
        let mut torque = Vec::new();
        for k in 0..(0.3 / h).round() as usize {
            let t = k as f64 * h;
            if k % every == 0 || k < 64 {
                let q = *Rotation3::from_axis_angle(&Vector3::z_axis(), t * t * t).matrix();
                set_rotation(&mut s, "root.rotation", &q);
                set(&mut s, "root.angularVelocity[3]", 3.0 * t * t);
            }
            s.do_step(t, h).unwrap();
            torque.push(get(&mut s, "root.torque[3]"));
        }
        torque[960..]
            .windows(3)
            .fold(0.0f64, |m, w| m.max((w[2] - 2.0 * w[1] + w[0]).abs()))
    };
    let (often, seldom) = (largest_second_difference(4), largest_second_difference(32));
    println!("largest second difference of the reaction torque: samples every 4 steps {often:.3e} N m, every 32 {seldom:.3e} N m");
    assert!(seldom < 16.0 * often, "{seldom:e} against {often:e} N m");
}
