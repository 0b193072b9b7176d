"""Fixtures shared by the fmpy tests of the packaged FMUs.

`cargo xtask test` builds the default FMU (``examples/cantilever.json``; also as FMI 3.0, ``FLEXBODY_FMU3``) and the driven cantilever
(``examples/driven_cantilever.json``, root clamped to an input frame) and passes their paths in
``FLEXBODY_FMU`` and ``FLEXBODY_DRIVEN_FMU``; without them the tests look for
``target/fmu/cantilever.fmu`` and ``target/fmu/driven_cantilever.fmu`` (what
``cargo xtask fmu [--body examples/driven_cantilever.json]`` writes) and fail if they are absent.
"""

import os
import pathlib

import pytest
from fmpy import extract, read_model_description

REPO = pathlib.Path(__file__).resolve().parents[2]


def _packaged_fmu(variable: str, file_name: str, build: str) -> str:
    path = pathlib.Path(os.environ.get(variable) or REPO / "target" / "fmu" / file_name)
    if not path.is_file():
        pytest.fail(f"no FMU at {path}: run `cargo xtask test`, or `{build}` and set {variable}")
    return str(path)


@pytest.fixture(scope="session")
def fmu_path() -> str:
    return _packaged_fmu("FLEXBODY_FMU", "cantilever.fmu", "cargo xtask fmu")


@pytest.fixture(scope="session")
def model_description(fmu_path):
    return read_model_description(fmu_path)


@pytest.fixture(scope="session")
def unzipdir(fmu_path, tmp_path_factory) -> str:
    """The FMU extracted once per session (what fmpy's FMU2Slave loads the library from)."""
    return extract(fmu_path, unzipdir=str(tmp_path_factory.mktemp("fmu")))


@pytest.fixture(scope="session")
def vr(model_description) -> dict:
    """Value reference by variable name."""
    return {v.name: v.valueReference for v in model_description.modelVariables}


@pytest.fixture(scope="session")
def driven_fmu_path() -> str:
    """The driven cantilever: B1's beam with its root face clamped to the motion interface 'root'."""
    return _packaged_fmu(
        "FLEXBODY_DRIVEN_FMU", "driven_cantilever.fmu", "cargo xtask fmu --body examples/driven_cantilever.json"
    )


@pytest.fixture(scope="session")
def driven_model_description(driven_fmu_path):
    return read_model_description(driven_fmu_path)


@pytest.fixture(scope="session")
def driven_unzipdir(driven_fmu_path, tmp_path_factory) -> str:
    return extract(driven_fmu_path, unzipdir=str(tmp_path_factory.mktemp("driven_fmu")))


@pytest.fixture(scope="session")
def conrod_fmu_path() -> str:
    """The connecting rod: a Gmsh tet10 mesh in resources/, big eye a motion interface, small eye a force
    interface (examples/conrod.json)."""
    return _packaged_fmu("FLEXBODY_CONROD_FMU", "conrod.fmu", "cargo xtask fmu --body examples/conrod.json")


@pytest.fixture(scope="session")
def fmu3_path() -> str:
    """The default body as an FMI 3.0 FMU (``cargo xtask fmu --fmi 3``)."""
    return _packaged_fmu("FLEXBODY_FMU3", "cantilever-fmi3.fmu", "cargo xtask fmu --fmi 3")


@pytest.fixture(scope="session")
def arm_fmu_path() -> str:
    """Kane's beam on a hinge with a rigid hub that takes a motor torque (examples/controlled_arm.json)."""
    return _packaged_fmu("FLEXBODY_ARM_FMU", "controlled_arm.fmu", "cargo xtask fmu --body examples/controlled_arm.json")


@pytest.fixture(scope="session")
def arm_model_description(arm_fmu_path):
    return read_model_description(arm_fmu_path)


@pytest.fixture(scope="session")
def arm_unzipdir(arm_fmu_path, tmp_path_factory) -> str:
    return extract(arm_fmu_path, unzipdir=str(tmp_path_factory.mktemp("arm_fmu")))
