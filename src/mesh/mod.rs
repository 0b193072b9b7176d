//! Meshes of 3D solids: nodes, elements of one kind, validation, generators and node selectors.

pub mod generator;
pub mod selector;

pub use generator::beam;
pub use selector::NodeSelector;

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The element kinds the finite elements of [`crate::fem`] know.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElementKind {
    /// 8-node trilinear hexahedron (VTK_HEXAHEDRON node order).
    Hex8,
    /// 20-node serendipity hexahedron (VTK_QUADRATIC_HEXAHEDRON node order).
    Hex20,
}

impl ElementKind {
    /// Nodes per element.
    pub fn node_count(self) -> usize {
        match self {
            ElementKind::Hex8 => 8,
            ElementKind::Hex20 => 20,
        }
    }
}

/// A validated mesh: reference node positions `X` (m) and the connectivity of elements of one kind.
#[derive(Debug, Clone)]
pub struct Mesh {
    nodes: Vec<[f64; 3]>,
    kind: ElementKind,
    /// `kind.node_count()` node indices per element, flat.
    connectivity: Vec<usize>,
}

impl Mesh {
    /// Builds a mesh and validates it: node indices in range, every node used, no inverted or
    /// degenerate element (the Jacobian determinant is positive at every quadrature point and node);
    /// the error names the element.
    pub fn new(nodes: Vec<[f64; 3]>, kind: ElementKind, connectivity: Vec<usize>) -> Result<Mesh> {
        let _ = (&nodes, kind, &connectivity);
        Err(Error::new("Mesh::new: not implemented"))
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

    /// Smallest axis-aligned box holding all nodes: (min, max).
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.nodes {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        (lo, hi)
    }
}
