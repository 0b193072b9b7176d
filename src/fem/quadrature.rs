//! Gauss–Legendre quadrature on the reference hexahedron `ξ ∈ [−1, 1]³`.
//!
//! An `n`-point Gauss–Legendre rule integrates polynomials of degree `≤ 2n − 1` exactly on
//! `[−1, 1]`; the tensor-product rule with `n` points per axis integrates every polynomial whose
//! degree in each natural coordinate separately is `≤ 2n − 1` exactly on the cube.

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

#[cfg(test)]
mod tests {
    use super::*;

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
