"""The cost of python/examples/dask_sweep.py's sweep (rod_cube_friction, contact_end and
floor_impact over 64 x 16 points of mu and m2) in this process with `rodcube.sweep` and on a
dask.distributed LocalCluster of two single-threaded workers (blocks of 16 x 8 points), best of
three runs each after one to warm up, and whether the two results agree to the bit. Run with
the interpreter the package and dask are installed in:
    python python/benches/dask_sweep.py
"""

import importlib.util
import pathlib
import time

from dask.distributed import Client, LocalCluster

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "dask_sweep.py"


def best_of_three(run):
    run()
    best, out = float("inf"), None
    for _ in range(3):
        start = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - start)
    return best, out


def main():
    spec = importlib.util.spec_from_file_location("dask_sweep", EXAMPLE)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    local_s, local = best_of_three(example.local_sweep)
    points = local["ok"].size
    print(f"local rodcube.sweep: {points} points in {local_s:.3f} s ({local_s / points * 1e3:.3f} ms a point)")
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster) as client:
        dask_s, distributed = best_of_three(lambda: example.distributed_sweep(client))
    same = all(distributed[k].tobytes() == local[k].tobytes() for k in local if k != "errors")
    same = same and distributed["errors"] == local["errors"]
    print(f"dask map_blocks on 2 workers: {dask_s:.3f} s ({dask_s / local_s:.2f} x local); same to the bit: {same}")


if __name__ == "__main__":
    main()
