"""python/examples/dask_sweep.py on a dask.distributed cluster: run as a user runs it, with no
argument (it starts a LocalCluster of two workers) and with the address of a cluster's
scheduler, its result equals the local `rodcube.sweep` of the same grid to the bit: every
float's bytes (NaN included), the mask and every error's index and message."""

import importlib.util
import pathlib
import subprocess
import sys

import numpy as np
from dask.distributed import LocalCluster

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "dask_sweep.py"


def example():
    """The example as a module, for its grid and its local sweep (starting no cluster)."""
    spec = importlib.util.spec_from_file_location("dask_sweep", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(tmp_path, *args):
    """Runs the example in a fresh interpreter; returns what it printed and what it saved."""
    out = tmp_path / "result.npz"
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), *args, "--out", str(out)], capture_output=True, text=True, cwd=tmp_path
    )
    assert done.returncode == 0, done.stdout + done.stderr
    with np.load(out) as saved:
        return done.stdout, {name: saved[name] for name in saved.files}


def assert_same_to_the_bit(saved, local):
    keys = [k for k in local if k != "errors"]
    assert sorted(keys) == sorted(k for k in saved if not k.startswith("error_"))
    for key in keys:
        assert saved[key].dtype == local[key].dtype and saved[key].shape == local[key].shape, key
        assert saved[key].tobytes() == local[key].tobytes(), key
    assert [tuple(int(i) for i in row) for row in saved["error_index"]] == [i for i, _ in local["errors"]]
    assert saved["error_message"].tolist() == [m for _, m in local["errors"]]


def test_the_example_on_a_local_cluster_of_two_workers_is_the_local_sweep(tmp_path):
    printed, saved = run(tmp_path)
    assert "on 2 workers" in printed, printed
    local = example().local_sweep()
    # The grid has both kinds of points: some with every result, some where the contact holds.
    assert local["ok"].any() and not local["ok"].all()
    assert_same_to_the_bit(saved, local)


def test_the_example_uses_the_cluster_at_the_address_given(tmp_path):
    # Three workers, so that the example's own cluster (two) would show.
    with LocalCluster(n_workers=3, threads_per_worker=1, dashboard_address=None) as cluster:
        printed, saved = run(tmp_path, cluster.scheduler_address)
    assert "on 3 workers" in printed, printed
    assert_same_to_the_bit(saved, example().local_sweep())
