#![allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices
use super::*;
use crate::linalg::cholesky::SparseCholesky;
use crate::mesh::beam;

/// A material of unit modulus: energies, forces and stiffnesses are O(1) on O(1) meshes, so
/// the finite-difference error estimates below are absolute numbers.
fn unit_material() -> IsotropicMaterial {
    IsotropicMaterial {
        youngs_modulus: 1.0,
        poisson_ratio: 0.3,
        density: 1.0,
    }
}

/// A 2×2×1 patch of a 1 × 0.8 × 0.6 box with every node moved by a smooth non-affine field
/// (curved Hex20 edges, non-parallelepiped Hex8): the reference gradients differ from element
/// to element and point to point.
fn distorted_patch(kind: ElementKind) -> Mesh {
    let mesh = beam(1.0, 0.8, 0.6, [2, 2, 1], kind).unwrap();
    let nodes: Vec<[f64; 3]> = mesh
        .nodes()
        .iter()
        .map(|p| {
            [
                p[0] + 0.06 * (3.0 * p[1]).sin() + 0.04 * p[2] * p[2],
                p[1] + 0.05 * (2.0 * p[0]).cos() * p[2],
                p[2] + 0.05 * p[0] * p[1] + 0.03 * (4.0 * p[0]).sin(),
            ]
        })
        .collect();
    let connectivity = (0..mesh.element_count())
        .flat_map(|e| mesh.element(e).to_vec())
        .collect();
    Mesh::new(nodes, kind, connectivity).unwrap()
}

/// Rotation by `angle` (rad) about `axis` (Rodrigues).
fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let k = [axis[0] / norm, axis[1] / norm, axis[2] / norm];
    let (s, c) = angle.sin_cos();
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = (1.0 - c) * k[i] * k[j] + if i == j { c } else { 0.0 };
        }
    }
    r[0][1] -= s * k[2];
    r[0][2] += s * k[1];
    r[1][0] += s * k[2];
    r[1][2] -= s * k[0];
    r[2][0] -= s * k[1];
    r[2][1] += s * k[0];
    r
}

/// `x = Q (X + u(X)) + c`: a smooth displacement with strains of about 0.1, then a rotation
/// by 0.9 rad about a skew axis and a translation.
fn rotated_deformed(solid: &SvkSolid) -> Vec<f64> {
    let q = rotation([0.3, -0.5, 0.8], 0.9);
    let c = [0.2, -0.1, 0.4];
    let reference = solid.reference_positions();
    let mut x = vec![0.0; reference.len()];
    for (xi, p) in x.chunks_exact_mut(3).zip(reference.chunks_exact(3)) {
        let y = [
            p[0] + 0.08 * p[0] * p[0] + 0.05 * p[1] * p[2],
            p[1] + 0.1 * (2.0 * p[0]).sin() * (1.0 + p[2]),
            p[2] - 0.06 * p[0] + 0.07 * p[1] * p[1],
        ];
        for i in 0..3 {
            xi[i] = c[i] + q[i][0] * y[0] + q[i][1] * y[1] + q[i][2] * y[2];
        }
    }
    x
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

#[test]
fn internal_force_is_the_gradient_of_the_strain_energy() {
    // Central differences: error ≤ h²/6 |W'''| + ε |W| / h. With E = 1 and strains ~0.1 the
    // third derivative scales like |f| / ℓ² with ℓ ≈ 0.1–0.25 m the node spacing, so at
    // h = 2.5e-6 the truncation is ~1e-12/6 · 100 |f| ≈ 2e-11 |f| and the rounding
    // ~1e-16 · 6e-3 / 2.5e-6 ≈ 3e-13 (1e-11 |f|). The error was measured to scale as h²
    // (truncation) at h = 2e-5, 1e-5, 5e-6: at 2.5e-6 it is 8e-11 (Hex8), 1.5e-10 (Hex20),
    // 2.2e-10 (Tet4) and 7e-10 (Tet10, more nodes share the load) · max|f|. The bound
    // 1e-8 · max|f| keeps a margin and is far below any wrong term (≥ 1e-3).
    let h = 2.5e-6;
    for kind in ElementKind::ALL {
        let solid = SvkSolid::new(&distorted_patch(kind), &unit_material());
        let x = rotated_deformed(&solid);
        let mut f = vec![0.0; x.len()];
        solid.internal_force(&x, &mut f);
        let scale = max_abs(&f);
        assert!(
            scale > 1e-3,
            "{kind:?}: the deformation must load the patch"
        );
        let mut xp = x.clone();
        let mut worst = 0.0f64;
        for i in 0..x.len() {
            xp[i] = x[i] + h;
            let wp = solid.strain_energy(&xp);
            xp[i] = x[i] - h;
            let wm = solid.strain_energy(&xp);
            xp[i] = x[i];
            worst = worst.max(((wp - wm) / (2.0 * h) - f[i]).abs());
        }
        assert!(
            worst <= 1e-8 * scale,
            "{kind:?}: |f − ∇W|∞ = {worst:e}, max|f| = {scale:e}"
        );
    }
}

#[test]
fn tangent_is_the_jacobian_of_the_internal_force() {
    // Central differences of f: error ≤ h²/6 |f'''| + ε |f| / h with |f'''| ~ |K| / ℓ² (ℓ the
    // node spacing, 0.15 m for Hex20): ≈ 1e-11/6 · 44 |K| ≈ 1e-10 |K| plus ~3e-13. Measured:
    // 2.6e-10 (Hex8) and 1.0e-9 (Hex20) · max|K|; the bound 1e-8 · max|K| keeps a margin and
    // is orders below a missing term (e.g. the geometric part, ~|S| ~ 1e-1 |K| here).
    let h = 1e-5;
    for kind in ElementKind::ALL {
        let solid = SvkSolid::new(&distorted_patch(kind), &unit_material());
        let x = rotated_deformed(&solid);
        let mut k = solid.tangent_pattern();
        solid.tangent_stiffness(&x, &mut k);
        let kd = k.to_dense();
        let scale = kd.amax();
        let n = x.len();
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        let mut xp = x.clone();
        let mut worst = 0.0f64;
        for j in 0..n {
            xp[j] = x[j] + h;
            solid.internal_force(&xp, &mut fp);
            xp[j] = x[j] - h;
            solid.internal_force(&xp, &mut fm);
            xp[j] = x[j];
            for i in 0..n {
                worst = worst.max(((fp[i] - fm[i]) / (2.0 * h) - kd[(i, j)]).abs());
            }
        }
        assert!(
            worst <= 1e-8 * scale,
            "{kind:?}: |K_T − ∂f/∂x|∞ = {worst:e}, max|K_T| = {scale:e}"
        );
        // The combined pass gives the same force and tangent.
        let mut f = vec![0.0; n];
        let mut f2 = vec![0.0; n];
        let mut k2 = solid.tangent_pattern();
        solid.internal_force(&x, &mut f);
        solid.internal_force_and_tangent(&x, &mut f2, &mut k2);
        let df: f64 = f
            .iter()
            .zip(&f2)
            .fold(0.0, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            df <= 1e-14 * max_abs(&f),
            "{kind:?}: force differs by {df:e}"
        );
        assert_eq!(k2.values, k.values);
    }
}

#[test]
fn tangent_is_symmetric_and_factorizes_on_the_pattern_of_k() {
    // K_T is the Hessian of W: symmetric. The scatter writes block (b, a) as the transpose of
    // block (a, b) so the stored matrix must be symmetric to the last bit; a misplaced block
    // would break that. Then: a Cholesky analysed on the linear K (+ αI) must refactor the
    // tangent numerically and solve with it.
    for kind in ElementKind::ALL {
        let material = unit_material();
        let mesh = distorted_patch(kind);
        let solid = SvkSolid::new(&mesh, &material);
        let x = rotated_deformed(&solid);
        let mut k = solid.tangent_pattern();
        solid.tangent_stiffness(&x, &mut k);
        let kd = k.to_dense();
        let asymmetry = (&kd - kd.transpose()).amax();
        assert_eq!(asymmetry, 0.0, "{kind:?}: K_T is not symmetric");

        let mut shifted = stiffness_matrix(&mesh, &material);
        let alpha = 0.1 * shifted.diagonal().iter().fold(0.0f64, |m, v| m.max(*v));
        let add_shift = |m: &mut SymmetricCsr| {
            for i in 0..m.n {
                let (start, end) = (m.row_ptr[i], m.row_ptr[i + 1]);
                let p = m.col_idx[start..end].binary_search(&i).unwrap();
                m.values[start + p] += alpha;
            }
        };
        add_shift(&mut shifted);
        let mut cholesky = SparseCholesky::new(&shifted).unwrap();
        add_shift(&mut k);
        cholesky.refactor(&k).unwrap();
        let n = x.len();
        let rhs: Vec<f64> = (0..n).map(|i| ((i * 7 % 11) as f64 - 5.0) * 0.1).collect();
        let mut y = rhs.clone();
        let mut workspace = cholesky.solve_scratch();
        cholesky.solve_in_place(&mut y, &mut workspace);
        let mut r = vec![0.0; n];
        k.mul_vec(&y, &mut r);
        let err = r
            .iter()
            .zip(&rhs)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        // Backward-stable solve: residual ~ ε · cond · |rhs| with a modest condition number.
        assert!(err <= 1e-10 * max_abs(&rhs), "{kind:?}: residual {err:e}");
    }
}

#[test]
fn rigid_motion_is_stress_free_at_any_angle() {
    // x = Q X + c exactly gives F = Q, E = 0: only round-off remains. Positions carry an error
    // ε |x| (|x| ≤ ~3 m here), so H has an error ~ε |x| / ℓ ≈ 1e-15 (node spacing ℓ ≈ 0.2 m),
    // E ~ 1e-15, and the nodal force is ~(λ + 2μ) E ℓ² ≈ 3e11 · 1e-15 · 0.04 ≈ 1e-5 N
    // (measured up to 1.5e-4 N). Bounds: strains below 1e-13 (measured ≤ 1e-14), forces below
    // 1e-13 (λ + 2μ) · 0.1 m² ≈ 3e-3 N, energy below (λ + 2μ) · 1e-28 m³ ≈ 3e-17 J (measured
    // ≤ 8e-19 J). A unit strain would give forces of ~1e10 N.
    let material = IsotropicMaterial::STEEL;
    let modulus = material.lame_lambda() + 2.0 * material.shear_modulus();
    for kind in ElementKind::ALL {
        let solid = SvkSolid::new(&distorted_patch(kind), &material);
        let reference = solid.reference_positions().to_vec();
        let mut f = vec![0.0; reference.len()];
        for (axis, angle) in [
            ([0.0, 0.0, 1.0], 0.3),
            ([1.0, 2.0, -0.5], 2.0),
            ([-0.4, 0.1, 0.9], std::f64::consts::PI),
            ([0.7, -0.7, 0.2], 4.5),
            ([0.0, 1.0, 0.0], -17.0),
        ] {
            let q = rotation(axis, angle);
            let c = [1.5, -2.0, 0.7];
            let mut x = vec![0.0; reference.len()];
            for (xi, p) in x.chunks_exact_mut(3).zip(reference.chunks_exact(3)) {
                for i in 0..3 {
                    xi[i] = c[i] + q[i][0] * p[0] + q[i][1] * p[1] + q[i][2] * p[2];
                }
            }
            solid.internal_force(&x, &mut f);
            let force = max_abs(&f);
            assert!(
                force <= 1e-13 * modulus * 0.1,
                "{kind:?} angle {angle}: max|f| = {force:e} N"
            );
            let energy = solid.strain_energy(&x);
            assert!(
                energy.abs() <= modulus * 1e-28,
                "{kind:?} angle {angle}: W = {energy:e} J"
            );
            let strains = solid.green_strain_at_gauss_points(&x);
            let worst = strains.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(worst <= 1e-13, "{kind:?} angle {angle}: |E| = {worst:e}");
        }
    }
}

#[test]
fn small_displacement_limit_is_the_linear_stiffness() {
    // At x = X: F = I, S = 0, and the block formula reduces term by term to the one of
    // `stiffness_matrix` (same Gauss data): equal to round-off (a few ε · max|K|).
    // For x = X + u with |∇u| ~ δ, f(X + u) − K u = O(δ²) (the HᵀH of E and F S − S), so
    // |f − K u| / |K u| ≈ δ: with δ ≈ 1e-7 the bound 1e-5 holds with a wide margin and a
    // wrong linear term (relative error O(1)) fails it.
    let material = IsotropicMaterial::STEEL;
    for kind in ElementKind::ALL {
        let mesh = distorted_patch(kind);
        let solid = SvkSolid::new(&mesh, &material);
        let linear = stiffness_matrix(&mesh, &material);
        let reference = solid.reference_positions().to_vec();
        let mut k = solid.tangent_pattern();
        solid.tangent_stiffness(&reference, &mut k);
        assert_eq!((&k.row_ptr, &k.col_idx), (&linear.row_ptr, &linear.col_idx));
        let scale = max_abs(&linear.values);
        let worst = k
            .values
            .iter()
            .zip(&linear.values)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            worst <= 1e-14 * scale,
            "{kind:?}: |K_T(X) − K| = {worst:e}, max|K| = {scale:e}"
        );

        let delta = 1e-7;
        let u: Vec<f64> = reference
            .chunks_exact(3)
            .flat_map(|p| {
                [
                    delta * (p[1] * p[2] + (3.0 * p[0]).sin()),
                    delta * (p[0] * p[0] - p[2]),
                    delta * (2.0 * p[1]).cos() * p[0],
                ]
            })
            .collect();
        let x: Vec<f64> = reference.iter().zip(&u).map(|(a, b)| a + b).collect();
        let n = x.len();
        let (mut f, mut ku) = (vec![0.0; n], vec![0.0; n]);
        solid.internal_force(&x, &mut f);
        linear.mul_vec(&u, &mut ku);
        let diff = f
            .iter()
            .zip(&ku)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            diff <= 1e-5 * max_abs(&ku),
            "{kind:?}: |f(X+u) − K u| = {diff:e}, |K u| = {:e}",
            max_abs(&ku)
        );
        assert_eq!(solid.strain_energy(&reference), 0.0);
    }
}

#[test]
fn homogeneous_stretch_gives_its_green_strain_and_energy_everywhere() {
    // x = A X with constant A: both element families reproduce affine fields, so at every
    // Gauss point E = ½ (AᵀA − I) to round-off, and W = (½ λ (tr E)² + μ E:E) V with V the
    // reference volume (the weights sum to V; the distorted patch still fills the same volume
    // as the box only approximately, so V is taken from the weights through the energy of a
    // stretch with known density).
    let material = unit_material();
    let a = [[1.1, 0.05, -0.02], [0.03, 0.95, 0.1], [0.0, -0.04, 1.2]];
    let mut e = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let ata: f64 = (0..3).map(|k| a[k][i] * a[k][j]).sum();
            e[i][j] = 0.5 * (ata - if i == j { 1.0 } else { 0.0 });
        }
    }
    let expected = voigt(&e);
    let trace = e[0][0] + e[1][1] + e[2][2];
    let ee: f64 = e.iter().flatten().map(|v| v * v).sum();
    let density = 0.5 * material.lame_lambda() * trace * trace + material.shear_modulus() * ee;
    for kind in ElementKind::ALL {
        let solid = SvkSolid::new(&distorted_patch(kind), &material);
        let x: Vec<f64> = solid
            .reference_positions()
            .chunks_exact(3)
            .flat_map(|p| {
                let mut y = [0.0; 3];
                for i in 0..3 {
                    y[i] = a[i][0] * p[0] + a[i][1] * p[1] + a[i][2] * p[2];
                }
                y
            })
            .collect();
        let strains = solid.green_strain_at_gauss_points(&x);
        assert_eq!(strains.len(), solid.gauss_point_positions().len());
        assert_eq!(
            strains.len(),
            solid.element_count() * solid.gauss_points_per_element()
        );
        for s in &strains {
            for (v, w) in s.iter().zip(&expected) {
                assert!((v - w).abs() < 1e-13, "{kind:?}: {s:?} vs {expected:?}");
            }
        }
        let volume: f64 = solid.weights.iter().sum();
        let energy = solid.strain_energy(&x);
        assert!(
            (energy - density * volume).abs() <= 1e-13 * energy,
            "{kind:?}: W = {energy}, expected {}",
            density * volume
        );
        // A homogeneous stress is self-equilibrated: interior nodes carry no force. Check
        // the total force and moment instead (they vanish for any state: rigid invariance).
        let mut f = vec![0.0; x.len()];
        solid.internal_force(&x, &mut f);
        let mut total = [0.0; 3];
        let mut moment = [0.0; 3];
        for (fi, xi) in f.chunks_exact(3).zip(x.chunks_exact(3)) {
            for d in 0..3 {
                total[d] += fi[d];
            }
            moment[0] += xi[1] * fi[2] - xi[2] * fi[1];
            moment[1] += xi[2] * fi[0] - xi[0] * fi[2];
            moment[2] += xi[0] * fi[1] - xi[1] * fi[0];
        }
        let scale = max_abs(&f);
        for d in 0..3 {
            assert!(total[d].abs() <= 1e-13 * scale, "{kind:?}: Σf = {total:?}");
            assert!(
                moment[d].abs() <= 1e-13 * scale,
                "{kind:?}: Σx×f = {moment:?}"
            );
        }
    }
}

/// Timing of one internal force and one tangent assembly on B1's mesh (Hex20 20×2×2) and on
/// Hex20 40×4×4. Run in release:
/// `cargo test --release --lib fem::nonlinear -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_of_force_and_tangent() {
    use std::time::Instant;
    for divisions in [[20, 2, 2], [40, 4, 4]] {
        let mesh = beam(1.0, 0.02, 0.02, divisions, ElementKind::Hex20).unwrap();
        let solid = SvkSolid::new(&mesh, &IsotropicMaterial::STEEL);
        let x: Vec<f64> = solid
            .reference_positions()
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1] - 0.01 * p[0] * p[0], p[2] + 1e-3 * p[0]])
            .collect();
        let n = x.len();
        let mut f = vec![0.0; n];
        let mut k = solid.tangent_pattern();
        // The fastest of 30 runs (ms): the machine is shared, the minimum is the figure least
        // disturbed by other processes.
        let time = |run: &mut dyn FnMut()| {
            run();
            (0..30)
                .map(|_| {
                    let start = Instant::now();
                    run();
                    start.elapsed().as_secs_f64() * 1e3
                })
                .fold(f64::INFINITY, f64::min)
        };
        let force_ms = time(&mut || solid.internal_force(&x, &mut f));
        let energy_ms = time(&mut || {
            std::hint::black_box(solid.strain_energy(&x));
        });
        let tangent_ms = time(&mut || solid.tangent_stiffness(&x, &mut k));
        let both_ms = time(&mut || solid.internal_force_and_tangent(&x, &mut f, &mut k));
        println!(
            "hex20 {divisions:?}: {n} DOF, nnz(K) = {}: internal force {force_ms:.3} ms, \
             energy {energy_ms:.3} ms, tangent {tangent_ms:.3} ms, force+tangent {both_ms:.3} ms",
            k.nnz()
        );
    }
}
