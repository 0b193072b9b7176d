"""Each importer's habits (docs/fmu.md, "What the importers do"), replayed through fmpy's low-level FMU2Slave the way
that importer calls the FMU: OMSimulator (four-slash resource URI, visible and logging on, start
values before setupExperiment, no stop time, every status must be exactly fmi2OK, time accumulated
as t += h, a tiny last step), the FMU Compliance Checker (inputs before setupExperiment, no
tolerance and no stop time, all outputs read every step, overshooting last step, instance name
copied, static version strings) and threads (ctypes releases the GIL: instances stepped at the same
time from Python threads give the results they give alone)."""

import ctypes
import pathlib
import threading

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2CoSimulation, fmi2Warning

from flexbody_fmu import LOG, Instance

H = 1e-3


def status_checker():
    """fmpy's fmiCallLogger: collects every call whose status is not fmi2OK (fmpy itself lets
    fmi2Warning through; OMSimulator treats it as an error)."""
    bad = []

    def log(message):
        # fmpy writes "fmi2DoStep(...) -> OK" for status-returning calls.
        if " -> " in message and message.rsplit(" -> ", 1)[1].strip() in ("WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"):
            bad.append(message)

    return bad, log


def test_omsimulator_habits_with_a_four_slash_resource_uri(driven_unzipdir, driven_model_description):
    # The driven cantilever's GUID differs from the embedded default body's: if the four-slash
    # URI were not understood, the FMU would fall back to the default body and refuse the GUID.
    resources = pathlib.Path(driven_unzipdir, "resources").resolve()
    uri = "file:///" + str(resources)  # fmi4c: "file:///" + absolute path -> file:////tmp/...
    assert uri.startswith("file:////")
    bad, call_logger = status_checker()
    s = Instance(driven_unzipdir, driven_model_description, "oms", resource_location=uri, visible=True,
                 call_logger=call_logger)
    try:
        # Start values (SSV) between instantiate and setupExperiment, in the Instantiated state.
        s.set("damping.beta", 1e-3)
        s.fmu.setupExperiment(tolerance=1e-6, startTime=0.0, stopTime=None)  # stopTimeDefined = false
        s.fmu.enterInitializationMode()
        s.set("root.velocity[2]", 0.0)
        s.fmu.exitInitializationMode()
        # The root frame moves up at 0.1 m/s; time accumulates as OMS does.
        t = 0.0
        outputs = [v for v in s.real_outputs]
        for k in range(150):
            s.set("root.position[2]", 0.1 * t)
            s.set("root.velocity[2]", 0.1)
            s.fmu.doStep(t, H, noSetFMUStatePriorToCurrentPoint=True)
            t += H
            values = np.array(s.fmu.getReal([s.vr[n] for n in outputs]))
            assert np.all(np.isfinite(values))
        # The last step clamped to the stop time: a tiny step.
        s.fmu.doStep(t, 1e-12, noSetFMUStatePriorToCurrentPoint=True)
        assert np.all(np.isfinite(s.outputs()))
        assert s.get("tip.position[2]") == pytest.approx(0.1 * t, abs=2e-3)
        s.fmu.terminate()
        assert bad == [], bad
        assert [r for r in s.messages() if r.status >= fmi2Warning] == []
    finally:
        s.fmu.freeInstance()


def test_fmucheck_habits(unzipdir, model_description):
    bad, call_logger = status_checker()
    s = Instance(unzipdir, model_description, "Test FMI 2.0 CS", call_logger=call_logger)
    try:
        assert s.fmu.getTypesPlatform() == "default"
        assert s.fmu.getVersion() == "2.0"
        # Inputs from -i before setupExperiment, in the Instantiated state.
        s.set("tip.force[2]", -10.0)
        s.fmu.setupExperiment(tolerance=None, startTime=0.0, stopTime=None)
        s.fmu.enterInitializationMode()
        s.fmu.exitInitializationMode()
        stop, h = 0.0255, 2e-3  # not a multiple of h: the last step overshoots
        tcur = 0.0
        refs = [s.vr[n] for n in s.real_outputs]
        while tcur < stop:
            s.fmu.doStep(tcur, h, noSetFMUStatePriorToCurrentPoint=True)
            tcur += h
            assert np.all(np.isfinite(s.fmu.getReal(refs)))
        assert tcur > stop
        assert s.get("tip.position[2]") < 0.0
        s.fmu.terminate()
        assert bad == [], bad
        assert [r for r in s.messages() if r.status >= fmi2Warning] == []
    finally:
        s.fmu.freeInstance()


def test_instance_name_guid_and_resource_location_are_copied(unzipdir, model_description):
    # fmuCheck passes its own buffers and checks that the FMU copied them: here they are
    # overwritten right after fmi2Instantiate; later messages still carry the original name.
    s = Instance(unzipdir, model_description, "copy-probe")
    try:
        name = ctypes.create_string_buffer(b"copied name")
        guid = ctypes.create_string_buffer(model_description.guid.encode())
        location = ctypes.create_string_buffer(pathlib.Path(unzipdir, "resources").as_uri().encode())
        component = s.fmu.fmi2Instantiate(name, fmi2CoSimulation, guid, location, ctypes.byref(s.fmu.callbacks), 0, 1)
        assert component
        for buffer in (name, guid, location):
            ctypes.memset(buffer, ord("#"), len(buffer) - 1)
        before = len(LOG)
        # A rejected call makes the FMU log with the name it copied.
        with pytest.raises(FMICallException):
            s.fmu.fmi2DoStep(component, 0.0, H, 1)
        new = LOG[before:]
        assert new and all(r.instance_name == "copied name" for r in new), new
        assert all(r.environment == s.environment for r in new)
        s.fmu.fmi2FreeInstance(component)
    finally:
        s.free()


def test_instances_stepped_from_python_threads_match_their_runs_alone(unzipdir, model_description):
    loads = [-1.0, -2.0, -3.0, -4.0]

    def run(k, barrier=None, results=None):
        s = Instance(unzipdir, model_description, f"thread-{k}-{barrier is not None}")
        try:
            s.initialize({"tip.force[3]": loads[k], "damping.beta": 1e-4})
            if barrier is not None:
                barrier.wait()
            rows = s.step(H, 40)
        finally:
            s.free()
        if results is not None:
            results[k] = rows
        return rows

    alone = [run(k) for k in range(len(loads))]
    results = [None] * len(loads)
    barrier = threading.Barrier(len(loads))
    threads = [threading.Thread(target=run, args=(k, barrier, results)) for k in range(len(loads))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for k in range(len(loads)):
        assert results[k] is not None, f"thread {k} failed"
        assert results[k].tobytes() == alone[k].tobytes(), f"instance {k}"
    assert len({r[-1].tobytes() for r in alone}) == len(loads)


def test_omsimulator_extra_step_on_one_input_update_takes_the_motion_on(driven_unzipdir, driven_model_description):
    # OMSimulator's stepUntil(t + H) accumulates its time and, when the sum falls an ulp short of
    # the target, takes one more whole step without new inputs (FMU time ends a step ahead of
    # its caller); a master may also split a step into two. The inputs describe the frame at the
    # time they were set and the FMU extrapolates from there, so the root turning at 2 rad/s with
    # its pose set once per H = 0.01 s and every third update stepped as two half steps must
    # follow the run with one step per update: both take the same 1 ms internal steps and solve
    # the same equations, so they differ by rounding and the iteration's stopping point only
    # (solver.tolerance 1e-10 x 1 m per step), far below the 2e-7 m of tip bending here. With
    # the fixed internal step (model.accuracy = 0): under the error control the two runs may sit
    # on different rungs of the internal step, and differ by the integration error instead.
    big_h, omega = 1e-2, 2.0
    runs = []
    for split in (False, True):
        s = Instance(driven_unzipdir, driven_model_description, f"oms-split-{split}")
        try:
            s.initialize({"root.angularVelocity[3]": omega, "model.accuracy": 0.0})
            tip = []
            for k in range(60):
                t = k * big_h
                c, si = np.cos(omega * t), np.sin(omega * t)
                for name, value in zip(("rotation[1]", "rotation[2]", "rotation[4]", "rotation[5]"), (c, -si, si, c)):
                    s.set(f"root.{name}", value)
                if split and k % 3 == 0:
                    s.fmu.doStep(t, big_h / 2)
                    s.fmu.doStep(t + big_h / 2, big_h / 2)
                else:
                    s.fmu.doStep(t, big_h)
                tip.append([s.get(f"tip.position[{i}]") for i in (1, 2, 3)])
            runs.append(np.array(tip))
        finally:
            s.free()
    whole, split = runs
    # The tip went round by 1.2 rad at 1 m radius: a frame left behind by omega*H/2 would be
    # 1e-2 m off.
    assert np.hypot(*whole[-1, :2]) == pytest.approx(1.0, abs=1e-3)
    assert np.max(np.abs(split - whole)) < 1e-9


def test_fmpy_simulate_fmu_and_an_exact_step_loop_give_the_same_bits(fmu_path, unzipdir, model_description):
    # fmpy's simulate_fmu steps by the difference of two grid times, (k+1) H - k H, which is H
    # off by an ulp at some k; a loop with exact steps passes H itself. The FMU takes a step
    # within ulps of the last one as that step, so both runs are the same to the last bit
    # (before, they differed by 2.5e-13 m and 1.9e-7 N: where the iteration stops moved).
    big_h, n = 1e-3, 300
    grid_steps = [(k + 1) * big_h - k * big_h for k in range(n)]
    assert any(h != big_h for h in grid_steps), "the grid has no jittered step"
    inputs = [v.name for v in model_description.modelVariables if v.causality == "input" and v.type == "Real"]
    # A row at every communication point: fmpy interpolates between rows as (1 - w) u0 + w u1,
    # which turns -10 into -10.000000000000002 between two rows; at a row it is the row's value,
    # so both runs get the same inputs.
    signal = np.array(
        [tuple([k * big_h] + [(-10.0 if name == "tip.force[2]" else 0.0) for name in inputs]) for k in range(n + 1)],
        dtype=[("time", np.float64)] + [(name, np.float64) for name in inputs],
    )
    names = ["tip.position[2]", "root.force[2]"]
    result = simulate_fmu(fmu_path, start_time=0.0, stop_time=n * big_h, output_interval=big_h, input=signal, output=names)
    s = Instance(unzipdir, model_description, "exact-steps")
    try:
        # The stop time simulate_fmu sets up: model.accuracy's horizon (docs/formulation.md).
        s.initialize({"tip.force[2]": -10.0}, stop_time=n * big_h)
        rows = [[s.get(name) for name in names]]
        for _ in range(n):
            s.set("tip.force[2]", -10.0)
            s.step(big_h)
            rows.append([s.get(name) for name in names])
    finally:
        s.free()
    exact = np.array(rows)
    fmpy_rows = np.column_stack([result[name] for name in names])
    assert fmpy_rows.shape == exact.shape
    assert fmpy_rows.tobytes() == exact.tobytes()
