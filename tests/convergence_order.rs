//! Convergence order in time (issue 7): generalized-α is second order for any ρ∞.
//!
//! A B1-like cantilever (steel, 1 m × 20 mm × 20 mm, hex20 10×1×1, root clamped) under a
//! smooth tip load `F(t) = −10 sin²(π t / T) N`, T = 20 ms, evaluated at `t_{n+1}` (the scheme's
//! equilibrium time), integrated to 2T. The pulse starts with zero load and zero load rate, so
//! the unresolved high modes of the mesh stay quiet and the error is the scheme's: the tip
//! deflection error against a run at h = H/64 falls as h² (observed order in [1.8, 2.2]).
//!
//! Through the FMU, inputs are held over a communication step and a jump at a communication
//! point costs an error of order h (measured: the same pulse held at 1 ms through the slave
//! converged at order 1.0–1.1). `restart_for_load_change` removes it (order 2 again, to the
//! level of the unresolved modes) but destabilised the iterated coupling of two FMUs, so the
//! slave does not use it; it is tested below for consistency. Input derivatives (issue 6) give
//! continuous loads.

use flexbody::body::{Body, BodyOptions};
use flexbody::fem::{self, IsotropicMaterial};
use flexbody::mesh::{generator, ElementKind};
use flexbody::solver::central_difference::CentralDifference;
use flexbody::solver::consistent_acceleration::ConsistentAcceleration;
use flexbody::solver::generalized_alpha::{
    self, initial_acceleration, GeneralizedAlpha, IterationMatrix, StepWorkspace,
};
use flexbody::solver::problem::{
    last_residual, residual, DynamicState, FreeNodes, IterationSettings, ResidualWorkspace,
    StepProblem,
};

const PULSE: f64 = 0.02;

struct Cantilever {
    body: Body,
    free: FreeNodes,
    tip: Vec<usize>,
}

/// The cantilever with 10×1×1 elements of `kind`, and its HRZ-lumped masses.
fn cantilever_of(kind: ElementKind) -> (Cantilever, Vec<f64>) {
    let mesh = generator::beam(1.0, 0.02, 0.02, [10, 1, 1], kind).unwrap();
    let material = IsotropicMaterial::STEEL;
    let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
    let lumped = fem::lumped_masses(&mesh, material.density);
    let body = Body::new(
        reference,
        fem::scalar_mass_matrix(&mesh, material.density),
        fem::stiffness_matrix(&mesh, &material),
        lumped.clone(),
        BodyOptions::default(),
    );
    let clamped: Vec<bool> = mesh.nodes().iter().map(|p| p[0].abs() < 1e-9).collect();
    let tip = (0..mesh.node_count())
        .filter(|&i| (mesh.nodes()[i][0] - 1.0).abs() < 1e-9)
        .collect();
    let free = FreeNodes::new(&body, &clamped);
    (Cantilever { body, free, tip }, lumped)
}

fn cantilever() -> Cantilever {
    cantilever_of(ElementKind::Hex20).0
}

impl Cantilever {
    /// A step's problem under `loads`; no node is prescribed but the clamped root, which never
    /// moves.
    fn problem<'a>(&'a self, loads: &'a dyn Fn(&[f64], &mut [f64])) -> StepProblem<'a> {
        StepProblem {
            body: &self.body,
            free: &self.free,
            loads,
            prescribe: &|_t: f64, _s: &mut DynamicState| {},
        }
    }

    /// Mean y of the tip nodes (m).
    fn tip_deflection(&self, x: &[f64]) -> f64 {
        self.tip.iter().map(|&i| x[3 * i + 1]).sum::<f64>() / self.tip.len() as f64
    }
}

fn load(c: &Cantilever, t: f64) -> impl Fn(&[f64], &mut [f64]) + '_ {
    let f = -10.0 * (std::f64::consts::PI * t.min(PULSE) / PULSE).sin().powi(2);
    move |_x: &[f64], out: &mut [f64]| {
        for &i in &c.tip {
            out[3 * i + 1] += f / c.tip.len() as f64;
        }
    }
}

fn initial_state(c: &Cantilever) -> DynamicState {
    let n3 = c.body.reference.len();
    DynamicState {
        time: 0.0,
        position: c.body.reference.clone(),
        velocity: vec![0.0; n3],
        acceleration: vec![0.0; n3],
        pseudo_acceleration: vec![0.0; n3],
        multipliers: vec![],
        step_size: 0.0,
        iteration_error_ratio: f64::INFINITY,
    }
}

/// `steps` steps of `h` under the pulse from rest with consistent accelerations (smooth: the
/// pulse starts with zero load and zero load rate), `each(n, state)` after step `n`; the state
/// at the end.
fn pulse_run(
    c: &Cantilever,
    h: f64,
    rho_inf: f64,
    steps: usize,
    mut each: impl FnMut(usize, &DynamicState),
) -> DynamicState {
    let scheme = GeneralizedAlpha::new(rho_inf);
    let mut matrix = IterationMatrix::new(&c.body, &c.free, &scheme, h, 0.0, 0.0).unwrap();
    let mut ws = StepWorkspace::new(&c.body, &c.free);
    let mut forces = ResidualWorkspace::new(&c.body);
    let mut state = initial_state(c);
    let mut mass = ConsistentAcceleration::new(&c.free).unwrap();
    let (state_ref, forces_ref) = (&mut state, &mut forces);
    initial_acceleration(
        &c.body,
        &c.free,
        &load(c, 0.0),
        state_ref,
        forces_ref,
        &mut mass,
    )
    .unwrap();
    let settings = IterationSettings {
        absolute_tolerance: 1e-14,
        carried_below: 0.0,
        max_iterations: 50,
        estimate_error: None,
    };
    for n in 1..=steps {
        let loads = load(c, n as f64 * h);
        let problem = c.problem(&loads);
        let (state_ref, ws, forces) = (&mut state, &mut ws, &mut forces);
        generalized_alpha::step(&problem, &mut matrix, &settings, h, state_ref, ws, forces)
            .unwrap();
        each(n, &state);
    }
    state
}

/// Mean tip deflection at t = k·H, H = 1 ms, up to 2T, with steps h = H/m.
fn run(c: &Cantilever, m: usize, rho_inf: f64) -> Vec<f64> {
    let h = 1e-3 / m as f64;
    let mut tip = Vec::new();
    let steps = (2.0 * PULSE / h).round() as usize;
    pulse_run(c, h, rho_inf, steps, |n, state| {
        if n % m == 0 {
            tip.push(c.tip_deflection(&state.position));
        }
    });
    tip
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn generalized_alpha_is_second_order() {
    let c = cantilever();
    for rho_inf in [1.0, 0.6] {
        let reference = run(&c, 64, rho_inf);
        let errors: Vec<f64> = [2, 4, 8]
            .iter()
            .map(|&m| largest_difference(&run(&c, m, rho_inf), &reference))
            .collect();
        let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        let shown: Vec<String> = errors.iter().map(|e| format!("{e:.3e}")).collect();
        println!("ρ∞ = {rho_inf}: errors {shown:?} m at h = 0.5, 0.25, 0.125 ms; observed orders {orders:.2?}");
        for p in &orders {
            assert!((1.8..=2.2).contains(p), "ρ∞ = {rho_inf}: order {p:.2}");
        }
    }
}

#[test]
fn a_load_jump_restarts_from_consistent_accelerations() {
    // After `restart_for_load_change`, the residual M ẍ + f − f_ext of the new loads vanishes
    // on the free DOFs, as it did for the old loads before (to the mass solve's round-off).
    let c = cantilever();
    let mut ws = StepWorkspace::new(&c.body, &c.free);
    let mut forces = ResidualWorkspace::new(&c.body);
    let mut state = initial_state(&c);
    let mut mass = ConsistentAcceleration::new(&c.free).unwrap();
    let (old, new) = (load(&c, 0.25 * PULSE), load(&c, 0.5 * PULSE));
    initial_acceleration(&c.body, &c.free, &old, &mut state, &mut forces, &mut mass).unwrap();
    let scale = 10.0;
    let free_residual = |ws: &ResidualWorkspace| {
        let r = last_residual(ws);
        c.free
            .nodes
            .iter()
            .flat_map(|&i| 3 * i..3 * i + 3)
            .fold(0.0_f64, |m, d| m.max(r[d].abs()))
    };
    residual(&c.body, &c.free, &state, &old, &mut forces);
    assert!(free_residual(&forces) < 1e-9 * scale);
    residual(&c.body, &c.free, &state, &new, &mut forces);
    // The jump: 5 N spread over the tip nodes.
    assert!(
        free_residual(&forces) > 0.5 * 5.0 / c.tip.len() as f64,
        "the loads did jump"
    );
    let (state_ref, forces_ref) = (&mut state, &mut forces);
    generalized_alpha::restart_for_load_change(
        &c.free, &mut mass, &old, &new, state_ref, forces_ref, &mut ws,
    );
    residual(&c.body, &c.free, &state, &new, &mut forces);
    assert!(
        free_residual(&forces) < 1e-9 * scale,
        "{:e}",
        free_residual(&forces)
    );
    assert_eq!(state.acceleration, state.pseudo_acceleration);
}

#[test]
fn central_difference_critical_step_matches_the_highest_eigenvalue() {
    // The hex8 mesh: the explicit scheme takes ~1e4 steps here.
    let (c, lumped) = cantilever_of(ElementKind::Hex8);
    let scheme = CentralDifference::new(&c.body, &lumped, &c.free).unwrap();
    // Dense ω_max² = λ_max(M_L^{-1/2} K_FF M_L^{-1/2}).
    let dofs: Vec<usize> = c
        .free
        .nodes
        .iter()
        .flat_map(|&i| 3 * i..3 * i + 3)
        .collect();
    let k = c.body.stiffness_matrix.to_dense();
    let a = nalgebra::DMatrix::from_fn(dofs.len(), dofs.len(), |r, s| {
        let (i, j) = (dofs[r], dofs[s]);
        k[(i, j)] / (lumped[i / 3] * lumped[j / 3]).sqrt()
    });
    let exact = a.symmetric_eigenvalues().max().sqrt();
    let estimate = scheme.highest_frequency;
    println!("ω_max: power iteration {estimate:.6e}, dense {exact:.6e} rad/s");
    assert!(estimate <= exact * (1.0 + 1e-9) && estimate > 0.99 * exact);
}

/// Central difference on the coarse cantilever: tip deflection at every 1 ms up to 2T.
fn run_explicit(c: &Cantilever, scheme: &CentralDifference, h: f64) -> Vec<f64> {
    let mut ws = ResidualWorkspace::new(&c.body);
    let mut state = initial_state(c);
    let per_ms = (1e-3 / h).round() as usize;
    let mut tip = Vec::new();
    for n in 1..=(2.0 * PULSE / 1e-3).round() as usize * per_ms {
        // The explicit scheme evaluates the loads at t_{n+1} as well.
        let loads = load(c, n as f64 * h);
        let problem = c.problem(&loads);
        scheme.step(&problem, h, &mut state, &mut ws).unwrap();
        if n % per_ms == 0 {
            tip.push(c.tip_deflection(&state.position));
        }
    }
    tip
}

#[test]
fn central_difference_is_second_order_and_refuses_an_unstable_step() {
    let (c, lumped) = cantilever_of(ElementKind::Hex8);
    let scheme = CentralDifference::new(&c.body, &lumped, &c.free).unwrap();
    // Steps that divide 1 ms, the largest below the stable step.
    let base = 1e-3 / (1e-3 / scheme.stable_step()).ceil();
    let reference = run_explicit(&c, &scheme, base / 16.0);
    let errors: Vec<f64> = [1.0, 2.0, 4.0]
        .iter()
        .map(|&d| largest_difference(&run_explicit(&c, &scheme, base / d), &reference))
        .collect();
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!(
        "central difference: h = {base:.3e} s (stable {:.3e}), errors {errors:?}, orders {orders:.2?}",
        scheme.stable_step()
    );
    for p in &orders {
        assert!((1.8..=2.2).contains(p), "order {p:.2}");
    }
    // A step above the stable one is refused (Discard), the state untouched.
    let mut ws = ResidualWorkspace::new(&c.body);
    let mut state = initial_state(&c);
    let before = state.clone();
    let loads = load(&c, 0.0);
    let problem = c.problem(&loads);
    let error = scheme
        .step(&problem, 1.01 * scheme.stable_step(), &mut state, &mut ws)
        .unwrap_err();
    assert_eq!(error.kind, flexbody::ErrorKind::Discard);
    assert!(error.message.contains("stable step"), "{}", error.message);
    assert_eq!(state, before);
}

/// The state at `t` after steps of `h` under the pulse.
fn state_at(c: &Cantilever, t: f64, h: f64, rho_inf: f64) -> DynamicState {
    pulse_run(c, h, rho_inf, (t / h).round() as usize, |_, _| {})
}

/// `m` steps of `h / m` from `start`; the error estimate of the last one (m, asked with
/// `enough = 0`: always filtered).
fn steps_from(
    c: &Cantilever,
    start: &DynamicState,
    h: f64,
    m: usize,
    rho_inf: f64,
) -> (DynamicState, f64) {
    let hs = h / m as f64;
    let scheme = GeneralizedAlpha::new(rho_inf);
    let mut matrix = IterationMatrix::new(&c.body, &c.free, &scheme, hs, 0.0, 0.0).unwrap();
    let mut ws = StepWorkspace::new(&c.body, &c.free);
    let mut forces = ResidualWorkspace::new(&c.body);
    let mut state = start.clone();
    // The step from the state as it is: not carried over from the start's own step size
    // (`generalized_alpha::change_step`, which shifts the velocities by `c_v (h'² − h²) ⃛x`, a
    // third-order change of the step's position: with it the coarse step's error is 0.58 of
    // the estimate at h = 4e-4 s, ρ∞ = 0.9).
    state.step_size = 0.0;
    let settings = IterationSettings {
        absolute_tolerance: 1e-14,
        carried_below: 0.0,
        max_iterations: 50,
        estimate_error: Some(0.0),
    };
    let mut estimate = 0.0;
    for n in 1..=m {
        let loads = load(c, start.time + n as f64 * hs);
        let problem = c.problem(&loads);
        let (state, ws, forces) = (&mut state, &mut ws, &mut forces);
        let report =
            generalized_alpha::step(&problem, &mut matrix, &settings, hs, state, ws, forces)
                .unwrap();
        estimate = report.error_estimate.unwrap();
    }
    (state, estimate)
}

/// `√((a − b)ᵀ M (a − b) / m)` (m).
fn mass_weighted_difference(c: &Cantilever, a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let mut md = vec![0.0; d.len()];
    c.body.mass_times(&d, &mut md);
    (flexbody::linalg::dot(&d, &md) / c.body.total_mass).sqrt()
}

#[test]
fn the_local_error_estimate_is_third_order_and_measures_the_step() {
    // From a smooth state in the middle of the pulse, one step of h: the estimate of
    // `IterationMatrix::local_error` (docs/formulation.md, "Time error control") falls like h³
    // (local error of a second-order scheme) and matches the step's true error, measured
    // against 256 steps of h/256 from the same state, within a factor 2 (the estimate is the
    // leading term; measured: within 20 %). With ρ∞ < 1 the pseudo-acceleration of the start
    // state belongs to its own step size (1e-5 s, close to ẍ): the same holds.
    let c = cantilever();
    for rho_inf in [1.0, 0.9] {
        let start = state_at(&c, 0.5 * PULSE, 1e-5, rho_inf);
        let mut estimates = Vec::new();
        for h in [4e-4, 2e-4, 1e-4] {
            let (coarse, estimate) = steps_from(&c, &start, h, 1, rho_inf);
            let (fine, _) = steps_from(&c, &start, h, 256, rho_inf);
            let actual = mass_weighted_difference(&c, &coarse.position, &fine.position);
            println!("ρ∞ = {rho_inf}, h = {h:e}: estimate {estimate:.3e} m, error of the step {actual:.3e} m");
            let ratio = actual / estimate;
            assert!(
                (0.5..=2.0).contains(&ratio),
                "h = {h}: error / estimate = {ratio:.3}"
            );
            estimates.push(estimate);
        }
        for w in estimates.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!(
                (2.7..=3.3).contains(&order),
                "ρ∞ = {rho_inf}: order {order:.2}"
            );
        }
    }
}
