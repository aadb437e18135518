"""The Effect base class and the declarations every effect is made of.

An effect declares its parameters as data (`Parameter`: name, unit, default,
neutral value, admissible and search ranges, search starts), the way
scikit-learn kernels declare their ``Hyperparameter``s, and may declare how
discovery should scan it (`MatchedFilter`). It changes the model through one
or more hooks (identity by default):

- ``rig(rig)``                       -> a rig with a fixed parameter replaced
- ``host(omega, rig, K1)``           -> the primary (host) dynamic stiffness Z11 - kp - iω cp
- ``capacitance(omega, rig, Cp)``    -> the piezo capacitance, wherever Cp appears
- ``branch(omega, rig, Kp)``         -> the piezo's mechanical branch kp + iω cp, wherever kp appears
- ``shunt(omega, rig, Zs)``          -> the shunt impedance
- ``sensor(omega, channel, factor)`` -> the factor the sensor applies to a1 or a2

and says in words what a fitted instance means (``explain(rig)``). Hooks use
only arithmetic (and ``dual.exp``), so the same code serves NumPy, torch and
the forward-mode duals behind the analytic Jacobian.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ...errors import DataError

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Parameter:
    """One parameter of an effect, declared as data.

    Parameters
    ----------
    name : parameter name, e.g. ``"tau_s"``.
    unit : SI unit, for reports.
    default : value used when the parameter is not given (None: it must be given).
    neutral : value at which the effect vanishes (None: there is none, e.g. a frequency).
    hard : physically admissible range; values outside are refused.
    search : range used when the parameter is fitted (None: the hard range).
    starts : values discovery starts a fit from (all parameters' starts form a grid).
    """

    name: str
    unit: str = ""
    default: float | None = None
    neutral: float | None = None
    hard: tuple = (-math.inf, math.inf)
    search: tuple | None = None
    starts: tuple = ()

    @property
    def placeholder(self) -> float:
        """A harmless value to hold until a fit sets it: neutral, else default, else mid search range."""
        if self.neutral is not None:
            return self.neutral
        if self.default is not None:
            return self.default
        lo, hi = self.search or self.hard
        return math.sqrt(lo * hi) if lo > 0 else 0.5 * (lo + hi)


@dataclass(frozen=True)
class MatchedFilter:
    """How discovery scans an effect with a location (a mode's frequency, say).

    Near its neutral value the ``amplitude`` parameter enters the model
    linearly, so for every ``location`` on a geometric grid over the measured
    band (relative ``step``) and every combination of ``shapes`` values, the
    best amplitude and the χ² it removes follow in closed form from one batched
    Jacobian. The ``keep`` best become starts, the ``refine`` best distinct ones
    are fitted.

    Parameters
    ----------
    location : parameter scanned over the band.
    step : relative step of the location grid.
    amplitude : parameter that enters linearly at its neutral value.
    amplitude_range : clip of the closed-form amplitude.
    shapes : {parameter: values tried at every location}.
    keep : starts kept from the scan.
    refine : distinct best starts fitted by least squares.
    """

    location: str
    step: float
    amplitude: str
    amplitude_range: tuple
    shapes: dict = field(default_factory=dict)
    keep: int = 40
    refine: int = 3


def scaled(factor, x):
    """``factor * x``, or ``x`` itself when there is no factor (None): a hook's optional scaling."""
    return x if factor is None else factor * x


class Effect:
    """Base class. Subclasses declare ``name``, ``parameter_specs`` and override hooks."""

    name: ClassVar[str] = ""
    family: ClassVar[str] = ""  # for effects with variants: the shared name before ':' (parameter_offset)
    variants: ClassVar[tuple[str, ...]] = ()  # e.g. the targets of parameter_offset:<p>
    parameter_specs: ClassVar[tuple[Parameter, ...]] = ()
    description: ClassVar[str] = ""
    acts_on: ClassVar[str] = ""  # "sensor", "host", "piezo", "shunt", "rig"
    scan: ClassVar[MatchedFilter | None] = None  # a location scan for discovery; None: start grid only
    # derived from parameter_specs (see __init_subclass__)
    parameter_names: ClassVar[tuple[str, ...]] = ()
    defaults: ClassVar[dict] = {}  # values used when a parameter is not given
    neutral: ClassVar[dict] = {}  # values at which the effect vanishes

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        specs = cls.__dict__.get("parameter_specs")
        if isinstance(specs, tuple):  # a property (per-instance specs) sets these itself
            cls.parameter_names = tuple(p.name for p in specs)
            cls.defaults = {p.name: p.default for p in specs if p.default is not None}
            cls.neutral = {p.name: p.neutral for p in specs if p.neutral is not None}

    def __init__(self, **params):
        unknown = set(params) - set(self.parameter_names)
        if unknown:
            raise DataError(
                f"effect {self.name}: unknown parameter(s) {sorted(unknown)}; "
                f"expected {', '.join(self.parameter_names)}"
            )
        values = dict(self.defaults)
        values.update(params)
        missing = [p for p in self.parameter_names if p not in values]
        if missing:
            raise DataError(f"effect {self.name}: missing parameter(s) {', '.join(missing)}")
        object.__setattr__(self, "params", {p: values[p] for p in self.parameter_names})
        self._check()

    @classmethod
    def at_rest(cls, rig) -> "Effect":
        """The effect at harmless values, to put in a model before a fit sets them."""
        return cls(**{p.name: p.placeholder for p in cls.parameter_specs})

    def __setattr__(self, key, val):
        raise AttributeError("effects are immutable; use .replace(**params)")

    def __getattr__(self, key):
        params = self.__dict__.get("params", {})
        if key in params:
            return params[key]
        raise AttributeError(key)

    def __repr__(self):
        inner = ", ".join(f"{k}={_fmt(v)}" for k, v in self.params.items())
        return f"effect({self.name!r}, {inner})"

    def __eq__(self, other):
        return type(self) is type(other) and self.name == other.name and all(
            _same(self.params[k], other.params[k]) for k in self.params
        )

    __hash__ = None  # type: ignore[assignment]  # equal by value, mutable parameters: unhashable

    def replace(self, **params) -> "Effect":
        """A copy with some parameter values changed."""
        new = dict(self.params)
        new.update(params)
        return self._rebuild(new)

    def _rebuild(self, params):
        return type(self)(**params)

    def _check(self):
        """Validate parameter values (skipped for traced/dual values)."""
        for p, (lo, hi) in self.hard_bounds().items():
            v = self.params[p]
            if not isinstance(v, (int, float, np.ndarray, np.generic, list)):
                continue  # torch tensor or dual: checked by its owner
            arr = np.asarray(v, dtype=float)
            if not np.all(np.isfinite(arr)):
                raise DataError(f"effect {self.name}: {p} is not finite")
            if np.any(arr < lo) or np.any(arr > hi):
                bad = np.flatnonzero((arr.reshape(-1) < lo) | (arr.reshape(-1) > hi))
                where = f" (element {bad[0]} of {arr.size})" if arr.size > 1 else ""
                raise DataError(f"effect {self.name}: {p}={arr.reshape(-1)[bad[0]]:g}{where} outside [{lo:g}, {hi:g}]")

    def hard_bounds(self) -> dict:
        """Physically admissible range of each parameter."""
        return {p.name: p.hard for p in self.parameter_specs}

    def bounds(self, rig) -> dict:
        """Search range used when the parameter is fitted."""
        return {p.name: p.search or p.hard for p in self.parameter_specs}

    def starts(self, rig) -> list[dict]:
        """Starting values for a fit: the grid of every parameter's declared starts."""
        names = [p.name for p in self.parameter_specs]
        return [dict(zip(names, vals)) for vals in itertools.product(*(p.starts for p in self.parameter_specs))]

    def qualified(self, param: str) -> str:
        """Full parameter name used by Jacobians, e.g. 'extra_mode.f_hz'."""
        return f"{self.name}.{param}"

    def explain(self, rig) -> str:
        """The fitted effect in plain engineering words (subclasses say it better)."""
        units = {p.name: p.unit for p in self.parameter_specs}
        values = ", ".join(f"{k} = {float(v):.3g}{' ' + units[k] if units.get(k) else ''}"
                           for k, v in self.params.items())
        return f"{self.description} ({values})"

    # hooks: identity by default
    def rig(self, rig):
        return rig

    def host(self, omega, rig, K1):
        return K1

    def capacitance(self, omega, rig, Cp):
        return Cp

    def branch(self, omega, rig, Kp):
        return Kp

    def shunt(self, omega, rig, Zs):
        return Zs

    def sensor(self, omega, channel, factor):
        return factor


def _fmt(v):
    if isinstance(v, (int, float, np.generic)):
        return f"{float(v):g}"
    if isinstance(v, np.ndarray):
        return f"array{v.shape}"
    return type(v).__name__


def _same(a, b):
    try:
        return bool(np.all(np.asarray(a) == np.asarray(b)))
    except Exception:
        return a is b
