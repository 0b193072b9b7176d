//! B2: a free-floating tumbling beam. With the nonlinear force term `f_nl` the internal forces
//! are free of net moment, so linear and angular momentum are conserved to solver tolerance;
//! without it the angular momentum drifts (DESIGN.md section 2).

mod common;
use common::*;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::Vector3;

fn tumbling(nonlinear_forces: bool) -> Slave {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/tumbling.json")).unwrap();
    let mut s = Slave::from_body(BodyFile::from_json(&text).unwrap()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    for (k, w) in [0.5, 3.0, 7.0].iter().enumerate() {
        set(&mut s, &format!("initial.angularVelocity[{}]", k + 1), *w);
    }
    set(&mut s, "model.nonlinearForces", if nonlinear_forces { 1.0 } else { 0.0 });
    s.exit_initialization_mode().unwrap();
    s
}

fn momenta(s: &mut Slave) -> (Vector3<f64>, Vector3<f64>) {
    let p = Vector3::from_fn(|k, _| get(s, &format!("body.linearMomentum[{}]", k + 1)));
    let l = Vector3::from_fn(|k, _| get(s, &format!("body.angularMomentum[{}]", k + 1)));
    (p, l)
}

/// Largest relative change of the angular momentum over 1 s (1000 steps).
fn angular_momentum_drift(nonlinear_forces: bool) -> (f64, f64) {
    let mut s = tumbling(nonlinear_forces);
    let (_, l0) = momenta(&mut s);
    let h = 1e-3;
    let (mut worst_l, mut worst_p) = (0.0_f64, 0.0_f64);
    for k in 0..1000 {
        s.do_step(k as f64 * h, h).unwrap();
        let (p, l) = momenta(&mut s);
        worst_l = worst_l.max((l - l0).norm() / l0.norm());
        // |p| relative to the momentum scale of the rotation: m · |ω| · L/2
        worst_p = worst_p.max(p.norm() / (3.14 * 7.6 * 0.5));
    }
    (worst_l, worst_p)
}

#[test]
fn with_f_nl_a_free_body_conserves_momentum() {
    let (l_drift, p_drift) = angular_momentum_drift(true);
    // Solver tolerance 1e-12 × body size per step, 1000 steps: 1e-9 relative is generous.
    assert!(l_drift < 1e-9, "angular momentum drift {l_drift:e}");
    assert!(p_drift < 1e-12, "linear momentum {p_drift:e}");
    let (l_drift_without, p_without) = angular_momentum_drift(false);
    assert!(p_without < 1e-12, "linear momentum without f_nl {p_without:e}");
    assert!(
        l_drift_without > 100.0 * l_drift,
        "without f_nl the angular momentum should drift visibly: {l_drift_without:e} vs {l_drift:e}"
    );
}
