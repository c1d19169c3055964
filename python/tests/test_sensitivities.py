"""rodcube's exact sensitivities from Python: `solve(..., want=[..., "sensitivities"])` gives
the numbers of `rodcube run`'s results.json (to the bit, units included), `sweep(...,
sensitivities=True)` those of `rodcube sweep --sensitivities` (to the bit) and of `solve` (the
angle's to the bit; the time's, which the planner and the per-point solver integrate from
differently rounded fall coefficients, within 1e-15 relative, or of the natural scale t/p
where cancellation makes the sensitivity small), and all of them
agree with central differences of the sweep's own angle and time. An integrated separation
has its forward sensitivities; a sensitivity that does not exist (an impact's) is no number,
and the note says why.

`tests/python.rs` sets RODCUBE_BIN to the `rodcube` binary of the same build."""

import csv
import json
import math
import os
import subprocess

import numpy as np
import pytest

import rodcube
from test_rodcube import PAPER

WANT = ["separation_angle", "separation_time", "sensitivities"]
OF = ("separation_angle", "separation_time")


def cli(*args):
    binary = os.environ.get("RODCUBE_BIN")
    assert binary, "RODCUBE_BIN must name the rodcube binary (tests/python.rs sets it)"
    return subprocess.run([binary, *args], capture_output=True, text=True, check=True)


def test_solve_gives_results_jsons_sensitivities_to_the_bit(tmp_path):
    scene = tmp_path / "paper.yaml"
    values = ", ".join(f"{k}: {v!r}" for k, v in PAPER.items())
    scene.write_text(f"model: rod_cube\nparameters: {{{values}}}\nwant: [{', '.join(WANT)}]\n")
    cli("run", str(scene), "--out", str(tmp_path / "out"))
    record = json.loads((tmp_path / "out" / "results.json").read_text())["sensitivities"]
    one = rodcube.solve("rod_cube", want=WANT, **PAPER)
    assert set(one["sensitivities"]) == set(record) == set(one["sensitivity_units"])
    for key, entry in record.items():
        assert one["sensitivities"][key] == entry["value"], key
        assert one["sensitivity_units"][key] == entry["unit"], key
    # Every parameter, for the angle and the time, and the elasticities.
    for of in OF:
        for p in PAPER:
            assert f"d({of})/d({p})" in record and f"elasticity({of};{p})" in record
    assert one["sensitivity_units"]["d(separation_time)/d(g)"] == "s^3/m"
    assert one["sensitivities"]["d(separation_angle)/d(g)"] == 0.0
    assert "notes" not in one or not any(k.startswith("sensitivities") for k in one["notes"])


def test_sweep_gives_rodcube_sweeps_numbers_and_solves():
    n = np.array([0.01, 1.0, 3.0, 100.0])
    a = np.array([0.1, 0.5, 0.25, 0.9])
    s = rodcube.sweep(n, a, m1=1.0, ell=1.0, g=9.81, sensitivities=True)
    assert s["ok"].all() and s["errors"] == []
    names = [f"d({of})/d({p})" for of in OF for p in PAPER]
    assert [k for k in s if k.startswith("d(")] == names
    for i in range(len(n)):
        point = dict(PAPER, m2=n[i], a=a[i])
        one = rodcube.solve("rod_cube", want=WANT, **point)
        for p in PAPER:
            key = f"d(separation_angle)/d({p})"
            assert s[key][i] == one["sensitivities"][key], (i, key)
            key = f"d(separation_time)/d({p})"
            scale = max(one["separation_time"] / point[p], abs(one["sensitivities"][key]))
            assert abs(s[key][i] - one["sensitivities"][key]) <= 1e-15 * scale, (i, key)
    # Without the flag there are no such arrays.
    assert not any(k.startswith("d(") for k in rodcube.sweep(n, a, m1=1.0, ell=1.0, g=9.81))


def test_sweep_gives_the_clis_sweep_columns_to_the_bit(tmp_path):
    out = tmp_path / "out"
    cli("sweep", "--n", "0.5,3", "--a-over-ell", "0.25,0.75", "--set", "m1=1,ell=1,g=9.81",
        "--sensitivities", "--out", str(out))
    lines = [l for l in (out / "sweep.csv").read_text().splitlines() if not l.startswith("#")]
    rows = list(csv.DictReader(lines))
    assert len(rows) == 4
    s = rodcube.sweep(
        n=[float(r["n"]) for r in rows],
        a_over_ell=[float(r["a_over_ell"]) for r in rows],
        m1=1.0, ell=1.0, g=9.81, sensitivities=True,
    )
    for i, row in enumerate(rows):
        for of in OF:
            for p in PAPER:
                key = f"d({of})/d({p})"
                assert s[key][i] == float(row[key]), (i, key)


@pytest.mark.parametrize("point", [PAPER, dict(PAPER, m2=0.05, a=0.8), dict(PAPER, m2=40.0, a=0.1)])
def test_sweeps_sensitivities_are_its_own_central_differences(point):
    exact = rodcube.sweep(axes={"m1": point["m1"]}, **{k: v for k, v in point.items() if k != "m1"},
                          sensitivities=True)
    for p, value in point.items():
        h = 1e-5 * value
        rest = {k: v for k, v in point.items() if k != p}
        s = rodcube.sweep(axes={p: [value - h, value + h]}, **rest)
        for of in OF:
            fd = (s[of][1] - s[of][0]) / (2 * h)
            d = float(exact[f"d({of})/d({p})"])
            scale = abs(float(exact[of])) / value
            assert abs(fd - d) <= 1e-6 * scale, (p, of, fd, d)


def test_a_sensitivity_that_does_not_exist_is_a_note_and_no_number():
    # The friction model's separation is integrated, with its forward sensitivities; an
    # impact's impulses and energy have none (only its time is differentiated), and a note why.
    names = [p for p, _, _ in rodcube.parameters("rod_cube_friction")]
    point = {p: PAPER.get(p, 0.2) for p in names}
    one = rodcube.solve("rod_cube_friction", want=WANT + ["impacts"], **point)
    assert math.isfinite(one["separation_angle"])
    for p in names:
        assert math.isfinite(one["sensitivities"][f"d(separation_angle)/d({p})"]), p
    assert one["sensitivity_units"]["d(separation_time)/d(mu)"] == "s"
    assert "times only" in one["notes"]["sensitivities.impacts"]
    assert not any("impacts" in k for k in one["sensitivities"])
    # A point that fails has NaN sensitivities and one error.
    s = rodcube.sweep(n=3.0, a_over_ell=[0.25, 1.5], m1=1.0, ell=1.0, g=9.81, sensitivities=True)
    assert s["ok"].tolist() == [True, False] and [i for i, _ in s["errors"]] == [(1,)]
    assert np.isnan(s["d(separation_time)/d(a)"][1]) and np.isfinite(s["d(separation_time)/d(a)"][0])
