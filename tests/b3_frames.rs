//! B3 with several co-moving frames converges to the full nonlinear reference on the same mesh.
//!
//! With one frame, the exact-gradient model (`f_nl` on) is late and low on B3: parts of the beam
//! turn against the single body frame, and the rotation error of the linear strain then dwarfs
//! the true centrifugal strain (`examples/b3_strain.rs`). With `model.frames = P` each slab of
//! elements has its own best-fit frame; as the slabs shrink the model becomes the element-wise
//! co-rotational method, whose error against the geometrically nonlinear solution vanishes with
//! the slabs' rotation relative to their frame (second order in the slab length).
//!
//! The mesh is B3's section with 20 hex20 elements along the beam (the example body has 40) to
//! keep the `full` reference affordable in a test; the comparison runs through the spin-up and
//! the peak (t ≤ 7.5 s).

mod common;
use common::*;
use flexbody::model::body_file::MeshSpec;

const H: f64 = 1e-2;
const END: f64 = 7.5;

/// Tip deflection in the hub frame (m) at every step up to `END`, and iterations per step.
fn run(settings: &[(&str, f64)]) -> (Vec<f64>, f64) {
    let (history, iterations, _) = run_until(settings, END);
    (history, iterations)
}

/// [`run`] up to `end`, with the `model.auto` messages.
fn run_until(settings: &[(&str, f64)], end: f64) -> (Vec<f64>, f64, Vec<String>) {
    let s = initialized(b3_body(), settings);
    drive(s, end)
}

/// The tip deflection of a run to `end` with `end` as its stop time, as importers define it
/// (the time error control's horizon), and its internal steps.
fn run_to_stop(settings: &[(&str, f64)], end: f64) -> (Vec<f64>, u64, Vec<String>) {
    let mut s = flexbody::slave::Slave::from_body(b3_body()).unwrap();
    s.setup_experiment(0.0, Some(end), None).unwrap();
    s.enter_initialization_mode().unwrap();
    for (name, value) in settings {
        set(&mut s, name, *value);
    }
    s.exit_initialization_mode().unwrap();
    let mut steps = 0;
    let (history, _, log) = drive_counting(s, end, &mut steps);
    (history, steps, log)
}

/// Steps `s` on the hub schedule to `end`.
fn drive(s: flexbody::slave::Slave, end: f64) -> (Vec<f64>, f64, Vec<String>) {
    drive_counting(s, end, &mut 0)
}

/// [`drive`], counting the internal steps into `steps`.
fn drive_counting(
    mut s: flexbody::slave::Slave,
    end: f64,
    steps: &mut u64,
) -> (Vec<f64>, f64, Vec<String>) {
    let drive = common::b3::HubDrive::new(&s);
    let mut history = Vec::new();
    let mut log = Vec::new();
    for k in 0..(end / H).round() as usize {
        history.push(drive.step(&mut s, k as f64 * H, H).unwrap());
        log.extend(
            s.drain_events()
                .map(|e| e.message)
                .filter(|m| m.starts_with("model.auto")),
        );
    }
    let (internal, iterations) = s.solver_statistics();
    *steps = internal;
    (history, iterations as f64 / internal as f64, log)
}

/// B3 with 20 elements along the beam.
fn b3_body() -> flexbody::model::BodyFile {
    let mut body = example_body("hub_beam");
    let MeshSpec::Beam { divisions, .. } = &mut body.mesh else {
        unreachable!("B3 is a beam")
    };
    divisions[0] = 20;
    body
}

/// Largest |y − y_ref| over the run, relative to the reference's peak.
fn deviation(y: &[f64], reference: &[f64]) -> f64 {
    let peak = reference.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    y.iter()
        .zip(reference)
        .fold(0.0_f64, |a, (y, r)| a.max((y - r).abs()))
        / peak
}

#[test]
fn exact_gradient_model_converges_to_full_as_the_frames_shrink() {
    let (full, full_iterations) = run(&[("model.formulation", 2.0)]);
    let mut errors = Vec::new();
    for frames in [1.0, 4.0, 20.0] {
        // f_nl forced on (model.auto would keep it off with one frame on this supported body).
        let (y, iterations) = run(&[
            ("model.nonlinearForces", 1.0),
            ("model.frames", frames),
            ("model.auto", 0.0),
        ]);
        let e = deviation(&y, &full);
        println!(
            "{frames:>2} frames, f_nl on: largest deviation from full {:.3} % of the peak, {iterations:.2} iterations/step (full: {full_iterations:.2})",
            100.0 * e
        );
        errors.push(e);
    }
    // One frame: the artefact of the single frame (measured: 21 % of the peak, the response is
    // late and low) must show, or this test no longer shows what the frames are for.
    assert!(errors[0] > 0.05, "one frame: {:.4}", errors[0]);
    // Slabs 5× shorter: measured 0.52 % → 0.076 % (6.9×, an observed order of 1.2 rather than
    // the 2 of the slab rotation alone: the models also differ by SVK vs. linear material and
    // by the frames' damping-free iteration tolerance); ask for at least first order (5×).
    assert!(
        errors[2] < errors[1] / 5.0,
        "4 → 20 frames: {:.4} → {:.4}",
        errors[1],
        errors[2]
    );
    // One element per frame is the co-rotational method: within 1 % of full through the peak.
    assert!(errors[2] < 0.01, "20 frames: {:.4}", errors[2]);
}

#[test]
fn the_slabs_own_stiffening_takes_most_of_their_model_error() {
    // Each slab's prestress acting on its own deformation (`model.stiffening = stress` with
    // several frames; docs/formulation.md, "Geometric stiffening within the slabs") is the
    // second-order strain the slabs' linear strain leaves out. All at the same fixed 10 ms, so
    // that the time error is the same on both sides of each comparison.
    let fixed = ("model.accuracy", 0.0);
    let (full, _) = run(&[("model.formulation", 2.0), fixed]);
    let mut errors = Vec::new();
    for frames in [5.0, 20.0] {
        let (plain, _) = run(&[("model.frames", frames), fixed]);
        let (own, _) = run(&[("model.frames", frames), ("model.stiffening", 3.0), fixed]);
        let (e_plain, e_own) = (deviation(&plain, &full), deviation(&own, &full));
        println!(
            "{frames} slabs: {:.4} % of the peak from full, with their own stiffening {:.4} %",
            100.0 * e_plain,
            100.0 * e_own
        );
        errors.push((e_plain, e_own));
    }
    let [(plain_5, own_5), (plain_20, own_20)] = errors[..] else {
        unreachable!()
    };
    // Measured: 5 slabs 0.336 % → 0.204 %, 20 slabs 0.050 % → 0.012 %.
    assert!(own_5 < plain_5 && own_20 < plain_20 / 2.0, "{errors:?}");
    // Slabs 4× shorter: with their own stiffening the error falls at second order in the slab
    // length (measured 16.7×, the order 2 of the rotation within a slab: 16×; asked: order 1.5,
    // 8×), without it at 6.7× (order 1.4).
    assert!(own_20 < own_5 / 8.0, "{errors:?}");
    // model.auto's slabs take it where the accuracy asks for it: at 1e-3 it changes their
    // stiffness by more than a quarter of the accuracy during the spin-up (switched on, once,
    // logged); at the default 1e-2 it stays off on B3 (its largest change, 40 slabs: 5.7e-4).
    let (_, _, log) = run_until(&[("model.accuracy", 1e-3)], END);
    let on: Vec<f64> = log
        .iter()
        .filter(|m| m.contains("the slabs' own geometric stiffening switched on"))
        .map(|m| logged_time(m))
        .collect();
    assert_eq!(on.len(), 1, "{log:?}");
    // It is measured on the slabs' own state, the one carried over to them, not on the one
    // frame's state a redone step starts from: that read 2.55e-4 on the example's 40 slabs,
    // above the switch, and it came on at the slabs' own communication point (1.68 s here)
    // before that was mended. Measured: slabs at 1.68 s, their own stiffening at 4.72 s (this
    // run has no stop time: the horizon is `T₁`, the switch at 0.25 × 1e-3 / π).
    let slabs = log
        .iter()
        .find(|m| m.contains("carried over to the slabs"))
        .map(|m| logged_time(m))
        .expect("the slabs came on");
    assert!(
        on[0] > slabs + 1.0,
        "slabs at {slabs} s, their stiffening at {} s",
        on[0]
    );
}

#[test]
fn a_redone_step_decides_the_slabs_stiffening_on_its_own_state() {
    // B3 at `model.accuracy = 1e-3` with the run's stop time (20 s: the slabs' stiffening
    // switches at 0.25 × 1e-3 / 38 = 6.6e-6), to 2 s. The slabs come on at 1.68 s, and that
    // communication step is tried on 2.5 ms, then on 0.625 ms (rejected: its estimate did not
    // fall, which teaches the estimate floor), then taken on 2.5 ms again. Each attempt carries
    // the state over to the slabs with its own rung's iteration matrix. The 0.625 ms attempt's
    // carry-over, stopped after its 50 corrections, read the slabs' stiffening at 3.56e-5, and
    // the stiffening came on from a state the run threw away; the accepted attempt's reads it
    // below the switch, as the first attempt's on the same rung did. A redone attempt decides
    // again on its own state (docs/formulation.md, "Geometric stiffening within the slabs"):
    // the stiffening stays off through the slabs' step (measured: it comes on at 3.11 s).
    let mut s = flexbody::slave::Slave::from_body(b3_body()).unwrap();
    s.setup_experiment(0.0, Some(20.0), None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.accuracy", 1e-3);
    s.exit_initialization_mode().unwrap();
    let drive = common::b3::HubDrive::new(&s);
    let mut log = Vec::new();
    // Communication steps redone at the slabs' point.
    let mut redone_at_slabs = 0;
    for k in 0..200 {
        let rejected = s.rejected_steps();
        drive.step(&mut s, k as f64 * H, H).unwrap();
        let events: Vec<String> = s.drain_events().map(|e| e.message).collect();
        if events
            .iter()
            .any(|m| m.contains("carried over to the slabs"))
        {
            redone_at_slabs = s.rejected_steps() - rejected;
        }
        log.extend(events.into_iter().filter(|m| m.starts_with("model.auto")));
    }
    let slabs = log
        .iter()
        .find(|m| m.contains("carried over to the slabs"))
        .map(|m| logged_time(m))
        .expect("the slabs came on");
    assert!((1.6..1.8).contains(&slabs), "slabs at {slabs} s");
    // The scene this test is about: the slabs' step was redone (the finer rung, then the rung
    // it came from).
    assert!(redone_at_slabs >= 1, "{redone_at_slabs} redone");
    let on: Vec<&String> = log
        .iter()
        .filter(|m| m.contains("the slabs' own geometric stiffening switched on"))
        .collect();
    assert!(on.is_empty(), "{on:?}");
}

/// The time `t` of a `model.auto: at t = … ` decision.
fn logged_time(message: &str) -> f64 {
    message["model.auto: at t = ".len()..]
        .split(' ')
        .next()
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no time in {message}"))
}

#[test]
fn model_auto_takes_slabs_once_b3_bends_far() {
    // The defaults (model.auto, model.accuracy = 1e-2): the single frame's error estimate
    // 4 ‖∇ū‖² passes a quarter of the accuracy early in the spin-up (B3's ‖∇ū‖ peaks at 0.061
    // near 6.7 s; it passes 0.025 at 3.1 s) and the body takes one slab per element layer for
    // the rest of the run, once; over 20 s it follows `full` within the 0.5 % of the
    // peak at every communication point (measured: 0.10 % here on 20 elements, against 1.58 %
    // for one frame; 0.24 % on the 40-element example body against full at a quarter of the
    // step, bench/results).
    let end = 20.0;
    let (full, _, _) = run_until(&[("model.formulation", 2.0)], end);
    let (one, _, _) = run_until(&[("model.accuracy", 0.0)], end);
    let (auto, _, log) = run_until(&[], end);
    for m in &log {
        println!("{m}");
    }
    let switches: Vec<&String> = log
        .iter()
        .filter(|m| m.contains("slabs, one per element layer"))
        .collect();
    assert_eq!(switches.len(), 1, "{log:?}");
    let t = logged_time(switches[0]);
    assert!((2.0..9.0).contains(&t), "slabs at t = {t} s");
    // The state carried over to them, once (docs/formulation.md, "The slabs' switch").
    assert_eq!(
        log.iter()
            .filter(|m| m.contains("carried over to the slabs"))
            .count(),
        1,
        "{log:?}"
    );
    let (e_one, e_auto) = (deviation(&one, &full), deviation(&auto, &full));
    println!(
        "deviation from full over {end} s: one frame {:.3} %, model.auto {:.3} %",
        100.0 * e_one,
        100.0 * e_auto
    );
    assert!(e_auto < e_one, "{e_auto} against {e_one}");
    assert!(e_auto < 5e-3, "{e_auto}");

    // With inertial stiffening allowed too: it comes on early and goes off with the slabs (it
    // acts on the one frame's deformation, docs/formulation.md, "Geometric stiffening"), which
    // carry their own. While it stayed on with them, the example's 40 elements ended 1.3e-2 of
    // the peak off `full`.
    let (stiffened, _, log) = run_until(&[("model.stiffening", 2.0)], end);
    let e_stiffened = deviation(&stiffened, &full);
    println!("stiffening allowed: {:.3} %; {log:?}", 100.0 * e_stiffened);
    assert!(
        log.iter()
            .any(|m| m.contains("slabs")
                && m.contains("without the one frame's geometric stiffening")),
        "{log:?}"
    );
    assert!(e_stiffened < 5e-3, "{e_stiffened}");
    // Several frames with inertial stiffening are refused by name (`stress` is each slab's own).
    let e = refused(
        b3_body(),
        &[("model.frames", 5.0), ("model.stiffening", 2.0)],
    );
    assert!(
        e.message.contains("model.frames") && e.message.contains("model.stiffening"),
        "{e}"
    );
}

/// The internal steps of B3 (20 elements, stop time 20 s) at `model.accuracy = 1e-3` per
/// second up to `end`, with `settings`, and the log of `model.auto` and of the estimate.
fn steps_per_second(settings: &[(&str, f64)], end: f64) -> (Vec<u64>, Vec<String>) {
    let mut s = flexbody::slave::Slave::from_body(b3_body()).unwrap();
    s.setup_experiment(0.0, Some(20.0), None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.accuracy", 1e-3);
    for (name, value) in settings {
        set(&mut s, name, *value);
    }
    s.exit_initialization_mode().unwrap();
    let drive = common::b3::HubDrive::new(&s);
    let (mut counts, mut log, mut last) = (Vec::new(), Vec::new(), 0);
    for k in 0..(end / H).round() as usize {
        drive.step(&mut s, k as f64 * H, H).unwrap();
        log.extend(s.drain_events().map(|e| e.message));
        if (k + 1) % 100 == 0 {
            let steps = s.solver_statistics().0;
            counts.push(steps - last);
            last = steps;
        }
    }
    (counts, log)
}

/// model.auto's slabs come on in the spin-up (at `model.accuracy = 1e-3` near 1.7 s) with the
/// state carried over to them (docs/formulation.md, "The slabs' switch"): the one frame's state
/// balances its own spurious strain of the slabs' turns by an axial stretch, which the slabs
/// sprang back from at the stiff modes' periods. The error control then resolved that ringing
/// for good: internal steps of 0.16 ms from the switch on (6 400 a second, measured on the
/// 40-element example body). Carried over, the seconds after the switch take about the steps
/// of the slabs in force from the start (measured: 191, 100, 100 against 200, 200, 200). The
/// hub's motion, sampled every 10 ms, is estimated throughout: no warning of steps that were
/// not.
#[test]
fn the_slabs_come_on_without_ringing_and_the_sampled_spin_up_is_estimated() {
    let end = 4.0;
    let (auto, log) = steps_per_second(&[], end);
    let (slabs, _) = steps_per_second(&[("model.frames", 20.0)], end);
    let switch = log
        .iter()
        .find(|m| m.contains("slabs, one per element layer"))
        .unwrap_or_else(|| panic!("no slabs: {log:?}"));
    let t = logged_time(switch);
    println!("slabs at {t} s; internal steps per second: model.auto {auto:?}, 20 slabs from the start {slabs:?}");
    assert!((1.0..3.0).contains(&t), "slabs at t = {t} s");
    let after = t.ceil() as usize;
    for second in after..auto.len() {
        assert!(
            auto[second] <= 2 * slabs[second],
            "second {}: {} internal steps against the slabs' {}",
            second + 1,
            auto[second],
            slabs[second]
        );
    }
    assert!(
        !log.iter().any(|m| m.contains("were not estimated")),
        "{log:?}"
    );
}

#[test]
fn a_change_of_step_on_the_spinning_beam_leaves_no_vibration() {
    // B3 (20 elements, one frame, fixed steps) spun up at 10 ms; from 15 s, where the hub turns
    // at a steady 6 rad/s, the importer halves its communication step (the internal step with
    // it). Generalized-α's velocities lag a rotation by c_v (ωh)² (3.0e-4 of the rigid velocity
    // at ωh = 0.06, c_v = β − γ/2 + 1/12 = 0.084 for ρ∞ = 0.9); kept across the change, the lag
    // of the old step against the hub's new one is an elastic velocity of 0.75 × 3.0e-4 × ωL ≈
    // 0.014 m/s at the tip, a vibration of about 0.6 % of the peak (measured: 0.59 % on the
    // example's 40 elements). Carried over (`generalized_alpha::change_step`), the halved run
    // stays as close to the 10 ms run as the two steps' own errors allow (each within 0.05 %
    // of `full` after 15 s): 0.2 % bounds it with room for both.
    // A reduced body (8 modes) takes the same carry-over on its fields' coefficients (the jerk
    // field is affine in the position); without it the reduced B3 rang at 0.4 % of the peak
    // after the error control refined from 10 ms to 0.31 ms at 15 s.
    for modes in [0.0, 8.0] {
        let settings = [
            ("model.accuracy", 0.0),
            ("model.auto", 0.0),
            ("solver.stepSize", 1e-2),
            ("model.modes", modes),
        ];
        let end = 17.0;
        let (whole, _, _) = run_until(&settings, end);
        let mut body = example_body("hub_beam");
        let MeshSpec::Beam { divisions, .. } = &mut body.mesh else {
            unreachable!("B3 is a beam")
        };
        divisions[0] = 20;
        let mut s = initialized(body, &settings);
        let drive = common::b3::HubDrive::new(&s);
        let mut halved = Vec::new();
        for k in 0..1500 {
            halved.push(drive.step(&mut s, k as f64 * H, H).unwrap());
        }
        let mut t = 15.0;
        for k in 1500..(end / H).round() as usize {
            let mut y = 0.0;
            for _ in 0..2 {
                y = drive.step(&mut s, t, 0.5 * H).unwrap();
                t += 0.5 * H;
            }
            assert!((t - (k + 1) as f64 * H).abs() < 1e-9);
            halved.push(y);
        }
        let peak = whole.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        let after = whole[1500..]
            .iter()
            .zip(&halved[1500..])
            .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()))
            / peak;
        println!(
            "model.modes = {modes}: after the change of step {:.3} % of the peak",
            100.0 * after
        );
        assert!(after < 2e-3, "model.modes = {modes}: {after}");
    }
}

/// A reduced body takes several co-moving frames too (docs/formulation.md, "The reduced
/// body"): its slabs act on its coordinates. On B3 (20 elements, the whole 20 s, fixed
/// 10 ms) the reduced body with 8 modes and 20 slabs stays within 0.5 % of `full`'s peak (issue
/// 17's bar; measured 7.6e-4, 1.6e-3 before the basis held the slabs' second order) as the mesh
/// body with the same slabs does (8.7e-4), where the reduced body with one frame carries the one frame's
/// error (1.6e-2).
#[test]
fn a_reduced_body_with_slabs_or_stiffening_follows_full_as_the_mesh_body_does() {
    let fixed = [("model.accuracy", 0.0), ("model.auto", 0.0)];
    let whole = |settings: &[(&str, f64)]| {
        let (y, iterations, _) = run_until(settings, 20.0);
        (y, iterations)
    };
    let with = |extra: &[(&'static str, f64)]| {
        let mut settings = fixed.to_vec();
        settings.extend_from_slice(extra);
        whole(&settings)
    };
    let (full, _) = whole(&[("model.formulation", 2.0), ("model.accuracy", 0.0)]);
    let (mesh, mesh_iterations) = with(&[("model.frames", 20.0)]);
    let (reduced, reduced_iterations) = with(&[("model.frames", 20.0), ("model.modes", 8.0)]);
    let (one_frame, _) = with(&[("model.modes", 8.0)]);
    let (mesh_e, reduced_e, one_e) = (
        deviation(&mesh, &full),
        deviation(&reduced, &full),
        deviation(&one_frame, &full),
    );
    println!(
        "from full: mesh, 20 slabs {mesh_e:.3e} ({mesh_iterations:.2} iterations/step); reduced (8 modes), 20 slabs {reduced_e:.3e} ({reduced_iterations:.2}); reduced, one frame {one_e:.3e}; reduced from mesh {:.3e}",
        deviation(&reduced, &mesh)
    );
    assert!(reduced_e < 5e-3 && mesh_e < 5e-3, "{reduced_e} {mesh_e}");
    assert!(
        one_e > 5.0 * reduced_e,
        "one frame {one_e}, slabs {reduced_e}"
    );

    // One frame with inertial stiffening (docs/formulation.md, "The reduced body": stiffening
    // from the driving motion): most of the one frame's error on B3 is the missing geometric
    // stiffening. The reduced body takes its prestress from the hub's motion, the mesh body
    // from its state.
    let stiffened = [("model.stiffening", 2.0)];
    let (mesh_stiffened, _) = with(&stiffened);
    let (reduced_stiffened, _) = with(&[("model.stiffening", 2.0), ("model.modes", 8.0)]);
    let (mesh_stiffened_e, reduced_stiffened_e) = (
        deviation(&mesh_stiffened, &full),
        deviation(&reduced_stiffened, &full),
    );
    println!(
        "from full, one frame with inertial stiffening: mesh {mesh_stiffened_e:.3e}, reduced (8 modes) {reduced_stiffened_e:.3e}; reduced from mesh {:.3e}",
        deviation(&reduced_stiffened, &mesh_stiffened)
    );
    // Measured: 1.85e-3 against one frame's 1.58e-2; the reduced from the mesh body 2.2e-4,
    // against the stiffened model's own 1.74e-3.
    assert!(
        reduced_stiffened_e < 0.2 * one_e,
        "stiffened {reduced_stiffened_e}, one frame {one_e}"
    );
    assert!(
        deviation(&reduced_stiffened, &mesh_stiffened) < 0.25 * mesh_stiffened_e,
        "the reduced body's stiffening differs from the mesh body's"
    );

    // The defaults plus `model.modes = auto`, under the time error control with the run as its
    // horizon (the stop time defined, as importers define it). model.auto switches the
    // stiffening from the driving motion on by itself once it matters to model.accuracy
    // (docs/formulation.md, "The reduced body"). The time error control brings the run within
    // model.accuracy of the same model converged in time (its stiffening forced, internal
    // steps of 1.25 ms). What is left against `full` is the one frame's model error, which no
    // internal step removes: the controlled run is 4.7e-3 off `full` (at 10 ms), 5.3e-4 off the
    // model converged in time, where the reduced body with 8 modes and its stiffening forced is
    // 1.9e-3 off at a fixed 10 ms, its time error partly cancelling its model error (on the
    // 40-element body 2.1e-3 at 10 ms, 3.1e-3 at 1.25 ms). The estimate leaves out the hub's
    // steady spin, whose error the
    // motion interface takes, so the steady spin after 15 s keeps the spin-up's steps. Before,
    // the reduced body's estimate carried the spin's jerk, 135 times its allowance at 15.02 s,
    // and refined 32-fold: 9 630 internal steps.
    let (controlled, steps, log) = run_to_stop(&[("model.modes", -1.0)], 20.0);
    let (converged, _, _) = run_to_stop(
        &[
            ("model.modes", -1.0),
            ("model.auto", 0.0),
            ("model.stiffening", 2.0),
            ("solver.stepSize", 1.25e-3),
        ],
        20.0,
    );
    let (controlled_e, time_e) = (
        deviation(&controlled, &full),
        deviation(&controlled, &converged),
    );
    println!(
        "model.modes = auto, the run as the horizon: {controlled_e:.3e} from full, {time_e:.3e} from the model converged in time, in {steps} internal steps; {log:?}"
    );
    assert!(
        log.iter()
            .any(|m| m.contains("stiffening from the driving motion switched on")),
        "{log:?}"
    );
    // The initialization says that it decides (logEvents).
    assert!(
        log.iter()
            .any(|m| m.contains("is switched per communication step")),
        "{log:?}"
    );
    assert!(time_e < 1e-3, "{time_e} from the model converged in time");
    assert!(
        controlled_e < 0.5 * one_e,
        "controlled {controlled_e}, one frame {one_e}"
    );
    assert!(
        steps < 7000,
        "{steps} internal steps for 2 000 communication steps"
    );
}

/// A reduced body's stiffening takes the driving motion's accelerations from the driving frames
/// of this step and the last, which are part of the FMU state: a fresh instance given a state
/// saved in the spin-up repeats the later steps bit for bit.
#[test]
fn the_driving_motion_of_a_reduced_bodys_stiffening_is_part_of_its_state() {
    // model.auto off: the stiffening is in force from the start (with it, it comes on at about
    // 2.45 s, after the steps compared here).
    let settings = [
        ("model.modes", 4.0),
        ("model.stiffening", 2.0),
        ("model.auto", 0.0),
    ];
    let mut s = initialized(b3_body(), &settings);
    let drive = common::b3::HubDrive::new(&s);
    for k in 0..200 {
        drive.step(&mut s, k as f64 * H, H).unwrap();
    }
    let mut saved = Vec::new();
    s.get_state().write_bytes(&mut saved);
    let later = |s: &mut flexbody::slave::Slave| -> Vec<f64> {
        (200..220)
            .map(|k| drive.step(s, k as f64 * H, H).unwrap())
            .collect()
    };
    let expected = later(&mut s);
    let mut fresh = initialized(b3_body(), &settings);
    let state = fresh.state_from_bytes(&saved).unwrap();
    fresh.set_state(&state).unwrap();
    assert_eq!(later(&mut fresh), expected);
}

/// An importer may step several times per input update (docs/fmu.md, "Inputs are samples in
/// time"): the hub's velocities, given at every update, are samples of a smooth motion, so the
/// driving frame follows their rates between updates (`DrivingFrame`), and the reduced body's
/// stiffening, refreshed at every communication step, takes the frame's velocities there. B3
/// reduced with its stiffening forced, internal steps of 2.5 ms, hub inputs every 10 ms stepped
/// as one communication step per update or as four, against inputs every 2.5 ms: the four steps
/// follow the finer updates' path to 7.5 s 3.4 × closer than the one (7.1e-7 of the peak
/// against 2.4e-6). Held at constant velocities between updates (as before the rates were
/// followed) the four steps took the one step's path (2.2e-8 apart): the bound, half, separates
/// the two.
#[test]
fn stepping_several_times_per_input_update_follows_the_motion_between_updates() {
    let settings = [
        ("model.modes", 4.0),
        ("model.stiffening", 2.0),
        ("model.auto", 0.0),
        ("model.accuracy", 0.0),
        ("solver.stepSize", 2.5e-3),
    ];
    // Inputs every `every` seconds, each update stepped as `substeps` steps.
    let run = |every: f64, substeps: usize| {
        let mut s = initialized(b3_body(), &settings);
        let drive = common::b3::HubDrive::new(&s);
        let mut tip = Vec::new();
        let per_h = (H / every).round() as usize;
        for k in 0..(END / every).round() as usize {
            let t = k as f64 * every;
            drive.set_hub(&mut s, t).unwrap();
            let h = every / substeps as f64;
            for j in 0..substeps {
                s.do_step(t + j as f64 * h, h).unwrap();
            }
            if (k + 1) % per_h == 0 {
                tip.push(drive.tip_deflection(&mut s, t + every).unwrap());
            }
        }
        tip
    };
    let (whole, quarters, fine) = (run(H, 1), run(H, 4), run(H / 4.0, 1));
    let (one, four) = (deviation(&whole, &fine), deviation(&quarters, &fine));
    println!(
        "against inputs every 2.5 ms: one step per update {one:.3e} of the peak, four {four:.3e}"
    );
    assert!(four < 0.5 * one, "four steps {four:e}, one step {one:e}");
}

/// The slabs' own stiffening, switched on by model.auto at 1e-3 during the spin-up (the slabs
/// come on at 1.68 s, their own stiffening at 4.72 s, coming in over the lowest period `T₁` =
/// 1.6 s), is part of the FMU state (a feature bit and when it came on; `G_p` follows from the
/// positions): the saving instance and a fresh one, given a state saved while it comes in
/// (5.5 s), repeat the later steps bit for bit.
#[test]
fn the_slabs_own_stiffening_is_part_of_the_state() {
    let settings = [("model.accuracy", 1e-3)];
    let mut s = initialized(b3_body(), &settings);
    let drive = common::b3::HubDrive::new(&s);
    let mut log = Vec::new();
    for k in 0..550 {
        drive.step(&mut s, k as f64 * H, H).unwrap();
        log.extend(s.drain_events().map(|e| e.message));
    }
    let switched = log
        .iter()
        .find(|m| m.contains("the slabs' own geometric stiffening switched on"))
        .map(|m| logged_time(m))
        .unwrap_or_else(|| {
            panic!(
                "{:?}",
                log.iter()
                    .filter(|m| m.starts_with("model.auto"))
                    .collect::<Vec<_>>()
            )
        });
    // Saved while it comes in: within the lowest period after the switch (the horizon's
    // period, logged at initialization as there is no stop time).
    let period: f64 = log
        .iter()
        .find_map(|m| m.split("T₁ = ").nth(1))
        .and_then(|rest| rest.split(' ').next())
        .and_then(|t| t.parse().ok())
        .expect("the lowest period is logged");
    let saved_at = 550.0 * H;
    assert!(
        saved_at - period < switched && switched < saved_at,
        "switched on at {switched} s, T₁ = {period} s, saved at {saved_at} s"
    );
    let mut saved = Vec::new();
    s.get_state().write_bytes(&mut saved);
    let later = |s: &mut flexbody::slave::Slave| -> Vec<f64> {
        (550..570)
            .map(|k| drive.step(s, k as f64 * H, H).unwrap())
            .collect()
    };
    let expected = later(&mut s);
    // Restored into the instance that went on and into a fresh one, whose slabs are parked.
    let state = s.state_from_bytes(&saved).unwrap();
    s.set_state(&state).unwrap();
    assert_eq!(later(&mut s), expected);
    let mut fresh = initialized(b3_body(), &settings);
    let state = fresh.state_from_bytes(&saved).unwrap();
    fresh.set_state(&state).unwrap();
    assert_eq!(later(&mut fresh), expected);
}
