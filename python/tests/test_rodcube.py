"""rodcube's Python package: the paper's numbers, series as NumPy arrays, the sweep against
single solves, the registry, and errors as exceptions with rodcube's messages. Also runs the
README's Python example."""

import math
import pathlib
import re

import numpy as np
import pytest

import rodcube

PAPER = dict(m1=1.0, m2=3.0, ell=1.0, a=0.25, g=9.81)


def test_the_papers_separation():
    r = rodcube.solve("rod_cube", want=["separation_angle", "separation_time"], **PAPER)
    assert set(r) == {"separation_angle", "separation_time"}
    # Section 3 of the paper: 9.61 degrees and 0.108 s; the C example prints these digits.
    assert r["separation_angle"] == 0.16774308203514918
    assert abs(r["separation_time"] - 0.10849325417085605) < 2e-16


def test_series_are_numpy_arrays_and_words_are_strings():
    r = rodcube.solve(
        "rod_cube",
        want=["theta_series", "contact_force_series", "contact_end", "checks"],
        samples=11,
        **PAPER,
    )
    t = r["theta_series"]["t"]
    assert isinstance(t, np.ndarray) and t.shape == (11,) and t[0] == 0.0
    assert np.all(np.diff(t) > 0)
    force = r["contact_force_series"]
    assert set(force) >= {"t", "contact_force"}
    assert abs(force["contact_force"][-1]) < 1e-9  # the push vanishes at separation
    assert r["contact_end_cause"] == "force"
    assert all(c["passed"] for c in r["checks"].values())


def test_the_sweep_agrees_with_single_solves_and_marks_failures_nan():
    n = np.array([0.01, 1.0, 3.0, 100.0, 3.0])
    a = np.array([0.1, 0.5, 0.25, 0.9, 1.5])  # the last: the cube taller than the rod
    s = rodcube.sweep(n, a)
    for i in range(4):
        one = rodcube.solve("rod_cube", m1=1.0, m2=n[i], ell=1.0, a=a[i], g=1.0)
        assert s["separation_angle"][i] == one["separation_angle"]
        assert abs(s["separation_time"][i] / one["separation_time"] - 1) < 2e-15
    assert math.isnan(s["separation_angle"][4]) and math.isnan(s["separation_time"][4])
    # Fixed parameters other than the swept ones.
    g = rodcube.sweep(n[:1], a[:1], g=9.81)
    one = rodcube.solve("rod_cube", m1=1.0, m2=n[0], ell=1.0, a=a[0], g=9.81)
    assert g["separation_time"][0] == pytest.approx(one["separation_time"], rel=2e-15)


def test_axes_are_named_by_the_models_parameters_or_ratios():
    m2 = np.array([0.5, 2.0, 8.0])
    ell = np.array([1.0, 2.0, 4.0])
    s = rodcube.sweep(axes={"m2": m2, "ell": ell, "a_over_ell": np.full(3, 0.25)}, g=9.81)
    for i in range(3):
        one = rodcube.solve("rod_cube", m1=1.0, m2=m2[i], ell=ell[i], a=0.25 * ell[i], g=9.81)
        assert s["separation_angle"][i] == one["separation_angle"]
        assert s["separation_time"][i] == pytest.approx(one["separation_time"], rel=2e-15)


def test_a_large_sweep_runs_in_parallel():
    n = np.logspace(-3, 3, 300).repeat(300)
    a = np.tile(np.linspace(0.01, 0.99, 300), 300)
    s = rodcube.sweep(n, a, model="hinged_rod")
    assert s["separation_time"].shape == (90000,)
    assert not np.isnan(s["separation_time"]).any()


def test_the_registry():
    names = rodcube.models()
    assert "rod_cube" in names and "wall_ladder" in names
    params = rodcube.parameters("rod_cube")
    assert [p[0] for p in params] == ["m1", "m2", "ell", "a", "g"]
    assert params[3][1] == "m"


def test_errors_are_exceptions_with_rodcubes_messages():
    with pytest.raises(rodcube.RodcubeError, match="no model `rod_ball`"):
        rodcube.solve("rod_ball", **PAPER)
    with pytest.raises(rodcube.RodcubeError, match=re.escape("a < ell")):
        rodcube.solve("rod_cube", **dict(PAPER, a=1.5))
    with pytest.raises(rodcube.RodcubeError, match="unknown quantity `speed`"):
        rodcube.solve("rod_cube", want=["speed"], **PAPER)
    with pytest.raises(rodcube.RodcubeError, match="`g`"):
        rodcube.solve("rod_cube", m1=1.0, m2=3.0, ell=1.0, a=0.25)
    with pytest.raises(rodcube.RodcubeError, match="must be a number"):
        rodcube.solve("rod_cube", **dict(PAPER, g="down"))
    with pytest.raises(rodcube.RodcubeError, match="as many"):
        rodcube.sweep(np.ones(3), np.ones(2))
    with pytest.raises(rodcube.RodcubeError, match="no parameter or ratio `n`"):
        rodcube.sweep(np.ones(3), np.ones(3), model="wall_ladder")
    with pytest.raises(rodcube.RodcubeError, match="set twice"):
        rodcube.sweep(np.ones(3), np.ones(3), axes={"m2": np.ones(3)})
    assert issubclass(rodcube.RodcubeError, ValueError)


def test_the_readme_example_runs():
    readme = pathlib.Path(__file__).resolve().parents[2] / "README.md"
    blocks = re.findall(r"```python\n(.*?)```", readme.read_text(), re.S)
    assert len(blocks) == 1, "the README has one Python example"
    exec(compile(blocks[0], "README.md", "exec"), {})
