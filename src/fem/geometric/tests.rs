#![allow(clippy::needless_range_loop)] // index-heavy linear algebra reads clearer with indices

use super::*;
use crate::element::corner_count;
use crate::fem::assembly::tests::straighten_edges;
use crate::fem::stiffness_matrix;
use crate::mesh::beam;

/// A 2×2×1 block of distorted elements (interior corner and top corners moved; Hex20
/// mid-edge nodes on the straight edges), so that gradients vary within the elements.
fn distorted_block(kind: ElementKind) -> Mesh {
    let block = beam(1.0, 0.8, 0.6, [2, 2, 1], kind).unwrap();
    let mut nodes = block.nodes().to_vec();
    for (i, p) in nodes.iter_mut().enumerate() {
        let is_corner = (0..block.element_count()).any(|e| {
            block.element(e)[..corner_count(kind)].contains(&i) // corners come first (VTK)
        });
        if is_corner {
            // A smooth perturbation of at most 0.04 m on elements of 0.5 × 0.4 × 0.6 m.
            let s = (3.1 * p[0] + 1.7 * p[1] - 2.3 * p[2]).sin();
            p[0] += 0.04 * s;
            p[1] += 0.03 * (2.0 * s * s - 1.0);
            p[2] += 0.02 * s * (1.0 - s);
        }
    }
    for e in 0..block.element_count() {
        straighten_edges(&mut nodes, kind, block.element(e));
    }
    let connectivity = (0..block.element_count())
        .flat_map(|e| block.element(e).to_vec())
        .collect();
    Mesh::new(nodes, kind, connectivity).unwrap()
}

/// A deterministic, non-uniform Gauss-point stress field (Pa), all six components non-zero.
fn varied_stress(mesh: &Mesh) -> Vec<[f64; 6]> {
    (0..gauss_point_count(mesh))
        .map(|g| {
            let t = g as f64;
            [
                1e6 * (0.3 * t).sin(),
                -2e6 * (0.17 * t).cos(),
                5e5 + 1e5 * t.sqrt(),
                3e5 * (0.5 * t).cos(),
                -4e5 * (0.11 * t).sin(),
                2e5,
            ]
        })
        .collect()
}

fn quadratic_form(a: &SymmetricCsr, u: &[f64]) -> f64 {
    let mut au = vec![0.0; u.len()];
    a.mul_vec(u, &mut au);
    u.iter().zip(&au).map(|(x, y)| x * y).sum()
}

fn max_abs(values: &[f64]) -> f64 {
    values.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

#[test]
fn gauss_point_count_is_that_of_the_stiffness_rule() {
    for kind in ElementKind::ALL {
        assert_eq!(
            gauss_points_per_element(kind),
            integration_rule(kind).len(),
            "{kind:?}"
        );
    }
}

#[test]
fn pattern_is_that_of_the_stiffness_matrix() {
    for kind in ElementKind::ALL {
        let mesh = distorted_block(kind);
        let k = stiffness_matrix(&mesh, &IsotropicMaterial::STEEL);
        let k_g = geometric_stiffness(&mesh, &varied_stress(&mesh));
        assert_eq!(k_g.n, k.n);
        assert_eq!(k_g.row_ptr, k.row_ptr, "{kind:?}");
        assert_eq!(k_g.col_idx, k.col_idx, "{kind:?}");
    }
}

#[test]
fn geometric_stiffness_is_symmetric_and_direction_diagonal() {
    // Each entry is a sum of the same products in the same order whichever triangle it is
    // in (the element matrix is mirrored, not recomputed), so symmetry holds to round-off
    // of the assembly order only: 1e-14 of the largest entry.
    for kind in ElementKind::ALL {
        let mesh = distorted_block(kind);
        let k_g = geometric_stiffness(&mesh, &varied_stress(&mesh));
        let dense = k_g.to_dense();
        let scale = max_abs(&k_g.values);
        assert!(scale > 0.0);
        for i in 0..k_g.n {
            for j in 0..k_g.n {
                assert!(
                    (dense[(i, j)] - dense[(j, i)]).abs() <= 1e-14 * scale,
                    "{kind:?} ({i}, {j})"
                );
                if i % 3 != j % 3 {
                    assert_eq!(dense[(i, j)], 0.0, "{kind:?} ({i}, {j})");
                }
            }
        }
    }
}

#[test]
fn zero_stress_gives_zero_matrix() {
    for kind in ElementKind::ALL {
        let mesh = distorted_block(kind);
        let k_g = geometric_stiffness(&mesh, &vec![[0.0; 6]; gauss_point_count(&mesh)]);
        assert!(k_g.values.iter().all(|&v| v == 0.0), "{kind:?}");
    }
}

#[test]
fn uniaxial_stress_quadratic_form_is_exact_for_linear_fields() {
    // u = A x + b is reproduced exactly by both element families: Σ_a u_a ⊗ ∇N_a = A at
    // every point, also on the distorted block, so uᵀ K_G u = Σ_gp w det J σ_xx |A e_x|²
    // = σ_xx V |A e_x|² with V = Σ_gp w det J (the quadrature of the volume, itself exact
    // here: det J of a trilinear map has degree ≤ 2 per natural variable, and the straight-
    // edged Hex20 map is that trilinear map; straight-edged tetrahedra have a constant det J).
    // Tolerance: round-off, 1e-12 relative.
    let a = [[0.3, -0.2, 0.5], [0.7, 0.1, -0.4], [-0.6, 0.25, 0.15]];
    let b = [0.01, -0.02, 0.03];
    let sigma = 3.7e6;
    for kind in ElementKind::ALL {
        for (m, mesh) in [
            beam(1.3, 0.5, 0.4, [3, 2, 2], kind).unwrap(),
            distorted_block(kind),
        ]
        .into_iter()
        .enumerate()
        {
            let mut u = vec![0.0; 3 * mesh.node_count()];
            for (i, p) in mesh.nodes().iter().enumerate() {
                for r in 0..3 {
                    u[3 * i + r] = b[r] + (0..3).map(|c| a[r][c] * p[c]).sum::<f64>();
                }
            }
            let reference = ReferenceGradients::new(kind);
            let n = kind.node_count();
            let mut coords = [[0.0; 3]; MAX_NODES];
            let mut g = [[0.0; 3]; MAX_NODES];
            let mut volume = 0.0;
            for e in 0..mesh.element_count() {
                element_coordinates(&mesh, e, &mut coords);
                for q in 0..reference.weights.len() {
                    volume += reference.weights[q]
                        * physical_gradients(
                            &coords[..n],
                            &reference.derivatives[q][..n],
                            &mut g[..n],
                        );
                }
            }
            if m == 0 {
                // The regular 1.3 × 0.5 × 0.4 block.
                assert!((volume / (1.3 * 0.5 * 0.4) - 1.0).abs() < 1e-13);
            }
            let stress = vec![[sigma, 0.0, 0.0, 0.0, 0.0, 0.0]; gauss_point_count(&mesh)];
            let k_g = geometric_stiffness(&mesh, &stress);
            let du_dx2: f64 = (0..3).map(|r| a[r][0] * a[r][0]).sum();
            let expected = sigma * volume * du_dx2;
            let got = quadratic_form(&k_g, &u);
            assert!(
                (got / expected - 1.0).abs() < 1e-12,
                "{kind:?}: {got} vs {expected}"
            );
            // A rigid translation has no gradient: K_G b = 0.
            let mut t = vec![0.0; u.len()];
            for i in 0..mesh.node_count() {
                t[3 * i..3 * i + 3].copy_from_slice(&b);
            }
            let mut kt = vec![0.0; t.len()];
            k_g.mul_vec(&t, &mut kt);
            assert!(max_abs(&kt) <= 1e-12 * max_abs(&k_g.values) * max_abs(&b));
        }
    }
}

#[test]
fn stress_of_a_linear_field_is_d_times_its_strain_everywhere() {
    // u = A x: ε = sym A at every Gauss point (exact reproduction); σ = D ε with D from
    // `elasticity_matrix` (independent of the λ/μ form used inside). Round-off: 1e-12 of
    // the largest stress component.
    let a = [
        [1e-3, -2e-4, 5e-4],
        [7e-4, -3e-4, -4e-4],
        [-6e-4, 2.5e-4, 1.5e-4],
    ];
    let material = IsotropicMaterial::STEEL;
    let d = material.elasticity_matrix();
    let strain = [
        a[0][0],
        a[1][1],
        a[2][2],
        a[1][2] + a[2][1],
        a[0][2] + a[2][0],
        a[0][1] + a[1][0],
    ];
    let expected: Vec<f64> = (0..6)
        .map(|i| (0..6).map(|j| d[i][j] * strain[j]).sum())
        .collect();
    let scale = max_abs(&expected);
    for kind in ElementKind::ALL {
        let mesh = distorted_block(kind);
        let mut u = vec![0.0; 3 * mesh.node_count()];
        for (i, p) in mesh.nodes().iter().enumerate() {
            for r in 0..3 {
                u[3 * i + r] = (0..3).map(|c| a[r][c] * p[c]).sum::<f64>();
            }
        }
        let stress = stress_at_gauss_points(&mesh, &material, &u);
        let per_element = match kind {
            ElementKind::Hex8 => 8,
            ElementKind::Hex20 => 27,
            ElementKind::Tet4 => 1,
            ElementKind::Tet10 => 4,
        };
        assert_eq!(stress.len(), mesh.element_count() * per_element);
        for s in &stress {
            for c in 0..6 {
                assert!((s[c] - expected[c]).abs() <= 1e-12 * scale, "{kind:?}");
            }
        }
    }
}

#[test]
fn in_place_and_weighted_sum_agree_with_the_allocating_assembly() {
    for kind in ElementKind::ALL {
        let mesh = distorted_block(kind);
        let s1 = varied_stress(&mesh);
        let s2: Vec<[f64; 6]> = s1.iter().rev().map(|s| s.map(|v| 0.5 * v + 1e5)).collect();
        let k1 = geometric_stiffness(&mesh, &s1);
        let k2 = geometric_stiffness(&mesh, &s2);
        let scale = max_abs(&k1.values).max(max_abs(&k2.values));

        // In place into a matrix holding stale values (a clone of K): identical result.
        let mut out = stiffness_matrix(&mesh, &IsotropicMaterial::STEEL);
        geometric_stiffness_into(&mesh, &s1, &mut out);
        assert_eq!(out, k1, "{kind:?}");

        // K_G is linear in the stress: K_G(c1 s1 + c2 s2) = c1 K_G(s1) + c2 K_G(s2), up to
        // round-off (1e-13 of the largest entry).
        let (c1, c2) = (-1.5, 2.25);
        let combined: Vec<[f64; 6]> = s1
            .iter()
            .zip(&s2)
            .map(|(a, b)| std::array::from_fn(|c| c1 * a[c] + c2 * b[c]))
            .collect();
        let direct = geometric_stiffness(&mesh, &combined);
        let mut sum = k1.clone();
        weighted_sum_into(&mut sum, &[(c1, &k1), (c2, &k2)]);
        assert_eq!(sum.col_idx, direct.col_idx);
        for (x, y) in sum.values.iter().zip(&direct.values) {
            assert!((x - y).abs() <= 1e-13 * scale, "{kind:?}: {x} vs {y}");
        }
        // A single term with weight 1 copies; no terms zeroes.
        weighted_sum_into(&mut sum, &[(1.0, &k2)]);
        assert_eq!(sum, k2);
        weighted_sum_into(&mut sum, &[]);
        assert!(sum.values.iter().all(|&v| v == 0.0));
    }
}

#[test]
fn weighted_sum_of_many_terms_is_the_sum_term_by_term() {
    // Six terms (one group of four, one of two): the same values, bit for bit, as adding the
    // terms one at a time in their order.
    let mesh = beam(1.0, 1.0, 1.0, [2, 1, 1], ElementKind::Hex8).unwrap();
    let count = gauss_point_count(&mesh);
    let terms: Vec<(f64, SymmetricCsr)> = (0..6)
        .map(|k| {
            let stress: Vec<[f64; 6]> = (0..count)
                .map(|g| std::array::from_fn(|c| ((k * 7 + g * 3 + c) % 11) as f64 - 5.0))
                .collect();
            (0.3 * k as f64 - 0.7, geometric_stiffness(&mesh, &stress))
        })
        .collect();
    let refs: Vec<(f64, &SymmetricCsr)> = terms.iter().map(|(c, t)| (*c, t)).collect();
    for n in 1..=refs.len() {
        let mut partial = terms[0].1.clone();
        weighted_sum_into(&mut partial, &refs[..n]);
        let mut one_by_one = terms[0].1.clone();
        weighted_sum_into(&mut one_by_one, &refs[..1]);
        for term in &refs[1..n] {
            for (v, &x) in one_by_one.values.iter_mut().zip(&term.1.values) {
                *v += term.0 * x;
            }
        }
        assert_eq!(partial, one_by_one, "{n} terms");
    }
}

#[test]
#[should_panic(expected = "pattern differs")]
fn weighted_sum_rejects_a_different_pattern() {
    let mesh = beam(1.0, 1.0, 1.0, [1, 1, 1], ElementKind::Hex8).unwrap();
    let k_g = geometric_stiffness(&mesh, &vec![[1.0; 6]; gauss_point_count(&mesh)]);
    let smaller = k_g.submatrix(&[0, 1, 2]);
    let mut out = k_g.clone();
    weighted_sum_into(&mut out, &[(1.0, &smaller)]);
}

#[test]
fn unit_stress_stiffness_sums_to_the_assembly_of_a_constant_stress() {
    // With the same stress at every Gauss point of every element, Σ_k S_k G_e,k assembled
    // over the elements is `geometric_stiffness`; the mean gradients reproduce the gradient
    // of a linear field (Σ_a X_a ⊗ ḡ_a = I).
    for kind in [
        ElementKind::Hex8,
        ElementKind::Hex20,
        ElementKind::Tet4,
        ElementKind::Tet10,
    ] {
        let mesh = distorted_block(kind);
        let stress = [3.0e5, -1.2e5, 0.7e5, 2.1e4, -4.4e4, 1.3e4];
        let k_g = geometric_stiffness(&mesh, &vec![stress; gauss_point_count(&mesh)]);
        let mut assembled = stiffness_pattern(&mesh);
        for e in 0..mesh.element_count() {
            let (unit, mean) = unit_stress_geometric_stiffness(&mesh, e);
            let nodes = mesh.element(e);
            let mut entry = 0;
            for a in 0..nodes.len() {
                for b in a..nodes.len() {
                    let value: f64 = (0..6).map(|k| stress[k] * unit[k][entry]).sum();
                    entry += 1;
                    for d in 0..3 {
                        let (row, column) = (3 * nodes[a] + d, 3 * nodes[b] + d);
                        let places: &[(usize, usize)] = if a == b {
                            &[(row, column)]
                        } else {
                            &[(row, column), (column, row)]
                        };
                        for &(r, c) in places {
                            let range = assembled.row_ptr[r]..assembled.row_ptr[r + 1];
                            let k = assembled.col_idx[range.clone()].binary_search(&c).unwrap();
                            assembled.values[range.start + k] += value;
                        }
                    }
                }
            }
            let mut identity = [[0.0; 3]; 3];
            for (&n, g) in nodes.iter().zip(&mean) {
                for r in 0..3 {
                    for c in 0..3 {
                        identity[r][c] += mesh.nodes()[n][r] * g[c];
                    }
                }
            }
            for r in 0..3 {
                for c in 0..3 {
                    let expected = if r == c { 1.0 } else { 0.0 };
                    assert!(
                        (identity[r][c] - expected).abs() < 1e-12,
                        "{kind:?}: {identity:?}"
                    );
                }
            }
        }
        let scale = max_abs(&k_g.values);
        for (x, y) in assembled.values.iter().zip(&k_g.values) {
            assert!((x - y).abs() <= 1e-12 * scale, "{kind:?}: {x} vs {y}");
        }
    }
}
