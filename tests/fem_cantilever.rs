//! B1 of docs/benchmarks.md: the clamped steel cantilever (L = 1 m, 0.02 × 0.02 m, E = 2.1e11 Pa,
//! ν = 0.3, ρ = 7850 kg/m³), root face x = 0 clamped by removing its DOFs, F = 10 N in −y spread
//! over the tip-face nodes with weights proportional to their HRZ-lumped masses; the tip
//! deflection is the mean y-displacement of the tip-face nodes with the same weights.

mod common;
use common::face;
use flexbody::fem::modal::lowest_eigenpairs;
use flexbody::fem::{lumped_masses, scalar_mass_matrix, stiffness_matrix, IsotropicMaterial};
use flexbody::linalg::SparseCholesky;
use flexbody::mesh::{beam, ElementKind, Mesh};

const LENGTH: f64 = 1.0;
const SIDE: f64 = 0.02;
const FORCE: f64 = 10.0;
/// Euler–Bernoulli `F L³ / (3 E I)` (m).
const EULER_BERNOULLI: f64 = 1.19048e-3;
/// Timoshenko (m).
const TIMOSHENKO: f64 = 1.19084e-3;
/// Converged 3D solid value, 0.9987 × Euler–Bernoulli (m).
const CONVERGED_3D: f64 = 0.9987 * EULER_BERNOULLI;
/// First bending frequency (Hz), Euler–Bernoulli.
const FIRST_BENDING_HZ: f64 = 16.71;

/// DOFs of all nodes not on the root face, ascending.
fn free_dofs(mesh: &Mesh) -> Vec<usize> {
    let root = face(mesh, 0.0);
    (0..mesh.node_count())
        .filter(|i| root.binary_search(i).is_err())
        .flat_map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect()
}

/// Static tip deflection (m, positive downwards) of B1 on `mesh`.
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

fn b1(divisions: [usize; 3], kind: ElementKind) -> Mesh {
    beam(LENGTH, SIDE, SIDE, divisions, kind).unwrap()
}

#[test]
fn default_mesh_static_deflection_within_1_percent_of_timoshenko() {
    let w = tip_deflection(&b1([20, 2, 2], ElementKind::Hex20));
    let rel = w / TIMOSHENKO - 1.0;
    println!(
        "hex20 [20,2,2]: tip deflection {w:.6e} m ({:+.3} % vs Timoshenko, {:.5} × EB)",
        100.0 * rel,
        w / EULER_BERNOULLI
    );
    assert!(rel.abs() < 0.01, "{w:e}");
}

#[test]
fn hex20_converges_monotonically_to_the_3d_value() {
    let meshes = [[10, 1, 1], [20, 2, 2], [40, 4, 4]];
    let errors: Vec<f64> = meshes
        .iter()
        .map(|&d| {
            let w = tip_deflection(&b1(d, ElementKind::Hex20));
            let e = (w / CONVERGED_3D - 1.0).abs();
            println!(
                "hex20 {d:?}: {w:.6e} m, |error| vs converged 3D {:.3} %",
                100.0 * e
            );
            e
        })
        .collect();
    assert!(errors.windows(2).all(|p| p[1] < p[0]), "{errors:?}");
    assert!(errors[2] < 0.005, "{errors:?}");
}

#[test]
fn hex8_converges_slowly_because_of_shear_locking() {
    // Fully integrated trilinear bricks lock in bending: too stiff on coarse meshes, approaching
    // the converged value from below as the mesh is refined along the axis and through the depth.
    let meshes = [[10, 1, 1], [20, 2, 2], [40, 4, 4], [80, 4, 4], [160, 8, 8]];
    let ratios: Vec<f64> = meshes
        .iter()
        .map(|&d| {
            let w = tip_deflection(&b1(d, ElementKind::Hex8));
            println!(
                "hex8 {d:?}: {w:.6e} m = {:.4} × converged 3D",
                w / CONVERGED_3D
            );
            w / CONVERGED_3D
        })
        .collect();
    assert!(ratios.windows(2).all(|p| p[0] < p[1]), "{ratios:?}");
    assert!(
        ratios[0] < 0.5,
        "coarse hex8 should visibly lock: {ratios:?}"
    );
    assert!(ratios[4] > 0.95 && ratios[4] < 1.0, "{ratios:?}");
}

#[test]
fn first_bending_frequencies_within_1_percent() {
    let mesh = b1([20, 2, 2], ElementKind::Hex20);
    let material = IsotropicMaterial::STEEL;
    let free = free_dofs(&mesh);
    let k = stiffness_matrix(&mesh, &material).submatrix(&free);
    let m = scalar_mass_matrix(&mesh, material.density)
        .kron_i3()
        .submatrix(&free);
    let pairs = lowest_eigenpairs(&k, &m, 2, 1e-10, 100).unwrap();
    let f = pairs.frequencies_hz();
    println!(
        "hex20 [20,2,2]: f1 = {:.4} Hz, {:.4} Hz ({} subspace iterations)",
        f[0], f[1], pairs.iterations
    );
    for fi in &f {
        assert!((fi / FIRST_BENDING_HZ - 1.0).abs() < 0.01, "{f:?}");
    }
    // Square section: the y and z bending frequencies coincide up to discretization symmetry.
    assert!((f[1] - f[0]).abs() < 1e-6 * f[0], "{f:?}");
}
