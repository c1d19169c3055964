"""Models derived a minute ago, run from Python with no compiler: `load_models(path)` loads the
directory of tapes that `tests/python.rs` derived (`rodcube derive --tapes-into DIR plank.yaml`,
from a spec it writes itself: the paper's rod on a free block as a plank on a crate, under
names of its own, compiled into nothing) and names in RODCUBE_TAPES; then `solve`, `run` and
`sweep` take the model by name and are checked against the paper's closed forms, written again
here; a truncated tape is refused with a message naming the file.

The closed forms (PHYSICS.md, re-derived by hand; n = mc/mp, r = h/L): the separation's sine s
is the root in (0, r) of eq. (14), 3 s^3 - 12 (1+n) s + 8 r (1+n) = 0, found here by bisection;
its time is eq. (15), int dtheta / theta_dot with theta_dot^2 = 4 (g/L) (r - sin theta) / D,
D = 4/3 - sin^2(theta)/(1+n), from theta_0 = asin(r) (eq. 9); and the push at release is eq.
(16) at theta_0, 3 mc g r cos(theta_0) / (4 (1+n) - 3 r^2)."""

import math
import os
import pathlib
import re
import shutil

import numpy as np
import pytest

import rodcube

MODELS = ["plank", "plank_closed", "plank_free"]
POINT = dict(mp=1.0, mc=3.0, L=1.0, h=0.25, g=9.81)


def tapes():
    """The directory of tapes tests/python.rs derived; the test fails (never skips) without it."""
    path = os.environ.get("RODCUBE_TAPES")
    assert path, "RODCUBE_TAPES must name a directory of tapes (tests/python.rs derives and sets it)"
    return pathlib.Path(path)


@pytest.fixture(scope="module")
def loaded():
    return rodcube.load_models(tapes())


def separation_angle(n, r):
    """theta_sep from eq. (14) by bisection on (0, r), where the cubic falls from 8 r (1+n) > 0
    to r (3 r^2 - 4 (1+n)) < 0 (its derivative 9 s^2 - 12 (1+n) is negative there)."""
    lo, hi = 0.0, r
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if 3.0 * mid**3 - 12.0 * (1.0 + n) * mid + 8.0 * r * (1.0 + n) > 0.0:
            lo = mid
        else:
            hi = mid
    return math.asin(0.5 * (lo + hi))


def separation_time(n, r, ell, g, panels=8, nodes=30):
    """t_sep from eq. (15): theta = theta_0 - u^2 removes the endpoint's 1/sqrt, and
    r - sin(theta) = 2 cos(theta_0 - u^2/2) sin(u^2/2) its cancellation; Gauss-Legendre panels
    in u from 0 to sqrt(theta_0 - theta_sep)."""
    theta0 = math.asin(r)
    end = math.sqrt(theta0 - separation_angle(n, r))
    x, w = np.polynomial.legendre.leggauss(nodes)
    width = end / panels
    total = 0.0
    for p in range(panels):
        u = width * (p + 0.5 * (x + 1.0))
        theta = theta0 - u * u
        drop = 2.0 * np.cos(theta0 - u * u / 2) * np.sin(u * u / 2)
        rate_sq = 4.0 * (g / ell) * drop / (4.0 / 3.0 - np.sin(theta) ** 2 / (1.0 + n))
        total += 0.5 * width * float(np.sum(w * 2.0 * u / np.sqrt(rate_sq)))
    return total


def push_at_release(n, r, mc, g):
    """Eq. (16) at release: the push of the plank's top on the crate (N)."""
    return 3.0 * mc * g * r * math.cos(math.asin(r)) / (4.0 * (1.0 + n) - 3.0 * r * r)


def test_the_closed_forms_reproduce_the_papers_figures():
    # Section 3 of the paper (n = 3, a/ell = 1/4): 9.61 degrees, 0.108 s; a check of the
    # oracles before they judge rodcube.
    assert round(math.degrees(separation_angle(3.0, 0.25)), 2) == 9.61
    assert round(separation_time(3.0, 0.25, 1.0, 9.81), 3) == 0.108


def test_load_models_names_the_models_of_the_directory(loaded):
    assert loaded == MODELS
    for model in MODELS:
        assert model in rodcube.models()
    assert [p[0] for p in rodcube.parameters("plank")] == ["mp", "mc", "L", "h", "g"]
    assert rodcube.parameters("plank")[3][1] == "m"
    # Again: the same names, and the registry does not grow.
    count = len(rodcube.models())
    assert rodcube.load_models(str(tapes())) == MODELS
    assert len(rodcube.models()) == count
    # A tape holds the program, not the derivation.
    with pytest.raises(rodcube.RodcubeError, match=re.escape("plank.tape.json")):
        rodcube.derivation("plank")


@pytest.mark.parametrize("point", [POINT, dict(mp=2.0, mc=0.5, L=1.5, h=0.9, g=9.81)])
def test_solve_takes_the_loaded_model_by_name(loaded, point):
    r = rodcube.solve(
        "plank", want=["separation_angle", "separation_time", "push_series"], tolerance=1e-12, **point
    )
    n, ratio = point["mc"] / point["mp"], point["h"] / point["L"]
    assert r["separation_angle"] == pytest.approx(separation_angle(n, ratio), rel=1e-13, abs=0)
    expected = separation_time(n, ratio, point["L"], point["g"])
    assert r["separation_time"] == pytest.approx(expected, rel=1e-12, abs=0)
    push = r["push_series"]["push"]
    assert push[0] == pytest.approx(push_at_release(n, ratio, point["mc"], point["g"]), rel=1e-12)
    assert abs(push[-1]) < 1e-9  # it vanishes at the separation
    assert "not compiled into" in r["notes"]["model"] and "plank.tape.json" in r["notes"]["model"]


def test_run_takes_the_loaded_model_by_name(loaded):
    scene = {
        "model": "plank",
        "parameters": POINT,
        "want": ["separation_angle", "separation_time", "push_series"],
        "tolerance": 1e-12,
    }
    result = rodcube.run(scene)
    assert result.model == "plank"
    assert result["separation_angle"] == pytest.approx(separation_angle(3.0, 0.25), rel=1e-13, abs=0)
    assert result["separation_time"] == pytest.approx(separation_time(3.0, 0.25, 1.0, 9.81), rel=1e-12, abs=0)
    push = result.series["push_series"]["push"]
    assert push[0] == pytest.approx(push_at_release(3.0, 0.25, 3.0, 9.81), rel=1e-12)
    assert "not compiled into" in result.notes["model"]


def test_sweep_takes_the_loaded_model_by_name_in_parallel(loaded):
    # 70 x 70 points: more than one parallel task of the compiled half (4096 points each).
    n = np.logspace(-2, 2, 70)
    r = np.linspace(0.02, 0.95, 70)
    s = rodcube.sweep(model="plank", axes={"mc_over_mp": n[:, None], "h_over_L": r}, mp=1.0, L=1.0, g=9.81)
    assert s["separation_angle"].shape == (70, 70)
    assert s["ok"].all() and s["errors"] == []
    for i, j in np.ndindex(70, 70):
        expected = separation_angle(n[i], r[j])
        assert s["separation_angle"][i, j] == pytest.approx(expected, rel=1e-13, abs=0), (i, j)
    for k in range(0, 4900, 97):
        i, j = divmod(k, 70)
        expected = separation_time(n[i], r[j], 1.0, 9.81)
        assert s["separation_time"][i, j] == pytest.approx(expected, rel=1e-12, abs=0), (i, j)
    # The per-point solver (sweep) and the planner (solve) agree on a point.
    one = rodcube.solve("plank", mp=1.0, mc=n[5], L=1.0, h=r[7], g=9.81)
    assert s["separation_angle"][5, 7] == pytest.approx(one["separation_angle"], rel=2e-15, abs=0)
    assert s["separation_time"][5, 7] == pytest.approx(one["separation_time"], rel=2e-15, abs=0)


def test_sweep_with_want_runs_the_loaded_model_through_the_planner(loaded):
    # The plank's contact end over a 6 x 5 grid: the closed forms' angle and time (the first
    # contact lets go by its force: the separation), each point the planner's own.
    n = np.logspace(-1, 1, 6)[:, None]
    r = np.linspace(0.1, 0.8, 5)
    s = rodcube.sweep(
        model="plank", want=["contact_end"], axes={"mc_over_mp": n, "h_over_L": r}, mp=1.0, L=1.0, g=9.81
    )
    assert s["ok"].all() and s["errors"] == []
    assert [key for key, _ in rodcube.sweep_results("plank", ["contact_end"])] == [
        k for k in s if k not in ("ok", "errors")
    ]
    for i, j in np.ndindex(6, 5):
        nn, rr = float(n[i, 0]), float(r[j])
        assert s["contact_end_angle"][i, j] == pytest.approx(separation_angle(nn, rr), rel=1e-12, abs=0)
        assert s["contact_end_time"][i, j] == pytest.approx(separation_time(nn, rr, 1.0, 9.81), rel=1e-10, abs=0)


def test_a_truncated_tape_is_refused_naming_the_file(tmp_path):
    before = rodcube.models()
    broken = tmp_path / "broken"
    shutil.copytree(tapes(), broken)
    cut = broken / "plank_free.tape.json"
    text = cut.read_text()
    cut.write_text(text[: len(text) // 2])
    with pytest.raises(rodcube.RodcubeError, match=re.escape(str(cut)) + r":\d+:\d+: not a rodcube tape"):
        rodcube.load_models(broken)
    # A directory that is not there, named.
    with pytest.raises(rodcube.RodcubeError, match=re.escape(str(tmp_path / "nowhere"))):
        rodcube.load_models(tmp_path / "nowhere")
    # Nothing of a refused directory was loaded.
    assert rodcube.models() == before
