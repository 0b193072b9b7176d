//! The one error type of the crate: a kind (what the FMI layer returns) and a message that names
//! the variable, the value and the reason.

use std::fmt;

/// How the FMI layer reports an [`Error`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// Bad input, bad parameter, missing or malformed resource: `fmi2Error`.
    Error,
    /// A step that did not converge; the state was rolled back: `fmi2Discard`.
    Discard,
}

/// An error with a message meant for the engineer reading the importer's log.
#[derive(Debug, Clone, PartialEq)]
pub struct Error {
    pub kind: ErrorKind,
    pub message: String,
}

impl Error {
    /// An `fmi2Error` with the given message.
    pub fn new(message: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Error,
            message: message.into(),
        }
    }

    /// An `fmi2Discard`: the step did not converge and nothing was changed.
    pub fn discard(message: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Discard,
            message: message.into(),
        }
    }

    /// A rejected value: names the variable, the value and the reason.
    pub fn invalid_value(name: &str, value: impl fmt::Display, reason: &str) -> Self {
        Error::new(format!("{name} = {value} rejected: {reason}"))
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// Result with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
