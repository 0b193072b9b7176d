//! One FMU instance as the C ABI sees it: the slave, the logger and the FMI 2.0 co-simulation
//! calling-sequence state machine (FMI 2.0.4 section 4.2.4). No raw pointers here: the exports
//! in [`super::exports`] turn C arguments into slices and call these methods.
//!
//! Rules implemented (one state check per call, `fmi2Error` and a message naming the function
//! and the state otherwise):
//!
//! | function | allowed in |
//! | --- | --- |
//! | SetupExperiment, EnterInitializationMode | Instantiated |
//! | ExitInitializationMode | InitializationMode |
//! | DoStep | StepComplete |
//! | Terminate | StepComplete, StepFailed, StepCanceled |
//! | Get{Real,Integer,Boolean,String} | InitializationMode, StepComplete, StepFailed, StepCanceled, Terminated, Error |
//! | Set{Real,Integer,Boolean,String} | Instantiated, InitializationMode, StepComplete |
//! | Get{,Real,Integer,Boolean,String}Status | StepComplete, StepFailed, StepCanceled, Terminated |
//! | Reset, SetDebugLogging, Get/Set/FreeFMUstate | every state but Fatal |
//!
//! Settable variables: in Instantiated and InitializationMode parameters (fixed or tunable) and
//! inputs; in StepComplete inputs and tunable parameters; outputs never.
//!
//! Error states: a call rejected for its arguments or the state changes nothing and leaves the
//! state as it was. A failure of the physics once it has started changing things (an error from
//! `exit_initialization_mode` or `do_step`) or a panic puts the instance in Error, from which
//! `fmi2Reset`, `fmi2SetFMUstate` or `fmi2FreeInstance` lead out. A `do_step` that does not
//! converge returns `fmi2Discard` and puts the instance in StepFailed (the slave rolled back).

use super::logger::{category, Logger};
use super::types::fmi2Status;
use crate::error::{ErrorKind, Result};
use crate::model::{Causality, Variability, Variable, VariableTable, VariableType};
use crate::slave::{Slave, SlaveState};

/// The co-simulation slave as the FMI layer needs it. [`Slave`] implements it; unit tests use a
/// mock so the state machine is tested without the physics.
pub trait CoSimSlave {
    /// A complete snapshot (see [`Slave::get_state`]).
    type State;
    fn guid(&self) -> &str;
    fn variables(&self) -> &VariableTable;
    fn setup_experiment(
        &mut self,
        start_time: f64,
        stop_time: Option<f64>,
        tolerance: Option<f64>,
    ) -> Result<()>;
    fn enter_initialization_mode(&mut self) -> Result<()>;
    fn exit_initialization_mode(&mut self) -> Result<()>;
    fn get_real(&mut self, vr: u32) -> Result<f64>;
    fn set_real(&mut self, vr: u32, value: f64) -> Result<()>;
    fn get_integer(&mut self, vr: u32) -> Result<i32>;
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<()>;
    fn get_boolean(&mut self, vr: u32) -> Result<bool>;
    fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()>;
    /// Value of a String variable (default: there are none).
    fn get_string(&mut self, vr: u32) -> Result<String> {
        Err(crate::Error::new(format!(
            "no String variable has value reference {vr}"
        )))
    }
    /// Sets a String parameter (default: there are none).
    fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let _ = value;
        Err(crate::Error::new(format!(
            "no String variable has value reference {vr}"
        )))
    }
    fn do_step(
        &mut self,
        current_communication_point: f64,
        communication_step_size: f64,
    ) -> Result<()>;
    fn time(&self) -> f64;
    fn reset(&mut self);
    fn get_state(&self) -> Self::State;
    fn set_state(&mut self, state: &Self::State) -> Result<()>;
    /// Appends the portable byte form of `state` (see `fmi2SerializeFMUstate`).
    fn state_to_bytes(&self, state: &Self::State, out: &mut Vec<u8>);
    /// Reads what [`CoSimSlave::state_to_bytes`] wrote, checked against this slave.
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<Self::State>;
    /// Checks a value for a Real variable without setting it (`Ok` if `set_real` would accept it).
    fn check_real(&self, vr: u32, value: f64) -> Result<()> {
        let _ = (vr, value);
        Ok(())
    }
    /// `fmi2SetRealInputDerivatives` (value references are Real inputs, orders ≥ 1, checked by
    /// the caller): all or nothing.
    fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<()>;
    /// `fmi2GetRealOutputDerivatives` for one output.
    fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64>;
    /// Hands the slave's pending log messages (category, text) to `sink`.
    fn drain_events(&mut self, sink: &mut dyn FnMut(&'static str, &str)) {
        let _ = sink;
    }
}

impl CoSimSlave for Slave {
    type State = SlaveState;
    fn guid(&self) -> &str {
        Slave::guid(self)
    }
    fn variables(&self) -> &VariableTable {
        Slave::variables(self)
    }
    fn setup_experiment(
        &mut self,
        start_time: f64,
        stop_time: Option<f64>,
        tolerance: Option<f64>,
    ) -> Result<()> {
        Slave::setup_experiment(self, start_time, stop_time, tolerance)
    }
    fn enter_initialization_mode(&mut self) -> Result<()> {
        Slave::enter_initialization_mode(self)
    }
    fn exit_initialization_mode(&mut self) -> Result<()> {
        Slave::exit_initialization_mode(self)
    }
    fn get_real(&mut self, vr: u32) -> Result<f64> {
        Slave::get_real(self, vr)
    }
    fn set_real(&mut self, vr: u32, value: f64) -> Result<()> {
        Slave::set_real(self, vr, value)
    }
    fn get_integer(&mut self, vr: u32) -> Result<i32> {
        Slave::get_integer(self, vr)
    }
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<()> {
        Slave::set_integer(self, vr, value)
    }
    fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        Slave::get_boolean(self, vr)
    }
    fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()> {
        Slave::set_boolean(self, vr, value)
    }
    fn get_string(&mut self, vr: u32) -> Result<String> {
        Slave::get_string(self, vr)
    }
    fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        Slave::set_string(self, vr, value)
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<()> {
        Slave::do_step(self, t, h)
    }
    fn time(&self) -> f64 {
        Slave::time(self)
    }
    fn reset(&mut self) {
        Slave::reset(self)
    }
    fn get_state(&self) -> SlaveState {
        Slave::get_state(self)
    }
    fn set_state(&mut self, state: &SlaveState) -> Result<()> {
        Slave::set_state(self, state)
    }
    fn state_to_bytes(&self, state: &SlaveState, out: &mut Vec<u8>) {
        state.write_bytes(out)
    }
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<SlaveState> {
        Slave::state_from_bytes(self, bytes)
    }
    fn check_real(&self, vr: u32, value: f64) -> Result<()> {
        Slave::check_real(self, vr, value)
    }
    fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<()> {
        Slave::set_real_input_derivatives(self, vrs, orders, values)
    }
    fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64> {
        Slave::get_real_output_derivative(self, vr, order)
    }
    fn drain_events(&mut self, sink: &mut dyn FnMut(&'static str, &str)) {
        for e in Slave::drain_events(self) {
            sink(e.category, &e.message);
        }
    }
}

/// The states of the FMI 2.0 co-simulation calling sequence (StepInProgress never occurs: every
/// step is synchronous).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MachineState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
    Fatal,
}

use MachineState as M;

const SETUP: &[MachineState] = &[M::Instantiated];
const EXIT_INIT: &[MachineState] = &[M::InitializationMode];
const DO_STEP: &[MachineState] = &[M::StepComplete];
const TERMINATE: &[MachineState] = &[M::StepComplete, M::StepFailed, M::StepCanceled];
const GET: &[MachineState] = &[
    M::InitializationMode,
    M::StepComplete,
    M::StepFailed,
    M::StepCanceled,
    M::Terminated,
    M::Error,
];
const SET: &[MachineState] = &[M::Instantiated, M::InitializationMode, M::StepComplete];
/// `fmi2GetRealOutputDerivatives`: outputs of a computed state (as the Reference FMUs).
const OUTPUT_DERIVATIVES: &[MachineState] = &[
    M::StepComplete,
    M::StepFailed,
    M::StepCanceled,
    M::Terminated,
    M::Error,
];
const STATUS: &[MachineState] = &[
    M::StepComplete,
    M::StepFailed,
    M::StepCanceled,
    M::Terminated,
];
const ANY_BUT_FATAL: &[MachineState] = &[
    M::Instantiated,
    M::InitializationMode,
    M::StepComplete,
    M::StepFailed,
    M::StepCanceled,
    M::Terminated,
    M::Error,
];

/// Identifies a [`Snapshot`] made by this crate (a cheap guard against foreign pointers).
const SNAPSHOT_MAGIC: u64 = 0x666c_6578_6d75_7374; // "flexmust"

/// The first bytes of a serialized FMU state.
///
/// Layout of `fmi2SerializeFMUstate`'s bytes (little-endian): the magic `FLEXBODY` (8 bytes),
/// the format version [`SERIALIZED_FORMAT`] (u32), the GUID (u32 length, UTF-8 bytes), the
/// calling-sequence state (u8) and the termination flag (u8), the payload length (u64) and the
/// slave's payload (`src/slave/state_bytes.rs`: positions, velocities, accelerations,
/// pseudo-accelerations, multipliers, inputs and their derivatives, parameters, counters as f64,
/// i32 and u64). The GUID covers the body file, the variable table and the crate version, so a
/// state of another body or another version is refused by name.
pub const SERIALIZED_MAGIC: &[u8; 8] = b"FLEXBODY";
/// Version of the serialized layout (header and payload together: bump on any change).
pub const SERIALIZED_FORMAT: u32 = 1;
/// Fixed bytes of the header besides the GUID.
const SERIALIZED_HEADER: usize = 8 + 4 + 4 + 1 + 1 + 8;

fn machine_state_code(m: MachineState) -> u8 {
    match m {
        M::Instantiated => 0,
        M::InitializationMode => 1,
        M::StepComplete => 2,
        M::StepFailed => 3,
        M::StepCanceled => 4,
        M::Terminated => 5,
        M::Error => 6,
        M::Fatal => 7,
    }
}

fn machine_state_from_code(code: u8) -> Option<MachineState> {
    Some(match code {
        0 => M::Instantiated,
        1 => M::InitializationMode,
        2 => M::StepComplete,
        3 => M::StepFailed,
        4 => M::StepCanceled,
        5 => M::Terminated,
        6 => M::Error,
        7 => M::Fatal,
        _ => return None,
    })
}

/// What `fmi2GetFMUstate` saves: the slave's snapshot and the calling-sequence state, so that
/// `fmi2SetFMUstate` after an `fmi2Discard` returns to StepComplete.
pub struct Snapshot<T> {
    magic: u64,
    guid: String,
    slave: T,
    machine: MachineState,
    terminate_requested: bool,
}

impl<T> Snapshot<T> {
    /// Whether this looks like a snapshot made by this crate.
    pub fn is_valid(&self) -> bool {
        self.magic == SNAPSHOT_MAGIC
    }
}

impl<T> Drop for Snapshot<T> {
    fn drop(&mut self) {
        // Poison the tag so a double free or use after free is more likely to be caught.
        self.magic = 0;
    }
}

/// One FMU instance.
pub struct Instance<S: CoSimSlave> {
    slave: S,
    logger: Logger,
    state: MachineState,
    /// Set by a discarded step: `fmi2GetBooleanStatus(fmi2Terminated)` answers true.
    terminate_requested: bool,
    /// The strings of the last `fmi2GetString` (valid until the next call on this instance).
    strings: Vec<std::ffi::CString>,
}

/// What a value getter returns for the C side.
pub trait FromSlave<S: CoSimSlave>: Sized {
    const TYPE: VariableType;
    fn get(slave: &mut S, vr: u32) -> Result<Self>;
    /// NaN or an infinity (never passed to the importer).
    fn is_non_finite(&self) -> bool {
        false
    }
}

impl<S: CoSimSlave> FromSlave<S> for f64 {
    const TYPE: VariableType = VariableType::Real;
    fn get(slave: &mut S, vr: u32) -> Result<f64> {
        slave.get_real(vr)
    }
    fn is_non_finite(&self) -> bool {
        !self.is_finite()
    }
}

impl<S: CoSimSlave> FromSlave<S> for i32 {
    const TYPE: VariableType = VariableType::Integer;
    fn get(slave: &mut S, vr: u32) -> Result<i32> {
        slave.get_integer(vr)
    }
}

impl<S: CoSimSlave> FromSlave<S> for bool {
    const TYPE: VariableType = VariableType::Boolean;
    fn get(slave: &mut S, vr: u32) -> Result<bool> {
        slave.get_boolean(vr)
    }
}

/// What a value setter takes from the C side.
pub trait ToSlave<S: CoSimSlave>: Sized + Copy {
    const TYPE: VariableType;
    fn set(slave: &mut S, vr: u32, value: Self) -> Result<()>;
    /// Whether `set` would accept the value (checked for the whole array before setting any).
    fn check(slave: &S, vr: u32, value: Self) -> Result<()> {
        let _ = (slave, vr, value);
        Ok(())
    }
}

impl<S: CoSimSlave> ToSlave<S> for f64 {
    const TYPE: VariableType = VariableType::Real;
    fn set(slave: &mut S, vr: u32, value: f64) -> Result<()> {
        slave.set_real(vr, value)
    }
    fn check(slave: &S, vr: u32, value: f64) -> Result<()> {
        slave.check_real(vr, value)
    }
}

impl<S: CoSimSlave> ToSlave<S> for i32 {
    const TYPE: VariableType = VariableType::Integer;
    fn set(slave: &mut S, vr: u32, value: i32) -> Result<()> {
        slave.set_integer(vr, value)
    }
}

impl<S: CoSimSlave> ToSlave<S> for bool {
    const TYPE: VariableType = VariableType::Boolean;
    fn set(slave: &mut S, vr: u32, value: bool) -> Result<()> {
        slave.set_boolean(vr, value)
    }
}

fn type_name(ty: VariableType) -> &'static str {
    match ty {
        VariableType::Real => "Real",
        VariableType::Integer => "Integer",
        VariableType::Boolean => "Boolean",
        VariableType::String => "String",
    }
}

/// Why `v` may not be set in `state` (None: it may). FMI 2.0.4 section 4.2.4, co-simulation.
pub fn settability_violation(state: MachineState, v: &Variable) -> Option<String> {
    match v.causality {
        Causality::Output => Some(format!("{} is an output and cannot be set", v.name)),
        Causality::Input => None,
        Causality::Parameter => match state {
            M::Instantiated | M::InitializationMode => None,
            M::StepComplete if v.variability == Variability::Tunable => None,
            _ => Some(format!(
                "{} is a {} parameter and can only be set before fmi2ExitInitializationMode",
                v.name,
                match v.variability {
                    Variability::Fixed => "fixed",
                    Variability::Tunable => "tunable",
                    Variability::Discrete => "discrete",
                    Variability::Continuous => "continuous",
                }
            )),
        },
    }
}

impl<S: CoSimSlave> Instance<S> {
    /// A freshly instantiated instance.
    pub fn new(slave: S, logger: Logger) -> Self {
        Instance {
            slave,
            logger,
            state: M::Instantiated,
            terminate_requested: false,
            strings: Vec::new(),
        }
    }

    /// Passes the slave's log messages on to the logger (their categories decide whether they
    /// reach the importer).
    fn flush_events(&mut self) {
        let logger = &mut self.logger;
        self.slave.drain_events(&mut |category, message| {
            logger.log(fmi2Status::fmi2OK, category, message)
        });
    }

    /// The calling-sequence state.
    pub fn state(&self) -> MachineState {
        self.state
    }

    /// The slave (read-only).
    pub fn slave(&self) -> &S {
        &self.slave
    }

    /// The logger.
    pub fn logger_mut(&mut self) -> &mut Logger {
        &mut self.logger
    }

    /// Logs `message` as an error of `function` and returns `fmi2Error`; the state is unchanged.
    pub fn fail(&mut self, function: &str, message: &str) -> fmi2Status {
        self.logger.error(&format!("{function}: {message}"));
        fmi2Status::fmi2Error
    }

    /// Records a panic caught at the C boundary: logs it and enters the Error state.
    pub fn panicked(&mut self, function: &str, what: &str) -> fmi2Status {
        self.state = M::Error;
        self.fail(
            function,
            &format!("internal error (panic): {what}; the instance is now in the Error state"),
        )
    }

    fn check_state(
        &mut self,
        function: &str,
        allowed: &[MachineState],
    ) -> std::result::Result<(), fmi2Status> {
        if allowed.contains(&self.state) {
            Ok(())
        } else {
            let allowed: Vec<String> = allowed.iter().map(|s| format!("{s:?}")).collect();
            Err(self.fail(
                function,
                &format!(
                    "not allowed in state {:?} (allowed in: {})",
                    self.state,
                    allowed.join(", ")
                ),
            ))
        }
    }

    /// Maps a slave error to a status: `Discard` logs under `logStatusDiscard`, `Error` under
    /// `logStatusError`.
    fn report(&mut self, function: &str, e: &crate::Error) -> fmi2Status {
        match e.kind {
            ErrorKind::Error => self.fail(function, &e.message),
            ErrorKind::Discard => {
                self.logger.log(
                    fmi2Status::fmi2Discard,
                    category::DISCARD,
                    &format!("{function}: {}", e.message),
                );
                fmi2Status::fmi2Discard
            }
        }
    }

    /// `fmi2SetDebugLogging`.
    pub fn set_debug_logging(
        &mut self,
        logging_on: bool,
        categories: Option<&[&str]>,
    ) -> fmi2Status {
        const F: &str = "fmi2SetDebugLogging";
        if let Err(s) = self.check_state(F, ANY_BUT_FATAL) {
            return s;
        }
        match self.logger.set_debug_logging(logging_on, categories) {
            Ok(()) => fmi2Status::fmi2OK,
            Err(e) => self.fail(F, &e),
        }
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> fmi2Status {
        const F: &str = "fmi2SetupExperiment";
        if let Err(s) = self.check_state(F, SETUP) {
            return s;
        }
        if !start_time.is_finite() {
            return self.fail(
                F,
                &format!("startTime = {start_time} rejected: must be finite"),
            );
        }
        if let Some(stop) = stop_time {
            if !(stop.is_finite() && stop >= start_time) {
                return self.fail(
                    F,
                    &format!("stopTime = {stop} rejected: must be finite and not before startTime = {start_time}"),
                );
            }
        }
        if let Some(tol) = tolerance {
            if !(tol.is_finite() && tol > 0.0) {
                return self.fail(
                    F,
                    &format!("tolerance = {tol} rejected: must be finite and > 0"),
                );
            }
        }
        match self
            .slave
            .setup_experiment(start_time, stop_time, tolerance)
        {
            Ok(()) => {
                self.logger.event(&format!(
                    "{F}: startTime = {start_time}, stopTime = {stop_time:?}, tolerance = {tolerance:?}"
                ));
                fmi2Status::fmi2OK
            }
            Err(e) => self.report(F, &e),
        }
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> fmi2Status {
        const F: &str = "fmi2EnterInitializationMode";
        if let Err(s) = self.check_state(F, SETUP) {
            return s;
        }
        match self.slave.enter_initialization_mode() {
            Ok(()) => {
                self.state = M::InitializationMode;
                self.logger
                    .event(&format!("{F}: entered Initialization Mode"));
                fmi2Status::fmi2OK
            }
            Err(e) => self.report(F, &e),
        }
    }

    /// `fmi2ExitInitializationMode`: an error of the slave (bad parameters, bad body) puts the
    /// instance in Error.
    pub fn exit_initialization_mode(&mut self) -> fmi2Status {
        const F: &str = "fmi2ExitInitializationMode";
        if let Err(s) = self.check_state(F, EXIT_INIT) {
            return s;
        }
        let result = self.slave.exit_initialization_mode();
        self.flush_events();
        match result {
            Ok(()) => {
                self.state = M::StepComplete;
                self.logger
                    .event(&format!("{F}: initialized at t = {}", self.slave.time()));
                fmi2Status::fmi2OK
            }
            Err(e) => {
                self.state = M::Error;
                self.report(F, &e);
                fmi2Status::fmi2Error
            }
        }
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> fmi2Status {
        const F: &str = "fmi2Terminate";
        if let Err(s) = self.check_state(F, TERMINATE) {
            return s;
        }
        self.state = M::Terminated;
        self.logger
            .event(&format!("{F}: terminated at t = {}", self.slave.time()));
        fmi2Status::fmi2OK
    }

    /// `fmi2Reset`: the slave back to its freshly instantiated state, the calling sequence back to
    /// Instantiated and the termination flag cleared. The debug-logging settings are the
    /// importer's and are kept.
    pub fn reset(&mut self) -> fmi2Status {
        const F: &str = "fmi2Reset";
        if let Err(s) = self.check_state(F, ANY_BUT_FATAL) {
            return s;
        }
        self.slave.reset();
        self.state = M::Instantiated;
        self.terminate_requested = false;
        self.logger.event(&format!("{F}: back to Instantiated"));
        fmi2Status::fmi2OK
    }

    /// Looks up `vr` of type `ty`; the error names the value reference and, when it exists with
    /// another type, that type.
    fn lookup(&self, ty: VariableType, vr: u32) -> std::result::Result<&Variable, String> {
        let table = self.slave.variables();
        table.get(ty, vr).ok_or_else(|| {
            let other = [
                VariableType::Real,
                VariableType::Integer,
                VariableType::Boolean,
                VariableType::String,
            ]
            .into_iter()
            .find_map(|t| table.get(t, vr));
            match other {
                Some(v) => format!(
                    "value reference {vr} is the {} variable {}, not a {} variable",
                    type_name(v.ty),
                    v.name,
                    type_name(ty)
                ),
                None => format!("unknown {} value reference {vr}", type_name(ty)),
            }
        })
    }

    /// `fmi2Get{Real,Integer,Boolean}`: `values[i]` of `vrs[i]` (same length, checked by the
    /// caller). Non-finite Reals are refused rather than passed on.
    pub fn get_values<T: FromSlave<S> + Copy + std::fmt::Debug>(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &mut [T],
    ) -> fmi2Status {
        debug_assert_eq!(vrs.len(), values.len());
        if let Err(s) = self.check_state(function, GET) {
            return s;
        }
        for (&vr, out) in vrs.iter().zip(values.iter_mut()) {
            let name = match self.lookup(T::TYPE, vr) {
                Ok(v) => v.name.clone(),
                Err(e) => return self.fail(function, &e),
            };
            match T::get(&mut self.slave, vr) {
                Ok(x) if x.is_non_finite() => {
                    return self.fail(function, &format!("{name} (value reference {vr}) is {x:?}"));
                }
                Ok(x) => *out = x,
                Err(e) => return self.report(function, &e),
            }
        }
        fmi2Status::fmi2OK
    }

    /// `fmi2Set{Real,Integer,Boolean}`: checks every value reference, its settability in the
    /// current state and (Reals) its value before setting any value; then sets them in order
    /// (the slave rejects bad values with a message naming the variable).
    pub fn set_values<T: ToSlave<S>>(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[T],
    ) -> fmi2Status {
        debug_assert_eq!(vrs.len(), values.len());
        if let Err(s) = self.check_state(function, SET) {
            return s;
        }
        for &vr in vrs {
            let reason = match self.lookup(T::TYPE, vr) {
                Ok(v) => settability_violation(self.state, v)
                    .map(|r| format!("{r} (value reference {vr}, state {:?})", self.state)),
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(function, &reason);
            }
        }
        for (&vr, &x) in vrs.iter().zip(values) {
            if let Err(e) = T::check(&self.slave, vr, x) {
                return self.report(function, &e);
            }
        }
        for (&vr, &x) in vrs.iter().zip(values) {
            if let Err(e) = T::set(&mut self.slave, vr, x) {
                return self.report(function, &e);
            }
        }
        fmi2Status::fmi2OK
    }

    /// `fmi2GetString`: the values of `vrs`, kept in the instance until its next
    /// `fmi2GetString` (the caller hands out pointers into them). A value with a NUL byte is
    /// refused.
    pub fn get_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
    ) -> (fmi2Status, &[std::ffi::CString]) {
        if let Err(s) = self.check_state(function, GET) {
            return (s, &[]);
        }
        let mut values = Vec::with_capacity(vrs.len());
        for &vr in vrs {
            if let Err(e) = self.lookup(VariableType::String, vr) {
                return (self.fail(function, &e), &[]);
            }
            match self.slave.get_string(vr) {
                Ok(text) => match std::ffi::CString::new(text) {
                    Ok(c) => values.push(c),
                    Err(_) => {
                        let status = self.fail(
                            function,
                            &format!("String value reference {vr} holds a NUL character"),
                        );
                        return (status, &[]);
                    }
                },
                Err(e) => return (self.report(function, &e), &[]),
            }
        }
        self.strings = values;
        (fmi2Status::fmi2OK, &self.strings)
    }

    /// `fmi2SetString`: like [`Self::set_values`]; a NULL string (None) is an error naming the
    /// variable.
    pub fn set_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[Option<String>],
    ) -> fmi2Status {
        debug_assert_eq!(vrs.len(), values.len());
        if let Err(s) = self.check_state(function, SET) {
            return s;
        }
        for (&vr, value) in vrs.iter().zip(values) {
            let reason = match self.lookup(VariableType::String, vr) {
                Ok(v) => settability_violation(self.state, v)
                    .map(|r| format!("{r} (value reference {vr}, state {:?})", self.state))
                    .or_else(|| {
                        value
                            .is_none()
                            .then(|| format!("{} = NULL rejected: not a string", v.name))
                    }),
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(function, &reason);
            }
        }
        for (&vr, value) in vrs.iter().zip(values) {
            if let Err(e) = self
                .slave
                .set_string(vr, value.as_deref().unwrap_or_default())
            {
                return self.report(function, &e);
            }
        }
        fmi2Status::fmi2OK
    }

    /// `fmi2DoStep`: `h` must be finite and > 0; the slave checks `t` against its time. A
    /// discarded step (no convergence, rolled back) gives StepFailed; an error gives Error.
    pub fn do_step(&mut self, t: f64, h: f64) -> fmi2Status {
        const F: &str = "fmi2DoStep";
        if let Err(s) = self.check_state(F, DO_STEP) {
            return s;
        }
        if !t.is_finite() {
            return self.fail(
                F,
                &format!("currentCommunicationPoint = {t} rejected: must be finite"),
            );
        }
        if !(h.is_finite() && h > 0.0) {
            return self.fail(
                F,
                &format!("communicationStepSize = {h} rejected: must be finite and > 0"),
            );
        }
        let result = self.slave.do_step(t, h);
        self.flush_events();
        match result {
            Ok(()) => fmi2Status::fmi2OK,
            Err(e) => {
                let status = self.report(F, &e);
                if status == fmi2Status::fmi2Discard {
                    self.state = M::StepFailed;
                    self.terminate_requested = true;
                } else {
                    self.state = M::Error;
                }
                status
            }
        }
    }

    /// `fmi2SetRealInputDerivatives` (`canInterpolateInputs="true"`): allowed where inputs may be
    /// set; every value reference must be a Real input and every order 1 or 2 (what the slave
    /// can use); all or nothing.
    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> fmi2Status {
        const F: &str = "fmi2SetRealInputDerivatives";
        if let Err(s) = self.check_state(F, SET) {
            return s;
        }
        for (&vr, &order) in vrs.iter().zip(orders) {
            let reason = match self.lookup(VariableType::Real, vr) {
                Ok(v) if v.causality != Causality::Input => {
                    Some(format!("{} (value reference {vr}) is not an input", v.name))
                }
                Ok(v) if order < 1 => Some(format!(
                    "order = {order} rejected for {} (value reference {vr}): must be at least 1",
                    v.name
                )),
                Ok(_) => None,
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(F, &reason);
            }
        }
        match self.slave.set_real_input_derivatives(vrs, orders, values) {
            Ok(()) => fmi2Status::fmi2OK,
            Err(e) => self.report(F, &e),
        }
    }

    /// `fmi2GetRealOutputDerivatives` (`maxOutputDerivativeOrder="2"`): every value reference
    /// must be a Real output; the slave says which derivatives exist.
    pub fn get_real_output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &mut [f64],
    ) -> fmi2Status {
        const F: &str = "fmi2GetRealOutputDerivatives";
        if let Err(s) = self.check_state(F, OUTPUT_DERIVATIVES) {
            return s;
        }
        for ((&vr, &order), out) in vrs.iter().zip(orders).zip(values.iter_mut()) {
            if let Err(e) = self.lookup(VariableType::Real, vr) {
                return self.fail(F, &e);
            }
            match self.slave.get_real_output_derivative(vr, order) {
                Ok(x) if x.is_finite() => *out = x,
                Ok(x) => {
                    return self.fail(F, &format!("the derivative of value reference {vr} is {x}"))
                }
                Err(e) => return self.report(F, &e),
            }
        }
        fmi2Status::fmi2OK
    }

    /// Functions this FMU does not support (`fmi2GetDirectionalDerivative`): `fmi2Error` with a
    /// message.
    pub fn unsupported(&mut self, function: &str, why: &str) -> fmi2Status {
        self.fail(function, &format!("not supported: {why}"))
    }

    /// `fmi2CancelStep`: only allowed in StepInProgress, which this synchronous FMU never enters;
    /// so always an `fmi2Error` that names the state, and nothing changes.
    pub fn cancel_step(&mut self) -> fmi2Status {
        const F: &str = "fmi2CancelStep";
        let state = self.state;
        self.fail(
            F,
            &format!(
                "not allowed in state {state:?}: only while an asynchronous fmi2DoStep is pending (StepInProgress), which never happens here: fmi2DoStep is synchronous (canRunAsynchronuously=\"false\") and never returns fmi2Pending"
            ),
        )
    }

    /// `fmi2GetStatus`: `fmi2DoStepStatus` is only defined after `fmi2Pending`, which this
    /// synchronous FMU never returns; other kinds are not `fmi2Status`-valued.
    pub fn get_status(
        &mut self,
        kind: std::ffi::c_int,
    ) -> std::result::Result<fmi2Status, fmi2Status> {
        const F: &str = "fmi2GetStatus";
        self.check_state(F, STATUS)?;
        Err(self.status_kind_error(F, kind))
    }

    #[allow(non_upper_case_globals)]
    fn status_kind_error(&mut self, function: &str, kind: std::ffi::c_int) -> fmi2Status {
        use super::types::*;
        let name = status_kind_name(kind);
        let why = match kind {
            fmi2DoStepStatus | fmi2PendingStatus => {
                format!("{name} is only defined after fmi2DoStep returned fmi2Pending, which this FMU never does")
            }
            fmi2LastSuccessfulTime => format!("{name} is a Real status: use fmi2GetRealStatus"),
            fmi2Terminated => format!("{name} is a Boolean status: use fmi2GetBooleanStatus"),
            _ => format!("unknown status kind {name}"),
        };
        self.fail(function, &why)
    }

    /// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime` is the slave's time (the end of the last
    /// successful step).
    pub fn get_real_status(
        &mut self,
        kind: std::ffi::c_int,
    ) -> std::result::Result<f64, fmi2Status> {
        const F: &str = "fmi2GetRealStatus";
        self.check_state(F, STATUS)?;
        if kind == super::types::fmi2LastSuccessfulTime {
            Ok(self.slave.time())
        } else {
            Err(self.status_kind_error(F, kind))
        }
    }

    /// `fmi2GetIntegerStatus`: FMI 2.0 defines no Integer status.
    pub fn get_integer_status(
        &mut self,
        kind: std::ffi::c_int,
    ) -> std::result::Result<i32, fmi2Status> {
        const F: &str = "fmi2GetIntegerStatus";
        self.check_state(F, STATUS)?;
        Err(self.status_kind_error(F, kind))
    }

    /// `fmi2GetBooleanStatus`: `fmi2Terminated` is true after a discarded step (the slave asks
    /// the master to end the simulation).
    pub fn get_boolean_status(
        &mut self,
        kind: std::ffi::c_int,
    ) -> std::result::Result<bool, fmi2Status> {
        const F: &str = "fmi2GetBooleanStatus";
        self.check_state(F, STATUS)?;
        if kind == super::types::fmi2Terminated {
            Ok(self.terminate_requested)
        } else {
            Err(self.status_kind_error(F, kind))
        }
    }

    /// `fmi2GetStringStatus`: `fmi2PendingStatus` needs a pending step, which never happens.
    pub fn get_string_status(&mut self, kind: std::ffi::c_int) -> fmi2Status {
        const F: &str = "fmi2GetStringStatus";
        if let Err(s) = self.check_state(F, STATUS) {
            return s;
        }
        self.status_kind_error(F, kind)
    }

    /// `fmi2GetFMUstate` (new snapshot) — the caller boxes it or overwrites an old one.
    pub fn snapshot(
        &mut self,
        function: &str,
    ) -> std::result::Result<Snapshot<S::State>, fmi2Status> {
        self.check_state(function, ANY_BUT_FATAL)?;
        Ok(Snapshot {
            magic: SNAPSHOT_MAGIC,
            guid: self.slave.guid().to_string(),
            slave: self.slave.get_state(),
            machine: self.state,
            terminate_requested: self.terminate_requested,
        })
    }

    /// `fmi2SetFMUstate`: restores the slave and the calling-sequence state; the snapshot stays
    /// valid.
    pub fn restore(&mut self, snapshot: &Snapshot<S::State>) -> fmi2Status {
        const F: &str = "fmi2SetFMUstate";
        if let Err(s) = self.check_state(F, ANY_BUT_FATAL) {
            return s;
        }
        if !snapshot.is_valid() {
            return self.fail(
                F,
                "the FMU state is not a live state of this FMU (freed, or from another FMU)",
            );
        }
        if snapshot.guid != self.slave.guid() {
            return self.fail(
                F,
                &format!(
                    "the FMU state belongs to an FMU with GUID {}, this instance has {}",
                    snapshot.guid,
                    self.slave.guid()
                ),
            );
        }
        match self.slave.set_state(&snapshot.slave) {
            Ok(()) => {
                self.state = snapshot.machine;
                self.terminate_requested = snapshot.terminate_requested;
                self.logger.event(&format!(
                    "{F}: restored state {:?} at t = {}",
                    self.state,
                    self.slave.time()
                ));
                fmi2Status::fmi2OK
            }
            Err(e) => self.report(F, &e),
        }
    }

    /// `fmi2SerializeFMUstate`: the portable bytes of `snapshot` (layout in [`SERIALIZED_MAGIC`]).
    pub fn serialize_snapshot(
        &mut self,
        function: &str,
        snapshot: &Snapshot<S::State>,
    ) -> std::result::Result<Vec<u8>, fmi2Status> {
        self.check_state(function, ANY_BUT_FATAL)?;
        if !snapshot.is_valid() {
            return Err(self.fail(
                function,
                "FMUstate is not a live state of this FMU (freed, or from another FMU)",
            ));
        }
        let mut payload = Vec::new();
        self.slave.state_to_bytes(&snapshot.slave, &mut payload);
        let guid = snapshot.guid.as_bytes();
        let mut out = Vec::with_capacity(SERIALIZED_HEADER + guid.len() + payload.len());
        out.extend_from_slice(SERIALIZED_MAGIC);
        out.extend_from_slice(&SERIALIZED_FORMAT.to_le_bytes());
        out.extend_from_slice(&(guid.len() as u32).to_le_bytes());
        out.extend_from_slice(guid);
        out.push(machine_state_code(snapshot.machine));
        out.push(u8::from(snapshot.terminate_requested));
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&payload);
        Ok(out)
    }

    /// `fmi2DeSerializeFMUstate`: a snapshot from bytes of [`Instance::serialize_snapshot`],
    /// checked: magic, format version, GUID (the same body and build), then the slave's payload.
    /// Bytes after the declared payload must be zero (an importer may pass a larger buffer).
    pub fn deserialize_snapshot(
        &mut self,
        bytes: &[u8],
    ) -> std::result::Result<Snapshot<S::State>, fmi2Status> {
        const F: &str = "fmi2DeSerializeFMUstate";
        self.check_state(F, ANY_BUT_FATAL)?;
        match self.parse_snapshot(bytes) {
            Ok(s) => Ok(s),
            Err(message) => Err(self.fail(F, &message)),
        }
    }

    fn parse_snapshot(&self, bytes: &[u8]) -> std::result::Result<Snapshot<S::State>, String> {
        let truncated = || {
            format!(
                "the serialized FMU state is truncated ({} bytes) or not one of this FMU",
                bytes.len()
            )
        };
        if bytes.len() < SERIALIZED_MAGIC.len() || &bytes[..8] != SERIALIZED_MAGIC {
            return Err(format!(
                "the {} bytes are not a serialized state of this FMU (they do not start with \"FLEXBODY\")",
                bytes.len()
            ));
        }
        let u32_at = |at: usize| {
            bytes
                .get(at..at + 4)
                .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
        };
        let format = u32_at(8).ok_or_else(truncated)?;
        if format != SERIALIZED_FORMAT {
            return Err(format!(
                "the serialized FMU state has format version {format}; this FMU reads version {SERIALIZED_FORMAT} (it was written by another version of flexbody)"
            ));
        }
        let guid_len = u32_at(12).ok_or_else(truncated)? as usize;
        let guid_end = 16usize.checked_add(guid_len).ok_or_else(truncated)?;
        let guid = bytes.get(16..guid_end).ok_or_else(truncated)?;
        let guid = String::from_utf8_lossy(guid).into_owned();
        if guid != self.slave.guid() {
            return Err(format!(
                "the serialized FMU state belongs to an FMU with GUID {guid}; this instance has GUID {} (another body, body file or version of flexbody)",
                self.slave.guid()
            ));
        }
        let rest = &bytes[guid_end..];
        if rest.len() < 10 {
            return Err(truncated());
        }
        let machine = machine_state_from_code(rest[0]).ok_or_else(|| {
            format!(
                "the serialized FMU state has an unknown calling-sequence state {}",
                rest[0]
            )
        })?;
        let terminate_requested = match rest[1] {
            0 => false,
            1 => true,
            b => {
                return Err(format!(
                    "the serialized FMU state has {b} as its termination flag: not 0 or 1"
                ))
            }
        };
        let len = u64::from_le_bytes(rest[2..10].try_into().unwrap());
        let payload_end = usize::try_from(len)
            .ok()
            .and_then(|l| l.checked_add(10))
            .filter(|&end| end <= rest.len())
            .ok_or_else(truncated)?;
        if rest[payload_end..].iter().any(|&b| b != 0) {
            return Err(format!(
                "the serialized FMU state is followed by {} bytes that are not zero",
                rest.len() - payload_end
            ));
        }
        let slave = self
            .slave
            .state_from_bytes(&rest[10..payload_end])
            .map_err(|e| e.message)?;
        Ok(Snapshot {
            magic: SNAPSHOT_MAGIC,
            guid,
            slave,
            machine,
            terminate_requested,
        })
    }

    /// Checks the state for `fmi2FreeFMUstate`.
    pub fn may_free_state(&mut self) -> std::result::Result<(), fmi2Status> {
        self.check_state("fmi2FreeFMUstate", ANY_BUT_FATAL)
    }
}

#[cfg(test)]
mod tests {
    //! The state machine against a mock slave (the physics is not needed to test the calling
    //! sequence). Value references are those of the default body's table: 1 = Young's modulus
    //! (fixed parameter), 6 = gravity[1] (tunable), 33 = maxIterations (Integer), 34 =
    //! nonlinearForces (Boolean), 40 = body.position[1] (output), 1100 = tip.force[1] (input;
    //! `tip` is the second interface).
    use super::*;
    use crate::fmi2::logger::Sink;
    use crate::fmi2::types::{
        fmi2LastSuccessfulTime as LAST_SUCCESSFUL_TIME, fmi2Terminated as TERMINATED,
    };
    use crate::model::BodyFile;
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
        assert!(
            last_message(&log).contains("fmi2SetupExperiment: not allowed in state StepComplete")
        );
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
        assert!(
            last_message(&log).contains("fmi2DoStep: internal error (panic): index out of bounds")
        );
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
                [&bytes[..8], &2u32.to_le_bytes(), &bytes[12..]].concat(),
                "format version 2",
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
        assert!(
            last_message(&log).contains("body.position[1] (value reference 40) is not an input")
        );
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
}
