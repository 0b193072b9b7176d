//! The slabs' own geometric stiffening (docs/formulation.md, "Geometric stiffening within the
//! slabs"): in each slab `p` the prestress of the slab's own deformation acts on that
//! deformation,
//!
//! `f_G,p = R_p (G_p ⊗ I3) ū_p`, `G_p = Σ_{e ∈ p} Σ_k S̄_e,k G_e,k`,
//! `S̄_e = D : sym(Σ_a ū_p,a ⊗ ḡ_e,a)`,
//!
//! with `S̄_e` the element's mean stress (Voigt, Pa), `G_e,k` its geometric stiffness per unit
//! stress component and `ḡ_e,a` its volume-mean shape-function gradients
//! ([`fem::geometric::unit_stress_geometric_stiffness`]). `G_p` is refreshed once per
//! communication step from the state at its start and held during it (as the one frame's
//! `K_G`). It is the work of the slab's prestress on the second-order part `½ ∇ūᵀ∇ū` of its
//! Green strain, which the slabs' linear strain leaves out, with the prestress frozen (the stress
//! of that nonlinear strain, the other term of the same order, is not included, and nothing is
//! added to the strain energy): B3's spin-up stiffens its slabs' bending by the axial stress of
//! the spin.

use crate::fem::{self, IsotropicMaterial};
use crate::mesh::Mesh;

/// One element's part of `G_p`.
#[derive(Debug, Clone)]
struct ElementStiffening {
    /// The element's nodes (the slab's local numbers).
    nodes: Vec<usize>,
    /// `ḡ_a` (1/m).
    mean_gradients: Vec<[f64; 3]>,
    /// `G_k` (m), upper triangles row by row.
    unit: [Vec<f64>; 6],
    /// `Σ_k S̄_k G_k` of the last update (N/m), upper triangle row by row.
    values: Vec<f64>,
    /// Lamé's `λ` and `μ` of the element's material (Pa).
    lame: (f64, f64),
}

/// The geometric stiffness of one slab's own prestress (see the module documentation).
#[derive(Debug, Clone)]
pub struct SlabStiffening {
    elements: Vec<ElementStiffening>,
}

impl SlabStiffening {
    /// The stiffening of the slab whose elements are those of `mesh` (the slab's local nodes),
    /// element `e` of `materials[e]`. Zero until the first [`Self::update`]. Set-up only
    /// (allocates).
    pub fn new(mesh: &Mesh, materials: &[IsotropicMaterial]) -> SlabStiffening {
        let elements = (0..mesh.element_count())
            .map(|e| {
                let (unit, mean_gradients) =
                    fem::geometric::unit_stress_geometric_stiffness(mesh, e);
                ElementStiffening {
                    nodes: mesh.element(e).to_vec(),
                    mean_gradients,
                    values: vec![0.0; unit[0].len()],
                    unit,
                    lame: (materials[e].lame_lambda(), materials[e].shear_modulus()),
                }
            })
            .collect();
        SlabStiffening { elements }
    }

    /// Refreshes `G_p` from the slab's local deformation `ubar` (m, flat over its local nodes).
    /// No allocation.
    pub fn update(&mut self, ubar: &[f64], scale: f64) {
        for element in &mut self.elements {
            let (lambda, mu) = element.lame;
            // grad[r][c] = ∂ū_r/∂X_c, the element's mean.
            let mut grad = [[0.0; 3]; 3];
            for (&a, g) in element.nodes.iter().zip(&element.mean_gradients) {
                let u = &ubar[3 * a..3 * a + 3];
                for r in 0..3 {
                    for c in 0..3 {
                        grad[r][c] += u[r] * g[c];
                    }
                }
            }
            let stress = fem::geometric::linear_stress(&grad, lambda, mu).map(|s| s * scale);
            element.values.fill(0.0);
            for (s, unit) in stress.iter().zip(&element.unit) {
                for (v, u) in element.values.iter_mut().zip(unit) {
                    *v += s * u;
                }
            }
        }
    }

    /// Adds `(G_p ⊗ I3) ū` to `f` (both flat over the slab's local nodes; N) and returns
    /// `½ ūᵀ (G_p ⊗ I3) ū` (J). No allocation.
    pub fn add_force(&self, ubar: &[f64], f: &mut [f64]) -> f64 {
        let mut twice_energy = 0.0;
        for element in &self.elements {
            let mut entry = 0;
            let nodes = &element.nodes;
            for (i, &a) in nodes.iter().enumerate() {
                let ua = [ubar[3 * a], ubar[3 * a + 1], ubar[3 * a + 2]];
                // The diagonal entry, then the pairs (a, b > a) both ways.
                let g = element.values[entry];
                entry += 1;
                let mut fa = [g * ua[0], g * ua[1], g * ua[2]];
                let mut off_diagonal = [0.0; 3];
                for &b in &nodes[i + 1..] {
                    let g = element.values[entry];
                    entry += 1;
                    for d in 0..3 {
                        off_diagonal[d] += g * ubar[3 * b + d];
                        f[3 * b + d] += g * ua[d];
                    }
                }
                for d in 0..3 {
                    twice_energy += ua[d] * (fa[d] + 2.0 * off_diagonal[d]);
                    fa[d] += off_diagonal[d];
                    f[3 * a + d] += fa[d];
                }
            }
        }
        0.5 * twice_energy
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::geometric::{geometric_stiffness, stress_at_gauss_points};
    use crate::mesh::{generator, ElementKind};

    #[test]
    fn an_affine_deformation_gives_the_geometric_stiffness_of_its_stress() {
        // An affine ū has the same stress at every Gauss point, so the element-mean prestress
        // is exact: G ⊗ I3 is `geometric_stiffness` of that stress, force and energy alike.
        let mesh = generator::beam(1.0, 0.1, 0.2, [3, 1, 2], ElementKind::Hex20).unwrap();
        let material = IsotropicMaterial::STEEL;
        let strain = [
            [1e-3, 2e-4, -3e-4],
            [-1e-4, -5e-4, 4e-4],
            [2e-4, 1e-4, 3e-4],
        ];
        let ubar: Vec<f64> = mesh
            .nodes()
            .iter()
            .flat_map(|x| {
                let mut u = [0.0; 3];
                for r in 0..3 {
                    for c in 0..3 {
                        u[r] += strain[r][c] * x[c];
                    }
                }
                u
            })
            .collect();
        let mut stiffening = SlabStiffening::new(&mesh, &vec![material; mesh.element_count()]);
        stiffening.update(&ubar, 1.0);
        let k_g = geometric_stiffness(&mesh, &stress_at_gauss_points(&mesh, &material, &ubar));
        let v: Vec<f64> = (0..ubar.len())
            .map(|k| 1e-3 * ((k * 7919 % 17) as f64 - 8.0))
            .collect();
        let mut expected = vec![0.0; v.len()];
        k_g.mul_vec(&v, &mut expected);
        let mut f = vec![0.0; v.len()];
        let energy = stiffening.add_force(&v, &mut f);
        let scale = expected.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(scale > 0.0);
        for (a, b) in f.iter().zip(&expected) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
        }
        let quadratic = 0.5 * crate::linalg::dot(&v, &expected);
        assert!((energy - quadratic).abs() <= 1e-12 * quadratic.abs());
    }
}
