//! The state machine against a mock slave (the physics is not needed to test the calling
//! sequence). Value references are those of the default body's table: 1 = Young's modulus
//! (fixed parameter), 6 = gravity[1] (tunable), 33 = maxIterations (Integer), 34 =
//! nonlinearForces (Boolean), 40 = body.position[1] (output), 1100 = tip.force[1] (input;
//! `tip` is the second interface).
use super::*;
use crate::error::Result;
use crate::fmi2::logger::Sink;
use crate::fmi2::types::{
    fmi2LastSuccessfulTime as LAST_SUCCESSFUL_TIME, fmi2Terminated as TERMINATED,
};
use crate::model::{BodyFile, Causality, Variability, VariableTable, VariableType};
use crate::Error;
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

const YOUNG: u32 = 1;
const GRAVITY_X: u32 = 6;
const MAX_ITER: u32 = 33;
const NONLINEAR: u32 = 34;
const BODY_X: u32 = 40;
const TIP_FX: u32 = 1100;

#[derive(Clone, PartialEq, Debug)]
struct MockState {
    time: f64,
    reals: HashMap<u32, f64>,
}

struct Mock {
    table: VariableTable,
    time: f64,
    reals: HashMap<u32, f64>,
    ints: HashMap<u32, i32>,
    bools: HashMap<u32, bool>,
    /// The next do_step fails with this error.
    fail_next_step: Option<Error>,
    resets: usize,
}

impl Mock {
    fn new() -> Mock {
        Mock {
            table: VariableTable::new(&BodyFile::default_body().interfaces),
            time: 0.0,
            reals: HashMap::new(),
            ints: HashMap::new(),
            bools: HashMap::new(),
            fail_next_step: None,
            resets: 0,
        }
    }
}

impl CoSimSlave for Mock {
    type State = MockState;
    fn guid(&self) -> &str {
        "{mock}"
    }
    fn variables(&self) -> &VariableTable {
        &self.table
    }
    fn setup_experiment(&mut self, start: f64, _: Option<f64>, _: Option<f64>) -> Result<()> {
        self.time = start;
        Ok(())
    }
    fn enter_initialization_mode(&mut self) -> Result<()> {
        Ok(())
    }
    fn exit_initialization_mode(&mut self) -> Result<()> {
        match self.reals.get(&YOUNG) {
            Some(&e) if e <= 0.0 => Err(Error::invalid_value(
                "material.youngsModulus",
                e,
                "must be > 0",
            )),
            _ => Ok(()),
        }
    }
    fn get_real(&mut self, vr: u32) -> Result<f64> {
        Ok(self.reals.get(&vr).copied().unwrap_or(0.0))
    }
    fn set_real(&mut self, vr: u32, value: f64) -> Result<()> {
        if value.is_nan() {
            return Err(Error::invalid_value("x", value, "NaN"));
        }
        self.reals.insert(vr, value);
        Ok(())
    }
    fn get_integer(&mut self, vr: u32) -> Result<i32> {
        Ok(self.ints.get(&vr).copied().unwrap_or(25))
    }
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<()> {
        self.ints.insert(vr, value);
        Ok(())
    }
    fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        Ok(self.bools.get(&vr).copied().unwrap_or(false))
    }
    fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()> {
        self.bools.insert(vr, value);
        Ok(())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<()> {
        if let Some(e) = self.fail_next_step.take() {
            return Err(e);
        }
        if (t - self.time).abs() > 1e-5 * h {
            return Err(Error::new(format!("t = {t} does not match {}", self.time)));
        }
        self.time = t + h;
        *self.reals.entry(BODY_X).or_insert(0.0) += h;
        Ok(())
    }
    fn time(&self) -> f64 {
        self.time
    }
    fn reset(&mut self) {
        let table = self.table.clone();
        let resets = self.resets + 1;
        *self = Mock::new();
        self.table = table;
        self.resets = resets;
    }
    fn get_state(&self) -> MockState {
        MockState {
            time: self.time,
            reals: self.reals.clone(),
        }
    }
    fn set_state(&mut self, s: &MockState) -> Result<()> {
        self.time = s.time;
        self.reals = s.reals.clone();
        Ok(())
    }
    fn state_to_bytes(&self, s: &MockState, out: &mut Vec<u8>) {
        out.extend_from_slice(&s.time.to_le_bytes());
        let mut reals: Vec<_> = s.reals.iter().collect();
        reals.sort_by_key(|(vr, _)| **vr);
        for (vr, x) in reals {
            out.extend_from_slice(&vr.to_le_bytes());
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<MockState> {
        if bytes.len() < 8 || !(bytes.len() - 8).is_multiple_of(12) {
            return Err(Error::new("mock state: bad length"));
        }
        let time = f64::from_le_bytes(bytes[..8].try_into().unwrap());
        let reals = bytes[8..]
            .chunks(12)
            .map(|c| {
                (
                    u32::from_le_bytes(c[..4].try_into().unwrap()),
                    f64::from_le_bytes(c[4..].try_into().unwrap()),
                )
            })
            .collect();
        Ok(MockState { time, reals })
    }
    fn set_real_input_derivatives(&mut self, _: &[u32], _: &[i32], _: &[f64]) -> Result<()> {
        Ok(())
    }
    fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64> {
        if order == 1 {
            Ok(self.reals.get(&vr).copied().unwrap_or(0.0) * 10.0)
        } else {
            Err(Error::new("no such derivative"))
        }
    }
}

type Log = Rc<RefCell<Vec<(fmi2Status, String, String)>>>;

#[test]
fn the_value_references_used_here_name_the_expected_variables() {
    let table = Mock::new().table;
    for (ty, vr, name, causality, variability) in [
        (
            VariableType::Real,
            YOUNG,
            "material.youngsModulus",
            Causality::Parameter,
            Variability::Fixed,
        ),
        (
            VariableType::Real,
            GRAVITY_X,
            "gravity[1]",
            Causality::Parameter,
            Variability::Tunable,
        ),
        (
            VariableType::Integer,
            MAX_ITER,
            "solver.maxIterations",
            Causality::Parameter,
            Variability::Fixed,
        ),
        (
            VariableType::Boolean,
            NONLINEAR,
            "model.nonlinearForces",
            Causality::Parameter,
            Variability::Fixed,
        ),
        (
            VariableType::Real,
            BODY_X,
            "body.position[1]",
            Causality::Output,
            Variability::Continuous,
        ),
        (
            VariableType::Real,
            TIP_FX,
            "tip.force[1]",
            Causality::Input,
            Variability::Continuous,
        ),
    ] {
        let v = table
            .get(ty, vr)
            .unwrap_or_else(|| panic!("no {name} at {vr}"));
        assert_eq!(
            (v.name.as_str(), v.causality, v.variability),
            (name, causality, variability)
        );
    }
}

fn instance(logging_on: bool) -> (Instance<Mock>, Log) {
    let log: Log = Rc::default();
    let sink = log.clone();
    let logger = Logger::new(
        Sink::Rust(Box::new(move |s, c, m| {
            sink.borrow_mut().push((s, c.into(), m.into()))
        })),
        "test",
        logging_on,
    );
    (Instance::new(Mock::new(), logger), log)
}

fn last_message(log: &Log) -> String {
    log.borrow().last().map(|m| m.2.clone()).unwrap_or_default()
}

/// Instantiated → InitializationMode → StepComplete.
fn initialized() -> (Instance<Mock>, Log) {
    let (mut i, log) = instance(false);
    assert_eq!(i.setup_experiment(None, 0.0, None), fmi2Status::fmi2OK);
    assert_eq!(i.enter_initialization_mode(), fmi2Status::fmi2OK);
    assert_eq!(i.exit_initialization_mode(), fmi2Status::fmi2OK);
    assert_eq!(i.state(), M::StepComplete);
    (i, log)
}

const OK: fmi2Status = fmi2Status::fmi2OK;
const ERR: fmi2Status = fmi2Status::fmi2Error;

#[test]
fn full_calling_sequence() {
    let (mut i, log) = instance(false);
    assert_eq!(
        i.set_values("fmi2SetReal", &[YOUNG, TIP_FX], &[2.0e11, 1.0]),
        OK
    );
    assert_eq!(i.setup_experiment(Some(1e-6), 0.5, Some(2.0)), OK);
    assert_eq!(i.enter_initialization_mode(), OK);
    assert_eq!(i.set_values("fmi2SetInteger", &[MAX_ITER], &[7]), OK);
    assert_eq!(i.set_values("fmi2SetBoolean", &[NONLINEAR], &[true]), OK);
    assert_eq!(i.exit_initialization_mode(), OK);
    assert_eq!(i.state(), M::StepComplete);
    assert_eq!(i.do_step(0.5, 0.25), OK);
    assert_eq!(i.do_step(0.75, 0.25), OK);
    let mut out = [f64::NAN; 2];
    assert_eq!(i.get_values("fmi2GetReal", &[BODY_X, YOUNG], &mut out), OK);
    assert_eq!(out, [0.5, 2.0e11]);
    let mut n = [0i32];
    assert_eq!(i.get_values("fmi2GetInteger", &[MAX_ITER], &mut n), OK);
    assert_eq!(n, [7]);
    let mut b = [false];
    assert_eq!(i.get_values("fmi2GetBoolean", &[NONLINEAR], &mut b), OK);
    assert!(b[0]);
    assert_eq!(i.get_real_status(LAST_SUCCESSFUL_TIME), Ok(1.0));
    assert_eq!(i.get_boolean_status(TERMINATED), Ok(false));
    assert_eq!(i.terminate(), OK);
    assert_eq!(i.state(), M::Terminated);
    // Outputs can still be read after fmi2Terminate.
    assert_eq!(i.get_values("fmi2GetReal", &[BODY_X], &mut out[..1]), OK);
    assert_eq!(i.reset(), OK);
    assert_eq!(i.state(), M::Instantiated);
    assert_eq!(i.slave().resets, 1);
    assert!(log.borrow().is_empty(), "{:?}", log.borrow());
}

#[test]
fn calls_in_the_wrong_state_are_errors_that_name_function_and_state() {
    let (mut i, log) = instance(false);
    let mut x = [0.0];
    type Call = Box<dyn Fn(&mut Instance<Mock>) -> fmi2Status>;
    let cases: Vec<(&str, Call)> = vec![
        ("fmi2DoStep", Box::new(|i| i.do_step(0.0, 0.1))),
        (
            "fmi2ExitInitializationMode",
            Box::new(|i| i.exit_initialization_mode()),
        ),
        ("fmi2Terminate", Box::new(|i| i.terminate())),
        (
            "fmi2GetBooleanStatus",
            Box::new(|i| i.get_boolean_status(3).unwrap_err()),
        ),
    ];
    for (name, f) in &cases {
        assert_eq!(f(&mut i), ERR, "{name}");
        let m = last_message(&log);
        assert!(
            m.starts_with(name) && m.contains("state Instantiated"),
            "{m}"
        );
        assert_eq!(i.state(), M::Instantiated, "{name} changed the state");
    }
    assert_eq!(i.get_values("fmi2GetReal", &[BODY_X], &mut x), ERR);
    assert!(last_message(&log).contains("fmi2GetReal: not allowed in state Instantiated"));

    let (mut i, log) = initialized();
    assert_eq!(i.setup_experiment(None, 0.0, None), ERR);
    assert!(last_message(&log).contains("fmi2SetupExperiment: not allowed in state StepComplete"));
    assert_eq!(i.enter_initialization_mode(), ERR);
    assert_eq!(i.state(), M::StepComplete);
    assert_eq!(i.terminate(), OK);
    assert_eq!(i.do_step(0.0, 0.1), ERR);
    assert_eq!(i.set_values("fmi2SetReal", &[TIP_FX], &[1.0]), ERR);
    assert!(last_message(&log).contains("state Terminated"));
}

#[test]
fn settability_follows_fmi_2_table() {
    // Instantiated and InitializationMode: parameters (fixed and tunable) and inputs.
    let (mut i, log) = instance(false);
    assert_eq!(
        i.set_values("fmi2SetReal", &[YOUNG, GRAVITY_X, TIP_FX], &[1.0, 2.0, 3.0]),
        OK
    );
    assert_eq!(i.set_values("fmi2SetReal", &[BODY_X], &[1.0]), ERR);
    assert!(
        last_message(&log).contains("body.position[1] is an output"),
        "{}",
        last_message(&log)
    );
    i.enter_initialization_mode();
    assert_eq!(
        i.set_values("fmi2SetReal", &[YOUNG, GRAVITY_X, TIP_FX], &[1.0, 2.0, 3.0]),
        OK
    );
    assert_eq!(i.set_values("fmi2SetBoolean", &[NONLINEAR], &[true]), OK);
    i.exit_initialization_mode();

    // StepComplete: inputs and tunable parameters only.
    assert_eq!(
        i.set_values("fmi2SetReal", &[GRAVITY_X, TIP_FX], &[-9.81, 4.0]),
        OK
    );
    assert_eq!(i.slave().reals[&GRAVITY_X], -9.81);
    // A fixed parameter in the list: nothing is set.
    assert_eq!(
        i.set_values("fmi2SetReal", &[TIP_FX, YOUNG], &[5.0, 7.0]),
        ERR
    );
    let m = last_message(&log);
    assert!(
        m.contains("material.youngsModulus") && m.contains("value reference 1"),
        "{m}"
    );
    assert_eq!(i.slave().reals[&TIP_FX], 4.0, "a rejected call set a value");
    assert_eq!(i.set_values("fmi2SetBoolean", &[NONLINEAR], &[false]), ERR);
    assert_eq!(i.set_values("fmi2SetInteger", &[MAX_ITER], &[3]), ERR);
    assert_eq!(i.set_values("fmi2SetReal", &[BODY_X], &[1.0]), ERR);
}

#[test]
fn unknown_value_references_and_wrong_types_are_named() {
    let (mut i, log) = initialized();
    let mut x = [0.0];
    assert_eq!(i.get_values("fmi2GetReal", &[999], &mut x), ERR);
    assert!(last_message(&log).contains("unknown Real value reference 999"));
    assert_eq!(i.get_values("fmi2GetReal", &[NONLINEAR], &mut x), ERR);
    let m = last_message(&log);
    assert!(
        m.contains("value reference 34 is the Boolean variable model.nonlinearForces"),
        "{m}"
    );
    let mut b = [false];
    assert_eq!(i.get_values("fmi2GetBoolean", &[YOUNG], &mut b), ERR);
    assert!(last_message(&log).contains("not a Boolean variable"));
    assert_eq!(i.set_values("fmi2SetInteger", &[12345], &[1]), ERR);
    assert!(last_message(&log).contains("unknown Integer value reference 12345"));
    assert_eq!(i.get_strings("fmi2GetString", &[]).0, OK);
    assert_eq!(i.get_strings("fmi2GetString", &[YOUNG]).0, ERR);
    assert!(last_message(&log).contains("not a String variable"));
    assert_eq!(
        i.set_strings("fmi2SetString", &[YOUNG], &[Some("x".into())]),
        ERR
    );
    assert!(last_message(&log).contains("not a String variable"));
    assert_eq!(i.get_strings("fmi2GetString", &[12345]).0, ERR);
    assert!(last_message(&log).contains("unknown String value reference 12345"));
    assert_eq!(i.state(), M::StepComplete);
}

#[test]
fn non_finite_outputs_are_refused() {
    let (mut i, log) = initialized();
    i.slave.reals.insert(BODY_X, f64::NAN);
    let mut x = [0.0];
    assert_eq!(i.get_values("fmi2GetReal", &[BODY_X], &mut x), ERR);
    assert!(last_message(&log).contains("body.position[1] (value reference 40) is NaN"));
}

#[test]
fn slave_value_errors_are_passed_on() {
    let (mut i, log) = instance(false);
    assert_eq!(i.set_values("fmi2SetReal", &[TIP_FX], &[f64::NAN]), ERR);
    assert!(last_message(&log).contains("rejected"));
    assert_eq!(i.state(), M::Instantiated);
}

#[test]
fn discarded_step_gives_step_failed_and_rollback_recovers() {
    let (mut i, log) = initialized();
    assert_eq!(i.do_step(0.0, 0.1), OK);
    let saved = i.snapshot("fmi2GetFMUstate").unwrap();
    i.slave.fail_next_step = Some(Error::discard("no convergence in 25 iterations"));
    assert_eq!(i.do_step(0.1, 0.1), fmi2Status::fmi2Discard);
    assert_eq!(i.state(), M::StepFailed);
    {
        let l = log.borrow();
        let (s, c, m) = l.last().unwrap();
        assert_eq!(*s, fmi2Status::fmi2Discard);
        assert_eq!(c, "logStatusDiscard");
        assert!(m.contains("fmi2DoStep: no convergence"), "{m}");
    }
    assert_eq!(i.get_boolean_status(TERMINATED), Ok(true));
    assert_eq!(i.get_real_status(LAST_SUCCESSFUL_TIME), Ok(0.1));
    assert_eq!(i.do_step(0.1, 0.1), ERR, "no step from StepFailed");
    // Outputs stay readable.
    let mut x = [0.0];
    assert_eq!(i.get_values("fmi2GetReal", &[BODY_X], &mut x), OK);

    assert_eq!(i.restore(&saved), OK);
    assert_eq!(i.state(), M::StepComplete);
    assert_eq!(i.get_boolean_status(TERMINATED), Ok(false));
    assert_eq!(i.do_step(0.1, 0.1), OK);
    // The snapshot is still valid and can be used again.
    assert_eq!(i.restore(&saved), OK);
    assert_eq!(i.slave().time, 0.1);
    assert_eq!(i.terminate(), OK);
}

#[test]
fn step_errors_enter_error_state_and_reset_leaves_it() {
    let (mut i, log) = initialized();
    assert_eq!(i.do_step(0.3, 0.1), ERR, "wrong communication point");
    assert!(last_message(&log).contains("does not match"));
    assert_eq!(i.state(), M::Error);
    assert_eq!(i.do_step(0.0, 0.1), ERR);
    assert_eq!(i.terminate(), ERR);
    let mut x = [0.0];
    assert_eq!(i.get_values("fmi2GetReal", &[BODY_X], &mut x), OK);
    assert_eq!(i.reset(), OK);
    assert_eq!(i.state(), M::Instantiated);
    assert_eq!(
        i.get_boolean_status(TERMINATED),
        Err(ERR),
        "Instantiated has no status"
    );
}

#[test]
fn bad_step_arguments_change_nothing() {
    let (mut i, log) = initialized();
    for h in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        assert_eq!(i.do_step(0.0, h), ERR, "h = {h}");
        assert!(last_message(&log).contains("communicationStepSize"));
        assert_eq!(i.state(), M::StepComplete);
    }
    assert_eq!(i.do_step(f64::NAN, 0.1), ERR);
    assert_eq!(i.do_step(0.0, 0.1), OK);
}

#[test]
fn setup_experiment_checks_its_arguments() {
    let (mut i, _) = instance(false);
    assert_eq!(i.setup_experiment(None, 1.0, Some(0.5)), ERR);
    assert_eq!(i.setup_experiment(None, f64::NAN, None), ERR);
    assert_eq!(i.setup_experiment(Some(0.0), 0.0, None), ERR);
    assert_eq!(
        i.setup_experiment(Some(1e-4), 0.0, None),
        OK,
        "stop time is optional"
    );
}

#[test]
fn failed_initialization_enters_error() {
    let (mut i, log) = instance(false);
    i.set_values("fmi2SetReal", &[YOUNG], &[-1.0]);
    i.enter_initialization_mode();
    assert_eq!(i.exit_initialization_mode(), ERR);
    assert!(last_message(&log).contains("material.youngsModulus = -1 rejected"));
    assert_eq!(i.state(), M::Error);
}

#[test]
fn status_queries() {
    let (mut i, log) = initialized();
    for kind in 0..5 {
        assert_eq!(i.get_status(kind), Err(ERR));
        assert_eq!(i.get_integer_status(kind), Err(ERR));
        assert_eq!(i.get_string_status(kind), ERR);
    }
    assert!(last_message(&log).contains("unknown status kind fmi2StatusKind(4)"));
    assert_eq!(i.get_real_status(3), Err(ERR));
    assert!(last_message(&log).contains("use fmi2GetBooleanStatus"));
    assert_eq!(i.get_boolean_status(2), Err(ERR));
    assert!(last_message(&log).contains("use fmi2GetRealStatus"));
}

#[test]
fn debug_messages_follow_the_logging_switch() {
    let (mut i, log) = instance(false);
    i.setup_experiment(None, 0.0, None);
    assert!(log.borrow().is_empty());
    assert_eq!(i.set_debug_logging(true, Some(&["logEvents"])), OK);
    i.enter_initialization_mode();
    assert_eq!(log.borrow().len(), 1);
    assert_eq!(log.borrow()[0].1, "logEvents");
    assert_eq!(i.set_debug_logging(true, Some(&["logBogus"])), ERR);
    assert!(last_message(&log).contains("logBogus"));
}

#[test]
fn panic_enters_error_state() {
    let (mut i, log) = initialized();
    assert_eq!(i.panicked("fmi2DoStep", "index out of bounds"), ERR);
    assert_eq!(i.state(), M::Error);
    assert!(last_message(&log).contains("fmi2DoStep: internal error (panic): index out of bounds"));
}

#[test]
fn serialized_snapshot_round_trips_and_damaged_bytes_are_refused() {
    let (mut i, log) = initialized();
    assert_eq!(i.do_step(0.0, 0.25), OK);
    let s = i.snapshot("fmi2GetFMUstate").unwrap();
    let bytes = i.serialize_snapshot("fmi2SerializeFMUstate", &s).unwrap();
    assert_eq!(&bytes[..8], b"FLEXBODY");
    let back = i.deserialize_snapshot(&bytes).unwrap();
    assert_eq!(back.slave, s.slave);
    assert_eq!(
        (back.machine, back.guid.as_str()),
        (M::StepComplete, "{mock}")
    );
    // Trailing zeros (a larger buffer) are fine; anything else is not.
    let mut padded = bytes.clone();
    padded.extend_from_slice(&[0; 7]);
    assert!(i.deserialize_snapshot(&padded).is_ok());
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (bytes[..bytes.len() - 1].to_vec(), "truncated"),
        (b"NOTFLEXB".to_vec(), "do not start with"),
        (
            [&bytes[..8], &99u32.to_le_bytes(), &bytes[12..]].concat(),
            "format version 99",
        ),
        (
            [&bytes[..16], b"{mocx}", &bytes[22..]].concat(),
            "GUID {mocx}",
        ),
        ([&bytes[..], &[1]].concat(), "not zero"),
    ];
    for (bad, fragment) in cases {
        assert_eq!(i.deserialize_snapshot(&bad).err(), Some(ERR), "{fragment}");
        let m = last_message(&log);
        assert!(m.contains(fragment), "{fragment}: {m}");
    }
    assert_eq!(i.state(), M::StepComplete);
}

#[test]
fn cancel_step_is_a_calling_sequence_error_in_every_state() {
    let (mut i, log) = initialized();
    assert_eq!(i.cancel_step(), ERR);
    assert!(last_message(&log).contains("StepInProgress"));
    assert_eq!(i.state(), M::StepComplete);
    assert_eq!(i.do_step(0.0, 0.1), OK);
}

#[test]
fn derivative_calls_check_causality_order_and_state() {
    let (mut i, log) = instance(false);
    let mut x = [0.0];
    assert_eq!(i.set_real_input_derivatives(&[TIP_FX], &[1], &[2.0]), OK);
    assert_eq!(i.set_real_input_derivatives(&[BODY_X], &[1], &[2.0]), ERR);
    assert!(last_message(&log).contains("body.position[1] (value reference 40) is not an input"));
    assert_eq!(i.set_real_input_derivatives(&[TIP_FX], &[0], &[2.0]), ERR);
    assert!(last_message(&log).contains("order = 0"));
    assert_eq!(
        i.set_real_input_derivatives(&[NONLINEAR], &[1], &[2.0]),
        ERR
    );
    assert!(last_message(&log).contains("Boolean"));
    assert_eq!(i.get_real_output_derivatives(&[BODY_X], &[1], &mut x), ERR);
    assert!(last_message(&log).contains("state Instantiated"));
    let (mut i, log) = initialized();
    assert_eq!(i.do_step(0.0, 0.5), OK);
    assert_eq!(i.get_real_output_derivatives(&[BODY_X], &[1], &mut x), OK);
    assert_eq!(x, [5.0]);
    assert_eq!(i.get_real_output_derivatives(&[BODY_X], &[2], &mut x), ERR);
    assert!(last_message(&log).contains("no such derivative"));
    assert_eq!(i.terminate(), OK);
    assert_eq!(i.set_real_input_derivatives(&[TIP_FX], &[1], &[2.0]), ERR);
}

#[test]
fn snapshot_from_another_fmu_is_refused() {
    let (mut i, log) = initialized();
    let mut s = i.snapshot("fmi2GetFMUstate").unwrap();
    s.guid = "{other}".into();
    assert_eq!(i.restore(&s), ERR);
    assert!(last_message(&log).contains("{other}"));
}
