//! Import of Gmsh meshes (MSH file format 4.1, ASCII or binary) with the `mshio` parser.
//!
//! * The volume (3D) elements make the mesh. They must all be of one supported kind: 4- or
//!   10-node tetrahedra (Gmsh types 4 and 11) or 8- or 20-node hexahedra (types 5 and 17).
//!   Gmsh's node order is VTK's except for Tet10 (Gmsh's local nodes 8 and 9, on edges 2-3 and
//!   1-3, are VTK's 9 and 8) and Hex20 (mid-edge nodes in another edge order): both are permuted
//!   to the VTK order of [`crate::element`] here ([`TET10_FROM_GMSH`], [`HEX20_FROM_GMSH`]).
//! * Nodes used by no volume element are dropped; the others are numbered by ascending Gmsh tag.
//! * Every physical group (of any dimension: points, curves, surfaces, volumes) becomes a named
//!   node set, the nodes of its elements: `$PhysicalNames` gives the names (a group without a
//!   name is called `"<dim>:<tag>"`), the `$Entities` section which entities belong to which
//!   group. Body files select such a set with `{ "group": "name" }`. Groups of the same name and
//!   different dimension are merged.
//! * Coordinates are multiplied by `scale` (e.g. 1e-3 for a mesh drawn in mm).
//!
//! With contiguous node tags MSH 4.1 files do not need the tags per block; `mshio` then numbers
//! the nodes of the blocks consecutively from the smallest tag in file order, as Gmsh writes them.

use super::{ElementKind, Mesh};
use crate::error::{Error, Result};
use mshio::{ElementType, MshFile};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// `vtk[i] = gmsh[TET10_FROM_GMSH[i]]`: Gmsh's nodes 8 (edge 2-3) and 9 (edge 1-3) swapped.
pub const TET10_FROM_GMSH: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];

/// `vtk[i] = gmsh[HEX20_FROM_GMSH[i]]`. Gmsh orders the Hex20 edges 0-1, 0-3, 0-4, 1-2, 1-5,
/// 2-3, 2-6, 3-7, 4-5, 4-7, 5-6, 6-7 (nodes 8–19); VTK 0-1, 1-2, 2-3, 3-0, 4-5, 5-6, 6-7, 7-4,
/// 0-4, 1-5, 2-6, 3-7.
pub const HEX20_FROM_GMSH: [usize; 20] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15,
];

/// Reads a Gmsh `.msh` file (module documentation); errors name the file.
pub fn read(path: &Path, scale: f64) -> Result<Mesh> {
    let bytes = std::fs::read(path).map_err(|e| {
        Error::new(format!(
            "cannot read the Gmsh mesh file {}: {e}",
            path.display()
        ))
    })?;
    parse(&bytes, scale).map_err(|e| Error::new(format!("{}: {}", path.display(), e.message)))
}

/// A readable name of a Gmsh element type.
fn type_name(t: ElementType) -> String {
    let described = match t {
        ElementType::Tet4 => "4-node tetrahedron",
        ElementType::Tet10 => "10-node tetrahedron",
        ElementType::Hex8 => "8-node hexahedron",
        ElementType::Hex20 => "20-node hexahedron",
        ElementType::Hex27 => "27-node hexahedron",
        ElementType::Pri6 => "6-node prism",
        ElementType::Pri15 => "15-node prism",
        ElementType::Pri18 => "18-node prism",
        ElementType::Pyr5 => "5-node pyramid",
        ElementType::Pyr13 => "13-node pyramid",
        ElementType::Pyr14 => "14-node pyramid",
        ElementType::Tet20 => "20-node (cubic) tetrahedron",
        _ => "",
    };
    let code = t as i32;
    if described.is_empty() {
        format!("{t:?} (Gmsh type {code})")
    } else {
        format!("{t:?} ({described}, Gmsh type {code})")
    }
}

/// The `MeshFormat` line: version and file type (0 ASCII, 1 binary). Checked before `mshio`
/// parses, so that a file of another version gets a message saying so.
fn check_header(bytes: &[u8]) -> Result<()> {
    let text_start = &bytes[..bytes.len().min(256)];
    let head = String::from_utf8_lossy(text_start);
    let mut lines = head.lines().map(str::trim);
    if lines.next() != Some("$MeshFormat") {
        return Err(Error::new(
            "not a Gmsh mesh file: it does not start with $MeshFormat",
        ));
    }
    let format = lines.next().unwrap_or("");
    let version = format.split_whitespace().next().unwrap_or("");
    if version != "4.1" {
        return Err(Error::new(format!(
            "MSH file format version '{version}' is not supported: only 4.1 is read (in Gmsh: \
             Mesh.MshFileVersion = 4.1, or File > Export > Version 4 ASCII/binary)"
        )));
    }
    Ok(())
}

/// `$PhysicalNames`: (dimension, tag) → name. The section is text even in binary files.
fn physical_names(bytes: &[u8]) -> Result<HashMap<(i32, i32), String>> {
    let mut names = HashMap::new();
    let find = |needle: &[u8]| bytes.windows(needle.len()).position(|w| w == needle);
    let Some(start) = find(b"\n$PhysicalNames") else {
        return Ok(names);
    };
    let body = &bytes[start + b"\n$PhysicalNames".len()..];
    let end = body
        .windows(b"$EndPhysicalNames".len())
        .position(|w| w == b"$EndPhysicalNames")
        .ok_or_else(|| Error::new("$PhysicalNames section without $EndPhysicalNames"))?;
    let text = String::from_utf8_lossy(&body[..end]);
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let count: usize = lines
        .next()
        .and_then(|l| l.parse().ok())
        .ok_or_else(|| Error::new("$PhysicalNames: the first line must be the group count"))?;
    for _ in 0..count {
        let line = lines
            .next()
            .ok_or_else(|| Error::new(format!("$PhysicalNames: fewer than {count} groups")))?;
        let bad = || Error::new(format!("$PhysicalNames: cannot read line '{line}'"));
        let mut fields = line.splitn(3, char::is_whitespace);
        let dim: i32 = fields.next().and_then(|f| f.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = fields.next().and_then(|f| f.parse().ok()).ok_or_else(bad)?;
        let name = fields.next().ok_or_else(bad)?.trim().trim_matches('"');
        names.insert((dim, tag), name.to_string());
    }
    Ok(names)
}

/// Parses the bytes of a `.msh` file (module documentation).
pub fn parse(bytes: &[u8], scale: f64) -> Result<Mesh> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(Error::invalid_value(
            "gmsh.scale",
            scale,
            "must be positive and finite",
        ));
    }
    check_header(bytes)?;
    let names = physical_names(bytes)?;
    // mshio reports malformed input as errors, but a few corner cases still end in `expect`:
    // a panic here must become an error too.
    let parsed = std::panic::catch_unwind(|| {
        mshio::parse_msh_bytes(bytes).map_err(|e| {
            let mut message = e
                .to_string()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ");
            if message.len() > 600 {
                let mut cut = 600;
                while !message.is_char_boundary(cut) {
                    cut -= 1;
                }
                message.truncate(cut);
                message.push_str(" …");
            }
            message
        })
    });
    let msh = match parsed {
        Ok(Ok(msh)) => msh,
        Ok(Err(message)) => {
            return Err(Error::new(format!(
                "not a valid MSH 4.1 file (truncated or corrupt?): {message}"
            )))
        }
        Err(_) => {
            return Err(Error::new(
                "not a valid MSH 4.1 file (truncated or corrupt?): the parser failed",
            ))
        }
    };
    convert(&msh, &names, scale)
}

/// Builds the mesh and its groups from a parsed file.
fn convert(
    msh: &MshFile<u64, i32, f64>,
    names: &HashMap<(i32, i32), String>,
    scale: f64,
) -> Result<Mesh> {
    let nodes = msh
        .data
        .nodes
        .as_ref()
        .ok_or_else(|| Error::new("the file has no $Nodes section"))?;
    let elements = msh
        .data
        .elements
        .as_ref()
        .ok_or_else(|| Error::new("the file has no $Elements section"))?;

    // Node tag → coordinates (m).
    let mut coordinates: HashMap<u64, [f64; 3]> = HashMap::new();
    let mut next_tag = nodes.min_node_tag;
    for block in &nodes.node_blocks {
        match &block.node_tags {
            Some(tags) => {
                for (&tag, &i) in tags {
                    let p = &block.nodes[i];
                    coordinates.insert(tag, [p.x * scale, p.y * scale, p.z * scale]);
                }
            }
            None => {
                for p in &block.nodes {
                    coordinates.insert(next_tag, [p.x * scale, p.y * scale, p.z * scale]);
                    next_tag += 1;
                }
            }
        }
    }

    // The volume elements: one supported kind.
    let mut kind: Option<(ElementKind, ElementType)> = None;
    let mut volume_tags: Vec<u64> = Vec::new(); // Gmsh node tags, VTK order, flat
    let mut element_tags: Vec<u64> = Vec::new(); // Gmsh tag of each volume element
    let mut element_count = 0usize;
    for block in elements.element_blocks.iter().filter(|b| b.entity_dim == 3) {
        let t = block.element_type;
        let this = match t {
            ElementType::Tet4 => ElementKind::Tet4,
            ElementType::Tet10 => ElementKind::Tet10,
            ElementType::Hex8 => ElementKind::Hex8,
            ElementType::Hex20 => ElementKind::Hex20,
            other => {
                return Err(Error::new(format!(
                    "volume entity {}: element type {} is not supported (supported: 4- and \
                     10-node tetrahedra, 8- and 20-node hexahedra)",
                    block.entity_tag,
                    type_name(other)
                )))
            }
        };
        match kind {
            None => kind = Some((this, t)),
            Some((k, first)) if k != this => {
                return Err(Error::new(format!(
                    "mixed volume element types {} and {} (volume entity {}): a mesh must use one \
                     element type",
                    type_name(first),
                    type_name(t),
                    block.entity_tag
                )))
            }
            _ => {}
        }
        let n = this.node_count();
        for element in &block.elements {
            if element.nodes.len() != n {
                return Err(Error::new(format!(
                    "element {} has {} nodes, {} expected for {}",
                    element.element_tag,
                    element.nodes.len(),
                    n,
                    type_name(t)
                )));
            }
            match this {
                ElementKind::Tet10 => {
                    volume_tags.extend(TET10_FROM_GMSH.iter().map(|&g| element.nodes[g]))
                }
                ElementKind::Hex20 => {
                    volume_tags.extend(HEX20_FROM_GMSH.iter().map(|&g| element.nodes[g]))
                }
                _ => volume_tags.extend_from_slice(&element.nodes),
            }
            element_tags.push(element.element_tag);
            element_count += 1;
        }
    }
    let (kind, _) = kind.ok_or_else(|| {
        Error::new(
            "the file has no volume (3D) elements: mesh the volume (Gmsh: Mesh > 3D, or gmsh -3)",
        )
    })?;

    // Nodes used by volume elements, by ascending tag.
    let mut used: Vec<u64> = volume_tags.clone();
    used.sort_unstable();
    used.dedup();
    let mut index: HashMap<u64, usize> = HashMap::with_capacity(used.len());
    let mut positions = Vec::with_capacity(used.len());
    for (i, &tag) in used.iter().enumerate() {
        let p = coordinates.get(&tag).ok_or_else(|| {
            Error::new(format!(
                "a volume element refers to node {tag}, which is not in the $Nodes section"
            ))
        })?;
        index.insert(tag, i);
        positions.push(*p);
    }
    let connectivity: Vec<usize> = volume_tags.iter().map(|t| index[t]).collect();
    debug_assert_eq!(connectivity.len(), element_count * kind.node_count());
    // Mesh::new names elements by index: add the Gmsh element tag.
    let mesh = Mesh::new(positions, kind, connectivity).map_err(|e| {
        let tag = e
            .message
            .strip_prefix("mesh: element ")
            .and_then(|rest| rest.split(' ').next())
            .and_then(|index| index.parse::<usize>().ok())
            .and_then(|index| element_tags.get(index));
        match tag {
            Some(tag) => Error::new(format!("{} (Gmsh element {tag})", e.message)),
            None => e,
        }
    })?;

    // Physical groups: entity (dim, tag) → physical tags, then the nodes of the elements.
    let mut entity_groups: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
    if let Some(entities) = &msh.data.entities {
        for p in &entities.points {
            entity_groups.insert((0, p.tag), p.physical_tags.clone());
        }
        for c in &entities.curves {
            entity_groups.insert((1, c.tag), c.physical_tags.clone());
        }
        for s in &entities.surfaces {
            entity_groups.insert((2, s.tag), s.physical_tags.clone());
        }
        for v in &entities.volumes {
            entity_groups.insert((3, v.tag), v.physical_tags.clone());
        }
    }
    let mut groups: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for block in &elements.element_blocks {
        let Some(physical) = entity_groups.get(&(block.entity_dim, block.entity_tag)) else {
            continue;
        };
        for &p in physical {
            let dim = block.entity_dim;
            let name = names
                .get(&(dim, p.abs()))
                .cloned()
                .unwrap_or_else(|| format!("{dim}:{}", p.abs()));
            let set = groups.entry(name.clone()).or_default();
            for element in &block.elements {
                for tag in &element.nodes {
                    let i = index.get(tag).ok_or_else(|| {
                        Error::new(format!(
                            "physical group '{name}' holds node {tag}, which belongs to no volume \
                             element"
                        ))
                    })?;
                    set.push(*i);
                }
            }
        }
    }
    mesh.with_groups(groups)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One unit tetrahedron, ASCII MSH 4.1 with a surface group `bottom` (the face z = 0) and a
    /// volume group `solid`.
    const ONE_TET: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
2 1 \"bottom\"
3 2 \"solid\"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 1 0 1 1 0
1 0 0 0 1 1 1 1 2 1 1
$EndEntities
$Nodes
2 4 1 4
2 1 0 3
1
2
3
0 0 0
1 0 0
0 1 0
3 1 0 1
4
0 0 1
$EndNodes
$Elements
2 2 1 2
2 1 2 1
1 1 3 2
3 1 4 1
2 1 2 3 4
$EndElements
";

    #[test]
    fn reads_a_tetrahedron_with_groups() {
        let mesh = parse(ONE_TET.as_bytes(), 2.0).unwrap();
        assert_eq!(mesh.kind(), ElementKind::Tet4);
        assert_eq!(mesh.node_count(), 4);
        assert_eq!(mesh.nodes()[3], [0.0, 0.0, 2.0]);
        assert_eq!(mesh.group("bottom").unwrap(), &[0, 1, 2]);
        assert_eq!(mesh.group("solid").unwrap(), &[0, 1, 2, 3]);
        let names: Vec<&str> = mesh.group_names().collect();
        assert_eq!(names, ["bottom", "solid"]);
    }

    #[test]
    fn bad_files_give_clear_errors() {
        let e = parse(b"hello", 1.0).unwrap_err();
        assert!(
            e.message.contains("does not start with $MeshFormat"),
            "{}",
            e.message
        );
        let old = ONE_TET.replace("4.1 0 8", "2.2 0 8");
        let e = parse(old.as_bytes(), 1.0).unwrap_err();
        assert!(
            e.message.contains("version '2.2' is not supported"),
            "{}",
            e.message
        );
        let truncated = &ONE_TET[..ONE_TET.find("$Elements").unwrap() + 20];
        let e = parse(truncated.as_bytes(), 1.0).unwrap_err();
        assert!(
            e.message.contains("not a valid MSH 4.1 file"),
            "{}",
            e.message
        );
        let e = parse(ONE_TET.as_bytes(), -1.0).unwrap_err();
        assert!(e.message.contains("gmsh.scale = -1"), "{}", e.message);
        // A prism instead of the tetrahedron (6 nodes; only 4 exist, but the type is caught first).
        let prism = ONE_TET.replace("3 1 4 1\n2 1 2 3 4", "3 1 6 1\n2 1 2 3 4 1 2");
        let e = parse(prism.as_bytes(), 1.0).unwrap_err();
        assert!(
            e.message
                .contains("Pri6 (6-node prism, Gmsh type 6) is not supported"),
            "{}",
            e.message
        );
        // Inverted: swap two vertices.
        let inverted = ONE_TET.replace("2 1 2 3 4", "2 2 1 3 4");
        let e = parse(inverted.as_bytes(), 1.0).unwrap_err();
        assert!(
            e.message.contains("element 0 is inverted") && e.message.contains("(Gmsh element 2)"),
            "{}",
            e.message
        );
        // Only surface elements.
        let flat = ONE_TET
            .replace("2 2 1 2\n", "1 1 1 1\n")
            .replace("3 1 4 1\n2 1 2 3 4\n", "");
        let e = parse(flat.as_bytes(), 1.0).unwrap_err();
        assert!(
            e.message.contains("no volume (3D) elements"),
            "{}",
            e.message
        );
    }
}
