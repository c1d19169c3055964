"""Sweep throughput from Python: rodcube.sweep over 1e6 points of rod_cube (n = m2/m1 from
1e-3 to 1e3 logarithmically, a/ell from 0.01 to 0.99), best of three runs, arrays in and out
included. Run with the interpreter the package is installed in:
    python python/benches/sweep.py
"""

import time

import numpy as np

import rodcube

n = np.logspace(-3, 3, 1000).repeat(1000)
a = np.tile(np.linspace(0.01, 0.99, 1000), 1000)
best = float("inf")
for _ in range(3):
    start = time.perf_counter()
    out = rodcube.sweep(n, a)
    best = min(best, time.perf_counter() - start)
failed = int(np.isnan(out["separation_time"]).sum())
print(f"{n.size} points in {best:.3f} s: {n.size / best:.3e} points/s ({failed} without a solution)")
