//! The rotation factor of the polar decomposition `a = R P` (docs/formulation.md, "The co-moving
//! frame"): the rotation nearest to a 3 × 3 matrix, which the best-fit frames take from their
//! moment `A = Σ w_i (x_i − c) X̄_iᵀ`. On the step's path by Newton's iteration on the rotation
//! from a guess ([`polar_rotation_near`], [`RotationGuess`]); else by Higham's scaled Newton
//! iteration ([`polar_rotation`]) or the SVD ([`nearest_rotation`]).

use super::frame::{add_outer, skew};
use nalgebra::{Matrix3, Vector3};

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
        if !theta.iter().all(|t| t.is_finite()) {
            return None;
        }
        let phi = 0.5 * theta;
        let k = skew(&phi);
        r *= Matrix3::identity() + (2.0 / (1.0 + phi.norm_squared())) * (k + k * k);
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

/// The first guess of a best-fit frame's rotation from its moment `A`
/// ([`super::FrameWeights::best_fit`]). At the reference `A_ref = Σ_k X̄_k a_kᵀ = Σ w_i X̄_i X̄_iᵀ =
/// Σ_j λ_j e_j e_jᵀ` (`λ₁ ≥ λ₂ ≥ λ₃ ≥ 0`), and a body turned by `R` and strained has
/// `A ≈ R A_ref`, so `A e_j ≈ λ_j R e_j`: the images of the two principal axes of the largest
/// moments, `A e₁` and `A e₂`, are `R e₁` and `R e₂` up to the strain and their lengths, and
/// the best determined (a thin direction's image is the strain's noise over `λ₃`). The guess
/// is `g₁ = A e₁` normalised, `g₂` the part of `A e₂` normal to it normalised, `g₃ = g₁ × g₂`,
/// put back on the axes: `R̃ = Σ_j g_j e_jᵀ` (`e₃ = e₁ × e₂`). A planar set (`λ₃ = 0`) needs
/// nothing else; a collinear set (`λ₂ ≤ 1e-12 λ₁`) has no guess.
#[derive(Debug, Clone, Copy)]
pub(super) struct RotationGuess {
    /// `e₁, e₂, e₁ × e₂`.
    axes: [Vector3<f64>; 3],
}

impl RotationGuess {
    /// From the reference offsets and arms ([`Self::from_moment`]).
    pub(super) fn new(offsets: &[Vector3<f64>], arms: &[Vector3<f64>]) -> Option<RotationGuess> {
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
    pub(super) fn rotation(&self, a: &Matrix3<f64>) -> Option<Matrix3<f64>> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The turn `R` of the tests' moments `a = R P` and the principal axes `Q` of `P`.
    fn turn_and_axes() -> (Matrix3<f64>, Matrix3<f64>) {
        let turn = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.3, -1.1, 0.7));
        let axes = nalgebra::Rotation3::from_scaled_axis(Vector3::new(-0.9, 0.2, 0.4));
        (turn.into_inner(), axes.into_inner())
    }

    #[test]
    fn newton_polar_factor_recovers_the_rotation() {
        // a = R P with R a rotation and P symmetric positive definite of condition κ: the
        // iteration returns R, orthogonal with det +1 to round-off, within κ × round-off of
        // R and within the SVD's own error of the SVD's.
        let (r, q) = turn_and_axes();
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
        let (r, q) = turn_and_axes();
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
    fn reflected_cloud_still_gives_a_rotation() {
        let a = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0);
        let r = nearest_rotation(&a);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }
}
