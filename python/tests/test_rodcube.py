"""rodcube's Python package: the paper's numbers, series as NumPy arrays, the sweep against
independent oracles (the paper's cubic, a quadrature in NumPy) and against single solves, its
required parameters, failure reasons and broadcasting, the registry, errors as exceptions with
rodcube's messages, and the type stubs shipped in the package. Also runs the README's Python
example.

Every expected number says where it comes from: the paper's printed figures, a closed form
solved here in NumPy, a quadrature written here in NumPy, or dimensional analysis; none is
copied from rodcube's own output."""

import ast
import inspect
import math
import pathlib
import re

import numpy as np
import pytest

import rodcube

PAPER = dict(m1=1.0, m2=3.0, ell=1.0, a=0.25, g=9.81)
# What a sweep in n = m2/m1 and a/ell needs besides its axes.
SCALE = dict(m1=1.0, ell=1.0, g=9.81)


def cubic_root(coefficients, below):
    """The one real root in (0, below) of a polynomial (highest degree first), by np.roots."""
    roots = np.roots(coefficients)
    inside = [z.real for z in roots if z.imag == 0 and 0 < z.real < below]
    assert len(inside) == 1, roots
    return inside[0]


def rod_cube_angle(n, r):
    """The separation angle of the rod on the cube, independent of rodcube: the paper's eq.
    (14), re-derived in PHYSICS.md, says s = sin(theta_sep) solves
    3 s^3 - 12 (1+n) s + 8 r (1+n) = 0 with its root in (0, r) (n = m2/m1, r = a/ell);
    divided here by (1+n) so that extreme mass ratios keep their digits."""
    return math.asin(cubic_root([3.0 / (1.0 + n), 0.0, -12.0, 8.0 * r], r))


def hinged_rod_angle(n, r):
    """The separation angle of a rod hinged at its foot (PHYSICS.md, erratum 5, derived by the
    paper's method): s = sin(theta_sep) solves 3 n s^3 + 3 s - 2 r = 0."""
    return math.asin(cubic_root([3.0 * n, 0.0, 3.0, -2.0 * r], r))


def rod_cube_time(n, r, ell, g, nodes=40):
    """The separation time of the rod on the cube, independent of rodcube: the paper's eq.
    (15), t = (1/2) sqrt(ell/g) int_{theta_sep}^{theta_0} sqrt(D / (r - sin theta)) dtheta with
    D = 4/3 - sin^2(theta)/(1+n), theta_0 = asin(r). The substitution theta = theta_0 - u^2
    and r - sin theta = 2 cos(theta_0 - u^2/2) sin(u^2/2) remove the 1/sqrt endpoint
    singularity; the smooth integrand in u is summed by NumPy's Gauss-Legendre nodes."""
    theta0 = math.asin(r)
    top = math.sqrt(theta0 - rod_cube_angle(n, r))
    x, w = np.polynomial.legendre.leggauss(nodes)
    u = 0.5 * top * (x + 1.0)
    theta = theta0 - u * u
    d = 4.0 / 3.0 - np.sin(theta) ** 2 / (1.0 + n)
    # 2u / sqrt(r - sin theta), with sin(u^2/2)/u^2 finite as u -> 0.
    f = 2.0 * np.sqrt(d / (2.0 * np.cos(theta0 - u * u / 2) * (np.sin(u * u / 2) / (u * u))))
    return 0.5 * math.sqrt(ell / g) * 0.5 * top * float(np.sum(w * f))


def test_the_oracles_reproduce_the_papers_figures():
    # Section 3 of the paper: n = 3, a/ell = 1/4: theta_sep = 9.61 degrees, 0.108 s for a
    # 1.0 m rod (g = 9.81 m/s^2; PHYSICS.md: 9.8 gives 0.10855, also 0.108 to the paper's
    # digits). A check of the oracles above, before they judge rodcube.
    assert round(math.degrees(rod_cube_angle(3.0, 0.25)), 2) == 9.61
    assert round(rod_cube_time(3.0, 0.25, 1.0, 9.81), 3) == 0.108
    # The r -> 0 limit (PHYSICS.md): t_sep -> (2/3) sqrt(a/g) for any n.
    a = 1e-6
    assert rod_cube_time(3.0, a, 1.0, 9.81) == pytest.approx(2 / 3 * math.sqrt(a / 9.81), rel=1e-5)


def test_the_papers_separation():
    r = rodcube.solve("rod_cube", want=["separation_angle", "separation_time"], **PAPER)
    assert set(r) == {"separation_angle", "separation_time"}
    # The paper's printed figures, to the digits it prints (Section 3): 9.61 deg, 0.108 s.
    assert round(math.degrees(r["separation_angle"]), 2) == 9.61
    assert round(r["separation_time"], 3) == 0.108
    # The paper's cubic eq. (14), solved by np.roots.
    assert r["separation_angle"] == pytest.approx(rod_cube_angle(3.0, 0.25), rel=1e-14, abs=0)
    # The paper's eq. (15), integrated here in NumPy.
    assert r["separation_time"] == pytest.approx(rod_cube_time(3.0, 0.25, 1.0, 9.81), rel=1e-13, abs=0)


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
    # The series ends at the separation: the paper's 0.108 s.
    assert round(t[-1], 3) == 0.108
    force = r["contact_force_series"]
    assert set(force) >= {"t", "contact_force"}
    assert abs(force["contact_force"][-1]) < 1e-9  # the push vanishes at separation
    assert r["contact_end_cause"] == "force"
    assert all(c["passed"] for c in r["checks"].values())


def test_the_sweeps_angles_and_times_are_the_papers_equations_over_the_plane():
    # A 2-D sweep: n down a column, a/ell along a row, from extreme mass ratios to a nearly
    # upright rod.
    n = np.array([1e-6, 0.01, 0.3, 1.0, 3.0, 10.0, 100.0, 1e6])
    r = np.array([1e-4, 0.01, 0.1, 0.25, 0.5, 0.9, 0.999])
    s = rodcube.sweep(n[:, None], r[None, :], **SCALE)
    assert s["separation_angle"].shape == s["separation_time"].shape == (8, 7)
    assert s["ok"].all() and s["errors"] == []
    for i, j in np.ndindex(8, 7):
        # Eq. (14) by np.roots, and eq. (15) by Gauss-Legendre in NumPy.
        expected = rod_cube_angle(n[i], r[j])
        assert s["separation_angle"][i, j] == pytest.approx(expected, rel=1e-14, abs=0), (i, j)
        expected = rod_cube_time(n[i], r[j], 1.0, 9.81)
        assert s["separation_time"][i, j] == pytest.approx(expected, rel=1e-13, abs=0), (i, j)


def test_the_sweep_agrees_with_single_solves():
    # Two routes through the library: the per-point solver (sweep) and the planner (solve).
    n = np.array([0.01, 1.0, 3.0, 100.0])
    a = np.array([0.1, 0.5, 0.25, 0.9])
    s = rodcube.sweep(n, a, **SCALE)
    for i in range(4):
        one = rodcube.solve("rod_cube", m1=1.0, m2=n[i], ell=1.0, a=a[i], g=9.81)
        assert s["separation_angle"][i] == pytest.approx(one["separation_angle"], rel=2e-15, abs=0)
        assert s["separation_time"][i] == pytest.approx(one["separation_time"], rel=2e-15, abs=0)


def test_a_failed_point_is_masked_with_its_reason():
    n = np.array([3.0, 3.0, 3.0])
    a = np.array([0.25, 1.5, 0.5])  # the middle one: the cube taller than the rod
    s = rodcube.sweep(n, a, **SCALE)
    assert s["ok"].dtype == np.bool_
    assert s["ok"].tolist() == [True, False, True]
    assert np.isnan(s["separation_angle"][1]) and np.isnan(s["separation_time"][1])
    assert not np.isnan(s["separation_time"][[0, 2]]).any()
    assert len(s["errors"]) == 1
    index, message = s["errors"][0]
    assert index == (1,)
    assert "a < ell" in message and "a = 1.5" in message
    # The index addresses the result arrays; the failures come in the order of argwhere(~ok).
    assert np.isnan(s["separation_time"][index])
    grid = rodcube.sweep(n=[[3.0], [1.0]], a_over_ell=[1.5, 0.25, 2.0], **SCALE)
    assert [i for i, _ in grid["errors"]] == [tuple(k) for k in np.argwhere(~grid["ok"])]
    assert [i for i, _ in grid["errors"]] == [(0, 0), (0, 2), (1, 0), (1, 2)]
    # A non-finite value on an axis fails its point, not the sweep.
    s = rodcube.sweep(n=[3.0, np.nan], a_over_ell=0.25, **SCALE)
    assert s["ok"].tolist() == [True, False] and s["errors"][0][0] == (1,)
    assert s["errors"][0][1]


def test_every_parameter_needs_a_value():
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.sweep(3.0, 0.25)
    text = str(e.value)
    # Each missing parameter with its unit and meaning (the model's own, see parameters()),
    # and the ratio axes that are measured against it.
    assert "no value for 3 parameters" in text
    assert "m1 [kg]: mass of the rod; the axis `n` is measured against it" in text
    assert "ell [m]: length of the rod; the axis `a_over_ell` is measured against it" in text
    assert "g [m/s^2]: gravitational acceleration" in text
    assert not re.search(r"^  (m2|a) ", text, re.M)  # set by the axes
    with pytest.raises(rodcube.RodcubeError, match=r"no value for 1 parameter \(") as e:
        rodcube.sweep(axes={"m2": [1.0, 2.0], "a": 0.1}, m1=1.0, g=9.81)
    assert "ell [m]" in str(e.value)


def test_g_is_never_defaulted():
    # Every other parameter given: g alone is missing, and the sweep refuses to run.
    with pytest.raises(rodcube.RodcubeError, match=r"no value for 1 parameter") as e:
        rodcube.sweep(3.0, 0.25, m1=1.0, ell=1.0)
    assert "g [m/s^2]" in str(e.value)
    with pytest.raises(rodcube.RodcubeError, match=r"g \[m/s\^2\]"):
        rodcube.sweep(3.0, 0.25, defaults={"m1": 1.0, "ell": 1.0})
    with pytest.raises(rodcube.RodcubeError, match=r"g \[m/s\^2\]"):
        rodcube.sweep(axes={"m2": 3.0, "a": 0.25}, m1=1.0, ell=1.0, model="hinged_rod")


def test_defaults_give_what_nothing_else_sets():
    n = np.array([0.5, 3.0])
    r = np.array([0.25, 0.5])
    given = rodcube.sweep(n, r, **SCALE)
    by_defaults = rodcube.sweep(n, r, defaults=SCALE)
    np.testing.assert_array_equal(by_defaults["separation_time"], given["separation_time"])
    # Keywords and axes win over defaults: m2 comes from n, g from the keyword. On the moon
    # (g = 1.62 m/s^2) the time is sqrt(9.81/1.62) times longer (t scales as sqrt(ell/g),
    # eq. 15); a default that applied would change it.
    moon = rodcube.sweep(n, r, m1=1.0, g=1.62, defaults={"ell": 1.0, "g": 9.81, "m2": 100.0})
    np.testing.assert_allclose(
        moon["separation_time"], given["separation_time"] * math.sqrt(9.81 / 1.62), rtol=1e-14
    )
    np.testing.assert_array_equal(moon["separation_angle"], given["separation_angle"])
    # A longer rod: t scales as sqrt(ell) at a fixed a/ell (eq. 15).
    long = rodcube.sweep(n, r, defaults=dict(SCALE, ell=4.0))
    np.testing.assert_allclose(long["separation_time"], 2 * given["separation_time"], rtol=1e-14)
    with pytest.raises(rodcube.RodcubeError, match="defaults: model `rod_cube` has no parameter `G`"):
        rodcube.sweep(n, r, m1=1.0, ell=1.0, defaults={"G": 9.81})
    with pytest.raises(rodcube.RodcubeError, match="must be one number"):
        rodcube.sweep(n, r, m1=1.0, ell=1.0, defaults={"g": [9.81, 1.62]})
    with pytest.raises(rodcube.RodcubeError, match="defaults must be a dict"):
        rodcube.sweep(n, r, defaults=[("g", 9.81)])


def test_scalars_and_array_likes_broadcast():
    # The paper's point, all scalars: 0-d results.
    point = rodcube.sweep(n=3.0, a_over_ell=0.25, **SCALE)
    assert point["separation_angle"].shape == () and point["ok"].shape == ()
    assert round(math.degrees(float(point["separation_angle"])), 2) == 9.61  # the paper
    # A scalar against a list.
    s = rodcube.sweep(n=3.0, a_over_ell=[0.1, 0.25], **SCALE)
    assert s["separation_angle"].shape == (2,)
    for k, r in enumerate([0.1, 0.25]):
        assert s["separation_angle"][k] == pytest.approx(rod_cube_angle(3.0, r), rel=1e-14, abs=0)
    # 0-d arrays and tuples are array-likes too.
    t = rodcube.sweep(np.float64(3.0), (0.1, 0.25), **SCALE)
    np.testing.assert_array_equal(t["separation_angle"], s["separation_angle"])
    # A column against a row: a 2-D grid, and 3-D with a keyword parameter as an axis.
    n = np.array([0.5, 3.0, 30.0])
    r = np.array([0.1, 0.25, 0.5, 0.75])
    grid = rodcube.sweep(n[:, None], r, **SCALE)
    assert grid["separation_time"].shape == (3, 4)
    for i, j in np.ndindex(3, 4):
        assert grid["separation_angle"][i, j] == pytest.approx(rod_cube_angle(n[i], r[j]), rel=1e-14, abs=0)
    g = np.array([9.81, 1.62]).reshape(2, 1, 1)
    cube = rodcube.sweep(n[:, None], r, m1=1.0, ell=1.0, g=g)
    assert cube["separation_time"].shape == (2, 3, 4)
    np.testing.assert_array_equal(cube["separation_time"][0], grid["separation_time"])
    # t scales as 1/sqrt(g) (eq. 15).
    np.testing.assert_allclose(
        cube["separation_time"][1], grid["separation_time"] * math.sqrt(9.81 / 1.62), rtol=1e-14
    )
    # An axis in `axes` broadcasts with the others.
    named = rodcube.sweep(n[:, None], axes={"a": r}, m1=1.0, ell=1.0, g=9.81)
    np.testing.assert_array_equal(named["separation_angle"], grid["separation_angle"])
    # No points: empty results of the broadcast shape.
    empty = rodcube.sweep(np.zeros((0, 3)), 0.25, **SCALE)
    assert empty["separation_time"].shape == (0, 3) and empty["errors"] == []


def test_shapes_that_do_not_broadcast_are_refused_by_name():
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.sweep(np.ones(3), np.ones(2), **SCALE)
    assert str(e.value) == "the axes' shapes do not broadcast together: `n` (3,), `a_over_ell` (2,)"
    with pytest.raises(rodcube.RodcubeError, match=r"`g` \(2, 2\)"):
        rodcube.sweep(np.ones(3), 0.25, m1=1.0, ell=1.0, g=np.ones((2, 2)))


def test_axes_are_named_by_the_models_parameters_or_ratios():
    m2 = np.array([0.5, 2.0, 8.0])
    ell = np.array([1.0, 2.0, 4.0])
    s = rodcube.sweep(axes={"m2": m2, "ell": ell, "a_over_ell": 0.25}, m1=1.0, g=9.81)
    for i in range(3):
        # The angle depends on n = m2/m1 and a/ell only (eq. 14); t on ell/g (eq. 15).
        assert s["separation_angle"][i] == pytest.approx(rod_cube_angle(m2[i], 0.25), rel=1e-14, abs=0)
        expected = rod_cube_time(m2[i], 0.25, ell[i], 9.81)
        assert s["separation_time"][i] == pytest.approx(expected, rel=1e-13, abs=0)


def test_a_large_sweep_runs_in_parallel():
    n = np.logspace(-3, 3, 300)
    a = np.linspace(0.01, 0.99, 300)
    s = rodcube.sweep(n[:, None], a, model="hinged_rod", **SCALE)
    assert s["separation_time"].shape == (300, 300)
    assert s["ok"].all() and s["errors"] == []
    # Against the hinged rod's cubic (PHYSICS.md, erratum 5) on every 37th point.
    for k in range(0, 90000, 37):
        i, j = divmod(k, 300)
        expected = hinged_rod_angle(n[i], a[j])
        assert s["separation_angle"][i, j] == pytest.approx(expected, rel=1e-14, abs=0), (i, j)


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
    with pytest.raises(rodcube.RodcubeError, match="parameter `g` must be a number"):
        rodcube.sweep(np.ones(3), np.ones(3), m1=1.0, ell=1.0, g="down")
    with pytest.raises(rodcube.RodcubeError, match="axis `n` must be a number"):
        rodcube.sweep(["x"], 0.25, **SCALE)
    with pytest.raises(rodcube.RodcubeError, match="no parameter or ratio `n`"):
        rodcube.sweep(np.ones(3), np.ones(3), model="wall_ladder", **SCALE)
    with pytest.raises(rodcube.RodcubeError, match="set twice"):
        rodcube.sweep(np.ones(3), np.ones(3), axes={"m2": np.ones(3)}, **SCALE)
    with pytest.raises(rodcube.RodcubeError, match="set twice"):
        rodcube.sweep(np.ones(3), 0.25, m2=2.0, **SCALE)
    with pytest.raises(rodcube.RodcubeError, match="has no parameter `G`"):
        rodcube.sweep(np.ones(3), 0.25, m1=1.0, ell=1.0, G=9.81)
    with pytest.raises(rodcube.RodcubeError, match="give an axis"):
        rodcube.sweep(**PAPER)
    with pytest.raises(rodcube.RodcubeError, match="not a finite number"):
        rodcube.sweep(np.ones(3), 0.25, m1=1.0, ell=1.0, g=math.inf)
    # The compiled half refuses columns of different lengths (the package broadcasts first).
    with pytest.raises(rodcube.RodcubeError, match="as many"):
        rodcube._rodcube.sweep_flat("rod_cube", ["n", "a_over_ell"], [np.ones(3), np.ones(2)], [], [])
    assert issubclass(rodcube.RodcubeError, ValueError)


def test_the_rod_lands_bounces_and_goes_on_to_until():
    # The paper's rod and cube with every support a contact: it lands flat at the paper's
    # landing time (0.187051069750276 s, by hand in tests/phases.rs) and, plastic, stays down.
    r = rodcube.solve(
        "rod_cube_liftoff", want=["impacts", "floor_impact", "theta_series"], tolerance=1e-12,
        samples=50, until=0.3, e=0.0, **PAPER,
    )
    (impact,) = r["impacts"]
    assert impact["closing"] == "tip_floor"
    assert impact["time"] == pytest.approx(0.187051069750276, rel=1e-11, abs=0)
    tip = next(c for c in impact["per_contact"] if c["contact"] == "tip_floor")
    assert tip["normal_velocity_before"] < 0 and abs(tip["normal_velocity_after"]) < 1e-12
    # By hand (the foot resting, the tip striking): P_tip = m ell |w| / 3 with w the landing
    # rate, the energy lost (1/2)(1/12 + 1/4) m ell^2 w^2.
    w = r["impact_angular_velocity"]
    assert tip["impulse"] == pytest.approx(abs(w) / 3, rel=1e-12)
    assert impact["energy_lost"] == pytest.approx(0.5 * (1 / 12 + 1 / 4) * w * w, rel=1e-12)
    assert r["theta_series"]["t"][-1] == pytest.approx(0.3, rel=1e-12)
    assert "until" in r["notes"]
    with pytest.raises(rodcube.RodcubeError, match="until"):
        rodcube.solve("rod_cube_liftoff", until=-1.0, e=0.0, **PAPER)


def test_the_package_ships_its_type_stubs():
    # The installed package (a wheel built by maturin), not the source tree.
    package = pathlib.Path(rodcube.__file__).parent
    assert (package / "py.typed").is_file()
    stub = ast.parse((package / "__init__.pyi").read_text())
    functions = {f.name: f for f in stub.body if isinstance(f, ast.FunctionDef)}
    classes = {c.name for c in stub.body if isinstance(c, ast.ClassDef)}
    assert "RodcubeError" in classes
    # Every public function is in the stub, with the runtime's parameters, kinds and
    # defaults, and a return type.
    stubbed_classes = {c.name: c for c in stub.body if isinstance(c, ast.ClassDef)}
    exported = [
        ast.literal_eval(node.value)
        for node in stub.body
        if isinstance(node, ast.Assign) and [t.id for t in node.targets] == ["__all__"]
    ]
    assert exported == [rodcube.__all__]
    for name in rodcube.__all__:
        if name == "RodcubeError":
            continue
        runtime = getattr(rodcube, name)
        if inspect.isclass(runtime):
            # Every public attribute of the class (and its notebook hooks) is in the stub.
            assert name in stubbed_classes, name
            members = {
                target.id if isinstance(target, ast.Name) else getattr(target, "name", None)
                for node in stubbed_classes[name].body
                for target in (node.target if isinstance(node, ast.AnnAssign) else node,)
            }
            public = {m for m in vars(runtime) if not m.startswith("_") or m.startswith("_repr_")}
            assert public <= members, (name, public - members)
            continue
        assert name in functions, name
        f = functions[name]
        assert f.returns is not None, name
        a = f.args
        empty = inspect.Parameter.empty
        defaults = [empty] * (len(a.posonlyargs + a.args) - len(a.defaults)) + a.defaults
        stubbed = [(p.arg, "POSITIONAL_ONLY") for p in a.posonlyargs]
        stubbed += [(p.arg, "POSITIONAL_OR_KEYWORD") for p in a.args]
        stubbed += [(p.arg, "KEYWORD_ONLY") for p in a.kwonlyargs]
        defaults += a.kw_defaults
        if a.vararg:
            stubbed.append((a.vararg.arg, "VAR_POSITIONAL"))
            defaults.append(empty)
        if a.kwarg:
            stubbed.append((a.kwarg.arg, "VAR_KEYWORD"))
            defaults.append(empty)
        params = a.posonlyargs + a.args + a.kwonlyargs + [p for p in (a.vararg, a.kwarg) if p]
        assert all(p.annotation is not None for p in params), name
        runtime = inspect.signature(getattr(rodcube, name)).parameters.values()
        assert stubbed == [(p.name, p.kind.name) for p in runtime], name
        stub_defaults = [d if d is empty else ast.literal_eval(d) for d in defaults]
        assert stub_defaults == [p.default for p in runtime], name


def test_the_readme_example_runs():
    readme = pathlib.Path(__file__).resolve().parents[2] / "README.md"
    blocks = re.findall(r"```python\n(.*?)```", readme.read_text(), re.S)
    assert len(blocks) == 1, "the README has one Python example"
    exec(compile(blocks[0], "README.md", "exec"), {})
