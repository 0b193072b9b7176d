//! A lumped rigid body carried by a rigid attachment (docs/formulation.md, "Rigid attachments"):
//! a hub, a motor rotor, a tip mass, given by its mass, centre of mass and inertia tensor.
//!
//! It enters the body as six point masses ("mass points", extra nodes without stiffness) that
//! move rigidly with the attachment's node set: `m/6` each at `x_c ± s_k v_k`, `s_k = √(3 θ_k/m)`,
//! with `θ_k`, `v_k` the eigenpairs of the second moment about the centre of mass
//! `Θ_c = ½ tr(I_c) 1 − I_c` (`I_c` the inertia tensor about the centre of mass). The six points
//! have the body's mass, centre of mass and second moment (`Σ (m/6) 2 s_k² v_k v_kᵀ = Θ_c`), so
//! moving rigidly they have its kinetic energy `½ m |v_c|² + ½ ωᵀ I ω` exactly; the mass matrix
//! stays constant (`m/6` on the diagonal of `Ms`).

use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};

/// A rigid body's inertia in body coordinates (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedBody {
    /// Mass (kg), positive.
    pub mass: f64,
    /// Centre of mass (m, reference coordinates).
    pub center_of_mass: Vector3<f64>,
    /// Inertia tensor about `point` (kg m²), symmetric.
    pub inertia: Matrix3<f64>,
    /// The point `inertia` is taken about (m, reference coordinates): the interface's reference
    /// point.
    pub point: Vector3<f64>,
}

impl LumpedBody {
    /// The inertia tensor about the centre of mass (parallel axes): `I_c = I_p − m (|d|² 1 − d dᵀ)`,
    /// `d = x_c − p`.
    pub fn central_inertia(&self) -> Matrix3<f64> {
        let d = self.center_of_mass - self.point;
        self.inertia - self.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose())
    }

    /// The six mass points `(position, mass)` (reference coordinates). Error, naming
    /// `interface`, if the mass is not positive and finite or the inertia is not that of a rigid
    /// body (symmetric, its central principal moments non-negative and satisfying the triangle
    /// inequalities `I_a ≤ I_b + I_c`, i.e. `Θ_c` positive semi-definite).
    pub fn mass_points(&self, interface: &str) -> Result<Vec<(Vector3<f64>, f64)>> {
        let m = self.mass;
        if !(m.is_finite() && m > 0.0) {
            return Err(Error::new(format!(
                "interface '{interface}': mass = {m} kg; a lumped body needs a positive, finite mass"
            )));
        }
        let i_p = self.inertia;
        let scale = i_p.abs().max().max(m * 1e-300);
        if !i_p.iter().all(|v| v.is_finite())
            || !self.center_of_mass.iter().all(|v| v.is_finite())
            || (i_p - i_p.transpose()).abs().max() > 1e-9 * scale
        {
            return Err(Error::new(format!(
                "interface '{interface}': inertia {:?} kg m² (about the reference point) must be finite and symmetric, centerOfMass {:?} finite",
                i_p.transpose().as_slice(),
                self.center_of_mass.as_slice()
            )));
        }
        let i_c = self.central_inertia();
        let theta = Matrix3::identity() * (0.5 * i_c.trace()) - i_c;
        let eigen = theta.symmetric_eigen();
        let tolerance = 1e-9 * (scale + m * (self.center_of_mass - self.point).norm_squared());
        if eigen.eigenvalues.min() < -tolerance {
            return Err(Error::new(format!(
                "interface '{interface}': inertia {:?} kg m² about the reference point is not that of a rigid body of mass {m} kg with its centre of mass at {:?}: its central principal moments {:?} must be non-negative and each at most the sum of the other two",
                i_p.transpose().as_slice(),
                self.center_of_mass.as_slice(),
                i_c.symmetric_eigenvalues().as_slice()
            )));
        }
        let mut points = Vec::with_capacity(6);
        for k in 0..3 {
            let s = (3.0 * eigen.eigenvalues[k].max(0.0) / m).sqrt();
            let v = eigen.eigenvectors.column(k).into_owned();
            points.push((self.center_of_mass + s * v, m / 6.0));
            points.push((self.center_of_mass - s * v, m / 6.0));
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The six points have the body's mass, first moment and inertia about any point.
    #[test]
    fn the_mass_points_carry_mass_centre_and_inertia() {
        let body = LumpedBody {
            mass: 3.0,
            center_of_mass: Vector3::new(0.1, -0.2, 0.05),
            inertia: Matrix3::new(0.9, 0.02, -0.01, 0.02, 0.7, 0.03, -0.01, 0.03, 0.5),
            point: Vector3::new(0.0, 0.1, 0.0),
        };
        let points = body.mass_points("hub").unwrap();
        let mass: f64 = points.iter().map(|p| p.1).sum();
        let centre = points.iter().map(|p| p.1 * p.0).sum::<Vector3<f64>>() / mass;
        let inertia = points.iter().fold(Matrix3::zeros(), |i, (x, m)| {
            let r = x - body.point;
            i + *m * (Matrix3::identity() * r.norm_squared() - r * r.transpose())
        });
        assert!((mass - 3.0).abs() < 1e-14);
        assert!((centre - body.center_of_mass).norm() < 1e-14);
        assert!((inertia - body.inertia).abs().max() < 1e-14, "{inertia}");
    }

    #[test]
    fn an_impossible_inertia_is_refused_by_name() {
        // A rod along x has I_xx = 0 ≤ I_yy + I_zz; I_xx = 3 > 1 + 1 is no rigid body.
        let body = LumpedBody {
            mass: 1.0,
            center_of_mass: Vector3::zeros(),
            inertia: Matrix3::from_diagonal(&Vector3::new(3.0, 1.0, 1.0)),
            point: Vector3::zeros(),
        };
        let e = body.mass_points("hub").unwrap_err();
        assert!(
            e.message.contains("'hub'") && e.message.contains("not that of a rigid body"),
            "{}",
            e.message
        );
        let point = LumpedBody {
            inertia: Matrix3::zeros(),
            ..body
        };
        assert_eq!(point.mass_points("tip").unwrap().len(), 6);
        let massless = LumpedBody { mass: 0.0, ..point };
        assert!(massless
            .mass_points("tip")
            .unwrap_err()
            .message
            .contains("mass = 0"));
    }
}
