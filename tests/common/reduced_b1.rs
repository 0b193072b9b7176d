//! B1 (the default cantilever) at the library level for the reduced body's tests: its mesh,
//! lumped masses, root and tip node sets, and its reduction.

use super::face;
use flexbody::body::{InterfaceSets, MeshData, ModeCount, NodeSet, Reduction};
use flexbody::fem::{lumped_masses, scalar_mass_matrix, stiffness_matrix, IsotropicMaterial};
use flexbody::linalg::SymmetricCsr;
use flexbody::mesh::Mesh;
use flexbody::model::BodyFile;
use nalgebra::Vector3;

/// B1 on the default mesh (hex20 20×2×2), root face clamped, 10 N in −y on the tip face.
pub struct B1 {
    pub mesh: Mesh,
    pub reference: Vec<f64>,
    pub lumped: Vec<f64>,
    pub root: NodeSet,
    pub tip: NodeSet,
}

impl B1 {
    pub fn new() -> B1 {
        let body = BodyFile::default_body();
        let mesh = body.mesh.build(None).unwrap();
        let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
        let lumped = lumped_masses(&mesh, IsotropicMaterial::STEEL.density);
        let set = |name: &str, x: f64, point: Option<Vector3<f64>>| {
            let nodes = face(&mesh, x);
            let weights = nodes.iter().map(|&i| lumped[i]).collect();
            NodeSet::new(name, nodes, weights, &reference, point).unwrap()
        };
        let root = set("root", 0.0, None);
        let tip = set("tip", 1.0, Some(Vector3::new(1.0, 0.0, 0.0)));
        B1 {
            mesh,
            reference,
            lumped,
            root,
            tip,
        }
    }

    /// Mean y-displacement of the tip face (HRZ weights) of the nodal displacement `u`.
    pub fn tip_deflection(&self, u: &[f64]) -> f64 {
        let fw = &self.tip.frame_weights;
        fw.nodes
            .iter()
            .zip(&fw.weights)
            .map(|(&i, &w)| w * u[3 * i + 1])
            .sum::<f64>()
            / fw.total_weight
    }

    /// The mesh data of a reduction with `Ms` and `K` (no rigid sets, no mass points).
    pub fn mesh_data<'a>(&'a self, ms: &'a SymmetricCsr, k: &'a SymmetricCsr) -> MeshData<'a> {
        MeshData {
            reference: &self.reference,
            mass: ms,
            stiffness: k,
            force_stiffness: None,
            lumped: &self.lumped,
            frame_weights: &self.lumped,
            second_order_force: None,
        }
    }

    /// Steel's `K` and `Ms` on the mesh, and the reduction with `boundary` sets, `loaded` sets
    /// and `modes` fixed-interface modes.
    pub fn reduced(
        &self,
        boundary: &[&NodeSet],
        loaded: &[&NodeSet],
        modes: usize,
    ) -> (SymmetricCsr, SymmetricCsr, Reduction) {
        let material = IsotropicMaterial::STEEL;
        let k = stiffness_matrix(&self.mesh, &material);
        let ms = scalar_mass_matrix(&self.mesh, material.density);
        let reduction = Reduction::new(
            &self.mesh_data(&ms, &k),
            &InterfaceSets {
                held: boundary,
                rigid: &[],
                loaded,
            },
            ModeCount::Fixed(modes),
        )
        .unwrap();
        (k, ms, reduction)
    }

    /// DOFs not on the root face.
    pub fn free_dofs(&self) -> Vec<usize> {
        let root = &self.root.frame_weights.nodes;
        (0..self.mesh.node_count())
            .filter(|i| !root.contains(i))
            .flat_map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect()
    }
}
