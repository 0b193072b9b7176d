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
