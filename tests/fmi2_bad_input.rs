//! Bad input at the C ABI (issue 6): non-finite and out-of-range values, unknown value
//! references, wrong types, NULL pointers and calls in the wrong state. Each is an `fmi2Error`
//! with a logger message that names the variable (or function), the value and the reason; the
//! instance stays usable and nothing of a rejected call is kept.

#![cfg(any(
    all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    ),
    all(target_os = "windows", target_arch = "x86_64")
))]

mod fmi2_support;

use flexbody::fmi2::exports::*;
use flexbody::fmi2::types::*;
use flexbody::slave::Slave;
use fmi2_support::*;
use std::ptr::{null, null_mut};

const OK: fmi2Status = fmi2Status::fmi2OK;
const ERR: fmi2Status = fmi2Status::fmi2Error;
const H: f64 = 1e-3;

fn vr(name: &str) -> u32 {
    Slave::from_resources(None)
        .unwrap()
        .variables()
        .by_name(name)
        .unwrap_or_else(|| panic!("no {name}"))
        .value_reference
}

fn new_instance(recorder: &Recorder) -> fmi2Component {
    let functions = callbacks(recorder);
    let guid = Slave::from_resources(None).unwrap().guid().to_string();
    let c = instantiate(
        Some("bad input"),
        fmi2CoSimulation,
        Some(&guid),
        None,
        Some(&functions),
        false,
    );
    assert!(!c.is_null());
    c
}

/// The last message is an error that contains every fragment.
fn assert_error(recorder: &Recorder, fragments: &[&str]) {
    let messages = recorder.take();
    let last = messages.last().expect("no message logged");
    assert_eq!(last.status, ERR, "{last:?}");
    assert_eq!(last.category, "logStatusError");
    for f in fragments {
        assert!(last.text.contains(f), "{f:?} not in {:?}", last.text);
    }
}

fn initialize(c: fmi2Component) {
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
    }
}

/// The instance still steps and gives finite outputs.
fn assert_runs(c: fmi2Component, t: f64) {
    unsafe { assert_eq!(fmi2DoStep(c, t, H, fmi2False), OK) };
    let (s, x) = get_real(c, &[vr("tip.position[3]"), vr("root.force[3]")]);
    assert_eq!(s, OK);
    assert!(x.iter().all(|v| v.is_finite()));
}

#[test]
fn out_of_range_and_non_finite_parameters_are_named_and_not_kept() {
    let recorder = Recorder::default();
    let c = new_instance(&recorder);
    let reals: &[(&str, f64, &str)] = &[
        ("material.youngsModulus", 0.0, "must be positive"),
        ("material.youngsModulus", -2.1e11, "must be positive"),
        ("material.youngsModulus", f64::NAN, "not a finite number"),
        (
            "material.youngsModulus",
            f64::INFINITY,
            "not a finite number",
        ),
        ("material.poissonRatio", 0.5, "must lie in (-1, 0.5)"),
        ("material.poissonRatio", -1.0, "must lie in (-1, 0.5)"),
        ("material.poissonRatio", 0.7, "must lie in (-1, 0.5)"),
        ("material.density", 0.0, "must be positive"),
        ("material.density", -7850.0, "must be positive"),
        ("damping.alpha", -1.0, "must not be negative"),
        ("damping.beta", -1e-3, "must not be negative"),
        ("solver.stepSize", 0.0, "must be positive"),
        ("solver.stepSize", -1e-3, "must be positive"),
        ("solver.tolerance", 0.0, "must lie in (0, 1)"),
        ("solver.tolerance", -1e-6, "must lie in (0, 1)"),
        ("solver.rhoInf", 1.5, "must lie in [0, 1]"),
        ("gravity[3]", f64::NEG_INFINITY, "not a finite number"),
        ("initial.position[1]", f64::NAN, "not a finite number"),
    ];
    for &(name, value, reason) in reals {
        assert_eq!(set_real(c, &[vr(name)], &[value]), ERR, "{name} = {value}");
        assert_error(&recorder, &[name, &format!("{value}"), reason]);
    }
    // All or nothing: a good value before a bad one is not kept either.
    let e = vr("material.youngsModulus");
    assert_eq!(set_real(c, &[e, vr("material.density")], &[1e9, -1.0]), ERR);
    assert_error(&recorder, &["material.density = -1 rejected"]);
    let (_, young) = get_real_after_init(c, e);
    assert_eq!(
        young, 2.1e11,
        "the rejected call changed material.youngsModulus"
    );

    let ints: &[(&str, i32, &str)] = &[
        ("solver.maxIterations", 0, "must be at least 1"),
        ("solver.maxIterations", -5, "must be at least 1"),
        ("model.formulation", 0, "not an item of Formulation"),
        ("model.formulation", 3, "not an item of Formulation"),
        ("model.stiffening", 4, "not an item of Stiffening"),
    ];
    unsafe {
        // Back to a fresh instance: fmi2Reset from StepComplete.
        assert_eq!(fmi2Reset(c), OK);
        for &(name, value, reason) in ints {
            assert_eq!(fmi2SetInteger(c, &vr(name), 1, &value), ERR, "{name}");
            assert_error(&recorder, &[name, &format!("{value}"), reason]);
        }
    }
    initialize(c);
    assert_runs(c, 0.0);
    unsafe { fmi2FreeInstance(c) };
}

/// Initializes `c` (from Instantiated) and reads `vr`.
fn get_real_after_init(c: fmi2Component, vr: u32) -> (fmi2Status, f64) {
    initialize(c);
    let (s, x) = get_real(c, &[vr]);
    (s, x[0])
}

#[test]
fn non_finite_inputs_are_named_and_the_instance_keeps_running() {
    let recorder = Recorder::default();
    let c = new_instance(&recorder);
    initialize(c);
    let fz = vr("tip.force[3]");
    for value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(set_real(c, &[fz], &[value]), ERR);
        assert_error(
            &recorder,
            &["tip.force[3]", &format!("{value}"), "not a finite number"],
        );
    }
    assert_runs(c, 0.0);
    let (_, f) = get_real(c, &[fz]);
    assert_eq!(f[0], 0.0, "a rejected input was kept");
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn unknown_value_references_and_wrong_types_are_named() {
    let recorder = Recorder::default();
    let c = new_instance(&recorder);
    initialize(c);
    let unknown = 987_654u32;
    let max_iterations = vr("solver.maxIterations");
    let nonlinear = vr("model.nonlinearForces");
    let young = vr("material.youngsModulus");
    let mut x = [0.0];
    let mut n = [0];
    let mut s: fmi2String = null();
    unsafe {
        assert_eq!(fmi2GetReal(c, &unknown, 1, x.as_mut_ptr()), ERR);
        assert_error(
            &recorder,
            &["fmi2GetReal", "unknown Real value reference 987654"],
        );
        assert_eq!(fmi2SetReal(c, &max_iterations, 1, &3.0), ERR);
        assert_error(
            &recorder,
            &["value reference 33 is the Integer variable solver.maxIterations, not a Real variable"],
        );
        assert_eq!(fmi2GetInteger(c, &young, 1, n.as_mut_ptr()), ERR);
        assert_error(
            &recorder,
            &["material.youngsModulus, not a Integer variable"],
        );
        assert_eq!(fmi2GetBoolean(c, &max_iterations, 1, n.as_mut_ptr()), ERR);
        assert_error(&recorder, &["solver.maxIterations, not a Boolean variable"]);
        assert_eq!(fmi2SetBoolean(c, &unknown, 1, &fmi2True), ERR);
        assert_error(&recorder, &["unknown Boolean value reference 987654"]);
        assert_eq!(fmi2SetInteger(c, &nonlinear, 1, &1), ERR);
        assert_error(
            &recorder,
            &["model.nonlinearForces, not a Integer variable"],
        );
        assert_eq!(fmi2GetString(c, &young, 1, &mut s), ERR);
        assert_error(
            &recorder,
            &["material.youngsModulus, not a String variable"],
        );
        let text = c"x";
        let value: fmi2String = text.as_ptr();
        assert_eq!(fmi2SetString(c, &young, 1, &value), ERR);
        assert_error(
            &recorder,
            &["material.youngsModulus, not a String variable"],
        );
    }
    assert_runs(c, 0.0);
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn null_pointers_are_errors_with_a_message() {
    let recorder = Recorder::default();
    let c = new_instance(&recorder);
    initialize(c);
    let v = [vr("tip.position[1]")];
    let mut x = [0.0];
    unsafe {
        type Call<'a> = Box<dyn Fn() -> fmi2Status + 'a>;
        let xp = x.as_mut_ptr();
        let calls: Vec<(Call, &str)> = vec![
            (
                Box::new(|| fmi2GetReal(c, null(), 1, xp)),
                "fmi2GetReal: vr or value is NULL",
            ),
            (
                Box::new(|| fmi2GetReal(c, v.as_ptr(), 1, null_mut())),
                "fmi2GetReal: vr or value is NULL",
            ),
            (
                Box::new(|| fmi2SetReal(c, null(), 2, x.as_ptr())),
                "fmi2SetReal: vr or value is NULL with nvr = 2",
            ),
            (
                Box::new(|| fmi2GetInteger(c, v.as_ptr(), 1, null_mut())),
                "fmi2GetInteger",
            ),
            (
                Box::new(|| fmi2SetBoolean(c, v.as_ptr(), 1, null())),
                "fmi2SetBoolean",
            ),
            (
                Box::new(|| fmi2GetString(c, v.as_ptr(), 1, null_mut())),
                "fmi2GetString",
            ),
            (
                Box::new(|| fmi2GetFMUstate(c, null_mut())),
                "fmi2GetFMUstate: FMUstate is NULL",
            ),
            (
                Box::new(|| fmi2SetFMUstate(c, null_mut())),
                "fmi2SetFMUstate: FMUstate is NULL",
            ),
            (
                Box::new(|| fmi2GetRealStatus(c, fmi2LastSuccessfulTime, null_mut())),
                "fmi2GetRealStatus: value is NULL",
            ),
            (
                Box::new(|| fmi2GetBooleanStatus(c, fmi2Terminated, null_mut())),
                "fmi2GetBooleanStatus: value is NULL",
            ),
            (
                Box::new(|| fmi2SetDebugLogging(c, fmi2True, 2, null())),
                "categories is NULL with nCategories = 2",
            ),
            (
                Box::new(|| fmi2GetRealOutputDerivatives(c, v.as_ptr(), 1, null(), xp)),
                "fmi2GetRealOutputDerivatives: vr, order or value is NULL",
            ),
        ];
        for (call, fragment) in calls {
            assert_eq!(call(), ERR, "{fragment}");
            assert_error(&recorder, &[fragment]);
        }
        // nvr = 0 with NULL arrays is an empty request, not an error.
        assert_eq!(fmi2GetReal(c, null(), 0, null_mut()), OK);
    }
    assert_runs(c, 0.0);
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn calls_in_the_wrong_state_and_bad_step_arguments_change_nothing() {
    let recorder = Recorder::default();
    let c = new_instance(&recorder);
    let mut x = [0.0];
    let mut status = OK;
    unsafe {
        // Instantiated.
        assert_eq!(fmi2DoStep(c, 0.0, H, fmi2False), ERR);
        assert_error(
            &recorder,
            &["fmi2DoStep: not allowed in state Instantiated"],
        );
        assert_eq!(fmi2ExitInitializationMode(c), ERR);
        assert_error(&recorder, &["fmi2ExitInitializationMode", "Instantiated"]);
        assert_eq!(
            fmi2GetReal(c, &vr("tip.position[1]"), 1, x.as_mut_ptr()),
            ERR
        );
        assert_error(
            &recorder,
            &["fmi2GetReal: not allowed in state Instantiated"],
        );
        assert_eq!(fmi2Terminate(c), ERR);
        assert_error(&recorder, &["fmi2Terminate", "Instantiated"]);
        assert_eq!(
            fmi2SetupExperiment(c, fmi2True, -1.0, 0.0, fmi2False, 0.0),
            ERR
        );
        assert_error(&recorder, &["tolerance = -1 rejected"]);
        assert_eq!(
            fmi2SetupExperiment(c, fmi2False, 0.0, 1.0, fmi2True, 0.5),
            ERR
        );
        assert_error(&recorder, &["stopTime = 0.5 rejected"]);
    }
    initialize(c);
    unsafe {
        // StepComplete.
        assert_eq!(
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            ERR
        );
        assert_error(
            &recorder,
            &["fmi2SetupExperiment: not allowed in state StepComplete"],
        );
        assert_eq!(set_real(c, &[vr("material.youngsModulus")], &[1e9]), ERR);
        assert_error(
            &recorder,
            &[
                "material.youngsModulus is a fixed parameter",
                "state StepComplete",
            ],
        );
        assert_eq!(set_real(c, &[vr("tip.position[1]")], &[1.0]), ERR);
        assert_error(
            &recorder,
            &["tip.position[1] is an output and cannot be set"],
        );
        for h in [0.0, -H, f64::NAN, f64::INFINITY] {
            assert_eq!(fmi2DoStep(c, 0.0, h, fmi2False), ERR);
            assert_error(&recorder, &["communicationStepSize", "rejected"]);
        }
        assert_eq!(fmi2DoStep(c, 0.5, H, fmi2False), ERR);
        assert_error(
            &recorder,
            &["currentCommunicationPoint = 0.5 rejected", "does not match"],
        );
        // A mismatched communication point is an error of the step: Error state, fmi2Reset
        // leads out; the other errors above left StepComplete.
        assert_eq!(fmi2Reset(c), OK);
    }
    initialize(c);
    unsafe {
        assert_eq!(fmi2CancelStep(c), ERR);
        assert_error(&recorder, &["fmi2CancelStep", "StepInProgress"]);
        assert_eq!(fmi2GetStatus(c, fmi2DoStepStatus, &mut status), ERR);
        assert_error(
            &recorder,
            &["fmi2DoStepStatus is only defined after fmi2DoStep returned fmi2Pending"],
        );
        assert_eq!(fmi2GetRealStatus(c, 17, x.as_mut_ptr()), ERR);
        assert_error(&recorder, &["unknown status kind fmi2StatusKind(17)"]);
    }
    assert_runs(c, 0.0);
    unsafe {
        assert_eq!(fmi2Terminate(c), OK);
        assert_eq!(fmi2Terminate(c), ERR);
        assert_error(
            &recorder,
            &["fmi2Terminate: not allowed in state Terminated"],
        );
        assert_eq!(fmi2DoStep(c, H, H, fmi2False), ERR);
        // Outputs stay readable after fmi2Terminate; fmi2Reset gives a fresh instance.
        assert_eq!(
            fmi2GetReal(c, &vr("tip.position[1]"), 1, x.as_mut_ptr()),
            OK
        );
        assert_eq!(fmi2Reset(c), OK);
    }
    initialize(c);
    assert_runs(c, 0.0);
    unsafe { fmi2FreeInstance(c) };
}
