//! Meshes of 3D solids: nodes, elements of one kind, validation, generators and node selectors.

pub mod generator;
pub mod gmsh;
pub mod selector;

pub use generator::beam;
pub use selector::NodeSelector;

use crate::error::{Error, Result};
use std::collections::BTreeMap;

pub use crate::element::ElementKind;

/// A validated mesh: reference node positions `X` (m), the connectivity of elements of one kind
/// and named node sets (the physical groups of an imported mesh).
#[derive(Debug, Clone)]
pub struct Mesh {
    nodes: Vec<[f64; 3]>,
    kind: ElementKind,
    /// `kind.node_count()` node indices per element, flat.
    connectivity: Vec<usize>,
    /// Named node sets: ascending, unique node indices.
    groups: BTreeMap<String, Vec<usize>>,
}

impl Mesh {
    /// Builds a mesh and validates it: node indices in range, every node used, no inverted or
    /// degenerate element (the Jacobian determinant is positive at every quadrature point and node);
    /// the error names the element.
    ///
    /// "Degenerate" means `det J ≤ 1e-12 · (h/2)³` somewhere, with `h` the largest distance between
    /// two nodes of the element (`(h/2)³` is the size of `det J` of a cube of edge `h`; a regular
    /// tetrahedron of edge `h` has `det J = h³/√2`): the checks run at the points of the mass
    /// rule (the richest rule of each kind) and at the element's nodes.
    pub fn new(nodes: Vec<[f64; 3]>, kind: ElementKind, connectivity: Vec<usize>) -> Result<Mesh> {
        let per_element = kind.node_count();
        if nodes.is_empty() {
            return Err(Error::new("mesh: no nodes"));
        }
        if connectivity.is_empty() {
            return Err(Error::new("mesh: no elements"));
        }
        if !connectivity.len().is_multiple_of(per_element) {
            return Err(Error::new(format!(
                "mesh: connectivity length {} is not a multiple of {per_element} ({kind:?} nodes per element)",
                connectivity.len()
            )));
        }
        if let Some((i, p)) = nodes
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            return Err(Error::new(format!(
                "mesh: node {i} has a non-finite coordinate {p:?}"
            )));
        }
        let mut used = vec![false; nodes.len()];
        for (e, element) in connectivity.chunks(per_element).enumerate() {
            for (a, &node) in element.iter().enumerate() {
                if node >= nodes.len() {
                    return Err(Error::new(format!(
                        "mesh: element {e} local node {a} refers to node {node}, but the mesh has {} nodes",
                        nodes.len()
                    )));
                }
                used[node] = true;
            }
            for a in 0..per_element {
                if element[a + 1..].contains(&element[a]) {
                    return Err(Error::new(format!(
                        "mesh: element {e} uses node {} twice (degenerate element)",
                        element[a]
                    )));
                }
            }
        }
        if let Some(unused) = used.iter().position(|u| !u) {
            return Err(Error::new(format!(
                "mesh: node {unused} is not used by any element"
            )));
        }
        let mesh = Mesh {
            nodes,
            kind,
            connectivity,
            groups: BTreeMap::new(),
        };
        mesh.check_jacobians()?;
        Ok(mesh)
    }

    /// The mesh with named node sets (node indices in any order, repeats allowed); an index out of
    /// range or an empty set is an error naming the group.
    pub fn with_groups(mut self, groups: BTreeMap<String, Vec<usize>>) -> Result<Mesh> {
        for (name, mut nodes) in groups {
            nodes.sort_unstable();
            nodes.dedup();
            if nodes.is_empty() {
                return Err(Error::new(format!("mesh: node group '{name}' is empty")));
            }
            if let Some(&bad) = nodes.iter().find(|&&i| i >= self.nodes.len()) {
                return Err(Error::new(format!(
                    "mesh: node group '{name}' refers to node {bad}, but the mesh has {} nodes",
                    self.nodes.len()
                )));
            }
            self.groups.insert(name, nodes);
        }
        Ok(self)
    }

    /// The nodes of the named group (ascending), if there is one.
    pub fn group(&self, name: &str) -> Option<&[usize]> {
        self.groups.get(name).map(Vec::as_slice)
    }

    /// The names of the node groups, sorted.
    pub fn group_names(&self) -> impl Iterator<Item = &str> {
        self.groups.keys().map(String::as_str)
    }

    /// The Jacobian determinant check of [`Mesh::new`].
    fn check_jacobians(&self) -> Result<()> {
        use crate::element::{
            mass_rule, natural_coordinates, physical_gradients, shape_functions, MAX_NODES,
        };
        let kind = self.kind;
        let n = kind.node_count();
        let mut points: Vec<[f64; 3]> = mass_rule(kind).iter().map(|q| q.xi).collect();
        points.extend_from_slice(natural_coordinates(kind));
        // Natural derivatives at every check point, computed once.
        let mut values = [0.0; MAX_NODES];
        let derivatives: Vec<[[f64; 3]; MAX_NODES]> = points
            .iter()
            .map(|xi| {
                let mut d = [[0.0; 3]; MAX_NODES];
                shape_functions(kind, *xi, &mut values, &mut d);
                d
            })
            .collect();
        let mut coords = [[0.0; 3]; MAX_NODES];
        let mut gradients = [[0.0; 3]; MAX_NODES];
        for e in 0..self.element_count() {
            for (c, &node) in coords.iter_mut().zip(self.element(e)) {
                *c = self.nodes[node];
            }
            let mut h2: f64 = 0.0;
            for a in 0..n {
                for b in a + 1..n {
                    let d2: f64 = (0..3).map(|k| (coords[a][k] - coords[b][k]).powi(2)).sum();
                    h2 = h2.max(d2);
                }
            }
            let threshold = 1e-12 * (0.5 * h2.sqrt()).powi(3);
            for (xi, d) in points.iter().zip(&derivatives) {
                let det = physical_gradients(&coords[..n], &d[..n], &mut gradients[..n]);
                if det.is_nan() || det <= threshold {
                    let what = if det <= 0.0 { "inverted" } else { "degenerate" };
                    return Err(Error::new(format!(
                        "mesh: element {e} is {what}: Jacobian determinant {det:.6e} at natural point {xi:?} (must be > 0)"
                    )));
                }
            }
        }
        Ok(())
    }

    /// Reference node positions `X` (m).
    pub fn nodes(&self) -> &[[f64; 3]] {
        &self.nodes
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn kind(&self) -> ElementKind {
        self.kind
    }

    pub fn element_count(&self) -> usize {
        self.connectivity.len() / self.kind.node_count()
    }

    /// The node indices of element `e`.
    pub fn element(&self, e: usize) -> &[usize] {
        let n = self.kind.node_count();
        &self.connectivity[e * n..(e + 1) * n]
    }

    /// The centroid of element `e`'s nodes (m): the mean of their reference positions.
    pub fn element_centroid(&self, e: usize) -> [f64; 3] {
        let nodes = self.element(e);
        let mut c = [0.0; 3];
        for &i in nodes {
            for (cd, pd) in c.iter_mut().zip(&self.nodes[i]) {
                *cd += pd;
            }
        }
        c.map(|v| v / nodes.len() as f64)
    }

    /// Smallest axis-aligned box holding all nodes: (min, max).
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        bounding_box(self.nodes.iter().copied())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit cube Hex8 in VTK order.
    fn cube() -> Vec<[f64; 3]> {
        crate::element::HEX8_NODES
            .iter()
            .map(|p| [0.5 * (p[0] + 1.0), 0.5 * (p[1] + 1.0), 0.5 * (p[2] + 1.0)])
            .collect()
    }

    #[test]
    fn valid_cube_is_accepted() {
        let m = Mesh::new(cube(), ElementKind::Hex8, (0..8).collect()).unwrap();
        assert_eq!(m.element_count(), 1);
        assert_eq!(m.element(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn inverted_element_is_named() {
        // Two cubes side by side; the second lists its faces top/bottom swapped (mirror image).
        let mut nodes = cube();
        nodes.extend(cube().iter().map(|p| [p[0] + 1.0, p[1], p[2]]));
        let mut conn: Vec<usize> = (0..8).collect();
        conn.extend([12, 13, 14, 15, 8, 9, 10, 11]);
        let e = Mesh::new(nodes, ElementKind::Hex8, conn).unwrap_err();
        assert!(e.message.contains("element 1 is inverted"), "{}", e.message);
        assert!(
            e.message.contains("-1.25"),
            "det J = −(1/2)³ expected: {}",
            e.message
        );
    }

    #[test]
    fn distorted_node_inverting_only_near_a_node_is_caught() {
        // Pull corner 6 through the opposite corner region: det J < 0 at node 6 at least.
        let mut nodes = cube();
        nodes[6] = [0.1, 0.1, 0.1];
        let e = Mesh::new(nodes, ElementKind::Hex8, (0..8).collect()).unwrap_err();
        assert!(e.message.contains("element 0"), "{}", e.message);
    }

    #[test]
    fn flat_element_is_degenerate() {
        let mut nodes = cube();
        for p in nodes.iter_mut().skip(4) {
            p[2] = 0.0;
        }
        // Different nodes at the same place: reject, naming the element.
        let e = Mesh::new(nodes, ElementKind::Hex8, (0..8).collect()).unwrap_err();
        assert!(e.message.contains("element 0 is"), "{}", e.message);
    }

    #[test]
    fn bad_indices_and_unused_nodes() {
        let e = Mesh::new(cube(), ElementKind::Hex8, vec![0, 1, 2, 3, 4, 5, 6, 8]).unwrap_err();
        assert!(
            e.message
                .contains("element 0 local node 7 refers to node 8"),
            "{}",
            e.message
        );
        let mut nodes = cube();
        nodes.push([5.0, 5.0, 5.0]);
        let e = Mesh::new(nodes, ElementKind::Hex8, (0..8).collect()).unwrap_err();
        assert!(e.message.contains("node 8 is not used"), "{}", e.message);
        let e = Mesh::new(cube(), ElementKind::Hex20, (0..8).collect()).unwrap_err();
        assert!(e.message.contains("not a multiple of 20"), "{}", e.message);
    }
}

#[cfg(test)]
mod hex20_tests {
    use super::*;

    #[test]
    fn folded_hex20_edge_is_rejected() {
        // Mid-edge node 8 of edge 0-1 pulled beyond corner 1: the map folds near node 1.
        let base = generator::beam(1.0, 1.0, 1.0, [1, 1, 1], ElementKind::Hex20).unwrap();
        let mut nodes = base.nodes().to_vec();
        let mid = base.element(0)[8];
        nodes[mid][0] = 1.3;
        let conn = base.element(0).to_vec();
        let e = Mesh::new(nodes, ElementKind::Hex20, conn).unwrap_err();
        assert!(e.message.contains("element 0 is inverted"), "{}", e.message);
    }
}

/// The smallest and largest coordinates of `points` (the corners of their axis-aligned bounding
/// box), m.
pub fn bounding_box(points: impl Iterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}
