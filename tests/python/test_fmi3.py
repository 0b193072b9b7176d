"""The FMI 3.0 FMU (``cargo xtask fmu --fmi 3``): the same slave as the FMI 2.0 FMU behind FMI
3.0's functions and model description. fmpy validates the description and drives both; their
numbers must agree bit for bit, since the two C layers call the same code with the same values."""

import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

# B1's tip load (10 N down) and a 0.05 s step response, as in test_cosimulation.py.
STOP, STEP, LOAD = 0.05, 1e-3, -10.0


def test_the_fmi3_description_is_valid_and_has_arrays(fmu3_path):
    assert validate_fmu(fmu3_path) == []
    md = read_model_description(fmu3_path)
    assert md.fmiVersion == "3.0"
    variables = {v.name: v for v in md.modelVariables}
    assert variables["time"].causality == "independent"
    shape = lambda name: [int(d.start) for d in variables[name].dimensions]  # noqa: E731
    assert shape("tip.position") == [3]
    assert shape("tip.rotation") == [3, 3]
    assert shape("tip.force") == [3]
    assert variables["solver.integrator"].type == "Enumeration"
    with zipfile.ZipFile(fmu3_path) as archive:
        binaries = sorted(n for n in archive.namelist() if n.startswith("binaries/"))
    assert binaries == ["binaries/x86_64-linux/flexbody.so", "binaries/x86_64-windows/flexbody.dll"]


def test_b1_step_response_is_the_fmi2_one_bit_for_bit(fmu_path, fmu3_path):
    outputs = ["tip.position", "tip.velocity", "root.force", "body.rotation"]
    fmi3 = simulate_fmu(
        fmu3_path, stop_time=STOP, output_interval=STEP, start_values={"tip.force": [0.0, 0.0, LOAD]},
        output=outputs,
    )
    scalars = [f"{name}[{k}]" for name in outputs for k in range(1, 10 if "rotation" in name else 4)]
    fmi2 = simulate_fmu(
        fmu_path, stop_time=STOP, output_interval=STEP, start_values={"tip.force[3]": LOAD}, output=scalars,
    )
    assert np.array_equal(fmi3["time"], fmi2["time"])
    for name in outputs:
        columns = [fmi2[s] for s in scalars if s.startswith(name + "[")]
        expected = np.stack(columns, axis=1)
        got = fmi3[name].reshape(len(fmi3), -1)
        assert np.array_equal(got, expected), name
    # And it is a step response: the tip has moved down.
    assert fmi3["tip.position"][-1, 2] < -1e-4


def test_fmi3_state_round_trip_repeats_the_steps(fmu3_path, tmp_path):
    md = read_model_description(fmu3_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipdir = extract(fmu3_path, unzipdir=str(tmp_path / "fmu3"))
    fmu = FMU3Slave(
        guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="b1"
    )
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setFloat64([vr["tip.force"]], [0.0, 0.0, LOAD])
    fmu.exitInitializationMode()
    t = 0.0
    for _ in range(10):
        fmu.doStep(t, STEP)
        t += STEP
    state = fmu.serializeFMUState(fmu.getFMUState())
    for _ in range(10):
        fmu.doStep(t + _ * STEP, STEP)
    first = fmu.getFloat64([vr["tip.position"], vr["time"]], nValues=4)
    fmu.setFMUState(fmu.deserializeFMUState(state))
    for _ in range(10):
        fmu.doStep(t + _ * STEP, STEP)
    assert fmu.getFloat64([vr["tip.position"], vr["time"]], nValues=4) == first
    assert first[2] < 0.0
    fmu.terminate()
    fmu.freeInstance()


def test_fmi3_bad_input_is_refused_with_a_message_and_changes_nothing(fmu3_path, tmp_path):
    from fmpy.fmi1 import FMICallException

    md = read_model_description(fmu3_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipdir = extract(fmu3_path, unzipdir=str(tmp_path / "fmu3"))
    messages = []

    def log(environment, status, category, message):
        messages.append((status, category.decode(), message.decode()))

    fmu = FMU3Slave(
        guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bad"
    )
    fmu.instantiate(logMessage=log)
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    # A NaN element: refused with the element's name, nothing set (all or nothing).
    with pytest.raises(FMICallException):
        fmu.setFloat64([vr["tip.force"]], [1.0, 2.0, float("nan")])
    assert "tip.force[3]" in messages[-1][2] and messages[-1][1] == "logStatusError"
    assert fmu.getFloat64([vr["tip.force"]], nValues=3) == [0.0, 0.0, 0.0]
    # The wrong number of values for an array, and an output set: refused, named.
    with pytest.raises(FMICallException):
        fmu.getFloat64([vr["tip.position"]], nValues=2)
    assert "nValues = 2" in messages[-1][2] and messages[-1][2].startswith("fmi3GetFloat64")
    with pytest.raises(FMICallException):
        fmu.setFloat64([vr["tip.position"]], [0.0, 0.0, 0.0])
    assert "output" in messages[-1][2]
    # The instance is still usable: the rejected calls changed nothing.
    fmu.doStep(0.0, STEP)
    assert fmu.getFloat64([vr["time"]]) == [STEP]
    assert all(status <= 1 for status, _, text in messages if "fmi3DoStep" in text)
    fmu.terminate()
    fmu.freeInstance()
