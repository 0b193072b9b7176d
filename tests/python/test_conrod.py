"""The connecting rod FMU (examples/conrod.json): a Gmsh tet10 part packaged with its mesh, run by
fmpy with the big eye driven (motion interface) and the small eye loaded (force interface), with
ParaView results (`output.directory`) read back by meshio; and a malformed mesh in resources/
that makes instantiation fail with a logged message."""

import pathlib
import shutil
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import fmi2Error

from flexbody_fmu import Instance

CENTRE_DISTANCE = 0.15  # m, big eye at the origin, small eye at (0.15, 0, 0)
SMALL_BORE, BIG_BORE = 0.010, 0.022  # m
T_END, H = 4e-3, 5e-4  # s
SPEED = 0.5  # m/s: the big eye moves along y
LOAD = -2000.0  # N: compressive load on the small eye (along the rod, -x)


def motion_input(model_description):
    """The big eye translates at SPEED along y; the small eye takes LOAD along x from t = 0."""
    names = [v.name for v in model_description.modelVariables if v.causality == "input"]
    rows = []
    for t in (0.0, T_END + H):
        values = {n: 0.0 for n in names}
        for k in (1, 5, 9):
            values[f"big_eye.rotation[{k}]"] = 1.0
        values["big_eye.position[2]"] = SPEED * t
        values["big_eye.velocity[2]"] = SPEED
        values["small_eye.force[1]"] = LOAD
        rows.append(tuple([t] + [values[n] for n in names]))
    return np.array(rows, dtype=[("time", np.float64)] + [(n, np.float64) for n in names])


def test_driven_and_loaded_conrod_writes_paraview_files(conrod_fmu_path, tmp_path):
    md = read_model_description(conrod_fmu_path)
    directory = tmp_path / "vtk"
    result = simulate_fmu(
        conrod_fmu_path,
        stop_time=T_END,
        output_interval=H,
        start_values={"output.directory": str(directory), "output.interval": 1e-3},
        input=motion_input(md),
        output=["small_eye.position[1]", "small_eye.position[2]", "big_eye.force[1]", "big_eye.position[2]"],
    )
    for name in result.dtype.names:
        assert np.all(np.isfinite(result[name])), name
    # The driven eye follows its input; the rod goes along (rigid motion plus deformation).
    assert result["small_eye.position[2]"][-1] == pytest.approx(SPEED * T_END, rel=0.05)
    # The small eye is pushed towards the big eye: the rod shortens.
    assert result["small_eye.position[1]"][-1] < CENTRE_DISTANCE

    # The .pvd lists the saved times (every 1 ms from 0): each .vtu opens in meshio.
    pvd = directory / "conrod.pvd"
    datasets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    times = [float(d.get("timestep")) for d in datasets]
    assert times == pytest.approx([0.0, 1e-3, 2e-3, 3e-3, 4e-3], abs=1e-9)
    for d in datasets:
        mesh = meshio.read(directory / d.get("file"))
        assert [c.type for c in mesh.cells] == ["tetra10"]
        for name, width in (("displacement", 3), ("velocity", 3), ("deformation", 3), ("vonMises", 1)):
            values = np.asarray(mesh.point_data[name]).reshape(len(mesh.points), -1)
            assert values.shape[1] == width, name
            assert np.all(np.isfinite(values)), name
    # In the last state, relative to the driving frame (a pure translation by SPEED t along y):
    # the big eye is clamped to it, the loaded small eye has moved (the rod shortened); the rod
    # carries stress.
    reference = mesh.points - mesh.point_data["displacement"]
    r_small = np.hypot(reference[:, 0] - CENTRE_DISTANCE, reference[:, 1])
    r_big = np.hypot(reference[:, 0], reference[:, 1])
    small = np.abs(r_small - SMALL_BORE) < 1e-6
    big = np.abs(r_big - BIG_BORE) < 1e-6
    assert small.sum() > 10 and big.sum() > 10
    relative = mesh.point_data["displacement"] - np.array([0.0, SPEED * times[-1], 0.0])
    assert np.abs(relative[big]).max() < 1e-9
    assert relative[small, 0].mean() < -1e-7  # pushed towards the big eye
    assert np.linalg.norm(mesh.point_data["deformation"], axis=1)[small].mean() > 1e-7
    assert np.max(mesh.point_data["vonMises"]) > 1e5


def test_malformed_mesh_fails_instantiation_with_a_logged_message(conrod_fmu_path, tmp_path):
    md = read_model_description(conrod_fmu_path)
    unzipdir = pathlib.Path(extract(conrod_fmu_path, unzipdir=str(tmp_path / "fmu")))
    msh = unzipdir / "resources" / "conrod" / "conrod.msh"
    text = msh.read_bytes()
    msh.write_bytes(text[: len(text) // 3])  # truncated
    with pytest.raises(Exception):
        Instance(str(unzipdir), md, "conrod-truncated")
    from flexbody_fmu import LOG

    errors = [r for r in LOG if r.instance_name == "conrod-truncated" and r.status == fmi2Error]
    assert errors, "no error logged"
    message = errors[-1].message
    assert "conrod.msh" in message and "not a valid MSH 4.1 file" in message, message
    shutil.rmtree(unzipdir)
