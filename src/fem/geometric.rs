//! Geometric (initial-stress) stiffness of a prestress field, and the small-strain stress at the
//! Gauss points that such a field is usually made of.
//!
//! With a prestress `S0` (second Piola–Kirchhoff, Pa) the nonlinear part of the Green strain,
//! `E_nl = ½ ∇uᵀ∇u`, adds the energy `∫ S0 : ½ ∇uᵀ∇u dV = ½ uᵀ K_G u`, whose second variation is
//!
//! ```text
//!     K_G[3a+d, 3b+e] = δ_de Σ_gp w_gp det J_gp (∇N_a · S0_gp ∇N_b)        (N/m)
//! ```
//!
//! (`∇N_a` the physical shape-function gradients, 1/m). `K_G` is symmetric, linear in `S0`, and
//! block-diagonal in the directions (`(∇N_a · S0 ∇N_b) I3` per node pair). It is integrated with
//! the same rule as `K` ([`integration_rule`]), one stress per Gauss point.
//!
//! **Gauss-point order** (of [`stress_at_gauss_points`] and of the `stress` argument of the
//! assembly routines): element by element (`e = 0, 1, …`), and within an element the points of
//! [`integration_rule`]`(kind)` in that rule's order (for the hexahedra ξ fastest, then η, then
//! ζ). Index `e · p + q` with `p` = [`gauss_points_per_element`]. Stresses are Voigt
//! vectors `[σ_xx, σ_yy, σ_zz, σ_yz, σ_xz, σ_xy]` (Pa).
//!
//! **Pattern.** Every matrix built here has exactly the sparsity pattern of
//! [`stiffness_matrix`](super::stiffness_matrix) (row `3i+d` holds the columns `3j+e`, `e = 0, 1,
//! 2`, of every node `j` sharing an element with node `i`, ascending), even though the entries
//! with `d ≠ e` of `K_G` are zero. So [`SymmetricCsr::linear_combination`] of `K` and `K_G`
//! keeps `K`'s pattern, and [`weighted_sum_into`] can combine `K`, `K_G` and precomputed unit
//! cases value by value without looking at indices.

pub use super::assembly::stiffness_pattern;
use super::IsotropicMaterial;
use crate::element::{integration_rule, physical_gradients, shape_functions, MAX_NODES};
use crate::linalg::SymmetricCsr;
use crate::mesh::{ElementKind, Mesh};

/// Gauss points of the stiffness rule per element of `kind` (8 for Hex8, 27 for Hex20, 1 for
/// Tet4, 4 for Tet10).
pub fn gauss_points_per_element(kind: ElementKind) -> usize {
    match kind {
        ElementKind::Hex8 => 8,
        ElementKind::Hex20 => 27,
        ElementKind::Tet4 => 1,
        ElementKind::Tet10 => 4,
    }
}

/// Gauss points of the whole mesh: `element_count × gauss_points_per_element`.
pub fn gauss_point_count(mesh: &Mesh) -> usize {
    mesh.element_count() * gauss_points_per_element(mesh.kind())
}

/// Natural derivatives of the shape functions at the points of the full rule of `kind`, and the
/// rule's weights.
struct ReferenceGradients {
    weights: Vec<f64>,
    derivatives: Vec<[[f64; 3]; MAX_NODES]>,
}

impl ReferenceGradients {
    fn new(kind: ElementKind) -> ReferenceGradients {
        let rule = integration_rule(kind);
        let mut values = [0.0; MAX_NODES];
        let derivatives = rule
            .iter()
            .map(|q| {
                let mut d = [[0.0; 3]; MAX_NODES];
                shape_functions(kind, q.xi, &mut values, &mut d);
                d
            })
            .collect();
        ReferenceGradients {
            weights: rule.iter().map(|q| q.weight).collect(),
            derivatives,
        }
    }
}

/// Copies the coordinates of the nodes of element `e` into `coords`.
fn element_coordinates(mesh: &Mesh, e: usize, coords: &mut [[f64; 3]; MAX_NODES]) {
    for (c, &node) in coords.iter_mut().zip(mesh.element(e)) {
        *c = mesh.nodes()[node];
    }
}

/// The linear (small-strain) stress `σ = D ε(u)` (Pa) of the displacement `u` (m, DOF
/// `3·node + direction`, length `3N`) at every Gauss point of the full rule, in the order of the
/// module doc, Voigt `[xx, yy, zz, yz, xz, xy]`. `ε = sym ∇u`; for the isotropic `D`
/// (see [`IsotropicMaterial::elasticity_matrix`]) `σ = λ tr(ε) I + 2μ ε`.
pub fn stress_at_gauss_points(
    mesh: &Mesh,
    material: &IsotropicMaterial,
    u: &[f64],
) -> Vec<[f64; 6]> {
    let mut stress = vec![[0.0; 6]; gauss_point_count(mesh)];
    stress_at_gauss_points_into(mesh, material, u, &mut stress);
    stress
}

/// [`stress_at_gauss_points`] into `stress` (length [`gauss_point_count`]), without allocating
/// beyond the reference element's rule (a few hundred numbers).
/// Panics if `u` or `stress` has the wrong length or an element is inverted.
pub fn stress_at_gauss_points_into(
    mesh: &Mesh,
    material: &IsotropicMaterial,
    u: &[f64],
    stress: &mut [[f64; 6]],
) {
    assert_eq!(
        u.len(),
        3 * mesh.node_count(),
        "stress_at_gauss_points: u has the wrong length"
    );
    assert_eq!(
        stress.len(),
        gauss_point_count(mesh),
        "stress_at_gauss_points: stress has the wrong length"
    );
    let reference = ReferenceGradients::new(mesh.kind());
    let n = mesh.kind().node_count();
    let p = reference.weights.len();
    let lambda = material.lame_lambda();
    let mu = material.shear_modulus();
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    for e in 0..mesh.element_count() {
        element_coordinates(mesh, e, &mut coords);
        let nodes = mesh.element(e);
        for q in 0..p {
            let det = physical_gradients(
                &coords[..n],
                &reference.derivatives[q][..n],
                &mut gradients[..n],
            );
            assert!(det > 0.0, "stress_at_gauss_points: element {e} inverted");
            // grad[r][c] = ∂u_r/∂x_c.
            let mut grad = [[0.0; 3]; 3];
            for (g, &node) in gradients[..n].iter().zip(nodes) {
                let ua = &u[3 * node..3 * node + 3];
                for r in 0..3 {
                    for c in 0..3 {
                        grad[r][c] += ua[r] * g[c];
                    }
                }
            }
            stress[e * p + q] = linear_stress(&grad, lambda, mu);
        }
    }
}

/// The isotropic linear stress `σ = λ tr(ε) I + 2μ ε`, `ε = sym ∇u` (Pa, Voigt in the order of
/// the module doc) of the displacement gradient `grad[r][c] = ∂u_r/∂x_c` and Lamé's `λ`, `μ`.
pub fn linear_stress(grad: &[[f64; 3]; 3], lambda: f64, mu: f64) -> [f64; 6] {
    let trace = grad[0][0] + grad[1][1] + grad[2][2];
    [
        lambda * trace + 2.0 * mu * grad[0][0],
        lambda * trace + 2.0 * mu * grad[1][1],
        lambda * trace + 2.0 * mu * grad[2][2],
        mu * (grad[1][2] + grad[2][1]),
        mu * (grad[0][2] + grad[2][0]),
        mu * (grad[0][1] + grad[1][0]),
    ]
}

/// The geometric stiffness `K_G(S0)` (N/m, `3N × 3N`) of the Gauss-point prestress `stress`
/// (Pa, Voigt, order and length as in the module doc), on the pattern of
/// [`stiffness_matrix`](super::stiffness_matrix):
/// `K_G[3a+d, 3b+e] = δ_de Σ_gp w det J (∇N_a · S0 ∇N_b)`.
pub fn geometric_stiffness(mesh: &Mesh, stress: &[[f64; 6]]) -> SymmetricCsr {
    let mut k_g = stiffness_pattern(mesh);
    geometric_stiffness_into(mesh, stress, &mut k_g);
    k_g
}

/// [`geometric_stiffness`] written into `out`, which must contain (at least) the pattern of
/// [`stiffness_matrix`](super::stiffness_matrix) — e.g. a clone of `K` or of an earlier `K_G`.
/// All values of `out` are overwritten (entries outside the `K_G` blocks become 0). No heap
/// allocation beyond the reference rule (a few hundred numbers); entries are located by binary
/// search in the sorted rows. Panics if `stress` has the wrong length, `out` has the wrong
/// dimension or lacks an entry, or an element is inverted.
pub fn geometric_stiffness_into(mesh: &Mesh, stress: &[[f64; 6]], out: &mut SymmetricCsr) {
    assert_eq!(
        stress.len(),
        gauss_point_count(mesh),
        "geometric_stiffness: stress has the wrong length"
    );
    assert_eq!(
        out.n,
        3 * mesh.node_count(),
        "geometric_stiffness: the output matrix has the wrong dimension"
    );
    let reference = ReferenceGradients::new(mesh.kind());
    let n = mesh.kind().node_count();
    let p = reference.weights.len();
    out.values.fill(0.0);
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    // Upper triangle (b ≥ a) of the scalar element matrix g[a][b] = Σ w ∇N_a · S0 ∇N_b.
    let mut ge = [[0.0f64; MAX_NODES]; MAX_NODES];
    for e in 0..mesh.element_count() {
        element_coordinates(mesh, e, &mut coords);
        for row in ge.iter_mut().take(n) {
            row[..n].fill(0.0);
        }
        for q in 0..p {
            let det = physical_gradients(
                &coords[..n],
                &reference.derivatives[q][..n],
                &mut gradients[..n],
            );
            assert!(det > 0.0, "geometric_stiffness: element {e} inverted");
            let w = reference.weights[q] * det;
            let s = &stress[e * p + q];
            // S0 as a symmetric 3×3 matrix, scaled by the quadrature weight.
            let sw = [
                [w * s[0], w * s[5], w * s[4]],
                [w * s[5], w * s[1], w * s[3]],
                [w * s[4], w * s[3], w * s[2]],
            ];
            for a in 0..n {
                let ga = gradients[a];
                // S0 ∇N_a (S0 symmetric).
                let sa = [
                    sw[0][0] * ga[0] + sw[0][1] * ga[1] + sw[0][2] * ga[2],
                    sw[1][0] * ga[0] + sw[1][1] * ga[1] + sw[1][2] * ga[2],
                    sw[2][0] * ga[0] + sw[2][1] * ga[1] + sw[2][2] * ga[2],
                ];
                for b in a..n {
                    let gb = gradients[b];
                    ge[a][b] += sa[0] * gb[0] + sa[1] * gb[1] + sa[2] * gb[2];
                }
            }
        }
        let nodes = mesh.element(e);
        for a in 0..n {
            for b in 0..n {
                let value = if b >= a { ge[a][b] } else { ge[b][a] };
                for d in 0..3 {
                    let row = 3 * nodes[a] + d;
                    let column = 3 * nodes[b] + d;
                    let range = out.row_ptr[row]..out.row_ptr[row + 1];
                    let k = out.col_idx[range.clone()]
                        .binary_search(&column)
                        .unwrap_or_else(|_| {
                            panic!(
                                "geometric_stiffness: entry ({row}, {column}) missing from the \
                                 output pattern"
                            )
                        });
                    out.values[range.start + k] += value;
                }
            }
        }
    }
}

/// The geometric stiffness of element `e` of `mesh` per unit of each prestress component, for a
/// prestress constant over the element, and the element's volume-mean shape-function gradients:
///
/// * `G_k[a][b] = ∫_e ∇N_a · E_k ∇N_b dV` (m) for the Voigt unit stresses `E_k` (order of the
///   module doc; the shear ones have 1 in both off-diagonal places), upper triangle `a ≤ b` row
///   by row (`n(n+1)/2` entries for `n` nodes), so that a constant prestress `S̄` gives
///   `K_G,e = (Σ_k S̄_k G_k) ⊗ I3`, [`geometric_stiffness`] with `S̄` at every Gauss point;
/// * `ḡ_a = (1/V_e) ∫_e ∇N_a dV` (1/m), so that the element's mean displacement gradient is
///   `Σ_a u_a ⊗ ḡ_a`.
///
/// Set-up only (allocates). Panics if the element is inverted.
pub fn unit_stress_geometric_stiffness(mesh: &Mesh, e: usize) -> ([Vec<f64>; 6], Vec<[f64; 3]>) {
    let reference = ReferenceGradients::new(mesh.kind());
    let n = mesh.kind().node_count();
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    element_coordinates(mesh, e, &mut coords);
    let mut unit: [Vec<f64>; 6] = std::array::from_fn(|_| vec![0.0; n * (n + 1) / 2]);
    let mut mean = vec![[0.0; 3]; n];
    let mut volume = 0.0;
    // The index pairs (i, j) of `E_k`'s entries, each entry 1.
    const PAIRS: [&[(usize, usize)]; 6] = [
        &[(0, 0)],
        &[(1, 1)],
        &[(2, 2)],
        &[(1, 2), (2, 1)],
        &[(0, 2), (2, 0)],
        &[(0, 1), (1, 0)],
    ];
    for (q, &weight) in reference.weights.iter().enumerate() {
        let det = physical_gradients(
            &coords[..n],
            &reference.derivatives[q][..n],
            &mut gradients[..n],
        );
        assert!(
            det > 0.0,
            "unit_stress_geometric_stiffness: element {e} inverted"
        );
        let w = weight * det;
        volume += w;
        for (m, g) in mean.iter_mut().zip(&gradients[..n]) {
            for i in 0..3 {
                m[i] += w * g[i];
            }
        }
        for (k, pairs) in PAIRS.iter().enumerate() {
            let mut entry = 0;
            for a in 0..n {
                for b in a..n {
                    unit[k][entry] += w * pairs
                        .iter()
                        .map(|&(i, j)| gradients[a][i] * gradients[b][j])
                        .sum::<f64>();
                    entry += 1;
                }
            }
        }
    }
    for m in &mut mean {
        for v in m.iter_mut() {
            *v /= volume;
        }
    }
    (unit, mean)
}

/// `out = Σ_k c_k A_k` entry by entry, for matrices sharing one pattern (that of `out`): e.g.
/// `K_G = Σ_k c_k K_G,k` from precomputed unit load cases (`K_G` is linear in the stress), or
/// `K + K_G`. Allocation-free, `nnz` multiply-adds per term, the terms taken four at a time in
/// one pass over the values (a reduced body's dense `K_G` is refreshed from four terms in one
/// pass instead of four); the sum is formed in the terms' order, so the result is that of
/// adding them one by one.
///
/// Panics if a term's dimension or entry count differs from `out`'s; that the column indices are
/// identical too is checked in debug builds only (comparing them costs as much as the sum).
/// `out` must not be one of the terms (the borrow checker enforces it). With no terms, `out = 0`.
pub fn weighted_sum_into(out: &mut SymmetricCsr, terms: &[(f64, &SymmetricCsr)]) {
    for (_, term) in terms {
        assert!(
            term.n == out.n && term.values.len() == out.values.len(),
            "weighted_sum_into: a term's pattern differs from the output's"
        );
        debug_assert!(
            term.row_ptr == out.row_ptr && term.col_idx == out.col_idx,
            "weighted_sum_into: a term's pattern differs from the output's"
        );
    }
    if terms.is_empty() {
        out.values.fill(0.0);
    }
    for (group, chunk) in terms.chunks(4).enumerate() {
        add_group(&mut out.values, chunk, group == 0);
    }
}

/// `out (=|+=) Σ c_k a_k` over up to four terms in one pass, added in order; `first`: `out` is
/// overwritten.
fn add_group(out: &mut [f64], terms: &[(f64, &SymmetricCsr)], first: bool) {
    let n = out.len();
    let value = |k: usize| (terms[k].0, &terms[k].1.values[..n]);
    // The branches are taken once per call, so that each loop is a plain fused sum the
    // compiler vectorizes.
    match (terms.len(), first) {
        (1, true) => {
            let (c0, a0) = value(0);
            for i in 0..n {
                out[i] = c0 * a0[i];
            }
        }
        (1, false) => {
            let (c0, a0) = value(0);
            for i in 0..n {
                out[i] += c0 * a0[i];
            }
        }
        (2, true) => {
            let ((c0, a0), (c1, a1)) = (value(0), value(1));
            for i in 0..n {
                out[i] = c0 * a0[i] + c1 * a1[i];
            }
        }
        (2, false) => {
            let ((c0, a0), (c1, a1)) = (value(0), value(1));
            for i in 0..n {
                out[i] = out[i] + c0 * a0[i] + c1 * a1[i];
            }
        }
        (3, true) => {
            let ((c0, a0), (c1, a1), (c2, a2)) = (value(0), value(1), value(2));
            for i in 0..n {
                out[i] = c0 * a0[i] + c1 * a1[i] + c2 * a2[i];
            }
        }
        (3, false) => {
            let ((c0, a0), (c1, a1), (c2, a2)) = (value(0), value(1), value(2));
            for i in 0..n {
                out[i] = out[i] + c0 * a0[i] + c1 * a1[i] + c2 * a2[i];
            }
        }
        (_, true) => {
            let ((c0, a0), (c1, a1), (c2, a2), (c3, a3)) = (value(0), value(1), value(2), value(3));
            for i in 0..n {
                out[i] = c0 * a0[i] + c1 * a1[i] + c2 * a2[i] + c3 * a3[i];
            }
        }
        (_, false) => {
            let ((c0, a0), (c1, a1), (c2, a2), (c3, a3)) = (value(0), value(1), value(2), value(3));
            for i in 0..n {
                out[i] = out[i] + c0 * a0[i] + c1 * a1[i] + c2 * a2[i] + c3 * a3[i];
            }
        }
    }
}

#[cfg(test)]
mod tests;
