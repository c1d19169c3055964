"""FMPy's view of an FMU that `rodcube fmu rod_cube` wrote (run by tests/fmu.rs).

Usage: check_fmu.py FMU SERIES_JSON LANDING_JSON STOP_TIME
- FMPy validates the model description without a problem;
- `simulate_fmu` at a 1e-4 s output step to STOP_TIME gives theta within 1e-9 of the
  theta_series of SERIES_JSON (`rodcube run` of the same parameters with `until: STOP_TIME`
  and samples on the same 1e-4 s grid), at the same times;
- the first output time with a zero contact force is within one output step of
  0.108493254 s, and the phase index goes from 0 to 1 there;
- run to 0.3 s, the FMU stops at the rod's landing (fmi2Discard, fmi2Terminated), at the
  time `rodcube run` gives for it (LANDING_JSON's floor_impact_time);
- fmi2SetReal of a parameter out of its domain is fmi2Error with a logged message, and so is
  fmi2ExitInitializationMode with parameters that break a requirement (a < ell); after
  fmi2Reset the start values hold again, and the release angle, asin(a/ell), can be read in
  initialization mode.
Prints one line per check; exits non-zero (an AssertionError) on the first that fails.
"""

import contextlib
import io
import json
import sys

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2Error
from fmpy.validation import validate_fmu

STEP = 1e-4
SEPARATION = 0.108493254


def main(fmu, results, landing, stop):
    problems = validate_fmu(fmu)
    assert problems == [], f"FMPy's validation: {problems}"
    md = read_model_description(fmu, validate=True, validate_variable_names=True,
                                validate_model_structure=True)
    names = [v.name for v in md.modelVariables]
    print("validated:", len(names), "variables")

    columns = json.load(open(results))["series"]["theta_series"]["columns"]
    t_run = np.array(columns[0]["values"])
    theta_run = np.array(columns[1]["values"])
    r = simulate_fmu(fmu, stop_time=stop, output_interval=STEP)
    assert len(r) == len(t_run), f"{len(r)} FMU samples, {len(t_run)} in the run's series"
    dt = np.max(np.abs(r["time"] - t_run))
    assert dt < 1e-15, f"the series' times differ from the FMU's by {dt}"
    err = np.max(np.abs(r["theta"] - theta_run))
    assert err <= 1e-9, f"theta differs from rodcube run's by {err}"
    print(f"theta: largest difference {err:.3e} rad over {len(r)} samples")

    zero = np.flatnonzero(r["contact_force"] <= 0.0)
    assert zero.size > 0, "the contact force never reaches zero"
    t0 = r["time"][zero[0]]
    assert abs(t0 - SEPARATION) <= STEP, f"first zero force at {t0} s"
    assert np.all(r["contact_force"][: zero[0]] > 0.0)
    phases = r["phase"]
    assert phases[0] == 0 and phases[zero[0] - 1] == 0 and phases[zero[0]] == 1, phases
    print(f"first zero contact force at {t0} s")

    log = io.StringIO()
    with contextlib.redirect_stdout(log):
        full = simulate_fmu(fmu, stop_time=0.3, output_interval=STEP)
    landing = json.load(open(landing))["results"]["floor_impact_time"]["value"]
    assert abs(full["time"][-1] - landing) < 1e-15, (full["time"][-1], landing)
    assert "the motion ended" in log.getvalue(), log.getvalue()
    print(f"to 0.3 s: stops at the landing, {full['time'][-1]} s")

    unzipdir = extract(fmu)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="check")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    slave.instantiate()
    log = io.StringIO()
    with contextlib.redirect_stdout(log):
        try:
            slave.setReal([vr["m1"]], [-1.0])
            raise AssertionError("fmi2SetReal(m1 = -1) was accepted")
        except FMICallException as e:
            assert e.status == fmi2Error, e
    assert "m1" in log.getvalue() and "-1" in log.getvalue(), log.getvalue()
    print("fmi2SetReal(m1 = -1):", log.getvalue().strip())
    assert slave.getReal([vr["m1"]]) == [1.0]
    slave.setReal([vr["a"]], [2.0])
    slave.setupExperiment()
    slave.enterInitializationMode()
    log = io.StringIO()
    with contextlib.redirect_stdout(log):
        try:
            slave.exitInitializationMode()
            raise AssertionError("a = 2 m with ell = 1 m was accepted")
        except FMICallException as e:
            assert e.status == fmi2Error, e
    print("a = 2 m, ell = 1 m:", log.getvalue().strip())
    slave.reset()
    slave.setupExperiment()
    slave.enterInitializationMode()
    initial = slave.getReal([vr["theta"]])[0]
    slave.exitInitializationMode()
    assert initial == slave.getReal([vr["theta"]])[0] == r["theta"][0] == np.arcsin(0.25)
    print("after fmi2Reset: theta at release", initial, "in and after initialization mode")
    slave.terminate()
    slave.freeInstance()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]))
