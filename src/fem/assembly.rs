//! Assembly of the constant FE matrices of a mesh.
//!
//! The sparsity pattern comes from the node graph (nodes sharing an element), built once per
//! matrix; element matrices are computed into fixed-size stack arrays and scattered straight into
//! the CSR values (no triplets, no per-element heap allocation). `K` uses the rule of
//! [`integration_rule`] (full Gauss–Legendre 2×2×2 for Hex8, 3×3×3 for Hex20; 1 point for Tet4,
//! 4 for Tet10), the mass and the lumped masses that of [`mass_rule`] (the same for the
//! hexahedra; 4 points for Tet4, 14 for Tet10).

use super::element::{integration_rule, mass_rule, physical_gradients, shape_functions, MAX_NODES};
use super::quadrature::QuadraturePoint;
use super::IsotropicMaterial;
use crate::linalg::SymmetricCsr;
use crate::mesh::{ElementKind, Mesh};

/// Shape function values and natural derivatives at the points of a rule of `kind`.
struct ReferenceElement {
    weights: Vec<f64>,
    values: Vec<[f64; MAX_NODES]>,
    derivatives: Vec<[[f64; 3]; MAX_NODES]>,
}

impl ReferenceElement {
    /// At the points of the stiffness rule ([`integration_rule`]).
    fn new(kind: ElementKind) -> ReferenceElement {
        Self::with_rule(kind, &integration_rule(kind))
    }

    /// At the points of the mass rule ([`mass_rule`]).
    fn for_mass(kind: ElementKind) -> ReferenceElement {
        Self::with_rule(kind, &mass_rule(kind))
    }

    fn with_rule(kind: ElementKind, rule: &[QuadraturePoint]) -> ReferenceElement {
        let mut values = Vec::with_capacity(rule.len());
        let mut derivatives = Vec::with_capacity(rule.len());
        for q in rule {
            let mut v = [0.0; MAX_NODES];
            let mut d = [[0.0; 3]; MAX_NODES];
            shape_functions(kind, q.xi, &mut v, &mut d);
            values.push(v);
            derivatives.push(d);
        }
        ReferenceElement {
            weights: rule.iter().map(|q| q.weight).collect(),
            values,
            derivatives,
        }
    }
}

/// The node graph: for node `i`, the ascending list of nodes sharing an element with it
/// (including `i`), in CSR form.
struct NodeGraph {
    row_ptr: Vec<usize>,
    neighbours: Vec<usize>,
}

impl NodeGraph {
    fn new(mesh: &Mesh) -> NodeGraph {
        let n = mesh.node_count();
        // Elements of each node (CSR).
        let mut elem_ptr = vec![0usize; n + 1];
        for e in 0..mesh.element_count() {
            for &i in mesh.element(e) {
                elem_ptr[i + 1] += 1;
            }
        }
        for i in 0..n {
            elem_ptr[i + 1] += elem_ptr[i];
        }
        let mut fill = elem_ptr.clone();
        let mut elements = vec![0usize; elem_ptr[n]];
        for e in 0..mesh.element_count() {
            for &i in mesh.element(e) {
                elements[fill[i]] = e;
                fill[i] += 1;
            }
        }
        let mut row_ptr = Vec::with_capacity(n + 1);
        row_ptr.push(0);
        let mut neighbours = Vec::new();
        let mut scratch = Vec::new();
        for i in 0..n {
            scratch.clear();
            for &e in &elements[elem_ptr[i]..elem_ptr[i + 1]] {
                scratch.extend_from_slice(mesh.element(e));
            }
            scratch.sort_unstable();
            scratch.dedup();
            neighbours.extend_from_slice(&scratch);
            row_ptr.push(neighbours.len());
        }
        NodeGraph {
            row_ptr,
            neighbours,
        }
    }

    /// Position of node `j` within the neighbour list of node `i`.
    fn position(&self, i: usize, j: usize) -> usize {
        self.neighbours[self.row_ptr[i]..self.row_ptr[i + 1]]
            .binary_search(&j)
            .expect("element nodes are neighbours")
    }

    /// For element nodes `nodes`, `out[a * n + b]` = position of `nodes[b]` in the list of `nodes[a]`.
    fn local_positions(&self, nodes: &[usize], out: &mut [usize; MAX_NODES * MAX_NODES]) {
        let n = nodes.len();
        for (a, &i) in nodes.iter().enumerate() {
            for (b, &j) in nodes.iter().enumerate() {
                out[a * n + b] = self.position(i, j);
            }
        }
    }
}

/// Copies the coordinates of the nodes of element `e` into `coords`.
fn element_coordinates(mesh: &Mesh, e: usize, coords: &mut [[f64; 3]; MAX_NODES]) {
    for (c, &node) in coords.iter_mut().zip(mesh.element(e)) {
        *c = mesh.nodes()[node];
    }
}

/// The consistent scalar mass matrix `Ms[i,j] = ∫ ρ N_i N_j dV` (kg), `N × N` for `N` nodes.
/// The mass matrix of the body is `M = Ms ⊗ I3`. `Σ_ij Ms[i,j] = ρ V` (partition of unity).
pub fn scalar_mass_matrix(mesh: &Mesh, density: f64) -> SymmetricCsr {
    scalar_mass_matrix_of(mesh, &|_| density)
}

/// [`scalar_mass_matrix`] with the density (kg/m³) of each element, `density(e)` (material
/// regions).
pub fn scalar_mass_matrix_of(mesh: &Mesh, density: &dyn Fn(usize) -> f64) -> SymmetricCsr {
    let graph = NodeGraph::new(mesh);
    let reference = ReferenceElement::for_mass(mesh.kind());
    let n = mesh.kind().node_count();
    let mut values = vec![0.0; graph.neighbours.len()];
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    let mut positions = [0usize; MAX_NODES * MAX_NODES];
    let mut me = [[0.0; MAX_NODES]; MAX_NODES];
    for e in 0..mesh.element_count() {
        let density = density(e);
        element_coordinates(mesh, e, &mut coords);
        for row in me.iter_mut().take(n) {
            row[..n].fill(0.0);
        }
        for q in 0..reference.weights.len() {
            let det = physical_gradients(
                &coords[..n],
                &reference.derivatives[q][..n],
                &mut gradients[..n],
            );
            let w = density * reference.weights[q] * det;
            let v = &reference.values[q];
            for a in 0..n {
                let wa = w * v[a];
                for b in a..n {
                    me[a][b] += wa * v[b];
                }
            }
        }
        let nodes = mesh.element(e);
        graph.local_positions(nodes, &mut positions);
        for a in 0..n {
            let start = graph.row_ptr[nodes[a]];
            for b in 0..n {
                let m = if b >= a { me[a][b] } else { me[b][a] };
                values[start + positions[a * n + b]] += m;
            }
        }
    }
    SymmetricCsr {
        n: mesh.node_count(),
        row_ptr: graph.row_ptr,
        col_idx: graph.neighbours,
        values,
    }
}

/// The sparsity pattern of [`stiffness_matrix`] with all values zero: row `3i+d` holds columns
/// `3j, 3j+1, 3j+2` for every node `j` sharing an element with node `i` (including `i`),
/// ascending. Every `3N × 3N` matrix of a mesh (`K`, `K_G`, the tangent) has this pattern.
pub fn stiffness_pattern(mesh: &Mesh) -> SymmetricCsr {
    displacement_pattern(&NodeGraph::new(mesh))
}

/// Row `3i+d` holds columns `3j+e` for every neighbour `j` of `i` and `e = 0, 1, 2`.
fn displacement_pattern(graph: &NodeGraph) -> SymmetricCsr {
    let node_count = graph.row_ptr.len() - 1;
    let mut row_ptr = Vec::with_capacity(3 * node_count + 1);
    row_ptr.push(0);
    let mut col_idx = Vec::with_capacity(9 * graph.neighbours.len());
    for i in 0..node_count {
        let neighbours = &graph.neighbours[graph.row_ptr[i]..graph.row_ptr[i + 1]];
        for _ in 0..3 {
            for &j in neighbours {
                col_idx.extend_from_slice(&[3 * j, 3 * j + 1, 3 * j + 2]);
            }
            row_ptr.push(col_idx.len());
        }
    }
    SymmetricCsr {
        n: 3 * node_count,
        values: vec![0.0; col_idx.len()],
        row_ptr,
        col_idx,
    }
}

/// The small-strain stiffness `K = ∫ Bᵀ D B dV` (N/m), `3N × 3N`, DOF `3 * node + direction`.
///
/// For the isotropic `D` of [`IsotropicMaterial::elasticity_matrix`] the 3×3 block coupling
/// nodes `a` and `b` reduces to
/// `K_ab[d][e] = ∫ λ ∂_d N_a ∂_e N_b + μ ∂_e N_a ∂_d N_b + μ δ_de ∇N_a·∇N_b dV`
/// (the Hessian of the strain energy density `λ/2 (tr ε)² + μ ε:ε`), which is what is summed.
pub fn stiffness_matrix(mesh: &Mesh, material: &IsotropicMaterial) -> SymmetricCsr {
    stiffness_matrix_of(mesh, &|_| *material)
}

/// [`stiffness_matrix`] with the material of each element, `material(e)` (material regions:
/// `λ`, `μ` per element; the assembled `K` stays symmetric positive semi-definite with the
/// six rigid-body modes in its kernel).
pub fn stiffness_matrix_of(
    mesh: &Mesh,
    material: &dyn Fn(usize) -> IsotropicMaterial,
) -> SymmetricCsr {
    let graph = NodeGraph::new(mesh);
    let reference = ReferenceElement::new(mesh.kind());
    let n = mesh.kind().node_count();
    let node_count = mesh.node_count();
    let SymmetricCsr {
        row_ptr,
        col_idx,
        mut values,
        ..
    } = displacement_pattern(&graph);

    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    let mut positions = [0usize; MAX_NODES * MAX_NODES];
    // Upper-triangle blocks (b ≥ a) of the element matrix, block (a, b) row-major 3×3.
    let mut ke = [[[0.0f64; 9]; MAX_NODES]; MAX_NODES];
    for e in 0..mesh.element_count() {
        let element_material = material(e);
        let lambda = element_material.lame_lambda();
        let mu = element_material.shear_modulus();
        element_coordinates(mesh, e, &mut coords);
        for row in ke.iter_mut().take(n) {
            for block in row.iter_mut().take(n) {
                *block = [0.0; 9];
            }
        }
        for q in 0..reference.weights.len() {
            let det = physical_gradients(
                &coords[..n],
                &reference.derivatives[q][..n],
                &mut gradients[..n],
            );
            let w = reference.weights[q] * det;
            for a in 0..n {
                let ga = gradients[a];
                let la = [w * lambda * ga[0], w * lambda * ga[1], w * lambda * ga[2]];
                let ma = [w * mu * ga[0], w * mu * ga[1], w * mu * ga[2]];
                for b in a..n {
                    let gb = gradients[b];
                    let dot = ma[0] * gb[0] + ma[1] * gb[1] + ma[2] * gb[2];
                    let block = &mut ke[a][b];
                    for d in 0..3 {
                        for c in 0..3 {
                            block[3 * d + c] += la[d] * gb[c] + ma[c] * gb[d];
                        }
                        block[4 * d] += dot;
                    }
                }
            }
        }
        let nodes = mesh.element(e);
        graph.local_positions(nodes, &mut positions);
        for a in 0..n {
            for b in 0..n {
                let p = 3 * positions[a * n + b];
                for d in 0..3 {
                    let start = row_ptr[3 * nodes[a] + d] + p;
                    for c in 0..3 {
                        // K_ba = K_abᵀ.
                        let v = if b >= a {
                            ke[a][b][3 * d + c]
                        } else {
                            ke[b][a][3 * c + d]
                        };
                        values[start + c] += v;
                    }
                }
            }
        }
    }
    SymmetricCsr {
        n: 3 * node_count,
        row_ptr,
        col_idx,
        values,
    }
}

/// HRZ-lumped (diagonal-scaled) nodal masses (kg): `m_i = Ms[i,i] · m_e / Σ_j Ms_e[j,j]` summed
/// over elements; all positive, summing to the total mass `ρV`.
pub fn lumped_masses(mesh: &Mesh, density: f64) -> Vec<f64> {
    lumped_masses_of(mesh, &|_| density)
}

/// [`lumped_masses`] with the density (kg/m³) of each element, `density(e)`.
pub fn lumped_masses_of(mesh: &Mesh, density: &dyn Fn(usize) -> f64) -> Vec<f64> {
    let reference = ReferenceElement::for_mass(mesh.kind());
    let n = mesh.kind().node_count();
    let mut lumped = vec![0.0; mesh.node_count()];
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    let mut diagonal = [0.0; MAX_NODES];
    for e in 0..mesh.element_count() {
        let density = density(e);
        element_coordinates(mesh, e, &mut coords);
        diagonal[..n].fill(0.0);
        let mut element_mass = 0.0;
        for q in 0..reference.weights.len() {
            let det = physical_gradients(
                &coords[..n],
                &reference.derivatives[q][..n],
                &mut gradients[..n],
            );
            let w = density * reference.weights[q] * det;
            element_mass += w;
            for (diag, &value) in diagonal[..n].iter_mut().zip(&reference.values[q][..n]) {
                *diag += w * value * value;
            }
        }
        let scale = element_mass / diagonal[..n].iter().sum::<f64>();
        for (a, &node) in mesh.element(e).iter().enumerate() {
            lumped[node] += scale * diagonal[a];
        }
    }
    lumped
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices
mod tests {
    use super::*;
    use crate::fem::element::{edges, natural_coordinates};
    use crate::linalg::cholesky::SparseCholesky;
    use crate::mesh::beam;
    use nalgebra::{DMatrix, SymmetricEigen};

    /// A distorted single element: the unit cube with corners moved (mid-edge nodes of Hex20 on
    /// the straight edges between them).
    fn distorted_element(kind: ElementKind) -> Mesh {
        let shift = [
            [0.0, 0.0, 0.0],
            [0.1, -0.05, 0.02],
            [0.05, 0.1, -0.03],
            [-0.08, 0.0, 0.04],
            [0.02, 0.06, 0.0],
            [0.0, -0.1, 0.1],
            [0.12, 0.04, -0.05],
            [-0.04, 0.0, 0.09],
        ];
        let mut nodes: Vec<[f64; 3]> = natural_coordinates(kind)
            .iter()
            .map(|p| [0.5 * (p[0] + 1.0), 0.5 * (p[1] + 1.0), 0.5 * (p[2] + 1.0)])
            .collect();
        for (p, s) in nodes.iter_mut().zip(shift) {
            for d in 0..3 {
                p[d] += s[d];
            }
        }
        straighten_edges(
            &mut nodes,
            kind,
            &(0..kind.node_count()).collect::<Vec<_>>(),
        );
        Mesh::new(nodes, kind, (0..kind.node_count()).collect()).unwrap()
    }

    /// Places every Hex20 or Tet10 mid-edge node at the midpoint of its edge's corners.
    fn straighten_edges(nodes: &mut [[f64; 3]], kind: ElementKind, element: &[usize]) {
        if kind.is_quadratic() {
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

    /// Sorted eigenvalues of `K` divided by the largest.
    fn relative_spectrum(k: &SymmetricCsr) -> Vec<f64> {
        let mut ev: Vec<f64> = SymmetricEigen::new(k.to_dense())
            .eigenvalues
            .iter()
            .copied()
            .collect();
        ev.sort_by(f64::total_cmp);
        let max = *ev.last().unwrap();
        ev.iter().map(|v| v / max).collect()
    }

    /// Six rigid-body modes: |λ| ≤ 1e-12 λ_max (round-off of a matrix with entries ~λ_max is
    /// ~1e-15 λ_max); the 7th (smallest deformation mode) must be ≥ 1e-3 λ_max.
    fn assert_six_rigid_modes(k: &SymmetricCsr, what: &str) {
        let ev = relative_spectrum(k);
        let zeros = ev.iter().filter(|v| v.abs() <= 1e-12).count();
        assert_eq!(zeros, 6, "{what}: spectrum starts {:?}", &ev[..8]);
        assert!(ev[6] >= 1e-3, "{what}: 7th eigenvalue {:e} λ_max", ev[6]);
    }

    #[test]
    fn stiffness_has_exactly_six_zero_eigenvalues() {
        for kind in ElementKind::ALL {
            let cube = beam(1.0, 1.0, 1.0, [1, 1, 1], kind).unwrap();
            assert_six_rigid_modes(
                &stiffness_matrix(&cube, &IsotropicMaterial::STEEL),
                &format!("{kind:?} cube"),
            );
            let distorted = distorted_element(kind);
            assert_six_rigid_modes(
                &stiffness_matrix(&distorted, &IsotropicMaterial::STEEL),
                &format!("{kind:?} distorted"),
            );
            let pair = beam(2.0, 1.0, 0.7, [2, 1, 1], kind).unwrap();
            assert_six_rigid_modes(
                &stiffness_matrix(&pair, &IsotropicMaterial::STEEL),
                &format!("{kind:?} 2×1×1"),
            );
        }
    }

    /// `∫ Bᵀ D B dV` with the explicit 6×3N strain–displacement matrix and `D` of the material.
    fn reference_stiffness(mesh: &Mesh, material: &IsotropicMaterial) -> DMatrix<f64> {
        let kind = mesh.kind();
        let n = kind.node_count();
        let d = DMatrix::from_fn(6, 6, |r, c| material.elasticity_matrix()[r][c]);
        let mut k = DMatrix::zeros(3 * n, 3 * n);
        let coords: Vec<[f64; 3]> = mesh.element(0).iter().map(|&i| mesh.nodes()[i]).collect();
        for q in integration_rule(kind) {
            let mut v = [0.0; MAX_NODES];
            let mut dn = [[0.0; 3]; MAX_NODES];
            let mut g = [[0.0; 3]; MAX_NODES];
            shape_functions(kind, q.xi, &mut v, &mut dn);
            let det = physical_gradients(&coords, &dn[..n], &mut g[..n]);
            let mut b = DMatrix::zeros(6, 3 * n);
            for a in 0..n {
                let [gx, gy, gz] = g[a];
                b[(0, 3 * a)] = gx;
                b[(1, 3 * a + 1)] = gy;
                b[(2, 3 * a + 2)] = gz;
                b[(3, 3 * a + 1)] = gz; // γ_yz
                b[(3, 3 * a + 2)] = gy;
                b[(4, 3 * a)] = gz; // γ_xz
                b[(4, 3 * a + 2)] = gx;
                b[(5, 3 * a)] = gy; // γ_xy
                b[(5, 3 * a + 1)] = gx;
            }
            k += b.transpose() * &d * b * (q.weight * det);
        }
        k
    }

    #[test]
    fn isotropic_block_formula_equals_bt_d_b() {
        for kind in ElementKind::ALL {
            let mesh = distorted_element(kind);
            let k = stiffness_matrix(&mesh, &IsotropicMaterial::STEEL).to_dense();
            let reference = reference_stiffness(&mesh, &IsotropicMaterial::STEEL);
            let scale = reference.amax();
            assert!((k - reference).amax() <= 1e-13 * scale, "{kind:?}");
        }
    }

    #[test]
    fn masses_sum_to_rho_v_and_hrz_is_positive() {
        let rho = 7850.0;
        for kind in ElementKind::ALL {
            for mesh in [
                beam(1.0, 0.02, 0.03, [5, 2, 3], kind).unwrap(),
                patch_mesh(kind),
            ] {
                let (lo, hi) = mesh.bounding_box();
                let total = rho * (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
                let ms = scalar_mass_matrix(&mesh, rho);
                let sum: f64 = ms.values.iter().sum();
                assert!(
                    (sum - total).abs() <= 1e-12 * total,
                    "{kind:?}: Σ Ms = {sum}, ρV = {total}"
                );
                let lumped = lumped_masses(&mesh, rho);
                let sum: f64 = lumped.iter().sum();
                assert!(
                    (sum - total).abs() <= 1e-12 * total,
                    "{kind:?}: Σ lumped = {sum}"
                );
                assert!(
                    lumped.iter().all(|&m| m > 0.0),
                    "{kind:?}: a lumped mass is not positive"
                );
                // Ms is symmetric positive definite.
                assert!(SparseCholesky::new(&ms).is_ok());
                assert_eq!(ms.to_dense(), ms.to_dense().transpose());
            }
        }
        // Why HRZ: the consistent row sums of a Hex20 are negative at the corners, and those of a
        // Tet10 too (−ρV/20 for a single element: ∫ L(2L − 1) dV = −V/20).
        let cube = beam(1.0, 1.0, 1.0, [1, 1, 1], ElementKind::Hex20).unwrap();
        let ms = scalar_mass_matrix(&cube, rho);
        let corner_row: f64 = ms.row(cube.element(0)[0]).1.iter().sum();
        assert!(corner_row < 0.0, "corner row sum {corner_row}");
        let tet = Mesh::new(
            crate::fem::element::TET10_NODES.to_vec(),
            ElementKind::Tet10,
            (0..10).collect(),
        )
        .unwrap();
        let ms = scalar_mass_matrix(&tet, rho);
        let volume = 1.0 / 6.0;
        for corner in 0..4 {
            let row: f64 = ms.row(corner).1.iter().sum();
            assert!(
                (row + rho * volume / 20.0).abs() < 1e-12 * rho * volume,
                "Tet10 corner row sum {row}"
            );
        }
    }

    /// 2×2×2 block `[0,2]×[−1,1]²` with the interior corner node and the face-centre corner nodes
    /// moved (face centres within their face), Hex20 mid-edge nodes on straight edges.
    fn patch_mesh(kind: ElementKind) -> Mesh {
        let base = beam(2.0, 2.0, 2.0, [2, 2, 2], kind).unwrap();
        let mut nodes = base.nodes().to_vec();
        let moves: [([f64; 3], [f64; 3]); 7] = [
            ([1.0, 0.0, 0.0], [1.17, -0.13, 0.09]),
            ([0.0, 0.0, 0.0], [0.0, 0.11, -0.07]),
            ([2.0, 0.0, 0.0], [2.0, -0.09, 0.14]),
            ([1.0, -1.0, 0.0], [0.86, -1.0, 0.12]),
            ([1.0, 1.0, 0.0], [1.1, 1.0, -0.15]),
            ([1.0, 0.0, -1.0], [0.92, 0.08, -1.0]),
            ([1.0, 0.0, 1.0], [1.13, -0.1, 1.0]),
        ];
        for (from, to) in moves {
            let i = nodes.iter().position(|p| *p == from).expect("lattice node");
            nodes[i] = to;
        }
        for e in 0..base.element_count() {
            straighten_edges(&mut nodes, kind, base.element(e));
        }
        Mesh::new(
            nodes,
            kind,
            (0..base.element_count())
                .flat_map(|e| base.element(e).to_vec())
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn constant_strain_patch_test_on_distorted_meshes() {
        let a = [
            [1.0e-3, 2.0e-4, -3.0e-4],
            [5.0e-4, -2.0e-3, 1.0e-4],
            [-1.0e-4, 3.0e-4, 1.5e-3],
        ];
        let b = [1.0e-3, -2.0e-3, 5.0e-4];
        let exact = |x: &[f64; 3]| -> [f64; 3] {
            let mut u = b;
            for r in 0..3 {
                for c in 0..3 {
                    u[r] += a[r][c] * x[c];
                }
            }
            u
        };
        let material = IsotropicMaterial::STEEL;
        for kind in ElementKind::ALL {
            let mesh = patch_mesh(kind);
            let (lo, hi) = mesh.bounding_box();
            let on_boundary = |p: &[f64; 3]| {
                (0..3).any(|d| (p[d] - lo[d]).abs() < 1e-12 || (p[d] - hi[d]).abs() < 1e-12)
            };
            let interior: Vec<usize> = (0..mesh.node_count())
                .filter(|&i| !on_boundary(&mesh.nodes()[i]))
                .collect();
            // Tet10: every point of the 5×5×5 lattice is a node (module doc of `beam`).
            let expected_interior = match kind {
                ElementKind::Hex8 | ElementKind::Tet4 => 1,
                ElementKind::Hex20 => 7,
                ElementKind::Tet10 => 27,
            };
            assert_eq!(interior.len(), expected_interior);
            let free: Vec<usize> = interior
                .iter()
                .flat_map(|&i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect();
            let k = stiffness_matrix(&mesh, &material);
            // Boundary displacements prescribed, interior zero: rhs = −K_IB u_B = −(K u_B)_I.
            let mut u = vec![0.0; 3 * mesh.node_count()];
            for (i, p) in mesh.nodes().iter().enumerate() {
                if on_boundary(p) {
                    u[3 * i..3 * i + 3].copy_from_slice(&exact(p));
                }
            }
            let mut ku = vec![0.0; u.len()];
            k.mul_vec(&u, &mut ku);
            let mut rhs: Vec<f64> = free.iter().map(|&f| -ku[f]).collect();
            let factor = SparseCholesky::new(&k.submatrix(&free)).unwrap();
            factor.solve_in_place(&mut rhs, &mut factor.solve_scratch());
            for (&f, &value) in free.iter().zip(&rhs) {
                u[f] = value;
            }
            let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for &i in &interior {
                let e = exact(&mesh.nodes()[i]);
                for d in 0..3 {
                    let err = (u[3 * i + d] - e[d]).abs();
                    assert!(
                        err <= 1e-10 * scale,
                        "{kind:?} node {i} dir {d}: error {err:e}"
                    );
                }
            }
            // Strain (and so stress σ = D ε) at every quadrature point equals sym(A).
            let n = kind.node_count();
            let mut v = [0.0; MAX_NODES];
            let mut dn = [[0.0; 3]; MAX_NODES];
            let mut g = [[0.0; 3]; MAX_NODES];
            let strain_scale = 2.0e-3;
            for el in 0..mesh.element_count() {
                let nodes = mesh.element(el);
                let coords: Vec<[f64; 3]> = nodes.iter().map(|&i| mesh.nodes()[i]).collect();
                for q in integration_rule(kind) {
                    shape_functions(kind, q.xi, &mut v, &mut dn);
                    physical_gradients(&coords, &dn[..n], &mut g[..n]);
                    for r in 0..3 {
                        for c in 0..3 {
                            let grad: f64 = (0..n).map(|k| u[3 * nodes[k] + r] * g[k][c]).sum();
                            let grad_t: f64 = (0..n).map(|k| u[3 * nodes[k] + c] * g[k][r]).sum();
                            let eps = 0.5 * (grad + grad_t);
                            let eps_exact = 0.5 * (a[r][c] + a[c][r]);
                            assert!(
                                (eps - eps_exact).abs() <= 1e-10 * strain_scale,
                                "{kind:?} element {el}"
                            );
                        }
                    }
                }
            }
        }
    }
}
