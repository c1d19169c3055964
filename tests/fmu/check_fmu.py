"""FMPy's view of the FMUs that `rodcube fmu` writes (run by tests/fmu.rs).

Usage: check_fmu.py paper FMU SERIES_JSON LANDING_JSON STOP_TIME
       check_fmu.py tape FMU RUN_JSON TAPES_DIR STOP_TIME

`paper`: the FMU of `rod_cube`, compiled into the library too:
- FMPy validates the model description without a problem; the FMU carries the tapes of the
  system and its two fast phases in resources/, those of generated/;
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

`tape`: the FMU of a model that is only a tape (derived into TAPES_DIR by the test, compiled
into no library), RUN_JSON being `rodcube run --models TAPES_DIR` of the FMU's scene (to
STOP_TIME, samples on the 1e-4 s grid, every output's series):
- FMPy validates it; its resources/ hold rodcube.json and the model's tape, byte for byte
  the file of TAPES_DIR;
- unzipped into a directory whose name needs percent-encoding in the resource location
  (a space, `%`, a non-ASCII letter), `simulate_fmu` at a 1e-4 s output step to STOP_TIME
  gives every output (the angle, its rate, every contact's force, every point) within 1e-9
  (relative to the value, or absolute under 1) of the run's series at the same times, and the
  phase index of the run's phases (the push's end, the landing's impact) at every output;
- without its tape in resources/ fmi2Instantiate fails, logging that there is no such model;
  with the tape's body edited, logging the tape's digest.
Prints one line per check; exits non-zero (an AssertionError) on the first that fails.
"""

import contextlib
import io
import json
import pathlib
import shutil
import sys
import zipfile

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2Error
from fmpy.validation import validate_fmu

STEP = 1e-4
SEPARATION = 0.108493254


def validated(fmu):
    """The model description, after FMPy's validation found no problem."""
    problems = validate_fmu(fmu)
    assert problems == [], f"FMPy's validation: {problems}"
    md = read_model_description(fmu, validate=True, validate_variable_names=True,
                                validate_model_structure=True)
    print("validated:", len(md.modelVariables), "variables")
    return md


def resources(fmu):
    """The files in the FMU's resources/, by name, with their contents."""
    with zipfile.ZipFile(fmu) as z:
        return {n[len("resources/"):]: z.read(n) for n in z.namelist()
                if n.startswith("resources/")}


def paper(fmu, results, landing, stop):
    md = validated(fmu)
    generated = pathlib.Path(__file__).resolve().parents[2] / "generated"
    models = ["rod_cube", "rod_cube_closed", "rod_cube_free"]
    carried = resources(fmu)
    assert sorted(carried) == sorted(["rodcube.json"] + [f"{m}.tape.json" for m in models]), \
        sorted(carried)
    for m in models:
        assert carried[f"{m}.tape.json"] == (generated / f"{m}.tape.json").read_bytes(), m
    print("resources/ carries the tapes of", ", ".join(models), "as generated/ holds them")

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


def tape(fmu, run, tapes, stop):
    md = validated(fmu)
    model = md.modelName
    carried = resources(fmu)
    assert sorted(carried) == ["rodcube.json", f"{model}.tape.json"], sorted(carried)
    own = (pathlib.Path(tapes) / f"{model}.tape.json").read_bytes()
    assert carried[f"{model}.tape.json"] == own, "the tape differs from the one derived"
    print(f"resources/ carries {model}.tape.json as derived")

    # Unzipped where the resource location needs percent-encoding: FMPy's is
    # pathlib.Path(...).as_uri().
    where = pathlib.Path("un zipped %41 é").resolve()
    shutil.rmtree(where, ignore_errors=True)
    unzipped = pathlib.Path(extract(fmu, unzipdir=str(where)))
    location = (unzipped / "resources").as_uri()
    assert "%20" in location and "%25" in location, location
    r = simulate_fmu(str(unzipped), stop_time=stop, output_interval=STEP)

    data = json.load(open(run))
    series = {}
    for s in data["series"].values():
        columns = {c["name"]: np.array(c["values"]) for c in s["columns"]}
        t = columns.pop("t")
        assert len(r) == len(t), f"{len(r)} FMU samples, {len(t)} in the run's series"
        dt = np.max(np.abs(r["time"] - t))
        assert dt < 1e-15, f"the series' times differ from the FMU's by {dt}"
        series.update(columns)
    # In value-reference order: the angle, its rate, the contacts' forces, the points.
    outputs = [v.name for v in md.modelVariables
               if v.causality == "output" and v.type == "Real"]
    # The run's name of each output: the angle and its rate are named by the coordinate in
    # theta_series as in the FMU (`th`, `th_dot`), a point's x and y are in its trajectory, a
    # force has its own name.
    worst = 0.0
    for name in outputs:
        ours = name
        want = trajectory(data, ours) if "." in ours else series.get(ours)
        assert want is not None, f"the run has no series of {name}"
        err = np.max(np.abs(r[name] - want) / np.maximum(1.0, np.abs(want)))
        assert err <= 1e-9, f"{name} differs from rodcube run's by {err} (relative)"
        worst = max(worst, err)
    print(f"{len(outputs)} outputs ({', '.join(outputs)}) within {worst:.3e} of rodcube run's "
          f"series over {len(r)} samples, unzipped in {where.name!r} ({location})")

    results = data["results"]
    ends = sorted(v["value"] for k, v in results.items() if k.endswith("_end_time")
                  and k != "contact_end_time")
    ends += [i["time"] for i in results["impacts"]["value"]]
    want = np.array([sum(t >= e for e in ends) for t in r["time"]])
    assert np.array_equal(r["phase"], want), (r["phase"], ends)
    print(f"phase index as the run's phases, ending at {ends} s: 0 to {r['phase'][-1]}")

    refused(md, unzipped, lambda d: (d / f"{model}.tape.json").unlink(),
            f"no model `{model}`", "without its tape")

    def edit(d):
        text = (d / f"{model}.tape.json").read_text()
        at = text.index('"body"')
        (d / f"{model}.tape.json").write_text(text[:at] + text[at:].replace("0", "1", 1))
    refused(md, unzipped, edit, "digest", "with its body edited")


def trajectory(data, name):
    """A point's x or y from the run's `<point>_trajectory` series (`name` is
    `<point>.<axis>`, the FMU's)."""
    point, axis = name.split(".")
    s = data["series"].get(f"{point}_trajectory")
    if s is None:
        return None
    return np.array(next(c["values"] for c in s["columns"] if c["name"] == axis))


def refused(md, unzipped, change, message, what):
    """fmi2Instantiate of a copy of the unzipped FMU with `change` made to its resources/
    fails, logging `message`."""
    copy = unzipped.parent / (unzipped.name + " changed")
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(unzipped, copy)
    change(copy / "resources")
    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(copy),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="changed")
    log = io.StringIO()
    try:
        with contextlib.redirect_stdout(log):
            slave.instantiate()
    except Exception:  # FMPy raises where fmi2Instantiate returns NULL.
        pass
    else:
        raise AssertionError(f"fmi2Instantiate {what} succeeded")
    assert message in log.getvalue(), log.getvalue()
    print(f"{what}: fmi2Instantiate fails:", log.getvalue().strip())


if __name__ == "__main__":
    if sys.argv[1] == "paper":
        paper(sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5]))
    elif sys.argv[1] == "tape":
        tape(sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5]))
    else:
        sys.exit(f"unknown check {sys.argv[1]!r}: paper or tape")
