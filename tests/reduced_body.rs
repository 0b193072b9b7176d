//! The reduced body (`model.modes`, `body::reduction`) against the full mesh: B1's static
//! deflection and bending frequencies and a second boundary set moved rigidly (library level), the
//! step response through the slave, a rotating motion interface, a free tumbling body, the FMU
//! state and the parameter checks.

mod common;
use common::reduced_b1::B1;
use common::*;
use flexbody::body::{InterfaceSets, ModeCount, Reduction};
use flexbody::fem::modal::lowest_eigenpairs;
use flexbody::fem::{scalar_mass_matrix, stiffness_matrix, IsotropicMaterial};
use flexbody::linalg::SparseCholesky;
use flexbody::linalg::SymmetricCsr;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::{DMatrix, DVector, Rotation3, Vector3};

/// The full mesh's static displacement: `u` as given off the `free` DOFs, on them
/// `K_ff u_f = f_f − (K u)_f` for the nodal loads `load`.
fn static_displacement(
    k: &SymmetricCsr,
    free: &[usize],
    load: &[f64],
    mut u: Vec<f64>,
) -> Vec<f64> {
    let mut k_u = vec![0.0; u.len()];
    k.mul_vec(&u, &mut k_u);
    let mut u_free: Vec<f64> = free.iter().map(|&d| load[d] - k_u[d]).collect();
    let factor = SparseCholesky::new(&k.submatrix(free)).unwrap();
    factor.solve_in_place(&mut u_free, &mut factor.solve_scratch());
    for (&d, &v) in free.iter().zip(&u_free) {
        u[d] = v;
    }
    u
}

/// The coordinates (flat `3s` indices) not held by the first `sets` boundary sets.
fn free_coordinates(reduction: &Reduction, sets: usize) -> Vec<usize> {
    let held: Vec<usize> = reduction.held[..sets]
        .iter()
        .flatten()
        .map(|h| h.index)
        .collect();
    (0..reduction.field_count)
        .filter(|k| !held.contains(k))
        .flat_map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect()
}

/// The reduced body's static displacement of the mesh nodes under the reduced load `f` (flat
/// `3s`) with the coordinates of boundary set 0 held: `K_ff q_f = f_f` on the others, `q`
/// expanded to the nodes. Also `K_ff` and `M_ff` and the free coordinates' count.
fn reduced_static_displacement(
    reduction: &Reduction,
    f: &[f64],
) -> (Vec<f64>, DMatrix<f64>, DMatrix<f64>, usize) {
    let coordinates = free_coordinates(reduction, 1);
    let n = coordinates.len();
    let k_r = reduction.stiffness_matrix.to_dense();
    let m_r = reduction.mass_matrix.kron_i3().to_dense();
    let k_ff = DMatrix::from_fn(n, n, |a, b| k_r[(coordinates[a], coordinates[b])]);
    let m_ff = DMatrix::from_fn(n, n, |a, b| m_r[(coordinates[a], coordinates[b])]);
    let f_free = DVector::from_fn(n, |a, _| f[coordinates[a]]);
    let q_free = k_ff.clone().cholesky().unwrap().solve(&f_free);
    let mut q = vec![0.0; 3 * reduction.field_count];
    for (a, &c) in coordinates.iter().enumerate() {
        q[c] = q_free[a];
    }
    (reduction.expand(&q), k_ff, m_ff, n)
}

/// The generalized eigenvalues `K v = λ M v` of dense symmetric `K`, `M` (M positive definite),
/// ascending.
fn generalized_eigenvalues(k: &DMatrix<f64>, m: &DMatrix<f64>) -> Vec<f64> {
    // As 1/μ of L⁻¹ M L⁻ᵀ, K = L Lᵀ: the symmetric eigensolver's error is ~ε of the largest
    // eigenvalue, which is then the lowest λ's 1/λ₁ (through M's factor instead it is ε λ_max,
    // 1.7e-7 of λ₁ for B1 with 4 modes: λ_max/λ₁ = 7.5e8).
    let l = k.clone().cholesky().unwrap().unpack();
    let li = l.clone().try_inverse().unwrap();
    let a = &li * m * li.transpose();
    let a = 0.5 * (&a + a.transpose());
    let mut values: Vec<f64> = a
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .map(|mu| 1.0 / mu)
        .collect();
    values.sort_by(f64::total_cmp);
    values
}

fn hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// B1's static deflection and its lowest bending frequencies, reduced (`modes = 4`) against the
/// full mesh. Both are exact in theory, so the tolerances are round-off-level, far inside the
/// issue's 0.5 %:
/// * the static response to the tip load is the tip set's attachment mode, which is in the
///   basis; the only loss is the Gram–Schmidt cutoff (`DEPENDENCE_CUTOFF` = 1e-9 of a field), so
///   1e-5 relative;
/// * with the whole boundary clamped, the fixed-interface modes are B1's modes, so the 4 kept
///   are exact to the subspace iteration's 1e-9 (the Ritz value error is quadratic in the shape
///   error): 1e-7 relative. The next two (f5, f6, torsion/axial or the third bending pair) are
///   Rayleigh–Ritz upper bounds of the full mesh's.
#[test]
fn b1_static_deflection_and_bending_frequencies_match_the_full_mesh() {
    let mut b1 = B1::new();
    let (k, ms, reduction) = b1.reduced(&[&b1.root], &[&b1.tip], 4);

    // Full mesh.
    let free = b1.free_dofs();
    let mut load = vec![0.0; b1.reference.len()];
    b1.tip.distribute(
        &b1.reference,
        &Vector3::new(0.0, -10.0, 0.0),
        &Vector3::zeros(),
        &mut load,
    );
    let u = static_displacement(&k, &free, &load, vec![0.0; b1.reference.len()]);
    let full_deflection = b1.tip_deflection(&u);
    let full_modes = lowest_eigenpairs(
        &k.submatrix(&free),
        &ms.kron_i3().submatrix(&free),
        6,
        1e-12,
        500,
    )
    .unwrap();

    // Reduced body: the root's held coordinates are clamped, the rest is free.
    b1.tip.set_reduction(Some((reduction.basis(), Vec::new())));
    let mut f = vec![0.0; 3 * reduction.field_count];
    b1.tip.distribute(
        &reduction.reference,
        &Vector3::new(0.0, -10.0, 0.0),
        &Vector3::zeros(),
        &mut f,
    );
    let (u_reduced, k_ff, m_ff, n) = reduced_static_displacement(&reduction, &f);
    let reduced_deflection = b1.tip_deflection(&u_reduced);
    let reduced_eigenvalues = generalized_eigenvalues(&k_ff, &m_ff);

    let static_error = (reduced_deflection / full_deflection - 1.0).abs();
    println!(
        "static tip deflection: full {full_deflection:.9e} m, reduced ({} fields, {n} free coordinates) {reduced_deflection:.9e} m, relative difference {static_error:.2e}",
        reduction.field_count
    );
    assert!(static_error < 1e-5, "{static_error:e}");
    for (j, (&full, &reduced)) in full_modes
        .eigenvalues
        .iter()
        .zip(&reduced_eigenvalues)
        .enumerate()
    {
        let error = reduced / full - 1.0;
        println!(
            "f{}: full {:.6} Hz, reduced {:.6} Hz ({:+.2e})",
            j + 1,
            hz(full),
            hz(reduced),
            error
        );
        if j < 4 {
            assert!(error.abs() < 1e-7, "f{}: {error:e}", j + 1);
        } else {
            assert!(error > -1e-9, "f{} below the full mesh's: {error:e}", j + 1);
        }
    }
}

/// `model.modes = auto` (`ModeCount::Accuracy`, docs/formulation.md "How many modes"): the
/// reduced body's static response to B1's uniform inertial load (gravity, a translational
/// acceleration: the load no interface carries) is within the accuracy asked of the full
/// mesh's, in the mass norm; one mode fewer would not have been, and a tighter accuracy takes
/// more modes. The bound is the choice's own criterion (the fixed-interface modes' truncation
/// error); the reduced body also holds the attachment modes, and its Galerkin solution is the
/// best in the energy norm, so the measured error lands at or below the predicted one.
#[test]
fn auto_mode_count_meets_the_accuracy_on_the_inertial_load() {
    let b1 = B1::new();
    let material = IsotropicMaterial::STEEL;
    let k = stiffness_matrix(&b1.mesh, &material);
    let ms = scalar_mass_matrix(&b1.mesh, material.density);
    let m3 = ms.kron_i3();
    let n3 = b1.reference.len();
    // Gravity in −y: f = M g.
    let mut g = vec![0.0; n3];
    for i in 0..n3 / 3 {
        g[3 * i + 1] = -9.81;
    }
    let mut load = vec![0.0; n3];
    m3.mul_vec(&g, &mut load);
    let full = static_displacement(&k, &b1.free_dofs(), &load, vec![0.0; n3]);
    let mass_norm = |u: &[f64]| {
        let mut mu = vec![0.0; u.len()];
        m3.mul_vec(u, &mut mu);
        flexbody::linalg::dot(u, &mu).sqrt()
    };
    let mut counts = Vec::new();
    for accuracy in [1e-2, 1e-3, 1e-4] {
        let reduction = Reduction::new(
            &b1.mesh_data(&ms, &k),
            &InterfaceSets {
                held: &[&b1.root],
                rigid: &[],
                loaded: &[&b1.tip],
            },
            ModeCount::Accuracy(accuracy),
        )
        .unwrap();
        let choice = reduction.mode_choice.unwrap();
        assert!(choice.met(), "{choice:?}");
        assert!(choice.error_one_fewer > accuracy, "{choice:?}");
        // The reduced static solution: K_ff q = Ψᵀ f on the coordinates the root does not hold.
        let s = reduction.field_count;
        let mut f = vec![0.0; 3 * s];
        for i in 0..reduction.node_count {
            for (field, &value) in reduction.fields[i * s..(i + 1) * s].iter().enumerate() {
                for d in 0..3 {
                    f[3 * field + d] += value * load[3 * i + d];
                }
            }
        }
        let reduced = reduced_static_displacement(&reduction, &f).0;
        let difference: Vec<f64> = reduced.iter().zip(&full).map(|(a, b)| a - b).collect();
        let error = mass_norm(&difference) / mass_norm(&full);
        println!(
            "accuracy {accuracy:e}: {} modes (predicted {:.2e}, {:.2e} with one fewer), {} fields; static error under gravity {error:.2e}, tip {:.3e} m against {:.3e} m",
            choice.count,
            choice.error,
            choice.error_one_fewer,
            s,
            b1.tip_deflection(&reduced),
            b1.tip_deflection(&full)
        );
        assert!(error <= accuracy, "{error:e} > {accuracy:e}");
        counts.push(choice.count);
    }
    assert!(counts.windows(2).all(|w| w[0] < w[1]), "{counts:?}");
}

/// `"modes": "auto"` in a body file, on a free body (`examples/tumbling.json`, free-free modes
/// with inertia relief) and on B3's beam driven by its hub (`examples/hub_beam.json`, a motion
/// interface): the choice is logged, meets the default accuracy, and the body steps.
#[test]
fn auto_mode_count_is_chosen_and_logged_for_free_and_driven_bodies() {
    for name in ["tumbling", "hub_beam"] {
        let path = format!("{}/examples/{name}.json", env!("CARGO_MANIFEST_DIR"));
        let mut json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let model = json
            .as_object_mut()
            .unwrap()
            .entry("model")
            .or_insert(serde_json::json!({}));
        model["modes"] = serde_json::json!("auto");
        let body = BodyFile::from_json(&json.to_string()).unwrap();
        let mut s = initialized(body, &[]);
        for k in 0..10 {
            s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
        }
        let modes = s
            .variables()
            .by_name("model.modes")
            .unwrap()
            .value_reference;
        assert_eq!(s.get_integer(modes).unwrap(), -1);
        let messages: Vec<String> = s.drain_events().map(|e| e.message).collect();
        let choice = messages
            .iter()
            .find(|m| m.contains("model.modes = auto"))
            .unwrap_or_else(|| panic!("{name}: no choice logged in {messages:?}"));
        println!("{name}: {choice}");
        assert!(!choice.contains("warning"), "{name}: {choice}");
    }
}

/// Tip deflection history (relative to the start) of the step response of B1 (10 N at t = 0,
/// undamped, ρ∞ = 1, h = 1e-4 s) over 30 ms (half a period of f1), and the wall time.
fn step_response(modes: f64) -> (Vec<f64>, f64) {
    let h = 1e-4;
    let mut s = initialized_default(&[
        ("model.modes", modes),
        ("tip.force[2]", -10.0),
        ("solver.stepSize", h),
        ("solver.rhoInf", 1.0),
    ]);
    let y0 = get(&mut s, "tip.position[2]");
    let started = std::time::Instant::now();
    let history = (0..300)
        .map(|k| {
            s.do_step(k as f64 * h, h).unwrap();
            get(&mut s, "tip.position[2]") - y0
        })
        .collect();
    (history, started.elapsed().as_secs_f64())
}

/// Two boundary sets: B1's root clamped and its tip face moved rigidly (a translation and a
/// rotation about its reference point), static, reduced (2 modes) against the full mesh with the
/// same motion prescribed on the tip face. The second set's constraint modes are the static
/// responses to its affine motions with the root held, so the reduced field is the full mesh's up
/// to the Gram–Schmidt cutoff (1e-9 of a field): asserted to 1e-7 of the largest displacement.
/// The tip face itself follows the prescribed motion exactly (its held coordinates).
#[test]
fn a_second_boundary_set_moves_the_reduced_body_as_it_moves_the_full_mesh() {
    let b1 = B1::new();
    let (k, _, reduction) = b1.reduced(&[&b1.root, &b1.tip], &[], 2);
    let position = |x: &[f64], i: usize| Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    let translation = Vector3::new(2e-4, 1e-3, -5e-4);
    let rotation = Rotation3::from_axis_angle(&Vector3::z_axis(), 1e-3).into_inner();
    let p_ref = b1.tip.reference_point;
    let moved = |x: Vector3<f64>| p_ref + translation + rotation * (x - p_ref);

    // Full mesh: u on the tip face prescribed, K_ff u_f = −K_fh u_h.
    let n3 = b1.reference.len();
    let tip_nodes = &b1.tip.frame_weights.nodes;
    let mut u_held = vec![0.0; n3];
    for &i in tip_nodes {
        let x = position(&b1.reference, i);
        let u = moved(x) - x;
        u_held[3 * i..3 * i + 3].copy_from_slice(u.as_slice());
    }
    let free: Vec<usize> = b1
        .free_dofs()
        .into_iter()
        .filter(|d| !tip_nodes.contains(&(d / 3)))
        .collect();
    let u_full = static_displacement(&k, &free, &vec![0.0; n3], u_held);

    // Reduced: the tip's held coordinates q = p + Q d (a point) or Q d (a direction).
    let mut dq = vec![0.0; 3 * reduction.field_count];
    for h in &reduction.held[1] {
        let q = if h.point {
            p_ref + translation + rotation * h.offset
        } else {
            rotation * h.offset
        };
        let dq_h = q - position(&reduction.reference, h.index);
        dq[3 * h.index..3 * h.index + 3].copy_from_slice(dq_h.as_slice());
    }
    let coordinates = free_coordinates(&reduction, reduction.held.len());
    let n = coordinates.len();
    let k_r = reduction.stiffness_matrix.to_dense();
    let k_dq = &k_r * DVector::from_column_slice(&dq);
    let k_ff = DMatrix::from_fn(n, n, |a, b| k_r[(coordinates[a], coordinates[b])]);
    let rhs = DVector::from_fn(n, |a, _| -k_dq[coordinates[a]]);
    let dq_free = k_ff.cholesky().unwrap().solve(&rhs);
    let mut q = reduction.reference.clone();
    for (k, v) in q.iter_mut().enumerate() {
        *v += dq[k];
    }
    for (a, &c) in coordinates.iter().enumerate() {
        q[c] += dq_free[a];
    }
    let x = reduction.expand(&q);

    let largest = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut difference: f64 = 0.0;
    for i in 0..b1.mesh.node_count() {
        let u = position(&x, i) - position(&b1.reference, i);
        difference = difference.max((u - position(&u_full, i)).amax());
    }
    let tip_error = tip_nodes
        .iter()
        .map(|&i| (position(&x, i) - moved(position(&b1.reference, i))).amax())
        .fold(0.0, f64::max);
    println!(
        "two boundary sets ({} fields): largest difference from the full mesh {:.2e} of the largest displacement {largest:.3e} m; tip face off its motion by {tip_error:.2e} m",
        reduction.field_count,
        difference / largest
    );
    assert!(difference < 1e-7 * largest, "{:e}", difference / largest);
    assert!(tip_error < 1e-12, "{tip_error:e}");
}

/// The step response through the whole slave converges to the full mesh's as modes are added:
/// the truncated modes (above f_{n+1}) keep their static part through the attachment modes and
/// lose only their dynamic part, which shrinks with f_{n+1}. With 8 modes (f9 ≈ 900 Hz) the
/// largest deviation over the first half period is within the 0.5 % of the peak
/// deflection, and below a tenth of the deviation with 2 modes.
#[test]
fn step_response_converges_to_the_full_mesh_with_the_number_of_modes() {
    let (full, full_time) = step_response(0.0);
    let peak = full.iter().fold(0.0_f64, |m, y| m.max(y.abs()));
    let deviation = |modes: f64| {
        let (reduced, time) = step_response(modes);
        let worst = reduced
            .iter()
            .zip(&full)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
            / peak;
        println!(
            "modes {modes}: largest deviation {:.3e} of the peak {peak:.4e} m; {:.3} s against the full mesh's {full_time:.3} s",
            worst, time
        );
        worst
    };
    let coarse = deviation(2.0);
    let fine = deviation(8.0);
    assert!(fine < 5e-3, "{fine:e}");
    assert!(fine < 0.1 * coarse, "{fine:e} vs {coarse:e}");
    // model.modes = auto with the default model.accuracy (1e-2) takes 4 modes
    // (auto_mode_count_meets_the_accuracy_on_the_inertial_load) and stays within that accuracy.
    let auto = deviation(-1.0);
    assert!(auto < 1e-2, "{auto:e}");
}

/// B4 on the reduced body: the root is a motion interface turning about z at π rad/s for three
/// turns, the tip load turning with it; the tip deflection in the root frame stays at the
/// full mesh's clamped static value within 0.5 % (as `tests/motion_interface.rs` asks of the
/// full mesh). A motion interface holds its set's affine coordinates, so the driven reduced body
/// sees the same clamp as a fixed support.
#[test]
fn b4_reduced_body_driven_by_a_rotating_motion_interface() {
    let omega = std::f64::consts::PI;
    let h: f64 = 1e-3;
    let body = example_body("driven_cantilever");
    let mut s = initialized(
        body,
        &[
            ("model.modes", 6.0),
            ("damping.beta", 2e-3),
            ("tip.force[2]", -10.0),
            ("root.angularVelocity[3]", omega),
        ],
    );
    let worst = b4_deviation_from_static(&mut s, h, omega);
    println!(
        "largest deviation from the static deflection: {:.3e}",
        worst
    );
    assert!(worst < 5e-3, "{:.3} %", 100.0 * worst);
    // Steady turning: the driving frame's load and the tip load give the centre of mass its
    // centripetal acceleration, F_root + F_tip = m (−ω² r) with r the centre of mass from the
    // axis (the start-up transient has decayed by e^{-60}; the scheme's error in ω² r is
    // O((ωh)²) = 1e-5): 1e-4 of the ~18 N.
    // The tip load is held over each step: the last one was set at t = 6 s − h.
    let q_last = *Rotation3::from_axis_angle(&Vector3::z_axis(), omega * (6.0 - h)).matrix();
    let tip_load = q_last * Vector3::new(0.0, -10.0, 0.0);
    let r = vector(&mut s, "body.position") - vector(&mut s, "root.position");
    let mass = 7850.0 * 0.02 * 0.02 * 1.0;
    let expected = -mass * omega * omega * Vector3::new(r.x, r.y, 0.0) - tip_load;
    let f = vector(&mut s, "root.force");
    println!("root.force {f:?}, expected {expected:?}");
    assert!(
        (f - expected).norm() < 1e-4 * expected.norm(),
        "root.force {f:?}, expected {expected:?}"
    );
}

/// Largest relative change of the angular momentum over 0.5 s of B2's tumbling beam (softened
/// to E = 2.1e8 Pa, ω = (0.5, 3, 7) rad/s about the centre of mass, f_nl on) reduced to 8
/// free-free modes, and the largest linear momentum relative to m |ω| L/2.
fn tumbling_drift(h: f64) -> (f64, f64) {
    let w = Vector3::new(0.5, 3.0, 7.0);
    let v = -w.cross(&Vector3::new(0.5, 0.0, 0.0));
    let mut s = initialized(
        example_body("tumbling"),
        &[
            ("model.modes", 8.0),
            ("initial.angularVelocity[1]", w.x),
            ("initial.angularVelocity[2]", w.y),
            ("initial.angularVelocity[3]", w.z),
            ("initial.velocity[1]", v.x),
            ("initial.velocity[2]", v.y),
            ("initial.velocity[3]", v.z),
            ("solver.stepSize", h),
            // The drift's order in h is measured with the fixed step.
            ("model.accuracy", 0.0),
            ("material.youngsModulus", 2.1e8),
        ],
    );
    let l0 = vector(&mut s, "body.angularMomentum");
    let (mut worst_l, mut worst_p) = (0.0_f64, 0.0_f64);
    for k in 0..(0.5 / h).round() as usize {
        s.do_step(k as f64 * h, h).unwrap();
        let l = vector(&mut s, "body.angularMomentum");
        let p = vector(&mut s, "body.linearMomentum");
        worst_l = worst_l.max((l - l0).norm() / l0.norm());
        worst_p = worst_p.max(p.norm() / (7850.0 * 0.02 * 0.02 * 7.6 * 0.5));
    }
    (worst_l, worst_p)
}

/// A free reduced body keeps the full mesh's conservation properties (B2, as
/// `tests/free_body.rs` shows them for the mesh): the affine fields hold every rigid motion
/// exactly and the projected f_nl is still the gradient of the projected energy, so the linear
/// momentum is conserved to round-off and the angular momentum to the trapezoidal rule's own
/// truncation error, which falls as h² (ratio 4 per halving, ±10 %).
#[test]
fn free_reduced_body_conserves_momentum() {
    let (coarse, p_coarse) = tumbling_drift(1e-3);
    let (fine, p_fine) = tumbling_drift(5e-4);
    println!("angular momentum drift {coarse:e} (h = 1e-3), {fine:e} (h = 5e-4); linear {p_coarse:e} {p_fine:e}");
    assert!(
        p_coarse < 1e-12 && p_fine < 1e-12,
        "linear momentum {p_coarse:e} {p_fine:e}"
    );
    let ratio = coarse / fine;
    assert!((3.6..4.4).contains(&ratio), "ratio {ratio}");
}

/// `fmi2GetFMUstate`/`fmi2SetFMUstate` and the byte form carry the reduced body's coordinates:
/// restoring the state reproduces the later steps bit for bit. The parameters are part of the
/// state, so a full-mesh state restored into an instance running reduced switches it back to the
/// full mesh (interfaces included) and reproduces the full mesh's steps, and back again.
#[test]
fn fmu_state_of_a_reduced_body_round_trips() {
    fn bytes(s: &Slave) -> Vec<u8> {
        let mut out = Vec::new();
        s.get_state().write_bytes(&mut out);
        out
    }
    fn restore(s: &mut Slave, bytes: &[u8]) {
        let state = s.state_from_bytes(bytes).unwrap();
        s.set_state(&state).unwrap();
    }
    fn run(s: &mut Slave) -> Vec<f64> {
        (5..10)
            .map(|k| {
                s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
                get(s, "tip.position[2]")
            })
            .collect()
    }
    let mut full = initialized_default(&[("tip.force[2]", -10.0)]);
    let mut s = initialized_default(&[("model.modes", 4.0), ("tip.force[2]", -10.0)]);
    for k in 0..5 {
        s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
        full.do_step(k as f64 * 1e-3, 1e-3).unwrap();
    }
    let reduced_state = bytes(&s);
    let full_state = bytes(&full);
    let reduced_run = run(&mut s);
    let full_run = run(&mut full);
    assert_ne!(reduced_run, full_run);
    restore(&mut s, &reduced_state);
    assert_eq!(run(&mut s), reduced_run);
    restore(&mut s, &full_state);
    assert_eq!(run(&mut s), full_run);
    restore(&mut s, &reduced_state);
    assert_eq!(run(&mut s), reduced_run);
}

/// Combinations the reduced body does not support are errors that name `model.modes` and say
/// why, at initialization.
#[test]
fn unsupported_combinations_are_errors_naming_the_parameter() {
    for (setting, value, reason) in [
        ("model.formulation", 2.0, "full"),
        // Inertial stiffening takes the driving motion of a motion interface; B1 has none.
        ("model.stiffening", 2.0, "motion interface"),
        ("model.stiffening", 3.0, "stress"),
        ("solver.integrator", 2.0, "centralDifference"),
    ] {
        let mut s = Slave::from_body(BodyFile::default_body()).unwrap();
        s.setup_experiment(0.0, None, None).unwrap();
        s.enter_initialization_mode().unwrap();
        set(&mut s, "model.modes", 4.0);
        set(&mut s, setting, value);
        let e = s.exit_initialization_mode().unwrap_err();
        assert!(
            e.message.contains("model.modes") && e.message.contains(reason),
            "{setting}: {e}"
        );
    }
    let mut body = BodyFile::default_body();
    body.interfaces[0].kind = flexbody::model::InterfaceKind::Pin;
    let mut s = Slave::from_body(body).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.modes", 4.0);
    let e = s.exit_initialization_mode().unwrap_err();
    assert!(
        e.message.contains("'root'") && e.message.contains("Pin"),
        "{e}"
    );
    // Inertial stiffening with several frames: the error does not send a reduced body to
    // `stress`, which it has not either.
    let mut s = Slave::from_body(BodyFile::default_body()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    for (name, value) in [
        ("model.modes", 4.0),
        ("model.frames", 2.0),
        ("model.stiffening", 2.0),
    ] {
        set(&mut s, name, value);
    }
    let e = s.exit_initialization_mode().unwrap_err();
    assert!(
        e.message.contains("model.frames = 2")
            && e.message.contains("no stiffening")
            && !e.message.contains("use model.stiffening = stress"),
        "{e}"
    );
    // Too many modes for the mesh.
    let mut s = Slave::from_body(BodyFile::default_body()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.modes", 1e6);
    let e = s.exit_initialization_mode().unwrap_err();
    assert!(e.message.contains("model.modes"), "{e}");
    assert!(s.set_by_name("model.modes", -2.0).is_err());
    assert!(s.set_by_name("model.modes", -1.0).is_ok()); // auto
}

/// Issue 17's B1 check of a reduced body with several frames: B1 (reduced to 4 modes) under
/// 10 N, settled by heavy damping, settles where the full mesh with the same frames does, one
/// frame or five slabs, within the 1e-6 (f1–f4 are held by
/// `b1_static_deflection_and_bending_frequencies_match_the_full_mesh`: the slabs' linearisation
/// at the reference is the same `K` and `M`). Measured: one frame 2.1e-10, five slabs 9.7e-8
/// (with `f_nl`, whose second order the modal derivatives take too: 9.7e-8).
/// The five slabs' part is the slab model's own nonlinearity (the mesh's five slabs differ from
/// its one frame by 8.8e-7 at 10 N): the basis holds it through the modal derivatives
/// (docs/formulation.md, "The reduced body"). Without them the reduced slabs were stiffer by
/// 5.2e-6, growing with the load's square (5.0e-4 at 100 N): the slabs' turning strained the
/// body along its axis, a locking of the basis.
#[test]
fn a_reduced_b1_with_slabs_settles_where_the_mesh_with_slabs_does() {
    let settled = |modes: f64, frames: f64, nonlinear_forces: f64| {
        let h = 1e-3;
        let mut s = initialized_default(&[
            ("model.modes", modes),
            ("model.frames", frames),
            ("model.nonlinearForces", nonlinear_forces),
            ("model.accuracy", 0.0),
            ("model.auto", 0.0),
            ("damping.beta", 2e-2),
            ("tip.force[2]", -10.0),
        ]);
        let y0 = get(&mut s, "tip.position[2]");
        for k in 0..600 {
            s.do_step(k as f64 * h, h).unwrap();
        }
        get(&mut s, "tip.position[2]") - y0
    };
    for (frames, nonlinear_forces) in [(1.0, 0.0), (5.0, 0.0), (5.0, 1.0)] {
        let reduced = settled(4.0, frames, nonlinear_forces);
        let mesh = settled(0.0, frames, nonlinear_forces);
        let error = (reduced / mesh - 1.0).abs();
        println!("{frames} frames, f_nl {nonlinear_forces}: settled tip deflection reduced {reduced:.9e} m, mesh {mesh:.9e} m ({error:.2e})");
        assert!(
            error < 1e-6,
            "{frames} frames, f_nl {nonlinear_forces}: {error:e}"
        );
    }
}
