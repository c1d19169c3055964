"""How long FMPy takes to simulate the paper's FMU, and how much of that is the FMU.

Usage: python benches/fmu_fmpy.py FMU [RUNS]  (FMPy from tests/fmu/requirements.txt)

Simulates FMU (`rodcube fmu rod_cube --out DIR` writes DIR/rod_cube.fmu) with
`fmpy.simulate_fmu(FMU, stop_time=0.3, output_interval=1e-4)` RUNS times (default 20) and
prints, for the fastest and the median run: the whole call's wall time (FMPy's extraction of
the archive, loading, instantiation, its step loop and its recorder included), the time spent
inside the FMU (timed around the C calls FMPy makes, their ctypes conversions included):
`fmi2Instantiate` and `fmi2ExitInitializationMode` (reads the resources, solves the release),
`fmi2DoStep` (walks the motion and samples it) and `fmi2GetReal`/`fmi2GetInteger` (the
recorder's reads of the outputs), and the share of the total they make. The same with the archive extracted once beforehand
(`simulate_fmu` of the directory), which leaves FMPy's own loop as the rest. The motion ends
at the rod's landing, 0.187 s, where the FMU stops the run (fmi2Discard, fmi2Terminated).
"""

import sys
import time

import fmpy
from fmpy import extract
from fmpy.fmi1 import _FMU

TIMED = {
    "fmi2Instantiate": "setup",
    "fmi2ExitInitializationMode": "setup",
    "fmi2DoStep": "doStep",
    "fmi2GetReal": "get",
    "fmi2GetInteger": "get",
}
spent = {"setup": 0.0, "doStep": 0.0, "get": 0.0}
calls = {"setup": 0, "doStep": 0, "get": 0}
original = _FMU._call


def timed_call(self, fname, *args):
    key = TIMED.get(fname)
    if key is None:
        return original(self, fname, *args)
    t0 = time.perf_counter()
    try:
        return original(self, fname, *args)
    finally:
        spent[key] += time.perf_counter() - t0
        calls[key] += 1


_FMU._call = timed_call


def measure(target, runs):
    rows = []
    for _ in range(runs):
        for k in spent:
            spent[k], calls[k] = 0.0, 0
        t0 = time.perf_counter()
        result = fmpy.simulate_fmu(target, stop_time=0.3, output_interval=1e-4)
        total = time.perf_counter() - t0
        row = (total, spent["setup"], spent["doStep"], spent["get"], dict(calls))
        rows.append(row + (result["time"][-1],))
    rows.sort(key=lambda r: r[0])
    return rows


def show(label, rows):
    for name, row in [("fastest", rows[0]), ("median", rows[len(rows) // 2])]:
        total, setup, step, get, n, end = row
        fmu = setup + step + get
        print(
            f"{label:9} {name:7}: total {total * 1e3:6.1f} ms; in the FMU {fmu * 1e3:5.1f} ms "
            f"({fmu / total:4.0%}): instantiate + exit initialization {setup * 1e3:4.1f} ms, "
            f"fmi2DoStep {step * 1e3:5.1f} ms ({n['doStep']} calls, "
            f"{step / n['doStep'] * 1e6:.1f} us each), outputs read {get * 1e3:5.1f} ms; "
            f"FMPy's rest {(total - fmu) * 1e3:5.1f} ms; simulated to {end:.6f} s"
        )


def main():
    fmu = sys.argv[1]
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    show("archive", measure(fmu, runs))
    show("extracted", measure(extract(fmu), runs))


if __name__ == "__main__":
    main()
