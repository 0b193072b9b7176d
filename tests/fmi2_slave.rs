//! The exported FMI 2.0 functions driving the real physics (`src/slave/`). Paths that do not
//! reach the physics are tested in `tests/fmi2_abi.rs`, the state machine itself against a mock
//! slave in `src/fmi2/instance/tests.rs`.
//!
//! Body: the embedded default (B1 cantilever, interfaces `root` (fixed, value references
//! 1000..) and `tip` (force, 1100..)).

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
use flexbody::model::{Causality, VariableType};
use flexbody::slave::Slave;
use fmi2_support::*;
use std::ptr::null_mut;

const OK: fmi2Status = fmi2Status::fmi2OK;
const ERR: fmi2Status = fmi2Status::fmi2Error;
const YOUNG: u32 = 1;
const GRAVITY_Z: u32 = 8;
const TIP_FZ: u32 = 1102;
const TIP_Z: u32 = 1108;
const H: f64 = 1e-3;

fn default_guid() -> String {
    Slave::from_resources(None)
        .expect("default body")
        .guid()
        .to_string()
}

/// Value references of every Real output, in table order.
fn real_outputs() -> Vec<u32> {
    let slave = Slave::from_resources(None).unwrap();
    slave
        .variables()
        .iter()
        .filter(|v| v.causality == Causality::Output && v.ty == VariableType::Real)
        .map(|v| v.value_reference)
        .collect()
}

fn new_instance(recorder: &Recorder, functions: &fmi2CallbackFunctions) -> fmi2Component {
    let c = instantiate(
        Some("slave test"),
        fmi2CoSimulation,
        Some(&default_guid()),
        None,
        Some(functions),
        true,
    );
    assert!(
        !c.is_null(),
        "fmi2Instantiate failed: {:?}",
        recorder.texts()
    );
    c
}

/// Instantiated → StepComplete at t = 0 with a tip load of `fz` N.
fn initialize(c: fmi2Component, fz: f64) {
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(set_real(c, &[TIP_FZ], &[fz]), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
    }
}

fn steps(c: fmi2Component, t0: f64, n: usize) -> f64 {
    let mut t = t0;
    for _ in 0..n {
        assert_eq!(
            unsafe { fmi2DoStep(c, t, H, fmi2False) },
            OK,
            "step at t = {t}"
        );
        t += H;
    }
    t
}

#[test]
fn full_run_through_the_c_abi() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = new_instance(&recorder, &functions);
    initialize(c, -10.0);
    let t = steps(c, 0.0, 50);
    let outputs = real_outputs();
    let (s, values) = get_real(c, &outputs);
    assert_eq!(s, OK);
    assert!(values.iter().all(|x| x.is_finite()), "{values:?}");
    let (_, z) = get_real(c, &[TIP_Z]);
    assert!(
        z[0] < 0.0,
        "a downward tip load must move the tip down: z = {}",
        z[0]
    );
    let mut last = 0.0;
    let mut terminated = fmi2True;
    unsafe {
        assert_eq!(fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut last), OK);
        assert_eq!(fmi2GetBooleanStatus(c, fmi2Terminated, &mut terminated), OK);
    }
    assert!(
        (last - t).abs() <= 1e-9,
        "last successful time {last} vs {t}"
    );
    assert_eq!(terminated, fmi2False);
    // Settability in StepComplete: the fixed Young's modulus no, the tunable gravity yes.
    assert_eq!(set_real(c, &[YOUNG], &[1e9]), ERR);
    assert!(
        recorder.last_text().contains("material.youngsModulus"),
        "{}",
        recorder.last_text()
    );
    assert_eq!(set_real(c, &[GRAVITY_Z], &[-9.81]), OK);
    // A communication point that is not the slave's time is an error.
    assert_eq!(unsafe { fmi2DoStep(c, t + 1.0, H, fmi2False) }, ERR);
    // Logger messages carry a copy of the instance name: the caller overwrote and freed its own.
    for m in recorder.take() {
        assert_eq!(m.instance_name, "slave test");
    }
    unsafe {
        fmi2FreeInstance(c);
    }
}

#[test]
fn fmu_state_rollback_reproduces_later_steps_bit_for_bit() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = new_instance(&recorder, &functions);
    initialize(c, -10.0);
    let t = steps(c, 0.0, 20);
    let outputs = real_outputs();
    let mut state: fmi2FMUstate = null_mut();
    unsafe { assert_eq!(fmi2GetFMUstate(c, &mut state), OK) };
    assert!(!state.is_null());
    let t_end = steps(c, t, 20);
    let (_, first) = get_real(c, &outputs);
    for _ in 0..2 {
        // The state stays valid after use.
        unsafe { assert_eq!(fmi2SetFMUstate(c, state), OK) };
        let mut last = 0.0;
        unsafe { fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut last) };
        assert!((last - t).abs() <= 1e-9);
        assert_eq!(steps(c, t, 20), t_end);
        let (_, again) = get_real(c, &outputs);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&again), bits(&first));
    }
    // Overwrite in place: the pointer stays the same and now holds the later state.
    let before = state;
    unsafe { assert_eq!(fmi2GetFMUstate(c, &mut state), OK) };
    assert_eq!(state, before);
    unsafe {
        assert_eq!(fmi2FreeFMUstate(c, &mut state), OK);
        assert!(state.is_null());
        assert_eq!(
            fmi2FreeFMUstate(c, &mut state),
            OK,
            "freeing NULL is a no-op"
        );
        fmi2FreeInstance(c);
    }
}

#[test]
fn reset_gives_a_fresh_instance_that_repeats_the_run() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = new_instance(&recorder, &functions);
    let outputs = real_outputs();
    initialize(c, -5.0);
    steps(c, 0.0, 10);
    let (_, first) = get_real(c, &outputs);
    unsafe {
        assert_eq!(fmi2Terminate(c), OK);
        assert_eq!(fmi2Reset(c), OK);
        // Back in Instantiated: stepping is refused, setting a fixed parameter allowed.
        assert_eq!(fmi2DoStep(c, 0.0, H, fmi2False), ERR);
    }
    initialize(c, -5.0);
    steps(c, 0.0, 10);
    let (_, second) = get_real(c, &outputs);
    assert_eq!(
        first.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        second.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn resource_locations_in_every_importer_spelling() {
    let dir = std::env::temp_dir().join(format!("flexbody fmi2 test {}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.to_str().unwrap().to_string();
    let encoded = path.replace(' ', "%20");
    let guid = default_guid();
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    // The directory has no body.json: the embedded default body (and its GUID) is used.
    for uri in [
        format!("file://{encoded}"),
        format!("file:{encoded}"),
        format!("file://localhost{encoded}"),
        format!("file:///{path}"), // OMS: "file:///" + absolute path, not encoded
        "file:///nonexistent/resources".to_string(),
    ] {
        let c = instantiate(
            Some("r"),
            fmi2CoSimulation,
            Some(&guid),
            Some(&uri),
            Some(&functions),
            false,
        );
        assert!(!c.is_null(), "{uri}: {:?}", recorder.texts());
        unsafe { fmi2FreeInstance(c) };
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn instances_are_independent_and_run_on_their_own_threads() {
    let run = |fz: f64| {
        let recorder = Recorder::default();
        let functions = callbacks(&recorder);
        let c = new_instance(&recorder, &functions);
        initialize(c, fz);
        steps(c, 0.0, 30);
        let (_, z) = get_real(c, &[TIP_Z]);
        unsafe { fmi2FreeInstance(c) };
        z[0]
    };
    let serial = [run(-10.0), run(-20.0)];
    let handles: Vec<_> = [-10.0, -20.0]
        .into_iter()
        .map(|fz| std::thread::spawn(move || run(fz)))
        .collect();
    let parallel: Vec<f64> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    assert_eq!(parallel[0].to_bits(), serial[0].to_bits());
    assert_eq!(parallel[1].to_bits(), serial[1].to_bits());
    assert!(serial[1] < serial[0], "twice the load, more deflection");
}

#[test]
fn every_output_can_be_read_in_every_readable_state() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = new_instance(&recorder, &functions);
    let outputs = real_outputs();
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(c, fmi2True, 1e-6, 0.0, fmi2False, 0.0),
            OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(get_real(c, &outputs).0, OK, "Initialization Mode");
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(get_real(c, &outputs).0, OK, "StepComplete");
        assert_eq!(fmi2Terminate(c), OK);
        assert_eq!(get_real(c, &outputs).0, OK, "Terminated");
        fmi2FreeInstance(c);
    }
}

/// `flexbody_GetStepJacobian` (docs/coupling.md, "Jacobians"): the same numbers as the slave's
/// `step_jacobian` after the same steps; in StepComplete only, with Real outputs as unknowns and
/// Real inputs as knowns, NULL arrays refused; a refused call leaves the instance stepping.
#[test]
fn the_step_jacobian_through_the_c_abi() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = new_instance(&recorder, &functions);
    let (unknowns, knowns) = ([TIP_Z, 1002], [TIP_FZ, 1101]);
    let mut jacobian = [0.0; 4];
    let call = |c, u: &[u32], k: &[u32], j: &mut [f64]| unsafe {
        flexbody_GetStepJacobian(c, u.as_ptr(), u.len(), k.as_ptr(), k.len(), j.as_mut_ptr())
    };
    // Before initialization: the calling sequence.
    assert_eq!(call(c, &unknowns, &knowns, &mut jacobian), ERR);
    assert!(
        recorder.last_text().contains("flexbody_GetStepJacobian"),
        "{}",
        recorder.last_text()
    );
    initialize(c, -10.0);
    steps(c, 0.0, 5);
    assert_eq!(
        call(c, &unknowns, &knowns, &mut jacobian),
        OK,
        "{:?}",
        recorder.texts()
    );
    // The slave's own after the same run.
    let mut s = Slave::from_resources(None).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_real(TIP_FZ, -10.0).unwrap();
    s.exit_initialization_mode().unwrap();
    for k in 0..5 {
        s.do_step(k as f64 * H, H).unwrap();
    }
    let mut expected = [0.0; 4];
    s.step_jacobian(&unknowns, &knowns, &mut expected).unwrap();
    assert_eq!(jacobian, expected);
    assert!(
        jacobian[0] > 0.0,
        "a force along z moves the tip along z: {jacobian:?}"
    );
    // Knowns must be inputs, unknowns outputs; NULL with a count is refused.
    assert_eq!(call(c, &[TIP_FZ], &knowns, &mut jacobian[..2]), ERR);
    assert!(
        recorder.last_text().contains("is not an output"),
        "{}",
        recorder.last_text()
    );
    assert_eq!(call(c, &unknowns, &[TIP_Z], &mut jacobian[..2]), ERR);
    assert!(
        recorder.last_text().contains("is not an input"),
        "{}",
        recorder.last_text()
    );
    let status = unsafe {
        flexbody_GetStepJacobian(c, null_mut(), 2, knowns.as_ptr(), 2, jacobian.as_mut_ptr())
    };
    assert_eq!(status, ERR);
    assert!(
        recorder.last_text().contains("NULL"),
        "{}",
        recorder.last_text()
    );
    // The instance steps on.
    steps(c, 5.0 * H, 1);
    unsafe { fmi2FreeInstance(c) };
}
