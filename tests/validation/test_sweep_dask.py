"""Sweeps on Dask: a LocalCluster of two worker processes gives the local executor's rows,
through ``run_sweep`` and through ``abdsim validate --sweep --scheduler ADDRESS``."""

from __future__ import annotations

import json
from concurrent.futures import ProcessPoolExecutor

import pytest

from abdsim.cli import main
from abdsim.validation import run_sweep
from abdsim.validation.scenes import default_scene
from abdsim.validation.sweep import SweepCase

distributed = pytest.importorskip("dask.distributed")

TIMING = {"speed_vs_mujoco"}  # wall-clock numbers differ from run to run


def cases(out, duration=0.1):
    return [
        SweepCase(str(default_scene()), dt, duration, str(out / f"dt{dt:g}")) for dt in (1e-3, 2e-3)
    ]


def results(rows):
    return [{k: v for k, v in r.items() if k not in TIMING and k != "out"} for r in rows]


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as c:
        yield c


def test_dask_sweep_equals_the_local_sweep(cluster, tmp_path):
    with ProcessPoolExecutor(max_workers=2) as pool:
        local = run_sweep(cases(tmp_path / "local"), executor=pool, progress=False)
    with distributed.Client(cluster) as client:
        remote = run_sweep(cases(tmp_path / "dask"), executor=client.get_executor(), progress=False)
        workers = client.run(lambda: __import__("os").getpid())
    assert len(workers) == 2
    assert all(r["passed"] and r["error"] is None for r in local)
    assert results(remote) == results(local)  # bit-identical errors, same verdicts
    assert local[0]["max_position_error"] > 0
    for r in remote:
        metrics = json.loads((tmp_path / "dask" / f"dt{r['dt']:g}" / "metrics.json").read_text())
        assert metrics["passed"] is True


def test_cli_sweep_on_a_scheduler(cluster, tmp_path, capsys):
    out = tmp_path / "cli"
    argv = ["validate", "--sweep", "--scheduler", cluster.scheduler_address, "--quiet"]
    argv += ["--duration", "0.1", "--sweep-dt", "1e-3", "--out", str(out), str(default_scene())]
    assert main(argv) == 0
    table = (out / "sweep.md").read_text()
    assert "tossed_bodies.xml | 0.001 | yes" in table
    assert "speed (× MuJoCo's, > 1 faster)" in table
    assert main(["validate", "--scheduler", cluster.scheduler_address]) == 1
    assert "add --sweep" in capsys.readouterr().err
