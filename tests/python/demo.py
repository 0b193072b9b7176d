"""`cargo xtask demo`: the default cantilever FMU (B1) under a step load, driven by fmpy.

A steel beam 1 m x 20 mm x 20 mm, clamped at the root, gets a tip force of -10 N along y
(`tip.force[2]`) at t = 0.01 s. Stiffness-proportional damping (`damping.beta` = 2 ms) lets it
settle within the second. Prints a table of the tip displacement and the root reaction, compares
the settled deflection with Timoshenko beam theory (1.19084e-3 m) and plots both to a PNG. The
FMU also writes ParaView files (`output.directory` = `<plot dir>/<plot stem>_vtk`, every 50 ms);
the last one is rendered with meshio and matplotlib (displacement exaggerated, coloured by the von
Mises stress) to `<plot stem>_deformed.png`.

Usage: python demo.py --fmu FILE --plot FILE.png
"""

import argparse
import pathlib
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import read_model_description, simulate_fmu  # noqa: E402

from flexbody_fmu import step_input  # noqa: E402

TIMOSHENKO_DEFLECTION = 1.19084e-3  # m
LOAD = 10.0  # N
T_STEP, T_END, H = 0.01, 1.0, 1e-3  # s
BETA = 2e-3  # s


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", required=True, help="the .fmu to run")
    parser.add_argument("--plot", required=True, help="where to write the PNG")
    args = parser.parse_args()

    md = read_model_description(args.fmu)
    print(f"{md.modelName}: {md.description}" if md.description else md.modelName)
    print(f"step load tip.force[2] = {-LOAD} N at t = {T_STEP} s, damping.beta = {BETA} s, "
          f"communication step {H} s, until t = {T_END} s")
    plot = pathlib.Path(args.plot)
    plot.parent.mkdir(parents=True, exist_ok=True)
    vtk_dir = plot.parent / f"{plot.stem}_vtk"
    wall = time.perf_counter()
    result = simulate_fmu(
        args.fmu,
        start_time=0.0,
        stop_time=T_END,
        output_interval=H,
        start_values={"damping.beta": BETA, "output.directory": str(vtk_dir), "output.interval": 0.05},
        input=step_input(md, "tip.force[2]", -LOAD, T_STEP, T_END),
        output=["tip.position[2]", "root.force[2]"],
    )
    wall = time.perf_counter() - wall
    t = result["time"]
    deflection = result["tip.position[2]"] - result["tip.position[2]"][0]
    reaction = result["root.force[2]"]

    print()
    print(f"{'t (s)':>8}  {'tip displacement y (mm)':>24}  {'root force y (N)':>17}")
    for t_row in [0.0, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0]:
        k = int(np.argmin(np.abs(t - t_row)))
        print(f"{t[k]:8.3f}  {deflection[k] * 1e3 + 0.0:24.5f}  {reaction[k] + 0.0:17.4f}")

    settled = deflection[-1]
    error = (abs(settled) - TIMOSHENKO_DEFLECTION) / TIMOSHENKO_DEFLECTION
    print()
    print(f"settled tip deflection {settled:.6e} m; Timoshenko {-TIMOSHENKO_DEFLECTION:.6e} m; "
          f"error {100 * error:+.3f} %")
    print(f"settled root reaction {reaction[-1]:.5f} N (balances the {LOAD} N load: "
          f"{100 * (reaction[-1] - LOAD) / LOAD:+.3f} %)")
    print(f"{len(t) - 1} communication steps in {wall:.2f} s wall time "
          f"({1e3 * wall / max(len(t) - 1, 1):.2f} ms per step, including instantiation)")

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    ax1.plot(t, deflection * 1e3, label="FMU: tip.position[2] - start")
    ax1.axhline(-TIMOSHENKO_DEFLECTION * 1e3, color="k", linestyle="--", label="Timoshenko static")
    ax1.set_ylabel("tip displacement y (mm)")
    ax1.legend(loc="upper right")
    ax1.grid(True)
    ax2.plot(t, reaction, color="tab:red", label="FMU: root.force[2]")
    ax2.axhline(LOAD, color="k", linestyle="--", label="static reaction")
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("root reaction y (N)")
    ax2.legend(loc="center right")
    ax2.grid(True)
    fig.suptitle(f"flexbody {md.modelName}: {-LOAD} N step at the tip, damping.beta = {BETA} s")
    fig.tight_layout()
    fig.savefig(plot, dpi=120)
    print(f"plot: {plot.resolve()}")
    picture = plot.with_name(f"{plot.stem}_deformed.png")
    render_last_state(vtk_dir / f"{md.modelName}.pvd", picture)
    print(f"deformed mesh: {picture.resolve()} (ParaView: open {(vtk_dir / f'{md.modelName}.pvd').resolve()})")


# Corner-node faces of the VTK hexahedron and tetrahedron (outward order irrelevant here).
FACES = {
    8: [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)],
    4: [(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)],
}


def render_last_state(pvd, picture, exaggeration=50.0):
    """The boundary faces of the last saved state, displacement times `exaggeration`, coloured
    by the von Mises stress (matplotlib 3D; meshio reads the .vtu)."""
    import xml.etree.ElementTree as ET

    import meshio
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    last = ET.parse(pvd).getroot().find("Collection").findall("DataSet")[-1]
    mesh = meshio.read(pvd.parent / last.get("file"))
    displacement = mesh.point_data["displacement"]
    points = mesh.points - displacement + exaggeration * displacement
    stress = mesh.point_data["vonMises"]
    cells = mesh.cells[0].data
    corners = 8 if cells.shape[1] in (8, 20) else 4
    count = {}
    for cell in cells[:, :corners]:
        for face in FACES[corners]:
            key = tuple(sorted(cell[list(face)]))
            count[key] = (count.get(key, (0, None))[0] + 1, cell[list(face)])
    faces = [nodes for n, nodes in count.values() if n == 1]
    polygons = [points[f] for f in faces]
    colours = np.array([stress[f].mean() for f in faces])
    fig = plt.figure(figsize=(10, 4.5))
    ax = fig.add_subplot(projection="3d")
    norm = matplotlib.colors.Normalize(vmin=0.0, vmax=max(colours.max(), 1.0))
    ax.add_collection3d(Poly3DCollection(polygons, facecolors=plt.cm.viridis(norm(colours)),
                                         edgecolors="k", linewidths=0.2))
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, extent = (lo + hi) / 2, np.maximum(hi - lo, 0.2 * (hi - lo).max())
    for setter, c, e in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, extent):
        setter(c - 0.55 * e, c + 0.55 * e)
    ax.set_box_aspect(tuple(extent / extent.max()))  # true scale where the part is not slender
    ax.view_init(elev=25, azim=-75)
    ax.locator_params(axis="y", nbins=3)
    ax.locator_params(axis="z", nbins=3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, shrink=0.7, label="von Mises (Pa)")
    ax.set_title(f"t = {float(last.get('timestep')):.3f} s, displacement x {exaggeration:g}")
    fig.tight_layout()
    fig.savefig(picture, dpi=120)


if __name__ == "__main__":
    main()
