"""Generates the Gmsh meshes the Rust tests read (tests/data/*.msh), with the `gmsh` Python
package pinned in tests/python/requirements.txt:

    python tests/data/make_meshes.py          # from the repository root, in the venv

* b1_tet10.msh: docs/benchmarks.md B1's cantilever (1 m x 20 mm x 20 mm), 10-node tetrahedra of size
  10 mm, physical surfaces `root` (x = 0) and `tip` (x = 1 m), volume `solid`. ASCII.
* quarter_ring_tet10.msh / .bin.msh: a quarter of a thick ring (radii 0.3 and 0.5 m, 0.2 m
  high), tet10 with the mid-edge nodes on the curved surfaces (curved elements), surfaces
  `inner` and `outer`; the same mesh ASCII and binary.
* box_hex20.msh: a 0.3 x 0.2 x 0.1 m box of 3 x 2 x 1 transfinite 20-node hexahedra (Gmsh's
  hex20 node order), surface `left` (x = 0).

Gmsh numbers and orders deterministically for a given version and options: the files are
committed so that the Rust tests need no Python.
"""
import os
import sys

import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))


def start(name):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 1 if "-v" in sys.argv else 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.model.add(name)


def face_at(dim_tags, axis, value, tol=1e-6):
    """Surfaces of `dim_tags` lying in the plane x_axis = value."""
    out = []
    for dim, tag in dim_tags:
        box = gmsh.model.getBoundingBox(dim, tag)
        if abs(box[axis] - value) < tol and abs(box[axis + 3] - value) < tol:
            out.append(tag)
    return out


def b1_tet10():
    start("b1_tet10")
    volume = gmsh.model.occ.addBox(0, -0.01, -0.01, 1.0, 0.02, 0.02)
    gmsh.model.occ.synchronize()
    surfaces = gmsh.model.getBoundary([(3, volume)], oriented=False)
    gmsh.model.addPhysicalGroup(2, face_at(surfaces, 0, 0.0), name="root")
    gmsh.model.addPhysicalGroup(2, face_at(surfaces, 0, 1.0), name="tip")
    gmsh.model.addPhysicalGroup(3, [volume], name="solid")
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.01)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.01)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    gmsh.write(os.path.join(HERE, "b1_tet10.msh"))
    gmsh.finalize()


def quarter_ring():
    start("quarter_ring")
    outer = gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 0.2, 0.5, angle=3.141592653589793 / 2)
    inner = gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 0.2, 0.3, angle=3.141592653589793 / 2)
    (ring,), _ = gmsh.model.occ.cut([(3, outer)], [(3, inner)])
    gmsh.model.occ.synchronize()
    curved = {"inner": [], "outer": []}
    for dim, tag in gmsh.model.getBoundary([ring], oriented=False):
        if gmsh.model.getType(dim, tag) == "Cylinder":
            x, y, _ = gmsh.model.occ.getCenterOfMass(dim, tag)
            curved["inner" if x * x + y * y < 0.16 else "outer"].append(tag)
    gmsh.model.addPhysicalGroup(2, curved["inner"], name="inner")
    gmsh.model.addPhysicalGroup(2, curved["outer"], name="outer")
    gmsh.model.addPhysicalGroup(3, [ring[1]], name="solid")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.12)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)  # mid-edge nodes on the cylinders: curved elements
    gmsh.write(os.path.join(HERE, "quarter_ring_tet10.msh"))
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.write(os.path.join(HERE, "quarter_ring_tet10.bin.msh"))
    gmsh.finalize()


def box_hex20():
    start("box_hex20")
    volume = gmsh.model.occ.addBox(0, 0, 0, 0.3, 0.2, 0.1)
    gmsh.model.occ.synchronize()
    for dim, tag in gmsh.model.getEntities(1):
        lo = gmsh.model.getBoundingBox(dim, tag)
        length = max(lo[3] - lo[0], lo[4] - lo[1], lo[5] - lo[2])
        gmsh.model.mesh.setTransfiniteCurve(tag, int(round(length / 0.1)) + 1)
    for dim, tag in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(tag)
        gmsh.model.mesh.setRecombine(dim, tag)
    gmsh.model.mesh.setTransfiniteVolume(volume)
    surfaces = gmsh.model.getBoundary([(3, volume)], oriented=False)
    gmsh.model.addPhysicalGroup(2, face_at(surfaces, 0, 0.0), name="left")
    gmsh.model.addPhysicalGroup(3, [volume], name="solid")
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)  # serendipity: 20 nodes
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    gmsh.write(os.path.join(HERE, "box_hex20.msh"))
    gmsh.finalize()


if __name__ == "__main__":
    b1_tet10()
    quarter_ring()
    box_hex20()
