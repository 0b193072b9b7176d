//! The exported FMI 3.0 functions called in-process, as an importer would: the B1 cantilever
//! stepped through FMI 3.0 gives FMI 2.0's numbers bit for bit; array variables, `time`, the
//! typed accessors, FMU states, the calling sequence and the messages under FMI 3.0's names.

use flexbody::fmi2::exports as fmi2;
use flexbody::fmi2::types::{fmi2False, fmi2Status, fmi2True};
use flexbody::fmi3::exports::*;
use flexbody::fmi3::types::*;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::ffi::{c_char, c_void, CStr, CString};
use std::ptr::{null, null_mut};
use std::sync::Mutex;

const OK: fmi3Status = fmi3Status::fmi3OK;
const ERR: fmi3Status = fmi3Status::fmi3Error;

/// The importer side of the logger: every (status, category, message).
#[derive(Default)]
struct Recorder {
    messages: Mutex<Vec<(fmi3Status, String, String)>>,
}

impl Recorder {
    fn last(&self) -> String {
        let messages = self.messages.lock().unwrap();
        messages.last().map(|m| m.2.clone()).unwrap_or_default()
    }
}

unsafe extern "C" fn record(
    environment: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    let recorder = &*(environment as *const Recorder);
    let text = |p: *const c_char| CStr::from_ptr(p).to_string_lossy().into_owned();
    recorder
        .messages
        .lock()
        .unwrap()
        .push((status, text(category), text(message)));
}

fn token() -> String {
    Slave::from_body(BodyFile::default_body())
        .unwrap()
        .guid()
        .to_string()
}

/// `fmi3InstantiateCoSimulation` of the embedded default body (no resource path).
fn instantiate(recorder: &Recorder, event_mode: bool) -> fmi3Instance {
    let name = CString::new("b1").unwrap();
    let token = CString::new(token()).unwrap();
    unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            null(),
            fmi3False,
            fmi3False,
            if event_mode { fmi3True } else { fmi3False },
            fmi3False,
            null(),
            0,
            recorder as *const Recorder as *mut c_void,
            Some(record),
            None,
        )
    }
}

fn get(instance: fmi3Instance, vrs: &[u32], n: usize) -> (fmi3Status, Vec<f64>) {
    let mut values = vec![f64::NAN; n];
    let s = unsafe { fmi3GetFloat64(instance, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), n) };
    (s, values)
}

fn set(instance: fmi3Instance, vrs: &[u32], values: &[f64]) -> fmi3Status {
    unsafe {
        fmi3SetFloat64(
            instance,
            vrs.as_ptr(),
            vrs.len(),
            values.as_ptr(),
            values.len(),
        )
    }
}

fn initialize(instance: fmi3Instance) {
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(instance, fmi3False, 0.0, 0.0, fmi3False, 0.0),
            OK
        );
        assert_eq!(fmi3ExitInitializationMode(instance), OK);
    }
}

/// `n` steps of `h` from `t0`; returns the end time.
fn steps(instance: fmi3Instance, t0: f64, h: f64, n: usize) -> f64 {
    let mut t = t0;
    for _ in 0..n {
        let (mut event, mut terminate, mut early, mut last) = (1u8, 1u8, 1u8, f64::NAN);
        let s = unsafe {
            fmi3DoStep(
                instance,
                t,
                h,
                fmi3True,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        };
        assert_eq!(s, OK);
        assert_eq!((event, terminate, early), (0, 0, 0));
        t += h;
        assert_eq!(last, t);
    }
    t
}

// The value references: tip.force is the array at 1100 (FMI 2.0's tip.force[1..3] are
// 1100..1102), tip.position at 1106, body.rotation at 43.
const TIP_FORCE: u32 = 1100;
const TIP_POSITION: u32 = 1106;
const BODY_ROTATION: u32 = 43;

#[test]
fn b1_through_fmi3_equals_b1_through_fmi2_bit_for_bit() {
    let recorder = Recorder::default();
    let v3 = instantiate(&recorder, false);
    assert!(!v3.is_null(), "{}", recorder.last());
    initialize(v3);
    assert_eq!(set(v3, &[TIP_FORCE], &[0.0, 0.0, -10.0]), OK);
    let t3 = steps(v3, 0.0, 1e-3, 40);

    let name = CString::new("b1").unwrap();
    let guid = CString::new(token()).unwrap();
    let v2 = unsafe {
        fmi2::fmi2Instantiate(
            name.as_ptr(),
            flexbody::fmi2::types::fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            null(),
            fmi2False,
            fmi2False,
        )
    };
    assert!(!v2.is_null());
    unsafe {
        assert_eq!(
            fmi2::fmi2SetupExperiment(v2, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2::fmi2EnterInitializationMode(v2), fmi2Status::fmi2OK);
        assert_eq!(fmi2::fmi2ExitInitializationMode(v2), fmi2Status::fmi2OK);
        let force = [1102u32];
        assert_eq!(
            fmi2::fmi2SetReal(v2, force.as_ptr(), 1, [-10.0].as_ptr()),
            fmi2Status::fmi2OK
        );
        let mut t = 0.0;
        for _ in 0..40 {
            assert_eq!(fmi2::fmi2DoStep(v2, t, 1e-3, fmi2True), fmi2Status::fmi2OK);
            t += 1e-3;
        }
        assert_eq!(t, t3);
    }
    let (s, fmi3_values) = get(v3, &[TIP_POSITION, BODY_ROTATION, 0], 3 + 9 + 1);
    assert_eq!(s, OK);
    let scalars: Vec<u32> = (1106..1109).chain(43..52).collect();
    let mut fmi2_values = vec![f64::NAN; scalars.len()];
    let s = unsafe {
        fmi2::fmi2GetReal(
            v2,
            scalars.as_ptr(),
            scalars.len(),
            fmi2_values.as_mut_ptr(),
        )
    };
    assert_eq!(s, fmi2Status::fmi2OK);
    assert_eq!(fmi3_values[..12], fmi2_values[..]);
    assert_eq!(fmi3_values[12], t3, "time");
    assert!(
        fmi3_values[2] < -1e-5,
        "the tip moves down: {}",
        fmi3_values[2]
    );
    unsafe {
        fmi3FreeInstance(v3);
        fmi2::fmi2FreeInstance(v2);
    }
}

#[test]
fn arrays_time_and_types_are_checked_with_fmi3_names() {
    let recorder = Recorder::default();
    let c = instantiate(&recorder, false);
    assert!(!c.is_null());
    // The calling sequence, in FMI 3.0's words.
    let (mut e, mut t, mut r, mut l) = (0u8, 0u8, 0u8, 0.0);
    let s = unsafe { fmi3DoStep(c, 0.0, 1e-3, fmi3False, &mut e, &mut t, &mut r, &mut l) };
    assert_eq!(s, ERR);
    assert!(
        recorder
            .last()
            .starts_with("fmi3DoStep: not allowed in state Instantiated (allowed in: StepMode)"),
        "{}",
        recorder.last()
    );
    initialize(c);

    // A 3-vector takes 3 values; a wrong count, or an element's own value reference, is refused.
    assert_eq!(get(c, &[TIP_POSITION], 3).0, OK);
    assert_eq!(get(c, &[TIP_POSITION], 2).0, ERR);
    assert!(
        recorder.last().contains("nValues = 2"),
        "{}",
        recorder.last()
    );
    assert_eq!(get(c, &[TIP_POSITION + 1], 1).0, ERR);
    assert!(
        recorder.last().contains("unknown value reference 1107"),
        "{}",
        recorder.last()
    );
    // Outputs and time cannot be set; a set with a bad value sets nothing.
    assert_eq!(set(c, &[0], &[1.0]), ERR);
    assert!(recorder.last().contains("time"), "{}", recorder.last());
    assert_eq!(set(c, &[TIP_POSITION], &[0.0; 3]), ERR);
    assert_eq!(set(c, &[TIP_FORCE], &[1.0, 2.0, f64::NAN]), ERR);
    assert!(
        recorder.last().contains("tip.force[3]"),
        "{}",
        recorder.last()
    );
    assert_eq!(get(c, &[TIP_FORCE], 3).1, vec![0.0; 3]);

    // Enumerations are Int64, counts Int32, flags Boolean, the output directory a String.
    let integrator = [29u32];
    let mut wide = [0i64];
    let s = unsafe { fmi3GetInt64(c, integrator.as_ptr(), 1, wide.as_mut_ptr(), 1) };
    assert_eq!((s, wide[0]), (OK, 1));
    let mut narrow = [0i32];
    let s = unsafe { fmi3GetInt32(c, integrator.as_ptr(), 1, narrow.as_mut_ptr(), 1) };
    assert_eq!(s, ERR);
    assert!(
        recorder.last().contains("solver.integrator") && recorder.last().contains("Int64"),
        "{}",
        recorder.last()
    );
    let frames = [39u32];
    let s = unsafe { fmi3GetInt32(c, frames.as_ptr(), 1, narrow.as_mut_ptr(), 1) };
    assert_eq!((s, narrow[0]), (OK, 1));
    let auto = [9u32];
    let mut flag = [7u8];
    let s = unsafe { fmi3GetBoolean(c, auto.as_ptr(), 1, flag.as_mut_ptr(), 1) };
    assert_eq!((s, flag[0]), (OK, fmi3True));
    let directory = [37u32];
    let mut text: [fmi3String; 1] = [null()];
    let s = unsafe { fmi3GetString(c, directory.as_ptr(), 1, text.as_mut_ptr(), 1) };
    assert_eq!(s, OK);
    assert_eq!(unsafe { CStr::from_ptr(text[0]) }.to_str().unwrap(), "");
    // Types without variables: an empty request is fine, a value reference is unknown.
    let mut small = [0.0f32];
    assert_eq!(
        unsafe { fmi3GetFloat32(c, null(), 0, small.as_mut_ptr(), 0) },
        OK
    );
    assert_eq!(
        unsafe { fmi3GetFloat32(c, frames.as_ptr(), 1, small.as_mut_ptr(), 1) },
        ERR
    );
    assert!(recorder.last().contains("no Float32 variables"));
    assert_eq!(unsafe { fmi3EnterStepMode(c) }, ERR);
    assert_eq!(unsafe { fmi3EnterEventMode(c) }, ERR);
    unsafe { fmi3FreeInstance(c) };
}

#[test]
fn fmu_state_rollback_and_serialization_repeat_the_steps_bit_for_bit() {
    let recorder = Recorder::default();
    let c = instantiate(&recorder, false);
    initialize(c);
    assert_eq!(set(c, &[TIP_FORCE], &[0.0, 5.0, -10.0]), OK);
    let t = steps(c, 0.0, 1e-3, 5);
    let mut state: fmi3FMUState = null_mut();
    assert_eq!(unsafe { fmi3GetFMUState(c, &mut state) }, OK);
    let mut size = 0usize;
    assert_eq!(
        unsafe { fmi3SerializedFMUStateSize(c, state, &mut size) },
        OK
    );
    let mut bytes = vec![0u8; size];
    assert_eq!(
        unsafe { fmi3SerializeFMUState(c, state, bytes.as_mut_ptr(), size) },
        OK
    );
    let end = steps(c, t, 1e-3, 5);
    let first = get(c, &[TIP_POSITION, 0], 4).1;
    assert_eq!(first[3], end);

    assert_eq!(unsafe { fmi3SetFMUState(c, state) }, OK);
    steps(c, t, 1e-3, 5);
    assert_eq!(get(c, &[TIP_POSITION, 0], 4).1, first);

    let mut restored: fmi3FMUState = null_mut();
    assert_eq!(
        unsafe { fmi3DeserializeFMUState(c, bytes.as_ptr(), size, &mut restored) },
        OK
    );
    assert_eq!(unsafe { fmi3SetFMUState(c, restored) }, OK);
    steps(c, t, 1e-3, 5);
    assert_eq!(get(c, &[TIP_POSITION, 0], 4).1, first);
    unsafe {
        assert_eq!(fmi3FreeFMUState(c, &mut state), OK);
        assert_eq!(fmi3FreeFMUState(c, &mut restored), OK);
        assert!(state.is_null() && restored.is_null());
        assert_eq!(fmi3Terminate(c), OK);
        assert_eq!(fmi3Reset(c), OK);
        fmi3FreeInstance(c);
    }
}

#[test]
fn what_this_fmu_does_not_offer_is_refused_with_a_message() {
    let recorder = Recorder::default();
    assert!(instantiate(&recorder, true).is_null());
    assert!(
        recorder.last().contains("eventModeUsed"),
        "{}",
        recorder.last()
    );

    let name = CString::new("me").unwrap();
    let token = CString::new(token()).unwrap();
    let me = unsafe {
        fmi3InstantiateModelExchange(
            name.as_ptr(),
            token.as_ptr(),
            null(),
            fmi3False,
            fmi3False,
            &recorder as *const Recorder as *mut c_void,
            Some(record),
        )
    };
    assert!(me.is_null());
    assert!(
        recorder
            .last()
            .starts_with("fmi3InstantiateModelExchange: me: this FMU supports co-simulation only"),
        "{}",
        recorder.last()
    );

    let wrong = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
    let c = unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            wrong.as_ptr(),
            null(),
            fmi3False,
            fmi3False,
            fmi3False,
            fmi3False,
            null(),
            0,
            &recorder as *const Recorder as *mut c_void,
            Some(record),
            None,
        )
    };
    assert!(c.is_null());
    assert!(
        recorder
            .last()
            .starts_with("fmi3InstantiateCoSimulation: me:"),
        "{}",
        recorder.last()
    );
    assert_eq!(
        unsafe { CStr::from_ptr(fmi3GetVersion()) }
            .to_str()
            .unwrap(),
        "3.0"
    );
    // A NULL instance is an error, not a crash.
    assert_eq!(unsafe { fmi3Terminate(null_mut()) }, ERR);
}

#[test]
fn a_discarded_step_is_rolled_back_and_a_shorter_one_may_follow() {
    // 100 MN at the tip with the plain iteration: the step of 1 ms does not converge (as in
    // tests/python/test_capabilities.py); FMI 3.0 keeps the instance in Step Mode.
    let recorder = Recorder::default();
    let c = instantiate(&recorder, false);
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0),
            OK
        );
    }
    let depth = [38u32];
    let zero = [0i32];
    assert_eq!(
        unsafe { fmi3SetInt32(c, depth.as_ptr(), 1, zero.as_ptr(), 1) },
        OK
    );
    assert_eq!(set(c, &[TIP_FORCE], &[0.0, -1e8, 0.0]), OK);
    assert_eq!(unsafe { fmi3ExitInitializationMode(c) }, OK);
    let before = get(c, &[TIP_POSITION, 0], 4).1;
    let (mut e, mut t, mut r, mut l) = (1u8, 1u8, 1u8, f64::NAN);
    let s = unsafe { fmi3DoStep(c, 0.0, 1e-3, fmi3False, &mut e, &mut t, &mut r, &mut l) };
    assert_eq!(s, fmi3Status::fmi3Discard);
    assert_eq!((t, l), (fmi3False, 0.0));
    // loggingOn = false: FMI 3.0 allows messages for fmi3Error and fmi3Fatal only.
    assert!(
        recorder.messages.lock().unwrap().is_empty(),
        "{:?}",
        recorder.messages.lock().unwrap()
    );
    assert_eq!(get(c, &[TIP_POSITION, 0], 4).1, before, "rolled back");
    // Still in Step Mode: inputs may be set and a shorter step taken.
    assert_eq!(set(c, &[TIP_FORCE], &[0.0, -1e8, 0.0]), OK);
    let s = unsafe { fmi3DoStep(c, 0.0, 1e-4, fmi3False, &mut e, &mut t, &mut r, &mut l) };
    assert_eq!(s, OK, "{}", recorder.last());
    assert_eq!(l, 1e-4);
    unsafe { fmi3FreeInstance(c) };
}

#[test]
fn start_values_can_be_read_in_instantiated_and_outputs_cannot() {
    // FMI 3.0, "State: Instantiated": fmi3Get* returns the start values (as set by fmi3Set*).
    let variables = Slave::from_body(BodyFile::default_body()).unwrap();
    let vr = |name: &str| variables.variables().by_name(name).unwrap().value_reference;
    let recorder = Recorder::default();
    let c = instantiate(&recorder, false);
    let (beta, step) = (vr("damping.beta"), vr("solver.stepSize"));
    let (s, start) = get(c, &[beta, step, TIP_FORCE], 5);
    assert_eq!(s, OK, "{}", recorder.last());
    let body = BodyFile::default_body();
    assert_eq!(start[1], body.solver.step_size);
    assert_eq!(&start[2..], &[0.0; 3]);
    assert_eq!(set(c, &[beta], &[1e-3]), OK);
    assert_eq!(get(c, &[beta], 1), (OK, vec![1e-3]));
    // An output has no start value: refused with its name and the reason.
    let (s, _) = get(c, &[TIP_POSITION], 3);
    assert_eq!(s, ERR);
    let message = recorder.last();
    assert!(
        message.contains("tip.position") && message.contains("fmi3EnterInitializationMode"),
        "{message}"
    );
    initialize(c);
    assert_eq!(get(c, &[beta], 1), (OK, vec![1e-3]));
    unsafe { fmi3FreeInstance(c) };
}

/// `flexbody_fmi3GetStepJacobian` (docs/coupling.md, "Jacobians"): over array elements, the
/// same numbers as the slave's step Jacobian after the same steps (tip.position[3] against
/// tip.force[3]: a 3 × 3 block); a wrong nJacobian and `time` are refused by name.
#[test]
fn the_step_jacobian_through_fmi3_over_array_elements() {
    let recorder = Recorder::default();
    let instance = instantiate(&recorder, false);
    initialize(instance);
    assert_eq!(set(instance, &[TIP_FORCE], &[0.0, -10.0, 0.0]), OK);
    steps(instance, 0.0, 1e-3, 5);
    let mut jacobian = [0.0; 9];
    let call = |u: &[u32], k: &[u32], j: &mut [f64]| unsafe {
        flexbody_fmi3GetStepJacobian(
            instance,
            u.as_ptr(),
            u.len(),
            k.as_ptr(),
            k.len(),
            j.as_mut_ptr(),
            j.len(),
        )
    };
    assert_eq!(call(&[TIP_POSITION], &[TIP_FORCE], &mut jacobian), OK);
    let mut s = Slave::from_body(BodyFile::default_body()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    s.set_real(TIP_FORCE + 1, -10.0).unwrap();
    for k in 0..5 {
        s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
    }
    let rows = [TIP_POSITION, TIP_POSITION + 1, TIP_POSITION + 2];
    let columns = [TIP_FORCE, TIP_FORCE + 1, TIP_FORCE + 2];
    let mut expected = [0.0; 9];
    s.step_jacobian(&rows, &columns, &mut expected).unwrap();
    assert_eq!(jacobian, expected);
    assert!(jacobian[4] > 0.0, "a force along y moves the tip along y");
    assert_eq!(call(&[TIP_POSITION], &[TIP_FORCE], &mut jacobian[..8]), ERR);
    assert!(
        recorder.last().contains("nJacobian = 8"),
        "{}",
        recorder.last()
    );
    assert_eq!(call(&[0], &[TIP_FORCE], &mut jacobian[..3]), ERR);
    assert!(recorder.last().contains("time"), "{}", recorder.last());
    // Several arrays, a [3,3] one among them: rows tip.position then tip.rotation (12),
    // columns tip.force then tip.torque (6), each array's elements in row-major order.
    let (tip_rotation, tip_torque) = (TIP_POSITION + 3, TIP_FORCE + 3);
    let mut big = [0.0; 72];
    assert_eq!(
        call(
            &[TIP_POSITION, tip_rotation],
            &[TIP_FORCE, tip_torque],
            &mut big
        ),
        OK
    );
    let rows: Vec<u32> = (TIP_POSITION..TIP_POSITION + 12).collect();
    let columns: Vec<u32> = (TIP_FORCE..TIP_FORCE + 6).collect();
    let mut expected = [0.0; 72];
    s.step_jacobian(&rows, &columns, &mut expected).unwrap();
    assert_eq!(big, expected);
    // An unknown value reference is named (before the sizes are checked).
    assert_eq!(call(&[9999], &[TIP_FORCE], &mut jacobian[..3]), ERR);
    assert!(recorder.last().contains("9999"), "{}", recorder.last());
    unsafe { fmi3FreeInstance(instance) };
    // Before a step: the calling sequence.
    let fresh = instantiate(&recorder, false);
    let status = unsafe {
        flexbody_fmi3GetStepJacobian(
            fresh,
            [TIP_POSITION].as_ptr(),
            1,
            [TIP_FORCE].as_ptr(),
            1,
            jacobian.as_mut_ptr(),
            9,
        )
    };
    assert_eq!(status, ERR);
    assert!(
        recorder.last().contains("flexbody_fmi3GetStepJacobian"),
        "{}",
        recorder.last()
    );
    unsafe { fmi3FreeInstance(fresh) };
}
