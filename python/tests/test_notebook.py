"""rodcube in notebooks, and the package as a wheel: `derivation` (every model's write-up carried
by the package, rendered with every step numbered as in the .tex, its expressions as in the
JSON record), `run` (a path, YAML text or a dict, the paper's numbers against the independent
oracles of test_rodcube.py, the HTML a notebook shows, errors with file, line and field),
`to_frame` with and without pandas, the example notebook executed by nbclient with and without
matplotlib (its outputs against what `rodcube run` prints), and the installed package coming
from a wheel.

The source tree is read only to compare with what the installed package carries; the package
never reads it. `tests/python.rs` sets RODCUBE_BIN to the `rodcube` binary of the same build."""

import json
import math
import os
import pathlib
import re
import subprocess
import sys
import sysconfig
from importlib import metadata

import pytest

import rodcube
from test_rodcube import PAPER, rod_cube_angle, rod_cube_time

ROOT = pathlib.Path(__file__).resolve().parents[2]
GENERATED = ROOT / "generated"
SCENE = ROOT / "scenes" / "paper.yaml"
NOTEBOOK = ROOT / "examples" / "paper.ipynb"
PAPER_YAML = """model: rod_cube
parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}
want: [separation_angle, separation_time, theta_series, tip_trajectory, checks]
"""


def test_every_compiled_model_has_its_derivation_in_the_package():
    compiled = sorted(p.name[: -len(".tex")] for p in GENERATED.glob("*.tex"))
    assert rodcube.derivation_models() == compiled
    assert set(compiled) <= set(rodcube.models())
    # The models `load_models` added (test_tapes.py does, in this process) have none, and say so.
    for model in set(rodcube.models()) - set(compiled):
        with pytest.raises(rodcube.RodcubeError, match="runs from its tape"):
            rodcube.derivation(model)
    for model in rodcube.derivation_models():
        d = rodcube.derivation(model)
        # Carried by the package, the same text as the committed files.
        assert d.latex == (GENERATED / f"{model}.tex").read_text(), model
        record = json.loads((GENERATED / f"{model}.json").read_text())
        assert d.record == record, model
        assert d.expressions == record["expressions"], model


def test_the_derivation_renders_every_step_numbered_as_in_the_tex():
    for model in rodcube.derivation_models():
        d = rodcube.derivation(model)
        md = d._repr_markdown_()
        titles = re.findall(r"\\subsection\*\{", d.latex)
        assert len(d.steps) == len(titles) > 0, model
        numbers = [int(n) for n in re.findall(r"^### (\d+)\. ", md, re.M)]
        assert numbers == list(range(1, len(titles) + 1)), model
        # Every display equation of the .tex, and every numbered one with its number.
        displays = len(re.findall(r"\\begin\{(?:equation|multline)\*\}", d.latex))
        assert md.count("$$") == 2 * displays, model
        for tag in re.findall(r"\\tag\*\{\$?\((\d+)\)", d.latex):
            assert re.search(rf"\\tag\*\{{\({tag}\)", md), (model, tag)
        for left in ("\\begin{equation", "\\begin{multline", "\\begin{tabular", "\\subsection", "\\texttt"):
            assert left not in md, (model, left)
        # A display never holds a lone `$`, which would end it in Markdown.
        for display in re.findall(r"\$\$\n(.*?)\n\$\$", md, re.S):
            assert "$" not in display, (model, display[:80])


def test_every_equation_and_text_shown_comes_from_the_json_record(monkeypatch):
    for model in rodcube.derivation_models():
        d = rodcube.derivation(model)
        md = d._repr_markdown_()
        w = d.record["write_up"]
        # The displays in order are the record's equations, then its results, each tagged.
        shown = re.findall(r"\$\$\n(.*?)\n\$\$", md, re.S)
        equations = w["equations"] + (w["results"] if w["groups"] else [])
        assert len(shown) == len(equations), model
        for display, e in zip(shown, equations):
            assert e["latex"].strip() in display, (model, e["title"])
            assert ("\\tag*{" in display) == bool(e["tag"]), (model, e["title"])
        assert [s.latex for s in d.steps[1:]] == [e["latex"] for e in equations], model
    # A record whose write-up says something else is what is shown: the .tex is not read.
    tex, record = rodcube._notebook.derivation_sources("rod_cube_closed")
    changed = json.loads(record)
    for k, e in enumerate(changed["write_up"]["equations"] + changed["write_up"]["results"]):
        e["latex"] = f"x_{{{k}}} = {k}"
    changed["write_up"]["intro"] = "An intro of the record's own."
    monkeypatch.setattr(rodcube._notebook, "derivation_sources", lambda model: (tex, json.dumps(changed)))
    md = rodcube.derivation("rod_cube_closed")._repr_markdown_()
    assert "An intro of the record's own." in md and "x_{0} = 0" in md
    assert "\\frac{\\dot{\\theta}^2}{g/\\ell}" in tex and "\\frac{\\dot{\\theta}^2}{g/\\ell}" not in md


def test_the_derivation_hands_out_its_expressions():
    d = rodcube.derivation("rod_cube_closed")
    condition = d.expression("separation_condition")
    assert isinstance(condition, str) and "sin(theta)" in condition
    assert d.expression("contact_force") == d.expressions["contact_force"]
    assert "lagrangian" in d.expressions
    # The dimensionless form: the paper's cubic 3 s^3 - 12 (1+n) s + 8 r (1+n), up to a factor.
    cubic = d.dimensionless["separation_condition"]
    for term in ("sin(theta)^3", "12*(1 + n)", "8*r*(1 + n)"):
        assert term in cubic, cubic
    with pytest.raises(rodcube.RodcubeError, match="has no expression `nope`; it has: .*lagrangian"):
        d.expression("nope")
    with pytest.raises(rodcube.RodcubeError, match="no model `nope`; there are: .*rod_cube_closed"):
        rodcube.derivation("nope")


@pytest.mark.parametrize(
    "scene",
    [SCENE, str(SCENE), PAPER_YAML, {"model": "rod_cube", "parameters": PAPER, "want": ["separation_angle", "separation_time", "theta_series", "tip_trajectory"]}],
    ids=["path", "str path", "yaml", "dict"],
)
def test_run_takes_a_path_yaml_or_a_dict(scene):
    result = rodcube.run(scene)
    assert result.model == "rod_cube"
    assert result.parameters == PAPER
    assert math.isclose(result["separation_angle"], rod_cube_angle(3.0, 0.25), rel_tol=1e-12)
    assert math.isclose(result["separation_time"], rod_cube_time(3.0, 0.25, 1.0, 9.81), rel_tol=1e-9)
    theta = result.series["theta_series"]["theta"]
    assert math.isclose(theta[0], math.asin(0.25), rel_tol=1e-15)
    assert result.units("theta_series")["theta"] == "rad"
    assert result.motion_svg is not None and "<animateTransform" in result.motion_svg


def test_the_result_shows_its_tables_checks_and_motion_as_html():
    result = rodcube.run(SCENE)
    page = result._repr_html_()
    for heading in ("Parameters", "Results", "Notes", "Checks", "Series", "Motion"):
        assert f"<h4>{heading}" in page, heading
    # Numbers as the command line shows them (12 significant digits; degrees to 6).
    angle = result["separation_angle"]
    assert f">{angle:.12g}<" in page
    assert f">{math.degrees(angle):.6g}°<" in page
    # One row per check, each with its status, and the count in the heading.
    assert page.count(">pass<") == len(result.checks) > 0
    assert f"Checks ({len(result.checks)} passed, 0 failed)" in page
    # Fitted to the notebook: full-width tables whose free text wraps, the picture scaled down.
    assert 'style="width:100%' in page and "white-space:normal" in page
    # motion.svg inline (not a link), animated, scaled to the page.
    assert '<svg style="max-width:100%;height:auto" ' in page
    assert page.count("<animateTransform") == result.motion_svg.count("<animateTransform") > 0
    # No motion without a trajectory.
    bare = rodcube.run(PAPER_YAML.replace(", theta_series, tip_trajectory, checks", ""))
    assert bare.motion_svg is None and "<svg" not in bare._repr_html_()


def test_scene_errors_name_the_file_line_and_field():
    bad = PAPER_YAML.replace("m2: 3.0", "m2: -3.0")
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.run(bad)
    assert "<yaml>:2:" in str(e.value) and "parameters.m2" in str(e.value) and "positive" in str(e.value)
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.run({"model": "rod_cube", "parameters": {"m1": 1.0}, "want": ["separation_angle"]})
    assert "<dict>:3:" in str(e.value) and "parameters.ell: missing parameter `ell`" in str(e.value)
    with pytest.raises(rodcube.RodcubeError) as e:
        rodcube.run({"model": "rod_cube", "parameters": PAPER, "want": ["separation_angle"], "tolerance": "tight"})
    assert "<dict>:" in str(e.value) and "tolerance" in str(e.value)
    with pytest.raises(rodcube.RodcubeError, match="cannot read the scene"):
        rodcube.run(str(ROOT / "scenes" / "no_such_scene.yaml"))
    with pytest.raises(rodcube.RodcubeError, match="a path, YAML text or a dict, not int"):
        rodcube.run(3)
    with pytest.raises(rodcube.RodcubeError, match="not <object"):
        rodcube.run({"model": object()})


def test_to_frame_gives_dataframes_where_pandas_is_installed():
    import pandas as pd  # pinned in requirements-test.txt (optional for users, not here)
    result = rodcube.run(SCENE)
    frame = result.to_frame()
    assert isinstance(frame, pd.DataFrame)
    assert frame.loc["separation_angle", "value"] == result["separation_angle"]
    assert frame.loc["separation_time", "unit"] == "s"
    theta = result.to_frame("theta_series")
    assert list(theta.columns) == ["t", "theta", "theta_dot", "theta_ddot"]
    assert theta.attrs["units"]["theta_dot"] == "rad/s"
    assert len(theta) == 1000
    with pytest.raises(rodcube.RodcubeError, match="no series `nope`"):
        result.to_frame("nope")


def test_without_pandas_there_is_no_to_frame_and_the_rest_works():
    # pandas made unimportable, as if it were not installed, in a fresh interpreter.
    code = f"""
import sys
sys.modules["pandas"] = None
import rodcube
assert not hasattr(rodcube.RunResult, "to_frame")
result = rodcube.run({str(SCENE)!r})
assert not hasattr(result, "to_frame")
assert "<h4>Results" in result._repr_html_()
print(result["separation_angle"])
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=os.getcwd())
    assert out.returncode == 0, out.stderr
    assert float(out.stdout) == rodcube.run(SCENE)["separation_angle"]


def cli_figures(out_dir):
    """separation_angle, its degrees and separation_time as `rodcube run` prints them."""
    binary = os.environ.get("RODCUBE_BIN")
    assert binary, "RODCUBE_BIN must name the rodcube binary (tests/python.rs sets it)"
    out = subprocess.run([binary, "run", str(SCENE), "--out", str(out_dir), "--wide"], capture_output=True, text=True, check=True)
    figures = {}
    for key in ("separation_angle", "separation_time"):
        row = re.search(rf"^│ {key} +┆ +(\S+) +┆ +\S+ +┆ *(\S*) ", out.stdout, re.M)
        assert row, out.stdout
        figures[key] = row.group(1)
        if row.group(2):
            figures[key + "_degrees"] = row.group(2)
    return figures


def execute(notebook, env):
    """The notebook executed by nbclient in a kernel of this interpreter, from examples/."""
    import nbclient
    import nbformat

    nb = nbformat.read(notebook, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(notebook.parent)}})
    saved = dict(os.environ)
    os.environ.update(env)
    try:
        client.execute()
    finally:
        os.environ.clear()
        os.environ.update(saved)
    return nb


def outputs(nb):
    """Every output of every code cell as (mime type or stream, text)."""
    found = []
    for cell in nb.cells:
        for o in cell.get("outputs", []):
            if o["output_type"] == "stream":
                found.append(("stream", o["text"]))
            elif o["output_type"] == "error":
                found.append(("error", "\n".join(o["traceback"])))
            else:
                found.extend((mime, data if isinstance(data, str) else "") for mime, data in o["data"].items())
    return found


def test_the_example_notebook_shows_the_papers_numbers(tmp_path):
    figures = cli_figures(tmp_path)
    assert figures["separation_angle_degrees"].startswith("9.61")  # the paper: 9.61°
    assert figures["separation_time"].startswith("0.108")  # the paper: 0.108 s
    nb = execute(NOTEBOOK, {})
    found = outputs(nb)
    assert not [t for kind, t in found if kind == "error"]
    text = "\n".join(t for kind, t in found if kind == "stream")
    assert f"separation angle: {figures['separation_angle']} rad = {figures['separation_angle_degrees']}" in text
    assert f"separation time:  {figures['separation_time']} s" in text
    html = "\n".join(t for kind, t in found if kind == "text/html")
    assert f">{figures['separation_angle']}<" in html and f">{figures['separation_time']}<" in html
    assert "<animateTransform" in html  # the motion, inline
    markdown = "\n".join(t for kind, t in found if kind == "text/markdown")
    assert "### 1. Parameters" in markdown and "\\tag*{(1)" in markdown  # the derivation
    assert any(kind == "image/png" for kind, _ in found)  # the sweep's plot


def test_the_example_notebook_runs_without_matplotlib(tmp_path):
    # A `matplotlib` that cannot be imported, first on the kernel's path.
    blocker = tmp_path / "matplotlib"
    blocker.mkdir()
    (blocker / "__init__.py").write_text('raise ImportError("matplotlib is blocked for this test")\n')
    nb = execute(NOTEBOOK, {"PYTHONPATH": str(tmp_path)})
    found = outputs(nb)
    assert not [t for kind, t in found if kind == "error"]
    assert not any(kind == "image/png" for kind, _ in found)
    text = "\n".join(t for kind, t in found if kind == "stream")
    assert "matplotlib is not installed; the sweep as a table:" in text
    assert re.search(r"^n =  3\.00: 9\.61\d*°$", text, re.M)  # n = 3 is on the sweep's grid


def test_the_package_is_installed_from_an_abi3_wheel():
    dist = metadata.distribution("rodcube")
    direct = json.loads(dist.read_text("direct_url.json") or "{}")
    assert direct.get("url", "").endswith(".whl"), direct
    wheel = dist.read_text("WHEEL") or ""
    assert re.search(r"^Tag: cp39-abi3-", wheel, re.M), wheel
    assert dist.metadata["Requires-Python"] == ">=3.9"
    # Not the source tree: the package lives in the environment's site-packages (which may
    # itself lie under the checkout, as the test's virtual environment does in target/).
    installed = pathlib.Path(rodcube.__file__).resolve().parents
    assert ROOT / "python" not in installed
    assert pathlib.Path(sysconfig.get_paths()["purelib"]).resolve() in installed
