//! Messages to the importer's logger callback, filtered by the log categories of
//! `modelDescription/variables.json` (`LOG_CATEGORIES`).
//!
//! Messages with the status categories `logStatusWarning`, `logStatusDiscard`, `logStatusError`
//! and `logStatusFatal` are always passed on (when there is a logger); `logEvents` and `logSolver`
//! only when debug logging is on for that category (`fmi2Instantiate(loggingOn)`,
//! `fmi2SetDebugLogging`). FMI 3.0 allows fewer: with logging off only errors, so there
//! `logStatusWarning` and `logStatusDiscard` are passed on only when enabled.

use super::types::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};
use crate::model::variables::LOG_CATEGORIES;
use std::ffi::CString;

pub use crate::model::category;

/// The status category that always reaches the logger for a status worse than OK.
pub fn category_of(status: fmi2Status) -> &'static str {
    match status {
        fmi2Status::fmi2Warning => category::WARNING,
        fmi2Status::fmi2Discard => category::DISCARD,
        fmi2Status::fmi2Error => category::ERROR,
        fmi2Status::fmi2Fatal => category::FATAL,
        fmi2Status::fmi2OK | fmi2Status::fmi2Pending => category::EVENTS,
    }
}

/// A Rust message sink, `(status, category, message)`: lets the instance be driven without a C
/// importer (unit tests, Rust hosts).
pub type RustSink = Box<dyn FnMut(fmi2Status, &str, &str)>;

/// Where messages go.
pub enum Sink {
    /// No logger (NULL callback or NULL `functions`): messages are dropped.
    None,
    /// The importer's C callback with its `componentEnvironment`.
    C {
        logger: fmi2CallbackLogger,
        environment: fmi2ComponentEnvironment,
    },
    /// A Rust closure.
    Rust(RustSink),
}

/// The logger of one instance: sink, copied instance name and enabled debug categories.
pub struct Logger {
    sink: Sink,
    instance_name: CString,
    /// `enabled[i]` for `LOG_CATEGORIES[i]`.
    enabled: Vec<bool>,
    /// The instance answers to FMI 3.0: messages name FMI 3.0's functions and states.
    fmi3: bool,
}

/// FMI 2.0 names in the messages of [`crate::fmi2::Instance`] and their FMI 3.0 counterparts,
/// longest first; any other `fmi2` prefix becomes `fmi3`.
const FMI3_NAMES: [(&str, &str); 15] = [
    ("fmi2GetRealOutputDerivatives", "fmi3GetOutputDerivatives"),
    ("fmi2SerializedFMUstateSize", "fmi3SerializedFMUStateSize"),
    ("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState"),
    ("fmi2SerializeFMUstate", "fmi3SerializeFMUState"),
    ("fmi2SetupExperiment", "fmi3EnterInitializationMode"),
    ("fmi2Instantiate", "fmi3InstantiateCoSimulation"),
    ("fmi2FreeFMUstate", "fmi3FreeFMUState"),
    ("fmi2GetFMUstate", "fmi3GetFMUState"),
    ("fmi2SetFMUstate", "fmi3SetFMUState"),
    ("fmi2GetReal", "fmi3GetFloat64"),
    ("fmi2SetReal", "fmi3SetFloat64"),
    ("this FMU's GUID", "this FMU's instantiationToken"),
    ("fmuGUID", "instantiationToken"),
    ("StepComplete", "StepMode"),
    ("StepFailed", "StepDiscarded"),
];

/// `message` with FMI 2.0's function and state names replaced by FMI 3.0's (FMI 3.0 section
/// 4.2.1: Step Mode and Step Discarded are FMI 2.0's StepComplete and StepFailed).
pub fn fmi3_names(message: &str) -> String {
    let mut text = message.to_string();
    for (fmi2, fmi3) in FMI3_NAMES {
        if text.contains(fmi2) {
            text = text.replace(fmi2, fmi3);
        }
    }
    text.replace("fmi2", "fmi3")
}

impl Logger {
    /// A logger for `instance_name` with every category enabled iff `logging_on`.
    pub fn new(sink: Sink, instance_name: &str, logging_on: bool) -> Logger {
        Logger {
            sink,
            instance_name: to_c_string(instance_name),
            enabled: vec![logging_on; LOG_CATEGORIES.len()],
            fmi3: false,
        }
    }

    /// This logger for an FMI 3.0 instance: its messages name FMI 3.0's functions and states
    /// ([`fmi3_names`]).
    pub fn for_fmi3(mut self) -> Logger {
        self.fmi3 = true;
        self
    }

    /// The instance name as passed to the callback (a copy owned by this logger).
    pub fn instance_name(&self) -> &std::ffi::CStr {
        &self.instance_name
    }

    /// `fmi2SetDebugLogging`: `categories = None` (nCategories = 0) sets every category, otherwise
    /// only the listed ones; an unknown name changes nothing and is returned as the error.
    pub fn set_debug_logging(
        &mut self,
        logging_on: bool,
        categories: Option<&[&str]>,
    ) -> Result<(), String> {
        match categories {
            None => self.enabled.iter_mut().for_each(|e| *e = logging_on),
            Some(names) => {
                let mut indices = Vec::with_capacity(names.len());
                for name in names {
                    let i = LOG_CATEGORIES
                        .iter()
                        .position(|(c, _)| c == name)
                        .ok_or_else(|| {
                            let known: Vec<&str> = LOG_CATEGORIES.iter().map(|(c, _)| *c).collect();
                            format!(
                                "unknown log category '{name}' (declared: {})",
                                known.join(", ")
                            )
                        })?;
                    indices.push(i);
                }
                for i in indices {
                    self.enabled[i] = logging_on;
                }
            }
        }
        Ok(())
    }

    /// Whether a message of `category` would be passed on: errors always; warnings and
    /// discards always under FMI 2.0, under FMI 3.0 only when their category is enabled (FMI
    /// 3.0, `loggingOn`: with logging off only `fmi3Error` and `fmi3Fatal` may be logged);
    /// debug categories when enabled.
    pub fn is_enabled(&self, category: &str) -> bool {
        match category {
            category::ERROR | category::FATAL => return true,
            category::WARNING | category::DISCARD if !self.fmi3 => return true,
            _ => {}
        }
        LOG_CATEGORIES
            .iter()
            .position(|(c, _)| *c == category)
            .is_some_and(|i| self.enabled[i])
    }

    /// Sends `message` if its category is enabled.
    pub fn log(&mut self, status: fmi2Status, category: &str, message: &str) {
        if !self.is_enabled(category) {
            return;
        }
        let translated;
        let message = if self.fmi3 {
            translated = fmi3_names(message);
            translated.as_str()
        } else {
            message
        };
        match &mut self.sink {
            Sink::None => {}
            Sink::Rust(f) => f(status, category, message),
            Sink::C {
                logger,
                environment,
            } => {
                let Some(callback) = *logger else { return };
                let category = to_c_string(category);
                let message = to_c_string(message);
                // SAFETY: the importer gave us this callback and environment in fmi2Instantiate;
                // every string is NUL-terminated and outlives the call; the format "%s" consumes
                // exactly the one variadic argument, a C string.
                unsafe {
                    callback(
                        *environment,
                        self.instance_name.as_ptr(),
                        status,
                        category.as_ptr(),
                        c"%s".as_ptr(),
                        message.as_ptr(),
                    )
                }
            }
        }
    }

    /// Logs an error (`logStatusError`).
    pub fn error(&mut self, message: &str) {
        self.log(fmi2Status::fmi2Error, category::ERROR, message);
    }

    /// Logs an event (`logEvents`, only when enabled).
    pub fn event(&mut self, message: &str) {
        self.log(fmi2Status::fmi2OK, category::EVENTS, message);
    }
}

/// A C string of `s`, with interior NUL bytes (which C would cut at) replaced by U+FFFD.
pub fn to_c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{fffd}")).expect("interior NULs were replaced")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;
    use std::rc::Rc;

    type Log = Rc<RefCell<Vec<(fmi2Status, String, String)>>>;

    fn capture(logging_on: bool) -> (Logger, Log) {
        let log: Log = Rc::default();
        let sink = log.clone();
        let logger = Logger::new(
            Sink::Rust(Box::new(move |s, c, m| {
                sink.borrow_mut().push((s, c.to_string(), m.to_string()))
            })),
            "inst",
            logging_on,
        );
        (logger, log)
    }

    #[test]
    fn status_messages_always_pass_debug_messages_only_when_enabled() {
        let (mut logger, log) = capture(false);
        logger.event("hidden");
        logger.log(fmi2Status::fmi2OK, category::SOLVER, "hidden");
        logger.error("shown");
        logger.log(fmi2Status::fmi2Discard, category::DISCARD, "shown too");
        assert_eq!(log.borrow().len(), 2);
        assert_eq!(log.borrow()[0].2, "shown");

        logger
            .set_debug_logging(true, Some(&["logSolver"]))
            .unwrap();
        logger.event("still hidden");
        logger.log(fmi2Status::fmi2OK, category::SOLVER, "solver");
        assert_eq!(log.borrow().len(), 3);
        assert_eq!(log.borrow()[2].1, "logSolver");

        logger.set_debug_logging(true, None).unwrap();
        logger.event("event");
        assert_eq!(log.borrow().len(), 4);
        logger.set_debug_logging(false, None).unwrap();
        logger.event("off again");
        assert_eq!(log.borrow().len(), 4);
    }

    #[test]
    fn an_fmi3_logger_with_logging_off_passes_errors_only() {
        let (logger, log) = capture(false);
        let mut logger = logger.for_fmi3();
        logger.log(fmi2Status::fmi2Warning, category::WARNING, "hidden");
        logger.log(fmi2Status::fmi2Discard, category::DISCARD, "hidden");
        logger.log(fmi2Status::fmi2Fatal, category::FATAL, "fatal");
        logger.error("error");
        assert_eq!(log.borrow().len(), 2);
        logger
            .set_debug_logging(true, Some(&["logStatusDiscard"]))
            .unwrap();
        logger.log(fmi2Status::fmi2Discard, category::DISCARD, "discard");
        logger.log(fmi2Status::fmi2Warning, category::WARNING, "hidden");
        assert_eq!(log.borrow().len(), 3);
        assert_eq!(log.borrow()[2].2, "discard");
    }

    #[test]
    fn unknown_category_is_rejected_and_changes_nothing() {
        let (mut logger, log) = capture(false);
        let e = logger
            .set_debug_logging(true, Some(&["logEvents", "logNonsense"]))
            .unwrap_err();
        assert!(e.contains("logNonsense"), "{e}");
        logger.event("hidden");
        assert!(log.borrow().is_empty());
    }

    #[test]
    fn every_declared_category_is_accepted() {
        let (mut logger, _) = capture(false);
        let names: Vec<&str> = LOG_CATEGORIES.iter().map(|(c, _)| *c).collect();
        logger.set_debug_logging(true, Some(&names)).unwrap();
        for c in [category::EVENTS, category::SOLVER] {
            assert!(logger.is_enabled(c));
        }
        // The categories the FMI layer uses are declared.
        for c in [
            category::EVENTS,
            category::SOLVER,
            category::WARNING,
            category::DISCARD,
            category::ERROR,
            category::FATAL,
        ] {
            assert!(names.contains(&c), "{c} is not in LOG_CATEGORIES");
        }
    }

    #[test]
    fn an_fmi3_logger_names_fmi3_functions_and_states() {
        let (logger, log) = capture(false);
        let mut logger = logger.for_fmi3();
        logger.error("fmi2DoStep: not allowed in state StepFailed (allowed in: StepComplete)");
        logger.error("fmi2GetFMUstate, fmi2GetRealOutputDerivatives, fmi2Discard");
        assert_eq!(
            log.borrow()[0].2,
            "fmi3DoStep: not allowed in state StepDiscarded (allowed in: StepMode)"
        );
        assert_eq!(
            log.borrow()[1].2,
            "fmi3GetFMUState, fmi3GetOutputDerivatives, fmi3Discard"
        );
    }

    #[test]
    fn interior_nul_does_not_truncate() {
        assert_eq!(to_c_string("a\0b").to_str().unwrap(), "a\u{fffd}b");
    }
}
