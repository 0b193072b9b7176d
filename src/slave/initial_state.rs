//! The initial state: the body placed rigidly by its first motion interface (or the initial
//! pose parameters), cross-checked against the others, pins settled, accelerations consistent.

use super::assembly::Features;
use super::auto_features::NOT_QUIET;
use super::interfaces::{apply_loads, prescribe_motion, rotation_input};
use super::step_control::Ladder;
use super::{Dynamics, LogEvent, Slave};
use crate::error::{Error, Result};
use crate::model::{category, InterfaceKind};
use crate::solver::generalized_alpha;
use crate::solver::problem::DynamicState;
use nalgebra::{Matrix3, Vector3};

/// The rigid placement of the body at the start: `x_i = origin + Q (X_i − anchor)`,
/// `ẋ_i = v + ω × Q (X_i − anchor)`.
struct RigidPlacement {
    origin: Vector3<f64>,
    rotation: Matrix3<f64>,
    anchor: Vector3<f64>,
    velocity: Vector3<f64>,
    angular_velocity: Vector3<f64>,
    /// The interface whose inputs define it (the first motion interface), if any.
    first_motion: Option<usize>,
    /// What the velocities come from, for messages.
    source: String,
}

impl Slave {
    /// Places the body rigidly and computes the consistent initial acceleration (docs/fmu.md,
    /// "Initialization"): with motion interfaces, so that the first one's constraint holds at t0
    /// with its input velocities (the others must agree with that rigid placement); without, at
    /// `initial.position`/`initial.rotation` with `initial.velocity`/`initial.angularVelocity`.
    pub(super) fn ensure_initial_state(&mut self) -> Result<()> {
        self.ensure_model()?;
        self.update_driving_frames()?;
        let placement = self.rigid_placement()?;
        let model = self.model.as_mut().unwrap();
        // model.auto starts with the terms that have an estimate off (the body is placed
        // rigidly: ū = 0, where both vanish); without it the switches are forced.
        // The linear body starts linear when allowed (placed rigidly, its frame is at the
        // placement); its placement is known once the body is placed, below.
        let features = match &model.indicators {
            Some(ind) => Features {
                nonlinear_forces: model.allowed.nonlinear_forces
                    && !ind.estimates_nonlinear_forces(),
                stiffening: model.allowed.stiffening && !ind.estimates_stiffening(),
                frames: false,
                frames_refused: false,
                linear: false,
                // Forced slabs' own stiffening from the start; model.auto's comes on later.
                slab_stiffening: model.allowed.slab_stiffening && !model.allowed.frames,
            },
            // A reduced body's stiffening from the driving motion starts off when model.auto
            // switches it: the first step's communication point decides.
            None => Features {
                frames: false,
                linear: false,
                stiffening: model.allowed.stiffening && model.driven_stiffening.is_none(),
                slab_stiffening: model.allowed.slab_stiffening && !model.allowed.frames,
                ..model.allowed
            },
        };
        model.apply_features(features);
        let features = Features {
            linear: model.allowed.linear,
            // f_nl belongs to the frame that follows the body.
            nonlinear_forces: features.nonlinear_forces && !model.allowed.linear,
            ..features
        };
        let body = &model.body;
        let n = body.node_count();
        let mut state = DynamicState {
            time: self.start_time,
            position: vec![0.0; 3 * n],
            velocity: vec![0.0; 3 * n],
            acceleration: vec![0.0; 3 * n],
            pseudo_acceleration: vec![0.0; 3 * n],
            multipliers: vec![0.0; model.free.multiplier_count()],
            step_size: 0.0,
            iteration_error_ratio: f64::INFINITY,
        };
        body.place_rigidly(
            &placement.origin,
            &placement.rotation,
            &placement.anchor,
            &placement.velocity,
            &placement.angular_velocity,
            &mut state.position,
            &mut state.velocity,
        );
        self.check_motion_interfaces(&state, placement.first_motion)?;
        let model = self.model.as_ref().unwrap();
        for interface in &self.interfaces {
            if interface.kind == InterfaceKind::Fixed {
                for i in interface.set.held_indices() {
                    state.velocity[3 * i..3 * i + 3].fill(0.0);
                }
            }
        }
        prescribe_motion(
            &model.body,
            &self.interfaces,
            &self.driving,
            self.start_time,
            &mut state,
        );
        self.hold_point_constraints(&state, &placement)?;
        let model = self.model.as_mut().unwrap();
        model.place_linear_body(&state.position);
        model.apply_features(features);
        model.refresh_slab_stiffening(&state.position, 1.0);
        let body = &model.body;
        let gravity = Vector3::from(self.parameters.gravity);
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
        if let Some(explicit) = model.integrator.explicit() {
            // The explicit scheme's accelerations belong to the lumped mass.
            explicit.accelerations(body, &model.free, &loads, &mut state, &mut model.forces);
        }
        self.dynamics = Some(Dynamics {
            state,
            loads: self.inputs.clone(),
            gravity: self.parameters.gravity,
            features,
            quiet_since: [NOT_QUIET; 3],
            ladder: Ladder::default(),
            deformation_scale: 0.0,
            high_mode_scale: 0.0,
            estimate_floor: 0.0,
            slab_stiffening_ratio: 0.0,
            slab_stiffening_since: None,
            scale_settling: super::step_control::ScaleSettling::at(self.start_time),
        });
        if let Some(horizon) = self.error_horizon() {
            let over = match self.run_length() {
                Some(_) => format!("over the run, stopTime − startTime = {horizon:.4e} s"),
                None => format!(
                    "over one period of the lowest mode, T₁ = {horizon:.4e} s (the stop time is not defined: the errors of a longer run may add up to more)"
                ),
            };
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "model.accuracy = {:e}: the internal step is chosen from solver.stepSize / 2^k (k ≤ {}; ≤ {} until the deformation scale is established) so that the estimated errors that last {over} add up to at most model.accuracy × the deformation scale",
                    self.parameters.accuracy,
                    super::step_control::MAX_LEVEL,
                    super::step_control::EARLY_MAX_LEVEL
                ),
            });
        }
        self.outputs.invalidate();
        Ok(())
    }

    /// The positions of the body at its rigid placement ([`Self::rigid_placement`]); allocates.
    pub(super) fn rigid_placement_positions(&self) -> Result<Vec<f64>> {
        let placement = self.rigid_placement()?;
        let body = &self.model.as_ref().expect("a model").body;
        let n3 = 3 * body.node_count();
        let (mut x, mut v) = (vec![0.0; n3], vec![0.0; n3]);
        body.place_rigidly(
            &placement.origin,
            &placement.rotation,
            &placement.anchor,
            &Vector3::zeros(),
            &Vector3::zeros(),
            &mut x,
            &mut v,
        );
        Ok(x)
    }

    /// The rigid placement from the first motion interface's driving frame, or from the
    /// `initial.*` parameters; a body held by a fixed support must start at rest.
    fn rigid_placement(&self) -> Result<RigidPlacement> {
        let p = &self.parameters;
        let first_motion = self
            .interfaces
            .iter()
            .position(|i| i.kind == InterfaceKind::Motion);
        let placement = match first_motion {
            Some(k) => {
                let f = &self.driving[k];
                let name = &self.body_file.interfaces[k].name;
                RigidPlacement {
                    origin: f.position,
                    rotation: f.rotation,
                    anchor: self.interfaces[k].set.reference_point,
                    velocity: f.velocity,
                    angular_velocity: f.angular_velocity,
                    first_motion,
                    source: format!("the inputs of motion interface '{name}'"),
                }
            }
            None => RigidPlacement {
                origin: Vector3::from(p.initial_position),
                rotation: rotation_input("initial.rotation", "", &p.initial_rotation)?,
                anchor: Vector3::zeros(),
                velocity: Vector3::from(p.initial_velocity),
                angular_velocity: Vector3::from(p.initial_angular_velocity),
                first_motion,
                source: "initial.velocity and initial.angularVelocity".to_string(),
            },
        };
        let has_fixed = self
            .interfaces
            .iter()
            .any(|i| i.kind == InterfaceKind::Fixed);
        let (v0, w0) = (placement.velocity, placement.angular_velocity);
        if has_fixed && (v0.norm() > 0.0 || w0.norm() > 0.0) {
            return Err(Error::new(format!(
                "{} rejected: velocity {:?}, angular velocity {:?}, but a body held by a fixed support must start at rest",
                placement.source,
                v0.as_slice(),
                w0.as_slice()
            )));
        }
        Ok(placement)
    }

    /// Every motion interface but the first must hold in the rigid placement `state` (to 1e-6
    /// of the body's size).
    fn check_motion_interfaces(
        &self,
        state: &DynamicState,
        first_motion: Option<usize>,
    ) -> Result<()> {
        let body = &self.model.as_ref().unwrap().body;
        let tolerance = 1e-6 * self.size;
        for (k, interface) in self.interfaces.iter().enumerate() {
            if interface.kind != InterfaceKind::Motion || Some(k) == first_motion {
                continue;
            }
            let mut placed = state.clone();
            interface.set.prescribe(
                &body.reference,
                &self.driving[k],
                self.start_time,
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
        Ok(())
    }

    /// Pins and hinges hold their centroids where the body was placed; the placement's velocity
    /// must not move them.
    fn hold_point_constraints(
        &mut self,
        state: &DynamicState,
        placement: &RigidPlacement,
    ) -> Result<()> {
        let model = self.model.as_mut().unwrap();
        for lock in &mut model.free.rigid {
            lock.place(&state.position);
        }
        let (v0, w0) = (placement.velocity, placement.angular_velocity);
        for (k, interface) in self.interfaces.iter().enumerate() {
            let first = interface.first_constraint;
            for constraint in
                &mut model.free.constraints[first..first + interface.point_constraints.len()]
            {
                constraint.target = constraint.centroid(&state.position);
                let speed = constraint.centroid(&state.velocity).norm();
                if speed > 1e-9 * (1.0 + v0.norm() + w0.norm() * self.size) {
                    return Err(Error::new(format!(
                        "{} rejected: the initial velocity moves the {:?} support '{}' at {speed:.3e} m/s; the body may only turn about it",
                        placement.source,
                        interface.kind,
                        self.body_file.interfaces[k].name
                    )));
                }
            }
        }
        Ok(())
    }
}
