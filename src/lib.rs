//! flexbody: an elastic 3D finite-element body, moved with the absolute coordinate formulation
//! with reduced strain (Gerstmayr & Irschik), exported as an FMI 2.0 co-simulation FMU.
//!
//! Data flows one way (DESIGN.md section 6):
//! body file ([`model`]) → [`mesh`] → FE matrices ([`fem`]) → [`body`] → [`solver`] → [`slave`] →
//! C ABI (`fmi2`). A layer knows only the layers before it; `unsafe` lives in `fmi2` only.

#![deny(unsafe_code)]

pub mod body;
pub mod element;
pub mod error;
pub mod fem;
#[allow(unsafe_code)]
pub mod fmi2;
pub mod linalg;
pub mod mesh;
pub mod model;
pub mod output;
pub mod slave;
pub mod solver;

pub use error::{Error, ErrorKind};
