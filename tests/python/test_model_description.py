"""The packaged FMU as an importer sees it before running it: archive layout, fmpy's validation,
the variables of docs/fmu.md with their units, and the declared capabilities."""

import json
import zipfile

import pytest
from fmpy.validation import validate_fmu

from conftest import REPO

MODEL_IDENTIFIER = "flexbody"


def test_fmpy_finds_no_problems(fmu_path):
    assert validate_fmu(fmu_path) == []


def test_fmpy_finds_no_problems_in_the_motion_driven_fmu(driven_fmu_path, driven_model_description):
    # Motion inputs (rotation start = identity, position start = the reference point) and the
    # enumerations model.formulation / model.stiffening with their TypeDefinitions.
    assert validate_fmu(driven_fmu_path) == []
    starts = {v.name: v.start for v in driven_model_description.modelVariables}
    assert [float(starts[f"root.rotation[{k}]"]) for k in range(1, 10)] == [1, 0, 0, 0, 1, 0, 0, 0, 1]
    types = {t.name: [item.name for item in t.items] for t in driven_model_description.typeDefinitions}
    assert types["Formulation"] == ["reducedStrain", "full"]
    assert types["Stiffening"] == ["none", "inertial", "stress"]


def test_archive_layout(fmu_path):
    with zipfile.ZipFile(fmu_path) as fmu:
        names = set(fmu.namelist())
        assert {"modelDescription.xml", f"binaries/linux64/{MODEL_IDENTIFIER}.so", "resources/body.json"} <= names
        assert not any("\\" in n for n in names)
        # The default FMU ships the default body unchanged.
        shipped = json.loads(fmu.read("resources/body.json"))
    assert shipped == json.loads((REPO / "examples" / "cantilever.json").read_text())


def test_cosimulation_capabilities(model_description):
    assert model_description.fmiVersion == "2.0"
    cs = model_description.coSimulation
    assert cs is not None and model_description.modelExchange is None
    assert cs.modelIdentifier == MODEL_IDENTIFIER
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canGetAndSetFMUstate
    assert not cs.canBeInstantiatedOnlyOncePerProcess
    assert model_description.guid


def _by_name(model_description):
    return {v.name: v for v in model_description.modelVariables}


def vector(name, n):
    return [f"{name}[{k}]" for k in range(1, n + 1)]


# docs/fmu.md, "Variables", for the default body: force interface `tip`, fixed support `root`.
TIP_INPUTS = vector("tip.force", 3) + vector("tip.torque", 3)
TIP_OUTPUTS = (
    vector("tip.position", 3)
    + vector("tip.rotation", 9)
    + vector("tip.velocity", 3)
    + vector("tip.angularVelocity", 3)
    + vector("tip.acceleration", 3)
    + vector("tip.angularAcceleration", 3)
)
ROOT_OUTPUTS = vector("root.force", 3) + vector("root.torque", 3)
BODY_OUTPUTS = (
    vector("body.position", 3)
    + vector("body.rotation", 9)
    + vector("body.velocity", 3)
    + vector("body.angularVelocity", 3)
    + vector("body.linearMomentum", 3)
    + vector("body.angularMomentum", 3)
    + ["body.kineticEnergy", "body.strainEnergy"]
)
PARAMETERS = (
    ["material.youngsModulus", "material.poissonRatio", "material.density"]
    + ["damping.alpha", "damping.beta"]
    + vector("gravity", 3)
    + vector("initial.position", 3)
    + vector("initial.rotation", 9)
    + vector("initial.velocity", 3)
    + vector("initial.angularVelocity", 3)
    + ["solver.stepSize", "solver.rhoInf", "solver.tolerance", "solver.maxIterations"]
    + ["model.nonlinearForces", "model.auto", "model.modes"]
)


@pytest.mark.parametrize(
    "names, causality",
    [(TIP_INPUTS, "input"), (TIP_OUTPUTS, "output"), (ROOT_OUTPUTS, "output"), (BODY_OUTPUTS, "output"),
     (PARAMETERS, "parameter")],
    ids=["tip inputs", "tip outputs", "root outputs", "body outputs", "parameters"],
)
def test_variables_of_the_design_are_present(model_description, names, causality):
    variables = _by_name(model_description)
    missing = [n for n in names if n not in variables]
    assert missing == []
    wrong = [(n, variables[n].causality) for n in names if variables[n].causality != causality]
    assert wrong == []


EXPECTED_UNITS = {
    "tip.force": "N", "tip.torque": "N.m", "tip.position": "m", "tip.rotation": "1", "tip.velocity": "m/s",
    "tip.angularVelocity": "rad/s", "tip.acceleration": "m/s2", "tip.angularAcceleration": "rad/s2",
    "root.force": "N", "root.torque": "N.m", "body.position": "m", "body.kineticEnergy": "J",
    "body.strainEnergy": "J", "material.youngsModulus": "Pa", "material.density": "kg/m3",
    "damping.alpha": "1/s", "damping.beta": "s", "gravity": "m/s2",
}


def test_every_real_variable_has_a_declared_unit(model_description):
    declared = {u.name for u in model_description.unitDefinitions}
    for v in model_description.modelVariables:
        if v.type != "Real":
            continue
        unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
        assert unit, f"{v.name} has no unit"
        assert unit in declared, f"{v.name}: unit {unit} is not in UnitDefinitions"
        base = v.name.split("[")[0]
        if base in EXPECTED_UNITS:
            assert unit == EXPECTED_UNITS[base], v.name


def test_inputs_have_start_values_and_outputs_are_listed(model_description):
    inputs = [v for v in model_description.modelVariables if v.causality == "input"]
    assert all(v.start is not None for v in inputs)
    outputs = [v for v in model_description.modelVariables if v.causality == "output"]
    assert [u.variable for u in model_description.outputs] == outputs
