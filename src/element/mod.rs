//! The reference finite elements (the floor below the mesh): element kinds ([`ElementKind`]),
//! node orders, quadrature rules ([`quadrature`]) and shape functions.
//!
//! Shape functions of the hexahedra (natural coordinates `ξ = (ξ, η, ζ) ∈ [−1, 1]³`) and of the
//! tetrahedra (natural coordinates in the unit tetrahedron `ξ, η, ζ ≥ 0, ξ + η + ζ ≤ 1`), the
//! isoparametric Jacobian, physical shape-function gradients and the quadrature rule of each kind.
//!
//! * Hex8 (trilinear): `N_a = ⅛ (1 + ξ ξ_a)(1 + η η_a)(1 + ζ ζ_a)`.
//! * Hex20 (serendipity): corner nodes
//!   `N_a = ⅛ (1 + ξ ξ_a)(1 + η η_a)(1 + ζ ζ_a)(ξ ξ_a + η η_a + ζ ζ_a − 2)`; a mid-edge node with
//!   natural coordinate 0 along one axis, e.g. `ξ_a = 0`: `N_a = ¼ (1 − ξ²)(1 + η η_a)(1 + ζ ζ_a)`.
//! * Tet4 (linear): with the barycentric coordinates `L_0 = 1 − ξ − η − ζ`, `L_1 = ξ`, `L_2 = η`,
//!   `L_3 = ζ`: `N_a = L_a`.
//! * Tet10 (quadratic): corners `N_a = L_a (2 L_a − 1)`, the node in the middle of edge `(a, b)`
//!   `N = 4 L_a L_b`.
//!
//! Node order is VTK's (see [`natural_coordinates`]). All families are partitions of unity and
//! reproduce linear fields, so an isoparametric element represents `u = A X + b` exactly.

pub mod quadrature;

use quadrature::{hexahedron_rule, tetrahedron_rule, QuadraturePoint};
use serde::{Deserialize, Serialize};

/// The element kinds this crate knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElementKind {
    /// 8-node trilinear hexahedron (VTK_HEXAHEDRON node order).
    Hex8,
    /// 20-node serendipity hexahedron (VTK_QUADRATIC_HEXAHEDRON node order).
    Hex20,
    /// 4-node linear tetrahedron (VTK_TETRA node order).
    Tet4,
    /// 10-node quadratic tetrahedron (VTK_QUADRATIC_TETRA node order).
    Tet10,
}

impl ElementKind {
    /// Every element kind.
    pub const ALL: [ElementKind; 4] = [
        ElementKind::Hex8,
        ElementKind::Hex20,
        ElementKind::Tet4,
        ElementKind::Tet10,
    ];

    /// Nodes per element.
    pub fn node_count(self) -> usize {
        match self {
            ElementKind::Hex8 => 8,
            ElementKind::Hex20 => 20,
            ElementKind::Tet4 => 4,
            ElementKind::Tet10 => 10,
        }
    }

    /// Whether the shape functions are quadratic (mid-edge nodes: Hex20, Tet10).
    pub fn is_quadratic(self) -> bool {
        matches!(self, ElementKind::Hex20 | ElementKind::Tet10)
    }
}

/// Largest node count of an element kind (for fixed-size, allocation-free local arrays).
pub const MAX_NODES: usize = 20;

/// Natural coordinates of the Hex8 nodes (VTK_HEXAHEDRON order): bottom face ζ = −1
/// counter-clockwise seen from +ζ starting at (−1,−1,−1), then the top face.
pub const HEX8_NODES: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Natural coordinates of the Hex20 nodes (VTK_QUADRATIC_HEXAHEDRON order): the 8 corners as
/// Hex8, then mid-edge nodes of edges 0-1, 1-2, 2-3, 3-0 (8–11), 4-5, 5-6, 6-7, 7-4 (12–15) and
/// 0-4, 1-5, 2-6, 3-7 (16–19).
pub const HEX20_NODES: [[f64; 3]; 20] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// The 12 edges of a hexahedron as (corner, corner, mid-edge node of Hex20), VTK numbering.
pub const HEX_EDGES: [(usize, usize, usize); 12] = [
    (0, 1, 8),
    (1, 2, 9),
    (2, 3, 10),
    (3, 0, 11),
    (4, 5, 12),
    (5, 6, 13),
    (6, 7, 14),
    (7, 4, 15),
    (0, 4, 16),
    (1, 5, 17),
    (2, 6, 18),
    (3, 7, 19),
];

/// Natural coordinates of the Tet4 nodes (VTK_TETRA order): the vertices `L_0 … L_3 = 1`.
pub const TET4_NODES: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// Natural coordinates of the Tet10 nodes (VTK_QUADRATIC_TETRA order): the 4 vertices as Tet4,
/// then the middles of edges 0-1, 1-2, 2-0, 0-3, 1-3, 2-3 (nodes 4–9). Gmsh's order differs
/// in the last two (its node 8 is on edge 2-3, node 9 on edge 1-3).
pub const TET10_NODES: [[f64; 3]; 10] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.0, 0.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.0],
    [0.0, 0.0, 0.5],
    [0.5, 0.0, 0.5],
    [0.0, 0.5, 0.5],
];

/// The 6 edges of a tetrahedron as (vertex, vertex, mid-edge node of Tet10), VTK numbering.
pub const TET_EDGES: [(usize, usize, usize); 6] = [
    (0, 1, 4),
    (1, 2, 5),
    (2, 0, 6),
    (0, 3, 7),
    (1, 3, 8),
    (2, 3, 9),
];

/// Natural coordinates of the nodes of `kind`, in element node order.
pub fn natural_coordinates(kind: ElementKind) -> &'static [[f64; 3]] {
    match kind {
        ElementKind::Hex8 => &HEX8_NODES,
        ElementKind::Hex20 => &HEX20_NODES,
        ElementKind::Tet4 => &TET4_NODES,
        ElementKind::Tet10 => &TET10_NODES,
    }
}

/// Edges of the element as (corner, corner, mid-edge node): the mid-edge node is meaningful for
/// the quadratic kinds (Hex20, Tet10) only.
pub fn edges(kind: ElementKind) -> &'static [(usize, usize, usize)] {
    match kind {
        ElementKind::Hex8 | ElementKind::Hex20 => &HEX_EDGES,
        ElementKind::Tet4 | ElementKind::Tet10 => &TET_EDGES,
    }
}

/// Corner (vertex) nodes per element: the first `corner_count` nodes in VTK order.
pub fn corner_count(kind: ElementKind) -> usize {
    match kind {
        ElementKind::Hex8 | ElementKind::Hex20 => 8,
        ElementKind::Tet4 | ElementKind::Tet10 => 4,
    }
}

/// The quadrature rule for the stiffness `K` (and everything evaluated per Gauss point: stress,
/// `K_G`, the St. Venant–Kirchhoff solid). Weights sum to the volume of the reference element
/// (8 for the cube, 1/6 for the unit tetrahedron).
///
/// * Hex8: 2×2×2 Gauss–Legendre; Hex20: 3×3×3 (the full rules).
/// * Tet4: 1 point (the centroid; `∇N` is constant, so `K` is exact on straight elements).
/// * Tet10: 4 points, degree 2 (`∇N_a · ∇N_b` is quadratic on a straight-edged element: exact).
pub fn integration_rule(kind: ElementKind) -> Vec<QuadraturePoint> {
    match kind {
        ElementKind::Hex8 => hexahedron_rule(2),
        ElementKind::Hex20 => hexahedron_rule(3),
        ElementKind::Tet4 => tetrahedron_rule(1),
        ElementKind::Tet10 => tetrahedron_rule(2),
    }
}

/// The quadrature rule for the consistent mass `∫ ρ N_a N_b dV` (and the HRZ-lumped masses):
/// the hexahedra use the rule of [`integration_rule`] (exact for the mass of a parallelepiped);
/// the tetrahedra need the degree of `N_a N_b`: Tet4 the 4-point degree-2 rule, Tet10 the
/// 14-point degree-5 rule (degree 4 is needed; unlike the 11-point degree-4 Keast rule its
/// weights are all positive).
pub fn mass_rule(kind: ElementKind) -> Vec<QuadraturePoint> {
    match kind {
        ElementKind::Hex8 | ElementKind::Hex20 => integration_rule(kind),
        ElementKind::Tet4 => tetrahedron_rule(2),
        ElementKind::Tet10 => tetrahedron_rule(5),
    }
}

/// Shape function values `N_a(ξ)` and natural derivatives `∂N_a/∂ξ_j` at `xi`, written into the
/// first `kind.node_count()` entries of `values` and `derivatives`.
pub fn shape_functions(
    kind: ElementKind,
    xi: [f64; 3],
    values: &mut [f64],
    derivatives: &mut [[f64; 3]],
) {
    match kind {
        ElementKind::Hex8 | ElementKind::Hex20 => {
            let nodes = natural_coordinates(kind);
            for (a, node) in nodes.iter().enumerate() {
                let (n, dn) = match kind {
                    ElementKind::Hex8 => trilinear(node, xi),
                    _ => serendipity(node, xi),
                };
                values[a] = n;
                derivatives[a] = dn;
            }
        }
        ElementKind::Tet4 | ElementKind::Tet10 => tetrahedral(kind, xi, values, derivatives),
    }
}

/// Barycentric coordinates `L_0 … L_3` at `ξ` and their (constant) natural gradients.
const BARYCENTRIC_GRADIENTS: [[f64; 3]; 4] = [
    [-1.0, -1.0, -1.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// Tet4 and Tet10 shape functions (module documentation) and their natural derivatives.
fn tetrahedral(kind: ElementKind, xi: [f64; 3], values: &mut [f64], derivatives: &mut [[f64; 3]]) {
    let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    let dl = &BARYCENTRIC_GRADIENTS;
    if kind == ElementKind::Tet4 {
        values[..4].copy_from_slice(&l);
        derivatives[..4].copy_from_slice(dl);
        return;
    }
    for a in 0..4 {
        // L (2L − 1), derivative (4L − 1) ∇L.
        values[a] = l[a] * (2.0 * l[a] - 1.0);
        let s = 4.0 * l[a] - 1.0;
        derivatives[a] = [s * dl[a][0], s * dl[a][1], s * dl[a][2]];
    }
    for &(a, b, m) in &TET_EDGES {
        // 4 L_a L_b, derivative 4 (L_b ∇L_a + L_a ∇L_b).
        values[m] = 4.0 * l[a] * l[b];
        derivatives[m] = std::array::from_fn(|j| 4.0 * (l[b] * dl[a][j] + l[a] * dl[b][j]));
    }
}

/// `⅛ Π_d (1 + ξ_d ξ_{a,d})` and its gradient.
fn trilinear(node: &[f64; 3], xi: [f64; 3]) -> (f64, [f64; 3]) {
    let f = [
        1.0 + xi[0] * node[0],
        1.0 + xi[1] * node[1],
        1.0 + xi[2] * node[2],
    ];
    let n = 0.125 * f[0] * f[1] * f[2];
    let dn = [
        0.125 * node[0] * f[1] * f[2],
        0.125 * f[0] * node[1] * f[2],
        0.125 * f[0] * f[1] * node[2],
    ];
    (n, dn)
}

/// Serendipity (20-node) shape function of the node at natural coordinates `node`.
fn serendipity(node: &[f64; 3], xi: [f64; 3]) -> (f64, [f64; 3]) {
    if node.iter().all(|c| *c != 0.0) {
        // Corner: ⅛ a b c s with a = 1 + ξξ_a, ..., s = ξξ_a + ηη_a + ζζ_a − 2.
        let f = [
            1.0 + xi[0] * node[0],
            1.0 + xi[1] * node[1],
            1.0 + xi[2] * node[2],
        ];
        let s = xi[0] * node[0] + xi[1] * node[1] + xi[2] * node[2] - 2.0;
        let n = 0.125 * f[0] * f[1] * f[2] * s;
        let dn = [
            0.125 * node[0] * f[1] * f[2] * (s + f[0]),
            0.125 * node[1] * f[0] * f[2] * (s + f[1]),
            0.125 * node[2] * f[0] * f[1] * (s + f[2]),
        ];
        (n, dn)
    } else {
        // Mid-edge: ¼ Π_d g_d with g_d = 1 − ξ_d² on the edge's axis, 1 + ξ_d ξ_{a,d} otherwise.
        let mut g = [0.0; 3];
        let mut dg = [0.0; 3];
        for d in 0..3 {
            if node[d] == 0.0 {
                g[d] = 1.0 - xi[d] * xi[d];
                dg[d] = -2.0 * xi[d];
            } else {
                g[d] = 1.0 + xi[d] * node[d];
                dg[d] = node[d];
            }
        }
        let n = 0.25 * g[0] * g[1] * g[2];
        let dn = [
            0.25 * dg[0] * g[1] * g[2],
            0.25 * g[0] * dg[1] * g[2],
            0.25 * g[0] * g[1] * dg[2],
        ];
        (n, dn)
    }
}

/// The Jacobian `J[i][j] = ∂x_i/∂ξ_j = Σ_a x_{a,i} ∂N_a/∂ξ_j` of the isoparametric map at a point
/// where the natural derivatives are `derivatives` (element node coordinates `coordinates`, m).
pub fn jacobian(coordinates: &[[f64; 3]], derivatives: &[[f64; 3]]) -> [[f64; 3]; 3] {
    let mut j = [[0.0; 3]; 3];
    for (x, dn) in coordinates.iter().zip(derivatives) {
        for r in 0..3 {
            for c in 0..3 {
                j[r][c] += x[r] * dn[c];
            }
        }
    }
    j
}

/// Determinant of a 3×3 matrix.
pub fn determinant(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Physical gradients `∇N_a = J⁻ᵀ ∂N_a/∂ξ` (1/m) written into `gradients`, from the element node
/// coordinates and the natural derivatives at one point. Returns `det J` (m³ per unit natural
/// volume); if it is not positive the gradients are left unspecified.
pub fn physical_gradients(
    coordinates: &[[f64; 3]],
    derivatives: &[[f64; 3]],
    gradients: &mut [[f64; 3]],
) -> f64 {
    let j = jacobian(coordinates, derivatives);
    let det = determinant(&j);
    if det.is_nan() || det <= 0.0 {
        return det;
    }
    // inverse = adjugate / det; ∇N_a[i] = Σ_j inv[j][i] dN_a/dξ_j.
    let inv_det = 1.0 / det;
    let adj = [
        [
            j[1][1] * j[2][2] - j[1][2] * j[2][1],
            j[0][2] * j[2][1] - j[0][1] * j[2][2],
            j[0][1] * j[1][2] - j[0][2] * j[1][1],
        ],
        [
            j[1][2] * j[2][0] - j[1][0] * j[2][2],
            j[0][0] * j[2][2] - j[0][2] * j[2][0],
            j[0][2] * j[1][0] - j[0][0] * j[1][2],
        ],
        [
            j[1][0] * j[2][1] - j[1][1] * j[2][0],
            j[0][1] * j[2][0] - j[0][0] * j[2][1],
            j[0][0] * j[1][1] - j[0][1] * j[1][0],
        ],
    ];
    for (g, dn) in gradients.iter_mut().zip(derivatives) {
        for i in 0..3 {
            g[i] = inv_det * (adj[0][i] * dn[0] + adj[1][i] * dn[1] + adj[2][i] * dn[2]);
        }
    }
    det
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices
mod tests {
    use super::*;

    fn sample_points() -> Vec<[f64; 3]> {
        vec![
            [0.0, 0.0, 0.0],
            [0.3, -0.7, 0.2],
            [-0.9, 0.4, 0.95],
            [1.0, 1.0, -1.0],
            [0.123, 0.456, -0.789],
        ]
    }

    #[test]
    fn kronecker_delta_at_nodes() {
        for kind in ElementKind::ALL {
            let n = kind.node_count();
            let mut v = [0.0; MAX_NODES];
            let mut d = [[0.0; 3]; MAX_NODES];
            for (b, node) in natural_coordinates(kind).iter().enumerate() {
                shape_functions(kind, *node, &mut v, &mut d);
                for (a, value) in v.iter().take(n).enumerate() {
                    let expected = if a == b { 1.0 } else { 0.0 };
                    assert!(
                        (value - expected).abs() < 1e-15,
                        "{kind:?} N_{a}(node {b}) = {value}"
                    );
                }
            }
        }
    }

    #[test]
    fn partition_of_unity_and_linear_reproduction() {
        for kind in ElementKind::ALL {
            let n = kind.node_count();
            let nodes = natural_coordinates(kind);
            let mut v = [0.0; MAX_NODES];
            let mut d = [[0.0; 3]; MAX_NODES];
            for xi in sample_points() {
                shape_functions(kind, xi, &mut v, &mut d);
                let sum: f64 = v[..n].iter().sum();
                assert!((sum - 1.0).abs() < 1e-14);
                for c in 0..3 {
                    // Σ N_a ξ_{a,c} = ξ_c and Σ ∂N_a/∂ξ_j ξ_{a,c} = δ_cj.
                    let interp: f64 = (0..n).map(|a| v[a] * nodes[a][c]).sum();
                    assert!((interp - xi[c]).abs() < 1e-14);
                    for j in 0..3 {
                        let g: f64 = (0..n).map(|a| d[a][j] * nodes[a][c]).sum();
                        let e = if c == j { 1.0 } else { 0.0 };
                        assert!((g - e).abs() < 1e-14);
                    }
                }
            }
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        // Shape functions are polynomials of degree ≤ 3 per variable: the central difference error
        // is h²/6 |f'''| ≤ h² · O(1); with h = 1e-5 and rounding ~1e-16/h the error is ≲ 1e-9.
        let h = 1e-5;
        for kind in ElementKind::ALL {
            let n = kind.node_count();
            let mut v = [0.0; MAX_NODES];
            let mut d = [[0.0; 3]; MAX_NODES];
            let mut vp = [0.0; MAX_NODES];
            let mut vm = [0.0; MAX_NODES];
            let mut scratch = [[0.0; 3]; MAX_NODES];
            for xi in sample_points() {
                shape_functions(kind, xi, &mut v, &mut d);
                for j in 0..3 {
                    let mut xp = xi;
                    xp[j] += h;
                    let mut xm = xi;
                    xm[j] -= h;
                    shape_functions(kind, xp, &mut vp, &mut scratch);
                    shape_functions(kind, xm, &mut vm, &mut scratch);
                    for a in 0..n {
                        let fd = (vp[a] - vm[a]) / (2.0 * h);
                        assert!((fd - d[a][j]).abs() < 1e-9, "{kind:?} a={a} j={j}");
                    }
                }
            }
        }
    }

    #[test]
    fn physical_gradients_of_an_affine_element() {
        // x = A ξ + c with a general A: ∇N_a = A⁻ᵀ ∂N_a/∂ξ, det J = det A; check ∇(Σ N_a x_a) = I.
        let a = [[0.6, 0.1, 0.05], [-0.2, 0.4, 0.1], [0.0, 0.15, 0.3]];
        for kind in ElementKind::ALL {
            let n = kind.node_count();
            let coords: Vec<[f64; 3]> = natural_coordinates(kind)
                .iter()
                .map(|p| {
                    let mut x = [1.0, 2.0, 3.0];
                    for r in 0..3 {
                        for c in 0..3 {
                            x[r] += a[r][c] * p[c];
                        }
                    }
                    x
                })
                .collect();
            let mut v = [0.0; MAX_NODES];
            let mut d = [[0.0; 3]; MAX_NODES];
            let mut g = [[0.0; 3]; MAX_NODES];
            shape_functions(kind, [0.2, -0.4, 0.6], &mut v, &mut d);
            let det = physical_gradients(&coords, &d[..n], &mut g[..n]);
            assert!((det - determinant(&a)).abs() < 1e-14);
            for r in 0..3 {
                for c in 0..3 {
                    let s: f64 = (0..n).map(|k| coords[k][r] * g[k][c]).sum();
                    let e = if r == c { 1.0 } else { 0.0 };
                    assert!((s - e).abs() < 1e-13);
                }
            }
        }
    }
}
