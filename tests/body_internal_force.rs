//! The internal force of the ACF-RS body (docs/formulation.md, "The internal force") against finite differences of the
//! strain energy `V = ½ ūᵀ K ū` on a rotated, deformed body; its balance (no net force or moment
//! with `f_nl`); damping that leaves rigid motion undamped.

use flexbody::body::frame::{node, set_node};
use flexbody::body::{Body, BodyOptions};
use flexbody::fem::{self, IsotropicMaterial};
use flexbody::mesh::{self, ElementKind};
use nalgebra::{Rotation3, Vector3};

fn small_beam(options: BodyOptions) -> Body {
    beam_of(options, 2.1e11)
}

fn beam_of(options: BodyOptions, youngs_modulus: f64) -> Body {
    let mesh = mesh::beam(0.4, 0.05, 0.03, [4, 1, 1], ElementKind::Hex20).unwrap();
    let material = IsotropicMaterial {
        youngs_modulus,
        poisson_ratio: 0.3,
        density: 7850.0,
    };
    let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
    Body::new(
        reference,
        fem::scalar_mass_matrix(&mesh, material.density),
        fem::stiffness_matrix(&mesh, &material),
        fem::lumped_masses(&mesh, material.density),
        options,
    )
}

/// A large rotation and translation of a deformed configuration (bending plus a twist, ~1e-3 m).
fn rotated_deformed(body: &Body) -> Vec<f64> {
    let q = Rotation3::from_scaled_axis(Vector3::new(0.7, -1.1, 2.0));
    let t = Vector3::new(0.3, -0.2, 1.5);
    let mut x = vec![0.0; body.reference.len()];
    for i in 0..body.node_count() {
        let p = node(&body.reference, i);
        let s = p.x / 0.4;
        let u = Vector3::new(
            2e-4 * (3.0 * s).sin() * p.y,
            2e-3 * s * s + 1e-4 * p.z,
            -1e-3 * s * s * s + 3e-3 * s * p.y,
        );
        set_node(&mut x, i, &(t + q * (p + u)));
    }
    x
}

#[test]
fn internal_force_is_the_gradient_of_the_strain_energy() {
    let body = small_beam(BodyOptions {
        nonlinear_forces: true,
        ..BodyOptions::default()
    });
    let x = rotated_deformed(&body);
    let mut scratch = body.force_scratch();
    let mut f = vec![0.0; x.len()];
    let zero = vec![0.0; x.len()];
    body.internal_force(&x, &zero, None, &mut scratch, &mut f);
    // Central differences: error O(ε²) ≈ 1e-9 relative at ε = 1e-7 m against deformations of
    // 1e-3 m; round-off of V (≈ 1e3 J × 1e-16 / 1e-7) is well below the tolerance.
    let eps = 1e-7;
    let f_scale = f.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut worst: f64 = 0.0;
    let mut xp = x.clone();
    for k in (0..x.len()).step_by(7) {
        xp[k] = x[k] + eps;
        let vp = body.strain_energy(&xp);
        xp[k] = x[k] - eps;
        let vm = body.strain_energy(&xp);
        xp[k] = x[k];
        let fd = (vp - vm) / (2.0 * eps);
        worst = worst.max((fd - f[k]).abs());
    }
    assert!(
        worst < 1e-6 * f_scale,
        "largest |f − ∂V/∂x| = {worst:e}, force scale {f_scale:e}"
    );

    // Without f_nl the force misses a term of second order in ū: the mismatch is visible.
    let linear = small_beam(BodyOptions::default());
    let mut fl = vec![0.0; x.len()];
    linear.internal_force(&x, &zero, None, &mut scratch, &mut fl);
    let diff = f
        .iter()
        .zip(&fl)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        diff > 1e3 * worst,
        "f_nl should matter at this deformation: {diff:e}"
    );
}

#[test]
fn with_f_nl_the_internal_force_has_no_net_force_or_moment() {
    let mut results = Vec::new();
    for nonlinear_forces in [true, false] {
        let body = small_beam(BodyOptions {
            nonlinear_forces,
            ..BodyOptions::default()
        });
        let xs = rotated_deformed(&body);
        let mut scratch = body.force_scratch();
        let mut f = vec![0.0; xs.len()];
        let zero = vec![0.0; xs.len()];
        body.internal_force(&xs, &zero, None, &mut scratch, &mut f);
        let (mut force, mut moment, mut scale) = (Vector3::zeros(), Vector3::zeros(), 0.0_f64);
        for i in 0..body.node_count() {
            force += node(&f, i);
            moment += node(&xs, i).cross(&node(&f, i));
            scale = scale.max(node(&f, i).norm() * node(&xs, i).norm().max(1.0));
        }
        results.push((force.norm() / scale, moment.norm() / scale));
    }
    let (with, without) = (results[0], results[1]);
    // Net force vanishes either way (K annihilates translations); the net moment vanishes only with
    // f_nl (to round-off), without it it is of second order in the deformation.
    assert!(with.0 < 1e-13 && without.0 < 1e-13, "{with:?} {without:?}");
    assert!(with.1 < 1e-13, "net moment with f_nl: {:e}", with.1);
    assert!(
        without.1 > 1e4 * with.1.max(1e-16),
        "net moment without f_nl: {:e}",
        without.1
    );
}

#[test]
fn damping_leaves_rigid_motion_of_a_deformed_body_undamped() {
    let body = small_beam(BodyOptions {
        nonlinear_forces: false,
        damping_alpha: 5.0,
        damping_beta: 1e-3,
    });
    let undamped = small_beam(BodyOptions::default());
    let x = rotated_deformed(&body);
    let c = body.frame_weights.centroid(&x);
    let (vc, omega) = (Vector3::new(1.0, -2.0, 0.5), Vector3::new(3.0, -1.0, 7.0));
    let mut v = vec![0.0; x.len()];
    for i in 0..body.node_count() {
        set_node(&mut v, i, &(vc + omega.cross(&(node(&x, i) - c))));
    }
    let mut scratch = body.force_scratch();
    let (mut fd, mut f0) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    body.internal_force(&x, &v, None, &mut scratch, &mut fd);
    undamped.internal_force(&x, &v, None, &mut scratch, &mut f0);
    let scale = f0.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let diff = fd
        .iter()
        .zip(&f0)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        diff < 1e-9 * scale,
        "damping force of a rigid motion: {diff:e} (scale {scale:e})"
    );

    // A deformation rate is damped: the damping force opposes it (negative power).
    let mut vd = v.clone();
    for i in 0..body.node_count() {
        let p = node(&body.reference, i);
        set_node(
            &mut vd,
            i,
            &(node(&v, i) + Vector3::new(0.0, 0.05 * p.x * p.x, 0.0)),
        );
    }
    body.internal_force(&x, &vd, None, &mut scratch, &mut fd);
    undamped.internal_force(&x, &vd, None, &mut scratch, &mut f0);
    let power: f64 = (0..x.len()).map(|k| (fd[k] - f0[k]) * vd[k]).sum();
    assert!(
        power > 0.0,
        "damping must dissipate: power of f_d = {power:e}"
    );
}

/// The mass-proportional damping acts on the velocity relative to its kinetic-energy-nearest
/// rigid motion: for any velocity field it has no net force and no net moment (so it neither
/// brakes nor spins the body) and it dissipates. (A body of E = 1 Pa, so that the elastic forces
/// do not drown the damping force in round-off when the two are told apart.)
#[test]
fn mass_proportional_damping_has_no_net_force_or_moment_and_dissipates() {
    let damped = beam_of(
        BodyOptions {
            damping_alpha: 5.0,
            ..BodyOptions::default()
        },
        1.0,
    );
    let undamped = beam_of(BodyOptions::default(), 1.0);
    let x = rotated_deformed(&damped);
    let mut v = vec![0.0; x.len()];
    for (k, value) in v.iter_mut().enumerate() {
        *value = (0.7 * k as f64).sin() + 0.3 * (1.3 * k as f64).cos();
    }
    let mut scratch = damped.force_scratch();
    let (mut fd, mut f0) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    damped.internal_force(&x, &v, None, &mut scratch, &mut fd);
    undamped.internal_force(&x, &v, None, &mut scratch, &mut f0);
    let (mut force, mut moment, mut scale) = (Vector3::zeros(), Vector3::zeros(), 0.0_f64);
    let mut power = 0.0;
    for i in 0..damped.node_count() {
        let f = node(&fd, i) - node(&f0, i);
        force += f;
        moment += node(&x, i).cross(&f);
        scale = scale.max(f.norm() * node(&x, i).norm().max(1.0));
        power += f.dot(&node(&v, i));
    }
    assert!(force.norm() < 1e-12 * scale, "net damping force {force:?}");
    assert!(
        moment.norm() < 1e-12 * scale,
        "net damping moment {moment:?}"
    );
    assert!(power > 0.0, "power {power}");
}
