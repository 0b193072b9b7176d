//! Structured meshes of boxes ("beams").

use super::{ElementKind, Mesh};
use crate::error::Result;

/// A box `[0, length] × [−width/2, width/2] × [−height/2, height/2]` (m) meshed with
/// `divisions = [nx, ny, nz]` elements of `kind`. The beam axis is x, width along y, height along z.
pub fn beam(
    length: f64,
    width: f64,
    height: f64,
    divisions: [usize; 3],
    kind: ElementKind,
) -> Result<Mesh> {
    let _ = (length, width, height, divisions, kind);
    todo!("beam generator")
}
