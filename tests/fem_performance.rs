//! Timings of assembly, symbolic + numeric factorization and one solve (ignored by default; run
//! `cargo test --release --test fem_performance -- --ignored --nocapture`). The assertions only
//! check that the results are usable; the figures are printed for the record.

use flexbody::fem::{lumped_masses, scalar_mass_matrix, stiffness_matrix, IsotropicMaterial};
use flexbody::linalg::{SparseCholesky, SymmetricCsr};
use flexbody::mesh::{beam, ElementKind, NodeSelector};
use std::time::Instant;

fn time(divisions: [usize; 3]) {
    let material = IsotropicMaterial {
        youngs_modulus: 2.1e11,
        poisson_ratio: 0.3,
        density: 7850.0,
    };
    let t = Instant::now();
    let mesh = beam(1.0, 0.02, 0.02, divisions, ElementKind::Hex20).unwrap();
    let t_mesh = t.elapsed();
    let t = Instant::now();
    let k = stiffness_matrix(&mesh, &material);
    let t_k = t.elapsed();
    let t = Instant::now();
    let ms = scalar_mass_matrix(&mesh, material.density);
    let lumped = lumped_masses(&mesh, material.density);
    let t_m = t.elapsed();
    let root = NodeSelector::Plane {
        point: [0.0; 3],
        normal: [1.0, 0.0, 0.0],
        tolerance: None,
    }
    .select(&mesh)
    .unwrap();
    let free: Vec<usize> = (0..mesh.node_count())
        .filter(|i| root.binary_search(i).is_err())
        .flat_map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    // A Newmark-like iteration matrix c_m M + K on the free DOFs (h = 1e-3, β = 1/4).
    let t = Instant::now();
    let m = ms.kron_i3();
    let s = SymmetricCsr::linear_combination(4.0 / 1e-6, &m, 1.0, &k).submatrix(&free);
    let t_s = t.elapsed();
    let t = Instant::now();
    let factor = SparseCholesky::new(&s).unwrap();
    let t_f = t.elapsed();
    let mut ws = factor.solve_scratch();
    let mut rhs = vec![1.0; s.n];
    let t = Instant::now();
    factor.solve_in_place(&mut rhs, &mut ws);
    let t_solve = t.elapsed();
    assert!(rhs.iter().all(|v| v.is_finite()));
    assert!(lumped.iter().all(|&v| v > 0.0));
    println!(
        "hex20 {divisions:?}: {} DOF ({} free), K nnz {}, L nnz {}; mesh {:.1} ms, K {:.1} ms, Ms+lumped {:.1} ms, \
         c_m M + K on free DOFs {:.1} ms, Cholesky (symbolic+numeric) {:.1} ms, one solve {:.2} ms",
        3 * mesh.node_count(),
        free.len(),
        k.nnz(),
        factor.factor_nnz(),
        t_mesh.as_secs_f64() * 1e3,
        t_k.as_secs_f64() * 1e3,
        t_m.as_secs_f64() * 1e3,
        t_s.as_secs_f64() * 1e3,
        t_f.as_secs_f64() * 1e3,
        t_solve.as_secs_f64() * 1e3,
    );
}

#[test]
#[ignore = "timing; run with --release --ignored --nocapture"]
fn assembly_and_factorization_timings() {
    // The default body's mesh, then ~100k-DOF beams. The fill of the factor grows with the
    // cross-section: [400,4,4] (thin) factors much faster than [110,8,8] (fat, ~1 GB factor).
    time([20, 2, 2]);
    time([400, 4, 4]);
    if std::env::var_os("FLEXBODY_PERF_FAT").is_some() {
        time([110, 8, 8]);
    }
}
