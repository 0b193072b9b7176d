//! Node sets of supports and interfaces (docs/fmu.md): an RBE3-like distribution of a
//! force and torque over the nodes, the weighted least-squares rigid motion of the nodes that is
//! power-conjugate to it, and the resultant of nodal loads about the reference point.

use super::frame::{add_node, left_jacobian, node, set_node, Frame, FrameWeights};
use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};
use std::cell::RefCell;

/// A coordinate held by a boundary set: driven by the frame `(p, Q)` it is `p + Q d` (`point`)
/// or `Q d` (a direction), `d` = `offset`; `p` is the set's reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeldCoordinate {
    pub index: usize,
    pub offset: Vector3<f64>,
    pub point: bool,
}

/// The basis of a reduced body as a node set needs it: `S` (row-major `N × s`, node `i`'s row
/// is `fields[i s .. (i+1) s]`) and the reference positions of the mesh nodes (flat `3N`, m).
#[derive(Debug, Clone, Copy)]
pub struct FieldBasis<'a> {
    pub fields: &'a [f64],
    pub field_count: usize,
    pub mesh_reference: &'a [f64],
}

impl FieldBasis<'_> {
    fn row(&self, i: usize) -> &[f64] {
        &self.fields[i * self.field_count..(i + 1) * self.field_count]
    }
}

/// A node set with positive weights `w_i` and a reference point.
///
/// With `r_i = x_i − c` (c: weighted centroid), `W = Σ w_i` and the weighted polar inertia
/// `J = Σ w_i (|r_i|² I − r_i r_iᵀ)`:
/// * a force `F` and torque `T` about the reference point `p` load node `i` with
///   `f_i = w_i (F / W + θ × r_i)`, `θ = J⁻¹ (T + (p − c) × F)`, so `Σ f_i = F` and
///   `Σ (x_i − p) × f_i = T`;
/// * the motion reported is `ω = J⁻¹ Σ w_i r_i × ẋ_i`, `v_p = Σ w_i ẋ_i / W + ω × (p − c)`, so
///   that `Σ f_i · ẋ_i = F · v_p + T · ω`: coupling through the interface is power-neutral.
#[derive(Debug, Clone)]
pub struct NodeSet {
    pub frame_weights: FrameWeights,
    /// Reference point in reference coordinates (m).
    pub reference_point: Vector3<f64>,
    /// On a reduced body ([`FieldBasis`]): how the set's nodes follow the body's coordinates.
    /// The vectors the methods take are then the reduced body's (flat `3s`).
    pub expansion: Option<Box<SetExpansion>>,
}

/// A node set of a reduced body: its nodes' rows of the basis `S`, so that
/// `x_i = Σ_k S_ik q_k` on the set and a nodal load `f_i` is the generalized load
/// `Σ_i S_ik f_i` (the virtual work of the load is the same in both: the coupling stays
/// power-neutral).
#[derive(Debug, Clone)]
pub struct SetExpansion {
    /// Rows `S_i·` of the set's nodes in set order (row-major `n_set × s`).
    rows: Vec<f64>,
    fields: usize,
    /// The set with its nodes numbered `0..n_set` in set order.
    local: NodeSet,
    /// The coordinates the set holds (fixed support, motion interface); empty otherwise.
    pub held: Vec<HeldCoordinate>,
    /// `Σ_i (w_i / W) S_ik`: the generalized load of a force alone when the reference point is
    /// the centroid (to round-off; then `f_i = w_i F / W` does not depend on the positions).
    force_weights: Option<Vec<f64>>,
    /// Expanded positions, velocities, accelerations and loads of the set (4 × `3 n_set`).
    scratch: RefCell<Vec<f64>>,
}

/// Rigid motion of a node set at its reference point (global frame, SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterfaceMotion {
    pub position: Vector3<f64>,
    pub rotation: Matrix3<f64>,
    pub velocity: Vector3<f64>,
    pub angular_velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
    pub angular_acceleration: Vector3<f64>,
}

impl NodeSet {
    /// A node set `nodes` weighted by `weights` (> 0); `reference_point` defaults to the weighted
    /// centroid. Error if the set cannot carry a torque (fewer than three non-collinear nodes).
    pub fn new(
        name: &str,
        nodes: Vec<usize>,
        weights: Vec<f64>,
        reference: &[f64],
        reference_point: Option<Vector3<f64>>,
    ) -> Result<NodeSet> {
        if nodes.is_empty() {
            return Err(Error::new(format!(
                "interface '{name}': its node set is empty"
            )));
        }
        let frame_weights = FrameWeights::new(nodes, weights, reference);
        let j = polar_inertia(&frame_weights, reference, &frame_weights.reference_centroid);
        let eig = j.symmetric_eigenvalues();
        if eig.min() <= 1e-9 * eig.max() {
            return Err(Error::new(format!(
                "interface '{name}': its {} nodes are collinear, so the set cannot carry a torque",
                frame_weights.nodes.len()
            )));
        }
        let reference_point = reference_point.unwrap_or(frame_weights.reference_centroid);
        Ok(NodeSet {
            frame_weights,
            reference_point,
            expansion: None,
        })
    }

    /// Puts the set on the reduced body of basis `reduction`, holding `held` (empty for a loaded set);
    /// `None` puts it back on the mesh nodes.
    pub fn set_reduction(&mut self, reduction: Option<(FieldBasis, Vec<HeldCoordinate>)>) {
        let Some((reduction, held)) = reduction else {
            self.expansion = None;
            return;
        };
        let fw = &self.frame_weights;
        let s = reduction.field_count;
        let n_set = fw.nodes.len();
        let mut rows = Vec::with_capacity(n_set * s);
        let mut local_reference = Vec::with_capacity(3 * n_set);
        for &i in &fw.nodes {
            rows.extend_from_slice(reduction.row(i));
            local_reference.extend_from_slice(&reduction.mesh_reference[3 * i..3 * i + 3]);
        }
        let local = NodeSet {
            frame_weights: FrameWeights::new(
                (0..n_set).collect(),
                fw.weights.clone(),
                &local_reference,
            ),
            reference_point: self.reference_point,
            expansion: None,
        };
        // The reference point at the centroid up to round-off (1e-12 of the set's extent: a
        // body file's point on the tip face's centre against the computed centroid) changes
        // the torque of a force by at most 1e-12 of force × extent.
        let extent = fw
            .nodes
            .iter()
            .map(|&i| (node(reduction.mesh_reference, i) - fw.reference_centroid).norm())
            .fold(0.0, f64::max);
        let centred = (self.reference_point - fw.reference_centroid).norm() <= 1e-12 * extent;
        let force_weights = centred.then(|| {
            let mut w = vec![0.0; s];
            for (j, &wj) in fw.weights.iter().enumerate() {
                for k in 0..s {
                    w[k] += wj / fw.total_weight * rows[j * s + k];
                }
            }
            w
        });
        self.expansion = Some(Box::new(SetExpansion {
            rows,
            fields: s,
            local,
            held,
            force_weights,
            scratch: RefCell::new(vec![0.0; 12 * n_set]),
        }));
    }

    /// The nodes (or, on a reduced body, the coordinates) the set holds when it is a fixed
    /// support or a motion interface.
    pub fn held_indices(&self) -> Vec<usize> {
        match &self.expansion {
            Some(e) => e.held.iter().map(|h| h.index).collect(),
            None => self.frame_weights.nodes.clone(),
        }
    }

    /// Current position of the reference point: `c + R (p_ref − X_c)` with the best-fit frame.
    fn reference_point_at(&self, frame: &Frame) -> Vector3<f64> {
        frame.origin
            + frame.rotation * (self.reference_point - self.frame_weights.reference_centroid)
    }

    /// Adds the nodal loads of force `force` and torque `torque` about the reference point
    /// (N, N·m, global frame) at positions `x` to `f` (flat `3N`).
    pub fn distribute(
        &self,
        x: &[f64],
        force: &Vector3<f64>,
        torque: &Vector3<f64>,
        f: &mut [f64],
    ) {
        if let Some(e) = &self.expansion {
            return e.distribute(x, force, torque, f);
        }
        let fw = &self.frame_weights;
        let frame = fw.best_fit(x);
        let p = self.reference_point_at(&frame);
        let torque_c = torque + (p - frame.origin).cross(force);
        let j = polar_inertia(fw, x, &frame.origin);
        let theta = j.try_inverse().unwrap_or_else(Matrix3::zeros) * torque_c;
        let per_weight = force / fw.total_weight;
        for (&n, &w) in fw.nodes.iter().zip(&fw.weights) {
            let r = node(x, n) - frame.origin;
            add_node(f, n, &(w * (per_weight + theta.cross(&r))));
        }
    }

    /// Resultant force and torque about the current reference point of the nodal loads `f`
    /// restricted to the set.
    pub fn resultant(&self, x: &[f64], f: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        if let Some(e) = &self.expansion {
            return e.resultant(x, f);
        }
        let fw = &self.frame_weights;
        let frame = fw.best_fit(x);
        let p = self.reference_point_at(&frame);
        let mut force = Vector3::zeros();
        let mut torque = Vector3::zeros();
        for &n in &fw.nodes {
            let fi = node(f, n);
            force += fi;
            torque += (node(x, n) - p).cross(&fi);
        }
        (force, torque)
    }

    /// The weighted least-squares rigid motion of the set at positions `x`, velocities `v` and
    /// accelerations `a`; the angular acceleration is that of the least-squares rigid acceleration
    /// field `a_i ≈ a_c + α × r_i + ω × (ω × r_i)`.
    pub fn motion(&self, x: &[f64], v: &[f64], a: &[f64]) -> InterfaceMotion {
        if let Some(e) = &self.expansion {
            return e.motion(x, v, a);
        }
        let fw = &self.frame_weights;
        let frame = fw.best_fit(x);
        let p = self.reference_point_at(&frame);
        let d = p - frame.origin;
        let j_inv = polar_inertia(fw, x, &frame.origin)
            .try_inverse()
            .unwrap_or_else(Matrix3::zeros);
        let vc = fw.centroid(v);
        let ac = fw.centroid(a);
        let mut b = Vector3::zeros();
        for (&n, &w) in fw.nodes.iter().zip(&fw.weights) {
            b += w * (node(x, n) - frame.origin).cross(&node(v, n));
        }
        let omega = j_inv * b;
        let mut b = Vector3::zeros();
        for (&n, &w) in fw.nodes.iter().zip(&fw.weights) {
            let r = node(x, n) - frame.origin;
            let centripetal = omega.cross(&omega.cross(&r));
            b += w * r.cross(&(node(a, n) - ac - centripetal));
        }
        let alpha = j_inv * b;
        InterfaceMotion {
            position: p,
            rotation: frame.rotation,
            velocity: vc + omega.cross(&d),
            angular_velocity: omega,
            acceleration: ac + alpha.cross(&d) + omega.cross(&omega.cross(&d)),
            angular_acceleration: alpha,
        }
    }
}

/// The driving frame of a motion interface, as its inputs gave it at `changed_at` (s), the last
/// time they changed the motion: origin `p`, rotation `Q`, velocity `v` and angular velocity `ω`
/// (global), and `updated_at` (s), the last time they were given (changed or not).
///
/// `acceleration` and `angular_acceleration` are the mean rates of the velocities between their
/// last two changes, `(v_k − v_{k−1}) / Δt` (m/s², rad/s²; zero before the second): the driving
/// motion's accelerations as a reduced body's stiffening takes them.
///
/// At `t`, `τ = t − changed_at` after it was given, the frame is `p + v τ`, `exp([ω τ]×) Q`
/// with constant velocities, unless its velocities are samples of a smooth motion (they changed
/// at the update before too, or the frame already followed its rates, and the pose given lies on
/// the path of their mean: `rate_span = Δt > 0`, docs/fmu.md, "Inputs are samples in time"). It
/// then follows those rates too (`a`, `α`): `p + v τ + a τ²/2`, `exp([φ]×) Q` with
/// `φ = ω τ + α τ²/2`, velocity `v + a τ` and angular velocity `J_l(φ) φ̇`, the path's own
/// (`J_l` the left Jacobian of the rotation vector; `ω + α τ` when `α ∥ ω`). Every time is
/// measured from the inputs as given, so a frame carried over several steps is the frame of one.
///
/// A followed sample does not lie exactly on the path the frame was following: the rates'
/// change bends it by `O(Δt³)` in the pose and `O(Δt²)` in the velocities. The held nodes would
/// jump by that bend at the update, and a jump `δ` of a held position is an acceleration
/// `δ/(β h²)` over the next internal step `h`, ringing in the scheme's update formulas: on B3 at
/// `h = Δt/128`, 1 500 times the hub's own acceleration (docs/fmu.md, "Inputs are samples in
/// time": the bend carried off). So the frame starts where the path it followed stood, `offset`
/// (`δp`, `δθ`, `δv`, `δω`: that path's pose and velocities at `changed_at` less the sample's,
/// the rotation as the vector of `Q_path Qᵀ`), and sheds it by `changed_at + rate_span` along the
/// cubic `c(τ) = δ h₀₀(u) + δ̇ Δt h₁₀(u)`, `u = τ/Δt`, `h₀₀ = 2u³ − 3u² + 1`,
/// `h₁₀ = u³ − 2u² + u` (continuous in pose and velocity at both ends): the pose `p + c_p`,
/// `exp([c_θ]×) Q`, the velocities `v + ċ_p`, `J_l(c_θ) ċ_θ + exp([c_θ]×) ω` and the
/// accelerations `a + c̈_p` and the rotation's ([`DrivingFrame::accelerations_at`]); `δω` is
/// taken so that the angular velocity at the update is the path's,
/// `J_l(δθ) δω + exp([δθ]×) ω_s = ω_path`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrivingFrame {
    pub position: Vector3<f64>,
    pub rotation: Matrix3<f64>,
    pub velocity: Vector3<f64>,
    pub angular_velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
    pub angular_acceleration: Vector3<f64>,
    pub changed_at: f64,
    /// The time between the two changes the rates come from when the frame follows them (s);
    /// zero when it keeps constant velocities.
    pub rate_span: f64,
    pub updated_at: f64,
    /// The pose and velocities the frame starts with beyond the sample's and sheds over
    /// `rate_span`: `[δp, δθ, δv, δω]` (m, rad, m/s, rad/s; zero unless it sheds).
    pub offset: [Vector3<f64>; 4],
    /// Whether the frame was given at an update it followed through, so that it sheds its
    /// offset over `rate_span` (even an offset that is zero: a change given at the update is
    /// carried in the same way, which the step Jacobian takes).
    pub sheds: bool,
}

impl Default for DrivingFrame {
    fn default() -> Self {
        DrivingFrame {
            position: Vector3::zeros(),
            rotation: Matrix3::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
            changed_at: 0.0,
            rate_span: 0.0,
            updated_at: 0.0,
            offset: [Vector3::zeros(); 4],
            sheds: false,
        }
    }
}

impl DrivingFrame {
    /// The rates the frame follows: `(a, α)` when its velocities are samples of a smooth motion
    /// (`rate_span > 0`), zero otherwise.
    pub fn extrapolation_rates(&self) -> (Vector3<f64>, Vector3<f64>) {
        if self.rate_span > 0.0 {
            (self.acceleration, self.angular_acceleration)
        } else {
            (Vector3::zeros(), Vector3::zeros())
        }
    }

    /// The rotation vector of the turn from `changed_at` to `t`: `φ = ω τ + α τ²/2`.
    pub fn turn(&self, t: f64) -> Vector3<f64> {
        let tau = t - self.changed_at;
        let (_, alpha) = self.extrapolation_rates();
        self.angular_velocity * tau + alpha * (0.5 * tau * tau)
    }

    /// Origin and rotation at `t`, with what is left of the offset.
    pub fn at(&self, t: f64) -> (Vector3<f64>, Matrix3<f64>) {
        let tau = t - self.changed_at;
        let (a, _) = self.extrapolation_rates();
        let turn = nalgebra::Rotation3::from_scaled_axis(self.turn(t));
        let [(c_p, _, _), (c_theta, _, _)] = self.shed_offset(t);
        (
            self.position + self.velocity * tau + a * (0.5 * tau * tau) + c_p,
            rotation_of(&c_theta) * turn.matrix() * self.rotation,
        )
    }

    /// Velocity and angular velocity at `t`: `v + a τ` and `J_l(φ) (ω + α τ)`, with what is left
    /// of the offset.
    pub fn velocities_at(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let tau = t - self.changed_at;
        let (a, alpha) = self.extrapolation_rates();
        let angular = if self.rate_span > 0.0 {
            left_jacobian(&self.turn(t)) * (self.angular_velocity + alpha * tau)
        } else {
            self.angular_velocity
        };
        let [(_, dc_p, _), (c, dc, _)] = self.shed_offset(t);
        (
            self.velocity + a * tau + dc_p,
            left_jacobian(&c) * dc + rotation_of(&c) * angular,
        )
    }

    /// Acceleration and angular acceleration of the path at `t`: the rates the frame follows
    /// and the offset's. Of the rotation `exp([c]×) R_s`, whose angular velocity is
    /// `w = J_l(c) ċ + exp([c]×) ω_s`: `J_l(c) c̈ + (J_l(c) ċ) × exp([c]×) ω_s + exp([c]×) α`
    /// (without `J̇_l ċ`, second order in the offset).
    pub fn accelerations_at(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (a, alpha) = self.extrapolation_rates();
        let [(_, _, ddc_p), (c, dc, ddc)] = self.shed_offset(t);
        if c == Vector3::zeros() && dc == Vector3::zeros() && ddc == Vector3::zeros() {
            return (a + ddc_p, alpha);
        }
        let omega = DrivingFrame {
            sheds: false,
            ..*self
        }
        .velocities_at(t)
        .1;
        let (turn, jacobian) = (rotation_of(&c), left_jacobian(&c));
        (
            a + ddc_p,
            jacobian * ddc + (jacobian * dc).cross(&(turn * omega)) + turn * alpha,
        )
    }

    /// What is left at `t` of the offset, and its first and second time derivatives, for the
    /// position and the rotation: `c(τ) = δ h₀₀(u) + δ̇ Δt h₁₀(u)`, `u = τ/Δt` (zero outside
    /// `0 ≤ τ < Δt = rate_span`; the struct's documentation).
    fn shed_offset(&self, t: f64) -> [(Vector3<f64>, Vector3<f64>, Vector3<f64>); 2] {
        let zero = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
        let shedding = self
            .sheds
            .then(|| shedding(t - self.changed_at, self.rate_span))
            .flatten();
        let Some([h00, h10]) = shedding else {
            return [zero; 2];
        };
        let [dp, dtheta, dv, domega] = self.offset;
        let shed = |d: Vector3<f64>, e: Vector3<f64>| {
            (
                d * h00[0] + e * h10[0],
                d * h00[1] + e * h10[1],
                d * h00[2] + e * h10[2],
            )
        };
        [shed(dp, dv), shed(dtheta, domega)]
    }

    /// The frame as it stands at `t`, given anew there: pose and velocities at `t` (the offset's
    /// rest taken in), the same rates (for what takes the motion at one time: a step's start,
    /// the inputs of an interface set in part).
    pub fn advanced_to(&self, t: f64) -> DrivingFrame {
        let (position, rotation) = self.at(t);
        let (velocity, angular_velocity) = self.velocities_at(t);
        DrivingFrame {
            position,
            rotation,
            velocity,
            angular_velocity,
            changed_at: t,
            offset: [Vector3::zeros(); 4],
            sheds: false,
            ..*self
        }
    }
}

/// `exp([φ]×)`.
fn rotation_of(phi: &Vector3<f64>) -> Matrix3<f64> {
    *nalgebra::Rotation3::from_scaled_axis(*phi).matrix()
}

/// The weights with which an offset is shed `τ` after it was taken, over `span` (s):
/// `[h₀₀(u), Δt h₁₀(u)]` with `u = τ/Δt`, each with its first and second time derivatives
/// (`DrivingFrame`: the offset `(δ, δ̇)` left is `δ h₀₀ + δ̇ Δt h₁₀`). `None` outside
/// `0 ≤ τ < span` (nothing left) or without a span.
pub fn shedding(tau: f64, span: f64) -> Option<[[f64; 3]; 2]> {
    if !(span > 0.0 && (0.0..span).contains(&tau)) {
        return None;
    }
    let u = tau / span;
    Some([
        [
            2.0 * u * u * u - 3.0 * u * u + 1.0,
            (6.0 * u * u - 6.0 * u) / span,
            (12.0 * u - 6.0) / (span * span),
        ],
        [
            span * (u * u * u - 2.0 * u * u + u),
            3.0 * u * u - 4.0 * u + 1.0,
            (6.0 * u - 4.0) / span,
        ],
    ])
}

impl NodeSet {
    /// Calls `each(index, offset, point)` for every coordinate the set holds: a mesh node
    /// (`point`, offset `X_i − X_ref` from the reference point) or, on a reduced body, a held
    /// coordinate ([`HeldCoordinate`]). Driven by a frame `(p, Q)` the coordinate is `p + Q d`
    /// (`point`) or `Q d`, `d` the offset.
    pub fn for_each_held(
        &self,
        reference: &[f64],
        mut each: impl FnMut(usize, Vector3<f64>, bool),
    ) {
        match &self.expansion {
            Some(e) => e.held.iter().for_each(|h| each(h.index, h.offset, h.point)),
            None => {
                for &n in &self.frame_weights.nodes {
                    each(n, node(reference, n) - self.reference_point, true);
                }
            }
        }
    }

    /// Clamps the nodes to `frame` at time `t`: `x_i = p(t) + Q(t)(X_i − X_ref)`,
    /// `ẋ_i = v(t) + ω(t) × r_i`, `ẍ_i = a(t) + α(t) × r_i + ω(t) × (ω(t) × r_i)` with
    /// `r_i = x_i − p(t)` (X_ref: the reference point; `a(t)`, `α(t)` the rates the frame
    /// follows with what the offset it sheds adds, [`DrivingFrame::accelerations_at`]; the
    /// angular acceleration of the sample's path is `α` to `O(|ω × α| τ)`).
    pub fn prescribe(
        &self,
        reference: &[f64],
        frame: &DrivingFrame,
        t: f64,
        x: &mut [f64],
        v: &mut [f64],
        a: &mut [f64],
    ) {
        let (p, q) = frame.at(t);
        let (velocity, w) = frame.velocities_at(t);
        let (acceleration, alpha) = frame.accelerations_at(t);
        self.for_each_held(reference, |index, offset, point| {
            let r = q * offset;
            let (x0, v0, a0) = if point {
                (p, velocity, acceleration)
            } else {
                (Vector3::zeros(), Vector3::zeros(), Vector3::zeros())
            };
            set_node(x, index, &(x0 + r));
            set_node(v, index, &(v0 + w.cross(&r)));
            set_node(a, index, &(a0 + alpha.cross(&r) + w.cross(&w.cross(&r))));
        });
    }
}

impl SetExpansion {
    /// `x_j = Σ_k S_jk q_k` for the set's nodes `j` (flat `3 n_set`): the product of the set's
    /// rows of `S` (`n_set × s`) with the `s × 3` matrix of the `q_k` (faer, SIMD; no allocation).
    fn expand(&self, q: &[f64], out: &mut [f64]) {
        let s = self.fields;
        let n_set = self.rows.len() / s;
        faer::linalg::matmul::matmul(
            faer::MatMut::from_row_major_slice_mut(&mut out[..3 * n_set], n_set, 3),
            faer::Accum::Replace,
            faer::MatRef::from_row_major_slice(&self.rows, n_set, s),
            faer::MatRef::from_row_major_slice(&q[..3 * s], s, 3),
            1.0,
            faer::Par::Seq,
        );
    }

    fn distribute(&self, q: &[f64], force: &Vector3<f64>, torque: &Vector3<f64>, f: &mut [f64]) {
        if let (Some(w), true) = (&self.force_weights, torque.norm_squared() == 0.0) {
            for (k, &wk) in w.iter().enumerate() {
                add_node(f, k, &(wk * force));
            }
            return;
        }
        let n3 = self.local.frame_weights.nodes.len() * 3;
        let mut scratch = self.scratch.borrow_mut();
        let (xs, rest) = scratch.split_at_mut(n3);
        let fs = &mut rest[..n3];
        self.expand(q, xs);
        fs.fill(0.0);
        self.local.distribute(xs, force, torque, fs);
        // Σ_j S_jk f_j
        let s = self.fields;
        for (j, row) in self.rows.chunks_exact(s).enumerate() {
            let fj = node(fs, j);
            for (k, &sk) in row.iter().enumerate() {
                add_node(f, k, &(sk * fj));
            }
        }
    }

    fn motion(&self, q: &[f64], v: &[f64], a: &[f64]) -> InterfaceMotion {
        let n3 = self.local.frame_weights.nodes.len() * 3;
        let mut scratch = self.scratch.borrow_mut();
        let (xs, rest) = scratch.split_at_mut(n3);
        let (vs, rest) = rest.split_at_mut(n3);
        let avs = &mut rest[..n3];
        self.expand(q, xs);
        self.expand(v, vs);
        self.expand(a, avs);
        self.local.motion(xs, vs, avs)
    }

    /// Force and torque about the current reference point `p` of the generalized loads `f` on
    /// the held coordinates: with `x_i = q_0 + Σ_a φ_a(X_i) q_a` on the set,
    /// `Σ f_i = r_0` and `Σ (x_i − p) × f_i = (q_0 − p) × r_0 + Σ_a q_a × r_a`.
    fn resultant(&self, q: &[f64], f: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let n3 = self.local.frame_weights.nodes.len() * 3;
        let p = {
            let mut scratch = self.scratch.borrow_mut();
            let xs = &mut scratch[..n3];
            self.expand(q, xs);
            let frame = self.local.frame_weights.best_fit(xs);
            self.local.reference_point_at(&frame)
        };
        let (mut force, mut torque) = (Vector3::zeros(), Vector3::zeros());
        for h in &self.held {
            let (qk, rk) = (node(q, h.index), node(f, h.index));
            if h.point {
                force += rk;
                torque += (qk - p).cross(&rk);
            } else {
                torque += qk.cross(&rk);
            }
        }
        (force, torque)
    }
}

/// `J = Σ w_i (|r_i|² I − r_i r_iᵀ)`, `r_i = x_i − c` (kg·m²).
fn polar_inertia(fw: &FrameWeights, x: &[f64], c: &Vector3<f64>) -> Matrix3<f64> {
    let mut j = Matrix3::zeros();
    for (&n, &w) in fw.nodes.iter().zip(&fw.weights) {
        let r = node(x, n) - c;
        j += w * (Matrix3::identity() * r.norm_squared() - r * r.transpose());
    }
    j
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame given at `t = 1` s that follows its rates over 10 ms, with angular velocity `omega`
    /// and angular acceleration `alpha`.
    fn followed_at_one(omega: Vector3<f64>, alpha: Vector3<f64>) -> DrivingFrame {
        DrivingFrame {
            position: Vector3::new(1.0, 2.0, -0.5),
            rotation: *nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.2, 0.1, -0.4)).matrix(),
            velocity: Vector3::new(0.5, -1.0, 2.0),
            angular_velocity: omega,
            acceleration: Vector3::new(3.0, 1.0, -2.0),
            angular_acceleration: alpha,
            changed_at: 1.0,
            rate_span: 0.01,
            updated_at: 1.0,
            ..DrivingFrame::default()
        }
    }

    /// A frame following its rates is one path measured from its inputs: advanced to `t₁` it
    /// stands where the path is at `t₁`, its origin is `p + v τ + a τ²/2` and its angular
    /// velocity the derivative of its rotation (`ω` and `α` on different axes); without a span
    /// it keeps constant velocities.
    #[test]
    fn a_frame_following_its_rates_is_one_path() {
        let given = followed_at_one(Vector3::new(0.3, 1.5, -0.2), Vector3::new(-4.0, 0.5, 2.0));
        let (t1, t2) = (1.013, 1.034);
        let (a, b) = (given.advanced_to(t1), given);
        let (pa, qa) = a.at(t1);
        let (pb, qb) = b.at(t1);
        assert!((pa - pb).amax() < 1e-14 && (qa - qb).amax() < 1e-14);
        assert_eq!(a.velocities_at(t1), b.velocities_at(t1));
        let (pb, qb) = b.at(t2);
        let tau = t2 - 1.0;
        let p = given.position + given.velocity * tau + given.acceleration * (0.5 * tau * tau);
        assert!((pb - p).amax() < 1e-14);
        // The angular velocity is Q̇ Qᵀ of the path (central differences).
        let e = 1e-6;
        let dq = (b.at(t2 + e).1 - b.at(t2 - e).1) / (2.0 * e);
        let w = dq * qb.transpose();
        let (_, omega) = b.velocities_at(t2);
        assert!((Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]) - omega).amax() < 1e-8);
        let held = DrivingFrame {
            rate_span: 0.0,
            ..given
        };
        let (p, _) = held.at(t2);
        assert!((p - (given.position + given.velocity * tau)).amax() < 1e-14);
        assert_eq!(held.velocities_at(t2).0, given.velocity);
    }

    fn face() -> (Vec<f64>, NodeSet) {
        // 3×3 grid of nodes in the plane x = 1 with unequal weights
        let mut x = Vec::new();
        for j in 0..3 {
            for k in 0..3 {
                x.extend_from_slice(&[1.0, 0.01 * j as f64 - 0.01, 0.01 * k as f64 - 0.01]);
            }
        }
        let weights = (0..9).map(|i| 1.0 + (i % 4) as f64).collect();
        let set = NodeSet::new(
            "tip",
            (0..9).collect(),
            weights,
            &x,
            Some(Vector3::new(1.0, 0.0, 0.0)),
        )
        .unwrap();
        (x, set)
    }

    #[test]
    fn distributed_load_has_the_given_resultant() {
        let (x, set) = face();
        let force = Vector3::new(1.0, -10.0, 3.0);
        let torque = Vector3::new(0.5, 0.2, -0.1);
        let mut f = vec![0.0; x.len()];
        set.distribute(&x, &force, &torque, &mut f);
        let (rf, rt) = set.resultant(&x, &f);
        assert!((rf - force).norm() < 1e-12);
        assert!((rt - torque).norm() < 1e-12);
    }

    #[test]
    fn reported_motion_is_power_conjugate() {
        let (x, set) = face();
        let n = x.len() / 3;
        // an arbitrary (non-rigid) velocity field
        let mut v = vec![0.0; x.len()];
        for i in 0..n {
            set_node(
                &mut v,
                i,
                &Vector3::new((i as f64).sin(), (2.0 * i as f64).cos(), 0.3 * i as f64),
            );
        }
        let force = Vector3::new(1.0, -10.0, 3.0);
        let torque = Vector3::new(0.5, 0.2, -0.1);
        let mut f = vec![0.0; x.len()];
        set.distribute(&x, &force, &torque, &mut f);
        let nodal_power: f64 = f.iter().zip(&v).map(|(a, b)| a * b).sum();
        let m = set.motion(&x, &v, &v);
        let power = force.dot(&m.velocity) + torque.dot(&m.angular_velocity);
        assert!((nodal_power - power).abs() < 1e-12 * nodal_power.abs().max(1.0));
    }

    /// A followed sample's offset (the bend of the path it followed): the frame starts on that
    /// path, in pose and velocities, and is on the sample's own path from one span on; its
    /// accelerations are the second derivatives of its pose (central differences).
    #[test]
    fn a_frame_sheds_its_offset_over_one_span() {
        let sample = followed_at_one(Vector3::new(0.0, 0.0, 1.5), Vector3::new(0.0, 0.0, 2.0));
        let offset = [
            Vector3::new(1e-6, -2e-6, 3e-6),
            Vector3::new(0.0, 0.0, 4e-6),
            Vector3::new(-3e-4, 1e-4, 2e-4),
            Vector3::new(0.0, 0.0, -5e-4),
        ];
        let shed = DrivingFrame {
            offset,
            sheds: true,
            ..sample
        };
        let (p0, q0) = shed.at(1.0);
        let (v0, w0) = shed.velocities_at(1.0);
        assert!((p0 - sample.position - offset[0]).amax() < 1e-15);
        let turn = q0 * sample.rotation.transpose();
        assert!((crate::body::frame::rotation_vector(&turn) - offset[1]).amax() < 1e-15);
        assert!((v0 - sample.velocity - offset[2]).amax() < 1e-15);
        assert!((w0 - sample.angular_velocity - offset[3]).amax() < 1e-15);
        for t in [1.0101, 1.013] {
            assert_eq!(shed.at(t), sample.at(t));
            assert_eq!(shed.velocities_at(t), sample.velocities_at(t));
            assert_eq!(shed.accelerations_at(t), sample.extrapolation_rates());
        }
        // Just before the span ends (1e-5 of it) the offset is gone to second order: 3e-10 of
        // it (1e-15 m) where a linear decay would leave 1e-5 (3e-11 m).
        let (p1, _) = shed.at(1.01 - 1e-7);
        assert!((p1 - sample.at(1.01 - 1e-7).0).amax() < 1e-14);
        // Within the span the path is a cubic in τ: central differences of a step well above
        // the rounding.
        let e = 1e-4;
        for t in [1.002, 1.005, 1.008] {
            let (pm, pp, pc) = (shed.at(t - e).0, shed.at(t + e).0, shed.at(t).0);
            let (a, _) = shed.accelerations_at(t);
            assert!(((pp - 2.0 * pc + pm) / (e * e) - a).amax() < 1e-5 * a.amax());
            let (vm, vp) = (shed.velocities_at(t - e).0, shed.velocities_at(t + e).0);
            assert!(((vp - vm) / (2.0 * e) - a).amax() < 1e-6 * a.amax());
            // About a fixed axis the angular velocity and acceleration are exact.
            let (wm, wp) = (shed.velocities_at(t - e).1, shed.velocities_at(t + e).1);
            let (_, alpha) = shed.accelerations_at(t);
            assert!(((wp - wm) / (2.0 * e) - alpha).amax() < 1e-6 * alpha.amax());
        }
        // Given anew at a time within its span, the frame stands where it stood at that time
        // (it carries what is left of the offset on with constant rates from there).
        let later = shed.advanced_to(1.004);
        assert_eq!(later.offset, [Vector3::zeros(); 4]);
        let (pa, qa) = later.at(1.004);
        let (pb, qb) = shed.at(1.004);
        assert!((pa - pb).amax() < 1e-15 && (qa - qb).amax() < 1e-15);
    }

    /// The rotation `exp([c]×) R_s` turning with the offset and the sample's path about other
    /// axes: the angular velocity and acceleration the frame gives are those of its rotation
    /// (central differences of `Q̇ Qᵀ` and of the angular velocity).
    #[test]
    fn a_turn_shed_about_another_axis_keeps_the_rotations_own_rates() {
        let frame = DrivingFrame {
            rotation: *nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.3, -0.2, 0.5)).matrix(),
            angular_velocity: Vector3::new(0.4, 1.5, -0.7),
            angular_acceleration: Vector3::new(2.0, -1.0, 0.5),
            changed_at: 1.0,
            rate_span: 0.01,
            offset: [
                Vector3::zeros(),
                Vector3::new(2e-3, -1e-3, 3e-3),
                Vector3::zeros(),
                Vector3::new(-0.3, 0.2, 0.4),
            ],
            sheds: true,
            ..DrivingFrame::default()
        };
        let e = 1e-6;
        for t in [1.001, 1.004, 1.007] {
            let q = |t: f64| frame.at(t).1;
            let w = (q(t + e) - q(t - e)) / (2.0 * e) * q(t).transpose();
            let numeric = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            let (_, omega) = frame.velocities_at(t);
            assert!(
                (numeric - omega).amax() < 1e-8 * omega.amax(),
                "{numeric} {omega}"
            );
            let dw = (frame.velocities_at(t + e).1 - frame.velocities_at(t - e).1) / (2.0 * e);
            let (_, alpha) = frame.accelerations_at(t);
            // The sample's path takes `α` for its angular acceleration, to `O(|ω × α| τ)`
            // (`NodeSet::prescribe`): 1.5e-4 of it at 7 ms here; `J̇_l ċ`, left out, is
            // second order in the offset.
            assert!((dw - alpha).amax() < 1e-3 * dw.amax(), "{dw} {alpha}");
        }
    }

    #[test]
    fn collinear_set_is_rejected() {
        let x = vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0];
        let e = NodeSet::new("line", vec![0, 1, 2], vec![1.0; 3], &x, None).unwrap_err();
        assert!(e.message.contains("collinear"), "{e}");
    }
}
