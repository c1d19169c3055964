"""Type stubs of the rodcube package, for editors and type checkers: every public function with
its parameters and return types (`python/tests` checks them against the installed package)."""

from collections.abc import Mapping, Sequence
from os import PathLike
from typing import Any, NamedTuple, Optional, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

__all__ = [
    "Derivation",
    "RodcubeError",
    "RunResult",
    "derivation",
    "derivation_models",
    "load_models",
    "models",
    "parameters",
    "run",
    "solve",
    "sweep",
    "sweep_results",
]

class RodcubeError(ValueError):
    """A request rodcube refused or could not solve; the message says why."""

class Check(TypedDict):
    """One check of a solve: whether it passed, by what margin, and what it checks."""

    passed: bool
    margin: float
    meaning: str

class ContactImpulse(TypedDict):
    """One contact's part in an impact."""

    contact: str
    normal_velocity_before: float
    """Negative: approaching."""
    normal_velocity_after: float
    impulse: float
    tangential_impulse: float
    """Its friction's impulse (0 without friction), in the unit of `impulse`."""
    velocity_unit: str
    impulse_unit: str

class Impact(TypedDict):
    """An impact: where a contact closed, the impulses by Newton's law with complementarity and Coulomb's cone."""

    time: float
    """s from release."""
    closing: str
    contacts: list[str]
    per_contact: list[ContactImpulse]
    energy_lost: float
    """J, from the impulses: normal_energy_lost + friction_energy_lost."""
    normal_energy_lost: float
    """J, the normal impulses' part."""
    friction_energy_lost: float
    """J, the friction impulses' part."""
    zeno_limit: bool

class SweepResult(TypedDict):
    """What `sweep` returns; the arrays have the broadcast shape of its axes."""

    separation_angle: npt.NDArray[np.float64]
    """rad, NaN where the point failed."""
    separation_time: npt.NDArray[np.float64]
    """s, NaN where the point failed."""
    ok: npt.NDArray[np.bool_]
    """True where the point was solved."""
    errors: list[tuple[tuple[int, ...], str]]
    """(index into the arrays, rodcube's message) for every failed point, in C order."""

# With `sweep(..., sensitivities=True)` the result also holds, for every parameter `p`, the
# float arrays `"d(separation_angle)/d(<p>)"` (rad per unit of p) and
# `"d(separation_time)/d(<p>)"` (s per unit of p), NaN where the point failed or its
# sensitivities do not exist (then `ok` is False and `errors` says why); those keys are no
# identifiers, so `SweepResult` does not list them.

def models() -> list[str]:
    """The names of the registered models: those compiled into the package, then those
    `load_models` added."""

def load_models(path: Union[str, PathLike[str]]) -> list[str]:
    """Loads every tape (`*.tape.json`, as `rodcube derive --tapes-into DIR SPEC` or `cargo
    derive` writes them) of the directory `path` into the registry and returns the names of
    the models they hold, sorted; `solve`, `sweep`, `run` and `parameters` then take them by
    name, run from their tapes with no compiler (`solve`'s and `run`'s `notes["model"]` says
    so). A model not compiled into the package is added; a tape of a compiled model whose
    program differs (its spec was derived again) takes its place; a tape that holds a compiled
    model's own program is checked and the compiled code kept. Loading a directory again
    changes nothing. A tape refused (cut short, edited by hand, another format version, a
    program that could read out of bounds) raises `RodcubeError` with the loader's message,
    which names the file; nothing of the directory is loaded then."""

def parameters(model: str) -> list[tuple[str, str, str]]:
    """The parameters of a model, in order: `(name, unit, meaning)`."""

def solve(
    model: str,
    want: Optional[Sequence[str]] = None,
    tolerance: Optional[float] = None,
    samples: Optional[int] = None,
    until: Optional[float] = None,
    **parameters: float,
) -> dict[str, Any]:
    """Solves one parameter point (every parameter given) and returns what `want` names:
    scalars as `float`, words as `str`, series as `dict[str, NDArray[float64]]` by column,
    `checks` as `dict[str, Check]`, `impacts` as `list[Impact]`, and `notes: dict[str, str]`
    (why a wanted quantity has no value, how the motion ended) when there are any. `until`
    (s from release) carries the motion on through impacts to that time; without it the run
    ends where the bodies first meet. With `"sensitivities"` in `want`,
    `sensitivities: dict[str, float]` holds `d(<result>)/d(<parameter>)` and
    `elasticity(<result>;<parameter>)` keyed as in results.json and `sensitivity_units:
    dict[str, str]` their units; a sensitivity that does not exist is absent and `notes` says
    why.
    """

@overload
def sweep(
    n: Optional[npt.ArrayLike] = None,
    a_over_ell: Optional[npt.ArrayLike] = None,
    *,
    model: str = "rod_cube",
    want: Sequence[str],
    tolerance: Optional[float] = None,
    until: Optional[float] = None,
    axes: Optional[Mapping[str, npt.ArrayLike]] = None,
    defaults: Optional[Mapping[str, float]] = None,
    sensitivities: bool = False,
    **parameters: Union[float, npt.ArrayLike],
) -> dict[str, Any]:
    """Any model's scalar results through the planner over broadcast axes: a float array per
    scalar result of the wanted quantities (`contact_end`, `floor_impact`, ...), keyed as in
    results.json (`contact_end_time`, ...: `sweep_results(model, want)` lists them) and NaN
    where a point has none; `ok` (`NDArray[bool_]`, True where the point has a value of every
    wanted quantity) and `errors` (`list[tuple[tuple[int, ...], str]]`: index and rodcube's
    message, or the note why a quantity has no value, for every point not ok, in C order).
    `tolerance` and `until` are `solve`'s; `sensitivities=True` is refused here."""

@overload
def sweep(
    n: Optional[npt.ArrayLike] = None,
    a_over_ell: Optional[npt.ArrayLike] = None,
    *,
    model: str = "rod_cube",
    want: None = None,
    tolerance: None = None,
    until: None = None,
    axes: Optional[Mapping[str, npt.ArrayLike]] = None,
    defaults: Optional[Mapping[str, float]] = None,
    sensitivities: bool = False,
    **parameters: Union[float, npt.ArrayLike],
) -> SweepResult:
    """Separation angle and time over broadcast axes (`n` = m2/m1, `a_over_ell`, `axes`, and
    keyword parameters given as arrays); every parameter needs a value from an axis, a keyword
    or `defaults`, g included. `sensitivities=True` adds `d(separation_angle)/d(<p>)` and
    `d(separation_time)/d(<p>)` for every parameter (see above)."""

def sweep_results(model: str, want: Sequence[str]) -> list[tuple[str, str]]:
    """The scalar results `sweep(model=model, want=want, ...)` returns, `(key, unit)` in order:
    they follow from the model and `want` alone, whatever the points."""

class Step(NamedTuple):
    """One step of a derivation: a `\\subsection*` of the write-up, numbered in its order."""

    number: int
    section: str
    title: str
    latex: str
    """The step's LaTeX from the JSON record: its equation's lines, or the parameters table's
    rows."""
    tag: Optional[str]
    """The equation's number, for the results without units."""

class Derivation:
    """A model's derivation as the derivation tool wrote it (`generated/<model>.tex` and
    `.json`, carried by the package): a notebook shows it as Markdown with LaTeX, every step
    numbered as in the `.tex`, its texts and equations from the JSON record's `write_up`."""

    model: str
    latex: str
    """The write-up, the text of `generated/<model>.tex`."""
    record: dict[str, Any]
    """The JSON record, `generated/<model>.json`."""
    steps: list[Step]
    def __init__(self, model: str) -> None: ...
    @property
    def expressions(self) -> dict[str, str]:
        """The derived expressions by name, as strings."""
    @property
    def dimensionless(self) -> dict[str, str]:
        """The results without units by name, in the dimensionless groups and the angle."""
    def expression(self, name: str) -> str:
        """One expression by name, from `expressions` or else `dimensionless`."""
    def _repr_markdown_(self) -> str: ...

class RunResult:
    """What `run` returns: `results.json` of `rodcube run` as Python values, the series as
    NumPy arrays and `motion.svg`; a notebook shows it as HTML (tables, checks, the motion)."""

    json: str
    """The text of `results.json`."""
    record: dict[str, Any]
    motion_svg: Optional[str]
    """`motion.svg`, when the scene wanted a trajectory."""
    model: str
    parameters: dict[str, float]
    results: dict[str, dict[str, Any]]
    """Each result's `value`, `unit` and `meaning`."""
    checks: dict[str, dict[str, Any]]
    notes: dict[str, str]
    series: dict[str, dict[str, npt.NDArray[np.float64]]]
    def __init__(self, record_json: str, motion_svg: Optional[str]) -> None: ...
    def __getitem__(self, key: str) -> Any:
        """A result's value (a float, or a word) by name."""
    def units(self, series: str) -> dict[str, str]:
        """The unit of each column of a series."""
    def to_frame(self, series: Optional[str] = None) -> Any:
        """The results, or one series, as a pandas DataFrame. Only where pandas is installed:
        without it the method does not exist."""
    def _repr_html_(self) -> str: ...

def derivation(model: str) -> Derivation:
    """The derivation of `model` (any name of `derivation_models()`). A model `load_models`
    loaded from a tape has none (`RodcubeError` naming its tape)."""

def derivation_models() -> list[str]:
    """The models whose derivations the package carries: every model compiled into it."""

def run(scene: Union[str, PathLike[str], Mapping[str, Any]]) -> RunResult:
    """Runs a scene as `rodcube run` does: a path, YAML text, or a dict with the scene's keys.
    Errors are `RodcubeError` with rodcube's messages (file, line, column and field)."""
