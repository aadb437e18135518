"""JSON-ready copies of results: one place for what standard JSON cannot hold."""
from __future__ import annotations

import math


def jsonable(x, nulled: list | None = None, where: str = ""):
    """A copy of ``x`` that `json.dumps(..., allow_nan=False)` accepts.

    Parameters
    ----------
    x : object
        Dicts, lists, tuples, NumPy arrays and scalars, and plain Python values.
    nulled : list, optional
        When given, the path of every non-finite number written as None is appended.
    where : str
        Path of ``x`` in the enclosing document (for ``nulled``).

    Returns
    -------
    object
        Keys as strings, NumPy values as Python ones, NaN and ±inf as None
        (standard JSON has no NaN: a reader would choke on it).
    """
    if isinstance(x, dict):
        return {str(k): jsonable(v, nulled, f"{where}.{k}" if where else str(k)) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v, nulled, f"{where}[{i}]") for i, v in enumerate(x)]
    if hasattr(x, "tolist") and not isinstance(x, (str, bytes)):  # NumPy scalars and arrays
        return jsonable(x.tolist(), nulled, where)
    if isinstance(x, float) and not math.isfinite(x):
        if nulled is not None:
            nulled.append(where)
        return None
    return x
