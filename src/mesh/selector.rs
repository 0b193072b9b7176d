//! Node selectors: which mesh nodes make up a support's or an interface's node set.

use super::Mesh;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// A rule selecting nodes of a mesh (body file: `{ "box": { "min": [..], "max": [..] } }` or
/// `{ "plane": { "point": [..], "normal": [..], "tolerance": 1e-9 } }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub enum NodeSelector {
    /// Nodes inside the closed axis-aligned box (m), with a tolerance relative to the mesh size.
    Box { min: [f64; 3], max: [f64; 3] },
    /// Nodes within `tolerance` (m) of the plane through `point` with `normal`.
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        tolerance: Option<f64>,
    },
}

impl NodeSelector {
    /// The selected node indices, ascending. An empty selection is an error naming the selector.
    pub fn select(&self, mesh: &Mesh) -> Result<Vec<usize>> {
        let _ = mesh;
        todo!("select")
    }
}
