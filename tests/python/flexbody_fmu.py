"""Helpers for driving the flexbody FMU with fmpy's low-level FMU2Slave.

The logger: an FMU calls the importer's variadic C logger (`"%s"` plus the text), which ctypes
cannot receive; fmpy's native proxy (`fmpy.logging.addLoggerProxy`) formats the message and calls
one Python function, kept in a single C global. So all instances share :func:`_collect`, which
files each message under the instance name, and each instance gets its own
``componentEnvironment`` so the tests can check that the FMU passes it back.
"""

from ctypes import POINTER, byref, c_double, c_int, c_size_t, c_uint, c_void_p
from dataclasses import dataclass

import numpy as np
from fmpy import calloc, free
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CoSimulation,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

STATUS_LABELS = ["ok", "warning", "discard", "error", "fatal", "pending"]


@dataclass
class LogRecord:
    environment: int | None
    instance_name: str
    status: int
    category: str
    message: str


# Every message any instance logged, in order.
LOG: list[LogRecord] = []


def _text(b) -> str:
    return b.decode("utf-8", errors="replace") if b else ""


def _collect(environment, instance_name, status, category, message):
    LOG.append(LogRecord(environment, _text(instance_name), status, _text(category), _text(message)))


_LOGGER = fmi2CallbackLoggerTYPE(_collect)  # one ctypes thunk for the life of the process
_ALLOCATE = fmi2CallbackAllocateMemoryTYPE(calloc)
_FREE = fmi2CallbackFreeMemoryTYPE(free)
_next_environment = [0x1000]


class Instance:
    """One instantiated co-simulation slave with a message log of its own."""

    def __init__(self, unzipdir, model_description, name, resource_location=None, visible=False, call_logger=None):
        """`resource_location`: a URI to pass instead of fmpy's `file://` one (e.g. OMSimulator's
        four-slash `file:////<dir>`); `call_logger`: fmpy's `fmiCallLogger` (sees every call's
        status, fmi2Warning included)."""
        self.name = name
        self.model_description = model_description
        self.vr = {v.name: v.valueReference for v in model_description.modelVariables}
        self.types = {v.name: v.type for v in model_description.modelVariables}
        self.real_outputs = [
            v.name for v in model_description.modelVariables if v.causality == "output" and v.type == "Real"
        ]
        _next_environment[0] += 0x10
        self.environment = _next_environment[0]
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = _LOGGER
        callbacks.allocateMemory = _ALLOCATE
        callbacks.freeMemory = _FREE
        callbacks.componentEnvironment = self.environment
        addLoggerProxy(byref(callbacks))
        self.fmu = FMU2Slave(
            guid=model_description.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=model_description.coSimulation.modelIdentifier,
            instanceName=name,
            fmiCallLogger=call_logger,
        )
        if resource_location is None:
            # FMU2Slave.instantiate keeps a reference to the callbacks for the instance's lifetime.
            self.fmu.instantiate(visible=visible, loggingOn=True, callbacks=callbacks)
        else:
            self.fmu.callbacks = callbacks
            self.fmu.component = self.fmu.fmi2Instantiate(
                name.encode("utf-8"), fmi2CoSimulation, model_description.guid.encode("utf-8"),
                resource_location.encode("utf-8"), byref(callbacks), visible, True,
            )
            if self.fmu.component is None:
                raise Exception(f"fmi2Instantiate returned NULL for {resource_location}")
        self.time = 0.0

    def messages(self, status=None) -> list[LogRecord]:
        """Messages this instance logged (optionally only those with `status`)."""
        return [r for r in LOG if r.instance_name == self.name and (status is None or r.status == status)]

    def initialize(self, start_values=None, start_time=0.0, stop_time=None):
        """setupExperiment (the stop time, when given, is the run over which model.accuracy
        holds), start values (in Initialization Mode), exitInitializationMode."""
        self.fmu.setupExperiment(startTime=start_time, stopTime=stop_time)
        self.fmu.enterInitializationMode()
        for name, value in (start_values or {}).items():
            self.set(name, value)
        self.fmu.exitInitializationMode()
        self.time = start_time

    def set(self, name, value):
        """Sets a Real, Integer or Boolean variable by name."""
        kind = self.types[name]
        if kind == "Integer":
            self.fmu.setInteger([self.vr[name]], [int(value)])
        elif kind == "Boolean":
            self.fmu.setBoolean([self.vr[name]], [bool(value)])
        else:
            self.fmu.setReal([self.vr[name]], [float(value)])

    def get(self, name) -> float:
        return self.fmu.getReal([self.vr[name]])[0]

    def outputs(self) -> np.ndarray:
        """All Real outputs, in modelDescription order."""
        return np.array(self.fmu.getReal([self.vr[n] for n in self.real_outputs]), dtype=np.float64)

    def step(self, h, n=1) -> np.ndarray:
        """`n` steps of `h` (time as start + k h, no accumulation); the outputs after each step."""
        rows = []
        for _ in range(n):
            self.fmu.doStep(
                currentCommunicationPoint=self.time,
                communicationStepSize=h,
                noSetFMUStatePriorToCurrentPoint=False,
            )
            self.time += h
            rows.append(self.outputs())
        return np.array(rows)

    def step_jacobian(self, outputs, inputs) -> np.ndarray:
        """`flexbody_GetStepJacobian` (docs/coupling.md, "Jacobians"): the derivative of the
        outputs (names) at the end of the last doStep with respect to the inputs (names) held
        over it, as a matrix with a row per output."""
        f = self.fmu.dll.flexbody_GetStepJacobian
        f.argtypes = [c_void_p, POINTER(c_uint), c_size_t, POINTER(c_uint), c_size_t, POINTER(c_double)]
        f.restype = c_int
        unknowns = (c_uint * len(outputs))(*[self.vr[n] for n in outputs])
        knowns = (c_uint * len(inputs))(*[self.vr[n] for n in inputs])
        jacobian = (c_double * (len(outputs) * len(inputs)))()
        status = f(self.fmu.component, unknowns, len(outputs), knowns, len(inputs), jacobian)
        if status != 0:
            raise FMICallException(function="flexbody_GetStepJacobian", status=status)
        return np.array(jacobian[:], dtype=np.float64).reshape(len(outputs), len(inputs))

    def free(self):
        """Terminate (if the instance's state allows it) and free the instance."""
        try:
            self.fmu.terminate()
        except FMICallException:
            pass  # e.g. a test that failed half-way; freeing is allowed in every state
        self.fmu.freeInstance()


def step_input(model_description, name, value, t_step, t_end):
    """fmpy input signals: every Real input 0, and `name` stepping from 0 to `value` at `t_step`.

    A repeated time row marks the discontinuity; fmpy applies the right-hand value from `t_step` on.
    """
    inputs = [v.name for v in model_description.modelVariables if v.causality == "input" and v.type == "Real"]
    times = [0.0, t_step, t_step, t_end]
    rows = [tuple([t] + [(value if (n == name and k >= 2) else 0.0) for n in inputs]) for k, t in enumerate(times)]
    return np.array(rows, dtype=[("time", np.float64)] + [(n, np.float64) for n in inputs])
