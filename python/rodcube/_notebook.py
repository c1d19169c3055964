"""rodcube in notebooks: ``derivation(model)``, the model's derivation rendered as Markdown with
LaTeX (every step numbered in the order of ``generated/<model>.tex``, its texts and equations
from ``generated/<model>.json``'s ``write_up``, the context the ``.tex`` is rendered from, with
the write-up's own tags) and its expressions as strings; ``run(scene)``, a scene run as ``rodcube
run`` runs it, whose result shows its tables, checks and the animated ``motion.svg`` as HTML,
and gives ``to_frame()`` where pandas is installed.

The derivations are embedded in the compiled module (``_rodcube.derivation_sources``), so an
installed wheel needs no source tree. Numbers are formatted by rodcube's own formatter, as the
command line's tables show them.
"""

from __future__ import annotations

import html
import importlib.util
import json
import os
import re
from collections.abc import Mapping
from typing import Any, NamedTuple, Optional

import numpy as np

from ._rodcube import (
    RodcubeError,
    derivation_models,
    derivation_sources,
    format_number,
    result_order,
    run_scene,
)
from ._rodcube import parameters as _parameters

# --- derivations -------------------------------------------------------------------------


class Step(NamedTuple):
    """One step of a derivation: a ``\\subsection*`` of the write-up, numbered in its order."""

    number: int
    """1, 2, ... in the order of the ``.tex``."""
    section: str
    """The ``\\section*`` the step is in (LaTeX text)."""
    title: str
    """The step's heading (LaTeX text)."""
    latex: str
    """The step's LaTeX from the JSON record: its equation's lines (joined by ``\\\\``), or the
    parameters table's rows."""
    tag: Optional[str] = None
    """The equation's number (``(1)\\quad\\text{paper (9)}``), for the results without units."""


def _text(latex: str) -> str:
    """LaTeX running text as Markdown; inline math (``$...$``) is kept as it is."""
    parts = latex.split("$")
    for i in range(0, len(parts), 2):
        t = parts[i]
        t = re.sub(
            r"\\texttt\{((?:[^{}]|\{\})*)\}",
            lambda m: "`" + m.group(1).replace("\\_", "_").replace("\\^{}", "^") + "`",
            t,
        )
        t = t.replace("\\^{}", "^").replace("---", "\u2014").replace("--", "\u2013")
        # Code spans show backslashes: `rod\_cube` is `rod_cube`.
        t = re.sub(r"`[^`]*`", lambda m: m.group(0).replace("\\_", "_"), t)
        parts[i] = t.replace("~", " ")
    return "$".join(parts)


def _tag_text(tag: str) -> str:
    """A tag's text without math delimiters (a ``$`` would end the display in Markdown):
    ``(1)\\quad\\text{paper (9)}`` is ``(1) paper (9)``, with an em space."""
    tag = tag.strip().strip("$")
    tag = re.sub(r"\\text\{([^{}]*)\}", r"\1", tag)
    return re.sub(r"\\q?quad\s*", "\u2003", tag)


def _display(equation: Mapping[str, Any]) -> str:
    """An equation of the record's write-up as ``$$ ... $$`` for MathJax; a multi-line one is
    ``gathered``, its tag kept (as text) after it."""
    content = equation["latex"].strip()
    tag = f" \\tag*{{{_tag_text(equation['tag'])}}}" if equation.get("tag") else ""
    if equation["env"] == "multline*":
        content = f"\\begin{{gathered}}\n{content}\n\\end{{gathered}}"
    return f"$$\n{content}{tag}\n$$"


def _table(rows: list[Mapping[str, str]], header: tuple[str, str, str]) -> str:
    """A table of the record's write-up (``symbol``, ``meaning``, ``unit`` per row) as Markdown."""
    cells = [[_text(f"${r['symbol']}$"), _text(r["meaning"]), _text(r["unit"])] for r in rows]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(c) + " |" for c in cells]
    return "\n".join(lines)


def _tabular_rows(rows: list[Mapping[str, str]]) -> str:
    """A table's rows as the ``.tex`` writes them."""
    return "\n".join(f"${r['symbol']}$ & {r['meaning']} & {r['unit']} \\\\" for r in rows)


_MODEL, _PARAMETERS, _RESULTS, _TANGENTS = ("Model \\texttt{{{}}}", "Parameters", "Results without units", "Partial derivatives")
"""The write-up's own headings, as ``templates/model.tex.tera`` writes them."""


class Derivation:
    """A model's derivation as the derivation tool wrote it: shown in a notebook as Markdown
    with LaTeX, every step numbered as in ``generated/<model>.tex``, its texts and equations
    from ``generated/<model>.json`` (``write_up``, the context the ``.tex`` is rendered from);
    ``expressions`` gives the derived expressions as strings."""

    def __init__(self, model: str):
        tex, record = derivation_sources(model)
        self.model = model
        self.latex = tex
        self.record: dict[str, Any] = json.loads(record)
        self.steps = self._steps()

    def _steps(self) -> list[Step]:
        """The write-up's steps, numbered: the parameters, the equations, the results without
        units."""
        w = self.record["write_up"]
        model = _MODEL.format(w["name"])
        steps = [Step(1, model, _PARAMETERS, _tabular_rows(w["params"]))]
        steps += [Step(len(steps) + k + 1, model, e["title"], e["latex"]) for k, e in enumerate(w["equations"])]
        if w["groups"]:
            steps += [Step(len(steps) + k + 1, _RESULTS, e["title"], e["latex"], e["tag"]) for k, e in enumerate(w["results"])]
        return steps

    @property
    def expressions(self) -> dict[str, str]:
        """The derived expressions by name (``generated/<model>.json``'s ``expressions``)."""
        return dict(self.record["expressions"])

    @property
    def dimensionless(self) -> dict[str, str]:
        """The results without units by name, in the dimensionless groups and the angle."""
        return dict(self.record["dimensionless"].get("expressions", {}))

    def expression(self, name: str) -> str:
        """One expression by name, from ``expressions`` or else ``dimensionless``."""
        for table in (self.expressions, self.dimensionless):
            if name in table:
                return table[name]
        names = sorted(self.expressions) + sorted(self.dimensionless)
        raise RodcubeError(f"model `{self.model}` has no expression `{name}`; it has: {', '.join(names)}")

    def _repr_markdown_(self) -> str:
        w = self.record["write_up"]
        number = iter(self.steps)

        def step(title: str, body: str) -> list[str]:
            return [f"### {next(number).number}. {_text(title)}", body]

        out = [f"## {_text(_MODEL.format(w['name']))}", _text(w["intro"])]
        out += step(_PARAMETERS, _table(w["params"], ("symbol", "meaning", "unit")))
        for e in w["equations"]:
            out += step(e["title"], _display(e))
        if w["groups"]:
            out += [f"## {_RESULTS}", _table(w["groups"], ("", "meaning", "")), _text(w["scales"])]
            for e in w["results"]:
                out += step(e["title"], _display(e))
        if w["tangents"]:
            out += [f"## {_TANGENTS}", _text(w["tangents"])]
        return "\n\n".join(out) + "\n"

    def __repr__(self) -> str:
        return f"<rodcube.Derivation of {self.model}: {len(self.steps)} steps>"


def derivation(model: str) -> Derivation:
    """The derivation of ``model`` (any name of ``derivation_models()``). A model that
    ``load_models`` loaded from a tape has none: ``RodcubeError`` names its tape."""
    return Derivation(model)


# --- runs --------------------------------------------------------------------------------


def _number(value: Optional[float], sig: int = 12) -> str:
    """A number as the command line's tables show it; ``None`` (JSON's NaN) as ``NaN``."""
    return "NaN" if value is None else format_number(float(value), sig)


def _words(text: str) -> str:
    """Escaped text with rodcube's ``backticked`` names as code."""
    return re.sub(r"`([^`]*)`", r"<code>\1</code>", html.escape(str(text)))


_TABLE = 'style="width:100%;border-collapse:collapse;table-layout:auto"'
_CELL = 'style="text-align:{align};padding:2px 6px;vertical-align:top;white-space:{wrap}"'


def _html_table(header: list[str], rows: list[list[str]], right: tuple[int, ...] = (), wrap: tuple[int, ...] = ()) -> str:
    """An HTML table (cells already escaped) that fits the notebook's width: the free-text
    columns (``wrap``) wrap, the others do not; numbers (``right``) align right."""

    def cell(tag: str, i: int, text: str) -> str:
        style = _CELL.format(align="right" if i in right else "left", wrap="normal" if i in wrap else "nowrap")
        return f"<{tag} {style}>{text}</{tag}>"

    head = "".join(cell("th", i, html.escape(h)) for i, h in enumerate(header))
    body = "".join("<tr>" + "".join(cell("td", i, c) for i, c in enumerate(row)) + "</tr>" for row in rows)
    return f'<div style="max-width:100%;overflow-x:auto"><table {_TABLE}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>'


def _check_cells(key: str, check: Mapping[str, Any]) -> list[str]:
    """A check's row as the command line shows it: name, status, measured, held to, at t."""
    unit = check.get("unit") or ""
    unit = "" if unit == "1" else f" {unit}"
    if check["kind"] == "monitor":
        measured = f"min {_number(check['value'], 5)}{unit}"
        held = f"&gt;= {_number(check['limit'], 3)}{unit}"
    else:
        measured = f"drift {_number(check['value'], 3)}"
        held = f"&lt;= {_number(check['limit'], 3)}" + (" (built in)" if check["kind"] == "identity" else "")
    at = check.get("at_time")
    status = "pass" if check["passed"] else "<b>FAIL</b>"
    return [
        html.escape(key.rsplit(".", 1)[-1]),
        status,
        measured,
        held,
        "" if at is None else f"{_number(at, 4)} s",
        _words(check["meaning"]),
    ]


class RunResult:
    """What ``run(scene)`` returns: ``results.json`` of ``rodcube run`` as Python values, the
    series as NumPy arrays, and ``motion.svg`` when the scene wanted a trajectory. A notebook
    shows it as HTML: the parameters, results, notes and checks as tables that fit the page,
    the series' shapes, and the motion, animated."""

    def __init__(self, record_json: str, motion_svg: Optional[str]):
        self.json = record_json
        self.record: dict[str, Any] = json.loads(record_json)
        self.motion_svg = motion_svg
        self.model: str = self.record["model"]
        self.parameters: dict[str, float] = dict(self.record["parameters"])
        self.results: dict[str, dict[str, Any]] = dict(self.record.get("results", {}))
        self.checks: dict[str, dict[str, Any]] = dict(self.record.get("checks", {}))
        self.notes: dict[str, str] = dict(self.record.get("notes", {}))
        self.series: dict[str, dict[str, np.ndarray]] = {
            name: {
                c["name"]: np.array([np.nan if v is None else v for v in c["values"]], dtype=np.float64)
                for c in s["columns"]
            }
            for name, s in self.record.get("series", {}).items()
        }

    def __getitem__(self, key: str) -> Any:
        """A result's value (a float, or a word such as ``contact_end_cause``) by name."""
        if key not in self.results:
            raise KeyError(f"no result `{key}`; there are: {', '.join(sorted(self.results))}")
        return self.results[key]["value"]

    def units(self, series: str) -> dict[str, str]:
        """The unit of each column of a series."""
        return {c["name"]: c["unit"] for c in self.record["series"][series]["columns"]}

    def _repr_html_(self) -> str:
        info = {name: (unit, meaning) for name, unit, meaning in _parameters(self.model)}
        parts = [f"<h3>model <code>{html.escape(self.model)}</code></h3>"]
        rows = [
            [html.escape(n), _number(v), html.escape(info.get(n, ("", ""))[0]), _words(info.get(n, ("", ""))[1])]
            for n, v in self.parameters.items()
        ]
        parts += ["<h4>Parameters</h4>", _html_table(["parameter", "value", "unit", "meaning"], rows, (1,), (3,))]
        rows = []
        order = {name: i for i, name in enumerate(result_order())}
        for key, r in sorted(self.results.items(), key=lambda kv: (order.get(kv[0], len(order)), kv[0])):
            if key == "impacts":
                continue
            value, unit = r["value"], r.get("unit", "")
            number = isinstance(value, (int, float)) or value is None
            degrees = f"{_number(np.degrees(value), 6)}°" if unit == "rad" and value is not None else ""
            shown = _number(value) if number else _words(value)
            rows.append([html.escape(key), shown, html.escape("" if unit == "1" else unit), degrees, _words(r["meaning"])])
        parts += ["<h4>Results</h4>", _html_table(["result", "value", "unit", "degrees", "meaning"], rows, (1, 3), (4,))]
        impacts = self.results.get("impacts", {}).get("value") or []
        if impacts:
            rows = [
                [_number(i["time"]), _words(i["closing"]), _words(", ".join(i["contacts"])), _number(i["energy_lost"]), "yes" if i["zeno_limit"] else ""]
                for i in impacts
            ]
            parts += ["<h4>Impacts</h4>", _html_table(["t [s]", "closing", "contacts", "energy lost [J]", "Zeno limit"], rows, (0, 3), (2,))]
        if self.notes:
            rows = [[html.escape(k), _words(v)] for k, v in self.notes.items()]
            parts += ["<h4>Notes</h4>", _html_table(["about", "note"], rows, (), (1,))]
        if self.checks:
            parts.append(self._checks_html())
        if self.series:
            rows = [
                [html.escape(name), _words(", ".join(f"`{c}` [{u}]" for c, u in self.units(name).items())), str(len(next(iter(s.values()))))]
                for name, s in self.series.items()
            ]
            parts += ["<h4>Series</h4>", _html_table(["series", "columns", "rows"], rows, (2,), (1,))]
        if self.motion_svg:
            svg = self.motion_svg.replace("<svg ", '<svg style="max-width:100%;height:auto" ', 1)
            parts += ["<h4>Motion</h4>", f'<div style="max-width:100%">{svg}</div>']
        return "\n".join(parts)

    def _checks_html(self) -> str:
        """The checks, phase by phase, in the command line's order."""
        ordered = sorted(self.checks.items(), key=lambda kv: (kv[1]["order"], kv[1]["kind"] != "monitor", kv[0]))
        failed = sum(not c["passed"] for c in self.checks.values())
        parts = [f"<h4>Checks ({len(self.checks) - failed} passed, {failed} failed), phase by phase</h4>"]
        phase = None
        rows: list[list[str]] = []
        header = ["check", "status", "measured", "held to", "at t", "meaning"]
        for key, check in ordered:
            if check["phase"] != phase and rows:
                parts += [f"<p>{_words(phase)}:</p>", _html_table(header, rows, (4,), (5,))]
                rows = []
            phase = check["phase"]
            rows.append(_check_cells(key, check))
        if rows:
            parts += [f"<p>{_words(phase)}:</p>", _html_table(header, rows, (4,), (5,))]
        return "\n".join(parts)

    def __repr__(self) -> str:
        return f"<rodcube.RunResult of {self.model}: {len(self.results)} results, {len(self.series)} series>"


def _has_pandas() -> bool:
    """Whether pandas can be imported (without importing it)."""
    try:
        return importlib.util.find_spec("pandas") is not None
    except (ImportError, ValueError):
        # ValueError: `sys.modules["pandas"]` is None (blocked) or has no spec.
        return False


if _has_pandas():

    def to_frame(self: RunResult, series: Optional[str] = None):
        """The results as a pandas DataFrame (index: result; columns ``value``, ``unit``,
        ``meaning``), or with ``series`` that series (one column per column, the units in
        ``frame.attrs["units"]``). Only where pandas is installed."""
        import pandas as pd

        if series is None:
            rows = {k: (r["value"], r.get("unit", ""), r["meaning"]) for k, r in self.results.items() if k != "impacts"}
            return pd.DataFrame.from_dict(rows, orient="index", columns=["value", "unit", "meaning"])
        if series not in self.series:
            raise RodcubeError(f"no series `{series}`; there are: {', '.join(sorted(self.series))}")
        frame = pd.DataFrame(self.series[series])
        frame.attrs["units"] = self.units(series)
        return frame

    RunResult.to_frame = to_frame  # type: ignore[attr-defined]


def run(scene: Any) -> RunResult:
    """Runs a scene as ``rodcube run`` does: ``scene`` is a path (``str`` or ``os.PathLike``), a
    YAML scene as a string, or a dict with the scene's keys (``model``, ``parameters``,
    ``want``, and ``tolerance``, ``samples``, ``until`` if wanted). A string is YAML text when it
    spans lines or holds a ``:`` and names no file. Errors are ``RodcubeError`` with
    rodcube's messages (file, line, column and field; ``<yaml>`` or ``<dict>`` for a scene
    given as text or as a dict, whose lines are those of ``json.dumps(scene, indent=2)``)."""
    if isinstance(scene, os.PathLike):
        return RunResult(*run_scene(None, os.fspath(scene), ""))
    if isinstance(scene, str):
        if ("\n" in scene or ":" in scene) and not os.path.exists(scene):
            return RunResult(*run_scene(scene, None, "<yaml>"))
        return RunResult(*run_scene(None, scene, ""))
    if isinstance(scene, Mapping):

        def plain(value: Any) -> Any:
            if isinstance(value, np.generic):
                return value.item()
            if isinstance(value, np.ndarray):
                return value.tolist()
            raise RodcubeError(f"a scene holds numbers, strings, lists and dicts, not {value!r}")

        text = json.dumps(dict(scene), indent=2, default=plain)
        return RunResult(*run_scene(text, None, "<dict>"))
    raise RodcubeError(f"a scene is a path, YAML text or a dict, not {type(scene).__name__}")


__all__ = ["Derivation", "RunResult", "Step", "derivation", "derivation_models", "run"]
