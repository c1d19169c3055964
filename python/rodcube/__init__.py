"""rodcube from Python: the separation of a rod leaning on a cube, and models like it.

- ``solve(model, want=[...], **parameters)``: one parameter point through rodcube's planner;
  returns a dict of floats (scalars), strings (words such as ``contact_end_cause``) and dicts
  of NumPy arrays (series, by column).
- ``sweep(n, a_over_ell, model="rod_cube", axes={...}, **fixed)``: separation angle and time
  over NumPy arrays, in parallel with the GIL released; NaN where a point has no solution.
  Axes are ``n = m2/m1``, ``a_over_ell``, or in ``axes`` any parameter or ratio ``p_over_q``
  of two parameters; parameters on no axis are 1 unless given as keywords.
- ``models()`` and ``parameters(model)``: the registry.

Errors are ``RodcubeError`` (a ``ValueError``) with rodcube's own messages.
"""

from ._rodcube import RodcubeError, models, parameters, solve, sweep

__all__ = ["RodcubeError", "models", "parameters", "solve", "sweep"]
