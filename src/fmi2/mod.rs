//! The FMI 2.0 co-simulation C ABI: argument checks, the calling-sequence state machine, logging.
//! Thin and complete; every entry point catches panics. The physics lives in [`crate::slave`].
//!
//! * [`types`]: the C types, written by hand (`#[repr(C)]`).
//! * [`uri`]: `fmuResourceLocation` → directory.
//! * [`logger`]: the importer's logger callback and the log categories.
//! * [`instance`]: one instance: state machine, settability, status queries, FMU states.
//! * [`exports`]: the 34 `extern "C"` functions.
//!
//! There is no global mutable state: everything lives in the boxed instance, so many instances
//! can run in one process, each on its own thread.

pub mod exports;
pub mod instance;
pub mod logger;
pub mod types;
pub mod uri;

pub use instance::{CoSimSlave, Instance, MachineState};
pub use types::fmi2Status;
