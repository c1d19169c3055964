"""A sweep of the rod on the cube with Coulomb friction at its foot on a dask.distributed cluster.

The grid of the friction coefficient mu (0 to 2) and the cube's mass m2 (1 to 6 kg) is cut into
blocks with dask.array; ``dask.array.map_blocks`` hands each block to a worker, which runs
``rodcube.sweep(model="rod_cube_friction", want=["contact_end", "floor_impact"], ...)`` on it
(rodcube's own threads, the GIL released) and returns its results as one NumPy record array:
a float field per scalar result (``rodcube.sweep_results`` names them), ``ok``, and ``error``
(rodcube's reason where ``ok`` is False). The workers need the rodcube wheel installed, as they
need NumPy and dask; nothing else of this file is installed: dask sends the block function.

    python dask_sweep.py                     # a LocalCluster of two workers on this machine
    python dask_sweep.py tcp://host:8786     # the cluster whose scheduler is at that address
    python dask_sweep.py --out result.npz    # also save the arrays (python/tests checks them)

Each point's numbers do not depend on where it ran, so the result is the local
``rodcube.sweep`` over the whole grid to the bit (``local_sweep()``).
"""

from __future__ import annotations

import argparse
import time

import dask.array as da
import numpy as np
from dask.distributed import Client, LocalCluster

import rodcube

MODEL = "rod_cube_friction"
WANT = ["contact_end", "floor_impact"]
# The paper's rod and cube but for m2 (an axis): rodcube assumes no value, so each is given.
FIXED = {"m1": 1.0, "ell": 1.0, "a": 0.25, "g": 9.81}
# Points per block along mu and m2.
CHUNKS = (16, 8)


def axes():
    """The grid: mu down the rows (64 values), m2 across the columns (16), as full arrays."""
    mu = np.linspace(0.0, 2.0, 64)[:, None]
    m2 = np.linspace(1.0, 6.0, 16)[None, :]
    return np.broadcast_arrays(mu, m2)


def record_dtype():
    """A block's record: a float per scalar result of WANT, then ``ok`` and ``error``."""
    fields = [(key, np.float64) for key, _unit in rodcube.sweep_results(MODEL, WANT)]
    return np.dtype(fields + [("ok", np.bool_), ("error", object)])


def block(mu, m2):
    """One block's points on a worker: ``rodcube.sweep``'s dict as a record array."""
    result = rodcube.sweep(model=MODEL, want=WANT, mu=mu, m2=m2, **FIXED)
    records = np.empty(mu.shape, dtype=record_dtype())
    for key, _unit in rodcube.sweep_results(MODEL, WANT):
        records[key] = result[key]
    records["ok"] = result["ok"]
    records["error"] = ""
    for index, message in result["errors"]:
        records["error"][index] = message
    return records


def as_sweep(records):
    """The grid's record array as ``rodcube.sweep`` returns it: an array per result, ``ok``
    and ``errors``, ``(index, message)`` in C order."""
    out = {name: records[name] for name in records.dtype.names if name not in ("ok", "error")}
    out["ok"] = records["ok"]
    out["errors"] = [
        (tuple(int(i) for i in index), records["error"][tuple(index)])
        for index in np.argwhere(~records["ok"])
    ]
    return out


def distributed_sweep(client):
    """The sweep over the grid on ``client``'s cluster, block by block."""
    mu, m2 = (da.from_array(a, chunks=CHUNKS) for a in axes())
    meta = np.empty((0, 0), dtype=record_dtype())
    records = da.map_blocks(block, mu, m2, dtype=meta.dtype, meta=meta)
    return as_sweep(client.compute(records).result())


def local_sweep():
    """The same sweep in this process, in one call."""
    mu, m2 = axes()
    return rodcube.sweep(model=MODEL, want=WANT, mu=mu, m2=m2, **FIXED)


def save(result, path):
    """The result in an ``.npz`` (no pickles): each array, ``ok``, and the errors as
    ``error_index`` (one row per failed point) and ``error_message``."""
    arrays = {k: v for k, v in result.items() if k != "errors"}
    ndim = result["ok"].ndim
    index = np.array([i for i, _ in result["errors"]], dtype=np.intp).reshape(-1, ndim)
    messages = np.array([m for _, m in result["errors"]], dtype=str)
    np.savez(path, error_index=index, error_message=messages, **arrays)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "address", nargs="?", help="a dask scheduler's address (default: a LocalCluster of two workers)"
    )
    parser.add_argument("--out", help="save the result to this .npz file")
    args = parser.parse_args()
    if args.address:
        client, cluster = Client(args.address), None
    else:
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None)
        client = Client(cluster)
    try:
        start = time.perf_counter()
        result = distributed_sweep(client)
        seconds = time.perf_counter() - start
        workers = len(client.scheduler_info()["workers"])
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    ok = result["ok"]
    t = result["contact_end_time"]
    print(f"{MODEL}: {ok.size} points on {workers} workers in {seconds:.2f} s, {int(ok.sum())} with every result")
    print(f"the rod leaves the cube after {np.nanmin(t):.4f} to {np.nanmax(t):.4f} s")
    for index, message in result["errors"][:3]:
        print(f"  {index}: {message}")
    if args.out:
        save(result, args.out)
        print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
