//! The Radau IIA tableau (3 stages, order 5) and the eigen-decomposition of `A⁻¹` that turns
//! the stage system into one real and one complex system.

use nalgebra::{Complex, Matrix3, Vector3};

/// The Radau IIA (s = 3) tableau and the eigen-decomposition of `A⁻¹`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadauIIA {
    /// Nodes `c = ((4 − √6)/10, (4 + √6)/10, 1)`.
    pub c: [f64; 3],
    /// The Runge–Kutta matrix `A`.
    pub a: Matrix3<f64>,
    /// `A⁻¹` and `A⁻²`.
    pub a_inv: Matrix3<f64>,
    pub a_inv2: Matrix3<f64>,
    /// `A⁻¹ 𝟙`.
    pub a_inv_sums: Vector3<f64>,
    /// `T` with `T⁻¹ A⁻¹ T = diag(γ, [[α, −β], [β, α]])`, and `T⁻¹`.
    pub t: Matrix3<f64>,
    pub t_inv: Matrix3<f64>,
    pub gamma: f64,
    pub alpha: f64,
    pub beta: f64,
}

impl Default for RadauIIA {
    fn default() -> Self {
        Self::new()
    }
}

impl RadauIIA {
    pub fn new() -> RadauIIA {
        let s6 = 6.0_f64.sqrt();
        let a = Matrix3::new(
            (88.0 - 7.0 * s6) / 360.0,
            (296.0 - 169.0 * s6) / 1800.0,
            (-2.0 + 3.0 * s6) / 225.0,
            (296.0 + 169.0 * s6) / 1800.0,
            (88.0 + 7.0 * s6) / 360.0,
            (-2.0 - 3.0 * s6) / 225.0,
            (16.0 - s6) / 36.0,
            (16.0 + s6) / 36.0,
            1.0 / 9.0,
        );
        let a_inv = a.try_inverse().expect("the Radau matrix is invertible");
        let eigenvalues = a_inv.complex_eigenvalues();
        let (mut gamma, mut lambda) = (0.0, Complex::new(0.0, 0.0));
        for e in eigenvalues.iter() {
            if e.im.abs() < 1e-8 {
                gamma = e.re;
            } else if e.im < 0.0 {
                lambda = *e; // α − iβ
            }
        }
        // Null vectors of the rank-2 matrices A⁻¹ − λI: the (bilinear) cross product of two
        // independent rows.
        let null_vector = |lambda: Complex<f64>| -> [Complex<f64>; 3] {
            let row = |i: usize| -> [Complex<f64>; 3] {
                let mut r = [Complex::new(0.0, 0.0); 3];
                for (j, v) in r.iter_mut().enumerate() {
                    *v = Complex::new(a_inv[(i, j)], 0.0)
                        - if i == j {
                            lambda
                        } else {
                            Complex::new(0.0, 0.0)
                        };
                }
                r
            };
            let (p, q) = (row(0), row(1));
            [
                p[1] * q[2] - p[2] * q[1],
                p[2] * q[0] - p[0] * q[2],
                p[0] * q[1] - p[1] * q[0],
            ]
        };
        let v1 = null_vector(Complex::new(gamma, 0.0));
        let v2 = null_vector(lambda);
        let t = Matrix3::new(
            v1[0].re, v2[0].re, v2[0].im, v1[1].re, v2[1].re, v2[1].im, v1[2].re, v2[2].re,
            v2[2].im,
        );
        let t_inv = t.try_inverse().expect("A⁻¹ is diagonalisable");
        RadauIIA {
            c: [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0],
            a,
            a_inv,
            a_inv2: a_inv * a_inv,
            a_inv_sums: a_inv * Vector3::repeat(1.0),
            t,
            t_inv,
            gamma,
            alpha: lambda.re,
            beta: -lambda.im,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tableau_is_radau_iia_and_its_decomposition_is_exact() {
        let r = RadauIIA::new();
        // Row sums of A are c (C(1)); A c = c²/2 (C(2)); the last row is b (stiffly accurate).
        for i in 0..3 {
            let row: f64 = (0..3).map(|j| r.a[(i, j)]).sum();
            assert!((row - r.c[i]).abs() < 1e-15);
            let ac: f64 = (0..3).map(|j| r.a[(i, j)] * r.c[j]).sum();
            assert!((ac - 0.5 * r.c[i] * r.c[i]).abs() < 1e-15);
        }
        // Hairer–Wanner's values of the eigenvalues of A⁻¹.
        assert!(
            (r.gamma - 3.637_834_252_744_496).abs() < 1e-12,
            "{}",
            r.gamma
        );
        assert!(
            (r.alpha - 2.681_082_873_627_752).abs() < 1e-12,
            "{}",
            r.alpha
        );
        assert!((r.beta - 3.050_430_199_247_41).abs() < 1e-12, "{}", r.beta);
        let block = r.t_inv * r.a_inv * r.t;
        let expected = Matrix3::new(
            r.gamma, 0.0, 0.0, 0.0, r.alpha, -r.beta, 0.0, r.beta, r.alpha,
        );
        assert!((block - expected).amax() < 1e-12, "{block}");
    }
}
