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
pub use crate::slave::CoSimSlave;

mod snapshot;
mod values;
pub use snapshot::{Snapshot, SERIALIZED_FORMAT, SERIALIZED_MAGIC};
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
    /// FMI 3.0: the getters answer in Instantiated with the start values (parameters and
    /// inputs); FMI 2.0 allows them from Initialization Mode on.
    start_values_readable: bool,
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
            start_values_readable: false,
        }
    }

    /// The instance of an FMI 3.0 importer: its getters also answer in Instantiated, with the
    /// start values of the parameters and inputs (FMI 3.0, "State: Instantiated").
    pub fn reading_start_values(mut self) -> Self {
        self.start_values_readable = true;
        self
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
        self.slave.terminate();
        self.flush_events();
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

    /// FMI 3.0 after a discarded step: the instance stays in Step Mode (FMI 3.0 has no Step
    /// Discarded state: `fmi3Discard` leaves the FMU as before the call, and the importer may
    /// retry with other arguments), with no request to terminate. The slave has rolled back.
    pub fn continue_after_discard(&mut self) {
        if self.state == M::StepFailed {
            self.state = M::StepComplete;
            self.terminate_requested = false;
        }
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
}

#[cfg(test)]
mod tests;
