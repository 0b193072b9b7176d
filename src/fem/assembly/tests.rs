#![allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices
use super::*;
use crate::element::{edges, natural_coordinates};
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
pub(crate) fn straighten_edges(nodes: &mut [[f64; 3]], kind: ElementKind, element: &[usize]) {
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
        crate::element::TET10_NODES.to_vec(),
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
