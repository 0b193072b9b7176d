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
use crate::error::ErrorKind;
use crate::model::{Causality, Variable, VariableType};
pub use crate::slave::CoSimSlave;

mod snapshot;
mod values;
use snapshot::SNAPSHOT_MAGIC;
pub use snapshot::{Snapshot, SERIALIZED_FORMAT, SERIALIZED_MAGIC};
use values::type_name;
pub use values::{settability_violation, FromSlave, ToSlave};

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

    /// Checks the state for `fmi2FreeFMUstate`.
    pub fn may_free_state(&mut self) -> std::result::Result<(), fmi2Status> {
        self.check_state("fmi2FreeFMUstate", ANY_BUT_FATAL)
    }
}

#[cfg(test)]
mod tests;
