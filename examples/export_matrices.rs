//! Writes a body's mesh data and constant FE matrices as plain text, for the peer models of
//! `bench/peers.py` (Exudyn's floating frame of reference is then built on exactly our mesh, mass
//! and stiffness matrices).
//!
//! `cargo run --release --example export_matrices -- OUT_DIR [body.json]` (default body: B1, the
//! embedded cantilever). Files in `OUT_DIR`:
//! * `nodes.txt`: one line `x y z w` per node (reference position in m, HRZ-lumped mass in kg,
//!   the weights of our interfaces and co-moving frame);
//! * `mass.txt`: `i j value` for every stored entry of the scalar consistent mass `Ms` (N × N,
//!   both triangles; the 3N × 3N mass is `Ms ⊗ I3`);
//! * `stiffness.txt`: `i j value` for every stored entry of the small-strain stiffness `K`
//!   (3N × 3N, both triangles, DOF `3 i + c`).

use flexbody::linalg::sparse::SymmetricCsr;
use flexbody::model::BodyFile;
use flexbody::slave::Slave;
use std::io::Write;

fn write_csr(path: &std::path::Path, a: &SymmetricCsr) {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for i in 0..a.n {
        let (cols, values) = a.row(i);
        for (&j, &v) in cols.iter().zip(values) {
            writeln!(out, "{i} {j} {v:.17e}").unwrap();
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(
        args.first()
            .expect("usage: export_matrices OUT_DIR [body.json]"),
    );
    let body_file = match args.get(1) {
        Some(p) => BodyFile::from_json(&std::fs::read_to_string(p).unwrap()).unwrap(),
        None => BodyFile::default_body(),
    };
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = Slave::from_body(body_file).unwrap();
    s.setup_experiment(0.0, None, None).unwrap();
    s.enter_initialization_mode().unwrap();
    s.exit_initialization_mode().unwrap();
    let body = s.body().unwrap();
    let n = body.node_count();
    let fw = &body.frame_weights;
    let mut weight = vec![0.0; n];
    for (&i, &w) in fw.nodes.iter().zip(&fw.weights) {
        weight[i] = w;
    }
    let mut out = std::io::BufWriter::new(std::fs::File::create(dir.join("nodes.txt")).unwrap());
    for (i, w) in weight.iter().enumerate() {
        let x = &body.reference[3 * i..3 * i + 3];
        writeln!(out, "{:.17e} {:.17e} {:.17e} {w:.17e}", x[0], x[1], x[2]).unwrap();
    }
    drop(out);
    write_csr(&dir.join("mass.txt"), &body.mass_matrix);
    write_csr(&dir.join("stiffness.txt"), &body.stiffness_matrix);
    println!(
        "{n} nodes, {} DOF, nnz(Ms) = {}, nnz(K) = {}: written to {}",
        3 * n,
        body.mass_matrix.nnz(),
        body.stiffness_matrix.nnz(),
        dir.display()
    );
}
