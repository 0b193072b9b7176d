"""``farm.py``: runs farmed out to a Dask LocalCluster with two worker processes give the table the
same runs give one by one, bit for bit."""

import numpy as np
import pytest
from dask.distributed import Client, LocalCluster

from farm import run_cases

# Six tip loads on the default cantilever, 20 ms each.
CASES = [{"tip.force[2]": -f} for f in (1.0, 2.0, 5.0, 10.0, 20.0, 50.0)]
RUN = dict(stop_time=0.02, output_interval=1e-3, outputs=["tip.position[2]", "root.force[2]"])


def test_a_local_cluster_gives_the_table_of_the_runs_one_by_one(fmu_path):
    one_by_one = run_cases(fmu_path, CASES, **RUN)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        farmed = run_cases(fmu_path, CASES, client=client, **RUN)
    assert farmed.dtype == one_by_one.dtype
    assert len(farmed) == len(CASES) * 21
    for name in farmed.dtype.names:
        assert np.array_equal(farmed[name], one_by_one[name]), name
    # The table holds real, distinct runs: the tip goes down, more under more load (linear
    # regime: the deflection at 20 ms in proportion to the load within 2 %).
    final = farmed[farmed["time"] == farmed["time"].max()]
    deflection = final["tip.position[2]"] - farmed[farmed["time"] == 0.0]["tip.position[2]"]
    loads = np.array([c["tip.force[2]"] for c in CASES])
    assert np.all(deflection < 0)
    assert deflection / loads == pytest.approx(np.full(len(CASES), deflection[0] / loads[0]), rel=0.02)
