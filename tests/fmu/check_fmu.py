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
- the masses, g (and any parameter not a length or an angle) are tunable, ell and a fixed;
  stepping with fmi2DoStep at the 1e-4 s output step (FMPy's FMU2Slave):
  a) fmi2SetReal of g to its own value at t = 0.05 s (the rod on the cube, a fast phase) or
     0.15 s (the rod free) leaves theta within 1e-9 of the run without it at every output;
  b) g set to G2 at t = 0.05 s: from then until the contact ends, the energy with the new g,
     E = M(theta) theta_dot^2 / 2 + V_G2(theta), stays within 1e-8 (relative) of its value
     at 0.05 s, M(theta) = 2 (V(theta0) - V(theta)) / theta_dot^2(theta) from the paper's
     energy integral (eq. 9) by hand here; and the contact ends at another time than
     0.108493254 s;
  c) fmi2SetReal of ell (fixed) or of g = -1 between steps is fmi2Error with a logged
     message, and theta goes on as without it.
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

    tunable(fmu, md)


def stepping(fmu, md, steps, at=None, setting=None):
    """Time, theta, theta_dot, contact force and phase at each STEP output to steps * STEP by
    fmi2DoStep, with fmi2SetReal of `setting` ({name: value}) after `at` steps; also whether
    that call was refused and what was logged then."""
    vr = {v.name: v.valueReference for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="tune")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    names = ["theta", "theta_dot", "contact_force"]
    rows, refused, log = [], None, io.StringIO()
    for i in range(steps + 1):
        if i == at:
            with contextlib.redirect_stdout(log):
                try:
                    slave.setReal([vr[n] for n in setting], list(setting.values()))
                    refused = False
                except FMICallException as e:
                    assert e.status == fmi2Error, e
                    refused = True
        t = i * STEP
        rows.append([t, *slave.getReal([vr[n] for n in names]),
                     slave.getInteger([vr["phase"]])[0]])
        if i < steps:
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=(i + 1) * STEP - t)
    slave.terminate()
    slave.freeInstance()
    return np.array(rows), refused, log.getvalue().strip()


def tunable(fmu, md):
    variability = {v.name: v.variability for v in md.modelVariables if v.causality == "parameter"}
    assert variability == {"m1": "tunable", "m2": "tunable", "ell": "fixed", "a": "fixed",
                           "g": "tunable"}, variability
    print("tunable:", [n for n, v in variability.items() if v == "tunable"])
    steps = 1800
    plain, _, _ = stepping(fmu, md, steps)
    for t1 in (0.05, 0.15):
        at = round(t1 / STEP)
        same, refused, log = stepping(fmu, md, steps, at, {"g": G})
        assert refused is False, log
        err = np.max(np.abs(same[at:, 1] - plain[at:, 1]))
        assert err <= 1e-9, f"g set to itself at {t1} s: theta differs by {err}"
        assert np.array_equal(same[:at, 1], plain[:at, 1])
        assert np.array_equal(same[:, 4], plain[:, 4]), "the phase index changed"
        print(f"g = {G} again at t = {t1} s: theta within {err:.3e} rad of the run without it")

    at = round(0.05 / STEP)
    # To 0.13 s: with the larger g the rod lands before 0.18 s.
    run, refused, log = stepping(fmu, md, 1300, at, {"g": G2})
    assert refused is False, log
    t, theta, theta_dot, phase = run[:, 0], run[:, 1], run[:, 2], run[:, 4]
    contact = np.flatnonzero((t >= t[at]) & (phase == 0))
    end = contact[-1] + 1
    assert end < len(t) and phase[end] == 1, phase
    energy = mass(theta[contact]) * theta_dot[contact] ** 2 / 2 + potential(theta[contact], G2)
    drift = np.max(np.abs(energy / energy[0] - 1))
    assert drift <= 1e-8, f"the energy with g = {G2} drifts by {drift} (relative)"
    # The check tells: with the old g in V the same outputs are far from conserving energy.
    old = mass(theta[contact]) * theta_dot[contact] ** 2 / 2 + potential(theta[contact], G)
    assert np.max(np.abs(old / old[0] - 1)) > 1e-3
    assert abs(t[end] - SEPARATION) > 2 * STEP, f"the contact still ends at {t[end]} s"
    assert np.array_equal(theta[:at], plain[:at, 1])
    print(f"g = {G2} from t = 0.05 s: energy conserved within {drift:.3e} (relative) over "
          f"{len(contact)} outputs; the contact ends by {t[end]} s instead of {SEPARATION} s")

    for setting, word in (({"ell": 1.5}, "fixed"), ({"g": -1.0}, "-1")):
        run, refused, log = stepping(fmu, md, steps, at, setting)
        assert refused is True, f"{setting} between steps was accepted"
        assert word in log, log
        assert np.array_equal(run, plain), f"{setting}: the motion changed"
        print(f"{setting} between steps: refused, motion unchanged;", log)


# The paper's parameters (scenes/paper.yaml), and the new g of check b.
M1, M2, ELL, A, G = 1.0, 3.0, 1.0, 0.25, 9.81
G2 = 15.0


def potential(theta, g):
    """The rod's potential energy, m1 g (ell/2) sin(theta) (the cube's is constant)."""
    return M1 * g * ELL / 2 * np.sin(theta)


def mass(theta):
    """The generalized mass M(theta) of the contact phase: the paper's eq. (9), theta_dot^2 =
    4 (g/ell) (a/ell - sin(theta)) / (4/3 - sin(theta)^2 / (1 + m2/m1)) for the release from
    rest at theta0 = asin(a/ell), is energy conservation 1/2 M theta_dot^2 = V(theta0) -
    V(theta) (zero horizontal momentum, which a change of g keeps), so M = 2 (V(theta0) -
    V(theta)) / theta_dot^2, the same for any g (here g = 1)."""
    s = np.sin(theta)
    theta_dot_sq = 4 / ELL * (A / ELL - s) / (4 / 3 - s**2 / (1 + M2 / M1))
    return 2 * (potential(np.arcsin(A / ELL), 1.0) - potential(theta, 1.0)) / theta_dot_sq


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]))
