//! Cost of a step against its floor (one forward and one backward triangular solve with the
//! factor of the iteration matrix) as the mesh grows, 1k to ~100k DOF (issue 7).
//!
//! `cargo run --release --example step_scaling -- [--quick] [--csv FILE]`
//!
//! B1-like cantilevers (1 m × 20 mm × 20 mm steel, root clamped, 10 N at the tip, hex20) with
//! divisions 10×1×1 up to 90×9×9 (`--quick`: up to 20×2×2), default solver settings
//! (`reducedStrain`, f_nl off), h = 1e-4 s. Per size: DOF (free), nnz(L), the time of the setup
//! (assembly, ordering, factorisation: `exit_initialization_mode` and the first step), the median
//! of a solve and of a step and their ratio. The number of timed steps falls with the size so that
//! a size takes seconds, not minutes. CSV columns:
//! `elements,dof,free_dof,nnz_l,setup_s,solve_ms,step_ms,iterations_per_step,step_over_solve`.

use flexbody::model::body_file::MeshSpec;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::fmt::Write as _;
use std::time::Instant;

#[path = "support/mod.rs"]
mod support;

fn main() {
    let support::BenchArgs {
        quick,
        csv: csv_path,
    } = support::BenchArgs::parse();
    let sizes: &[[usize; 3]] = if quick {
        &[[10, 1, 1], [20, 2, 2]]
    } else {
        &[
            [10, 1, 1],
            [20, 2, 2],
            [40, 4, 4],
            [60, 6, 6],
            [80, 8, 8],
            [90, 9, 9],
        ]
    };
    let h = 1e-4;
    let mut csv = String::from(
        "elements,dof,free_dof,nnz_l,setup_s,solve_ms,step_ms,iterations_per_step,step_over_solve\n",
    );
    println!("B1-like hex20 cantilevers, h = {h:e} s, `reducedStrain` (defaults)\n");
    println!("| divisions | DOF (free) | nnz(L) | setup (s) | solve (ms) | step (ms) | steps/s | iterations/step | step/solve |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for &divisions in sizes {
        let mut body_file = BodyFile::default_body();
        let MeshSpec::Beam { divisions: d, .. } = &mut body_file.mesh else {
            unreachable!("the default body is a beam")
        };
        *d = divisions;
        let started = Instant::now();
        let mut s = Slave::from_body(body_file).unwrap();
        s.setup_experiment(0.0, None, None).unwrap();
        s.enter_initialization_mode().unwrap();
        s.set_by_name("solver.stepSize", h).unwrap();
        // Measured at the fixed step h.
        s.set_by_name("model.accuracy", 0.0).unwrap();
        s.set_by_name("tip.force[2]", -10.0).unwrap();
        s.exit_initialization_mode().unwrap();
        let mut t = 0.0;
        s.do_step(t, h).unwrap(); // the first step at a step size factorises
        t += h;
        let setup = started.elapsed().as_secs_f64();

        // The floor: one forward + backward solve with the slave's own factor.
        let nnz_l = s.iteration_matrix(h).unwrap().factor.factor_nnz();
        // Enough repetitions for a median, few enough for ~1-3 s per size.
        let repeats = (2e7 / nnz_l as f64).clamp(10.0, 200.0) as usize;
        let solve = support::solve_time(&s, h, repeats);
        let (dof, n_free) = (
            s.body().unwrap().reference.len(),
            s.free_nodes().unwrap().dof_count(),
        );
        let (step, iterations, _) = support::step_time(&mut s, t, h, repeats);
        let elements = divisions.iter().product::<usize>();
        println!(
            "| {}×{}×{} | {dof} ({n_free}) | {nnz_l} | {setup:.2} | {:.3} | {:.3} | {:.0} | {iterations:.2} | {:.2} |",
            divisions[0],
            divisions[1],
            divisions[2],
            1e3 * solve,
            1e3 * step,
            1.0 / step,
            step / solve
        );
        writeln!(
            csv,
            "{elements},{dof},{n_free},{nnz_l},{setup:.6e},{:.6e},{:.6e},{iterations:.4},{:.4}",
            1e3 * solve,
            1e3 * step,
            step / solve
        )
        .unwrap();
    }
    if let Some(path) = csv_path {
        std::fs::write(&path, csv).unwrap();
        println!("\nCSV: {}", path.display());
    }
}
