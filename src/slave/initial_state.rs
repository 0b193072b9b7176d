//! The initial state: the body placed rigidly by its first motion interface (or the initial
//! pose parameters), cross-checked against the others, pins settled, accelerations consistent.

use super::assembly::Features;
use super::auto_features::NOT_QUIET;
use super::interfaces::{apply_loads, prescribe_motion};
use super::{Dynamics, Slave};
use crate::body::frame::nearest_rotation;
use crate::error::{Error, Result};
use crate::model::InterfaceKind;
use crate::solver::generalized_alpha;
use crate::solver::problem::DynamicState;
use nalgebra::{Matrix3, Vector3};

impl Slave {
    /// Places the body rigidly and computes the consistent initial acceleration (DESIGN.md
    /// section 4): with motion interfaces, so that the first one's constraint holds at t0 with its
    /// input velocities (the others must agree with that rigid placement); without, at
    /// `initial.position`/`initial.rotation` with `initial.velocity`/`initial.angularVelocity`.
    pub(super) fn ensure_initial_state(&mut self) -> Result<()> {
        self.ensure_model()?;
        self.update_driving_frames()?;
        let p = &self.parameters;
        // The placement x_i = origin + Q (X_i − anchor), ẋ_i = v + ω × Q (X_i − anchor).
        let first_motion = self
            .interfaces
            .iter()
            .position(|i| i.kind == InterfaceKind::Motion);
        let (origin, q, anchor, v0, w0, source) = match first_motion {
            Some(k) => {
                let f = &self.driving[k];
                let name = &self.body_file.interfaces[k].name;
                (
                    f.position,
                    f.rotation,
                    self.interfaces[k].set.reference_point,
                    f.velocity,
                    f.angular_velocity,
                    format!("the inputs of motion interface '{name}'"),
                )
            }
            None => {
                let q = Matrix3::from_row_slice(&p.initial_rotation);
                let deviation = (q.transpose() * q - Matrix3::identity()).amax();
                if deviation > 1e-6 || q.determinant() <= 0.0 {
                    return Err(Error::new(format!(
                        "initial.rotation = {:?} rejected: not a rotation matrix (|QᵀQ − I| = {deviation:.2e}, det = {:.6})",
                        p.initial_rotation,
                        q.determinant()
                    )));
                }
                (
                    Vector3::from(p.initial_position),
                    nearest_rotation(&q),
                    Vector3::zeros(),
                    Vector3::from(p.initial_velocity),
                    Vector3::from(p.initial_angular_velocity),
                    "initial.velocity and initial.angularVelocity".to_string(),
                )
            }
        };
        let has_fixed = self
            .interfaces
            .iter()
            .any(|i| i.kind == InterfaceKind::Fixed);
        if has_fixed && (v0.norm() > 0.0 || w0.norm() > 0.0) {
            return Err(Error::new(format!(
                "{source} rejected: velocity {:?}, angular velocity {:?}, but a body held by a fixed support must start at rest",
                v0.as_slice(),
                w0.as_slice()
            )));
        }
        let model = self.model.as_mut().unwrap();
        // model.auto starts with the terms that have an estimate off (the body is placed
        // rigidly: ū = 0, where both vanish); without it the switches are forced.
        let features = match &model.indicators {
            Some(ind) => Features {
                nonlinear_forces: model.allowed.nonlinear_forces
                    && !ind.estimates_nonlinear_forces(),
                stiffening: model.allowed.stiffening && !ind.estimates_stiffening(),
            },
            None => model.allowed,
        };
        model.apply_features(features);
        let body = &model.body;
        let n = body.node_count();
        let mut state = DynamicState {
            time: self.start_time,
            position: vec![0.0; 3 * n],
            velocity: vec![0.0; 3 * n],
            acceleration: vec![0.0; 3 * n],
            pseudo_acceleration: vec![0.0; 3 * n],
            multipliers: vec![0.0; model.free.multiplier_count()],
        };
        body.place_rigidly(
            &origin,
            &q,
            &anchor,
            &v0,
            &w0,
            &mut state.position,
            &mut state.velocity,
        );
        // Every other motion interface must hold in this rigid placement.
        let tolerance = 1e-6 * self.size;
        for (k, interface) in self.interfaces.iter().enumerate() {
            if interface.kind != InterfaceKind::Motion || Some(k) == first_motion {
                continue;
            }
            let mut placed = state.clone();
            interface.set.prescribe(
                &body.reference,
                &self.driving[k],
                0.0,
                &mut placed.position,
                &mut placed.velocity,
                &mut placed.acceleration,
            );
            let gap = placed
                .position
                .iter()
                .zip(&state.position)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            if gap > tolerance {
                return Err(Error::new(format!(
                    "motion interfaces '{}' and '{}' disagree at t0: no rigid placement of the body satisfies both (their inputs differ by {gap:.3e} m at the nodes; tolerance {tolerance:.1e} m)",
                    self.body_file.interfaces[first_motion.unwrap()].name,
                    self.body_file.interfaces[k].name
                )));
            }
        }
        for interface in &self.interfaces {
            if interface.kind == InterfaceKind::Fixed {
                for i in interface.set.held_indices() {
                    state.velocity[3 * i..3 * i + 3].fill(0.0);
                }
            }
        }
        prescribe_motion(body, &self.interfaces, &self.driving, 0.0, &mut state);
        // Pins and hinges hold their centroids where the body was placed; the placement's
        // velocity must not move them.
        for (k, interface) in self.interfaces.iter().enumerate() {
            let first = interface.first_constraint;
            for constraint in
                &mut model.free.constraints[first..first + interface.point_constraints.len()]
            {
                constraint.target = constraint.centroid(&state.position);
                let speed = constraint.centroid(&state.velocity).norm();
                if speed > 1e-9 * (1.0 + v0.norm() + w0.norm() * self.size) {
                    return Err(Error::new(format!(
                        "{source} rejected: the initial velocity moves the {:?} support '{}' at {speed:.3e} m/s; the body may only turn about it",
                        interface.kind,
                        self.body_file.interfaces[k].name
                    )));
                }
            }
        }
        let body = &model.body;
        let gravity = Vector3::from(p.gravity);
        let interfaces = &self.interfaces;
        let inputs = &self.inputs;
        let loads =
            |x: &[f64], f: &mut [f64]| apply_loads(body, interfaces, inputs, None, &gravity, x, f);
        generalized_alpha::initial_acceleration(
            body,
            &model.free,
            &loads,
            &mut state,
            &mut model.forces,
            &mut model.mass,
        )?;
        if let Some(explicit) = &model.explicit {
            // The explicit scheme's accelerations belong to the lumped mass.
            explicit.accelerations(body, &model.free, &loads, &mut state, &mut model.forces);
        }
        self.dynamics = Some(Dynamics {
            state,
            loads: self.inputs.clone(),
            gravity: p.gravity,
            features,
            quiet_since: [NOT_QUIET; 2],
        });
        self.outputs.valid = false;
        Ok(())
    }
}
