//! Rigid attachments on the reduced body (`model.modes`, docs/formulation.md "Rigid
//! attachments", on the reduced body): the set is a boundary set of the basis whose barycentric
//! points the rigid-set constraint holds; lumped bodies, pins and hinges on it.

mod common;
use common::rigid::*;
use common::*;

/// The same on a reduced body (`model.modes = 4`): the hub face is the basis's boundary set and
/// the hub's mass points ride on its barycentric fields (body::reduction), so the rigid motion's
/// kinetic energy and momentum are exact there too.
#[test]
fn a_lumped_hub_adds_its_inertia_exactly_to_a_reduced_body() {
    lumped_hub_inertia(&[("model.modes", 4.0)]);
}

/// The same cantilever as a reduced body (`model.modes`): the rigid tip face is a boundary set
/// of the Craig–Bampton basis whose barycentric coordinates the rigid-set constraint holds, and
/// the tip body's mass points ride on it (body::reduction). Its period converges to the mesh
/// body's as modes are added.
#[test]
fn a_reduced_cantilever_with_a_rigid_tip_mass_has_the_mesh_bodys_frequency() {
    let period = tip_body_period(TIP_ALPHA, TIP_KAPPA);
    let (mesh, _) = measured_period(cantilever_with_tip_body(), &[], period);
    let mut errors = Vec::new();
    for modes in [1.0, 2.0, 4.0] {
        let (reduced, periods) = measured_period(
            cantilever_with_tip_body(),
            &[("model.modes", modes)],
            period,
        );
        let error = (reduced / mesh - 1.0).abs();
        println!("{modes} modes: {reduced:.9e} s against the mesh body's {mesh:.9e} s ({:+.2e}) over {periods} periods", reduced / mesh - 1.0);
        errors.push((reduced, error));
    }
    // Rayleigh–Ritz: a subspace of the mesh's coordinates is stiffer, its period shorter.
    assert!(errors[0].0 < mesh, "{errors:?}");
    // Measured: 9.3e-6 with one and two modes, 3.7e-7 with four (the crossings' own scatter
    // is about 1e-7 of the period: the same steps on both bodies).
    assert!(
        errors[2].1 < 1e-6 && errors[2].1 < errors[0].1 / 10.0,
        "{errors:?}"
    );
    assert!(
        (mesh - period).abs() < 5e-3 * period,
        "{mesh} s against {period} s"
    );
}

/// The largest distance of `set`'s nodes from the set's best rigid motion at each of `steps`
/// steps of 0.1 ms under a 100 N transverse tip load (12 mm static deflection), for the
/// cantilever with `tip` = its tip face as a reduced body with four modes.
fn reduced_tip_face_shape(rigid: bool, steps: usize) -> f64 {
    let mut body = cantilever_with_tip_body();
    if !rigid {
        let tip = body
            .interfaces
            .iter_mut()
            .find(|i| i.name == "tip")
            .unwrap();
        (tip.rigid, tip.mass, tip.inertia) = (false, None, None);
    }
    let mut s = initialized(body, &[("model.modes", 4.0), ("model.accuracy", 0.0)]);
    set(&mut s, "tip.force[2]", -100.0);
    let reduction = s.body().unwrap().reduction.clone().unwrap();
    let face: Vec<usize> = (0..reduction.node_count)
        .filter(|&i| (reduction.mesh_reference[3 * i] - 1.0).abs() < 1e-12)
        .collect();
    let mut worst: f64 = 0.0;
    for k in 0..steps {
        s.do_step(k as f64 * 1e-4, 1e-4).unwrap();
        let x = reduction.expand(&s.dynamic_state().unwrap().position);
        worst = worst.max(distance_from_rigid(&reduction.mesh_reference, &x, &face));
    }
    worst
}

/// A rigid face of a reduced body keeps its shape exactly: the expanded nodes of the tip face
/// stay within 1e-10 m of the face's rigid motion (the iteration's tolerance is 1e-12 m); the
/// same face not rigid deforms by far more (Poisson's contraction of the bending strain).
#[test]
fn a_rigid_face_of_a_reduced_body_keeps_its_shape() {
    let rigid = reduced_tip_face_shape(true, 100);
    let elastic = reduced_tip_face_shape(false, 100);
    println!("tip face: {rigid:.3e} m from rigid (rigid), {elastic:.3e} m (not rigid)");
    assert!(rigid < 1e-10, "{rigid} m");
    assert!(elastic > 1e3 * rigid.max(1e-13), "{elastic} m");
}

/// The same on a reduced body (`model.modes = 4`): the hub face is a boundary set of the basis,
/// the hinge holds its centroid (a point of its barycentric fields) and locks its points'
/// rotation to the axis (body::reduction).
#[test]
fn a_hinge_on_a_rigid_set_of_a_reduced_body_locks_it_to_its_axis() {
    hinge_on_a_rigid_set(&[("model.modes", 4.0)]);
}

/// The flexible arm (`examples/controlled_arm.json`: a hinge and a rigid 50 kg hub on the root
/// face of Kane's beam) under a 1 N m hub torque for 1 s, every 10 ms: the tip's deflection in
/// the hub's frame (m; peak 3.1 mm, a linear response).
fn arm_tip_deflection(settings: &[(&str, f64)]) -> Vec<f64> {
    let mut all = vec![("hub.torque[3]", 1.0), ("model.accuracy", 0.0)];
    all.extend_from_slice(settings);
    let mut s = initialized(arm_with_hub_on_the_hinge_face(1.0), &all);
    let h = 1e-2;
    (0..100)
        .map(|k| {
            s.do_step(k as f64 * h, h).unwrap();
            let q = nalgebra::Matrix3::from_fn(|i, j| {
                get(&mut s, &format!("hub.rotation[{}]", 3 * i + j + 1))
            });
            let tip = vector(&mut s, "tip.position") - vector(&mut s, "hub.position");
            (q.transpose() * tip).y
        })
        .collect()
}

/// The flexible arm as a reduced body follows the mesh body as modes are added (the same
/// internal steps): the hub's rigid set and the hinge on it are exact in both, so what differs
/// is the basis's truncation of the beam's inertial load, which falls with the modes taken.
/// Measured: 3.8e-5 of the peak with 8 modes, 1.7e-6 with 32. (Under 100 N m, 0.30 m of
/// deflection, the two differ by 6.4e-2, 1.4e-2 and 2.5e-3 of the peak with 8, 32 and 128
/// modes: docs/formulation.md, "The reduced body".)
#[test]
fn a_reduced_arm_with_a_rigid_hub_on_a_hinge_follows_the_mesh_body() {
    let mesh = arm_tip_deflection(&[]);
    let peak = mesh.iter().fold(0.0, |a: f64, &b| a.max(b.abs()));
    let errors: Vec<f64> = [8.0, 32.0]
        .iter()
        .map(|&modes| {
            let reduced = arm_tip_deflection(&[("model.modes", modes)]);
            let error = largest_difference(&reduced, &mesh) / peak;
            println!("{modes} modes: {error:.3e} of the peak deflection {peak:.4e} m");
            error
        })
        .collect();
    assert!(errors[0] < 1e-3 && errors[1] < 1e-5, "{errors:?}");
    assert!(errors[1] < errors[0] / 10.0, "{errors:?}");
}

/// The same with the arm as a reduced body (its hub's barycentric fields and their multipliers
/// in the state).
#[test]
fn a_saved_reduced_body_with_rigid_sets_continues_bit_for_bit() {
    saved_arm_continues(&[("model.modes", 4.0)]);
}

/// The lowest period `T₁` that `model.accuracy` works with, from the log (s).
fn logged_first_period(settings: &[(&str, f64)]) -> f64 {
    let mut s = flexbody::slave::Slave::from_body(cantilever_with_tip_body()).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    for &(name, value) in settings {
        set(&mut s, name, value);
    }
    s.exit_initialization_mode().unwrap();
    let message = s
        .drain_events()
        .find(|e| e.message.contains("T₁ = "))
        .unwrap()
        .message;
    let after = &message[message.find("T₁ = ").unwrap() + "T₁ = ".len()..];
    after[..after.find(' ').unwrap()].parse().unwrap()
}

/// The modal analysis behind `model.accuracy` holds a reduced body's rigid sets exactly (their
/// points replaced by their six rigid motions, `FreeNodes::rigid_set_motions`): with the rigid
/// tip body, `T₁` is the period the body vibrates with (the mesh body's, measured: 0.1358622 s)
/// whatever the mode count, within the basis's truncation (Rayleigh–Ritz: shorter) and the
/// scheme's period error of the measurement (5e-5). A penalty in its place (`K + κ V Vᵀ`, κ
/// 1e6 times `K`'s largest diagonal entry) gave 0.137 to 0.222 s, or no factorization at 32
/// modes: the lowest ω² fell below the round-off of the penalised matrix.
#[test]
fn the_lowest_period_of_a_reduced_body_with_rigid_sets_is_its_own() {
    let measured = 0.1358622;
    for modes in [4.0, 8.0, 16.0, 32.0] {
        let t1 = logged_first_period(&[("model.modes", modes), ("model.accuracy", 1e-2)]);
        println!(
            "{modes} modes: T₁ = {t1:.7} s ({:+.2e})",
            t1 / measured - 1.0
        );
        assert!((t1 / measured - 1.0).abs() < 2e-4, "{modes} modes: {t1} s");
    }
}

/// The VTK results of a reduced body with a lumped body draw the mesh's nodes only (the mass
/// points are not drawn): every point array has one row per mesh node.
#[test]
fn vtk_results_of_a_reduced_body_with_a_lumped_hub_have_the_mesh_nodes() {
    let dir = std::env::temp_dir().join(format!("flexbody-reduced-vtk-{}", std::process::id()));
    let mut s = flexbody::slave::Slave::from_body(example_body("controlled_arm")).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    let directory = s
        .variables()
        .by_name("output.directory")
        .unwrap()
        .value_reference;
    s.set_string(directory, &dir.display().to_string()).unwrap();
    set(&mut s, "model.modes", 4.0);
    set(&mut s, "hub.torque[3]", 10.0);
    s.exit_initialization_mode().unwrap();
    s.do_step(0.0, 0.01).unwrap();
    s.terminate();
    let n = s.mesh().node_count();
    let vtu = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "vtu"))
        .max()
        .unwrap();
    let text = std::fs::read_to_string(&vtu).unwrap();
    // The writer's files closed first (Windows removes no open file).
    drop(s);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(text.contains(&format!("NumberOfPoints=\"{n}\"")));
    for name in ["displacement", "velocity"] {
        let start = text.find(&format!("Name=\"{name}\"")).unwrap();
        let body = start + text[start..].find('>').unwrap() + 1;
        let end = body + text[body..].find("</DataArray>").unwrap();
        assert_eq!(text[body..end].split_whitespace().count(), 3 * n, "{name}");
    }
}

/// A reduced body rebuilt in one instance (another `model.modes`, then back) has the basis a
/// fresh instance builds: the interfaces' sets distribute the attachment modes' unit loads over
/// the mesh, not over the previous basis. A state saved with 4 modes restores into an instance
/// that built 8 first.
#[test]
fn a_rebuilt_reduced_body_has_the_basis_of_a_fresh_one() {
    let arm = || example_body("controlled_arm");
    let mut s = initialized(arm(), &[("model.modes", 4.0), ("hub.torque[3]", 50.0)]);
    for k in 0..5 {
        s.do_step(k as f64 * 0.01, 0.01).unwrap();
    }
    let saved = s.get_state();
    let mut other = flexbody::slave::Slave::from_body(arm()).unwrap();
    other.setup_experiment(0.0, None, None).unwrap();
    other.enter_initialization_mode().unwrap();
    set(&mut other, "model.modes", 8.0);
    get(&mut other, "tip.position[1]"); // builds the model with 8 modes
    set(&mut other, "model.modes", 4.0);
    other.exit_initialization_mode().unwrap();
    assert_eq!(
        other.body().unwrap().node_count(),
        s.body().unwrap().node_count()
    );
    other.set_state(&saved).unwrap();
    s.do_step(0.05, 0.01).unwrap();
    other.do_step(0.05, 0.01).unwrap();
    assert_eq!(
        get(&mut other, "tip.position[2]"),
        get(&mut s, "tip.position[2]")
    );
}

/// A rigid attachment sharing nodes with a fixed support on a reduced body is refused, naming
/// both (two boundary sets of the basis on the same nodes).
#[test]
fn a_rigid_set_on_a_supports_nodes_is_refused_by_name() {
    let mut body = flexbody::model::BodyFile::default_body();
    let mut hub = body.interfaces[0].clone();
    (hub.name, hub.kind, hub.rigid) = ("hub".into(), flexbody::model::InterfaceKind::Force, true);
    body.interfaces.push(hub);
    let mut s = flexbody::slave::Slave::from_body(body).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.modes", 4.0);
    let e = s.exit_initialization_mode().unwrap_err();
    assert!(
        e.message.contains("'hub'") && e.message.contains("'root'"),
        "{e}"
    );
}

/// A reduced body whose rebuild failed leaves no model behind: after `model.modes` = 100 000
/// (refused) and a reset, `model.modes = 4` gives the fresh instance's tip (the failed build had
/// put the sets back on the mesh while the old model stayed cached, and the next start indexed
/// mesh nodes in the reduced coordinates).
#[test]
fn a_failed_reduced_build_leaves_nothing_stale() {
    let tip_after_a_step = |s: &mut flexbody::slave::Slave| {
        s.do_step(0.0, 1e-3).unwrap();
        get(s, "tip.position[2]")
    };
    let mut fresh = initialized_default(&[("model.modes", 4.0), ("tip.force[2]", -10.0)]);
    let expected = tip_after_a_step(&mut fresh);
    let mut s = initialized_default(&[("model.modes", 4.0), ("tip.force[2]", -10.0)]);
    tip_after_a_step(&mut s);
    s.reset();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.modes", 100_000.0);
    assert!(s.exit_initialization_mode().is_err());
    s.reset();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    set(&mut s, "model.modes", 4.0);
    set(&mut s, "tip.force[2]", -10.0);
    s.exit_initialization_mode().unwrap();
    assert_eq!(tip_after_a_step(&mut s), expected);
}
