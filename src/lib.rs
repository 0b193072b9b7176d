//! flexbody: an elastic 3D finite-element body, moved with the absolute coordinate formulation
//! with reduced strain (Gerstmayr & Irschik), exported as an FMI 2.0 or 3.0 co-simulation FMU.
//!
//! Data flows one way: body file ([`model`]) → [`mesh`] → FE matrices ([`fem`]) → [`body`] →
//! [`solver`] → [`slave`] → C ABI (`fmi2`, and `fmi3` on top of it). The modules are floors
//! (docs/architecture.md, checked by `tests/floors.rs`): [`error`], [`linalg`], [`element`],
//! [`mesh`], [`fem`], [`body`], [`solver`] and [`output`], [`model`], [`slave`], `fmi2`, `fmi3`;
//! each uses only the floors below it. `unsafe` lives in the two C boundaries `fmi2` and `fmi3`
//! only.

#![deny(unsafe_code)]

pub mod body;
pub mod element;
pub mod error;
pub mod fem;
#[allow(unsafe_code)]
pub mod fmi2;
#[allow(unsafe_code)]
pub mod fmi3;
pub mod linalg;
pub mod mesh;
pub mod model;
pub mod output;
pub mod slave;
pub mod solver;

pub use error::{Error, ErrorKind};
