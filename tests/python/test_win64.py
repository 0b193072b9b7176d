"""The .fmu's binaries: linux64 and win64 (``cargo xtask fmu``'s default platforms), and the win64
DLL loaded the way a Windows importer loads it.

`cargo xtask test` checks the win64 DLL's import and export tables and runs the library's Rust
tests under wine. Here the packaged DLL itself runs under wine inside fmpy's remoting server
(``fmpy/remoting/win64/server_tcp.exe``, which loads it with ``LoadLibrary`` and serves its
``fmi2*`` functions over TCP) and is driven from Linux through fmpy's remoting client
(``client_tcp.so``). The server is started here rather than by the client: the client's own
start (``fmpy.util.add_remoting``) hands the server a lock file, held with a POSIX read lock, that
the server polls every 0.5 s to notice that the client has gone; under wine, whose ``CreateFile``
does not see POSIX locks, the server opened it, printed "Lock file ... open. Exiting." and stopped
in three runs out of four, the client then waiting for good. A client whose model identifier is
``client_tcp`` connects to a server already running instead."""

import os
import pathlib
import shutil
import signal
import socket
import subprocess
import time
import zipfile

import fmpy
import numpy as np
import pytest
from fmpy import extract
from fmpy.fmi2 import FMU2Slave

REMOTING = pathlib.Path(fmpy.__file__).parent / "remoting"
PORT = 8080  # rpclib's default port, on which fmpy's remoting server listens and its client calls
H, STEPS, LOAD = 1e-3, 40, -10.0  # B1: 10 N down at the tip, 40 steps of 1 ms


def test_the_fmu_carries_linux64_and_win64(fmu_path):
    with zipfile.ZipFile(fmu_path) as archive:
        names = set(archive.namelist())
    assert {"binaries/linux64/flexbody.so", "binaries/win64/flexbody.dll"} <= names
    # The library is named after the model identifier in both folders, nothing else is there.
    assert sorted(n for n in names if n.startswith("binaries/")) == [
        "binaries/linux64/flexbody.so",
        "binaries/win64/flexbody.dll",
    ]


def _b1_step_response(fmu: FMU2Slave, vr: dict, outputs: list) -> np.ndarray:
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([vr["tip.force[3]"]], [LOAD])
    fmu.exitInitializationMode()
    rows = []
    for k in range(STEPS):
        fmu.doStep(currentCommunicationPoint=k * H, communicationStepSize=H)
        rows.append(fmu.getReal([vr[name] for name in outputs]))
    fmu.terminate()
    fmu.freeInstance()
    return np.array(rows)


def _wait_for_port(server: subprocess.Popen, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if server.poll() is not None:
            pytest.fail(f"the remoting server under wine exited with {server.returncode}")
        try:
            socket.create_connection(("127.0.0.1", PORT), timeout=1.0).close()
            return
        except OSError:
            time.sleep(0.5)
    pytest.fail(f"the remoting server under wine did not listen on port {PORT} within {timeout} s")


def test_the_win64_binary_under_wine_gives_the_linux64_bits(fmu_path, model_description, tmp_path):
    wine64 = os.environ.get("FLEXBODY_WINE64")
    stand_in = os.environ.get("FLEXBODY_WINE_STAND_IN")
    if not (wine64 and stand_in):
        pytest.skip("FLEXBODY_WINE64 and FLEXBODY_WINE_STAND_IN are not set (`cargo xtask test` sets them)")
    try:
        socket.create_connection(("127.0.0.1", PORT), timeout=1.0).close()
        pytest.fail(f"port {PORT} is taken: the remoting server needs it")
    except OSError:
        pass
    vr = {v.name: v.valueReference for v in model_description.modelVariables}
    outputs = [v.name for v in model_description.modelVariables if v.causality == "output"]
    unzipdir = pathlib.Path(extract(fmu_path, unzipdir=str(tmp_path / "fmu")))
    shutil.copy(REMOTING / "linux64" / "client_tcp.so", unzipdir / "binaries" / "linux64" / "client_tcp.so")
    # The server's directory is searched first for the DLL's imports: wine 8.0 has no
    # bcryptprimitives.dll (Windows 10 and later do), so the test-only stand-in goes beside it.
    server_dir = tmp_path / "server"
    server_dir.mkdir()
    shutil.copy(REMOTING / "win64" / "server_tcp.exe", server_dir / "server_tcp.exe")
    shutil.copy(stand_in, server_dir / "bcryptprimitives.dll")
    log_path = tmp_path / "server.log"
    with open(log_path, "w") as log:
        server = subprocess.Popen(
            [wine64, str(server_dir / "server_tcp.exe"), str(unzipdir / "binaries" / "win64" / "flexbody.dll")],
            stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
            env={**os.environ, "WINEDEBUG": "-all"},
        )
    try:
        _wait_for_port(server, timeout=120.0)
        remote = FMU2Slave(
            guid=model_description.guid, unzipDirectory=str(unzipdir), modelIdentifier="client_tcp",
            instanceName="win64",
        )
        windows = _b1_step_response(remote, vr, outputs)
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        server.wait(timeout=30)
    local = FMU2Slave(
        guid=model_description.guid, unzipDirectory=str(unzipdir),
        modelIdentifier=model_description.coSimulation.modelIdentifier, instanceName="linux64",
    )
    linux = _b1_step_response(local, vr, outputs)
    # The step response moved the tip (the comparison is not vacuous) ...
    tip = outputs.index("tip.position[3]")
    assert linux[-1, tip] - linux[0, tip] < -1e-5
    # ... and the Windows DLL computed the same bits as the Linux library: one source, the same
    # IEEE arithmetic, no transcendental function whose libm could differ in the last bit.
    assert windows.tobytes() == linux.tobytes(), f"server log: {log_path.read_text()}"
