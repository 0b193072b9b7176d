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
/// `K + K_G`. Allocation-free, one pass over the values per term (`nnz` multiply-adds each).
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
    match terms.split_first() {
        None => out.values.fill(0.0),
        Some(((c0, first), rest)) => {
            for (o, &v) in out.values.iter_mut().zip(&first.values) {
                *o = c0 * v;
            }
            for (c, term) in rest {
                for (o, &v) in out.values.iter_mut().zip(&term.values) {
                    *o += c * v;
                }
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices
mod tests {
    use super::*;
    use crate::element::{corner_count, edges};
    use crate::fem::stiffness_matrix;
    use crate::mesh::beam;

    /// A 2×2×1 block of distorted elements (interior corner and top corners moved; Hex20
    /// mid-edge nodes on the straight edges), so that gradients vary within the elements.
    fn distorted_block(kind: ElementKind) -> Mesh {
        let block = beam(1.0, 0.8, 0.6, [2, 2, 1], kind).unwrap();
        let mut nodes = block.nodes().to_vec();
        for (i, p) in nodes.iter_mut().enumerate() {
            let is_corner = (0..block.element_count()).any(|e| {
                block.element(e)[..corner_count(kind)].contains(&i) // corners come first (VTK)
            });
            if is_corner {
                // A smooth perturbation of at most 0.04 m on elements of 0.5 × 0.4 × 0.6 m.
                let s = (3.1 * p[0] + 1.7 * p[1] - 2.3 * p[2]).sin();
                p[0] += 0.04 * s;
                p[1] += 0.03 * (2.0 * s * s - 1.0);
                p[2] += 0.02 * s * (1.0 - s);
            }
        }
        if kind.is_quadratic() {
            for e in 0..block.element_count() {
                let element = block.element(e);
                for &(a, b, mid) in edges(kind) {
                    let (pa, pb) = (nodes[element[a]], nodes[element[b]]);
                    nodes[element[mid]] = [
                        0.5 * (pa[0] + pb[0]),
                        0.5 * (pa[1] + pb[1]),
                        0.5 * (pa[2] + pb[2]),
                    ];
                }
            }
        }
        let connectivity = (0..block.element_count())
            .flat_map(|e| block.element(e).to_vec())
            .collect();
        Mesh::new(nodes, kind, connectivity).unwrap()
    }

    /// A deterministic, non-uniform Gauss-point stress field (Pa), all six components non-zero.
    fn varied_stress(mesh: &Mesh) -> Vec<[f64; 6]> {
        (0..gauss_point_count(mesh))
            .map(|g| {
                let t = g as f64;
                [
                    1e6 * (0.3 * t).sin(),
                    -2e6 * (0.17 * t).cos(),
                    5e5 + 1e5 * t.sqrt(),
                    3e5 * (0.5 * t).cos(),
                    -4e5 * (0.11 * t).sin(),
                    2e5,
                ]
            })
            .collect()
    }

    fn quadratic_form(a: &SymmetricCsr, u: &[f64]) -> f64 {
        let mut au = vec![0.0; u.len()];
        a.mul_vec(u, &mut au);
        u.iter().zip(&au).map(|(x, y)| x * y).sum()
    }

    fn max_abs(values: &[f64]) -> f64 {
        values.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn gauss_point_count_is_that_of_the_stiffness_rule() {
        for kind in ElementKind::ALL {
            assert_eq!(
                gauss_points_per_element(kind),
                integration_rule(kind).len(),
                "{kind:?}"
            );
        }
    }

    #[test]
    fn pattern_is_that_of_the_stiffness_matrix() {
        for kind in ElementKind::ALL {
            let mesh = distorted_block(kind);
            let k = stiffness_matrix(&mesh, &IsotropicMaterial::STEEL);
            let k_g = geometric_stiffness(&mesh, &varied_stress(&mesh));
            assert_eq!(k_g.n, k.n);
            assert_eq!(k_g.row_ptr, k.row_ptr, "{kind:?}");
            assert_eq!(k_g.col_idx, k.col_idx, "{kind:?}");
        }
    }

    #[test]
    fn geometric_stiffness_is_symmetric_and_direction_diagonal() {
        // Each entry is a sum of the same products in the same order whichever triangle it is
        // in (the element matrix is mirrored, not recomputed), so symmetry holds to round-off
        // of the assembly order only: 1e-14 of the largest entry.
        for kind in ElementKind::ALL {
            let mesh = distorted_block(kind);
            let k_g = geometric_stiffness(&mesh, &varied_stress(&mesh));
            let dense = k_g.to_dense();
            let scale = max_abs(&k_g.values);
            assert!(scale > 0.0);
            for i in 0..k_g.n {
                for j in 0..k_g.n {
                    assert!(
                        (dense[(i, j)] - dense[(j, i)]).abs() <= 1e-14 * scale,
                        "{kind:?} ({i}, {j})"
                    );
                    if i % 3 != j % 3 {
                        assert_eq!(dense[(i, j)], 0.0, "{kind:?} ({i}, {j})");
                    }
                }
            }
        }
    }

    #[test]
    fn zero_stress_gives_zero_matrix() {
        for kind in ElementKind::ALL {
            let mesh = distorted_block(kind);
            let k_g = geometric_stiffness(&mesh, &vec![[0.0; 6]; gauss_point_count(&mesh)]);
            assert!(k_g.values.iter().all(|&v| v == 0.0), "{kind:?}");
        }
    }

    #[test]
    fn uniaxial_stress_quadratic_form_is_exact_for_linear_fields() {
        // u = A x + b is reproduced exactly by both element families: Σ_a u_a ⊗ ∇N_a = A at
        // every point, also on the distorted block, so uᵀ K_G u = Σ_gp w det J σ_xx |A e_x|²
        // = σ_xx V |A e_x|² with V = Σ_gp w det J (the quadrature of the volume, itself exact
        // here: det J of a trilinear map has degree ≤ 2 per natural variable, and the straight-
        // edged Hex20 map is that trilinear map; straight-edged tetrahedra have a constant det J).
        // Tolerance: round-off, 1e-12 relative.
        let a = [[0.3, -0.2, 0.5], [0.7, 0.1, -0.4], [-0.6, 0.25, 0.15]];
        let b = [0.01, -0.02, 0.03];
        let sigma = 3.7e6;
        for kind in ElementKind::ALL {
            for (m, mesh) in [
                beam(1.3, 0.5, 0.4, [3, 2, 2], kind).unwrap(),
                distorted_block(kind),
            ]
            .into_iter()
            .enumerate()
            {
                let mut u = vec![0.0; 3 * mesh.node_count()];
                for (i, p) in mesh.nodes().iter().enumerate() {
                    for r in 0..3 {
                        u[3 * i + r] = b[r] + (0..3).map(|c| a[r][c] * p[c]).sum::<f64>();
                    }
                }
                let reference = ReferenceGradients::new(kind);
                let n = kind.node_count();
                let mut coords = [[0.0; 3]; MAX_NODES];
                let mut g = [[0.0; 3]; MAX_NODES];
                let mut volume = 0.0;
                for e in 0..mesh.element_count() {
                    element_coordinates(&mesh, e, &mut coords);
                    for q in 0..reference.weights.len() {
                        volume += reference.weights[q]
                            * physical_gradients(
                                &coords[..n],
                                &reference.derivatives[q][..n],
                                &mut g[..n],
                            );
                    }
                }
                if m == 0 {
                    // The regular 1.3 × 0.5 × 0.4 block.
                    assert!((volume / (1.3 * 0.5 * 0.4) - 1.0).abs() < 1e-13);
                }
                let stress = vec![[sigma, 0.0, 0.0, 0.0, 0.0, 0.0]; gauss_point_count(&mesh)];
                let k_g = geometric_stiffness(&mesh, &stress);
                let du_dx2: f64 = (0..3).map(|r| a[r][0] * a[r][0]).sum();
                let expected = sigma * volume * du_dx2;
                let got = quadratic_form(&k_g, &u);
                assert!(
                    (got / expected - 1.0).abs() < 1e-12,
                    "{kind:?}: {got} vs {expected}"
                );
                // A rigid translation has no gradient: K_G b = 0.
                let mut t = vec![0.0; u.len()];
                for i in 0..mesh.node_count() {
                    t[3 * i..3 * i + 3].copy_from_slice(&b);
                }
                let mut kt = vec![0.0; t.len()];
                k_g.mul_vec(&t, &mut kt);
                assert!(max_abs(&kt) <= 1e-12 * max_abs(&k_g.values) * max_abs(&b));
            }
        }
    }

    #[test]
    fn stress_of_a_linear_field_is_d_times_its_strain_everywhere() {
        // u = A x: ε = sym A at every Gauss point (exact reproduction); σ = D ε with D from
        // `elasticity_matrix` (independent of the λ/μ form used inside). Round-off: 1e-12 of
        // the largest stress component.
        let a = [
            [1e-3, -2e-4, 5e-4],
            [7e-4, -3e-4, -4e-4],
            [-6e-4, 2.5e-4, 1.5e-4],
        ];
        let material = IsotropicMaterial::STEEL;
        let d = material.elasticity_matrix();
        let strain = [
            a[0][0],
            a[1][1],
            a[2][2],
            a[1][2] + a[2][1],
            a[0][2] + a[2][0],
            a[0][1] + a[1][0],
        ];
        let expected: Vec<f64> = (0..6)
            .map(|i| (0..6).map(|j| d[i][j] * strain[j]).sum())
            .collect();
        let scale = max_abs(&expected);
        for kind in ElementKind::ALL {
            let mesh = distorted_block(kind);
            let mut u = vec![0.0; 3 * mesh.node_count()];
            for (i, p) in mesh.nodes().iter().enumerate() {
                for r in 0..3 {
                    u[3 * i + r] = (0..3).map(|c| a[r][c] * p[c]).sum::<f64>();
                }
            }
            let stress = stress_at_gauss_points(&mesh, &material, &u);
            let per_element = match kind {
                ElementKind::Hex8 => 8,
                ElementKind::Hex20 => 27,
                ElementKind::Tet4 => 1,
                ElementKind::Tet10 => 4,
            };
            assert_eq!(stress.len(), mesh.element_count() * per_element);
            for s in &stress {
                for c in 0..6 {
                    assert!((s[c] - expected[c]).abs() <= 1e-12 * scale, "{kind:?}");
                }
            }
        }
    }

    #[test]
    fn in_place_and_weighted_sum_agree_with_the_allocating_assembly() {
        for kind in ElementKind::ALL {
            let mesh = distorted_block(kind);
            let s1 = varied_stress(&mesh);
            let s2: Vec<[f64; 6]> = s1.iter().rev().map(|s| s.map(|v| 0.5 * v + 1e5)).collect();
            let k1 = geometric_stiffness(&mesh, &s1);
            let k2 = geometric_stiffness(&mesh, &s2);
            let scale = max_abs(&k1.values).max(max_abs(&k2.values));

            // In place into a matrix holding stale values (a clone of K): identical result.
            let mut out = stiffness_matrix(&mesh, &IsotropicMaterial::STEEL);
            geometric_stiffness_into(&mesh, &s1, &mut out);
            assert_eq!(out, k1, "{kind:?}");

            // K_G is linear in the stress: K_G(c1 s1 + c2 s2) = c1 K_G(s1) + c2 K_G(s2), up to
            // round-off (1e-13 of the largest entry).
            let (c1, c2) = (-1.5, 2.25);
            let combined: Vec<[f64; 6]> = s1
                .iter()
                .zip(&s2)
                .map(|(a, b)| std::array::from_fn(|c| c1 * a[c] + c2 * b[c]))
                .collect();
            let direct = geometric_stiffness(&mesh, &combined);
            let mut sum = k1.clone();
            weighted_sum_into(&mut sum, &[(c1, &k1), (c2, &k2)]);
            assert_eq!(sum.col_idx, direct.col_idx);
            for (x, y) in sum.values.iter().zip(&direct.values) {
                assert!((x - y).abs() <= 1e-13 * scale, "{kind:?}: {x} vs {y}");
            }
            // A single term with weight 1 copies; no terms zeroes.
            weighted_sum_into(&mut sum, &[(1.0, &k2)]);
            assert_eq!(sum, k2);
            weighted_sum_into(&mut sum, &[]);
            assert!(sum.values.iter().all(|&v| v == 0.0));
        }
    }

    #[test]
    #[should_panic(expected = "pattern differs")]
    fn weighted_sum_rejects_a_different_pattern() {
        let mesh = beam(1.0, 1.0, 1.0, [1, 1, 1], ElementKind::Hex8).unwrap();
        let k_g = geometric_stiffness(&mesh, &vec![[1.0; 6]; gauss_point_count(&mesh)]);
        let smaller = k_g.submatrix(&[0, 1, 2]);
        let mut out = k_g.clone();
        weighted_sum_into(&mut out, &[(1.0, &smaller)]);
    }

    #[test]
    fn unit_stress_stiffness_sums_to_the_assembly_of_a_constant_stress() {
        // With the same stress at every Gauss point of every element, Σ_k S_k G_e,k assembled
        // over the elements is `geometric_stiffness`; the mean gradients reproduce the gradient
        // of a linear field (Σ_a X_a ⊗ ḡ_a = I).
        for kind in [
            ElementKind::Hex8,
            ElementKind::Hex20,
            ElementKind::Tet4,
            ElementKind::Tet10,
        ] {
            let mesh = distorted_block(kind);
            let stress = [3.0e5, -1.2e5, 0.7e5, 2.1e4, -4.4e4, 1.3e4];
            let k_g = geometric_stiffness(&mesh, &vec![stress; gauss_point_count(&mesh)]);
            let mut assembled = stiffness_pattern(&mesh);
            for e in 0..mesh.element_count() {
                let (unit, mean) = unit_stress_geometric_stiffness(&mesh, e);
                let nodes = mesh.element(e);
                let mut entry = 0;
                for a in 0..nodes.len() {
                    for b in a..nodes.len() {
                        let value: f64 = (0..6).map(|k| stress[k] * unit[k][entry]).sum();
                        entry += 1;
                        for d in 0..3 {
                            let (row, column) = (3 * nodes[a] + d, 3 * nodes[b] + d);
                            let places: &[(usize, usize)] = if a == b {
                                &[(row, column)]
                            } else {
                                &[(row, column), (column, row)]
                            };
                            for &(r, c) in places {
                                let range = assembled.row_ptr[r]..assembled.row_ptr[r + 1];
                                let k = assembled.col_idx[range.clone()].binary_search(&c).unwrap();
                                assembled.values[range.start + k] += value;
                            }
                        }
                    }
                }
                let mut identity = [[0.0; 3]; 3];
                for (&n, g) in nodes.iter().zip(&mean) {
                    for r in 0..3 {
                        for c in 0..3 {
                            identity[r][c] += mesh.nodes()[n][r] * g[c];
                        }
                    }
                }
                for r in 0..3 {
                    for c in 0..3 {
                        let expected = if r == c { 1.0 } else { 0.0 };
                        assert!(
                            (identity[r][c] - expected).abs() < 1e-12,
                            "{kind:?}: {identity:?}"
                        );
                    }
                }
            }
            let scale = max_abs(&k_g.values);
            for (x, y) in assembled.values.iter().zip(&k_g.values) {
                assert!((x - y).abs() <= 1e-12 * scale, "{kind:?}: {x} vs {y}");
            }
        }
    }
}
