//! Small-strain stress at the nodes, for looking at results: `σ = λ tr(ε) I + 2μ ε` with
//! `ε = sym ∇u`, evaluated in every element at its own nodes (natural coordinates of the node,
//! [`natural_coordinates`]) and averaged over the elements that share a node (unweighted). The
//! von Mises equivalent stress `σ_v = sqrt(½((σ₁−σ₂)² + (σ₂−σ₃)² + (σ₃−σ₁)²))`, computed from the
//! components as `sqrt(σ_xx² + σ_yy² + σ_zz² − σ_xxσ_yy − σ_yyσ_zz − σ_zzσ_xx + 3(σ_xy² + σ_yz² + σ_xz²))`.

use super::IsotropicMaterial;
use crate::element::{natural_coordinates, physical_gradients, shape_functions, MAX_NODES};
use crate::mesh::Mesh;

/// Nodal-averaged small-strain stress (Pa, Voigt `[xx, yy, zz, yz, xz, xy]`) of the displacement
/// `u` (m, flat `3N`, any frame: the stress is in the same axes).
pub fn nodal_stress(mesh: &Mesh, material: &IsotropicMaterial, u: &[f64]) -> Vec<[f64; 6]> {
    let kind = mesh.kind();
    let n = kind.node_count();
    let lambda = material.lame_lambda();
    let mu = material.shear_modulus();
    let natural = natural_coordinates(kind);
    let mut derivatives = vec![[[0.0; 3]; MAX_NODES]; n];
    let mut values = [0.0; MAX_NODES];
    for (a, xi) in natural.iter().enumerate() {
        shape_functions(kind, *xi, &mut values, &mut derivatives[a]);
    }
    let mut sum = vec![[0.0; 6]; mesh.node_count()];
    let mut count = vec![0u32; mesh.node_count()];
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut g = [[0.0; 3]; MAX_NODES];
    for e in 0..mesh.element_count() {
        let nodes = mesh.element(e);
        for (c, &node) in coords.iter_mut().zip(nodes) {
            *c = mesh.nodes()[node];
        }
        for (a, &node) in nodes.iter().enumerate() {
            if physical_gradients(&coords[..n], &derivatives[a][..n], &mut g[..n]) <= 0.0 {
                continue; // cannot happen on a validated mesh
            }
            let mut h = [[0.0; 3]; 3]; // ∂u_r/∂x_c
            for (gb, &b) in g[..n].iter().zip(nodes) {
                for r in 0..3 {
                    for c in 0..3 {
                        h[r][c] += u[3 * b + r] * gb[c];
                    }
                }
            }
            let trace = h[0][0] + h[1][1] + h[2][2];
            let s = &mut sum[node];
            s[0] += lambda * trace + 2.0 * mu * h[0][0];
            s[1] += lambda * trace + 2.0 * mu * h[1][1];
            s[2] += lambda * trace + 2.0 * mu * h[2][2];
            s[3] += mu * (h[1][2] + h[2][1]);
            s[4] += mu * (h[0][2] + h[2][0]);
            s[5] += mu * (h[0][1] + h[1][0]);
            count[node] += 1;
        }
    }
    for (s, &c) in sum.iter_mut().zip(&count) {
        if c > 0 {
            for v in s.iter_mut() {
                *v /= c as f64;
            }
        }
    }
    sum
}

/// The von Mises equivalent of a Voigt stress `[xx, yy, zz, yz, xz, xy]` (Pa).
pub fn von_mises(s: &[f64; 6]) -> f64 {
    let [xx, yy, zz, yz, xz, xy] = *s;
    (xx * xx + yy * yy + zz * zz - xx * yy - yy * zz - zz * xx
        + 3.0 * (xy * xy + yz * yz + xz * xz))
        .max(0.0)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{beam, ElementKind};

    #[test]
    fn uniaxial_stretch_gives_e_times_strain_without_lateral_stress() {
        // u = (ε x, −ν ε y, −ν ε z): uniaxial stress σ_xx = E ε, all else zero, exactly
        // reproduced by every element kind (linear field), so von Mises = E ε to round-off.
        let material = IsotropicMaterial::STEEL;
        let (eps, nu) = (1e-4, material.poisson_ratio);
        for kind in ElementKind::ALL {
            let mesh = beam(0.4, 0.1, 0.2, [3, 2, 2], kind).unwrap();
            let u: Vec<f64> = mesh
                .nodes()
                .iter()
                .flat_map(|p| [eps * p[0], -nu * eps * p[1], -nu * eps * p[2]])
                .collect();
            let expected = material.youngs_modulus * eps;
            for s in nodal_stress(&mesh, &material, &u) {
                assert!((s[0] / expected - 1.0).abs() < 1e-10, "{kind:?}: {s:?}");
                for c in 1..6 {
                    assert!(s[c].abs() < 1e-10 * expected, "{kind:?}: {s:?}");
                }
                assert!((von_mises(&s) / expected - 1.0).abs() < 1e-10);
            }
        }
        // Pure shear τ: von Mises √3 τ.
        assert!((von_mises(&[0.0, 0.0, 0.0, 0.0, 0.0, 2.0]) - 2.0 * 3f64.sqrt()).abs() < 1e-12);
    }
}
