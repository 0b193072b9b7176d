//! Outputs, computed once per state on the first read, and their time derivatives.

use super::interfaces::apply_loads;
use super::{Slave, MAX_OUTPUT_DERIVATIVE_ORDER};
use crate::body::frame::node;
use crate::body::interface::InterfaceMotion;
use crate::error::{Error, Result};
use crate::model::variables::{FixedKey, InterfaceQuantity};
use crate::model::{InterfaceKind, Target, VariableType};
use crate::solver::problem::{last_residual, residual};
use nalgebra::{Matrix3, Vector3};

/// Outputs computed once per state, on the first read.
#[derive(Debug, Clone, Default)]
pub(super) struct Outputs {
    pub(super) valid: bool,
    pub(super) body: [f64; 26],
    /// Acceleration of the centre of mass (for output derivatives).
    pub(super) body_acceleration: [f64; 3],
    /// Per interface: force[3], torque[3], then motion (position, rotation, velocity, angular
    /// velocity, acceleration, angular acceleration) in value-reference slot order.
    pub(super) interfaces: Vec<[f64; 30]>,
    /// Scratch `M ẋ` (flat, the body's size; resized only when the model changes).
    pub(super) momentum: Vec<f64>,
}

impl Slave {
    /// Computes the outputs of the current state (once per state).
    pub(super) fn ensure_outputs(&mut self) -> Result<()> {
        if self.outputs.valid {
            return Ok(());
        }
        if self.dynamics.is_none() {
            // Initialization mode: outputs of the rigidly placed body with the current inputs.
            self.ensure_initial_state()?;
        }
        let model = self.model.as_mut().unwrap();
        let dynamics = self.dynamics.as_ref().unwrap();
        let state = &dynamics.state;
        let body = &model.body;
        let gravity = Vector3::from(dynamics.gravity);
        let interfaces = &self.interfaces;
        let loads_in = &dynamics.loads;
        let loads = |x: &[f64], f: &mut [f64]| {
            apply_loads(body, interfaces, loads_in, None, &gravity, x, f)
        };
        let kin = residual(body, &model.free, state, &loads, &mut model.forces);
        let residual = last_residual(&model.forces);

        // Body outputs (DESIGN.md section 4).
        let m = body.total_mass;
        let (mut com, mut vcom, mut acom) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
        for (i, &mi) in body.mass_row_sums.iter().enumerate() {
            com += mi * node(&state.position, i);
            vcom += mi * node(&state.velocity, i);
            acom += mi * node(&state.acceleration, i);
        }
        com /= m;
        vcom /= m;
        acom /= m;
        self.outputs.body_acceleration = acom.into();
        let (mut angular, mut kinetic) = (Vector3::zeros(), 0.0);
        let momentum = &mut self.outputs.momentum;
        momentum.resize(state.velocity.len(), 0.0); // sized by `finish_model`: no allocation
        body.mass_times(&state.velocity, momentum);
        for i in 0..body.node_count() {
            let mv = node(momentum, i);
            angular += (node(&state.position, i) - body.unit(i) * com).cross(&mv);
            kinetic += 0.5 * node(&state.velocity, i).dot(&mv);
        }
        let r = kin.frame.rotation;
        let omega = r * kin.angular_velocity_body;
        let out = &mut self.outputs.body;
        out[0..3].copy_from_slice(com.as_slice());
        for (k, value) in out[3..12].iter_mut().enumerate() {
            *value = r[(k / 3, k % 3)];
        }
        out[12..15].copy_from_slice(vcom.as_slice());
        out[15..18].copy_from_slice(omega.as_slice());
        out[18..21].copy_from_slice((m * vcom).as_slice());
        out[21..24].copy_from_slice(angular.as_slice());
        out[24] = kinetic;
        out[25] = match &body.full {
            Some(full) => full.strain_energy(&state.position),
            None => kin.strain_energy,
        };

        for (k, interface) in self.interfaces.iter().enumerate() {
            let out = &mut self.outputs.interfaces[k];
            match interface.kind {
                InterfaceKind::Pin | InterfaceKind::Hinge => {
                    // The constraint load on the body is −Cᵀλ: per point constraint a force −λ_k
                    // at its centroid c_k; the torque is taken about the reference point.
                    let p = interface
                        .set
                        .motion(&state.position, &state.velocity, &state.acceleration)
                        .position;
                    let (mut force, mut torque) = (Vector3::zeros(), Vector3::zeros());
                    let first = interface.first_constraint;
                    for (j, constraint) in model.free.constraints
                        [first..first + interface.point_constraints.len()]
                        .iter()
                        .enumerate()
                    {
                        let m = &state.multipliers[3 * (first + j)..3 * (first + j) + 3];
                        let f = -Vector3::new(m[0], m[1], m[2]);
                        force += f;
                        torque += (constraint.centroid(&state.position) - p).cross(&f);
                    }
                    out[0..3].copy_from_slice(force.as_slice());
                    out[3..6].copy_from_slice(torque.as_slice());
                }
                InterfaceKind::Fixed | InterfaceKind::Motion => {
                    // Reaction of the support on the body: λ_C = (M ẍ + f − f_ext)_C.
                    let (f, t) = interface.set.resultant(&state.position, residual);
                    out[0..3].copy_from_slice(f.as_slice());
                    out[3..6].copy_from_slice(t.as_slice());
                }
                InterfaceKind::Force => {
                    out[0..6].copy_from_slice(&dynamics.loads[k][0..6]);
                    let m: InterfaceMotion =
                        interface
                            .set
                            .motion(&state.position, &state.velocity, &state.acceleration);
                    out[6..9].copy_from_slice(m.position.as_slice());
                    for (j, value) in out[9..18].iter_mut().enumerate() {
                        *value = m.rotation[(j / 3, j % 3)];
                    }
                    out[18..21].copy_from_slice(m.velocity.as_slice());
                    out[21..24].copy_from_slice(m.angular_velocity.as_slice());
                    out[24..27].copy_from_slice(m.acceleration.as_slice());
                    out[27..30].copy_from_slice(m.angular_acceleration.as_slice());
                }
            }
        }
        let finite = self.outputs.body.iter().all(|x| x.is_finite())
            && self.outputs.body_acceleration.iter().all(|x| x.is_finite())
            && self
                .outputs
                .interfaces
                .iter()
                .flatten()
                .all(|x| x.is_finite());
        if !finite {
            return Err(Error::new(
                "the outputs of the current state are not finite",
            ));
        }
        self.outputs.valid = true;
        Ok(())
    }

    /// `fmi2GetRealOutputDerivatives`: the `order`-th time derivative (1 or 2) of an output at the
    /// current time. Available:
    ///
    /// | output | order 1 | order 2 |
    /// | --- | --- | --- |
    /// | `<i>.position` (force interface) | `<i>.velocity` | `<i>.acceleration` |
    /// | `<i>.rotation` | `[ω]× R` | `([α]× + [ω]×[ω]×) R` |
    /// | `<i>.velocity`, `<i>.angularVelocity` | `<i>.acceleration`, `<i>.angularAcceleration` | — |
    /// | `body.position` | `body.velocity` | centre-of-mass acceleration |
    /// | `body.velocity` | centre-of-mass acceleration | — |
    /// | `body.linearMomentum` | total mass × centre-of-mass acceleration | — |
    /// | `body.rotation` | `[ω]× R` (`ω` = `body.angularVelocity`) | — |
    ///
    /// An interface's rates are those of the least-squares rigid motion of its node set (the
    /// velocity and acceleration outputs): the exact time derivatives of its pose for a rigid
    /// motion of the set, and within the set's deformation rate otherwise. Other outputs
    /// (reactions, energies, momenta' rates other than the above) have no derivative: an error.
    pub fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64> {
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        let (target, causality) = (v.target, v.causality);
        // The name only for messages (no allocation on the way to a value).
        let name = |s: &Slave| {
            s.variables
                .get(VariableType::Real, vr)
                .map_or(String::new(), |v| v.name.clone())
        };
        if causality != crate::model::Causality::Output {
            return Err(Error::new(format!(
                "{} (value reference {vr}) is not an output: only outputs have derivatives to get",
                name(self)
            )));
        }
        if !(1..=MAX_OUTPUT_DERIVATIVE_ORDER).contains(&order) {
            return Err(Error::invalid_value(
                &format!("the order of the derivative of {}", name(self)),
                order,
                &format!("must be 1 or {MAX_OUTPUT_DERIVATIVE_ORDER} (maxOutputDerivativeOrder)"),
            ));
        }
        self.ensure_outputs()?;
        let rotation_rate = |r: &[f64], w: &[f64], a: Option<&[f64]>, c: usize| {
            let r = Matrix3::from_row_slice(r);
            let w = Vector3::from_column_slice(w).cross_matrix();
            let rate = match a {
                None => w * r,
                Some(a) => (Vector3::from_column_slice(a).cross_matrix() + w * w) * r,
            };
            rate[(c / 3, c % 3)]
        };
        use InterfaceQuantity as Q;
        let slot = |q: Q| q.slot() as usize;
        let value = match target {
            Target::Interface {
                index,
                quantity,
                component: c,
            } if self.interfaces[index].kind == InterfaceKind::Force => {
                let out = &self.outputs.interfaces[index];
                let three = |q: Q| &out[slot(q)..slot(q) + 3];
                match (quantity, order) {
                    (Q::Position, 1) => Some(out[slot(Q::Velocity) + c]),
                    (Q::Position, 2) | (Q::Velocity, 1) => Some(out[slot(Q::Acceleration) + c]),
                    (Q::AngularVelocity, 1) => Some(out[slot(Q::AngularAcceleration) + c]),
                    (Q::Rotation, 1) => Some(rotation_rate(
                        &out[slot(Q::Rotation)..slot(Q::Rotation) + 9],
                        three(Q::AngularVelocity),
                        None,
                        c,
                    )),
                    (Q::Rotation, 2) => Some(rotation_rate(
                        &out[slot(Q::Rotation)..slot(Q::Rotation) + 9],
                        three(Q::AngularVelocity),
                        Some(three(Q::AngularAcceleration)),
                        c,
                    )),
                    _ => None,
                }
            }
            Target::Fixed { key, component: c } => {
                let body = &self.outputs.body;
                let acom = &self.outputs.body_acceleration;
                let mass = self.model.as_ref().map_or(0.0, |m| m.body.total_mass);
                match (key, order) {
                    (FixedKey::BodyPosition, 1) => Some(body[12 + c]),
                    (FixedKey::BodyPosition, 2) | (FixedKey::BodyVelocity, 1) => Some(acom[c]),
                    (FixedKey::BodyLinearMomentum, 1) => Some(mass * acom[c]),
                    (FixedKey::BodyRotation, 1) => {
                        Some(rotation_rate(&body[3..12], &body[15..18], None, c))
                    }
                    _ => None,
                }
            }
            _ => None,
        };
        match value {
            Some(x) if x.is_finite() => Ok(x),
            Some(x) => Err(Error::new(format!(
                "the derivative of order {order} of {} evaluated to {x}: the state is not finite",
                name(self)
            ))),
            None => Err(Error::new(format!(
                "{} (value reference {vr}) has no derivative of order {order} (available: interface position and rotation up to order 2, velocity and angularVelocity order 1; body.position up to order 2, body.velocity, body.linearMomentum and body.rotation order 1)",
                name(self)
            ))),
        }
    }
}
