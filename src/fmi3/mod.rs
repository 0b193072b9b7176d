//! The FMI 3.0 co-simulation C ABI, beside FMI 2.0's ([`crate::fmi2`]) and on top of it: the
//! same slave, calling-sequence state machine, logger and FMU states; what FMI 3.0 changes is
//! here.
//!
//! * [`types`]: the C types, written by hand.
//! * [`instance`]: array variables (`tip.position` as one `[3]` variable, rotations `[3,3]`),
//!   the independent variable `time`, FMI 3.0's types (Float64, Int32, enumerations as Int64,
//!   Boolean as C `bool`).
//! * [`exports`]: the `extern "C"` functions.
//!
//! Like [`crate::fmi2`], this is a C boundary: together they are the only modules allowed
//! `unsafe` code (`#![deny(unsafe_code)]` elsewhere).

pub mod exports;
pub mod instance;
pub mod types;

pub use instance::Fmi3Instance;
