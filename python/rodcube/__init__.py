"""rodcube from Python: the separation of a rod leaning on a cube, and models like it.

- ``solve(model, want=[...], **parameters)``: one parameter point through rodcube's planner;
  returns a dict of floats (scalars), strings (words such as ``contact_end_cause``) and dicts
  of NumPy arrays (series, by column); ``"sensitivities"`` in ``want`` adds the dicts
  ``sensitivities`` and ``sensitivity_units``, keyed as in results.json.
- ``sweep(n, a_over_ell, *, model="rod_cube", axes={...}, defaults={...}, **parameters)``:
  separation angle and time over arrays, in parallel with the GIL released. Axes are
  ``n = m2/m1``, ``a_over_ell``, the entries of ``axes`` (any parameter or ratio ``p_over_q``
  of two parameters) and every keyword parameter given as an array; scalars and array-likes
  broadcast against each other as NumPy broadcasts. Every parameter needs a value: rodcube
  assumes none (not even g). A point that fails is NaN, ``False`` in the ``ok`` mask, and
  listed in ``errors`` with the reason. ``sensitivities=True`` adds the exact
  ``d(separation_angle)/d(<p>)`` and ``d(separation_time)/d(<p>)`` for every parameter.
  With ``want=[...]`` (quantity names) it sweeps any model through the planner instead and
  returns an array per scalar result of the wanted quantities (``contact_end_time``,
  ``floor_impact_time``, ...); ``sweep_results(model, want)`` lists them with their units.
  ``python/examples/dask_sweep.py`` runs such a sweep on a ``dask.distributed`` cluster.
- ``models()`` and ``parameters(model)``: the registry, with each parameter's unit and meaning.
- ``load_models(path)``: adds to the registry the models of a directory of tapes (as
  ``rodcube derive --tapes-into DIR SPEC`` writes them: a model derived a minute ago, run with
  no compiler) and returns their names; ``solve``, ``sweep``, ``run`` and ``parameters`` then
  take them by name. A tape refused (cut short, edited, another format version) raises
  ``RodcubeError`` naming the file, and nothing of the directory is loaded.
- ``derivation(model)``: the model's derivation (carried by the package for every model compiled
  into it; a tape holds no derivation), which a notebook shows
  as Markdown with LaTeX, every step numbered as in ``generated/<model>.tex`` (its texts and
  equations from the JSON record's ``write_up``); its
  ``expressions`` are the derived expressions as strings, ``steps`` the steps, ``latex`` the
  write-up. ``derivation_models()`` names the models it knows.
- ``run(scene)``: a scene (a path, YAML text or a dict) run as ``rodcube run`` runs it; the
  ``RunResult`` holds ``results.json`` as Python values (``result["separation_angle"]``,
  ``series`` as NumPy arrays, ``checks``, ``notes``) and ``motion_svg``, and a notebook shows it
  as HTML: the tables fitted to the page, the checks and the motion, animated. Where pandas is
  installed (it is optional) ``RunResult.to_frame()`` gives the results, or a series, as a
  DataFrame; without pandas the method does not exist.

Errors are ``RodcubeError`` (a ``ValueError``) with rodcube's own messages. Type stubs
(``__init__.pyi``) describe every function for editors and type checkers.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ._rodcube import RodcubeError, load_models, models, parameters, solve
from ._rodcube import sweep_flat as _sweep_flat
from ._rodcube import sweep_planned as _sweep_planned
from ._rodcube import sweep_results
from ._notebook import Derivation, RunResult, derivation, derivation_models, run

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


def _numbers(what, value):
    """``value`` as a float64 array, or a RodcubeError saying that ``what`` must be numbers."""
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise RodcubeError(
            f"{what} must be a number or an array-like of numbers, not {value!r}"
        ) from None


def sweep(
    n=None,
    a_over_ell=None,
    *,
    model="rod_cube",
    want=None,
    tolerance=None,
    until=None,
    axes=None,
    defaults=None,
    sensitivities=False,
    **parameters,
):
    """Separation angle and time of ``model`` over arrays of parameter values, or with
    ``want`` any of its scalar results.

    The axes are ``n`` (= m2/m1), ``a_over_ell``, the entries of ``axes`` (a dict from a
    parameter name, or a ratio ``p_over_q`` of two parameters of one unit, to values) and
    every keyword parameter given as an array-like; keyword parameters given as scalars are
    fixed. All axes broadcast against each other as NumPy broadcasts (scalars, lists, 0-d
    and n-d arrays); the results have the broadcast shape.

    Every parameter of the model needs a value: an axis sets it, a keyword gives it, or else
    ``defaults`` (a dict from parameter name to number) does. rodcube assumes none, g
    included. A ratio axis sets only its numerator: ``n`` sets m2 = n * m1, so m1 still needs
    a value, and ``a_over_ell`` sets a = a_over_ell * ell, so ell does. The paper's point is
    ``sweep(n=3.0, a_over_ell=0.25, m1=1.0, ell=1.0, g=9.81)``.

    Returns a dict:

    - ``separation_angle`` (rad) and ``separation_time`` (s): float arrays, NaN where a point
      failed;
    - ``ok``: a bool array, ``True`` where the point was solved;
    - ``errors``: ``(index, message)`` for every failed point in C order (the order of
      ``np.argwhere(~ok)``); ``index`` is a tuple indexing the result arrays, ``message`` is
      rodcube's reason.

    With ``want`` (a list of quantity names, as ``solve`` takes: ``separation_time``,
    ``contact_end``, ``floor_impact``, ``cross_check``, ...) every point runs through rodcube's
    planner instead, any model (integrated, friction, impacts, tapes) and any quantity with a
    number per point: the dict holds one float array per scalar result of the wanted quantities
    (``contact_end_time``, ``contact_end_angle``, ``<contact>_end_time``,
    ``floor_impact_time``, ``impact_angular_velocity``, ...: the keys of results.json, whose
    units ``sweep_results(model, want)`` lists) beside ``ok`` and ``errors``. A point is
    ``False`` in ``ok`` where the model refuses it or the planner fails (every value NaN), or
    where a wanted quantity has no value there (NaN, the others kept; ``errors`` gives its
    note); a contact of its own that holds to the end is NaN in its ``<contact>_end_*`` only.
    ``tolerance`` (relative, default 1e-10) and ``until`` (s from release: the motion goes on
    through impacts to that time) are ``solve``'s. The columns depend on the model and ``want``
    alone, so a sweep cut into blocks (``python/examples/dask_sweep.py`` runs one on a
    ``dask.distributed`` cluster) has the same keys in every block, and each point's numbers
    are the same wherever it runs.

    With ``sensitivities=True`` it also holds, for every parameter ``p`` of the model, the exact
    sensitivities ``d(separation_angle)/d(<p>)`` (rad per unit of ``p``) and
    ``d(separation_time)/d(<p>)`` (s per unit of ``p``) as float arrays of the same shape: the
    numbers of ``solve(..., want=[..., "sensitivities"])``, of results.json and of
    ``rodcube sweep --sensitivities``. Where a point's sensitivities do not exist (the contact
    opens at release, say) they are NaN, the point is ``False`` in ``ok`` (its angle and time
    kept) and ``errors`` says why.

    Raises ``RodcubeError`` for an unknown model, axis, parameter or quantity, a quantity
    that is no number per point, a parameter without a
    value (the message lists each with its unit and meaning), a parameter set twice, a value
    that is not a number, or axes whose shapes do not broadcast together.
    """
    named = []
    if n is not None:
        named.append(("n", n))
    if a_over_ell is not None:
        named.append(("a_over_ell", a_over_ell))
    if axes is not None:
        if not isinstance(axes, Mapping):
            raise RodcubeError(f"axes must be a dict from names to values, not {axes!r}")
        named.extend((str(name), values) for name, values in axes.items())
    fixed = []
    for name, value in parameters.items():
        values = _numbers(f"parameter `{name}`", value)
        if values.ndim == 0:
            fixed.append((name, float(values)))
        else:
            named.append((name, values))
    given = []
    if defaults is not None:
        if not isinstance(defaults, Mapping):
            raise RodcubeError(f"defaults must be a dict from parameter names to numbers, not {defaults!r}")
        for name, value in defaults.items():
            number = _numbers(f"defaults[{name!r}]", value)
            if number.ndim != 0:
                raise RodcubeError(f"defaults[{name!r}] must be one number, not an array of shape {number.shape}")
            given.append((str(name), float(number)))
    if not named:
        raise RodcubeError(
            "give an axis: n, a_over_ell, axes={name: values} (a parameter or a ratio p_over_q), "
            "or a keyword parameter with an array of values"
        )
    arrays = [_numbers(f"axis `{name}`", values) for name, values in named]
    try:
        broadcast = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(f"`{name}` {a.shape}" for (name, _), a in zip(named, arrays))
        raise RodcubeError(f"the axes' shapes do not broadcast together: {shapes}") from None
    shape = broadcast[0].shape
    columns = [np.ascontiguousarray(b).reshape(-1) for b in broadcast]
    names = [name for name, _ in named]
    if want is None:
        if tolerance is not None or until is not None:
            raise RodcubeError(
                "tolerance and until are the planner's: give them with want=[...]; the separation "
                "sweep without want solves each point exactly"
            )
        angle, time, ok, failures, derivatives = _sweep_flat(
            model, names, columns, fixed, given, bool(sensitivities)
        )
        results = [("separation_angle", angle), ("separation_time", time)] + derivatives
    else:
        if sensitivities:
            raise RodcubeError(
                "sensitivities=True is the separation sweep's (without want); with want, solve "
                "wants \"sensitivities\" point by point"
            )
        if isinstance(want, str) or not all(isinstance(w, str) for w in want):
            raise RodcubeError(f"want must be a list of quantity names, not {want!r}")
        results, ok, failures = _sweep_planned(
            model, list(want), names, columns, fixed, given, tolerance, until
        )
    return _shaped(shape, results, ok, failures)


def _shaped(shape, results, ok, failures):
    """The sweep's dict: each flat result and the mask in ``shape``, the failures' flat indices
    as index tuples into it."""
    if failures and shape:
        flat = np.fromiter((i for i, _ in failures), dtype=np.intp, count=len(failures))
        where = zip(*(k.tolist() for k in np.unravel_index(flat, shape)))
        errors = [(index, message) for index, (_, message) in zip(where, failures)]
    else:
        # A 0-d result: its one point's index is ().
        errors = [((), message) for _, message in failures]
    out = {name: values.reshape(shape) for name, values in results}
    out["ok"] = ok.reshape(shape)
    out["errors"] = errors
    return out
