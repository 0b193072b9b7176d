//! Geometric stiffening of the reduced-strain body (docs/formulation.md, "Geometric stiffening"):
//! `f_stiff = hR K_G(S0) ū` with the prestress `S0` either
//!
//! * `inertial`: the static stress of the co-moving frame's rigid acceleration field
//!   `a(X) = c̈ + α × X̄ + ω × (ω × X̄)` (body axes), linear in the 12 coefficients
//!   `c̈` (3), `α` (3) and `ω_a ω_b` (6, a ≤ b): `K_G = Σ_k c_k K_G,k` with the 12 unit load cases
//!   (body force `−ρ a_k`, clamped nodes held) precomputed once. On a reduced body the unit
//!   cases are projected on its fields, `(S ⊗ I3)ᵀ K_G,k (S ⊗ I3)`, and the coefficients come
//!   from the motion interface's driving motion, not from the state;
//! * `stress`: the stress of the current local deformation, `S0 = D : sym ∇ū`, `K_G` reassembled.
//!
//! Either way `K_G` is refreshed once per communication step and held during it.

use super::frame::{node, set_node, Frame};
use super::interface::DrivingFrame;
use super::reduction::Reduction;
use super::Body;
use crate::error::{Error, Result};
use crate::fem::geometric::{
    gauss_point_count, geometric_stiffness, geometric_stiffness_into, stiffness_pattern,
    stress_at_gauss_points, stress_at_gauss_points_into, weighted_sum_into,
};
use crate::fem::IsotropicMaterial;
use crate::linalg::SparseCholesky;
use crate::linalg::SymmetricCsr;
use crate::mesh::Mesh;
use nalgebra::{Matrix3, Vector3};

/// `f = K_G x` for `K_G` as [`GeometricStiffening::pattern`] holds it: the mesh's `3N × 3N`
/// matrix, or a reduced body's scalar factor `G_r` of `K_G = G_r ⊗ I3`
/// ([`Reduction::project_geometric_stiffness`]), told apart by the dimension (`s` against the
/// `3s` coordinates of `x`). No allocation.
pub fn geometric_stiffness_product(k_g: &SymmetricCsr, x: &[f64], f: &mut [f64]) {
    if 3 * k_g.n == x.len() {
        k_g.mul_nodes(x, f);
    } else {
        k_g.mul_vec(x, f);
    }
}

/// Which prestress drives the stiffening.
#[derive(Debug, Clone)]
pub enum GeometricStiffening {
    /// The 12 unit load cases' geometric stiffnesses and the largest magnitude of each one's
    /// entries (N/m per unit coefficient).
    Inertial {
        unit_cases: Vec<SymmetricCsr>,
        scales: Vec<f64>,
    },
    /// Gauss-point stresses and the local deformation (scratch).
    Stress {
        stresses: Vec<[f64; 6]>,
        local_deformation: Vec<f64>,
    },
}

/// The 12 coefficients of the co-moving frame's rigid acceleration field in body axes at the
/// state `(x, v, a)` (flat 3N): `c̈` (m/s²), `α` (rad/s², least squares of the acceleration
/// field about `c`, centripetal part removed), `ω_a ω_b` (a ≤ b: xx, yy, zz, xy, xz, yz; 1/s²).
/// `inertial` stiffening's `K_G = Σ_k c_k K_G,k`. O(N), no allocation.
pub fn inertial_coefficients(body: &Body, x: &[f64], v: &[f64], a: &[f64]) -> [f64; 12] {
    let fw = &body.frame_weights;
    let (frame, omega) = fw.moving_frame(x, v);
    let rt = frame.rotation.transpose();
    let c_ddot = rt * fw.centroid(a);
    let mut j = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for ((&n, &w), xb) in fw.nodes.iter().zip(&fw.weights).zip(&fw.reference_offsets) {
        let r = rt * (node(x, n) - frame.origin);
        let ai = rt * node(a, n) - c_ddot - omega.cross(&omega.cross(xb));
        j += w * (Matrix3::identity() * r.norm_squared() - r * r.transpose());
        b += w * r.cross(&ai);
    }
    let alpha = j.try_inverse().unwrap_or_else(Matrix3::zeros) * b;
    coefficients(&c_ddot, &alpha, &omega)
}

/// A term of `inertial`'s sum below this fraction of the largest, `|c_k| max|K_G,k|` (about
/// 45 ε), is negligible against it and left out: on a planar motion the others are the
/// round-off of the frame's axes.
const NEGLIGIBLE_TERM: f64 = 1e-14;

/// The 12 coefficients of the rigid acceleration field of a motion interface's `driving` motion
/// (its point `p`, `ω`, and the mean rates `α`, `a_p` of [`DrivingFrame`]), in the axes of the
/// body's co-moving `frame` (docs/formulation.md, "The reduced body": stiffening from the
/// driving motion): the field's acceleration at the frame's origin `c`,
/// `c̈ = Rᵀ (a_p + α × r + ω × (ω × r))` with `r = c − p`, then `Rᵀα` and `ω̄_a ω̄_b` with
/// `ω̄ = Rᵀω`, in the order of [`inertial_coefficients`]. Unlike those, they do not see the
/// body's own vibration, which through `f_stiff` would feed back on itself.
pub fn driven_inertial_coefficients(frame: &Frame, driving: &DrivingFrame) -> [f64; 12] {
    let rt = frame.rotation.transpose();
    let (w, r) = (driving.angular_velocity, frame.origin - driving.position);
    let c_ddot = rt
        * (driving.acceleration + driving.angular_acceleration.cross(&r) + w.cross(&w.cross(&r)));
    coefficients(&c_ddot, &(rt * driving.angular_acceleration), &(rt * w))
}

/// The 12 coefficients in their order: `c̈`, `α`, then `ω_a ω_b` for (a, b) = xx, yy, zz, xy,
/// xz, yz ([`unit_field`]'s order).
fn coefficients(c_ddot: &Vector3<f64>, alpha: &Vector3<f64>, w: &Vector3<f64>) -> [f64; 12] {
    [
        c_ddot.x,
        c_ddot.y,
        c_ddot.z,
        alpha.x,
        alpha.y,
        alpha.z,
        w.x * w.x,
        w.y * w.y,
        w.z * w.z,
        w.x * w.y,
        w.x * w.z,
        w.y * w.z,
    ]
}

/// The unit rigid acceleration field `k` (0..12) at the reference offset `xb`.
fn unit_field(k: usize, xb: &Vector3<f64>) -> Vector3<f64> {
    let e = |j: usize| Vector3::ith(j, 1.0);
    match k {
        0..=2 => e(k),
        3..=5 => e(k - 3).cross(xb),
        _ => {
            // ω × (ω × X̄) = Σ_{a≤b} ω_a ω_b T_ab(X̄): T_aa = e_a X̄_a − X̄,
            // T_ab = e_a X̄_b + e_b X̄_a (a < b).
            let (a, b) = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)][k - 6];
            if a == b {
                e(a) * xb[a] - xb
            } else {
                e(a) * xb[b] + e(b) * xb[a]
            }
        }
    }
}

impl GeometricStiffening {
    /// `inertial` stiffening for `body` held at its `clamped` nodes (error for an unsupported
    /// body: its unit load cases would need inertia relief, which is not implemented).
    pub fn inertial(
        mesh: &Mesh,
        material: &IsotropicMaterial,
        body: &Body,
        clamped: &[bool],
    ) -> Result<GeometricStiffening> {
        let free: Vec<usize> = (0..body.node_count()).filter(|&i| !clamped[i]).collect();
        if free.len() == body.node_count() {
            return Err(Error::new(
                "model.stiffening = inertial needs a fixed support or a motion interface (an unsupported body would need inertia relief)",
            ));
        }
        let dofs: Vec<usize> = free
            .iter()
            .flat_map(|&i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        // The unit cases' static solves need the elements inside rigid sets (whose constraints
        // these solves do not see) to keep `K` positive definite.
        let stiffness = body
            .modal_stiffness
            .as_ref()
            .unwrap_or(&body.stiffness_matrix);
        let factor = SparseCholesky::new(&stiffness.submatrix(&dofs))?;
        let mut workspace = factor.solve_scratch();
        let fw = &body.frame_weights;
        let n3 = body.reference.len();
        let (mut field, mut load) = (vec![0.0; n3], vec![0.0; n3]);
        let mut unit_cases = Vec::with_capacity(12);
        for k in 0..12 {
            for i in 0..body.node_count() {
                set_node(&mut field, i, &unit_field(k, &fw.reference_offsets[i]));
            }
            body.mass_times(&field, &mut load); // M a_k; the body force is −M a_k
            let mut rhs: Vec<f64> = dofs.iter().map(|&d| -load[d]).collect();
            factor.solve_in_place(&mut rhs, &mut workspace);
            let mut u = vec![0.0; n3];
            for (&d, v) in dofs.iter().zip(&rhs) {
                u[d] = *v;
            }
            unit_cases.push(geometric_stiffness(
                mesh,
                &stress_at_gauss_points(mesh, material, &u),
            ));
        }
        Ok(GeometricStiffening::inertial_of(unit_cases))
    }

    /// `inertial` stiffening of a reduced body: the mesh body's unit cases (`mesh_body`, held
    /// at its `clamped` nodes) projected on the basis, `(S ⊗ I3)ᵀ K_G,k (S ⊗ I3)`
    /// (docs/formulation.md, "The reduced body": geometric stiffening). The prestress is the
    /// mesh's static response to each unit field, not the modes'.
    pub fn inertial_reduced(
        mesh: &Mesh,
        material: &IsotropicMaterial,
        mesh_body: &Body,
        clamped: &[bool],
        reduction: &Reduction,
    ) -> Result<GeometricStiffening> {
        let GeometricStiffening::Inertial { unit_cases, .. } =
            GeometricStiffening::inertial(mesh, material, mesh_body, clamped)?
        else {
            unreachable!("inertial builds the unit cases")
        };
        Ok(GeometricStiffening::inertial_of(
            unit_cases
                .iter()
                .map(|k| reduction.project_geometric_stiffness(k))
                .collect(),
        ))
    }

    /// `inertial` stiffening of its 12 unit cases.
    fn inertial_of(unit_cases: Vec<SymmetricCsr>) -> GeometricStiffening {
        let scales = unit_cases
            .iter()
            .map(|k| k.values.iter().fold(0.0, |m: f64, v| m.max(v.abs())))
            .collect();
        GeometricStiffening::Inertial { unit_cases, scales }
    }

    /// `stress` stiffening.
    pub fn stress(mesh: &Mesh, body: &Body) -> GeometricStiffening {
        GeometricStiffening::Stress {
            stresses: vec![[0.0; 6]; gauss_point_count(mesh)],
            local_deformation: vec![0.0; body.reference.len()],
        }
    }

    /// The 12 unit load cases' geometric stiffnesses (`inertial` only).
    pub fn unit_cases(&self) -> Option<&[SymmetricCsr]> {
        match self {
            GeometricStiffening::Inertial { unit_cases, .. } => Some(unit_cases),
            GeometricStiffening::Stress { .. } => None,
        }
    }

    /// A zero matrix with the pattern of `K_G`: the mesh's (`3N × 3N`), or a reduced body's
    /// scalar factor `G_r` of `K_G = G_r ⊗ I3` (`s × s`, dense; [`geometric_stiffness_product`]).
    pub fn pattern(&self, mesh: &Mesh) -> SymmetricCsr {
        match self {
            GeometricStiffening::Inertial { unit_cases, .. } => {
                let mut pattern = unit_cases[0].clone();
                pattern.values.fill(0.0);
                pattern
            }
            GeometricStiffening::Stress { .. } => stiffness_pattern(mesh),
        }
    }

    /// Refreshes `k_g` for the state `(x, v, a)` (flat 3N). `inertial` takes the `driven`
    /// coefficients when given (a reduced body's: [`driven_inertial_coefficients`]), else those
    /// of the state ([`inertial_coefficients`]).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        mesh: &Mesh,
        material: &IsotropicMaterial,
        body: &Body,
        x: &[f64],
        v: &[f64],
        a: &[f64],
        driven: Option<&[f64; 12]>,
        k_g: &mut SymmetricCsr,
    ) {
        match self {
            GeometricStiffening::Inertial { unit_cases, scales } => {
                let c = driven
                    .copied()
                    .unwrap_or_else(|| inertial_coefficients(body, x, v, a));
                // A term below `NEGLIGIBLE_TERM` of the largest is left out: a planar motion
                // has 4 terms, the others round-off of the frame's axes.
                let size = |k: usize| (c[k] * scales[k]).abs();
                let largest = (0..12).map(size).fold(0.0, f64::max);
                let mut terms: [(f64, &SymmetricCsr); 12] = [(0.0, &unit_cases[0]); 12];
                let mut count = 0;
                for k in (0..12).filter(|&k| size(k) > NEGLIGIBLE_TERM * largest) {
                    terms[count] = (c[k], &unit_cases[k]);
                    count += 1;
                }
                weighted_sum_into(k_g, &terms[..count]);
            }
            GeometricStiffening::Stress {
                stresses,
                local_deformation,
            } => {
                let fw = &body.frame_weights;
                let frame = fw.best_fit(x);
                let rt = frame.rotation.transpose();
                for i in 0..body.node_count() {
                    let u = rt * (node(x, i) - frame.origin) - fw.reference_offsets[i];
                    set_node(local_deformation, i, &u);
                }
                stress_at_gauss_points_into(mesh, material, local_deformation, stresses);
                geometric_stiffness_into(mesh, stresses, k_g);
            }
        }
    }
}
