//! Time integration: generalized-α with its constant iteration matrix, Radau IIA and central
//! difference.
//!
//! Layers, each importing only from those below it:
//!
//! - [`problem`]: the shared vocabulary (free nodes, state, residual and its workspace, step
//!   problem and report), over [`constraints`] (point constraints);
//! - [`anderson`] and [`fixed_point`]: the fixed-point iteration's acceleration and stopping
//!   rule; [`consistent_acceleration`] and [`woodbury`]: solves used by the schemes;
//! - the schemes [`generalized_alpha`], [`radau`] and [`central_difference`];
//! - [`integrator`]: the scheme a model steps with, and its factorizations per step size.

pub mod anderson;
pub mod central_difference;
pub mod consistent_acceleration;
pub mod constraints;
pub mod fixed_point;
pub mod generalized_alpha;
pub mod integrator;
pub mod problem;
pub mod radau;
pub mod woodbury;
