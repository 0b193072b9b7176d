//! The stiffness folded into the generalized-α solve (docs/formulation.md, "The stiffness folded
//! into the solve"): the correction's solve of the folded residual plus `ū_F / k'` equals the
//! solve of the residual itself, `S̄⁻¹ hRᵀ r = S̄⁻¹ hRᵀ r° + ū_F / k'`, at a state far from
//! equilibrium (turned by 0.7 rad, deformed, moving), with Rayleigh damping (`k' ≠ 1`), on a mesh
//! body (sparse `K`, many held nodes) and on B1's reduced body (dense `K`, held coordinates).

mod common;

use common::reduced_b1::B1;
use flexbody::body::{Body, BodyOptions};
use flexbody::solver::generalized_alpha::{self, GeneralizedAlpha, IterationMatrix, StepWorkspace};
use flexbody::solver::problem::{
    folded_residual, last_residual, residual, DynamicState, FreeNodes, IterationSettings,
    ResidualWorkspace, StepProblem,
};
use nalgebra::{Matrix3, Rotation3, Vector3};

const ALPHA: f64 = 3.0; // 1/s
const BETA: f64 = 2e-4; // s

fn options() -> BodyOptions {
    BodyOptions {
        damping_alpha: ALPHA,
        damping_beta: BETA,
        ..BodyOptions::default()
    }
}

/// A state of `body`: its reference turned by 0.7 rad about (1, 2, 3) and shifted, plus a smooth
/// deformation of relative size 1e-3; velocities and accelerations of a few m/s and m/s².
fn state(body: &Body) -> DynamicState {
    let n3 = body.reference.len();
    let turn = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)),
        0.7,
    );
    let shift = Vector3::new(0.3, -0.2, 0.1);
    let mut s = DynamicState::zeros(n3, 0);
    for i in 0..n3 / 3 {
        let x = Vector3::new(
            body.reference[3 * i],
            body.reference[3 * i + 1],
            body.reference[3 * i + 2],
        );
        let u = 1e-3 * Vector3::new((3.0 * x.x).sin(), (2.0 * x.x + x.y).cos(), x.z * x.x);
        let p = turn * (x + u) + shift;
        for d in 0..3 {
            let k = (3 * i + d) as f64;
            s.position[3 * i + d] = p[d];
            s.velocity[3 * i + d] = (0.37 * k).sin();
            s.acceleration[3 * i + d] = 2.0 * (0.11 * k).cos();
        }
    }
    s
}

/// `S̄⁻¹ hRᵀ r` on the free DOFs, from the residual itself and from the folded one; with their
/// largest entry.
fn both_solves(body: &Body, free: &FreeNodes) -> (Vec<f64>, Vec<f64>, f64) {
    let scheme = GeneralizedAlpha::new(0.9);
    let h = 1e-3;
    let matrix = IterationMatrix::new(body, free, &scheme, h, ALPHA, BETA).unwrap();
    let c_m = scheme.mass_coefficient(h);
    let c_d = scheme.damping_coefficient(h);
    let k_prime = 1.0 + c_d * BETA;
    let kappa = (c_m + c_d * ALPHA) / k_prime;
    let s = state(body);
    let loads = |_x: &[f64], f: &mut [f64]| f.iter_mut().for_each(|v| *v = 0.01);
    let mut ws = ResidualWorkspace::new(body);
    let mut workspace = matrix.factor.solve_scratch();
    let mut solve = |r: &[f64], rotation: &Matrix3<f64>| {
        let mut y = vec![0.0; 3 * free.nodes.len()];
        for (k, &i) in free.nodes.iter().enumerate() {
            let local = rotation.transpose() * Vector3::from_column_slice(&r[3 * i..3 * i + 3]);
            y[3 * k..3 * k + 3].copy_from_slice(local.as_slice());
        }
        matrix.factor.solve_in_place(&mut y, &mut workspace);
        y
    };
    let kin = residual(body, free, &s, &loads, &mut ws);
    let plain = solve(last_residual(&ws), &kin.frame.rotation);
    let kin = folded_residual(body, free, &s, &loads, &mut ws, kappa);
    let mut folded = solve(last_residual(&ws), &kin.frame.rotation);
    let ubar = ws.force_scratch().local_deformation();
    for (k, &i) in free.nodes.iter().enumerate() {
        for d in 0..3 {
            folded[3 * k + d] += ubar[3 * i + d] / k_prime;
        }
    }
    let largest = plain
        .iter()
        .chain(ubar)
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    (plain, folded, largest)
}

fn assert_same(plain: &[f64], folded: &[f64], largest: f64) {
    // The two differ by round-off: the folded solve's two parts are each of the size of `ū`
    // (or of the correction), and each solve carries about cond(S̄) ε of it (measured 3e-12
    // on the mesh, 2e-12 on the reduced body, relative to the largest entry).
    let difference = plain
        .iter()
        .zip(folded)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        difference <= 1e-10 * largest,
        "the folded solve is {difference:e} from the plain one (largest entry {largest:e})"
    );
    // The fold is not trivially equal: with `ū_F` for `ū_F / k'` the two differ by 7e-2 (mesh)
    // and 1e-1 (reduced) of the largest entry.
    assert!(largest > 1e-6);
}

#[test]
fn a_mesh_body_folds_its_stiffness_into_the_solve() {
    let (mesh, body) = common::steel_beam(options());
    let clamped: Vec<bool> = mesh.nodes().iter().map(|p| p[0].abs() < 1e-9).collect();
    let free = FreeNodes::new(&body, &clamped);
    let (plain, folded, largest) = both_solves(&body, &free);
    assert_same(&plain, &folded, largest);
}

#[test]
fn a_reduced_body_folds_its_stiffness_into_the_solve() {
    let b1 = B1::new();
    let (_, _, reduction) = b1.reduced(&[&b1.root], &[&b1.tip], 4);
    let held: Vec<usize> = reduction.held[0].iter().map(|h| h.index).collect();
    let s = reduction.field_count;
    let body = Body::reduced(reduction, options());
    let clamped: Vec<bool> = (0..s).map(|k| held.contains(&k)).collect();
    let free = FreeNodes::new(&body, &clamped);
    assert!(!free.clamped.is_empty() && !free.nodes.is_empty());
    let (plain, folded, largest) = both_solves(&body, &free);
    assert_same(&plain, &folded, largest);
}

/// One generalized-α step of `body` from [`state`] (deformed, turned, moving) under a uniform
/// load, iterated to 1e-13 m; returns the plain residual's solve at its end, `S̄⁻¹ hRᵀ r` on the
/// free DOFs (the correction a plain iteration would still take), and the largest `|ū|`.
fn step_and_remaining_correction(body: &Body, free: &FreeNodes) -> (f64, f64) {
    let scheme = GeneralizedAlpha::new(0.9);
    let h = 1e-3;
    let mut matrix = IterationMatrix::new(body, free, &scheme, h, ALPHA, BETA).unwrap();
    let loads = |_x: &[f64], f: &mut [f64]| f.iter_mut().for_each(|v| *v = 0.01);
    let problem = StepProblem {
        body,
        free,
        loads: &loads,
        prescribe: &|_t: f64, _s: &mut DynamicState| {},
    };
    let settings = IterationSettings {
        absolute_tolerance: 1e-13,
        carried_below: 0.0,
        max_iterations: 50,
        estimate_error: None,
    };
    let mut s = state(body);
    let mut ws = StepWorkspace::new(body, free);
    let mut forces = ResidualWorkspace::new(body);
    generalized_alpha::step(
        &problem,
        &mut matrix,
        &settings,
        h,
        &mut s,
        &mut ws,
        &mut forces,
    )
    .unwrap();
    let kin = residual(body, free, &s, &loads, &mut forces);
    let r = last_residual(&forces);
    let mut y = vec![0.0; 3 * free.nodes.len()];
    for (k, &i) in free.nodes.iter().enumerate() {
        let local =
            kin.frame.rotation.transpose() * Vector3::from_column_slice(&r[3 * i..3 * i + 3]);
        y[3 * k..3 * k + 3].copy_from_slice(local.as_slice());
    }
    let mut workspace = matrix.factor.solve_scratch();
    matrix.factor.solve_in_place(&mut y, &mut workspace);
    let largest = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    (
        largest(&y),
        largest(forces.force_scratch().local_deformation()),
    )
}

#[test]
fn folded_steps_end_in_the_plain_residuals_equilibrium() {
    // Where a folded step ends, the plain residual leaves a correction of the solve's rounding
    // of `ū` (docs/formulation.md, "The stiffness folded into the solve": `S̄⁻¹ E ū`), far below
    // `ū` itself: measured 3e-11 of `|ū|` with one frame, 2e-11 for the linear body (whose `ū`
    // holds the 0.7 rad turn). With `κ = c'` for `c'/k'` in the iteration it is 0.14 of `|ū|`.
    let (mesh, body) = common::steel_beam(options());
    let clamped: Vec<bool> = mesh.nodes().iter().map(|p| p[0].abs() < 1e-9).collect();
    let free = FreeNodes::new(&body, &clamped);
    let (remaining, size) = step_and_remaining_correction(&body, &free);
    assert!(remaining <= 1e-9 * size, "{remaining:e} of {size:e}");

    // The linear body, which stops at its first correction.
    let mut linear = body.clone();
    linear.linear = Some(body.linear_placement(&body.reference));
    let free = FreeNodes::new(&linear, &clamped);
    let (remaining, size) = step_and_remaining_correction(&linear, &free);
    assert!(remaining <= 1e-9 * size, "{remaining:e} of {size:e}");
}
