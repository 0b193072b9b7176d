//! What a reduced body keeps on its coordinates against the same on its expanded nodes
//! (docs/formulation.md, "The reduced body"): its slabs (`Patches::reduce`, several frames),
//! whose force on the coordinates is the projection of the nodal force with the same strain
//! energy, and its geometric stiffness, kept as the scalar `G_r` of `K_G = G_r ⊗ I3`.

mod common;
use common::reduced_b1::B1;
use common::rigid::largest_difference;
use flexbody::body::{Patches, Reduction};
use flexbody::fem::geometric::{geometric_stiffness, stress_at_gauss_points};
use flexbody::fem::IsotropicMaterial;
use nalgebra::{Rotation3, Vector3};

/// B1's reduction to 4 modes (root held, tip loaded) and its five slabs, on the nodes and on
/// the coordinates.
fn b1_with_slabs() -> (Reduction, Patches, Patches) {
    let b1 = B1::new();
    let (_, _, reduction) = b1.reduced(&[&b1.root], &[&b1.tip], 4);
    let materials = vec![IsotropicMaterial::STEEL; b1.mesh.element_count()];
    let on_nodes = Patches::along_principal_axis(&b1.mesh, &materials, &b1.lumped, 5).unwrap();
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
        let difference = largest_difference(&projected, &direct);
        println!(
            "turned {angle} rad, deformation {size}, f_nl {nonlinear_forces}: force {largest:.3e}, difference {difference:.3e}; energy {energy_nodes:.6e} J against {energy_coordinates:.6e} J"
        );
        // The two are the same sums in another order: they differ by round-off, measured
        // 3e-14 to 7e-13 of the force, not by physics (leaving out the arms' term of `f_nl`
        // makes it 4e-2).
        assert!(largest > 0.0);
        assert!(
            difference <= 1e-11 * largest,
            "turned {angle}, f_nl {nonlinear_forces}: {difference:e} of {largest:e}"
        );
        assert!(
            (energy_nodes - energy_coordinates).abs() <= 1e-12 * energy_nodes,
            "energy {energy_nodes:e} against {energy_coordinates:e}"
        );
    }
}

/// The reduced geometric stiffness kept as `G_r` (`s × s`) acts on the coordinates as the
/// projection of the mesh's `K_G = G ⊗ I3` does: `(G_r ⊗ I3) v = (S ⊗ I3)ᵀ K_G (S ⊗ I3) v`.
#[test]
fn the_scalar_geometric_stiffness_is_the_projection_of_the_mesh_one() {
    let b1 = B1::new();
    let (_, _, reduction) = b1.reduced(&[&b1.root], &[&b1.tip], 4);
    let mesh = b1.mesh;
    // A prestress: the stress of a bending and stretching displacement of the beam.
    let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
    let u: Vec<f64> = reference
        .chunks(3)
        .flat_map(|p| [1e-4 * p[0], 1e-3 * p[0] * p[0], -5e-4 * p[0] * p[1]])
        .collect();
    let k_g = geometric_stiffness(
        &mesh,
        &stress_at_gauss_points(&mesh, &IsotropicMaterial::STEEL, &u),
    );
    let g_r = reduction.project_geometric_stiffness(&k_g);
    let s = reduction.field_count;
    assert_eq!((g_r.n, g_r.values.len()), (s, s * s));
    let v: Vec<f64> = (0..3 * s).map(|k| (0.37 * k as f64).sin()).collect();
    let mut kronecker = vec![0.0; 3 * s];
    g_r.mul_nodes(&v, &mut kronecker);
    let (mut x, mut k_g_x) = (
        vec![0.0; 3 * reduction.node_count],
        vec![0.0; 3 * reduction.node_count],
    );
    reduction.expand_into(&v, &mut x);
    k_g.mul_vec(&x, &mut k_g_x);
    let mut projected = vec![0.0; 3 * s];
    reduction.project_into(&k_g_x, &mut projected);
    let largest = projected.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let difference = largest_difference(&projected, &kronecker);
    println!("G_r ⊗ I3 against the projection: {difference:.3e} of {largest:.3e}");
    // Round-off of sums over the nodes in another order.
    assert!(largest > 0.0);
    assert!(
        difference <= 1e-11 * largest,
        "{difference:e} of {largest:e}"
    );
}
