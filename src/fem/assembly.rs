//! Assembly of the constant FE matrices of a mesh.
//!
//! The sparsity pattern comes from the node graph (nodes sharing an element), built once per
//! matrix; element matrices are computed into fixed-size stack arrays and scattered straight into
//! the CSR values (no triplets, no per-element heap allocation). Both matrices use the full
//! Gauss–Legendre rule of [`full_integration_points`] (2×2×2 for Hex8, 3×3×3 for Hex20).

use super::element::{full_integration_points, physical_gradients, shape_functions, MAX_NODES};
use super::quadrature::hexahedron_rule;
use super::{IsotropicMaterial, SymmetricCsr};
use crate::mesh::{ElementKind, Mesh};

/// Shape function values and natural derivatives at the points of the full rule of `kind`.
struct ReferenceElement {
    weights: Vec<f64>,
    values: Vec<[f64; MAX_NODES]>,
    derivatives: Vec<[[f64; 3]; MAX_NODES]>,
}

impl ReferenceElement {
    fn new(kind: ElementKind) -> ReferenceElement {
        let rule = hexahedron_rule(full_integration_points(kind));
        let mut values = Vec::with_capacity(rule.len());
        let mut derivatives = Vec::with_capacity(rule.len());
        for q in &rule {
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
    let graph = NodeGraph::new(mesh);
    let reference = ReferenceElement::new(mesh.kind());
    let n = mesh.kind().node_count();
    let mut values = vec![0.0; graph.neighbours.len()];
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    let mut positions = [0usize; MAX_NODES * MAX_NODES];
    let mut me = [[0.0; MAX_NODES]; MAX_NODES];
    for e in 0..mesh.element_count() {
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

/// The small-strain stiffness `K = ∫ Bᵀ D B dV` (N/m), `3N × 3N`, DOF `3 * node + direction`.
///
/// For the isotropic `D` of [`IsotropicMaterial::elasticity_matrix`] the 3×3 block coupling
/// nodes `a` and `b` reduces to
/// `K_ab[d][e] = ∫ λ ∂_d N_a ∂_e N_b + μ ∂_e N_a ∂_d N_b + μ δ_de ∇N_a·∇N_b dV`
/// (the Hessian of the strain energy density `λ/2 (tr ε)² + μ ε:ε`), which is what is summed.
pub fn stiffness_matrix(mesh: &Mesh, material: &IsotropicMaterial) -> SymmetricCsr {
    let graph = NodeGraph::new(mesh);
    let reference = ReferenceElement::new(mesh.kind());
    let n = mesh.kind().node_count();
    let lambda = material.lame_lambda();
    let mu = material.shear_modulus();
    let node_count = mesh.node_count();

    // Pattern: row 3i+d holds columns 3j+e for every neighbour j of i and e = 0, 1, 2.
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
    let mut values = vec![0.0; col_idx.len()];

    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    let mut positions = [0usize; MAX_NODES * MAX_NODES];
    // Upper-triangle blocks (b ≥ a) of the element matrix, block (a, b) row-major 3×3.
    let mut ke = [[[0.0f64; 9]; MAX_NODES]; MAX_NODES];
    for e in 0..mesh.element_count() {
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
    let reference = ReferenceElement::new(mesh.kind());
    let n = mesh.kind().node_count();
    let mut lumped = vec![0.0; mesh.node_count()];
    let mut coords = [[0.0; 3]; MAX_NODES];
    let mut gradients = [[0.0; 3]; MAX_NODES];
    let mut diagonal = [0.0; MAX_NODES];
    for e in 0..mesh.element_count() {
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
            for a in 0..n {
                diagonal[a] += w * reference.values[q][a] * reference.values[q][a];
            }
        }
        let scale = element_mass / diagonal[..n].iter().sum::<f64>();
        for (a, &node) in mesh.element(e).iter().enumerate() {
            lumped[node] += scale * diagonal[a];
        }
    }
    lumped
}
