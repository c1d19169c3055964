"""Sweep throughput from Python: rodcube.sweep over 1e6 points of rod_cube (n = m2/m1 from
1e-3 to 1e3 logarithmically down a column, a/ell from 0.01 to 0.99 along a row, broadcast to
1000 x 1000; m1 = 1 kg, ell = 1 m, g = 9.81 m/s^2), best of three runs, arrays in and out
included. Run with the interpreter the package is installed in:
    python python/benches/sweep.py
"""

import time

import numpy as np

import rodcube

n = np.logspace(-3, 3, 1000)[:, None]
a = np.linspace(0.01, 0.99, 1000)
best = float("inf")
for _ in range(3):
    start = time.perf_counter()
    out = rodcube.sweep(n, a, m1=1.0, ell=1.0, g=9.81)
    best = min(best, time.perf_counter() - start)
size = out["ok"].size
failed = len(out["errors"])
print(f"{size} points in {best:.3f} s: {size / best:.3e} points/s ({failed} without a solution)")
