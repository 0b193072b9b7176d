"""The default cantilever (B1) run through fmpy: the static deflection under a step load (the
mesh body, and the reduced body with one frame and with slabs), FMU state save/restore and
independent instances.

B1: steel beam 1 m x 20 mm x 20 mm (E = 210 GPa, nu = 0.3, rho = 7850 kg/m3), clamped at x = 0,
load at the tip. Timoshenko beam theory gives the static tip deflection under 10 N as
1.19084e-3 m (Euler-Bernoulli F L^3 / 3EI = 1.19048e-3 m plus shear); the hex20 mesh of the default
body reproduces it within 1 % (docs/benchmarks.md).
"""

import math

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi2 import fmi2Warning

from flexbody_fmu import Instance, step_input

TIMOSHENKO_DEFLECTION = 1.19084e-3  # m, |tip deflection| under 10 N
LOAD = 10.0  # N
H = 1e-3  # s, communication step = the body file's internal step


def test_step_load_settles_at_the_static_deflection(fmu_path, model_description):
    # Stiffness-proportional damping: the first bending mode (omega_1 = 3.516 sqrt(EI / (rho A L^4))
    # = 105 rad/s) decays at beta omega_1^2 / 2 = 11 1/s with beta = 2 ms, so after 0.99 s the
    # transient (initial amplitude = the static deflection) is down to exp(-10.9) = 2e-5 of it;
    # higher modes decay faster still. What is left of the 1 % tolerance is the mesh's error.
    t_step, t_end = 0.01, 1.0
    result = simulate_fmu(
        fmu_path,
        start_time=0.0,
        stop_time=t_end,
        output_interval=H,
        start_values={"damping.beta": 2e-3},
        input=step_input(model_description, "tip.force[2]", -LOAD, t_step, t_end),
        output=["tip.position[2]", "root.force[2]", "body.strainEnergy"],
    )
    t = result["time"]
    assert math.isclose(t[-1], t_end, rel_tol=1e-9)
    deflection = result["tip.position[2]"] - result["tip.position[2]"][0]
    reaction = result["root.force[2]"]

    before = t <= t_step + 1e-9
    # Nothing moves and nothing is loaded before the step (the body starts undeformed, at rest).
    assert np.all(np.abs(deflection[before]) < 1e-12)
    assert np.all(np.abs(reaction[before]) < 1e-6)
    # Sign convention: the load pushes the tip to -y, the support pushes the root to +y.
    assert deflection[-1] == pytest.approx(-TIMOSHENKO_DEFLECTION, rel=0.01)
    assert reaction[-1] == pytest.approx(+LOAD, rel=0.01)
    # Settled: the last 0.1 s moves by less than 0.1 % of the deflection.
    last = t >= t_end - 0.1
    assert np.ptp(deflection[last]) < 1e-3 * TIMOSHENKO_DEFLECTION
    # Strain energy of the settled beam: F delta / 2 (to the same 1 %).
    assert result["body.strainEnergy"][-1] == pytest.approx(0.5 * LOAD * TIMOSHENKO_DEFLECTION, rel=0.02)


def settled_tip_deflection(fmu_path, model_description, start_values):
    """B1's tip deflection after the damped step load of the test above (1 s, beta = 2 ms) with
    the given parameters."""
    result = simulate_fmu(
        fmu_path,
        start_time=0.0,
        stop_time=1.0,
        output_interval=H,
        start_values={"damping.beta": 2e-3, **start_values},
        input=step_input(model_description, "tip.force[2]", -LOAD, 0.01, 1.0),
        output=["tip.position[2]"],
    )
    tip = result["tip.position[2]"]
    return tip[-1] - tip[0]


@pytest.mark.parametrize("frames", [1, 5], ids=["one-frame", "5-slabs"])
def test_reduced_body_settles_where_the_mesh_does(fmu_path, model_description, frames):
    # The reduced body (model.modes = auto) through the FMU, with one frame and with five slabs
    # acting on its coordinates, against the mesh with the same frames: its attachment modes
    # hold the tip load's static response exactly, and with slabs its modal derivatives hold
    # their second order up to 1e-7 of the deflection under 10 N (tests/reduced_body.rs), so the
    # settled deflections agree to that and to what is left of the two transients after 1 s
    # (2e-5 of the deflection each, in the same lowest modes; measured 7e-10 and 2.9e-8).
    frames = {"model.frames": frames}
    mesh = settled_tip_deflection(fmu_path, model_description, frames)
    deflection = settled_tip_deflection(fmu_path, model_description, {"model.modes": -1, **frames})
    assert deflection == pytest.approx(-TIMOSHENKO_DEFLECTION, rel=0.01)
    assert deflection == pytest.approx(mesh, rel=1e-6)


def test_restored_state_reproduces_the_steps_bit_for_bit(unzipdir, model_description):
    slave = Instance(unzipdir, model_description, "state")
    try:
        slave.initialize({"damping.beta": 1e-4})
        slave.set("tip.force[2]", -LOAD)
        slave.step(H, 5)
        saved_outputs = slave.outputs()
        state = slave.fmu.getFMUstate()
        t_saved = slave.time

        first = slave.step(H, 20)
        slave.fmu.setFMUstate(state)
        slave.time = t_saved
        # The outputs are those of the saved point again ...
        assert saved_outputs.tobytes() == slave.outputs().tobytes()
        second = slave.step(H, 20)
        # ... and the following steps repeat exactly.
        assert first.tobytes() == second.tobytes()
        # The comparison is not vacuous: the tip moved during those 20 steps.
        tip = slave.real_outputs.index("tip.position[2]")
        assert abs(first[-1, tip] - first[0, tip]) > 1e-7

        # A state stays valid after being restored: once more, from the same state.
        slave.fmu.setFMUstate(state)
        slave.time = t_saved
        assert first.tobytes() == slave.step(H, 20).tobytes()
        slave.fmu.freeFMUstate(state)
        # Normal operation logs no warning or worse (OMSimulator treats fmi2Warning as an error).
        assert [r for r in slave.messages() if r.status >= fmi2Warning] == []
    finally:
        slave.free()


def test_uneven_and_jittered_communication_steps(unzipdir, model_description):
    # canHandleVariableCommunicationStepSize: steps that are not multiples of solver.stepSize, and
    # communication points accumulated as t += h (OMSimulator, fmuCheck), a few ulps off k h.
    slave = Instance(unzipdir, model_description, "steps")
    try:
        slave.initialize({"damping.beta": 1e-4})
        slave.set("tip.force[2]", -LOAD)
        t = 0.0
        for h in [0.5e-3, 2.5e-3, 1e-3, 0.3e-3, 1.7e-3] + [1e-3] * 30:
            slave.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h,
                             noSetFMUStatePriorToCurrentPoint=True)
            t += h
        assert np.all(np.isfinite(slave.outputs()))
        assert slave.get("tip.position[2]") < 0.0  # it moved, the way it was pushed
        assert [r for r in slave.messages() if r.status >= fmi2Warning] == []
    finally:
        slave.free()


def test_serialized_state_restores_into_another_instance(unzipdir, model_description):
    if not model_description.coSimulation.canSerializeFMUstate:
        pytest.skip("the FMU does not declare canSerializeFMUstate")
    a = Instance(unzipdir, model_description, "serialize-a")
    b = Instance(unzipdir, model_description, "serialize-b")
    try:
        a.initialize()
        a.set("tip.force[3]", -LOAD)
        a.step(H, 5)
        state = a.fmu.getFMUstate()
        data = a.fmu.serializeFMUstate(state)
        a.fmu.freeFMUstate(state)
        expected = a.step(H, 10)

        b.initialize()
        restored = b.fmu.deSerializeFMUstate(data)
        b.fmu.setFMUstate(restored)
        b.fmu.freeFMUstate(restored)
        b.time = 5 * H
        assert expected.tobytes() == b.step(H, 10).tobytes()
    finally:
        a.free()
        b.free()


def test_instances_are_independent(unzipdir, model_description):
    # a and b run interleaved with different loads; c runs b's load alone. Independent instances:
    # a differs from b, b equals c bit for bit, and stepping a leaves b's outputs untouched.
    a, b, c = (Instance(unzipdir, model_description, name) for name in ("a", "b", "c"))
    try:
        for slave, load in ((a, -LOAD), (b, -0.5 * LOAD), (c, -0.5 * LOAD)):
            slave.initialize({"damping.beta": 1e-4})
            slave.set("tip.force[2]", load)
        rows_b = []
        for _ in range(15):
            a.step(H)
            rows_b.append(b.step(H)[0])
        rows_b = np.array(rows_b)
        rows_c = c.step(H, 15)
        assert rows_b.tobytes() == rows_c.tobytes()

        tip = a.real_outputs.index("tip.position[2]")
        assert a.outputs()[tip] != b.outputs()[tip]

        before = b.outputs()
        a.set("tip.force[2]", +LOAD)
        a.step(H, 5)
        assert before.tobytes() == b.outputs().tobytes()
    finally:
        for slave in (a, b, c):
            slave.free()
