//! Assembly of the constant FE matrices of a mesh.
//!
//! The sparsity pattern comes from the node graph (nodes sharing an element), built once per
//! matrix; element matrices are computed into fixed-size stack arrays and scattered straight into
//! the CSR values (no triplets, no per-element heap allocation). `K` uses the rule of
//! [`integration_rule`] (full Gauss–Legendre 2×2×2 for Hex8, 3×3×3 for Hex20; 1 point for Tet4,
//! 4 for Tet10), the mass and the lumped masses that of [`mass_rule`] (the same for the
//! hexahedra; 4 points for Tet4, 14 for Tet10).

use super::IsotropicMaterial;
use crate::element::quadrature::QuadraturePoint;
use crate::element::{integration_rule, mass_rule, physical_gradients, shape_functions, MAX_NODES};
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
pub(crate) mod tests;
