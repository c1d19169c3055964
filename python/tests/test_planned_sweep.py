"""`sweep(..., want=[...])`: any model's scalar results over broadcast arrays through the
planner. Checked against the closed forms of the frictionless and the hinged rod (the friction
model's limits), against `solve` at every point to the bit, for its required parameters, its
refusals, and a model with impacts carried on through its bounces.

The closed forms are those of test_rodcube.py (the paper's eq. (14) and (15), and PHYSICS.md's
hinged rod), written there independently of rodcube."""

import numpy as np
import pytest

import rodcube
from test_rodcube import PAPER, hinged_rod_angle, rod_cube_angle, rod_cube_time

WANT = ["contact_end", "floor_impact"]


def test_the_friction_sweep_meets_its_limits():
    # Without friction the foot slides freely: the paper's rod on the cube, for every mass
    # ratio. With mu = 2 at n = 3 the foot sticks from release: the hinged rod.
    n = np.array([0.5, 1.0, 3.0, 8.0])
    # The integrated route holds the run's tolerance (1e-12 here).
    fixed = dict(m1=1.0, ell=1.0, a=0.25, g=9.81)
    s = rodcube.sweep(model="rod_cube_friction", want=WANT, tolerance=1e-12, mu=0.0, m2=n, **fixed)
    assert s["ok"].all() and s["errors"] == []
    for k, nk in enumerate(n):
        assert s["contact_end_angle"][k] == pytest.approx(rod_cube_angle(nk, 0.25), rel=1e-11, abs=0)
        assert s["contact_end_time"][k] == pytest.approx(rod_cube_time(nk, 0.25, 1.0, 9.81), rel=1e-11, abs=0)
        assert s["contact_end_friction_work"][k] == 0.0
    hinged = rodcube.sweep(model="rod_cube_friction", want=["contact_end"], tolerance=1e-12, mu=[2.0], **PAPER)
    assert hinged["contact_end_angle"][0] == pytest.approx(hinged_rod_angle(3.0, 0.25), rel=1e-11, abs=0)


def test_each_point_is_its_own_solve_to_the_bit():
    mu = np.linspace(0.0, 2.0, 9)[:, None]
    m2 = np.array([1.0, 3.0, 6.0])
    fixed = dict(m1=1.0, ell=1.0, a=0.25, g=9.81)
    s = rodcube.sweep(model="rod_cube_friction", want=WANT, mu=mu, m2=m2, tolerance=1e-11, **fixed)
    keys = [key for key, _ in rodcube.sweep_results("rod_cube_friction", WANT)]
    assert sorted(s) == sorted(keys + ["ok", "errors"])
    assert all(s[key].shape == (9, 3) and s[key].dtype == np.float64 for key in keys)
    failed = dict(s["errors"])
    for i, j in np.ndindex(9, 3):
        one = rodcube.solve(
            "rod_cube_friction", want=WANT, tolerance=1e-11, mu=float(mu[i, 0]), m2=float(m2[j]), **fixed
        )
        for key in keys:
            expected = np.float64(one.get(key, np.nan))
            assert s[key][i, j].tobytes() == expected.tobytes(), (key, i, j)
        # A point misses a wanted quantity exactly where solve explains its absence.
        explained = "contact_end_time" not in one or "floor_impact_time" not in one
        assert s["ok"][i, j] == (not explained), (i, j)
        if explained:
            note = one["notes"].get("contact_end") or one["notes"]["floor_impact"]
            assert note in failed[(i, j)]
    # Where the foot keeps the rod on the cube to the floor (mu between the slide and the
    # stick regimes, at n = 1) the contact holds: NaN, False, and the note why.
    assert not s["ok"].all()
    assert all("holds" in message for _, message in s["errors"])


def test_every_parameter_is_named_with_its_unit_when_missing():
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.sweep(model="rod_cube_friction", want=WANT, mu=[0.1, 0.2], m1=1.0, m2=3.0, ell=1.0, a=0.25)
    assert "g [m/s^2]" in str(e.value)
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.sweep(model="rod_cube_friction", want=WANT, m2=[1.0, 2.0], m1=1.0, ell=1.0, g=9.81)
    assert "a [m]" in str(e.value) and "mu [1]" in str(e.value)


def test_what_is_no_number_per_point_is_refused():
    def refused(**kwargs):
        with pytest.raises(rodcube.RodcubeError) as e:
            rodcube.sweep(model="rod_cube_friction", mu=[0.5], **PAPER, **kwargs)
        return str(e.value)

    assert "not a number per point" in refused(want=["theta_series"])
    assert "result of the quantity `contact_end`" in refused(want=["contact_end_time"])
    assert "list of quantity names" in refused(want="contact_end")
    assert "unknown quantity `speed`" in refused(want=["speed"])
    assert "sensitivities=True" in refused(want=["contact_end"], sensitivities=True)
    assert "tolerance" in refused(tolerance=1e-8)
    assert "outside" in refused(want=["contact_end"], tolerance=1.0)
    with pytest.raises(rodcube.RodcubeError, match="no model"):
        rodcube.sweep_results("no_such_model", WANT)


def test_a_model_with_impacts_goes_on_through_its_bounces():
    # The rod that can lift off the floor, to 0.6 s through its impacts (1 to 14 of them):
    # each restitution's landing is solve's, and it does not depend on the restitution, which
    # acts only at the impacts, the landing the first of them.
    e = np.array([0.0, 0.25, 0.5])
    s = rodcube.sweep(model="rod_cube_liftoff", want=["floor_impact"], until=0.6, e=e, **PAPER)
    assert s["ok"].all() and s["errors"] == []
    for k, ek in enumerate(e):
        one = rodcube.solve("rod_cube_liftoff", want=["floor_impact"], until=0.6, e=float(ek), **PAPER)
        for key in ("floor_impact_time", "impact_angular_velocity"):
            assert s[key][k].tobytes() == np.float64(one[key]).tobytes(), (key, ek)
    assert (s["floor_impact_time"] == s["floor_impact_time"][0]).all()
