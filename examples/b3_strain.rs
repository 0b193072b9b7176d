//! Issue 4, item 5: does one co-moving frame suffice on B3? Runs the `full` reference to
//! t = 2.2 s (spin-up of Kane's beam), then compares, at every Gauss point along the beam, the
//! frame-invariant Green strain of the `full` solution with the reduced (linear) strain of the
//! same positions seen from the single best-fit frame, `ε = sym ∇ū`. Their difference is
//! `½ ∇ūᵀ∇ū`, the rotation error of the linear strain: if it dwarfs the true strain, the reduced
//! strain is an artefact of the single frame.
//! `cargo run --release --example b3_strain [-- t_end h]`

use flexbody::fem::geometric::stress_at_gauss_points;
use flexbody::fem::nonlinear::SvkSolid;
use flexbody::fem::IsotropicMaterial;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use nalgebra::Vector3;
#[path = "../tests/common/b3.rs"]
mod b3;
use b3::HubDrive;

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let t_end = args.first().copied().unwrap_or(2.2);
    let h = args.get(1).copied().unwrap_or(1e-2);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/hub_beam.json"
    ))
    .unwrap();
    let body_file = BodyFile::from_json(&text).unwrap();
    let mut s = Slave::from_body(body_file).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_by_name("model.formulation", 2.0).unwrap();
    s.set_by_name("solver.stepSize", h).unwrap();
    // Measured at the fixed step h.
    s.set_by_name("model.accuracy", 0.0).unwrap();
    s.exit_initialization_mode().unwrap();
    let drive = HubDrive::new(&s);
    let steps = (t_end / h).round() as usize;
    for k in 0..steps {
        let t = k as f64 * h;
        drive.step(&mut s, t, h).unwrap();
    }
    let x = s.dynamic_state().unwrap().position.clone();
    let body = s.body().unwrap();
    let mesh = s.mesh().clone();
    let material = s.parameters().material;
    // Local deformation ū in the single best-fit frame.
    let fw = &body.frame_weights;
    let frame = fw.best_fit(&x);
    let rt = frame.rotation.transpose();
    let mut ubar = vec![0.0; x.len()];
    for i in 0..body.node_count() {
        let u = rt * (Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]) - frame.origin)
            - fw.reference_offsets[i];
        ubar[3 * i..3 * i + 3].copy_from_slice(u.as_slice());
    }
    // σ with E = 1, ν = 0 is ε itself (λ = 0, 2μ = 1).
    let unit = IsotropicMaterial {
        youngs_modulus: 1.0,
        poisson_ratio: 0.0,
        density: material.density,
    };
    let reduced = stress_at_gauss_points(&mesh, &unit, &ubar);
    let solid = SvkSolid::new(&mesh, &material);
    let green = solid.green_strain_at_gauss_points(&x);
    let positions = solid.gauss_point_positions();
    println!("B3 `full` at t = {t_end} s (h = {h} s), hex20 40×1×1: axial strain along the beam, Gauss points on the neutral line\n");
    println!("| X (m) | Green E_xx (full) | reduced ε_xx (one frame) | difference | local rotation from the frame (rad) |");
    println!("|---|---|---|---|---|");
    let (mut worst_ratio, mut max_green, mut max_diff) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (k, p) in positions.iter().enumerate() {
        let diff = reduced[k][0] - green[k][0];
        max_green = max_green.max(green[k][0].abs());
        max_diff = max_diff.max(diff.abs());
        worst_ratio = worst_ratio.max(diff.abs() / green[k][0].abs().max(1e-30));
        // print the points nearest the beam axis, one per element
        if p[1].abs() < 0.03 && p[2].abs() < 0.03 && (k % 27) == 13 {
            println!(
                "| {:.2} | {:+.3e} | {:+.3e} | {:+.3e} | {:.4} |",
                p[0],
                green[k][0],
                reduced[k][0],
                diff,
                (2.0 * diff.abs()).sqrt()
            );
        }
    }
    println!("\nlargest |E_xx| = {max_green:.3e}, largest |ε_xx − E_xx| = {max_diff:.3e} ({:.1}× the largest true strain)", max_diff / max_green);
}
