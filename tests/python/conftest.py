"""Fixtures shared by the fmpy tests of the packaged FMU.

`cargo xtask test` builds the FMU and passes its path in ``FLEXBODY_FMU``; without it the tests
look for ``target/fmu/cantilever.fmu`` (what ``cargo xtask fmu`` writes) and fail if it is absent.
"""

import os
import pathlib

import pytest
from fmpy import extract, read_model_description

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def fmu_path() -> str:
    path = pathlib.Path(os.environ.get("FLEXBODY_FMU") or REPO / "target" / "fmu" / "cantilever.fmu")
    if not path.is_file():
        pytest.fail(f"no FMU at {path}: run `cargo xtask test`, or `cargo xtask fmu` and set FLEXBODY_FMU")
    return str(path)


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
