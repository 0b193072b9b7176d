"""Errors reach the importer as fmi2Error plus a logger message that names what was wrong, and
the instance stays usable where FMI 2.0 allows it."""

import math

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Error

from flexbody_fmu import Instance

H = 1e-3


@pytest.fixture
def slave(unzipdir, model_description, request):
    instance = Instance(unzipdir, model_description, f"errors-{request.node.name}")
    yield instance
    instance.free()


def assert_logged_error(slave, *fragments):
    errors = slave.messages(status=fmi2Error)
    assert errors, f"no error message logged; all messages: {slave.messages()}"
    text = "\n".join(r.message for r in errors)
    for fragment in fragments:
        assert fragment in text, f"{fragment!r} not in the error messages:\n{text}"
    # The FMU logs with the importer's componentEnvironment and the instance name it was given.
    assert all(r.environment == slave.environment for r in slave.messages())


def assert_runs(slave):
    """A valid input is accepted and a step runs with finite outputs."""
    slave.set("tip.force[2]", -1.0)
    outputs = slave.step(H, 2)
    assert np.all(np.isfinite(outputs))


def test_do_step_before_initialization_is_an_error(slave):
    with pytest.raises(FMICallException) as error:
        slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=H)
    assert error.value.status == fmi2Error
    assert_logged_error(slave)
    # fmi2Reset is allowed in every state, the error state included: it gives a fresh instance.
    slave.fmu.reset()
    slave.initialize()
    assert_runs(slave)


def test_unknown_value_reference_is_named(slave):
    slave.initialize()
    unknown = 987654
    assert unknown not in slave.vr.values()
    with pytest.raises(FMICallException) as error:
        slave.fmu.setReal([unknown], [1.0])
    assert error.value.status == fmi2Error
    assert_logged_error(slave, str(unknown))
    assert_runs(slave)


def test_nan_input_is_rejected_and_named(slave):
    slave.initialize()
    with pytest.raises(FMICallException) as error:
        slave.set("tip.force[1]", math.nan)
    assert error.value.status == fmi2Error
    assert_logged_error(slave, "tip.force[1]")
    # The NaN was not stored: the next steps stay finite.
    assert_runs(slave)
    assert math.isfinite(slave.get("tip.position[1]"))


@pytest.mark.parametrize(
    "name, value, text, reason",
    [
        ("material.youngsModulus", 0.0, "= 0 rejected", "must be positive"),
        ("material.youngsModulus", math.inf, "= inf rejected", "not a finite number"),
        ("material.poissonRatio", 0.5, "= 0.5 rejected", "must lie in (-1, 0.5)"),
        ("material.poissonRatio", -1.0, "= -1 rejected", "must lie in (-1, 0.5)"),
        ("material.density", -1.0, "= -1 rejected", "must be positive"),
        ("damping.alpha", -0.1, "= -0.1 rejected", "must not be negative"),
        ("damping.beta", math.nan, "= NaN rejected", "not a finite number"),
        ("solver.stepSize", 0.0, "= 0 rejected", "must be positive"),
        ("solver.tolerance", 0.0, "= 0 rejected", "must lie in (0, 1)"),
        ("solver.rhoInf", 2.0, "= 2 rejected", "must lie in [0, 1]"),
    ],
)
def test_out_of_range_parameter_is_named_and_not_kept(slave, name, value, text, reason):
    # In the Instantiated state, as importers set start values; the rejected value is not kept.
    with pytest.raises(FMICallException) as error:
        slave.set(name, value)
    assert error.value.status == fmi2Error
    assert_logged_error(slave, f"{name} {text}", reason)
    slave.initialize()
    assert math.isfinite(slave.get(name))
    assert_runs(slave)


def test_wrong_type_and_wrong_state_are_named(slave):
    max_iterations = slave.vr["solver.maxIterations"]
    with pytest.raises(FMICallException):
        slave.fmu.setReal([max_iterations], [3.0])
    assert_logged_error(slave, "is the Integer variable solver.maxIterations, not a Real variable")
    with pytest.raises(FMICallException):
        slave.fmu.setInteger([max_iterations], [0])
    assert_logged_error(slave, "solver.maxIterations = 0 rejected")
    slave.initialize()
    with pytest.raises(FMICallException):
        slave.set("material.youngsModulus", 1e9)
    assert_logged_error(slave, "material.youngsModulus is a fixed parameter", "state StepComplete")
    with pytest.raises(FMICallException):
        slave.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=-H)
    assert_logged_error(slave, "communicationStepSize = -0.001 rejected")
    assert_runs(slave)
