//! The full nonlinear reference (`model.formulation = full`, total-Lagrangian St. Venant–Kirchhoff
//! with Newton on the assembled tangent) through the slave.

mod common;
use common::*;

/// At B1's load the deformation is small (δ/L ≈ 1e-3), so the full formulation and the reduced
/// strain settle at the same deflection: their difference is of second order, (δ/L)² ≈ 1e-6
/// relative; 1e-4 is the tolerance. Newton converges in a few iterations per step.
#[test]
fn full_formulation_settles_where_the_reduced_strain_does() {
    let settings = [("damping.beta", 2e-2), ("tip.force[2]", -10.0)];
    let mut full = initialized_default(&[settings[0], settings[1], ("model.formulation", 2.0)]);
    let mut reduced = initialized_default(&settings);
    let y0 = get(&mut full, "tip.position[2]");
    let h = 1e-3;
    // β = 20 ms: every mode decays at least like e^{−t/β}; 0.3 s leaves e^{−15}.
    for k in 0..300 {
        full.do_step(k as f64 * h, h).unwrap();
        reduced.do_step(k as f64 * h, h).unwrap();
    }
    let d_full = get(&mut full, "tip.position[2]") - y0;
    let d_reduced = get(&mut reduced, "tip.position[2]") - y0;
    assert!(
        (d_full - d_reduced).abs() < 1e-4 * d_reduced.abs(),
        "full {d_full:e} m, reduced strain {d_reduced:e} m"
    );
    let (steps, iterations) = full.solver_statistics();
    let per_step = iterations as f64 / steps as f64;
    assert!(per_step < 4.0, "{per_step} Newton iterations per step");
    // The strain energy of the settled body is the work of the load, F δ / 2, to first order.
    let energy = get(&mut full, "body.strainEnergy");
    assert!(
        (energy - 0.5 * 10.0 * d_full.abs()).abs() < 1e-3 * energy,
        "strain energy {energy:e} J vs F δ / 2 = {:e} J",
        0.5 * 10.0 * d_full.abs()
    );
}
