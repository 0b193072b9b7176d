//! Interfaces at run time: their node sets and point constraints, the driving frames of motion
//! interfaces, the loads of force interfaces, and the inputs as samples in time.

use super::{InputDerivatives, Inputs, Slave, INTERFACE_SLOTS};
use crate::body::frame::{angle_between, left_jacobian, nearest_rotation, node, rotation_vector};
use crate::body::interface::DrivingFrame;
use crate::body::{Body, NodeSet};
use crate::error::{Error, Result};
use crate::fem;
use crate::mesh::Mesh;
use crate::model::variables::InterfaceQuantity;
use crate::model::{BodyFile, InterfaceKind};
use crate::solver::problem::DynamicState;
use nalgebra::{Matrix3, Vector3};

/// An interface at run time: its kind and node set.
#[derive(Debug, Clone)]
pub(super) struct Interface {
    pub(super) kind: InterfaceKind,
    pub(super) set: NodeSet,
    /// Point constraints of a pin (one: the whole set) or a hinge (two: the halves of the set
    /// on either side of the plane through its centroid normal to the axis): node lists and
    /// weights.
    pub(super) point_constraints: Vec<(Vec<usize>, Vec<f64>)>,
    /// Index of the first of them in the solver's constraint list.
    pub(super) first_constraint: usize,
    /// A hinge on a rigid set (its own, or that of the interface with this index): one point
    /// constraint on the whole set's centroid and an axis lock on the rigid set
    /// (`RigidConstraint::axis_lock`) instead of the two half-centroids, which would hold the
    /// rigid distance between them twice.
    pub(super) locks: Option<usize>,
    /// The index of its axis lock in the solver's rigid constraints.
    pub(super) lock_constraint: usize,
}

/// The point constraints of a pin (the whole set) or a hinge (the two halves of the set on either
/// side of the plane through its centroid normal to `axis`; both halves' centroids must lie on
/// the axis, so that turning about it moves neither: a hole or a face with the axis through its
/// centre). Holding both half-centroids leaves exactly the rotation about the axis free.
pub(super) fn point_constraints(
    spec: &crate::model::InterfaceSpec,
    nodes: &[usize],
    weights: &[f64],
    reference: &[f64],
    size: f64,
) -> Result<Vec<(Vec<usize>, Vec<f64>)>> {
    let centroid = weighted_centroid(nodes, weights, reference);
    let tolerance = 1e-9 * size;
    if matches!(spec.kind, InterfaceKind::Pin | InterfaceKind::Hinge) {
        if let Some(p) = spec.reference_point {
            if (Vector3::from(p) - centroid).norm() > tolerance {
                return Err(Error::new(format!(
                    "interface '{}': a {:?} acts at the weighted centroid {:?} of its node set; referencePoint {:?} must be omitted or equal to it",
                    spec.name,
                    spec.kind,
                    centroid.as_slice(),
                    p
                )));
            }
        }
    }
    match spec.kind {
        InterfaceKind::Pin => Ok(vec![(nodes.to_vec(), weights.to_vec())]),
        InterfaceKind::Hinge => {
            let axis = spec.axis.map(Vector3::from).unwrap_or_default();
            if axis.norm().is_nan() || axis.norm() <= 0.0 {
                return Err(Error::new(format!(
                    "interface '{}': a hinge needs a nonzero \"axis\"",
                    spec.name
                )));
            }
            let axis = axis.normalize();
            let mut halves = [(Vec::new(), Vec::new()), (Vec::new(), Vec::new())];
            for (&i, &w) in nodes.iter().zip(weights) {
                let s = (node(reference, i) - centroid).dot(&axis);
                if s.abs() > tolerance {
                    let half = &mut halves[usize::from(s > 0.0)];
                    half.0.push(i);
                    half.1.push(w);
                }
            }
            for (nodes, weights) in &halves {
                if nodes.is_empty() {
                    return Err(Error::new(format!(
                        "interface '{}': the node set does not extend along the hinge axis {:?}",
                        spec.name,
                        axis.as_slice()
                    )));
                }
                let c = weighted_centroid(nodes, weights, reference);
                let off_axis = (c - centroid).cross(&axis).norm();
                if off_axis > 1e-6 * size {
                    return Err(Error::new(format!(
                        "interface '{}': the hinge axis {:?} through the centroid {:?} misses the centroid of one half of the node set by {off_axis:.3e} m; choose a set symmetric about the axis (a hole, or a face with the axis through its centre)",
                        spec.name,
                        axis.as_slice(),
                        centroid.as_slice()
                    )));
                }
            }
            Ok(halves.into_iter().collect())
        }
        _ => Ok(Vec::new()),
    }
}

/// `Σ w_i X_i / Σ w_i` over `nodes` at the reference positions `reference` (m).
fn weighted_centroid(nodes: &[usize], weights: &[f64], reference: &[f64]) -> Vector3<f64> {
    let total: f64 = weights.iter().sum();
    nodes
        .iter()
        .zip(weights)
        .fold(Vector3::zeros(), |c, (&i, w)| {
            c + *w / total * node(reference, i)
        })
}

/// How far from orthonormal a rotation given by the importer may be (`|QᵀQ − I|`, largest
/// entry): within it the nearest rotation is used, beyond it the value is an error. Rotations
/// typed with six digits, or integrated by a master over a long run, are a little off.
pub(super) const ROTATION_TOLERANCE: f64 = 1e-3;

/// The rotation `name` = `values` (row-major): the nearest rotation of a matrix within
/// [`ROTATION_TOLERANCE`] of orthonormal with a positive determinant, otherwise an error naming
/// the variable (`name`, followed by `suffix`) and the values. (The name comes in two parts so
/// that a motion interface's rotation, checked on every step, is named without allocating.)
pub(super) fn rotation_input(name: &str, suffix: &str, values: &[f64]) -> Result<Matrix3<f64>> {
    let q = Matrix3::from_row_slice(values);
    let deviation = (q.transpose() * q - Matrix3::identity()).amax();
    if deviation > ROTATION_TOLERANCE || q.determinant() <= 0.0 {
        return Err(Error::new(format!(
            "{name}{suffix} = {values:?} rejected: not a rotation matrix (|QᵀQ − I| = {deviation:.2e}, det = {:.6}); values within {ROTATION_TOLERANCE:e} of orthonormal are orthonormalised",
            q.determinant()
        )));
    }
    Ok(nearest_rotation(&q))
}

/// The driving frame of motion interface `name` from its inputs (the rotation through
/// [`rotation_input`]).
pub(super) fn driving_frame(name: &str, values: &Inputs) -> Result<DrivingFrame> {
    let slot = |q: InterfaceQuantity| q.slot() as usize;
    let vector = |q: InterfaceQuantity| Vector3::from_column_slice(&values[slot(q)..slot(q) + 3]);
    let r = slot(InterfaceQuantity::Rotation);
    Ok(DrivingFrame {
        position: vector(InterfaceQuantity::Position),
        rotation: rotation_input(name, ".rotation", &values[r..r + 9])?,
        velocity: vector(InterfaceQuantity::Velocity),
        angular_velocity: vector(InterfaceQuantity::AngularVelocity),
        ..DrivingFrame::default()
    })
}

/// Clamps the nodes of every motion interface to its driving frame at time `t`.
pub(super) fn prescribe_motion(
    body: &Body,
    interfaces: &[Interface],
    driving: &[DrivingFrame],
    t: f64,
    state: &mut DynamicState,
) {
    for (interface, frame) in interfaces.iter().zip(driving) {
        if interface.kind == InterfaceKind::Motion {
            interface.set.prescribe(
                &body.reference,
                frame,
                t,
                &mut state.position,
                &mut state.velocity,
                &mut state.acceleration,
            );
        }
    }
}

/// External loads at positions `x`: gravity `M (1 ⊗ g)` and each force interface's force and
/// torque distributed over its node set; added to `f`. With `extrapolation = (derivatives,
/// ages, τ)` the force inputs are taken `τ` seconds after the start of the step, which is
/// `ages[k]` after interface `k`'s inputs were sampled (see [`extrapolate`]).
pub(super) fn apply_loads(
    body: &Body,
    interfaces: &[Interface],
    inputs: &[Inputs],
    extrapolation: Option<(&[InputDerivatives], &[f64], f64)>,
    gravity: &Vector3<f64>,
    x: &[f64],
    f: &mut [f64],
) {
    if gravity.norm_squared() > 0.0 {
        body.add_uniform_acceleration_load(gravity, f);
    }
    // A linear body's loads act on its placement, as its elastic force does (docs/formulation.md,
    // "The linear body"): they do not follow the deformation.
    let x = body.linear.as_ref().map_or(x, |l| &l.positions[..]);
    for (k, (interface, input)) in interfaces.iter().zip(inputs).enumerate() {
        if interface.kind != InterfaceKind::Force {
            continue;
        }
        let mut load = [0.0; 6];
        load.copy_from_slice(&input[..6]);
        if let Some((derivatives, ages, tau)) = extrapolation {
            let d = &derivatives[k];
            let tau = ages[k] + tau;
            for (s, value) in load.iter_mut().enumerate() {
                if d[0][s] != 0.0 || d[1][s] != 0.0 {
                    *value += d[0][s] * tau + 0.5 * d[1][s] * tau * tau;
                }
            }
        }
        if load.iter().any(|&v| v != 0.0) {
            let force = Vector3::new(load[0], load[1], load[2]);
            let torque = Vector3::new(load[3], load[4], load[5]);
            interface.set.distribute(x, &force, &torque, f);
        }
    }
}

/// Whether the pose `new` given `since` seconds after the inputs `given` shows the velocities as
/// samples of a smooth motion: it lies nearer the path with the mean rates of the velocities
/// between the two (`new`'s accelerations; the velocities' mean, `p + (v + v_new) Δt / 2`) than the
/// path held at `given`'s velocities, `p + v Δt`, which a master that gives secant velocities
/// (`(p_{k+1} − p_k) / Δt`, docs/coupling.md) hits exactly. Distances add the origin's and
/// `size` times the turn between the rotations.
fn follows_rates(given: &DrivingFrame, new: &DrivingFrame, since: f64, size: f64) -> bool {
    let from = DrivingFrame {
        rate_span: 0.0,
        ..*given
    };
    let t = given.changed_at + since;
    let held = from.at(t);
    let smooth = DrivingFrame {
        acceleration: new.acceleration,
        angular_acceleration: new.angular_acceleration,
        rate_span: since,
        ..from
    }
    .at(t);
    let distance = |(p, q): &(Vector3<f64>, Matrix3<f64>)| {
        (new.position - p).norm() + size * angle_between(q, &new.rotation)
    };
    distance(&smooth) < distance(&held)
}

/// The offset `[δp, δθ, δv, δω]` of the pose and velocities of `path` from `sample`'s
/// (`DrivingFrame`): the rotation as the rotation vector of `Q_path Q_sampleᵀ`, and `δω` such
/// that `J_l(δθ) δω + exp([δθ]×) ω_sample = ω_path`, the angular velocity of
/// `exp([δθ]×) Q_sample` turning with both.
fn offset_from(path: &DrivingFrame, sample: &DrivingFrame) -> [Vector3<f64>; 4] {
    let turn = path.rotation * sample.rotation.transpose();
    let theta = rotation_vector(&turn);
    let rest = path.angular_velocity - turn * sample.angular_velocity;
    let omega = left_jacobian(&theta)
        .try_inverse()
        .map_or(rest, |inverse| inverse * rest);
    [
        path.position - sample.position,
        theta,
        path.velocity - sample.velocity,
        omega,
    ]
}

/// Whether two driving frames differ beyond round-off (`1e-12` of the quantity, plus `1e-12`
/// absolute).
fn frames_differ(a: &DrivingFrame, b: &DrivingFrame) -> bool {
    let far = |x: f64, y: f64| (x - y).abs() > 1e-12 * (1.0 + x.abs().max(y.abs()));
    let pairs = a
        .position
        .iter()
        .zip(b.position.iter())
        .chain(a.rotation.iter().zip(b.rotation.iter()))
        .chain(a.velocity.iter().zip(b.velocity.iter()))
        .chain(a.angular_velocity.iter().zip(b.angular_velocity.iter()));
    pairs.into_iter().any(|(&x, &y)| far(x, y))
}

/// A force interface's inputs `τ` seconds after their sample time: `u + u'·τ + u''·τ²/2`
/// in the force and torque slots (the only ones with derivatives); the same arithmetic as
/// [`apply_loads`], so the end-of-step loads match those the last internal step used.
pub(super) fn extrapolate(input: &mut Inputs, d: &InputDerivatives, tau: f64) {
    for s in 0..6 {
        if d[0][s] != 0.0 || d[1][s] != 0.0 {
            input[s] += d[0][s] * tau + 0.5 * d[1][s] * tau * tau;
        }
    }
}

impl Slave {
    /// The Lagrange multipliers of the interfaces on the mesh body: 3 per point constraint of a
    /// pin or hinge, `3n − 6` per rigid set of `n` nodes (`FreeNodes::multiplier_count` of a mesh
    /// body; a reduced body's rigid sets have 3 or 4 points, and fewer rows).
    pub(super) fn multiplier_count(&self) -> usize {
        self.interfaces
            .iter()
            .zip(&self.body_file.interfaces)
            .map(|(i, spec)| {
                let rigid =
                    spec.rigid && !matches!(i.kind, InterfaceKind::Fixed | InterfaceKind::Motion);
                3 * i.point_constraints.len()
                    + if rigid {
                        3 * i.set.frame_weights.nodes.len() - 6
                    } else {
                        0
                    }
                    + if i.locks.is_some() { 2 } else { 0 }
            })
            .sum()
    }

    /// The inputs' ages at the current time `t_0` (`t_0 − t_s` per interface) and the driving
    /// frames of the motion interfaces there: the frame of the inputs, extrapolated from their
    /// sample time `t_s` to `t_0` (no allocation unless an input is rejected).
    ///
    /// Returns whether an input jumps at `t_0`, and whether a motion interface's does: a motion
    /// interface's frame (pose or velocities) differs from the previous step's frame carried on
    /// to `t_0`, or a force interface set at `t_0` differs from the loads the state's
    /// accelerations belong to. The step after a jump starts from a kink of the driving motion
    /// or the load, which no internal step can resolve (the error control does not estimate its
    /// error, nor that of the next internal steps after a motion input's jump:
    /// `slave::step_control::MOTION_RINGING_STEPS`).
    pub(super) fn update_driving_frames(&mut self) -> Result<(bool, bool)> {
        let t = self.time();
        let mut jumped = false;
        let mut motion_jumped = false;
        let last = self.last_step_size;
        for (k, interface) in self.interfaces.iter().enumerate() {
            let age = t - self.input_times[k];
            self.input_ages[k] = age;
            match interface.kind {
                InterfaceKind::Motion => {
                    if age != 0.0 && last > 0.0 {
                        // Not set since the last step began: the motion carries on.
                        continue;
                    }
                    let old = self.driving[k];
                    let mut frame =
                        driving_frame(&self.body_file.interfaces[k].name, &self.inputs[k])?;
                    if age != 0.0 {
                        // Given before initialization at an earlier time: held from there.
                        (frame.position, frame.rotation) = frame.at(age);
                    }
                    (frame.changed_at, frame.updated_at) = (t, t);
                    if last > 0.0 {
                        if !frames_differ(&old.advanced_to(t), &frame) {
                            // Given again where the motion had carried on to.
                            self.driving[k].updated_at = t;
                            continue;
                        }
                        let followed = old.rate_span > 0.0;
                        // The velocities' mean rates since they were last given
                        // (`DrivingFrame`); followed when they are samples of a smooth motion:
                        // they changed at the update before too (not a step of the velocity
                        // after a calm stretch) or the frame followed its rates already, and the
                        // pose says so ([`follows_rates`]).
                        let since = t - old.changed_at;
                        if since > 0.0 {
                            frame.acceleration = (frame.velocity - old.velocity) / since;
                            frame.angular_acceleration =
                                (frame.angular_velocity - old.angular_velocity) / since;
                            let calm = old.rate_span == 0.0 && old.updated_at > old.changed_at;
                            if !calm && follows_rates(&old, &frame, since, self.size) {
                                frame.rate_span = since;
                            }
                        }
                        // A sampled smooth motion that goes on along its rates (followed up to
                        // this update and from it) bends the held path by the rates' change,
                        // `O(H²)` in the velocity and `O(H³)` in the pose: no jump, its steps
                        // are estimated like any other (docs/fmu.md, "Inputs are samples in
                        // time").
                        if followed && frame.rate_span > 0.0 {
                            // It starts where the path it followed stands, and sheds the
                            // difference by the next sample (`DrivingFrame`: the bend carried
                            // off).
                            frame.offset = offset_from(&old.advanced_to(t), &frame);
                            frame.sheds = true;
                        } else {
                            jumped = true;
                            motion_jumped = true;
                        }
                    }
                    self.driving[k] = frame;
                }
                InterfaceKind::Force if age == 0.0 => {
                    if let Some(d) = &self.dynamics {
                        jumped |= self.inputs[k][..6] != d.loads[k][..6];
                    }
                }
                _ => {}
            }
        }
        Ok((jumped, motion_jumped))
    }

    /// The driving frame of the motion interface as it stands at the start of the current step,
    /// with the mean rates of its velocities between their last two changes (`None` without
    /// one; a body whose stiffening takes it has exactly one). Part of the FMU state.
    pub(super) fn motion_frame(&self) -> Option<DrivingFrame> {
        let k = self
            .interfaces
            .iter()
            .position(|i| i.kind == InterfaceKind::Motion)?;
        Some(self.driving[k].advanced_to(self.time()))
    }

    /// Makes the current time the sample time of interface `k`'s inputs, before one of them (or
    /// a derivative) is set. Inputs set at time `t_s` describe the interface at `t_s`; those
    /// not set again continue along their extrapolation, so they are moved to the current time
    /// `t` (`τ = t − t_s`): a motion interface's pose and velocities where its driving frame
    /// stands at `t` ([`DrivingFrame::advanced_to`]: the inputs it was made from, or matched,
    /// carried on with constant velocities or with its rates), a force interface's force and
    /// torque with their derivatives (`u + u'τ + u''τ²/2`, `u' + u''τ`). Before initialization
    /// the inputs describe the start time. Allocation-free.
    pub(super) fn resample_inputs(&mut self, k: usize) {
        let t = self.time();
        let tau = t - self.input_times[k];
        self.input_times[k] = t;
        if self.dynamics.is_none() || tau == 0.0 {
            return;
        }
        let input = &mut self.inputs[k];
        match self.interfaces[k].kind {
            InterfaceKind::Motion => {
                // The inputs carry on as the driving frame made from them does (with its rates).
                let frame = self.driving[k].advanced_to(t);
                let slot = |q: InterfaceQuantity| q.slot() as usize;
                for (quantity, value) in [
                    (InterfaceQuantity::Position, frame.position),
                    (InterfaceQuantity::Velocity, frame.velocity),
                    (InterfaceQuantity::AngularVelocity, frame.angular_velocity),
                ] {
                    input[slot(quantity)..slot(quantity) + 3].copy_from_slice(value.as_slice());
                }
                let r = slot(InterfaceQuantity::Rotation);
                for (j, value) in input[r..r + 9].iter_mut().enumerate() {
                    *value = frame.rotation[(j / 3, j % 3)];
                }
            }
            InterfaceKind::Force => {
                let d = &mut self.input_derivatives[k];
                extrapolate(input, d, tau);
                let [first, second] = d;
                for (rate, change) in first[..6].iter_mut().zip(&second[..6]) {
                    *rate += change * tau;
                }
            }
            InterfaceKind::Fixed | InterfaceKind::Pin | InterfaceKind::Hinge => {}
        }
    }
}

/// The interfaces of `body_file` on `mesh` (node sets weighted by the lumped masses of a unit
/// density, point constraints of pins and hinges), and which nodes fixed supports and motion
/// interfaces hold. `size` is the body's characteristic size (m).
pub(super) fn interfaces_of(
    body_file: &BodyFile,
    mesh: &Mesh,
    size: f64,
) -> Result<(Vec<Interface>, Vec<bool>, Vec<MassPoint>)> {
    let mut reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
    let lumped = fem::lumped_masses(mesh, 1.0);
    let mut interfaces = Vec::new();
    let mut clamped = vec![false; mesh.node_count()];
    let mut mass_points = Vec::new();
    let mut whole_sets = Vec::new();
    for spec in &body_file.interfaces {
        let mut nodes = spec
            .nodes
            .select(mesh)
            .map_err(|e| Error::new(format!("interface '{}': {}", spec.name, e.message)))?;
        let mut weights: Vec<f64> = nodes.iter().map(|&i| lumped[i]).collect();
        let point_constraints = point_constraints(spec, &nodes, &weights, &reference, size)?;
        whole_sets.push((nodes.clone(), weights.clone()));
        // The reference point defaults to the weighted centroid of the mesh nodes (before a
        // lumped body's mass points join the set).
        let reference_point = spec.reference_point.map_or_else(
            || weighted_centroid(&nodes, &weights, &reference),
            Vector3::from,
        );
        // A lumped body joins the set as six mass points (docs/formulation.md, "Rigid
        // attachments"), weighted like an average node of the set.
        for (position, mass) in lumped_body_points(spec, reference_point)? {
            let index = reference.len() / 3;
            reference.extend_from_slice(position.as_slice());
            weights.push(weights.iter().sum::<f64>() / weights.len() as f64);
            nodes.push(index);
            clamped.push(false);
            mass_points.push(MassPoint { position, mass });
        }
        if matches!(spec.kind, InterfaceKind::Fixed | InterfaceKind::Motion) {
            for &i in &nodes {
                clamped[i] = true;
            }
        }
        let set = NodeSet::new(
            &spec.name,
            nodes,
            weights,
            &reference,
            Some(reference_point),
        )?;
        interfaces.push(Interface {
            kind: spec.kind,
            set,
            point_constraints,
            first_constraint: 0,
            locks: None,
            lock_constraint: 0,
        });
    }
    // A hinge on a rigid set: the whole set's centroid and an axis lock.
    let rigid_sets: Vec<Option<&[usize]>> = interfaces
        .iter()
        .zip(&body_file.interfaces)
        .map(|(i, spec)| {
            (spec.rigid
                && matches!(
                    i.kind,
                    InterfaceKind::Force | InterfaceKind::Pin | InterfaceKind::Hinge
                ))
            .then_some(&i.set.frame_weights.nodes[..])
        })
        .collect();
    let locks: Vec<Option<usize>> = interfaces
        .iter()
        .map(|hinge| {
            (hinge.kind == InterfaceKind::Hinge)
                .then(|| {
                    rigid_sets.iter().position(|set| {
                        set.is_some_and(|set| {
                            hinge
                                .set
                                .frame_weights
                                .nodes
                                .iter()
                                .any(|n| set.contains(n))
                        })
                    })
                })
                .flatten()
        })
        .collect();
    for ((interface, lock), whole) in interfaces.iter_mut().zip(locks).zip(whole_sets) {
        if lock.is_some() {
            interface.point_constraints = vec![whole];
            interface.locks = lock;
        }
    }
    if clamped.iter().all(|&c| c) {
        return Err(Error::new(
            "body file: fixed supports hold every node: nothing can move",
        ));
    }
    Ok((interfaces, clamped, mass_points))
}

/// A point mass of a lumped body (docs/formulation.md, "Rigid attachments"): an extra node of
/// the body after the mesh's, without stiffness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct MassPoint {
    /// Reference position (m).
    pub(super) position: Vector3<f64>,
    /// Mass (kg).
    pub(super) mass: f64,
}

/// The mass points of `spec`'s lumped body (none without `mass`), its inertia about the
/// interface's `reference_point` (without `inertia`: a point mass, `I_c = 0`). Error if the
/// interface cannot carry one: a lumped body needs a rigid set (`"rigid": true`, or a fixed
/// support or motion interface, which are rigid anyway).
fn lumped_body_points(
    spec: &crate::model::InterfaceSpec,
    point: Vector3<f64>,
) -> Result<Vec<(Vector3<f64>, f64)>> {
    let Some(mass) = spec.mass else {
        if spec.inertia.is_some() || spec.center_of_mass.is_some() {
            return Err(Error::new(format!(
                "interface '{}': inertia and centerOfMass describe a lumped body and need its \"mass\"",
                spec.name
            )));
        }
        return Ok(Vec::new());
    };
    let rigid = spec.rigid || matches!(spec.kind, InterfaceKind::Fixed | InterfaceKind::Motion);
    if !rigid {
        return Err(Error::new(format!(
            "interface '{}': a lumped body (mass {mass} kg) needs a rigid set to ride on: add \"rigid\": true",
            spec.name
        )));
    }
    let center_of_mass = spec.center_of_mass.map_or(point, Vector3::from);
    let d = center_of_mass - point;
    let body = crate::body::LumpedBody {
        mass,
        center_of_mass,
        inertia: spec.inertia.map_or(
            mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose()),
            |rows| Matrix3::from_fn(|i, j| rows[i][j]),
        ),
        point,
    };
    body.mass_points(&spec.name)
}

/// The inputs of a fresh instance: motion interfaces at their place in the body file, at rest;
/// no loads.
pub(super) fn default_inputs(interfaces: &[Interface]) -> Vec<Inputs> {
    interfaces
        .iter()
        .map(|i| {
            let mut values = [0.0; INTERFACE_SLOTS];
            if i.kind == InterfaceKind::Motion {
                let p = InterfaceQuantity::Position.slot() as usize;
                values[p..p + 3].copy_from_slice(i.set.reference_point.as_slice());
                let r = InterfaceQuantity::Rotation.slot() as usize;
                values[r..r + 9].copy_from_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
            }
            values
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The offset a followed update takes puts the frame where the path it followed stands, in
    /// pose and velocities, for turns about different axes (the path's `ω`, `α` and the
    /// sample's off `δθ`'s axis).
    #[test]
    fn a_followed_update_starts_where_the_path_stands() {
        let path = DrivingFrame {
            position: Vector3::new(0.1, -0.2, 0.3),
            rotation: *nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.2, 0.5, -0.1)).matrix(),
            velocity: Vector3::new(1.0, 0.5, -0.3),
            angular_velocity: Vector3::new(0.4, 1.5, -0.7),
            acceleration: Vector3::new(2.0, -1.0, 0.5),
            angular_acceleration: Vector3::new(-3.0, 1.0, 2.0),
            changed_at: 1.0,
            rate_span: 0.01,
            updated_at: 1.0,
            ..DrivingFrame::default()
        };
        let t = 1.01;
        let carried = path.advanced_to(t);
        let turn = nalgebra::Rotation3::from_scaled_axis(Vector3::new(3e-3, -2e-3, 1e-3));
        let sample = DrivingFrame {
            position: carried.position + Vector3::new(1e-4, -2e-4, 3e-4),
            rotation: turn.matrix() * carried.rotation,
            velocity: carried.velocity + Vector3::new(-2e-2, 1e-2, 3e-2),
            angular_velocity: carried.angular_velocity + Vector3::new(0.05, -0.03, 0.02),
            changed_at: t,
            updated_at: t,
            ..path
        };
        let shed = DrivingFrame {
            offset: offset_from(&carried, &sample),
            sheds: true,
            ..sample
        };
        let ((p, q), (v, w)) = (shed.at(t), shed.velocities_at(t));
        assert!((p - carried.position).amax() < 1e-15);
        assert!((q - carried.rotation).amax() < 1e-15);
        assert!((v - carried.velocity).amax() < 1e-15);
        assert!(
            (w - carried.angular_velocity).amax() < 1e-14,
            "{w} {}",
            carried.angular_velocity
        );
    }
}
