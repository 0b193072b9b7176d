//! Quadrature on the reference elements: Gauss–Legendre on the hexahedron `ξ ∈ [−1, 1]³`, and
//! symmetric rules on the unit tetrahedron `ξ, η, ζ ≥ 0, ξ + η + ζ ≤ 1` (volume 1/6).
//!
//! An `n`-point Gauss–Legendre rule integrates polynomials of degree `≤ 2n − 1` exactly on
//! `[−1, 1]`; the tensor-product rule with `n` points per axis integrates every polynomial whose
//! degree in each natural coordinate separately is `≤ 2n − 1` exactly on the cube. The
//! tetrahedron rules integrate every polynomial of total degree `≤ d` exactly (see
//! [`tetrahedron_rule`]).

/// One point of a quadrature rule: natural coordinates `ξ` and weight (the weights of a rule on
/// the cube sum to its volume, 8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraturePoint {
    pub xi: [f64; 3],
    pub weight: f64,
}

/// The `points`-point Gauss–Legendre rule on `[−1, 1]` as (abscissa, weight) pairs, ascending
/// abscissae, for `points` in 1..=4. Panics for other counts (a programming error: the elements
/// of this crate use 2 or 3).
pub fn gauss_legendre_1d(points: usize) -> &'static [(f64, f64)] {
    // Abscissae: roots of the Legendre polynomial P_n; weights 2 / ((1 − x²) P_n'(x)²).
    const G1: [(f64, f64); 1] = [(0.0, 2.0)];
    const G2: [(f64, f64); 2] = [
        (-0.577_350_269_189_625_8, 1.0),
        (0.577_350_269_189_625_8, 1.0),
    ];
    const G3: [(f64, f64); 3] = [
        (-0.774_596_669_241_483_4, 5.0 / 9.0),
        (0.0, 8.0 / 9.0),
        (0.774_596_669_241_483_4, 5.0 / 9.0),
    ];
    const G4: [(f64, f64); 4] = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    match points {
        1 => &G1,
        2 => &G2,
        3 => &G3,
        4 => &G4,
        _ => panic!("gauss_legendre_1d: {points} points not tabulated (1..=4)"),
    }
}

/// The tensor-product Gauss–Legendre rule with `points_per_axis` points along each natural axis
/// (`points_per_axis³` points, ξ varying fastest).
pub fn hexahedron_rule(points_per_axis: usize) -> Vec<QuadraturePoint> {
    let rule = gauss_legendre_1d(points_per_axis);
    let mut out = Vec::with_capacity(rule.len().pow(3));
    for &(zeta, wz) in rule {
        for &(eta, wy) in rule {
            for &(xi, wx) in rule {
                out.push(QuadraturePoint {
                    xi: [xi, eta, zeta],
                    weight: wx * wy * wz,
                });
            }
        }
    }
    out
}

/// Points of one symmetry orbit of the tetrahedron, given by barycentric coordinates.
fn tetrahedron_orbit(out: &mut Vec<QuadraturePoint>, barycentric: &[[f64; 4]], weight: f64) {
    // Natural coordinates (ξ, η, ζ) = (L_1, L_2, L_3).
    for l in barycentric {
        out.push(QuadraturePoint {
            xi: [l[1], l[2], l[3]],
            weight,
        });
    }
}

/// The 4 permutations of `(a, a, a, 1 − 3a)`.
fn orbit_s31(a: f64) -> [[f64; 4]; 4] {
    let b = 1.0 - 3.0 * a;
    [[b, a, a, a], [a, b, a, a], [a, a, b, a], [a, a, a, b]]
}

/// The 6 permutations of `(a, a, ½ − a, ½ − a)`.
fn orbit_s22(a: f64) -> [[f64; 4]; 6] {
    let b = 0.5 - a;
    [
        [a, a, b, b],
        [a, b, a, b],
        [a, b, b, a],
        [b, a, a, b],
        [b, a, b, a],
        [b, b, a, a],
    ]
}

/// A symmetric rule on the unit tetrahedron exact for every polynomial of total degree
/// `≤ degree` (the smallest tabulated one), weights summing to 1/6, all positive:
///
/// * degree ≤ 1: the centroid, 1 point;
/// * degree 2: 4 points `(a, a, a, 1 − 3a)`, `a = (5 − √5)/20`, weights 1/24;
/// * degree 3 to 5: 14 points (two 4-point orbits and one 6-point orbit; Walkington's
///   degree-5 rule, the one Gmsh uses for "Gauss5").
///
/// Panics for a degree above 5 (a programming error: the elements of this crate need ≤ 5).
pub fn tetrahedron_rule(degree: u32) -> Vec<QuadraturePoint> {
    let mut out = Vec::new();
    match degree {
        0 | 1 => tetrahedron_orbit(&mut out, &[[0.25; 4]], 1.0 / 6.0),
        2 => {
            let a = (5.0 - 5f64.sqrt()) / 20.0;
            tetrahedron_orbit(&mut out, &orbit_s31(a), 1.0 / 24.0);
        }
        3..=5 => {
            tetrahedron_orbit(
                &mut out,
                &orbit_s31(0.092_735_250_310_891_22),
                0.012_248_840_519_393_659,
            );
            tetrahedron_orbit(
                &mut out,
                &orbit_s31(0.310_885_919_263_300_6),
                0.018_781_320_953_002_643,
            );
            tetrahedron_orbit(
                &mut out,
                &orbit_s22(0.045_503_704_125_649_65),
                0.007_091_003_462_846_911,
            );
        }
        _ => panic!("tetrahedron_rule: degree {degree} not tabulated (≤ 5)"),
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn factorial(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    /// `∫ ξ^a η^b ζ^c` over the unit tetrahedron `= a! b! c! / (a + b + c + 3)!`.
    fn tetrahedron_monomial(a: u32, b: u32, c: u32) -> f64 {
        factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3)
    }

    #[test]
    fn tetrahedron_rules_are_exact_to_their_degree_and_not_beyond() {
        for (degree, points) in [(1, 1), (2, 4), (5, 14)] {
            let rule = tetrahedron_rule(degree);
            assert_eq!(rule.len(), points);
            assert!(rule.iter().all(|q| q.weight > 0.0));
            assert!(rule
                .iter()
                .all(|q| q.xi.iter().all(|&c| c > 0.0) && q.xi.iter().sum::<f64>() < 1.0));
            let mut worst_beyond = 0.0f64;
            for a in 0..=degree + 1 {
                for b in 0..=degree + 1 - a {
                    for c in 0..=degree + 1 - a - b {
                        let q: f64 = rule
                            .iter()
                            .map(|p| {
                                p.weight
                                    * p.xi[0].powi(a as i32)
                                    * p.xi[1].powi(b as i32)
                                    * p.xi[2].powi(c as i32)
                            })
                            .sum();
                        let exact = tetrahedron_monomial(a, b, c);
                        let error = (q - exact).abs() / exact;
                        if a + b + c <= degree {
                            // Round-off of ≤ 14 terms: a few ε.
                            assert!(
                                error < 1e-14,
                                "degree {degree}: ξ^{a} η^{b} ζ^{c}: {error:e}"
                            );
                        } else {
                            worst_beyond = worst_beyond.max(error);
                        }
                    }
                }
            }
            // Some monomial of degree + 1 is not integrated exactly (the rule is no better).
            assert!(worst_beyond > 1e-4, "degree {degree}: exact beyond?");
        }
    }

    /// ∫_{−1}^{1} x^k dx = 2/(k+1) for even k, 0 for odd k.
    fn exact_monomial(k: u32) -> f64 {
        if k % 2 == 1 {
            0.0
        } else {
            2.0 / (k as f64 + 1.0)
        }
    }

    #[test]
    fn one_dimensional_rules_are_exact_to_degree_2n_minus_1_and_not_beyond() {
        for n in 1..=4usize {
            let rule = gauss_legendre_1d(n);
            for k in 0..(2 * n as u32) {
                let q: f64 = rule.iter().map(|&(x, w)| w * x.powi(k as i32)).sum();
                assert!((q - exact_monomial(k)).abs() < 1e-15, "n={n} k={k}: {q}");
            }
            // Degree 2n is not integrated exactly (the rule is optimal, not more).
            let k = 2 * n as u32;
            let q: f64 = rule.iter().map(|&(x, w)| w * x.powi(k as i32)).sum();
            assert!(
                (q - exact_monomial(k)).abs() > 1e-3,
                "n={n} degree {k} exact?"
            );
        }
    }

    #[test]
    fn hexahedron_rule_integrates_tensor_monomials() {
        let rule = hexahedron_rule(3);
        assert_eq!(rule.len(), 27);
        let volume: f64 = rule.iter().map(|p| p.weight).sum();
        assert!((volume - 8.0).abs() < 1e-14);
        // x⁴ y² z⁵ + x² z⁴: degree ≤ 5 per coordinate.
        let q: f64 = rule
            .iter()
            .map(|p| {
                let [x, y, z] = p.xi;
                p.weight * (x.powi(4) * y * y * z.powi(5) + x * x * z.powi(4))
            })
            .sum();
        let exact = exact_monomial(2) * 2.0 * exact_monomial(4);
        assert!((q - exact).abs() < 1e-14, "{q} vs {exact}");
    }
}
