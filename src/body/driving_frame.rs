//! The driving frame of a motion interface: the motion its inputs give, followed between
//! updates with the velocities' rates, and the offset it sheds at an update it follows through
//! (docs/fmu.md, "Inputs are samples in time").

use super::frame::left_jacobian;
use nalgebra::{Matrix3, Vector3};

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
        let position = self.position + self.velocity * tau + a * (0.5 * tau * tau);
        let rotation = turn.matrix() * self.rotation;
        match self.shed_offset(t) {
            None => (position, rotation),
            Some([(c_p, _, _), (c, _, _)]) => (position + c_p, rotation_of(&c) * rotation),
        }
    }

    /// Velocity and angular velocity at `t`: `v + a τ` and `J_l(φ) (ω + α τ)`, with what is left
    /// of the offset.
    pub fn velocities_at(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let tau = t - self.changed_at;
        let (a, alpha) = self.extrapolation_rates();
        let velocity = self.velocity + a * tau;
        let angular = if self.rate_span > 0.0 {
            left_jacobian(&self.turn(t)) * (self.angular_velocity + alpha * tau)
        } else {
            self.angular_velocity
        };
        match self.shed_offset(t) {
            None => (velocity, angular),
            Some([(_, dc_p, _), (c, dc, _)]) => (
                velocity + dc_p,
                left_jacobian(&c) * dc + rotation_of(&c) * angular,
            ),
        }
    }

    /// Acceleration and angular acceleration of the path at `t`: the rates the frame follows
    /// and the offset's. Of the rotation `exp([c]×) R_s`, whose angular velocity is
    /// `w = J_l(c) ċ + exp([c]×) ω_s`: `J_l(c) c̈ + (J_l(c) ċ) × exp([c]×) ω_s + exp([c]×) α`
    /// (without `J̇_l ċ`, third order in the offset: its first-order part `½ ċ × ċ` vanishes).
    pub fn accelerations_at(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (a, alpha) = self.extrapolation_rates();
        let Some([(_, _, ddc_p), (c, dc, ddc)]) = self.shed_offset(t) else {
            return (a, alpha);
        };
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
    /// position and the rotation: `c(τ) = δ h₀₀(u) + δ̇ Δt h₁₀(u)`, `u = τ/Δt` (the struct's
    /// documentation). `None` where the frame does not shed or has shed it all (outside
    /// `0 ≤ τ < Δt = rate_span`).
    fn shed_offset(&self, t: f64) -> Option<[LeftOfOffset; 2]> {
        if !self.sheds {
            return None;
        }
        let [h00, h10] = shedding(t - self.changed_at, self.rate_span)?;
        let [dp, dtheta, dv, domega] = self.offset;
        let shed = |d: Vector3<f64>, e: Vector3<f64>| {
            (
                d * h00[0] + e * h10[0],
                d * h00[1] + e * h10[1],
                d * h00[2] + e * h10[2],
            )
        };
        Some([shed(dp, dv), shed(dtheta, domega)])
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

/// What is left of an offset at a time, with its first and second time derivatives (m, m/s,
/// m/s² for the position; rad, rad/s, rad/s² for the rotation).
type LeftOfOffset = (Vector3<f64>, Vector3<f64>, Vector3<f64>);

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
            // The central difference's own error, `e²/6` of the rotation's third derivative, is
            // about 1e-8 here; a composition without `J_l(c)` or `exp([c]×)` errs by 5e-4.
            assert!(
                (numeric - omega).amax() < 1e-6 * omega.amax(),
                "{numeric} {omega}"
            );
            let dw = (frame.velocities_at(t + e).1 - frame.velocities_at(t - e).1) / (2.0 * e);
            let (_, alpha) = frame.accelerations_at(t);
            // The sample's path takes `α` for its angular acceleration, to `O(|ω × α| τ)`
            // (`NodeSet::prescribe`): 1.5e-4 of it at 7 ms here; `J̇_l ċ`, left out, is
            // third order in the offset.
            assert!((dw - alpha).amax() < 1e-3 * dw.amax(), "{dw} {alpha}");
        }
    }
}
