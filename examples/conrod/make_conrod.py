"""Generates examples/conrod/conrod.msh: a steel connecting rod meshed with 10-node tetrahedra by
Gmsh (the `gmsh` Python package pinned in tests/python/requirements.txt):

    python examples/conrod/make_conrod.py       # from the repository root, in the venv

Geometry (m), in the x-y plane, thickness along z:

* big eye: centre (0, 0), bore radius 0.022, outer radius 0.036, 0.022 thick;
* small eye: centre (0.15, 0), bore radius 0.010, outer radius 0.018, 0.018 thick;
* shank: a web 0.010 thick whose width tapers from 0.030 at the big eye to 0.018 at the small eye.

Physical groups: the bore surfaces `big_eye` and `small_eye` (what examples/conrod.json's
interfaces select) and the volume `solid`. Element size 8 mm, 4 mm around the small eye;
second-order nodes on the curved surfaces.
"""
import math
import os
import sys

import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))
CENTRE_DISTANCE = 0.15
BIG = {"bore": 0.022, "outer": 0.036, "thickness": 0.022}
SMALL = {"bore": 0.010, "outer": 0.018, "thickness": 0.018}
WEB = {"thickness": 0.010, "big_width": 0.030, "small_width": 0.018}


def main():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 1 if "-v" in sys.argv else 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.model.add("conrod")
    occ = gmsh.model.occ

    def eye(x, spec):
        t = spec["thickness"]
        return occ.addCylinder(x, 0, -t / 2, 0, 0, t, spec["outer"])

    big = eye(0.0, BIG)
    small = eye(CENTRE_DISTANCE, SMALL)
    # The web: a tapered prism from the big eye's centre to the small eye's centre.
    t = WEB["thickness"]
    corners = [
        (0.0, -WEB["big_width"] / 2),
        (CENTRE_DISTANCE, -WEB["small_width"] / 2),
        (CENTRE_DISTANCE, WEB["small_width"] / 2),
        (0.0, WEB["big_width"] / 2),
    ]
    points = [occ.addPoint(x, y, -t / 2) for x, y in corners]
    lines = [occ.addLine(points[i], points[(i + 1) % 4]) for i in range(4)]
    face = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    web = occ.extrude([(2, face)], 0, 0, t)
    web_volume = [dt for dt in web if dt[0] == 3]
    rod, _ = occ.fuse([(3, big)], [(3, small)] + web_volume)
    bores = [
        occ.addCylinder(0, 0, -BIG["thickness"], 0, 0, 2 * BIG["thickness"], BIG["bore"]),
        occ.addCylinder(
            CENTRE_DISTANCE, 0, -SMALL["thickness"], 0, 0, 2 * SMALL["thickness"], SMALL["bore"]
        ),
    ]
    rod, _ = occ.cut(rod, [(3, b) for b in bores])
    occ.synchronize()
    assert len(rod) == 1, rod
    volume = rod[0][1]

    groups = {"big_eye": [], "small_eye": []}
    for dim, tag in gmsh.model.getBoundary(rod, oriented=False):
        if gmsh.model.getType(dim, tag) != "Cylinder":
            continue
        x, y, _ = occ.getCenterOfMass(dim, tag)
        # A bore's surface has its centre of mass on the axis; an outer surface does not
        # (it is cut by the web) or has the outer radius.
        lo = gmsh.model.getBoundingBox(dim, tag)
        radius = (lo[3] - lo[0]) / 2
        if abs(radius - BIG["bore"]) < 1e-6 and math.hypot(x, y) < 1e-6:
            groups["big_eye"].append(tag)
        elif abs(radius - SMALL["bore"]) < 1e-6 and math.hypot(x - CENTRE_DISTANCE, y) < 1e-6:
            groups["small_eye"].append(tag)
    for name, tags in groups.items():
        assert tags, name
        gmsh.model.addPhysicalGroup(2, tags, name=name)
    gmsh.model.addPhysicalGroup(3, [volume], name="solid")

    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.005)
    field = gmsh.model.mesh.field.add("Ball")
    gmsh.model.mesh.field.setNumber(field, "Radius", SMALL["outer"] + 0.004)
    gmsh.model.mesh.field.setNumber(field, "XCenter", CENTRE_DISTANCE)
    gmsh.model.mesh.field.setNumber(field, "VIn", 0.004)
    gmsh.model.mesh.field.setNumber(field, "VOut", 0.008)
    gmsh.model.mesh.field.setAsBackgroundMesh(field)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    out = os.path.join(HERE, "conrod.msh")
    gmsh.write(out)
    nodes = len(gmsh.model.mesh.getNodes()[0])
    print(f"wrote {out}: {nodes} nodes ({3 * nodes} DOF)")
    gmsh.finalize()


if __name__ == "__main__":
    main()
