"""One vocabulary for what an argument may be, checked in one place (as scikit-learn's ``_param_validation``).

A *constraint* is a list of the forms a value may take: ``None``, a type (``bool``, ``str``, a
class), an `Options` (one of fixed strings), an `Interval` (a finite number in a range), a
`Grid` (an increasing array of frequencies), a `Band` (a frequency range ``(lo, hi)``) or a
`SequenceOf` (a list or tuple of one kind, e.g. parameter names). `validate` accepts a value that matches any form of
its list and otherwise raises one line naming the argument; `validate_params` does it for every
call of a function from a table beside its signature, so adding a validated option means adding
one keyword and one entry:

    @validate_params({"n_search": [Interval(Whole, 1, 1 << 20)], "tol": [Interval(Real, 0, 1, "both")]})
    def identify(data, n_search=4096, tol=1e-12): ...

`invalid_values` gives, for a constraint list, values that it refuses (the tests feed them to
every validated function).
"""
from __future__ import annotations

import functools
import inspect
import math
from dataclasses import dataclass
from numbers import Real
from typing import Any

import numpy as np

from .errors import DataError, DataTypeError, SatmdError


class Whole(Real):
    """Interval kind: an integer given as any real number (4096, 4096.0, np.int64(4096))."""


@dataclass(frozen=True)
class Options:
    """One of a fixed set of strings."""

    values: tuple

    def accepts(self, v) -> bool:
        """Whether ``v`` is one of the strings.

        Parameters
        ----------
        v : any value

        Returns
        -------
        bool
        """
        return isinstance(v, str) and v in self.values

    def describe(self) -> str:
        """The constraint in words.

        Returns
        -------
        str
        """
        return "one of " + ", ".join(self.values)


def _num(x) -> str:
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e16 else f"{x:g}"


@dataclass(frozen=True)
class Interval:
    """A finite number of ``kind`` (Integral, Whole or Real) in [lo, hi]; ``open`` names the open ends."""

    kind: type
    lo: float | None = None
    hi: float | None = None
    open: str = ""  # "", "lo", "hi" or "both"

    def accepts(self, v) -> bool:
        """Whether ``v`` is a finite number of the kind within the bounds.

        Parameters
        ----------
        v : any value

        Returns
        -------
        bool
        """
        kind = Real if self.kind is Whole else self.kind
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, kind):
            return False
        x: Any = v  # a number of the kind
        if not math.isfinite(x) or (self.kind is Whole and not float(x).is_integer()):
            return False
        lo_ok = self.lo is None or (x > self.lo if self.open in ("lo", "both") else x >= self.lo)
        hi_ok = self.hi is None or (x < self.hi if self.open in ("hi", "both") else x <= self.hi)
        return lo_ok and hi_ok

    def bounds_text(self) -> str:
        """The bounds alone in words: ``in [0, 1)``, ``>= 1``, ``< 5`` (empty when unbounded).

        Returns
        -------
        str
        """
        lo_open, hi_open = self.open in ("lo", "both"), self.open in ("hi", "both")
        if self.lo is not None and self.hi is not None:
            return f"in {'(' if lo_open else '['}{_num(self.lo)}, {_num(self.hi)}{')' if hi_open else ']'}"
        if self.lo is not None:
            return f">{'' if lo_open else '='} {_num(self.lo)}"
        if self.hi is not None:
            return f"<{'' if hi_open else '='} {_num(self.hi)}"
        return ""

    def describe(self) -> str:
        """The constraint in words.

        Returns
        -------
        str
        """
        what = "a number" if self.kind is Real else "an integer"
        bounds = self.bounds_text()
        return f"{what} {bounds}" if bounds else ("a finite number" if self.kind is Real else "an integer")


class Grid:
    """An increasing 1-D array of at least two finite, positive frequencies [Hz]."""

    def accepts(self, v) -> bool:
        """Whether ``v`` is such an array.

        Parameters
        ----------
        v : any value

        Returns
        -------
        bool
        """
        try:
            f = np.asarray(v, float)
        except (TypeError, ValueError):
            return False
        return f.ndim == 1 and f.size >= 2 and bool(np.all(np.isfinite(f)) and f[0] > 0 and np.all(np.diff(f) > 0))

    def describe(self) -> str:
        """The constraint in words.

        Returns
        -------
        str
        """
        return "an increasing array of at least two positive frequencies"


@dataclass(frozen=True)
class Band:
    """A frequency range ``(lo, hi)`` in Hz: two finite numbers with 0 < lo < hi (``open_ends``: either may be
    None, for "where the data say")."""

    open_ends: bool = False

    def accepts(self, v) -> bool:
        """Whether ``v`` is such a pair.

        Parameters
        ----------
        v : any value

        Returns
        -------
        bool
        """
        try:
            ends = [None if b is None and self.open_ends else float(b) for b in v] if not isinstance(v, (str, bytes)) else []
        except (TypeError, ValueError):
            return False
        lo, hi = (ends if len(ends) == 2 else [math.nan, math.nan])
        ok = [b is None or (math.isfinite(b) and b > 0) for b in (lo, hi)]
        return all(ok) and (lo is None or hi is None or lo < hi)

    def describe(self) -> str:
        """The constraint in words.

        Returns
        -------
        str
        """
        return "a band (lo, hi) in Hz with 0 < lo < hi" + (" (None: an open end)" if self.open_ends else "")


@dataclass(frozen=True)
class SequenceOf:
    """A list, tuple or 1-D array (never a bare string) whose items are all instances of ``kind``."""

    kind: type

    def accepts(self, v) -> bool:
        """Whether ``v`` is a list, tuple or 1-D array of ``kind``.

        Parameters
        ----------
        v : any value

        Returns
        -------
        bool
        """
        if isinstance(v, np.ndarray) and v.ndim != 1:
            return False
        return isinstance(v, (list, tuple, np.ndarray)) and all(isinstance(x, self.kind) for x in v)

    def describe(self) -> str:
        """The constraint in words.

        Returns
        -------
        str
        """
        return f"a list of {self.kind.__name__}"


#: A list or tuple of names (parameters, channels, effects).
NAMES = SequenceOf(str)
#: How data arguments come to be, for `check_data`'s messages.
LOAD_HINT = " (e.g. satmd.io.load_frf(path) or load_recording(path))"


def describe(c) -> str:
    """One form of a constraint in words.

    Parameters
    ----------
    c : None, a type, Options, Interval, Grid, Band or SequenceOf

    Returns
    -------
    str
    """
    if c is None:
        return "None"
    if isinstance(c, type):
        return "True or False" if c is bool else f"a {c.__name__}"
    return c.describe()


def accepts(c, v) -> bool:
    """Whether the value ``v`` matches the form ``c``.

    Parameters
    ----------
    c : None, a type, Options, Interval, Grid, Band or SequenceOf
    v : any value

    Returns
    -------
    bool
    """
    if c is None:
        return v is None
    if c is bool:  # NumPy's booleans are flags too
        return isinstance(v, (bool, np.bool_))
    if isinstance(c, type):
        return isinstance(v, c)
    return c.accepts(v)


def _shown(value) -> str:
    return repr(value) if not isinstance(value, np.ndarray) else f"an array of shape {value.shape}"


def check(name: str, value, allowed, owner: str = "", error: type = DataError):
    """Raise one ``error`` line naming ``name`` when ``value`` matches none of the ``allowed`` forms.

    Parameters
    ----------
    name : the argument's name, as the user wrote it
    value : its value
    allowed : list of forms (None, a type, `Options`, `Interval`, `Grid`, `Band`, `SequenceOf`)
    owner : the function or class named in the message (empty: none)
    error : the exception class raised (a `SatmdError`)

    Returns
    -------
    object
        ``value``, unchanged.
    """
    if any(accepts(c, value) for c in allowed):
        return value
    options = [c for c in allowed if isinstance(c, Options)]
    if options:
        raise error(f"unknown {name} {value!r}{f' for {owner}' if owner else ''}; choose from "
                    + ", ".join(options[0].values))
    raise error(f"{owner + ': ' if owner else ''}{name} must be " + " or ".join(describe(c) for c in allowed)
                + f", got {_shown(value)}")


def _kind_of(value) -> str:
    return f"str {value!r}" if isinstance(value, str) and len(value) <= 60 else type(value).__name__


def check_data(value, name: str, kinds: tuple, owner: str = "", single: bool = True, many: bool = False,
               hint: str = ""):
    """``value`` when it is one of the classes ``kinds`` (with ``single``) or a non-empty list or tuple of
    them (with ``many``); else one `DataTypeError` line naming ``name``, or the first wrong item
    ``name[i]``, what is wanted (then ``hint``, e.g. how to load it) and what was given. ``owner``: the
    function named in the message (empty: none)."""
    wanted, lead = " or ".join(k.__name__ for k in kinds), f"{owner}: " if owner else ""
    if single and isinstance(value, kinds):
        return value
    if many and isinstance(value, (list, tuple)):
        if not len(value):
            raise DataTypeError(f"{lead}{name} is empty: give at least one {wanted}")
        for i, item in enumerate(value):
            if not isinstance(item, kinds):
                raise DataTypeError(f"{lead}{name}[{i}] must be {wanted}{hint}, got {_kind_of(item)}")
        return value
    forms = f"{wanted}, or a list of them" if single and many else f"a list of {wanted}" if many else wanted
    raise DataTypeError(f"{lead}{name} must be {forms}{hint}, got {_kind_of(value)}")


def validate(params: dict, constraints: dict, owner: str = "", error: type = SatmdError) -> None:
    """Raise a one-line ``error`` for the first parameter that matches none of its constraints.

    Parameters
    ----------
    params : name -> value (a missing name is not checked)
    constraints : name -> list of allowed forms (None, a type, `Options`, `Interval`, `Grid`)
    owner : the function or class named in the message
    error : the exception class raised

    Returns
    -------
    None
    """
    for name, allowed in constraints.items():
        if name in params:
            check(name, params[name], allowed, owner, error)


def validate_params(constraints: dict, error: type = DataError):
    """Decorator: validate the named arguments of every call against ``constraints``.

    Parameters
    ----------
    constraints : name -> list of allowed forms; every name must be a parameter of the function
    error : the exception class raised (DataError by default)

    Returns
    -------
    callable
        The decorator. The decorated function keeps its signature and docstring and carries the
        table as ``parameter_constraints``.
    """
    def decorate(fn):
        sig = inspect.signature(fn)
        unknown = set(constraints) - set(sig.parameters)
        if unknown:
            raise TypeError(f"{fn.__name__} has no parameter(s) {sorted(unknown)}")

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            bound = sig.bind(*args, **kwargs)
            validate(bound.arguments, constraints, fn.__name__, error)
            return fn(*args, **kwargs)

        wrapper.parameter_constraints = constraints
        return wrapper

    return decorate


def invalid_values(allowed) -> list:
    """Values that none of the ``allowed`` forms accepts (for tests of every constraint).

    Parameters
    ----------
    allowed : list of forms (None, a type, `Options`, `Interval`, `Grid`, `Band`, `SequenceOf`)

    Returns
    -------
    list
    """
    out = [object(), float("nan"), "not-an-option"]
    for c in allowed:
        if isinstance(c, Interval):
            step = 0.5 if c.kind is Real else 1
            out += [v for v in (None if c.lo is None else c.lo - step, None if c.hi is None else c.hi + step)
                    if v is not None]
            out += [c.lo, c.hi] if c.open == "both" else [c.lo] if c.open == "lo" else [c.hi] if c.open == "hi" else []
            if c.kind is not Real:
                out.append((c.lo if c.lo is not None else 0) + 0.5)
            out.append(True)
        elif isinstance(c, Grid):
            out += [np.array([1.0]), np.array([2.0, 1.0]), np.array([0.0, 1.0])]
        elif isinstance(c, Band):
            out += [(2.0, 1.0), (0.0, 1.0), (1.0, float("inf")), (1.0, 2.0, 3.0)]
        elif isinstance(c, SequenceOf):
            out += [[object()], (None,)]
    return [v for v in out if v is not None and not any(accepts(c, v) for c in allowed)]
