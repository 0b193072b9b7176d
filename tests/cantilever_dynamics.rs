//! B1 through the whole stack below the C ABI (body file → mesh → FE → body → solver → slave):
//! static deflection by damped settling, the support reaction, energy conservation of the
//! undamped step response with ρ∞ = 1, and its frequency.

mod common;
use common::*;

/// Tip load −10 N in y, damped (β = 2 ms: ζ₁ ≈ 0.1), 1 s: settles to the static deflection.
#[test]
fn damped_step_response_settles_at_the_static_deflection_and_the_support_balances_it() {
    let mut s = initialized_default(&[("damping.beta", 2e-3), ("tip.force[2]", -10.0)]);
    let y0 = get(&mut s, "tip.position[2]");
    let h = 1e-3;
    for k in 0..1000 {
        s.do_step(k as f64 * h, h).unwrap();
    }
    let deflection = get(&mut s, "tip.position[2]") - y0;
    let rel = (deflection + B1_TIMOSHENKO_DEFLECTION).abs() / B1_TIMOSHENKO_DEFLECTION;
    assert!(
        rel < 0.01,
        "tip deflection {deflection:e} m, {:.3} % off Timoshenko",
        100.0 * rel
    );
    // The settled body is in equilibrium: the root reaction balances the tip load (force and
    // moment about the root's reference point, the face centre (0,0,0)). Remaining motion after
    // 1 s at ζ₁ ≈ 0.1 is ~e^{-10.5} of the initial amplitude: 1e-4 relative.
    let f = get(&mut s, "root.force[2]");
    let t = get(&mut s, "root.torque[3]");
    assert!((f - 10.0).abs() < 1e-3 * 10.0, "root.force[2] = {f}");
    assert!((t - 10.0).abs() < 1e-3 * 10.0, "root.torque[3] = {t}");
    for name in [
        "root.force[1]",
        "root.force[3]",
        "root.torque[1]",
        "root.torque[2]",
    ] {
        let v = get(&mut s, name);
        assert!(v.abs() < 1e-3, "{name} = {v}");
    }
}

/// Undamped step response with ρ∞ = 1 (trapezoidal rule): the energy `T + V − F·(p − p₀)` is
/// conserved; the tip oscillates with the first bending frequency. `f_nl` is on: only with it is
/// the internal force the gradient of `V` (without it the energy error measured here was 1.3e-4
/// of the peak strain energy, since `R K Rᵀ ū` alone is not conservative).
#[test]
fn undamped_step_response_conserves_energy_and_oscillates_at_f1() {
    let h = 1e-4;
    let mut s = initialized_default(&[
        ("solver.rhoInf", 1.0),
        ("solver.stepSize", h),
        ("tip.force[2]", -10.0),
        ("model.nonlinearForces", 1.0),
        // Forced: model.auto keeps f_nl off on a supported body with one frame.
        ("model.auto", 0.0),
    ]);
    let y0 = get(&mut s, "tip.position[2]");
    let energy = |s: &mut flexbody::slave::Slave| {
        get(s, "body.kineticEnergy") + get(s, "body.strainEnergy")
            - (-10.0) * (get(s, "tip.position[2]") - y0)
    };
    let e0 = energy(&mut s);
    let (mut worst, mut peak_strain) = (0.0_f64, 0.0_f64);
    let mut ys = Vec::new();
    for k in 0..2000 {
        s.do_step(k as f64 * h, h).unwrap();
        let e = energy(&mut s);
        worst = worst.max((e - e0).abs());
        peak_strain = peak_strain.max(get(&mut s, "body.strainEnergy"));
        ys.push(get(&mut s, "tip.position[2]") - y0);
    }
    assert!(
        worst < 1e-6 * peak_strain,
        "energy error {worst:e} J against a peak strain energy of {peak_strain:e} J"
    );
    // Period from the up-crossings of the mean deflection.
    let mean = ys.iter().sum::<f64>() / ys.len() as f64;
    let crossings: Vec<f64> = (1..ys.len())
        .filter(|&k| ys[k - 1] < mean && ys[k] >= mean)
        .map(|k| (k as f64 - 1.0 + (mean - ys[k - 1]) / (ys[k] - ys[k - 1])) * h)
        .collect();
    assert!(crossings.len() >= 3, "{} crossings", crossings.len());
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let f1 = 1.0 / period;
    assert!(
        (f1 - B1_FIRST_FREQUENCY).abs() < 0.01 * B1_FIRST_FREQUENCY,
        "f1 = {f1} Hz"
    );
}
