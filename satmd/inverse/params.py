"""Hyperparameter constraints of `InverseModel`, checked in one place (as scikit-learn's ``_parameter_constraints``).

The defaults live in ``InverseModel.__init__``'s signature and nowhere
else; what depends on the preset (the size of its training set) lives in
``PRESET_SIZES``. Each constraint is a list of what a value may be: ``None``,
a type, an `Options` or an `Interval`; `validate` accepts a value that
matches any of them and otherwise raises one `SatmdError` line naming the
parameter.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from ..errors import SatmdError

#: Training-set size per preset when ``samples_per_pair`` / ``n_samples`` is None.
PRESET_SIZES = {"paper": {"samples_per_pair": 150}, "box": {"n_samples": 6000}}


@dataclass(frozen=True)
class Options:
    """One of a fixed set of strings."""

    values: tuple

    def accepts(self, v) -> bool:
        return isinstance(v, str) and v in self.values

    def describe(self) -> str:
        return "one of " + ", ".join(self.values)


@dataclass(frozen=True)
class Interval:
    """A finite number of ``kind`` (Integral or Real) in [lo, hi]; ``open`` names the open ends."""

    kind: type
    lo: float | None = None
    hi: float | None = None
    open: str = ""  # "", "lo", "hi" or "both"

    def accepts(self, v) -> bool:
        if isinstance(v, bool) or not isinstance(v, self.kind):
            return False
        if not math.isfinite(v):
            return False
        lo_ok = self.lo is None or (v > self.lo if self.open in ("lo", "both") else v >= self.lo)
        hi_ok = self.hi is None or (v < self.hi if self.open in ("hi", "both") else v <= self.hi)
        return lo_ok and hi_ok

    def describe(self) -> str:
        what = "an integer" if self.kind is Integral else "a number"
        lo = "" if self.lo is None else ("(" if self.open in ("lo", "both") else "[") + f"{self.lo:g}"
        hi = "" if self.hi is None else f"{self.hi:g}" + (")" if self.open in ("hi", "both") else "]")
        if lo and hi:
            return f"{what} in {lo}, {hi}"
        return f"{what} " + (f">{'' if self.open in ('lo', 'both') else '='} {self.lo:g}" if lo else
                             f"<{'' if self.open in ('hi', 'both') else '='} {self.hi:g}")


class Grid:
    """An increasing 1-D array of at least two finite, positive frequencies [Hz]."""

    def accepts(self, v) -> bool:
        try:
            f = np.asarray(v, float)
        except (TypeError, ValueError):
            return False
        return f.ndim == 1 and f.size >= 2 and bool(np.all(np.isfinite(f)) and f[0] > 0 and np.all(np.diff(f) > 0))

    def describe(self) -> str:
        return "an increasing array of at least two positive frequencies"


def _describe(c) -> str:
    if c is None:
        return "None"
    if isinstance(c, type):
        return "True or False" if c is bool else f"a {c.__name__}"
    return c.describe()


def _accepts(c, v) -> bool:
    if c is None:
        return v is None
    if isinstance(c, type):
        return isinstance(v, c)
    return c.accepts(v)


def validate(params: dict, constraints: dict, owner: str = "InverseModel") -> None:
    """Raise a one-line `SatmdError` for the first parameter that matches none of its constraints.

    Parameters
    ----------
    params : name -> value (``get_params()``)
    constraints : name -> list of allowed forms (None, a type, `Options`, `Interval`, `Grid`)
    owner : the class named in the message

    Returns
    -------
    None
    """
    for name, allowed in constraints.items():
        value = params[name]
        if not any(_accepts(c, value) for c in allowed):
            if any(isinstance(c, Options) for c in allowed):
                raise SatmdError(f"unknown {name} {value!r} for {owner}; choose from "
                                 + ", ".join(next(c for c in allowed if isinstance(c, Options)).values))
            shown = repr(value) if not isinstance(value, np.ndarray) else f"an array of shape {value.shape}"
            raise SatmdError(f"{owner}: {name} must be " + " or ".join(_describe(c) for c in allowed)
                             + f", got {shown}")
