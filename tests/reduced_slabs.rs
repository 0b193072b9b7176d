//! A reduced body's slabs on its coordinates (`Patches::reduce`, docs/formulation.md, "The
//! reduced body": several frames) against the same slabs on its expanded nodes: the force on the
//! coordinates is the projection of the nodal force, and the strain energy is the same.

use flexbody::body::{InterfaceSets, MeshData, ModeCount, NodeSet, Patches, Reduction};
use flexbody::fem::{lumped_masses, scalar_mass_matrix, stiffness_matrix, IsotropicMaterial};
use flexbody::mesh::NodeSelector;
use flexbody::model::BodyFile;
use nalgebra::{Rotation3, Vector3};

/// B1's mesh reduced to 4 modes (root held, tip loaded) and its five slabs, on the nodes and on
/// the coordinates.
fn b1_with_slabs() -> (Reduction, Patches, Patches) {
    let mesh = BodyFile::default_body().mesh.build(None).unwrap();
    let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
    let material = IsotropicMaterial::STEEL;
    let lumped = lumped_masses(&mesh, material.density);
    let set = |name: &str, x: f64, point: Option<Vector3<f64>>| {
        let nodes = NodeSelector::Plane {
            point: [x, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
            tolerance: None,
        }
        .select(&mesh)
        .unwrap();
        let weights = nodes.iter().map(|&i| lumped[i]).collect();
        NodeSet::new(name, nodes, weights, &reference, point).unwrap()
    };
    let (root, tip) = (set("root", 0.0, None), set("tip", 1.0, Some(Vector3::x())));
    let k = stiffness_matrix(&mesh, &material);
    let ms = scalar_mass_matrix(&mesh, material.density);
    let reduction = Reduction::new(
        &MeshData {
            reference: &reference,
            mass: &ms,
            stiffness: &k,
            force_stiffness: None,
            lumped: &lumped,
            frame_weights: &lumped,
            second_order_force: None,
        },
        &InterfaceSets {
            held: &[&root],
            rigid: &[],
            loaded: &[&tip],
        },
        ModeCount::Fixed(4),
    )
    .unwrap();
    let materials = vec![material; mesh.element_count()];
    let on_nodes = Patches::along_principal_axis(&mesh, &materials, &lumped, 5).unwrap();
    let mut on_coordinates = on_nodes.clone();
    on_coordinates.reduce(&reduction);
    (reduction, on_nodes, on_coordinates)
}

/// The coordinates of the body turned by `angle` about a skew axis, moved, and deformed by a
/// perturbation of every coefficient of relative size `size` (any `q` is a state of the
/// reduced body; the identity checked holds for all of them).
fn deformed_state(reduction: &Reduction, angle: f64, size: f64) -> Vec<f64> {
    let axis = nalgebra::Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
    let turn = Rotation3::from_axis_angle(&axis, angle);
    let shift = Vector3::new(0.2, -0.1, 0.05);
    let q_ref = &reduction.reference;
    let scale = q_ref.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut q = vec![0.0; q_ref.len()];
    for k in 0..reduction.field_count {
        let reference = Vector3::new(q_ref[3 * k], q_ref[3 * k + 1], q_ref[3 * k + 2]);
        let wobble = Vector3::new(
            (1.3 * k as f64).sin(),
            (0.7 * k as f64 + 0.4).cos(),
            (2.1 * k as f64 + 1.0).sin(),
        ) * (size * scale);
        let moved = turn * (reference + wobble) + shift * reduction.unit[k];
        q[3 * k..3 * k + 3].copy_from_slice(moved.as_slice());
    }
    q
}

#[test]
fn slabs_on_the_coordinates_give_the_projected_nodal_force() {
    let (reduction, on_nodes, on_coordinates) = b1_with_slabs();
    assert!(on_coordinates.acts_on_coordinates() && !on_nodes.acts_on_coordinates());
    let n3 = 3 * reduction.node_count;
    let s3 = 3 * reduction.field_count;
    for (angle, size, nonlinear_forces) in [
        (0.0, 1e-3, false),
        (0.7, 1e-3, false),
        (0.7, 1e-3, true),
        (2.5, 2e-2, true),
    ] {
        let q = deformed_state(&reduction, angle, size);
        // On the nodes: expand, the slabs' force, project back.
        let mut x = vec![0.0; n3];
        reduction.expand_into(&q, &mut x);
        let mut nodal = vec![0.0; n3];
        let energy_nodes =
            on_nodes.internal_force(&x, nonlinear_forces, &mut on_nodes.scratch(), &mut nodal);
        let mut projected = vec![0.0; s3];
        reduction.project_into(&nodal, &mut projected);
        // On the coordinates.
        let mut direct = vec![0.0; s3];
        let energy_coordinates = on_coordinates.internal_force(
            &q,
            nonlinear_forces,
            &mut on_coordinates.scratch(),
            &mut direct,
        );
        let largest = projected.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let difference = projected
            .iter()
            .zip(&direct)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        println!(
            "turned {angle} rad, deformation {size}, f_nl {nonlinear_forces}: force {largest:.3e}, difference {difference:.3e}; energy {energy_nodes:.6e} J against {energy_coordinates:.6e} J"
        );
        // The two are the same sums in another order: round-off of the largest terms, the
        // elastic forces of the reference-sized coordinates (about 1e-16 × ‖K‖ × |q|, a few
        // 1e-9 of the force here), not the physics.
        assert!(largest > 0.0);
        assert!(
            difference <= 1e-8 * largest,
            "turned {angle}, f_nl {nonlinear_forces}: {difference:e} of {largest:e}"
        );
        assert!(
            (energy_nodes - energy_coordinates).abs() <= 1e-8 * energy_nodes,
            "energy {energy_nodes:e} against {energy_coordinates:e}"
        );
    }
}
