"""The declared capabilities through fmpy's low-level API (issue 6): serialized FMU states (into a
new instance and into another process), input and output derivatives, retried and discarded
steps, fmi2CancelStep and the status queries of a synchronous FMU."""

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Discard, fmi2DoStepStatus, fmi2Error, fmi2LastSuccessfulTime, fmi2Terminated, fmi2Warning

from flexbody_fmu import Instance

H = 1e-3
HERE = pathlib.Path(__file__).resolve().parent


def test_capability_flags(model_description):
    cs = model_description.coSimulation
    assert cs.canSerializeFMUstate and cs.canGetAndSetFMUstate
    assert cs.canInterpolateInputs
    assert cs.maxOutputDerivativeOrder == 2
    assert cs.canHandleVariableCommunicationStepSize
    assert not cs.canRunAsynchronuously


def test_serialize_new_instance_deserialize_continue_bit_for_bit(unzipdir, model_description):
    a = Instance(unzipdir, model_description, "ser-a")
    b = Instance(unzipdir, model_description, "ser-b")
    try:
        a.initialize({"damping.beta": 1e-4, "tip.force[2]": -10.0})
        a.step(H, 7)
        data = a.fmu.serializeFMUstate(a.fmu.getFMUstate())
        assert data[:8] == b"FLEXBODY"
        t_saved = a.time
        a.set("tip.torque[1]", 0.5)
        expected = a.step(0.6e-3, 12)

        # b has other start values and has already stepped: the state brings everything along.
        b.initialize({"gravity[3]": -9.81})
        b.step(H, 2)
        state = b.fmu.deSerializeFMUstate(data)
        b.fmu.setFMUstate(state)
        b.fmu.freeFMUstate(state)
        assert b.fmu.getRealStatus(fmi2LastSuccessfulTime) == t_saved
        b.time = t_saved
        b.set("tip.torque[1]", 0.5)
        assert expected.tobytes() == b.step(0.6e-3, 12).tobytes()
        assert [r for r in a.messages() + b.messages() if r.status >= fmi2Warning] == []
    finally:
        a.free()
        b.free()


CHILD = """
import sys
import numpy as np
sys.path.insert(0, {here!r})
from fmpy import read_model_description
from flexbody_fmu import Instance
md = read_model_description({unzipdir!r})
b = Instance({unzipdir!r}, md, "child")
b.initialize()
state = b.fmu.deSerializeFMUstate(open({path!r}, "rb").read())
b.fmu.setFMUstate(state)
b.time = {t!r}
np.save({out!r}, b.step({h!r}, 10))
b.free()
"""


def test_serialized_state_continues_in_another_process(unzipdir, model_description, tmp_path):
    a = Instance(unzipdir, model_description, "ser-process")
    try:
        a.initialize({"tip.force[3]": -10.0})
        a.step(H, 5)
        path = tmp_path / "state.bin"
        path.write_bytes(a.fmu.serializeFMUstate(a.fmu.getFMUstate()))
        t = a.time
        expected = a.step(H, 10)
    finally:
        a.free()
    out = tmp_path / "child.npy"
    script = CHILD.format(here=str(HERE), unzipdir=str(unzipdir), path=str(path), t=t, out=str(out), h=H)
    subprocess.run([sys.executable, "-c", script], check=True, env={**os.environ})
    assert np.load(out).tobytes() == expected.tobytes()


def test_state_of_another_body_is_refused(unzipdir, model_description, driven_unzipdir, driven_model_description):
    a = Instance(unzipdir, model_description, "ser-own")
    b = Instance(driven_unzipdir, driven_model_description, "ser-other")
    try:
        a.initialize()
        data = a.fmu.serializeFMUstate(a.fmu.getFMUstate())
        b.initialize()
        with pytest.raises(FMICallException) as error:
            b.fmu.deSerializeFMUstate(data)
        assert error.value.status == fmi2Error
        text = "\n".join(r.message for r in b.messages(status=fmi2Error))
        assert model_description.guid in text and driven_model_description.guid in text
        b.step(H, 1)  # still usable
    finally:
        a.free()
        b.free()


def test_input_derivatives_extrapolate_the_force_over_the_step(unzipdir, model_description):
    # Four internal steps of 2^-10 s per communication step of 2^-8 s: a linear ramp given as
    # u, u' equals, bit for bit, the same ramp set before each of four one-internal-step
    # communication steps (the force is taken at each internal step's end).
    h = 1.0 / 1024.0
    # The fixed internal step (model.accuracy = 0): the comparison is of the inputs at each one.
    start = {"solver.stepSize": h, "tip.force[2]": -2.0, "model.accuracy": 0.0}
    slope = -3000.0
    a = Instance(unzipdir, model_description, "deriv-a")
    b = Instance(unzipdir, model_description, "deriv-b")
    try:
        a.initialize(start)
        a.fmu.setRealInputDerivatives([a.vr["tip.force[2]"]], [1], [slope])
        with_derivative = a.step(4 * h, 1)[0]
        b.initialize(start)
        for k in range(4):
            tau = k * h + h
            b.set("tip.force[2]", -2.0 + (slope * tau + 0.5 * 0.0 * tau * tau))
            b.fmu.doStep(k * h, h, noSetFMUStatePriorToCurrentPoint=False)
        assert with_derivative.tobytes() == b.outputs().tobytes()
        # Derivatives of outputs and of motion: refused with a message.
        with pytest.raises(FMICallException):
            a.fmu.setRealInputDerivatives([a.vr["tip.position[1]"]], [1], [1.0])
        assert "not an input" in a.messages(status=fmi2Error)[-1].message
    finally:
        a.free()
        b.free()


def test_output_derivatives(unzipdir, model_description):
    s = Instance(unzipdir, model_description, "outder")
    try:
        s.initialize({"tip.force[3]": -10.0})
        s.step(H, 10)
        vr = s.vr
        d = s.fmu.getRealOutputDerivatives(
            [vr["tip.position[3]"], vr["tip.position[3]"], vr["tip.velocity[3]"], vr["body.position[3]"]], [1, 2, 1, 1]
        )
        expected = s.fmu.getReal(
            [vr["tip.velocity[3]"], vr["tip.acceleration[3]"], vr["tip.acceleration[3]"], vr["body.velocity[3]"]]
        )
        assert d == expected
        assert d[0] != 0.0
        with pytest.raises(FMICallException):
            s.fmu.getRealOutputDerivatives([vr["root.force[3]"]], [1])
        assert "has no derivative" in s.messages(status=fmi2Error)[-1].message
    finally:
        s.free()


def test_hard_step_is_retried_and_impossible_step_discarded_then_smaller_step_works(unzipdir, model_description):
    hard = Instance(unzipdir, model_description, "retry")
    impossible = Instance(unzipdir, model_description, "discard")
    try:
        # 300 kN: some internal steps need halving; the importer sees only fmi2OK. (The plain
        # fixed-point iteration: Anderson's acceleration converges even here.)
        hard.initialize({"tip.force[2]": -3e5, "solver.andersonDepth": 0})
        assert np.all(np.isfinite(hard.step(H, 4)))
        assert [r for r in hard.messages() if r.status >= fmi2Warning] == []
        assert any("retrying it as 2 steps" in r.message for r in hard.messages())

        # 100 MN: discarded with the state of the step's start; restore and take 0.1 ms.
        impossible.initialize({"tip.force[2]": -1e8, "solver.andersonDepth": 0})
        saved = impossible.fmu.getFMUstate()
        before = impossible.outputs()
        with pytest.raises(FMICallException) as error:
            impossible.fmu.doStep(0.0, H, noSetFMUStatePriorToCurrentPoint=False)
        assert error.value.status == fmi2Discard
        (message,) = [r.message for r in impossible.messages(status=fmi2Discard)]
        assert "t = 0 by communicationStepSize = 0.001" in message and "last position correction" in message
        assert impossible.outputs().tobytes() == before.tobytes()
        assert impossible.fmu.getRealStatus(fmi2LastSuccessfulTime) == 0.0
        assert impossible.fmu.getBooleanStatus(fmi2Terminated)
        impossible.fmu.setFMUstate(saved)
        impossible.fmu.freeFMUstate(saved)
        assert np.all(np.isfinite(impossible.step(0.1 * H, 1)))
    finally:
        hard.free()
        impossible.free()


def test_cancel_step_and_pending_status_are_errors_of_a_synchronous_fmu(unzipdir, model_description):
    s = Instance(unzipdir, model_description, "cancel")
    try:
        s.initialize()
        s.step(H, 1)
        with pytest.raises(FMICallException):
            s.fmu.cancelStep()
        assert "StepInProgress" in s.messages(status=fmi2Error)[-1].message
        with pytest.raises(FMICallException):
            s.fmu.getStatus(fmi2DoStepStatus)
        assert s.fmu.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(H)
        s.step(H, 1)  # unchanged: the instance steps on
        # Reset from StepComplete and from Terminated gives a fresh instance that runs again.
        s.fmu.reset()
        s.initialize()
        s.step(H, 1)
        s.fmu.terminate()
        s.fmu.reset()
        s.initialize()
        s.step(H, 1)
    finally:
        s.free()
