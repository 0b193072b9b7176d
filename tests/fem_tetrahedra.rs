//! Tetrahedra and Gmsh meshes on B1 of docs/benchmarks.md (the clamped steel cantilever, 1 m ×
//! 20 mm × 20 mm, F = 10 N in −y on the tip face), and the node order of imported elements.
//!
//! Meshes: `tests/data/*.msh`, made by `tests/data/make_meshes.py` (Gmsh). The tet4 meshes are
//! the Kuhn-split boxes of `mesh::beam`.

mod common;
use common::face;
use flexbody::element::{edges, integration_rule, physical_gradients, shape_functions};
use flexbody::element::{mass_rule, MAX_NODES};
use flexbody::fem::modal::lowest_eigenpairs;
use flexbody::fem::{lumped_masses, scalar_mass_matrix, stiffness_matrix, IsotropicMaterial};
use flexbody::linalg::SparseCholesky;
use flexbody::mesh::{beam, gmsh, ElementKind, Mesh};

const LENGTH: f64 = 1.0;
const SIDE: f64 = 0.02;
const FORCE: f64 = 10.0;
/// Euler–Bernoulli `F L³ / (3 E I)` (m).
const EULER_BERNOULLI: f64 = 1.19048e-3;

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// DOFs of all nodes not on the root face x = 0, ascending.
fn free_dofs(mesh: &Mesh) -> Vec<usize> {
    let root = face(mesh, 0.0);
    (0..mesh.node_count())
        .filter(|i| root.binary_search(i).is_err())
        .flat_map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect()
}

/// Static tip deflection (m, positive downwards): F spread over the tip face with HRZ weights,
/// the deflection the same weighted mean (as `tests/fem_cantilever.rs`).
fn tip_deflection(mesh: &Mesh) -> f64 {
    let material = IsotropicMaterial::STEEL;
    let k = stiffness_matrix(mesh, &material);
    let lumped = lumped_masses(mesh, material.density);
    let tip = face(mesh, LENGTH);
    let tip_mass: f64 = tip.iter().map(|&i| lumped[i]).sum();
    let mut load = vec![0.0; 3 * mesh.node_count()];
    for &i in &tip {
        load[3 * i + 1] = -FORCE * lumped[i] / tip_mass;
    }
    let free = free_dofs(mesh);
    let mut u: Vec<f64> = free.iter().map(|&f| load[f]).collect();
    let factor = SparseCholesky::new(&k.submatrix(&free)).unwrap();
    factor.solve_in_place(&mut u, &mut factor.solve_scratch());
    let mut full = vec![0.0; 3 * mesh.node_count()];
    for (&f, &v) in free.iter().zip(&u) {
        full[f] = v;
    }
    -tip.iter()
        .map(|&i| lumped[i] * full[3 * i + 1])
        .sum::<f64>()
        / tip_mass
}

/// The two lowest frequencies (Hz) of the clamped beam.
fn bending_frequencies(mesh: &Mesh) -> [f64; 2] {
    let material = IsotropicMaterial::STEEL;
    let free = free_dofs(mesh);
    let k = stiffness_matrix(mesh, &material).submatrix(&free);
    let m = scalar_mass_matrix(mesh, material.density)
        .kron_i3()
        .submatrix(&free);
    let f = lowest_eigenpairs(&k, &m, 2, 1e-10, 200)
        .unwrap()
        .frequencies_hz();
    [f[0], f[1]]
}

#[test]
fn gmsh_tet10_cantilever_matches_hex20() {
    // The reference is the hex20 40×4×4 model, within 0.5 % of the converged 3D value
    // (tests/fem_cantilever.rs). The Gmsh tet10 mesh (10 mm, two elements through the depth) is
    // a different discretization of the same solid: its static deflection and both bending
    // frequencies must agree within 1 % (the target; both are converged to well below
    // that, so a wrong node order, rule or mass would show as a larger difference).
    let tet = gmsh::read(&data("b1_tet10.msh"), 1.0).unwrap();
    assert_eq!(tet.kind(), ElementKind::Tet10);
    let hex = beam(LENGTH, SIDE, SIDE, [40, 4, 4], ElementKind::Hex20).unwrap();
    let (w_tet, w_hex) = (tip_deflection(&tet), tip_deflection(&hex));
    let (f_tet, f_hex) = (bending_frequencies(&tet), bending_frequencies(&hex));
    println!(
        "static tip deflection: tet10 (Gmsh, {} nodes, {} DOF) {w_tet:.6e} m = {:.4} × EB, \
         hex20 [40,4,4] ({} DOF) {w_hex:.6e} m = {:.4} × EB, difference {:+.3} %",
        tet.node_count(),
        3 * tet.node_count(),
        w_tet / EULER_BERNOULLI,
        3 * hex.node_count(),
        w_hex / EULER_BERNOULLI,
        100.0 * (w_tet / w_hex - 1.0)
    );
    println!(
        "bending frequencies: tet10 {:.4}, {:.4} Hz; hex20 {:.4}, {:.4} Hz; differences {:+.3} %, {:+.3} %",
        f_tet[0],
        f_tet[1],
        f_hex[0],
        f_hex[1],
        100.0 * (f_tet[0] / f_hex[0] - 1.0),
        100.0 * (f_tet[1] / f_hex[1] - 1.0)
    );
    assert!((w_tet / w_hex - 1.0).abs() < 0.01);
    for c in 0..2 {
        assert!(
            (f_tet[c] / f_hex[c] - 1.0).abs() < 0.01,
            "{f_tet:?} vs {f_hex:?}"
        );
    }
}

#[test]
fn tet4_converges_slowly_with_refinement() {
    // Linear tetrahedra are constant-strain elements and lock in bending even worse than hex8:
    // far too stiff on coarse meshes, approaching the reference from below. Reference: the
    // hex20 40×4×4 deflection (within 0.5 % of the converged 3D solid). Measured errors: 97 %,
    // 89 %, 66 %, 33 % — roughly halving per refinement on the finer meshes, as expected of an
    // O(h²) energy error once the elements start to resolve the bending gradient.
    let reference =
        tip_deflection(&beam(LENGTH, SIDE, SIDE, [40, 4, 4], ElementKind::Hex20).unwrap());
    let meshes = [[10, 1, 1], [20, 2, 2], [40, 4, 4], [80, 8, 8]];
    println!("tet4 (Kuhn-split boxes) on B1, reference hex20 [40,4,4] = {reference:.6e} m");
    println!(
        "{:>12} {:>8} {:>14} {:>10}",
        "divisions", "DOF", "deflection (m)", "error"
    );
    let errors: Vec<f64> = meshes
        .iter()
        .map(|&d| {
            let mesh = beam(LENGTH, SIDE, SIDE, d, ElementKind::Tet4).unwrap();
            let w = tip_deflection(&mesh);
            let e = 1.0 - w / reference;
            println!(
                "{:>12} {:>8} {w:>14.6e} {:>9.2} %",
                format!("{d:?}"),
                3 * mesh.node_count(),
                100.0 * e
            );
            e
        })
        .collect();
    // Too stiff everywhere (error > 0), strictly decreasing, and converging: the last
    // refinement must at least cut the error by a third.
    assert!(errors.iter().all(|&e| e > 0.0), "{errors:?}");
    assert!(errors.windows(2).all(|p| p[1] < p[0]), "{errors:?}");
    assert!(errors[0] > 0.5, "coarse tet4 should lock badly: {errors:?}");
    assert!(errors[3] < 0.67 * errors[2], "{errors:?}");
}

/// Every mid-edge node of a straight-edged quadratic element lies at the middle of the two
/// corners that `edges(kind)` names: a check of the node order (VTK) that the import produces.
fn straight_edges_have_their_midpoints(mesh: &Mesh, tolerance: f64) -> usize {
    let mut checked = 0;
    for e in 0..mesh.element_count() {
        let nodes = mesh.element(e);
        for &(a, b, mid) in edges(mesh.kind()) {
            let (pa, pb, pm) = (
                mesh.nodes()[nodes[a]],
                mesh.nodes()[nodes[b]],
                mesh.nodes()[nodes[mid]],
            );
            let off: f64 = (0..3)
                .map(|d| (pm[d] - 0.5 * (pa[d] + pb[d])).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                off < tolerance,
                "element {e} edge ({a}, {b}): mid-node {off:e} m off"
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn imported_quadratic_elements_are_in_vtk_order() {
    // B1's box has flat faces only, so every edge is straight: Gmsh places the mid-edge nodes at
    // the exact midpoints (to its 16 printed digits).
    let tet = gmsh::read(&data("b1_tet10.msh"), 1.0).unwrap();
    assert!(straight_edges_have_their_midpoints(&tet, 1e-12) > 0);
    let hex = gmsh::read(&data("box_hex20.msh"), 1.0).unwrap();
    assert_eq!(hex.kind(), ElementKind::Hex20);
    assert_eq!(hex.element_count(), 6);
    assert_eq!(straight_edges_have_their_midpoints(&hex, 1e-12), 6 * 12);
    // The face x = 0 of 2 × 1 cells: 3 × 2 corners, 4 mid-edge nodes along y, 3 along z.
    assert_eq!(hex.group("left").unwrap().len(), 13);
    assert_eq!(
        tet.group("root").unwrap(),
        face(&tet, 0.0).as_slice(),
        "the physical surface 'root' is the face x = 0"
    );
    assert_eq!(tet.group("tip").unwrap(), face(&tet, LENGTH).as_slice());
}

#[test]
fn curved_tet10_ring_binary_and_ascii_agree_and_pass_the_patch_test() {
    // A quarter of a thick ring: Gmsh puts the mid-edge nodes of the cylinder faces on the
    // cylinders, so those elements are curved. Mesh::new checked det J > 0 everywhere.
    let ascii = gmsh::read(&data("quarter_ring_tet10.msh"), 1.0).unwrap();
    let binary = gmsh::read(&data("quarter_ring_tet10.bin.msh"), 1.0).unwrap();
    // ASCII prints 16 significant digits, binary holds the doubles: equal to 1e-15 relative.
    assert_eq!(ascii.node_count(), binary.node_count());
    for (p, q) in ascii.nodes().iter().zip(binary.nodes()) {
        assert!(
            (0..3).all(|d| (p[d] - q[d]).abs() <= 1e-15),
            "{p:?} vs {q:?}"
        );
    }
    assert_eq!(
        (0..ascii.element_count())
            .map(|e| ascii.element(e))
            .collect::<Vec<_>>(),
        (0..binary.element_count())
            .map(|e| binary.element(e))
            .collect::<Vec<_>>()
    );
    for group in ["inner", "outer", "solid"] {
        assert_eq!(ascii.group(group), binary.group(group), "{group}");
    }
    // The groups lie on their cylinders (r = 0.3 and 0.5 m).
    for (group, radius) in [("inner", 0.3), ("outer", 0.5)] {
        for &i in ascii.group(group).unwrap() {
            let p = ascii.nodes()[i];
            assert!(
                ((p[0] * p[0] + p[1] * p[1]).sqrt() - radius).abs() < 1e-9,
                "{group}"
            );
        }
    }
    // Some element is really curved: a mid-edge node off its chord's midpoint.
    let kind = ascii.kind();
    let curved = (0..ascii.element_count()).any(|e| {
        let n = ascii.element(e);
        edges(kind).iter().any(|&(a, b, m)| {
            let (pa, pb, pm) = (
                ascii.nodes()[n[a]],
                ascii.nodes()[n[b]],
                ascii.nodes()[n[m]],
            );
            (0..3)
                .map(|d| (pm[d] - 0.5 * (pa[d] + pb[d])).powi(2))
                .sum::<f64>()
                > 1e-8
        })
    });
    assert!(curved);
    // Volume: π/4 (0.5² − 0.3²) 0.2 up to the quadratic approximation of the arcs (chord
    // height of a 0.12 m element on r = 0.3 m is ~6e-3 m; the quadratic's error is ~1e-5 of
    // that per unit length, so 1e-4 relative is generous and a wrong order would fail it).
    let mut volume = 0.0;
    let n = kind.node_count();
    let (mut v, mut d, mut g) = (
        [0.0; MAX_NODES],
        [[0.0; 3]; MAX_NODES],
        [[0.0; 3]; MAX_NODES],
    );
    for e in 0..ascii.element_count() {
        let coords: Vec<[f64; 3]> = ascii.element(e).iter().map(|&i| ascii.nodes()[i]).collect();
        for q in mass_rule(kind) {
            shape_functions(kind, q.xi, &mut v, &mut d);
            volume += q.weight * physical_gradients(&coords, &d[..n], &mut g[..n]);
        }
    }
    let exact = std::f64::consts::FRAC_PI_4 * (0.25 - 0.09) * 0.2;
    println!("quarter ring volume {volume:.9} m³ vs {exact:.9} m³");
    assert!((volume / exact - 1.0).abs() < 1e-4, "{volume} vs {exact}");

    // Patch test on the curved mesh: isoparametric elements represent u = A x + b exactly
    // (the map reproduces x), so with the boundary nodes prescribed the interior solution is
    // that field and the strain is sym(A) at every Gauss point, to round-off.
    let a = [
        [1e-3, 2e-4, -3e-4],
        [5e-4, -2e-3, 1e-4],
        [-1e-4, 3e-4, 1.5e-3],
    ];
    let exact_u = |p: &[f64; 3]| -> [f64; 3] {
        std::array::from_fn(|r| 1e-3 + (0..3).map(|c| a[r][c] * p[c]).sum::<f64>())
    };
    let mut boundary = vec![false; ascii.node_count()];
    // Boundary nodes: those on a face of only one element.
    let mut faces = std::collections::HashMap::new();
    for e in 0..ascii.element_count() {
        let c = ascii.element(e);
        for skip in 0..4 {
            let mut f: Vec<usize> = (0..4).filter(|&k| k != skip).map(|k| c[k]).collect();
            f.sort_unstable();
            faces.entry(f).or_insert_with(Vec::new).push(e);
        }
    }
    for (f, elements) in &faces {
        if elements.len() == 1 {
            let c = ascii.element(elements[0]);
            for &node in f {
                boundary[node] = true;
            }
            // The face's mid-edge nodes too.
            for &(x, y, m) in edges(kind) {
                if f.contains(&c[x]) && f.contains(&c[y]) {
                    boundary[c[m]] = true;
                }
            }
        }
    }
    let free: Vec<usize> = (0..ascii.node_count())
        .filter(|&i| !boundary[i])
        .flat_map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    assert!(!free.is_empty());
    let k = stiffness_matrix(&ascii, &IsotropicMaterial::STEEL);
    let mut u = vec![0.0; 3 * ascii.node_count()];
    for (i, p) in ascii.nodes().iter().enumerate() {
        if boundary[i] {
            u[3 * i..3 * i + 3].copy_from_slice(&exact_u(p));
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
    let mut worst = 0.0f64;
    for e in 0..ascii.element_count() {
        let nodes = ascii.element(e);
        let coords: Vec<[f64; 3]> = nodes.iter().map(|&i| ascii.nodes()[i]).collect();
        for q in integration_rule(kind) {
            shape_functions(kind, q.xi, &mut v, &mut d);
            physical_gradients(&coords, &d[..n], &mut g[..n]);
            for r in 0..3 {
                for c in 0..3 {
                    let grad: f64 = (0..n).map(|k| u[3 * nodes[k] + r] * g[k][c]).sum();
                    let grad_t: f64 = (0..n).map(|k| u[3 * nodes[k] + c] * g[k][r]).sum();
                    let eps = 0.5 * (grad + grad_t);
                    worst = worst.max((eps - 0.5 * (a[r][c] + a[c][r])).abs());
                }
            }
        }
    }
    // Strains of 2e-3. On straight-edged elements the test is exact to round-off; on curved ones
    // the interior residual Σ_q w_q adj(J)ᵀ∇_ξN_a is a cubic that the 4-point (degree 2) rule
    // integrates only approximately, so a small consistency error remains that scales with the
    // curvature: measured 1.4e-6 of the strain here (elements of 0.12 m on radii of 0.3 m).
    // The bound 1e-4 keeps a margin; a wrong node order or shape function gives O(1) errors.
    println!("curved patch test: largest strain error {worst:.3e} (strain 2e-3)");
    assert!(worst < 1e-4 * 2e-3, "strain error {worst:e}");
}
