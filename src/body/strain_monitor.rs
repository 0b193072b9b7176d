//! A cheap watch on the small-strain assumption of the reduced-strain body.
//!
//! The reduced strain `ε(ū) = sym ∇ū` is measured against the co-moving frame; it stays a good
//! strain measure while `‖∇ū‖` (strain and rotation relative to the frame) is small. Beyond a
//! few percent the linear strain misses the `½ ∇ūᵀ∇ū` term and the results are wrong without
//! any other sign. The monitor bounds `‖∇ū‖` from below by difference quotients along segments
//! of every element, `|ū_k − ū_0| / |X_k − X_0|` from each element's first node to its others
//! (the mean of `∇ū` along the segment). Cost: one pass over the element nodes; no allocation.

use super::frame::node;
use crate::mesh::Mesh;

/// Default threshold of `‖∇ū‖` above which the FMU warns: 0.1, where the neglected quadratic
/// term reaches 5 % of the linear strain of a rotation-free stretch and a relative rotation of
/// 0.1 rad gives a spurious strain of 5e-3.
pub const DEFAULT_THRESHOLD: f64 = 0.1;

/// Segments (node pairs with their inverse reference length) of a mesh.
#[derive(Debug, Clone)]
pub struct StrainMonitor {
    segments: Vec<(u32, u32, f64)>,
}

impl StrainMonitor {
    pub fn new(mesh: &Mesh) -> StrainMonitor {
        let nodes = mesh.nodes();
        let mut segments = Vec::new();
        for e in 0..mesh.element_count() {
            let element = mesh.element(e);
            let first = element[0];
            for &other in &element[1..] {
                let d: f64 = (0..3)
                    .map(|c| (nodes[other][c] - nodes[first][c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if d > 0.0 {
                    segments.push((first as u32, other as u32, 1.0 / d));
                }
            }
        }
        StrainMonitor { segments }
    }

    /// The largest difference quotient `|ū_k − ū_0| / |X_k − X_0|` of the local deformation `ū`
    /// (flat `3N`, m): a lower bound of `max ‖∇ū‖`.
    pub fn largest_gradient(&self, local_deformation: &[f64]) -> f64 {
        self.segments
            .iter()
            .map(|&(a, b, inverse_length)| {
                (node(local_deformation, b as usize) - node(local_deformation, a as usize)).norm()
                    * inverse_length
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{generator, ElementKind};

    #[test]
    fn a_uniform_stretch_is_measured_exactly() {
        let mesh = generator::beam(1.0, 0.1, 0.1, [4, 1, 1], ElementKind::Hex20).unwrap();
        let monitor = StrainMonitor::new(&mesh);
        // ū = (ε x, 0, 0): ‖∇ū‖ along x is ε; the largest quotient is ε on x-aligned segments.
        let eps = 0.03;
        let u: Vec<f64> = mesh
            .nodes()
            .iter()
            .flat_map(|p| [eps * p[0], 0.0, 0.0])
            .collect();
        let g = monitor.largest_gradient(&u);
        assert!((g - eps).abs() < 1e-12, "{g}");
        // A rigid translation has no gradient.
        let t: Vec<f64> = mesh.nodes().iter().flat_map(|_| [1.0, 2.0, 3.0]).collect();
        assert!(monitor.largest_gradient(&t) < 1e-12);
    }
}
