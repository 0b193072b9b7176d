//! Outputs, computed once per state and by group on their first read, and their time derivatives.

use super::interfaces::{apply_loads, Interface};
use super::variables::body_output_slot;
use super::{Inputs, Slave, MAX_OUTPUT_DERIVATIVE_ORDER};
use crate::body::frame::node;
use crate::body::interface::InterfaceMotion;
use crate::body::{Body, BodyKinematics};
use crate::error::{Error, Result};
use crate::model::variables::{FixedKey, InterfaceQuantity};
use crate::model::{InterfaceKind, Target, VariableType};
use crate::solver::problem::{last_residual, residual, DynamicState, FreeNodes};
use nalgebra::{Matrix3, Vector3};

/// Outputs computed once per state, on the first read, in groups: an importer that reads one
/// interface's motion pays for that alone, not for the residual that the reactions and the
/// body's strain energy need (docs/fmu.md, "Variables").
#[derive(Debug, Clone, Default)]
pub(super) struct Outputs {
    /// Whether `body` and `body_acceleration` are those of the current state.
    body_valid: bool,
    /// Per interface: whether its slots are those of the current state.
    interface_valid: Vec<bool>,
    /// The residual's kinematics when the residual's scratch holds the current state's
    /// residual.
    residual: Option<BodyKinematics>,
    pub(super) body: [f64; 26],
    /// Acceleration of the centre of mass (for output derivatives).
    pub(super) body_acceleration: [f64; 3],
    /// Per interface: force[3], torque[3], then motion (position, rotation, velocity, angular
    /// velocity, acceleration, angular acceleration) in value-reference slot order.
    pub(super) interfaces: Vec<Inputs>,
    /// Scratch `M ẋ` (flat, the body's size; resized only when the model changes).
    pub(super) momentum: Vec<f64>,
}

impl Outputs {
    /// No outputs for `interfaces` interfaces yet.
    pub(super) fn new(interfaces: usize) -> Outputs {
        Outputs {
            interface_valid: vec![false; interfaces],
            interfaces: vec![[0.0; super::INTERFACE_SLOTS]; interfaces],
            ..Outputs::default()
        }
    }

    /// The state changed: every group is computed again on its next read.
    pub(super) fn invalidate(&mut self) {
        self.body_valid = false;
        self.residual = None;
        self.interface_valid.fill(false);
    }
}

/// Which outputs [`Slave::ensure_outputs`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum OutputGroup {
    /// The `body.*` outputs.
    Body,
    /// Interface `k`'s outputs.
    Interface(usize),
    /// All of them (and the residual's scratch of the current state).
    All,
}

impl Slave {
    /// Computes the outputs of `group` for the current state (once per state). The residual
    /// (`M ẍ + f − f_ext`) is evaluated only where something reads it: the body's outputs (its
    /// frame and strain energy) and the reactions of fixed supports and motion interfaces, which
    /// are all taken from it at once, so that no group reads a residual's scratch that another
    /// computation may have overwritten since.
    pub(super) fn ensure_outputs(&mut self, group: OutputGroup) -> Result<()> {
        let all = group == OutputGroup::All;
        let wanted = |k: usize| all || group == OutputGroup::Interface(k);
        let body_wanted = all || group == OutputGroup::Body;
        let reaction =
            |kind: InterfaceKind| matches!(kind, InterfaceKind::Fixed | InterfaceKind::Motion);
        let outputs = &self.outputs;
        let stale = |k: usize| wanted(k) && !outputs.interface_valid[k];
        let interfaces = 0..self.interfaces.len();
        let body_stale = body_wanted && !outputs.body_valid;
        let needs_residual = outputs.residual.is_none()
            && (all
                || body_stale
                || interfaces
                    .clone()
                    .any(|k| stale(k) && reaction(self.interfaces[k].kind)));
        if !(needs_residual || body_stale || interfaces.clone().any(stale)) {
            return Ok(());
        }
        if self.dynamics.is_none() {
            // Initialization mode: outputs of the rigidly placed body with the current inputs.
            self.ensure_initial_state()?;
        }
        // (No model after a build that failed: ensure_model clears it first.)
        let model = self.model.as_mut().ok_or_else(|| {
            Error::new("the body's model could not be built (see the error that said why)")
        })?;
        let dynamics = self.dynamics.as_ref().unwrap();
        let state = &dynamics.state;
        let body = &model.body;
        let outputs = &mut self.outputs;
        let names = &self.body_file.interfaces;
        let interface = |k: usize, residual: &[f64], outputs: &mut Outputs| {
            interface_outputs(
                &self.interfaces[k],
                &model.free,
                state,
                residual,
                &dynamics.loads[k],
                &mut outputs.interfaces[k],
            );
            if !outputs.interfaces[k].iter().all(|x| x.is_finite()) {
                return Err(Error::new(format!(
                    "the outputs of interface '{}' in the current state are not finite",
                    names[k].name
                )));
            }
            outputs.interface_valid[k] = true;
            Ok(())
        };
        if needs_residual {
            let gravity = Vector3::from(dynamics.gravity);
            let loads_in = &dynamics.loads;
            let loads = |x: &[f64], f: &mut [f64]| {
                apply_loads(body, &self.interfaces, loads_in, None, &gravity, x, f)
            };
            let kin = residual(body, &model.free, state, &loads, &mut model.forces);
            let residual = last_residual(&model.forces);
            for k in interfaces.clone() {
                if reaction(self.interfaces[k].kind) {
                    interface(k, residual, outputs)?;
                }
            }
            // Only once every reaction is taken: after an error the next read evaluates again.
            outputs.residual = Some(kin);
        }
        if body_stale {
            let kin = outputs.residual.expect("evaluated above");
            body_outputs(body, state, &kin, outputs);
            let finite = outputs.body.iter().all(|x| x.is_finite())
                && outputs.body_acceleration.iter().all(|x| x.is_finite());
            if !finite {
                return Err(Error::new(
                    "the body's outputs of the current state are not finite",
                ));
            }
            outputs.body_valid = true;
        }
        for k in interfaces {
            if wanted(k) && !outputs.interface_valid[k] {
                // Not a reaction (the reactions are valid with the residual): it is not read.
                debug_assert!(!reaction(self.interfaces[k].kind));
                interface(k, &[], outputs)?;
            }
        }
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
        let group = match target {
            Target::Interface { index, .. } => OutputGroup::Interface(index),
            _ => OutputGroup::Body,
        };
        self.ensure_outputs(group)?;
        let value = match target {
            Target::Interface {
                index,
                quantity,
                component,
            } if self.interfaces[index].kind == InterfaceKind::Force => {
                interface_output_derivative(
                    &self.outputs.interfaces[index],
                    quantity,
                    component,
                    order,
                )
            }
            Target::Fixed { key, component } => {
                let mass = self.model.as_ref().map_or(0.0, |m| m.body.total_mass);
                body_output_derivative(&self.outputs, mass, key, component, order)
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

/// The body outputs (docs/fmu.md, "Variables") of `state`: centre of mass, co-moving frame,
/// momenta about the centre of mass, kinetic and strain energy; and the centre of mass's
/// acceleration (for output derivatives).
fn body_outputs(body: &Body, state: &DynamicState, kin: &BodyKinematics, outputs: &mut Outputs) {
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
    outputs.body_acceleration = acom.into();
    let (mut angular, mut kinetic) = (Vector3::zeros(), 0.0);
    let momentum = &mut outputs.momentum;
    momentum.resize(state.velocity.len(), 0.0); // sized by `finish_model`: no allocation
    body.mass_times(&state.velocity, momentum);
    for i in 0..body.node_count() {
        let mv = node(momentum, i);
        angular += (node(&state.position, i) - body.unit(i) * com).cross(&mv);
        kinetic += 0.5 * node(&state.velocity, i).dot(&mv);
    }
    // The body's best-fit frame and its angular velocity, also where a linear body holds its
    // frame at the placement (docs/formulation.md, "The linear body").
    let (r, omega_body) = if body.linear.is_some() {
        let (frame, omega) = body
            .frame_weights
            .moving_frame(&state.position, &state.velocity);
        (frame.rotation, omega)
    } else {
        let omega =
            body.frame_weights
                .angular_velocity_at(&kin.frame, &state.position, &state.velocity);
        (kin.frame.rotation, omega)
    };
    let omega = r * omega_body;
    let strain_energy = match &body.full {
        Some(full) => full.strain_energy(&state.position),
        None => kin.strain_energy,
    };
    let out = &mut outputs.body;
    let mut put = |key: FixedKey, values: &[f64]| {
        let at = body_output_slot(key);
        out[at..at + values.len()].copy_from_slice(values);
    };
    put(FixedKey::BodyPosition, com.as_slice());
    put(FixedKey::BodyRotation, r.transpose().as_slice()); // row-major
    put(FixedKey::BodyVelocity, vcom.as_slice());
    put(FixedKey::BodyAngularVelocity, omega.as_slice());
    put(FixedKey::BodyLinearMomentum, (m * vcom).as_slice());
    put(FixedKey::BodyAngularMomentum, angular.as_slice());
    put(FixedKey::BodyKineticEnergy, &[kinetic]);
    put(FixedKey::BodyStrainEnergy, &[strain_energy]);
}

/// The outputs of one interface (value-reference slot order) in `state`, with `residual` the
/// residual of the equations of motion (the reactions of supports and motion interfaces) and
/// `load` the inputs the state's accelerations belong to.
fn interface_outputs(
    interface: &Interface,
    free: &FreeNodes,
    state: &DynamicState,
    residual: &[f64],
    load: &Inputs,
    out: &mut Inputs,
) {
    use InterfaceQuantity as Q;
    let put = |out: &mut Inputs, q: Q, values: &[f64]| {
        let at = q.slot() as usize;
        out[at..at + values.len()].copy_from_slice(values);
    };
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
            for (j, constraint) in free.constraints
                [first..first + interface.point_constraints.len()]
                .iter()
                .enumerate()
            {
                let m = &state.multipliers[3 * (first + j)..3 * (first + j) + 3];
                let f = -Vector3::new(m[0], m[1], m[2]);
                force += f;
                torque += (constraint.centroid(&state.position) - p).cross(&f);
            }
            if interface.locks.is_some() {
                // A hinge on a rigid set: the bearing's moment, from its axis lock.
                let lock = interface.lock_constraint;
                let first = 3 * free.constraints.len()
                    + free.rigid[..lock].iter().map(|r| r.rows()).sum::<usize>();
                let m = &state.multipliers[first..first + free.rigid[lock].rows()];
                torque -= free.rigid[lock].moment(&state.position, m, &p);
            }
            put(out, Q::Force, force.as_slice());
            put(out, Q::Torque, torque.as_slice());
        }
        InterfaceKind::Fixed | InterfaceKind::Motion => {
            // Reaction of the support on the body: λ_C = (M ẍ + f − f_ext)_C.
            let (f, t) = interface.set.resultant(&state.position, residual);
            put(out, Q::Force, f.as_slice());
            put(out, Q::Torque, t.as_slice());
        }
        InterfaceKind::Force => {
            let (f, t) = (Q::Force.slot() as usize, Q::Torque.slot() as usize);
            out[f..f + 3].copy_from_slice(&load[f..f + 3]);
            out[t..t + 3].copy_from_slice(&load[t..t + 3]);
            let m: InterfaceMotion =
                interface
                    .set
                    .motion(&state.position, &state.velocity, &state.acceleration);
            put(out, Q::Position, m.position.as_slice());
            put(out, Q::Rotation, m.rotation.transpose().as_slice()); // row-major
            put(out, Q::Velocity, m.velocity.as_slice());
            put(out, Q::AngularVelocity, m.angular_velocity.as_slice());
            put(out, Q::Acceleration, m.acceleration.as_slice());
            put(
                out,
                Q::AngularAcceleration,
                m.angular_acceleration.as_slice(),
            );
        }
    }
}

/// Component `c` (row-major) of `Ṙ = [ω]× R`, or with the angular acceleration `α` of
/// `R̈ = ([α]× + [ω]×[ω]×) R`.
fn rotation_rate(r: &[f64], w: &[f64], a: Option<&[f64]>, c: usize) -> f64 {
    let r = Matrix3::from_row_slice(r);
    let w = Vector3::from_column_slice(w).cross_matrix();
    let rate = match a {
        None => w * r,
        Some(a) => (Vector3::from_column_slice(a).cross_matrix() + w * w) * r,
    };
    rate[(c / 3, c % 3)]
}

/// Derivative `order` of component `c` of a force interface's output `quantity`, from its
/// outputs `out` (the rates of the least-squares rigid motion of its node set).
fn interface_output_derivative(
    out: &Inputs,
    quantity: InterfaceQuantity,
    c: usize,
    order: i32,
) -> Option<f64> {
    use InterfaceQuantity as Q;
    let slot = |q: Q| q.slot() as usize;
    let three = |q: Q| &out[slot(q)..slot(q) + 3];
    let rotation = &out[slot(Q::Rotation)..slot(Q::Rotation) + 9];
    match (quantity, order) {
        (Q::Position, 1) => Some(out[slot(Q::Velocity) + c]),
        (Q::Position, 2) | (Q::Velocity, 1) => Some(out[slot(Q::Acceleration) + c]),
        (Q::AngularVelocity, 1) => Some(out[slot(Q::AngularAcceleration) + c]),
        (Q::Rotation, 1) => Some(rotation_rate(rotation, three(Q::AngularVelocity), None, c)),
        (Q::Rotation, 2) => Some(rotation_rate(
            rotation,
            three(Q::AngularVelocity),
            Some(three(Q::AngularAcceleration)),
            c,
        )),
        _ => None,
    }
}

/// Derivative `order` of component `c` of the body output `key` (total mass `mass`).
fn body_output_derivative(
    outputs: &Outputs,
    mass: f64,
    key: FixedKey,
    c: usize,
    order: i32,
) -> Option<f64> {
    let body = &outputs.body;
    let acom = &outputs.body_acceleration;
    let at = |k: FixedKey| body_output_slot(k);
    match (key, order) {
        (FixedKey::BodyPosition, 1) => Some(body[at(FixedKey::BodyVelocity) + c]),
        (FixedKey::BodyPosition, 2) | (FixedKey::BodyVelocity, 1) => Some(acom[c]),
        (FixedKey::BodyLinearMomentum, 1) => Some(mass * acom[c]),
        (FixedKey::BodyRotation, 1) => {
            let (r, w) = (
                at(FixedKey::BodyRotation),
                at(FixedKey::BodyAngularVelocity),
            );
            Some(rotation_rate(&body[r..r + 9], &body[w..w + 3], None, c))
        }
        _ => None,
    }
}
