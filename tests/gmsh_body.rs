//! Body files with a Gmsh mesh: the connecting rod of `examples/conrod.json`, and clear errors at
//! instantiation for a malformed mesh file.

mod common;

use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::path::{Path, PathBuf};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples")
}

/// A scratch directory of this test process (removed by the caller's last test only if empty).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flexbody-gmsh-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn conrod_loads_with_its_eye_groups_and_steps() {
    let mut slave = Slave::from_body_path(&examples().join("conrod.json")).unwrap();
    let mesh = slave.mesh();
    assert_eq!(mesh.kind(), flexbody::mesh::ElementKind::Tet10);
    // The bores: every node of a group lies on its cylinder (radius 22 mm / 10 mm).
    for (group, centre, radius) in [("big_eye", 0.0, 0.022), ("small_eye", 0.15, 0.010)] {
        let nodes = mesh.group(group).unwrap();
        assert!(nodes.len() > 20, "{group}: {} nodes", nodes.len());
        for &i in nodes {
            let p = mesh.nodes()[i];
            let r = ((p[0] - centre).powi(2) + p[1] * p[1]).sqrt();
            assert!((r - radius).abs() < 1e-7, "{group}: node {i} at r = {r}");
        }
    }
    slave.setup_experiment(0.0, None, None).unwrap();
    slave.enter_initialization_mode().unwrap();
    slave.exit_initialization_mode().unwrap();
    // Pull the small eye along the rod (+x, 10 kN) with the big eye held: it moves in +x.
    common::set(&mut slave, "small_eye.force[1]", 1e4);
    let x0 = common::get(&mut slave, "small_eye.position[1]");
    for k in 0..5 {
        slave.do_step(k as f64 * 1e-4, 1e-4).unwrap();
    }
    let dx = common::get(&mut slave, "small_eye.position[1]") - x0;
    let dy = common::get(&mut slave, "small_eye.position[2]");
    // Axial stiffness of the rod is of order E A / L ≈ 2.1e11 · 2e-4 / 0.15 ≈ 3e8 N/m, so the
    // static stretch is ~3e-5 m; half a millisecond into a step load it is under way but below
    // twice the static value (dynamic overshoot).
    println!("small eye after 0.5 ms of 10 kN: dx = {dx:.3e} m, dy = {dy:.3e} m");
    assert!(dx > 1e-7 && dx < 2e-4, "dx = {dx:e}");
    assert!(dy.abs() < 0.1 * dx, "dy = {dy:e}");
}

#[test]
fn malformed_mesh_files_fail_at_instantiation_with_a_clear_message() {
    let dir = scratch("malformed");
    let good = std::fs::read(examples().join("conrod/conrod.msh")).unwrap();
    let body_text = std::fs::read_to_string(examples().join("conrod.json")).unwrap();
    let cases: Vec<(&str, Vec<u8>, String, &str)> = vec![
        (
            "truncated",
            good[..good.len() / 2].to_vec(),
            body_text.clone(),
            "not a valid MSH 4.1 file",
        ),
        (
            "version",
            String::from_utf8_lossy(&good)
                .replacen("4.1 0 8", "2.2 0 8", 1)
                .into_bytes(),
            body_text.clone(),
            "version '2.2' is not supported",
        ),
        (
            "group",
            good.clone(),
            body_text.replace("{ \"group\": \"small_eye\" }", "{ \"group\": \"piston\" }"),
            "no group 'piston'; its groups are: big_eye, small_eye, solid",
        ),
        (
            "missing",
            Vec::new(),
            body_text.replace("conrod/conrod.msh", "conrod/nowhere.msh"),
            "cannot read the Gmsh mesh file",
        ),
    ];
    for (name, msh, body, expected) in cases {
        let case = dir.join(name);
        std::fs::create_dir_all(case.join("conrod")).unwrap();
        if !msh.is_empty() {
            std::fs::write(case.join("conrod/conrod.msh"), &msh).unwrap();
        }
        std::fs::write(case.join("body.json"), &body).unwrap();
        // As the FMU loads it: body.json and the mesh in the resource directory.
        let message = match Slave::from_resources(Some(&case)) {
            Ok(_) => panic!("{name}: a malformed mesh was accepted"),
            Err(e) => e.message,
        };
        println!("{name}: {message}");
        assert!(message.contains(expected), "{name}: {message}");
        if name != "group" {
            assert!(
                message.contains("conrod/"),
                "{name}: the file is named: {message}"
            );
        }
        std::fs::remove_dir_all(&case).unwrap();
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_relative_mesh_path_without_a_base_is_relative_to_the_current_directory() {
    // Slave::from_body has no body-file directory: the mesh path is taken as given.
    let mut body = common::example_body_at(&examples().join("conrod.json"));
    if let flexbody::model::body_file::MeshSpec::Gmsh { file, .. } = &mut body.mesh {
        *file = examples().join("conrod/conrod.msh").display().to_string();
    }
    assert!(Slave::from_body(body).is_ok());
    let body =
        BodyFile::from_json(&std::fs::read_to_string(examples().join("conrod.json")).unwrap())
            .unwrap();
    let e = Slave::from_body(body).err().unwrap();
    assert!(
        e.message
            .contains("cannot read the Gmsh mesh file conrod/conrod.msh"),
        "{}",
        e.message
    );
}

/// The `DataArray` named `name` of a `.vtu` text: its numbers.
fn data_array(vtu: &str, name: &str) -> Vec<f64> {
    let start = vtu
        .find(&format!("Name=\"{name}\""))
        .unwrap_or_else(|| panic!("no array {name}"));
    let body_start = start + vtu[start..].find('>').unwrap() + 1;
    let body_end = body_start + vtu[body_start..].find("</DataArray>").unwrap();
    vtu[body_start..body_end]
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect()
}

#[test]
fn vtk_results_of_the_conrod_are_written_at_the_interval() {
    let dir = scratch("vtk");
    let mut slave = Slave::from_body_path(&examples().join("conrod.json")).unwrap();
    slave.setup_experiment(0.0, None, None).unwrap();
    slave.enter_initialization_mode().unwrap();
    let directory = slave
        .variables()
        .by_name("output.directory")
        .unwrap()
        .value_reference;
    slave
        .set_string(directory, &dir.join("results").display().to_string())
        .unwrap();
    common::set(&mut slave, "output.interval", 2e-4);
    slave.exit_initialization_mode().unwrap();
    common::set(&mut slave, "small_eye.force[2]", 5e3);
    for k in 0..5 {
        slave.do_step(k as f64 * 1e-4, 1e-4).unwrap();
    }
    let messages: Vec<String> = slave.drain_events().map(|e| e.message).collect();
    assert!(
        messages.iter().any(|m| m.contains("writing VTK results")),
        "{messages:?}"
    );
    // Saved at t = 0, 2e-4 and 4e-4 (the interval from the last saved time).
    let pvd = std::fs::read_to_string(dir.join("results/conrod.pvd")).unwrap();
    let files: Vec<&str> = pvd
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1))
        .map(|l| l.trim_end_matches("\"/>"))
        .collect();
    assert_eq!(
        files,
        [
            "conrod_000000.vtu",
            "conrod_000001.vtu",
            "conrod_000002.vtu"
        ],
        "{pvd}"
    );
    assert!(pvd.contains("timestep=\"4e-4\""), "{pvd}");
    let n = slave.mesh().node_count();
    let last = std::fs::read_to_string(dir.join("results").join(files[2])).unwrap();
    assert!(last.contains(&format!("NumberOfPoints=\"{n}\"")));
    let displacement = data_array(&last, "displacement");
    let stress = data_array(&last, "vonMises");
    let velocity = data_array(&last, "velocity");
    assert_eq!(displacement.len(), 3 * n);
    assert_eq!(stress.len(), n);
    assert!(displacement
        .iter()
        .chain(&stress)
        .chain(&velocity)
        .all(|v| v.is_finite()));
    // The loaded small eye moves in +y; the driven big eye stays put; the rod is stressed.
    let small = slave.mesh().group("small_eye").unwrap();
    let big = slave.mesh().group("big_eye").unwrap();
    let mean_y = |nodes: &[usize]| {
        nodes.iter().map(|&i| displacement[3 * i + 1]).sum::<f64>() / nodes.len() as f64
    };
    assert!(mean_y(small) > 1e-8, "{}", mean_y(small));
    assert!(big.iter().all(|&i| displacement[3 * i + 1].abs() < 1e-12));
    let peak = stress.iter().fold(0.0f64, |m, &s| m.max(s));
    println!("conrod after 0.4 ms of 5 kN lateral: small eye dy = {:.3e} m, peak von Mises {peak:.3e} Pa", mean_y(small));
    assert!(peak > 1e5 && peak < 1e10, "{peak:e}");
    let first = std::fs::read_to_string(dir.join("results").join(files[0])).unwrap();
    assert!(data_array(&first, "vonMises")
        .iter()
        .all(|&s| s.abs() < 1e-3));
    // The slave holds its results open; Windows deletes no open file.
    drop(slave);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unwritable_output_directory_is_a_logged_error_not_a_failure() {
    let dir = scratch("unwritable");
    let blocker = dir.join("file");
    std::fs::write(&blocker, b"not a directory").unwrap();
    let mut slave = Slave::from_body(BodyFile::default_body()).unwrap();
    slave.setup_experiment(0.0, None, None).unwrap();
    slave.enter_initialization_mode().unwrap();
    let directory = slave
        .variables()
        .by_name("output.directory")
        .unwrap()
        .value_reference;
    let target = blocker.join("results").display().to_string();
    slave.set_string(directory, &target).unwrap();
    assert_eq!(slave.get_string(directory).unwrap(), target);
    slave.exit_initialization_mode().unwrap();
    slave.do_step(0.0, 1e-3).unwrap();
    let errors: Vec<String> = slave
        .drain_events()
        .filter(|e| e.category == "logStatusError")
        .map(|e| e.message)
        .collect();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].contains("cannot create the directory") && errors[0].contains(&target),
        "{}",
        errors[0]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
