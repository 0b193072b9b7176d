//! The FMI 2.0 co-simulation C ABI: argument checks, the calling-sequence state machine, logging.
//! Thin and complete; every entry point catches panics. The physics lives in [`crate::slave`].
