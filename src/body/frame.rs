//! The co-moving frame `(c, R)` (docs/formulation.md, "The co-moving frame"): `c = Σ w_i x_i / Σ w_i`, `R` the weighted
//! best-fit rotation, i.e. the rotation factor of the polar decomposition of
//! `A = Σ w_i (x_i − c) X̄_iᵀ` with `X̄_i = X_i − X_c`.

use super::polar::RotationGuess;
pub use super::polar::{nearest_rotation, polar_rotation, polar_rotation_near};
use nalgebra::{Matrix3, Vector3};

/// `[a]×`, the cross-product matrix: `[a]× b = a × b`.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// `m ← m + a bᵀ`, written out (nalgebra's product of a column and a row goes through its
/// general matrix product, a third of the best-fit frame's cost on a reduced body).
pub(super) fn add_outer(m: &mut Matrix3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) {
    for c in 0..3 {
        for r in 0..3 {
            m[(r, c)] += a[r] * b[c];
        }
    }
}

/// The rigid field `t + θ × (x − c)` nearest to a field `f` over `nodes` in the weighted
/// least-squares sense, `Σ_i w_i |t + θ × (x_i − c) − f_i|²` (weights `weight(k) ≥ 0` of the
/// `k`-th of `nodes`, positions `x` flat `3N`): `c` and `t` the weighted means of `x_i` and
/// `f_i`, `θ = I⁻¹ Σ_i w_i (x_i − c) × f_i` with `I = Σ_i w_i (|r_i|² 1 − r_i r_iᵀ)`
/// (directions in which `I` vanishes, as about the line of collinear nodes, get no rotation). Returns `(c, t, θ)`; all zero
/// without weight. No allocation.
pub fn nearest_rigid_field(
    nodes: &[usize],
    weight: impl Fn(usize) -> f64,
    x: &[f64],
    f: impl Fn(usize) -> Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let (mut total, mut centre, mut mean) = (0.0, Vector3::zeros(), Vector3::zeros());
    for (k, &i) in nodes.iter().enumerate() {
        let w = weight(k);
        total += w;
        centre += w * node(x, i);
        mean += w * f(i);
    }
    if total <= 0.0 {
        return (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
    }
    centre /= total;
    mean /= total;
    let (mut inertia, mut moment) = (Matrix3::zeros(), Vector3::zeros());
    for (k, &i) in nodes.iter().enumerate() {
        let (w, r) = (weight(k), node(x, i) - centre);
        inertia += w * (Matrix3::identity() * r.norm_squared() - r * r.transpose());
        moment += w * r.cross(&f(i));
    }
    let eigen = inertia.symmetric_eigen();
    let largest = eigen.eigenvalues.amax();
    let mut rotation = Vector3::zeros();
    for k in 0..3 {
        let lambda = eigen.eigenvalues[k];
        if lambda > 1e-12 * largest {
            let e = eigen.eigenvectors.column(k);
            rotation += e * (e.dot(&moment) / lambda);
        }
    }
    (centre, mean, rotation)
}

/// Node `i` of a flat `3N` vector.
#[inline]
pub fn node(v: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2])
}

/// Writes node `i` of a flat `3N` vector.
#[inline]
pub fn set_node(v: &mut [f64], i: usize, value: &Vector3<f64>) {
    v[3 * i] = value.x;
    v[3 * i + 1] = value.y;
    v[3 * i + 2] = value.z;
}

/// Adds to node `i` of a flat `3N` vector.
#[inline]
pub fn add_node(v: &mut [f64], i: usize, value: &Vector3<f64>) {
    v[3 * i] += value.x;
    v[3 * i + 1] += value.y;
    v[3 * i + 2] += value.z;
}

/// Weights and reference geometry of a best-fit frame over a set of nodes: positive weights
/// `w_i` (kg, HRZ-lumped masses for the body frame), the weighted reference centroid `X_c` and
/// the reference offsets `X̄_i = X_i − X_c`.
///
/// The same frame serves a reduced body ([`super::reduction`]), whose coordinates `q_k` are the
/// coefficients of scalar fields `S_k` (`x_i = Σ_k S_ik q_k`): there the "weights" are
/// `Σ_i w_i S_ik` (any sign), the arms `a_k = Σ_i w_i S_ik X̄_i`, and `e_k` (the coefficients of
/// the constant field, `Σ_k S_ik e_k = 1`) replaces the 1 of every node in `x_i − c`. With
/// `a_i = w_i X̄_i` and `e_i = 1` the formulas below are the nodal ones, so one code serves both
/// and gives the reduced body exactly the frame of its expanded nodes.
#[derive(Debug, Clone)]
pub struct FrameWeights {
    pub nodes: Vec<usize>,
    pub weights: Vec<f64>,
    pub total_weight: f64,
    pub reference_centroid: Vector3<f64>,
    pub reference_offsets: Vec<Vector3<f64>>,
    /// `a_k = w_k X̄_k` (nodes) or `Σ_i w_i S_ik X̄_i` (reduced body) (kg·m).
    pub arms: Vec<Vector3<f64>>,
    /// `e_k`, the coefficients of the constant field; `None`: 1 for every node.
    pub unit: Option<Vec<f64>>,
    /// [`Self::best_fit`]'s first guess of `R` from `A`; `None` for a collinear node set.
    guess: Option<RotationGuess>,
}

/// A frame: origin `c` (m) and rotation `R` (columns: frame axes in global coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: Vector3<f64>,
    pub rotation: Matrix3<f64>,
}

impl FrameWeights {
    /// `nodes` with non-negative `weights` of positive sum (a lumped body's mass points weigh
    /// nothing in the body frame), reference positions taken from `reference` (flat `3N`).
    pub fn new(nodes: Vec<usize>, weights: Vec<f64>, reference: &[f64]) -> FrameWeights {
        assert_eq!(nodes.len(), weights.len());
        let total_weight: f64 = weights.iter().sum();
        assert!(
            weights.iter().all(|&w| w >= 0.0) && total_weight > 0.0,
            "frame weights must be non-negative with a positive sum"
        );
        let mut centroid = Vector3::zeros();
        for (&n, &w) in nodes.iter().zip(&weights) {
            centroid += w * node(reference, n);
        }
        centroid /= total_weight;
        let reference_offsets: Vec<Vector3<f64>> = nodes
            .iter()
            .map(|&n| node(reference, n) - centroid)
            .collect();
        let arms = weights
            .iter()
            .zip(&reference_offsets)
            .map(|(&w, xbar)| w * xbar)
            .collect::<Vec<_>>();
        FrameWeights {
            nodes,
            weights,
            total_weight,
            reference_centroid: centroid,
            guess: RotationGuess::new(&reference_offsets, &arms),
            reference_offsets,
            arms,
            unit: None,
        }
    }

    /// The frame of a reduced body with coordinates `q_k` (see the type's documentation):
    /// `weights_k = Σ_i w_i S_ik`, `total_weight = Σ_i w_i`, `X_c`, the reference offsets
    /// `X̄_k = q_ref,k − X_c e_k`, the arms `a_k` and `e_k`.
    pub fn reduced(
        weights: Vec<f64>,
        total_weight: f64,
        reference_centroid: Vector3<f64>,
        reference_offsets: Vec<Vector3<f64>>,
        arms: Vec<Vector3<f64>>,
        unit: Vec<f64>,
    ) -> FrameWeights {
        FrameWeights {
            nodes: (0..weights.len()).collect(),
            weights,
            total_weight,
            reference_centroid,
            guess: RotationGuess::new(&reference_offsets, &arms),
            reference_offsets,
            arms,
            unit: Some(unit),
        }
    }

    /// `e_k` of coordinate `k` (1 for a node).
    #[inline]
    pub fn unit(&self, k: usize) -> f64 {
        self.unit.as_ref().map_or(1.0, |u| u[k])
    }

    /// Weighted centroid `c = Σ w_i x_i / Σ w_i` of a flat `3N` vector `x` (positions,
    /// velocities or accelerations).
    pub fn centroid(&self, x: &[f64]) -> Vector3<f64> {
        let mut c = Vector3::zeros();
        for (&n, &w) in self.nodes.iter().zip(&self.weights) {
            c += w * node(x, n);
        }
        c / self.total_weight
    }

    /// The best-fit frame of positions `x`: `c` and `R = polar(Σ w_i (x_i − c) X̄_iᵀ)`
    /// (`= polar(Σ_k (q_k − c e_k) a_kᵀ)`), by [`polar_rotation_near`] from the guess of the
    /// principal axes' images (`RotationGuess` in [`super::polar`]), else by [`nearest_rotation`].
    pub fn best_fit(&self, x: &[f64]) -> Frame {
        let origin = self.centroid(x);
        let mut a = Matrix3::zeros();
        for (k, (&n, arm)) in self.nodes.iter().zip(&self.arms).enumerate() {
            add_outer(&mut a, &(node(x, n) - self.unit(k) * origin), arm);
        }
        let rotation = self
            .guess
            .and_then(|guess| guess.rotation(&a))
            .and_then(|guess| polar_rotation_near(&a, &guess))
            .unwrap_or_else(|| nearest_rotation(&a));
        Frame { origin, rotation }
    }

    /// `H = Σ w_i [X̄_i]× [X̄_i + ū_i]×` for the frame `frame` of positions `x` (≈ minus the
    /// weighted inertia tensor; docs/formulation.md, "The internal force"). It maps the frame's rotation variation:
    /// `H δθ = −Σ w_i X̄_i × Rᵀ δx_i` (body-frame `δθ`).
    pub fn rotation_sensitivity(&self, frame: &Frame, x: &[f64]) -> Matrix3<f64> {
        // [a]× [y]× = y aᵀ − (a · y) I: the sum of the outer products and of the dot products.
        let mut outer = Matrix3::zeros();
        let mut dots = 0.0;
        for (k, (&n, arm)) in self.nodes.iter().zip(&self.arms).enumerate() {
            // X̄_i + ū_i
            let y = frame.rotation.transpose() * (node(x, n) - self.unit(k) * frame.origin);
            add_outer(&mut outer, &y, arm);
            dots += arm.dot(&y);
        }
        outer - Matrix3::identity() * dots
    }

    /// Body-frame angular velocity of the best-fit frame, `ω̄ = −H⁻¹ Σ w_i X̄_i × Rᵀ ẋ_i`
    /// (rad/s); `h_inv` is `H⁻¹` from [`Self::rotation_sensitivity`].
    pub fn angular_velocity(&self, frame: &Frame, h_inv: &Matrix3<f64>, v: &[f64]) -> Vector3<f64> {
        let mut b = Vector3::zeros();
        let rt = frame.rotation.transpose();
        for (&n, arm) in self.nodes.iter().zip(&self.arms) {
            b += arm.cross(&(rt * node(v, n)));
        }
        -(h_inv * b)
    }

    /// The best-fit frame of positions `x` and its body-frame angular velocity `ω̄` (rad/s) at
    /// velocities `v` ([`Self::best_fit`], [`Self::angular_velocity`]; `H⁻¹` taken as zero where
    /// `H` is singular). O(N), no allocation.
    pub fn moving_frame(&self, x: &[f64], v: &[f64]) -> (Frame, Vector3<f64>) {
        let frame = self.best_fit(x);
        let omega = self.angular_velocity_at(&frame, x, v);
        (frame, omega)
    }

    /// The body-frame angular velocity `ω̄` (rad/s) of `frame`, the best-fit frame of positions
    /// `x`, at velocities `v` ([`Self::angular_velocity`] with `H⁻¹` from
    /// [`Self::rotation_sensitivity`], taken as zero where `H` is singular). O(N), no
    /// allocation.
    pub fn angular_velocity_at(&self, frame: &Frame, x: &[f64], v: &[f64]) -> Vector3<f64> {
        let h_inv = self
            .rotation_sensitivity(frame, x)
            .try_inverse()
            .unwrap_or_else(Matrix3::zeros);
        self.angular_velocity(frame, &h_inv, v)
    }
}

/// The angle `θ` (rad) of the turn `Aᵀ B` between two rotations: from `sin θ` (half the norm of
/// the skew part's axis, well conditioned at small angles) and, past π/2, from `cos θ`.
pub fn angle_between(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let turn = a.transpose() * b;
    (0.5 * skew_axis(&turn).norm()).atan2(0.5 * (turn.trace() - 1.0))
}

/// The axis of the skew part of a rotation `R`, `(R − Rᵀ)^∨ = 2 sin θ n`.
fn skew_axis(r: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    )
}

/// The rotation vector `φ = θ n` of a rotation `R = exp([φ]×)` (0 ≤ θ ≤ π): from the skew part
/// `2 sin θ n` and the angle of [`angle_between`], well conditioned at small angles (where it is
/// the skew part's half); near π, where the skew part vanishes, the axis from the symmetric part
/// `(R + Rᵀ)/2 − cos θ I = (1 − cos θ) n nᵀ` (its largest column), its sign the skew part's.
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let skew = skew_axis(r);
    let sine = 0.5 * skew.norm();
    let cosine = 0.5 * (r.trace() - 1.0);
    let theta = sine.atan2(cosine);
    if sine < 1e-3 && cosine < 0.0 {
        let outer = 0.5 * (r + r.transpose()) - Matrix3::identity() * cosine;
        let k = (0..3)
            .max_by(|&i, &j| outer[(i, i)].total_cmp(&outer[(j, j)]))
            .unwrap_or(0);
        let axis = outer.column(k).normalize();
        let sign = if axis.dot(&skew) < 0.0 { -1.0 } else { 1.0 };
        sign * theta * axis
    } else if sine < 1e-8 {
        0.5 * skew
    } else {
        skew * (0.5 * theta / sine)
    }
}

/// The left Jacobian of the rotation vector `φ`: `exp([φ + δ]×) = exp([J_l(φ) δ]×) exp([φ]×)` to
/// first order, `J_l = I + (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×²`, `θ = |φ|`.
pub fn left_jacobian(phi: &Vector3<f64>) -> Matrix3<f64> {
    let theta = phi.norm();
    let k = phi.cross_matrix();
    let (a, b) = if theta < 1e-4 {
        (
            0.5 - theta * theta / 24.0,
            1.0 / 6.0 - theta * theta / 120.0,
        )
    } else {
        (
            (1.0 - theta.cos()) / (theta * theta),
            (theta - theta.sin()) / (theta * theta * theta),
        )
    };
    Matrix3::identity() + a * k + b * k * k
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;
    use std::f64::consts::PI;

    #[test]
    fn the_angle_between_two_rotations_is_that_of_their_turn() {
        let a = *Rotation3::from_scaled_axis(Vector3::new(0.3, -0.2, 1.1)).matrix();
        let axis = Vector3::new(1.0, 2.0, -0.5).normalize();
        for theta in [1e-9, 1e-3, 0.7, 2.5] {
            let b = Rotation3::from_scaled_axis(axis * theta).matrix() * a;
            let found = angle_between(&a, &b);
            assert!(
                (found - theta).abs() < 1e-15 + 1e-12 * theta,
                "{found} for {theta}"
            );
        }
    }

    #[test]
    fn the_rotation_vector_inverts_the_exponential_from_0_to_pi() {
        // Both signs of the dominant component, and angles on both sides of the branch near π
        // (`sin θ = 1e-3`).
        for axis in [Vector3::new(0.3, -0.8, 0.5), Vector3::new(0.9, 0.2, -0.4)] {
            let axis = axis.normalize();
            let near_pi = [PI - 1.0001e-3, PI - 0.9999e-3, PI - 1e-5, PI - 1e-9];
            for theta in [0.0, 1e-12, 1e-7, 1e-3, 0.7, 2.0, 3.0]
                .into_iter()
                .chain(near_pi)
            {
                let phi = theta * axis;
                let r = *Rotation3::from_scaled_axis(phi).matrix();
                let back = rotation_vector(&r);
                assert!(
                    (back - phi).amax() < 1e-12,
                    "θ = {theta}: {back} against {phi}"
                );
            }
        }
        let axis = Vector3::new(0.3, -0.8, 0.5).normalize();
        // At π the two signs are the same rotation.
        let r = *Rotation3::from_scaled_axis(PI * axis).matrix();
        let back = rotation_vector(&r);
        assert!(
            (back.norm() - PI).abs() < 1e-12 && back.normalize().dot(&axis).abs() > 1.0 - 1e-12
        );
    }

    #[test]
    fn the_left_jacobian_is_the_derivative_of_the_exponential() {
        for phi in [
            Vector3::new(0.3, -0.2, 1.1),
            Vector3::new(1e-6, 2e-6, -1e-6),
        ] {
            let j = left_jacobian(&phi);
            let exp = |v: Vector3<f64>| *Rotation3::from_scaled_axis(v).matrix();
            for c in 0..3 {
                let e = 1e-6;
                let d = Vector3::ith(c, e);
                let numeric = (exp(phi + d) - exp(phi - d)) / (2.0 * e);
                let analytic = (j * Vector3::ith(c, 1.0)).cross_matrix() * exp(phi);
                assert!(
                    (numeric - analytic).amax() < 1e-9,
                    "φ = {phi:?}, component {c}: {numeric} against {analytic}"
                );
            }
        }
    }

    fn cloud() -> Vec<f64> {
        // an irregular cloud of 7 points
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 0.8, 0.1],
            [0.3, 0.2, 0.9],
            [1.1, 0.9, 0.3],
            [0.7, 0.1, 0.6],
            [0.1, 0.6, 0.7],
        ];
        p.iter().flatten().copied().collect()
    }

    #[test]
    fn best_fit_of_a_rigid_motion_is_that_motion() {
        let reference = cloud();
        let n = reference.len() / 3;
        let weights: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 * 0.3).collect();
        let fw = FrameWeights::new((0..n).collect(), weights, &reference);
        let q = *Rotation3::from_scaled_axis(Vector3::new(2.0, -1.0, 0.5)).matrix();
        let p = Vector3::new(3.0, -2.0, 1.0);
        let mut x = vec![0.0; 3 * n];
        for i in 0..n {
            set_node(&mut x, i, &(p + q * node(&reference, i)));
        }
        let f = fw.best_fit(&x);
        assert!((f.rotation - q).norm() < 1e-12);
        assert!((f.origin - (p + q * fw.reference_centroid)).norm() < 1e-12);
    }

    #[test]
    fn best_fit_of_a_slender_body_turned_rigidly_is_that_turn() {
        // A 10 m bar of 10 mm × 5 mm section (the nodes of its edges every 0.5 m): its moment
        // `a` has condition number 1e6. The frame is the turn to κ × round-off (measured
        // 3.6e-11); the SVD through `aᵀa` had it to κ² × round-off (1.25e-5 rad).
        // Laid along a skew axis, as a part drawn in its assembly's axes is.
        let laid = Rotation3::from_scaled_axis(Vector3::new(0.7, 0.3, -0.5));
        let mut reference = Vec::new();
        for k in 0..=20 {
            for (y, z) in [
                (-5e-3, -2.5e-3),
                (5e-3, -2.5e-3),
                (5e-3, 2.5e-3),
                (-5e-3, 2.5e-3),
            ] {
                let p = laid * Vector3::new(0.5 * k as f64, y, z);
                reference.extend_from_slice(p.as_slice());
            }
        }
        let n = reference.len() / 3;
        let fw = FrameWeights::new((0..n).collect(), vec![1.0; n], &reference);
        let q = *Rotation3::from_scaled_axis(Vector3::new(0.4, -0.9, 1.3)).matrix();
        let mut x = vec![0.0; 3 * n];
        for i in 0..n {
            set_node(&mut x, i, &(q * node(&reference, i)));
        }
        let error = (fw.best_fit(&x).rotation - q).norm();
        assert!(error < 1e-9, "{error:e}");
    }

    #[test]
    fn angular_velocity_of_a_rigid_rotation() {
        let reference = cloud();
        let n = reference.len() / 3;
        let fw = FrameWeights::new((0..n).collect(), vec![1.0; n], &reference);
        let q = *Rotation3::from_scaled_axis(Vector3::new(0.3, 0.2, -0.4)).matrix();
        let omega = Vector3::new(0.5, -3.0, 7.0); // global
        let mut x = vec![0.0; 3 * n];
        let mut v = vec![0.0; 3 * n];
        for i in 0..n {
            let r = q * (node(&reference, i) - fw.reference_centroid);
            set_node(&mut x, i, &r);
            set_node(&mut v, i, &omega.cross(&r));
        }
        let f = fw.best_fit(&x);
        let h_inv = fw.rotation_sensitivity(&f, &x).try_inverse().unwrap();
        let w_body = fw.angular_velocity(&f, &h_inv, &v);
        assert!((f.rotation * w_body - omega).norm() < 1e-12 * omega.norm());
    }

    #[test]
    fn the_frame_of_a_planar_node_set_is_its_turn() {
        // Four nodes of a skew square (a face, an interface), turned and stretched in plane:
        // the guess completes the normal, and the frame is the SVD's nearest rotation.
        let turn = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.4, 1.3, -0.8));
        let tilt = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.3, 0.2, 0.1));
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (0.0, 2.0)];
        let reference: Vec<f64> = corners
            .iter()
            .flat_map(|&(u, v)| {
                let p = tilt * Vector3::new(u, v, 0.0);
                [p.x, p.y, p.z]
            })
            .collect();
        let fw = FrameWeights::new(vec![0, 1, 2, 3], vec![1.0, 2.0, 1.0, 3.0], &reference);
        assert!(fw.guess.is_some());
        let stretch =
            tilt * Matrix3::new(1.05, 0.02, 0.0, -0.01, 0.97, 0.0, 0.0, 0.0, 1.0) * tilt.inverse();
        let x: Vec<f64> = (0..4)
            .flat_map(|i| {
                let p = turn * (stretch * node(&reference, i)) + Vector3::new(1.0, -2.0, 0.5);
                [p.x, p.y, p.z]
            })
            .collect();
        let frame = fw.best_fit(&x);
        let mut a = Matrix3::zeros();
        for (k, arm) in fw.arms.iter().enumerate() {
            add_outer(&mut a, &(node(&x, k) - frame.origin), arm);
        }
        assert!((frame.rotation - nearest_rotation(&a)).norm() < 1e-14);
        assert!((frame.rotation - turn.into_inner()).norm() < 0.05);
        // … by the iteration from the guess, not the SVD's fallback.
        let guess = fw.guess.and_then(|g| g.rotation(&a)).expect("a guess");
        let near = polar_rotation_near(&a, &guess).expect("converges");
        assert_eq!(near, frame.rotation);
    }

    #[test]
    fn a_thin_skew_face_bent_out_of_its_plane_takes_the_iteration() {
        // A 5 × 5 face 1 mm thick (out-of-plane offsets of ±0.5 mm) on a tilted plane, turned,
        // and moved out of its plane by up to 3 mm with no relation to its thickness: the guess
        // from the images of its two in-plane principal axes is good, where the images of the
        // global axes through `A_ref⁻¹` amplify the out-of-plane motion by 1/λ₃ (a review's
        // test: 137–171 of 200 such faces fell back to the SVD).
        let tilt = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.5, -0.3, 0.9));
        let turn = nalgebra::Rotation3::from_scaled_axis(Vector3::new(-1.2, 0.4, 0.7));
        let mut reference = Vec::new();
        let mut moved = Vec::new();
        for i in 0..25 {
            let (u, v) = ((i % 5) as f64 * 0.1, (i / 5) as f64 * 0.1);
            let depth = 5e-4 * (1.7 * i as f64).sin();
            let p = tilt * Vector3::new(u, v, depth);
            reference.extend_from_slice(p.as_slice());
            let lift = 3e-3 * (2.3 * i as f64 + 0.4).cos();
            let q = turn * (p + tilt * Vector3::new(0.0, 0.0, lift));
            moved.extend_from_slice(q.as_slice());
        }
        let fw = FrameWeights::new((0..25).collect(), vec![1.0; 25], &reference);
        let frame = fw.best_fit(&moved);
        let mut a = Matrix3::zeros();
        for (k, arm) in fw.arms.iter().enumerate() {
            add_outer(&mut a, &(node(&moved, k) - frame.origin), arm);
        }
        let guess = fw.guess.and_then(|g| g.rotation(&a)).expect("a guess");
        let near = polar_rotation_near(&a, &guess).expect("converges from the guess");
        assert_eq!(near, frame.rotation);
        assert!((near - nearest_rotation(&a)).norm() < 1e-12);
    }
}
