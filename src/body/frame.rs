//! The co-moving frame `(c, R)` (docs/formulation.md, "The co-moving frame"): `c = Σ w_i x_i / Σ w_i`, `R` the weighted
//! best-fit rotation, i.e. the rotation factor of the polar decomposition of
//! `A = Σ w_i (x_i − c) X̄_iᵀ` with `X̄_i = X_i − X_c`.

use nalgebra::{Matrix3, Vector3};

/// `[a]×`, the cross-product matrix: `[a]× b = a × b`.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// `m ← m + a bᵀ`, written out (nalgebra's product of a column and a row goes through its
/// general matrix product, a third of the best-fit frame's cost on a reduced body).
fn add_outer(m: &mut Matrix3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) {
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

/// The rotation closest to `a` in the Frobenius norm (rotation factor of the polar
/// decomposition `a = R P`), with `det R = +1` even when `det a < 0`. Where `a` is
/// comfortably invertible with `det a > 0` (a best-fit frame's moment of a body: about 1e-8 of
/// `‖a‖³` for B3's beam), [`polar_rotation`]; else (a planar node set, a reflection) the SVD
/// with the sign fix. Allocation-free.
pub fn nearest_rotation(a: &Matrix3<f64>) -> Matrix3<f64> {
    if let Some(r) = polar_rotation(a) {
        return r;
    }
    let svd = a.svd(true, true);
    let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
    let d = (u * v_t).determinant().signum();
    u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * v_t
}

/// `det a / ‖a‖_F³` below which [`nearest_rotation`] takes the SVD: a near-singular `a` (a planar
/// node set: 0) or a reflection. Above it `a`'s condition number is at most 1e7 (one large
/// singular value, `det/‖a‖³ ≈ κ⁻²`) to 1e13 (one small), where the scaled Newton iteration
/// converges in about ten steps.
const POLAR_NEWTON_DETERMINANT: f64 = 1e-14;

/// The polar factor `R` of `a = R P` by Higham's scaled Newton iteration,
/// `X ← (γ X + X^{-T}/γ)/2`, `γ = (‖X⁻¹‖_F / ‖X‖_F)^{1/2}` (Higham, *Functions of Matrices*,
/// 2008, §8.6): quadratic once close, the scaling bringing a badly conditioned `a` close in a
/// few steps. Once a step changes `X` by less than 1e-9 a last unscaled step takes it to
/// round-off. `None` where `a` is not comfortably invertible with a positive determinant
/// ([`POLAR_NEWTON_DETERMINANT`]) or the iteration does not settle. It is for accuracy, not
/// speed: B3 with `model.modes = auto` stepped in the same time as with the SVD.
pub fn polar_rotation(a: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let norm = a.norm();
    if !(norm.is_finite() && a.determinant() > POLAR_NEWTON_DETERMINANT * norm.powi(3)) {
        return None;
    }
    let mut x = *a;
    for _ in 0..30 {
        let inverse = x.try_inverse()?;
        let gamma = (inverse.norm() / x.norm()).sqrt();
        let next = 0.5 * (gamma * x + inverse.transpose() / gamma);
        let change = (next - x).norm();
        x = next;
        if change <= 1e-9 {
            let inverse = x.try_inverse()?;
            return Some(0.5 * (x + inverse.transpose()));
        }
    }
    None
}

/// The polar factor `R` of `a = R P` by Newton's iteration on the rotation itself, from a
/// `guess` near it (docs/formulation.md, "The co-moving frame"): with `B = Rᵀ a = S + [w]×`
/// (`S` symmetric, `[w]×` its skew part), the turn `θ` that makes `(R exp[θ]×)ᵀ a` symmetric
/// solves, to first order, `(tr S · 1 − S) θ = 2 w` (as `[θ]× S + S [θ]× = [(tr S · 1 − S) θ]×`),
/// and `R ← R cay(θ)` with the Cayley rotation `cay(θ) = 1 + 2 ([φ]× + [φ]×²) / (1 + |φ|²)`,
/// `φ = θ/2`, orthogonal to round-off and equal to `exp[θ]×` to second order. Quadratic like
/// [`polar_rotation`]'s, but each step is a product and a 3 × 3 solve, and from a guess off by
/// a small strain it takes two or three: it is the best-fit frame's hot path. Once a turn is
/// below 1e-8 rad, the next would be below round-off: it is the last. `None` if it does not
/// settle in ten steps or ends at a stationary point other than the maximum of `tr(Rᵀ a)` (a
/// guess too far); the caller then takes [`nearest_rotation`]. `a` may be singular (a planar
/// node set: `tr S · 1 − S` stays invertible) or a reflection: the result is
/// [`nearest_rotation`]'s.
pub fn polar_rotation_near(a: &Matrix3<f64>, guess: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let mut r = *guess;
    for _ in 0..10 {
        let b = r.transpose() * a;
        let s = 0.5 * (b + b.transpose());
        // 2 w: twice the axial vector of the skew part (b − bᵀ)/2.
        let two_w = Vector3::new(
            b[(2, 1)] - b[(1, 2)],
            b[(0, 2)] - b[(2, 0)],
            b[(1, 0)] - b[(0, 1)],
        );
        let theta = (Matrix3::identity() * s.trace() - s).try_inverse()? * two_w;
        let phi = 0.5 * theta;
        let k = skew(&phi);
        r *= Matrix3::identity() + (2.0 / (1.0 + phi.norm_squared())) * (k + k * k);
        if !theta.iter().all(|t| t.is_finite()) {
            return None;
        }
        if theta.norm() <= 1e-8 {
            // The stationary points of tr(Rᵀ a) over the rotations are `R = U diag(s) Vᵀ`
            // (a = U Σ Vᵀ, s = ±1, det R = 1), where `tr S · 1 − S` has the eigenvalues
            // `s_j σ_j + s_k σ_k`: only the maximum, the nearest rotation, has them all
            // positive (for `det a < 0` too, while σ₃ < σ₂).
            let b = r.transpose() * a;
            let s = 0.5 * (b + b.transpose());
            let h = Matrix3::identity() * s.trace() - s;
            let minor = h[(0, 0)] * h[(1, 1)] - h[(0, 1)] * h[(1, 0)];
            return (h[(0, 0)] > 0.0 && minor > 0.0 && h.determinant() > 0.0).then_some(r);
        }
    }
    None
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

/// The first guess of a best-fit frame's rotation from its moment `A`
/// ([`FrameWeights::best_fit`]). At the reference `A_ref = Σ_k X̄_k a_kᵀ = Σ w_i X̄_i X̄_iᵀ =
/// Σ_j λ_j e_j e_jᵀ` (`λ₁ ≥ λ₂ ≥ λ₃ ≥ 0`), and a body turned by `R` and strained has
/// `A ≈ R A_ref`, so `A e_j ≈ λ_j R e_j`: the images of the two principal axes of the largest
/// moments, `A e₁` and `A e₂`, are `R e₁` and `R e₂` up to the strain and their lengths, and
/// the best determined (a thin direction's image is the strain's noise over `λ₃`). The guess
/// is `g₁ = A e₁` normalised, `g₂` the part of `A e₂` normal to it normalised, `g₃ = g₁ × g₂`,
/// put back on the axes: `R̃ = Σ_j g_j e_jᵀ` (`e₃ = e₁ × e₂`). A planar set (`λ₃ = 0`) needs
/// nothing else; a collinear set (`λ₂ ≤ 1e-12 λ₁`) has no guess.
#[derive(Debug, Clone, Copy)]
struct RotationGuess {
    /// `e₁, e₂, e₁ × e₂`.
    axes: [Vector3<f64>; 3],
}

impl RotationGuess {
    /// From the reference offsets and arms ([`Self::from_moment`]).
    fn new(offsets: &[Vector3<f64>], arms: &[Vector3<f64>]) -> Option<RotationGuess> {
        let mut moment = Matrix3::zeros();
        for (offset, arm) in offsets.iter().zip(arms) {
            add_outer(&mut moment, offset, arm);
        }
        RotationGuess::from_moment(&moment)
    }

    /// From the reference moment `A_ref`; `None` where its second eigenvalue is below 1e-12 of
    /// the largest (a collinear set, a point) or it is not finite.
    fn from_moment(moment: &Matrix3<f64>) -> Option<RotationGuess> {
        let eigen = (0.5 * (moment + moment.transpose())).symmetric_eigen();
        let mut order = [0, 1, 2];
        order.sort_by(|&i, &j| eigen.eigenvalues[j].total_cmp(&eigen.eigenvalues[i]));
        let (largest, second) = (eigen.eigenvalues[order[0]], eigen.eigenvalues[order[1]]);
        if !(largest.is_finite() && largest > 0.0 && second > 1e-12 * largest) {
            return None;
        }
        let e1 = eigen.eigenvectors.column(order[0]).into_owned();
        let e2 = eigen.eigenvectors.column(order[1]).into_owned();
        Some(RotationGuess {
            axes: [e1, e2, e1.cross(&e2)],
        })
    }

    /// The guessed rotation for the moment `a`; `None` if it degenerates.
    fn rotation(&self, a: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        let [e1, e2, e3] = &self.axes;
        let g1 = (a * e1).try_normalize(0.0)?;
        let image = a * e2;
        let g2 = (image - g1 * g1.dot(&image)).try_normalize(1e-12 * image.norm())?;
        let g3 = g1.cross(&g2);
        let mut r = Matrix3::zeros();
        for (g, e) in [(&g1, e1), (&g2, e2), (&g3, e3)] {
            add_outer(&mut r, g, e);
        }
        Some(r)
    }
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
    /// principal axes' images ([`RotationGuess`]), else by [`nearest_rotation`].
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
    let axis = Vector3::new(
        turn[(2, 1)] - turn[(1, 2)],
        turn[(0, 2)] - turn[(2, 0)],
        turn[(1, 0)] - turn[(0, 1)],
    );
    (0.5 * axis.norm()).atan2(0.5 * (turn.trace() - 1.0))
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
    fn newton_polar_factor_recovers_the_rotation() {
        // a = R P with R a rotation and P symmetric positive definite of condition κ: the
        // iteration returns R, orthogonal with det +1 to round-off, within κ × round-off of
        // R and within the SVD's own error of the SVD's.
        let r = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.3, -1.1, 0.7)).into_inner();
        let q = nalgebra::Rotation3::from_scaled_axis(Vector3::new(-0.9, 0.2, 0.4)).into_inner();
        for kappa in [1.0, 1e2, 1e4, 1e6] {
            let p = q * Matrix3::from_diagonal(&Vector3::new(kappa, 3.0, 1.0)) * q.transpose();
            let a = r * p;
            let newton = polar_rotation(&a).expect("well conditioned");
            let svd = a.svd(true, true);
            let reference = svd.u.unwrap() * svd.v_t.unwrap();
            assert!((newton.transpose() * newton - Matrix3::identity()).norm() < 1e-14);
            assert!((newton.determinant() - 1.0).abs() < 1e-14);
            // The SVD here goes through `aᵀa` and loses `κ²` × round-off (4e-10 at κ = 1e4);
            // the iteration keeps to `κ` × round-off (1.2e-13 there).
            assert!(
                (newton - r).norm() < 1e-14 * kappa.max(10.0),
                "κ = {kappa:e}"
            );
            assert!(
                (newton - reference).norm() < 1e-15 * kappa * kappa + 1e-14,
                "κ = {kappa:e}"
            );
        }
        // A planar set (rank 2) and a reflection are the SVD's.
        let planar = r * Matrix3::from_diagonal(&Vector3::new(2.0, 1.0, 0.0));
        assert!(polar_rotation(&planar).is_none());
        let rotation = nearest_rotation(&planar);
        assert!((rotation.determinant() - 1.0).abs() < 1e-12);
        assert!((rotation * Vector3::x() - r * Vector3::x()).norm() < 1e-12);
        let reflection = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        assert!(polar_rotation(&reflection).is_none());
    }

    #[test]
    fn newton_on_the_rotation_is_the_polar_factor() {
        // a = R P as above, P off the reference moment J by a strain ε: from the guess of J's
        // principal axes' images the iteration on the rotation returns the polar factor to
        // κ × round-off, as the scaled Newton iteration does.
        let r = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.3, -1.1, 0.7)).into_inner();
        let q = nalgebra::Rotation3::from_scaled_axis(Vector3::new(-0.9, 0.2, 0.4)).into_inner();
        for kappa in [1.0, 1e2, 1e4, 1e6] {
            let j = q * Matrix3::from_diagonal(&Vector3::new(kappa, 3.0, 1.0)) * q.transpose();
            for strain in [0.0, 1e-3, 0.1, 0.3] {
                let e = strain * Matrix3::new(0.3, -0.5, 0.2, 0.1, 0.4, -0.6, 0.7, 0.2, -0.1);
                let a = r * (Matrix3::identity() + e) * j;
                let guess = RotationGuess::from_moment(&j)
                    .unwrap()
                    .rotation(&a)
                    .unwrap();
                let near = polar_rotation_near(&a, &guess).expect("converges");
                let newton = polar_rotation(&a).expect("well conditioned");
                assert!((near.transpose() * near - Matrix3::identity()).norm() < 1e-14);
                assert!((near.determinant() - 1.0).abs() < 1e-14);
                assert!(
                    (near - newton).norm() < 1e-14 * kappa.max(10.0),
                    "κ = {kappa:e}, ε = {strain}: {:e}",
                    (near - newton).norm()
                );
            }
        }
        // A guess half a turn away finds a stationary point that is not the polar factor, or
        // none: never a wrong rotation.
        let a = r * Matrix3::from_diagonal(&Vector3::new(3.0, 2.0, 1.0));
        let flipped = r * Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0));
        assert!(polar_rotation_near(&a, &flipped).is_none());
        // A planar moment (rank 2) and a reflection: the SVD's nearest rotation.
        for d in [
            Vector3::new(3.0, 2.0, 0.0),
            Vector3::new(3.0, 2.0, -1.0),
            Vector3::new(3.0, 2.0, -1e-3),
        ] {
            let a = r * Matrix3::from_diagonal(&d) * q;
            let svd = nearest_rotation(&a);
            let near = polar_rotation_near(&a, &(svd * q.transpose() * q)).expect("converges");
            assert!((near - svd).norm() < 1e-14, "{d:?}");
            let guess = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.1, -0.2, 0.15));
            let near = polar_rotation_near(&a, &(svd * guess.into_inner())).expect("converges");
            assert!(
                (near - svd).norm() < 1e-14,
                "{d:?}: {:e}",
                (near - svd).norm()
            );
        }
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

    #[test]
    fn reflected_cloud_still_gives_a_rotation() {
        let a = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0);
        let r = nearest_rotation(&a);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }
}
