//! Node selectors: which mesh nodes make up a support's or an interface's node set.

use super::Mesh;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Relative tolerance of the selectors: a length of `RELATIVE_TOLERANCE ×` the diagonal of the
/// mesh's bounding box (m) absorbs round-off in generated or imported coordinates.
pub const RELATIVE_TOLERANCE: f64 = 1e-9;

/// A rule selecting nodes of a mesh (body file: `{ "box": { "min": [..], "max": [..] } }`,
/// `{ "plane": { "point": [..], "normal": [..], "tolerance": 1e-9 } }` or `{ "group": "name" }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub enum NodeSelector {
    /// Nodes inside the closed axis-aligned box (m), with a tolerance relative to the mesh size
    /// ([`RELATIVE_TOLERANCE`] × bounding-box diagonal).
    Box { min: [f64; 3], max: [f64; 3] },
    /// Nodes within `tolerance` (m) of the plane through `point` with `normal` (any length but
    /// zero). Without `tolerance`: [`RELATIVE_TOLERANCE`] × bounding-box diagonal.
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        tolerance: Option<f64>,
    },
    /// The nodes of a named group of the mesh: a physical group of a Gmsh mesh (its elements'
    /// nodes, see [`crate::mesh::gmsh`]).
    Group(String),
}

impl NodeSelector {
    /// The selected node indices, ascending. An empty selection is an error naming the selector.
    pub fn select(&self, mesh: &Mesh) -> Result<Vec<usize>> {
        let (lo, hi) = mesh.bounding_box();
        let diagonal = (0..3).map(|d| (hi[d] - lo[d]).powi(2)).sum::<f64>().sqrt();
        let default_tolerance = RELATIVE_TOLERANCE * diagonal;
        let selected: Vec<usize> = match self {
            NodeSelector::Box { min, max } => {
                if (0..3).any(|d| !(min[d].is_finite() && max[d].is_finite() && min[d] <= max[d])) {
                    return Err(Error::new(format!(
                        "node selector {}: min must not exceed max and all bounds must be finite",
                        self.describe()
                    )));
                }
                let t = default_tolerance;
                mesh.nodes()
                    .iter()
                    .enumerate()
                    .filter(|(_, p)| (0..3).all(|d| p[d] >= min[d] - t && p[d] <= max[d] + t))
                    .map(|(i, _)| i)
                    .collect()
            }
            NodeSelector::Plane {
                point,
                normal,
                tolerance,
            } => {
                let length = normal.iter().map(|c| c * c).sum::<f64>().sqrt();
                if !(length.is_finite() && length > 0.0) || point.iter().any(|c| !c.is_finite()) {
                    return Err(Error::new(format!(
                        "node selector {}: the normal must be finite and nonzero, the point finite",
                        self.describe()
                    )));
                }
                let t = match tolerance {
                    None => default_tolerance,
                    Some(t) if t.is_finite() && *t >= 0.0 => *t,
                    Some(t) => {
                        return Err(Error::invalid_value(
                            "plane.tolerance",
                            t,
                            "must be non-negative and finite",
                        ))
                    }
                };
                mesh.nodes()
                    .iter()
                    .enumerate()
                    .filter(|(_, p)| {
                        let distance: f64 =
                            (0..3).map(|d| (p[d] - point[d]) * normal[d]).sum::<f64>() / length;
                        distance.abs() <= t
                    })
                    .map(|(i, _)| i)
                    .collect()
            }
            NodeSelector::Group(name) => match mesh.group(name) {
                Some(nodes) => nodes.to_vec(),
                None => {
                    let names: Vec<&str> = mesh.group_names().collect();
                    let known = if names.is_empty() {
                        "the mesh has no groups (only imported Gmsh meshes have physical groups)"
                            .to_string()
                    } else {
                        format!("its groups are: {}", names.join(", "))
                    };
                    return Err(Error::new(format!(
                        "node selector {}: the mesh has no group '{name}'; {known}",
                        self.describe()
                    )));
                }
            },
        };
        if selected.is_empty() {
            return Err(Error::new(format!(
                "node selector {} selects no node of the mesh (bounding box {lo:?} to {hi:?})",
                self.describe()
            )));
        }
        Ok(selected)
    }

    /// The selector as written in a body file, for messages.
    fn describe(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|_| format!("{self:?}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{beam, ElementKind};

    #[test]
    fn box_selects_closed_box_with_tolerance() {
        let m = beam(1.0, 0.2, 0.2, [10, 2, 2], ElementKind::Hex8).unwrap();
        // The root face x = 0: 3 × 3 nodes; the box is degenerate (min x = max x = 0).
        let s = NodeSelector::Box {
            min: [0.0, -1.0, -1.0],
            max: [0.0, 1.0, 1.0],
        };
        let root = s.select(&m).unwrap();
        assert_eq!(root, (0..9).collect::<Vec<_>>());
        // A face 1e-12 m inside the box still counts (tolerance 1e-9 × diagonal ≈ 1e-9 m).
        let s = NodeSelector::Box {
            min: [0.1 + 1e-12, -1.0, -1.0],
            max: [0.1 + 1e-12, 1.0, 1.0],
        };
        assert_eq!(s.select(&m).unwrap(), (9..18).collect::<Vec<_>>());
        // ... but 1e-6 m off does not.
        let s = NodeSelector::Box {
            min: [0.1 + 1e-6, -1.0, -1.0],
            max: [0.2 - 1e-6, 1.0, 1.0],
        };
        let e = s.select(&m).unwrap_err();
        assert!(
            e.message.contains("selects no node") && e.message.contains("box"),
            "{}",
            e.message
        );
    }

    #[test]
    fn plane_selects_by_distance() {
        let m = beam(1.0, 0.2, 0.2, [10, 2, 2], ElementKind::Hex20).unwrap();
        let tip = NodeSelector::Plane {
            point: [1.0, 0.0, 0.0],
            normal: [-2.0, 0.0, 0.0],
            tolerance: None,
        };
        let nodes = tip.select(&m).unwrap();
        assert_eq!(nodes.len(), 21); // 5×5 lattice minus 4 face-interior points
        assert!(nodes.windows(2).all(|w| w[0] < w[1]));
        assert!(nodes.iter().all(|&i| m.nodes()[i][0] == 1.0));
        // Diagonal plane y = z through the axis.
        let diag = NodeSelector::Plane {
            point: [0.0, 0.0, 0.0],
            normal: [0.0, 1.0, -1.0],
            tolerance: Some(1e-12),
        };
        let nodes = diag.select(&m).unwrap();
        assert!(!nodes.is_empty());
        assert!(nodes
            .iter()
            .all(|&i| (m.nodes()[i][1] - m.nodes()[i][2]).abs() < 1e-12));
        let zero = NodeSelector::Plane {
            point: [0.0; 3],
            normal: [0.0; 3],
            tolerance: None,
        };
        assert!(zero.select(&m).unwrap_err().message.contains("plane"));
        let far = NodeSelector::Plane {
            point: [2.0, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
            tolerance: None,
        };
        let e = far.select(&m).unwrap_err();
        assert!(
            e.message.contains("\"plane\"") && e.message.contains("selects no node"),
            "{}",
            e.message
        );
    }
}
