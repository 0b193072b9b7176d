//! VTK XML files for ParaView: one `.vtu` (unstructured grid, ASCII) per saved time and a `.pvd`
//! collection listing them with their times.
//!
//! Written by hand rather than with the `vtkio` crate: the format needed here is a few dozen lines
//! of XML, and vtkio pulls in old parser crates with future-incompatibility warnings for what
//! would be a small part of its API.

use crate::mesh::{ElementKind, Mesh};
use std::fmt::Write as _;
use std::io::{Seek, SeekFrom, Write};

/// The VTK cell type of an element kind (node orders are VTK's already, see
/// [`crate::element`]).
pub fn cell_type(kind: ElementKind) -> u8 {
    match kind {
        ElementKind::Hex8 => 12,  // VTK_HEXAHEDRON
        ElementKind::Hex20 => 25, // VTK_QUADRATIC_HEXAHEDRON
        ElementKind::Tet4 => 10,  // VTK_TETRA
        ElementKind::Tet10 => 24, // VTK_QUADRATIC_TETRA
    }
}

/// One array of point data: a name and 1 or 3 components per point.
pub struct PointData<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

/// The text of a `.vtu` file: the mesh's cells on the points `positions` (flat `3N`, m) with the
/// point data arrays.
pub fn unstructured_grid(mesh: &Mesh, positions: &[f64], data: &[PointData]) -> String {
    let n = mesh.node_count();
    let cells = mesh.element_count();
    let per = mesh.kind().node_count();
    let mut x = String::with_capacity(64 * n + 16 * per * cells);
    x.push_str("<?xml version=\"1.0\"?>\n");
    x.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    x.push_str("<UnstructuredGrid>\n");
    let _ = writeln!(
        x,
        "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{cells}\">"
    );
    x.push_str("<PointData>\n");
    for d in data {
        let _ = writeln!(
            x,
            "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">",
            d.name, d.components
        );
        for chunk in d.values.chunks(d.components) {
            for v in chunk {
                let _ = write!(x, "{v:e} ");
            }
            x.push('\n');
        }
        x.push_str("</DataArray>\n");
    }
    x.push_str("</PointData>\n<Points>\n");
    x.push_str("<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in positions.chunks(3) {
        let _ = writeln!(x, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    x.push_str("</DataArray>\n</Points>\n<Cells>\n");
    x.push_str("<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for e in 0..cells {
        for node in mesh.element(e) {
            let _ = write!(x, "{node} ");
        }
        x.push('\n');
    }
    x.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for e in 0..cells {
        let _ = write!(x, "{} ", (e + 1) * per);
    }
    x.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let t = cell_type(mesh.kind());
    for _ in 0..cells {
        let _ = write!(x, "{t} ");
    }
    x.push_str("\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    x
}

/// Closing lines of a `.pvd` file.
const PVD_TAIL: &str = "</Collection>\n</VTKFile>\n";

/// A `.pvd` collection kept valid after every entry: each new entry overwrites the closing lines
/// and writes them again, so the file is never rewritten as a whole.
pub struct Collection {
    file: std::fs::File,
    /// Where the closing lines start.
    tail: u64,
}

impl Collection {
    /// Creates (truncates) the collection file.
    pub fn create(path: &std::path::Path) -> std::io::Result<Collection> {
        let mut file = std::fs::File::create(path)?;
        let head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n<Collection>\n";
        file.write_all(head.as_bytes())?;
        file.write_all(PVD_TAIL.as_bytes())?;
        Ok(Collection {
            file,
            tail: head.len() as u64,
        })
    }

    /// Adds a dataset at `time` (s); `file` relative to the collection's directory.
    pub fn add(&mut self, time: f64, file: &str) -> std::io::Result<()> {
        let entry = format!("<DataSet timestep=\"{time:e}\" part=\"0\" file=\"{file}\"/>\n");
        self.file.seek(SeekFrom::Start(self.tail))?;
        self.file.write_all(entry.as_bytes())?;
        self.file.write_all(PVD_TAIL.as_bytes())?;
        self.file.flush()?;
        self.tail += entry.len() as u64;
        Ok(())
    }
}
