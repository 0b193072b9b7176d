//! Load time of a large Gmsh part: a ~100k-DOF tet10 mesh (B1's beam cut into Kuhn tetrahedra,
//! 100 × 6 × 6 cells, 33 969 nodes, 101 907 DOF) written as an MSH 4.1 file (ASCII and binary),
//! then timed as the FMU loads it:
//!
//! 1. `Slave::from_body_path`: read + parse the `.msh` (mshio), validate the mesh (Jacobians at
//!    every quadrature point and node), select the interface node sets (what `fmi2Instantiate`
//!    does);
//! 2. `exit_initialization_mode`: assemble `M`, `K`, lumped masses, place the body, factorise the
//!    iteration matrix (what `fmi2ExitInitializationMode` does).
//!
//! `cargo run --release --example gmsh_load_time` (prints, asserts nothing; the fastest of 3 runs).

use flexbody::mesh::{beam, gmsh::TET10_FROM_GMSH, ElementKind, Mesh};
use flexbody::slave::Slave;
use std::fmt::Write as _;
use std::time::Instant;

/// MSH 4.1 of a tet10 mesh: one volume entity, no groups (the body file selects planes).
fn msh(mesh: &Mesh, binary: bool) -> Vec<u8> {
    let n = mesh.node_count();
    let e = mesh.element_count();
    let mut out = Vec::new();
    let mut text = String::new();
    let _ = write!(text, "$MeshFormat\n4.1 {} 8\n", u8::from(binary));
    out.extend_from_slice(text.as_bytes());
    if binary {
        out.extend_from_slice(&1i32.to_le_bytes());
        out.push(b'\n');
    }
    text.clear();
    text.push_str("$EndMeshFormat\n$Nodes\n");
    // Gmsh element order: VTK nodes 8 and 9 swapped back (TET10_FROM_GMSH is its own inverse).
    let gmsh_nodes = |k: usize| TET10_FROM_GMSH.map(|g| mesh.element(k)[g] as u64 + 1);
    if binary {
        out.extend_from_slice(text.as_bytes());
        for v in [1u64, n as u64, 1, n as u64] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [3i32, 1, 0] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&(n as u64).to_le_bytes());
        for i in 1..=n as u64 {
            out.extend_from_slice(&i.to_le_bytes());
        }
        for p in mesh.nodes() {
            for c in p {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.extend_from_slice(b"\n$EndNodes\n$Elements\n");
        for v in [1u64, e as u64, 1, e as u64] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [3i32, 1, 11] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&(e as u64).to_le_bytes());
        for k in 0..e {
            out.extend_from_slice(&(k as u64 + 1).to_le_bytes());
            for node in gmsh_nodes(k) {
                out.extend_from_slice(&node.to_le_bytes());
            }
        }
        out.extend_from_slice(b"\n$EndElements\n");
        return out;
    }
    let _ = writeln!(text, "1 {n} 1 {n}\n3 1 0 {n}");
    for i in 1..=n {
        let _ = writeln!(text, "{i}");
    }
    for p in mesh.nodes() {
        let _ = writeln!(text, "{:?} {:?} {:?}", p[0], p[1], p[2]);
    }
    let _ = writeln!(text, "$EndNodes\n$Elements\n1 {e} 1 {e}\n3 1 11 {e}");
    for k in 0..e {
        let _ = write!(text, "{}", k + 1);
        for node in gmsh_nodes(k) {
            let _ = write!(text, " {node}");
        }
        text.push('\n');
    }
    text.push_str("$EndElements\n");
    out.extend_from_slice(text.as_bytes());
    out
}

fn main() {
    let mesh = beam(1.0, 0.02, 0.02, [100, 6, 6], ElementKind::Tet10).unwrap();
    let dir = std::env::temp_dir().join(format!("flexbody-load-time-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    println!(
        "tet10 beam: {} nodes, {} DOF, {} elements",
        mesh.node_count(),
        3 * mesh.node_count(),
        mesh.element_count()
    );
    for binary in [false, true] {
        let name = if binary { "part.bin.msh" } else { "part.msh" };
        let bytes = msh(&mesh, binary);
        std::fs::write(dir.join(name), &bytes).unwrap();
        let body = format!(
            r#"{{ "name": "big_part", "mesh": {{ "gmsh": {{ "file": "{name}" }} }},
                "material": {{ "youngsModulus": 2.1e11, "poissonRatio": 0.3, "density": 7850.0 }},
                "interfaces": [
                  {{ "name": "root", "kind": "fixed", "nodes": {{ "plane": {{ "point": [0, 0, 0], "normal": [1, 0, 0] }} }} }},
                  {{ "name": "tip", "kind": "force", "nodes": {{ "plane": {{ "point": [1, 0, 0], "normal": [1, 0, 0] }} }} }}
                ] }}"#
        );
        let body_path = dir.join("body.json");
        std::fs::write(&body_path, body).unwrap();
        let (mut instantiate, mut initialize) = (f64::INFINITY, f64::INFINITY);
        let mut events = Vec::new();
        for _ in 0..3 {
            let start = Instant::now();
            let mut slave = Slave::from_body_path(&body_path).unwrap();
            let loaded = start.elapsed().as_secs_f64();
            slave.setup_experiment(0.0, None, None).unwrap();
            slave.enter_initialization_mode().unwrap();
            let start = Instant::now();
            slave.exit_initialization_mode().unwrap();
            events = slave.drain_events().map(|e| e.message).collect();
            instantiate = instantiate.min(loaded);
            initialize = initialize.min(start.elapsed().as_secs_f64());
        }
        println!(
            "{} ({:.1} MB): instantiate (read, parse, validate, node sets) {:.3} s; \
             initialize (assemble M and K, factorise) {:.3} s; total {:.3} s",
            if binary {
                "binary MSH 4.1"
            } else {
                "ASCII MSH 4.1 "
            },
            bytes.len() as f64 / 1e6,
            instantiate,
            initialize,
            instantiate + initialize
        );
        for e in &events {
            println!("    {e}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
