//! Structured meshes of boxes ("beams").

use super::{ElementKind, Mesh};
use crate::element::{natural_coordinates, TET_EDGES};
use crate::error::{Error, Result};

/// The 6 permutations of the axes: tetrahedron `p` of the Kuhn subdivision of the unit cube runs
/// from corner `(0,0,0)` along `e_{π0}`, then `e_{π1}`, then `e_{π2}` to `(1,1,1)`.
const KUHN_PERMUTATIONS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [1, 2, 0],
    [2, 0, 1],
    [0, 2, 1],
    [2, 1, 0],
    [1, 0, 2],
];

/// A box `[0, length] × [−width/2, width/2] × [−height/2, height/2]` (m) meshed with
/// `divisions = [nx, ny, nz]` cells of `kind`. The beam axis is x, width along y, height along z.
///
/// Nodes lie on a lattice of spacing `(length/nx, width/ny, height/nz)` (Hex8, Tet4) or half of
/// it (Hex20: corners at even lattice indices, mid-edge nodes where exactly one index is odd; no
/// face or body centres; Tet10: every lattice point). Nodes are numbered with z fastest, then y,
/// then x, so the nodes of one cross-section are contiguous. Cell `(i, j, k)` has index
/// `c = (i · ny + j) · nz + k`; with hexahedra it is element `c`, with tetrahedra it is split into
/// the 6 tetrahedra `6c … 6c + 5` of the Kuhn subdivision (all sharing the cell's diagonal from
/// its corner at lowest x, y, z; conforming between cells).
pub fn beam(
    length: f64,
    width: f64,
    height: f64,
    divisions: [usize; 3],
    kind: ElementKind,
) -> Result<Mesh> {
    for (name, value) in [
        ("beam.length", length),
        ("beam.width", width),
        ("beam.height", height),
    ] {
        if !value.is_finite() || value <= 0.0 {
            return Err(Error::invalid_value(
                name,
                value,
                "must be positive and finite",
            ));
        }
    }
    if divisions.contains(&0) {
        return Err(Error::invalid_value(
            "beam.divisions",
            format!("{divisions:?}"),
            "every division count must be at least 1",
        ));
    }
    // Lattice points per element edge minus one: 1 (linear) or 2 (quadratic).
    let step = if kind.is_quadratic() { 2 } else { 1 };
    let lattice = [
        step * divisions[0] + 1,
        step * divisions[1] + 1,
        step * divisions[2] + 1,
    ];
    let is_node = |i: usize, j: usize, k: usize| match kind {
        ElementKind::Hex20 => (i % 2) + (j % 2) + (k % 2) <= 1,
        _ => true,
    };
    let origin = [0.0, -0.5 * width, -0.5 * height];
    let spacing = [
        length / (step * divisions[0]) as f64,
        width / (step * divisions[1]) as f64,
        height / (step * divisions[2]) as f64,
    ];
    let mut index = vec![usize::MAX; lattice[0] * lattice[1] * lattice[2]];
    let flat = |i: usize, j: usize, k: usize| (i * lattice[1] + j) * lattice[2] + k;
    let mut nodes = Vec::new();
    for i in 0..lattice[0] {
        for j in 0..lattice[1] {
            for k in 0..lattice[2] {
                if is_node(i, j, k) {
                    index[flat(i, j, k)] = nodes.len();
                    // The last lattice point is placed exactly on the far face.
                    let coord = |d: usize, m: usize, total: f64| {
                        if m + 1 == lattice[d] {
                            origin[d] + total
                        } else {
                            origin[d] + m as f64 * spacing[d]
                        }
                    };
                    nodes.push([coord(0, i, length), coord(1, j, width), coord(2, k, height)]);
                }
            }
        }
    }
    let natural = natural_coordinates(kind);
    let per_cell = match kind {
        ElementKind::Hex8 | ElementKind::Hex20 => 1,
        ElementKind::Tet4 | ElementKind::Tet10 => 6,
    };
    let mut connectivity = Vec::with_capacity(
        divisions[0] * divisions[1] * divisions[2] * per_cell * kind.node_count(),
    );
    for i in 0..divisions[0] {
        for j in 0..divisions[1] {
            for k in 0..divisions[2] {
                if per_cell == 6 {
                    for permutation in KUHN_PERMUTATIONS {
                        // Corners in lattice steps of the cell (0 or `step`).
                        let mut corners = [[0usize; 3]; 4];
                        for v in 1..4 {
                            corners[v] = corners[v - 1];
                            corners[v][permutation[v - 1]] = step;
                        }
                        // The volume has the sign of the permutation: swap two corners of the
                        // odd ones (an odd number of inversions).
                        let p = permutation;
                        let inversions = usize::from(p[0] > p[1])
                            + usize::from(p[0] > p[2])
                            + usize::from(p[1] > p[2]);
                        if inversions % 2 == 1 {
                            corners.swap(1, 2);
                        }
                        let node_at = |l: [usize; 3]| {
                            let node =
                                index[flat(step * i + l[0], step * j + l[1], step * k + l[2])];
                            debug_assert_ne!(node, usize::MAX);
                            node
                        };
                        for c in &corners {
                            connectivity.push(node_at(*c));
                        }
                        if kind == ElementKind::Tet10 {
                            for (a, b, _) in TET_EDGES {
                                let mid =
                                    std::array::from_fn(|d| (corners[a][d] + corners[b][d]) / 2);
                                connectivity.push(node_at(mid));
                            }
                        }
                    }
                    continue;
                }
                for xi in natural {
                    // Natural coordinate −1, 0, 1 ↦ lattice offset 0, step/2, step.
                    let offset = |c: f64| ((c + 1.0) * 0.5 * step as f64).round() as usize;
                    let (li, lj, lk) = (
                        step * i + offset(xi[0]),
                        step * j + offset(xi[1]),
                        step * k + offset(xi[2]),
                    );
                    let node = index[flat(li, lj, lk)];
                    debug_assert_ne!(node, usize::MAX);
                    connectivity.push(node);
                }
            }
        }
    }
    Mesh::new(nodes, kind, connectivity)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_and_element_counts() {
        let m = beam(1.0, 0.1, 0.2, [4, 2, 3], ElementKind::Hex8).unwrap();
        assert_eq!(m.node_count(), 5 * 3 * 4);
        assert_eq!(m.element_count(), 24);
        let m = beam(1.0, 0.1, 0.2, [4, 2, 3], ElementKind::Hex20).unwrap();
        // corners + x-, y-, z-edges
        let corners = 5 * 3 * 4;
        let edges = 4 * 3 * 4 + 5 * 2 * 4 + 5 * 3 * 3;
        assert_eq!(m.node_count(), corners + edges);
        assert_eq!(m.element_count(), 24);
        let (lo, hi) = m.bounding_box();
        assert_eq!(lo, [0.0, -0.05, -0.1]);
        assert_eq!(hi, [1.0, 0.05, 0.1]);
    }

    #[test]
    fn element_nodes_follow_vtk_order() {
        // One element: node positions are the natural coordinates mapped onto the box.
        for kind in [ElementKind::Hex8, ElementKind::Hex20] {
            let m = beam(2.0, 1.0, 4.0, [1, 1, 1], kind).unwrap();
            for (a, xi) in natural_coordinates(kind).iter().enumerate() {
                let x = m.nodes()[m.element(0)[a]];
                let expected = [1.0 + xi[0], 0.5 * xi[1], 2.0 * xi[2]];
                assert_eq!(x, expected, "{kind:?} local node {a}");
            }
        }
    }

    #[test]
    fn tetrahedra_fill_the_box_conformingly() {
        use crate::element::{mass_rule, physical_gradients, shape_functions, MAX_NODES};
        for (kind, lattice) in [
            (ElementKind::Tet4, [4, 3, 4]),
            (ElementKind::Tet10, [7, 5, 7]),
        ] {
            let m = beam(1.5, 0.1, 0.2, [3, 2, 3], kind).unwrap();
            // Every lattice point is a node (Tet10 uses all mid-edge and diagonal midpoints).
            assert_eq!(
                m.node_count(),
                lattice.iter().product::<usize>(),
                "{kind:?}"
            );
            assert_eq!(m.element_count(), 6 * 18);
            // Positive volumes (Mesh::new checked det J) that add up to the box.
            let n = kind.node_count();
            let mut volume = 0.0;
            let (mut v, mut d, mut g) = (
                [0.0; MAX_NODES],
                [[0.0; 3]; MAX_NODES],
                [[0.0; 3]; MAX_NODES],
            );
            for e in 0..m.element_count() {
                let coords: Vec<[f64; 3]> = m.element(e).iter().map(|&i| m.nodes()[i]).collect();
                for q in mass_rule(kind) {
                    shape_functions(kind, q.xi, &mut v, &mut d);
                    volume += q.weight * physical_gradients(&coords, &d[..n], &mut g[..n]);
                }
            }
            assert!(
                (volume / (1.5 * 0.1 * 0.2) - 1.0).abs() < 1e-13,
                "{kind:?}: {volume}"
            );
            // Conforming: every triangular face is shared by two elements or lies on the boundary.
            let mut faces = std::collections::HashMap::new();
            for e in 0..m.element_count() {
                let c = &m.element(e)[..4];
                for skip in 0..4 {
                    let mut f: Vec<usize> = (0..4).filter(|&k| k != skip).map(|k| c[k]).collect();
                    f.sort_unstable();
                    *faces.entry(f).or_insert(0) += 1;
                }
            }
            let (lo, hi) = m.bounding_box();
            for (f, count) in faces {
                let on_boundary = (0..3).any(|d| {
                    f.iter().all(|&i| m.nodes()[i][d] == lo[d])
                        || f.iter().all(|&i| m.nodes()[i][d] == hi[d])
                });
                assert_eq!(
                    count,
                    if on_boundary { 1 } else { 2 },
                    "{kind:?} face {f:?}"
                );
            }
        }
    }

    #[test]
    fn rejects_bad_sizes_and_divisions() {
        let e = beam(0.0, 1.0, 1.0, [1, 1, 1], ElementKind::Hex8).unwrap_err();
        assert!(
            e.message.starts_with("beam.length = 0 rejected"),
            "{}",
            e.message
        );
        let e = beam(1.0, -1.0, 1.0, [1, 1, 1], ElementKind::Hex8).unwrap_err();
        assert!(
            e.message.starts_with("beam.width = -1 rejected"),
            "{}",
            e.message
        );
        let e = beam(1.0, 1.0, f64::NAN, [1, 1, 1], ElementKind::Hex20).unwrap_err();
        assert!(
            e.message.starts_with("beam.height = NaN rejected"),
            "{}",
            e.message
        );
        let e = beam(1.0, 1.0, 1.0, [1, 0, 1], ElementKind::Hex20).unwrap_err();
        assert!(
            e.message.contains("beam.divisions = [1, 0, 1]"),
            "{}",
            e.message
        );
    }
}
