"""Many runs of one FMU, farmed out with Dask distributed and collected into one table.

A parameter study, a design of experiments or a Monte-Carlo over loads is a list of *cases*, each
a dict of start values (parameters and inputs held from t = 0). ``run_cases`` runs them with
``fmpy.simulate_fmu`` on the workers of a ``dask.distributed.Client`` (a ``LocalCluster`` on this
machine, or a scheduler on a cluster) or, without a client, one after the other here, and returns
one table: a NumPy structured array with a ``case`` column (the case's index), ``time`` and the
outputs asked for, ordered by case and time. The FMU's bytes travel to the workers once
(``Client.scatter``) and so does this file (``Client.upload_file``), so the workers need neither a
shared file system nor this repository, only the pinned fmpy and NumPy; each worker process writes
the FMU to its temporary directory once. A run is the same computation wherever it runs: the table is the
same, bit for bit, with or without the cluster.

Command line (a sweep of one start value)::

    python tests/python/farm.py --fmu target/fmu/cantilever.fmu --workers 2 \\
        --sweep tip.force[2]=-1,-2,-5,-10 --stop-time 0.05 --interval 0.001 \\
        --output tip.position[2] --output root.force[2] --csv sweep.csv

``--scheduler tcp://host:8786`` uses a running cluster instead of a local one.
"""

import argparse
import hashlib
import os
import tempfile

import numpy as np
from fmpy import simulate_fmu


def _local_copy(fmu_bytes: bytes) -> str:
    """The FMU as a file in this process's temporary directory (written once per content)."""
    digest = hashlib.sha256(fmu_bytes).hexdigest()[:16]
    path = os.path.join(tempfile.gettempdir(), f"flexbody-farm-{digest}.fmu")
    if not os.path.exists(path):
        partial = f"{path}.{os.getpid()}.partial"
        with open(partial, "wb") as f:
            f.write(fmu_bytes)
        os.replace(partial, path)
    return path


def run_case(fmu_bytes: bytes, case: int, start_values: dict, stop_time: float,
             output_interval: float, outputs: list) -> np.ndarray:
    """One run: its rows of the table (``case``, ``time``, the outputs)."""
    result = simulate_fmu(
        _local_copy(fmu_bytes),
        start_values=start_values,
        stop_time=stop_time,
        output_interval=output_interval,
        output=outputs,
    )
    rows = np.zeros(len(result), dtype=_row_type(outputs))
    rows["case"] = case
    for name in ["time"] + outputs:
        rows[name] = result[name]
    return rows


def _row_type(outputs: list) -> np.dtype:
    return np.dtype([("case", np.int64), ("time", np.float64)] + [(n, np.float64) for n in outputs])


def run_cases(fmu_path: str, cases: list, *, stop_time: float, output_interval: float,
              outputs: list, client=None) -> np.ndarray:
    """Runs every case (a dict of start values) and returns the one table of all their rows.
    With ``client`` (``dask.distributed.Client``) the runs go to its workers, otherwise they run
    here one after the other."""
    with open(fmu_path, "rb") as f:
        fmu_bytes = f.read()
    arguments = [(i, dict(case), stop_time, output_interval, list(outputs)) for i, case in enumerate(cases)]
    if client is None:
        parts = [run_case(fmu_bytes, *a) for a in arguments]
    else:
        # The workers import run_case from this file: send it along (a cluster's workers do not
        # have this repository).
        client.upload_file(os.path.abspath(__file__))
        shared = client.scatter(fmu_bytes, broadcast=True)
        futures = [client.submit(run_case, shared, *a, pure=False) for a in arguments]
        parts = client.gather(futures)
    if not parts:
        return np.zeros(0, dtype=_row_type(outputs))
    return np.concatenate(parts)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu", required=True)
    parser.add_argument("--sweep", required=True, help="NAME=V1,V2,...: one case per value")
    parser.add_argument("--set", action="append", default=[], help="NAME=VALUE in every case")
    parser.add_argument("--stop-time", type=float, required=True)
    parser.add_argument("--interval", type=float, required=True)
    parser.add_argument("--output", action="append", required=True)
    parser.add_argument("--workers", type=int, default=2, help="local cluster size")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler")
    parser.add_argument("--csv", help="write the table here")
    args = parser.parse_args()

    name, values = args.sweep.split("=", 1)
    common = dict((kv.split("=", 1)[0], float(kv.split("=", 1)[1])) for kv in args.set)
    cases = [{**common, name: float(v)} for v in values.split(",")]

    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client = Client(args.scheduler)
    else:
        client = Client(LocalCluster(n_workers=args.workers, threads_per_worker=1, dashboard_address=None))
    with client:
        table = run_cases(args.fmu, cases, stop_time=args.stop_time, output_interval=args.interval,
                          outputs=args.output, client=client)
    if args.csv:
        np.savetxt(args.csv, table, delimiter=",", header=",".join(table.dtype.names), comments="",
                   fmt=["%d"] + ["%.17g"] * (len(table.dtype.names) - 1))
    for case in range(len(cases)):
        last = table[table["case"] == case][-1]
        print(f"case {case} ({name} = {cases[case][name]}): " +
              ", ".join(f"{n} = {last[n]:.6g}" for n in args.output) + f" at t = {last['time']:g}")


if __name__ == "__main__":
    main()
