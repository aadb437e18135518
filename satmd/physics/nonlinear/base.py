"""The NonlinearElement base class and its equivalent-linear result.

A nonlinear element is the same kind of object as a linear effect (it *is* an
`Effect`: declared `Parameter`s, ``params``, ``replace``, ``bounds``, ``starts``,
``explain``), and it carries everything else about itself, so that every consumer
(integrator, discovery, fit, tuning) is generic:

- where it acts and what it reads (``acts``, ``reads``), which the one
  time-domain integrator turns into an input column and output rows;
- its force law, once: ``law(p0, p1, y) -> (force, slope)``, written with NumPy
  functions so that the same code runs on arrays (``force``, ``slope``) and is
  compiled for the integrator's sequential pass (`kernel`); ``kernel_parameters()``
  gives (p0, p1). The force is the part beyond the linear model of SPEC §2 (the
  linear part, e.g. ``kp d``, stays in the model);
- its statistical (Gaussian) equivalent linearisation, ``equivalent_linear(rig,
  rms)`` (numerical by default: nominal + E[slope], Stein's lemma): the linear
  parameter it moves (``linear_parameter``) and which way with level (``moves``);
- how a fit moves its parameters (``coordinates(rig, rms)``: scale, bounds, starts).

Its linear hooks are all identity: in a FRF the element is absent (its
small-signal limit), which is what the linear model of a rig at low level is.
"""
from __future__ import annotations

from ...conventions import TINY

import itertools
import math
from dataclasses import asdict, dataclass
from typing import Any, Callable, ClassVar, cast

import numpy as np

from ..effects.base import Effect

# what an element can read (the integrator's signals) and where it can act
READS = ("d", "v", "u1", "v1", "i")
ACTS = ("absorber", "host", "shunt")
LINEAR_TARGETS = ("kp", "k1", "cp", "L")

# Gauss-Hermite (probabilists') nodes and weights for E[f(X)], X ~ N(0, 1)
_GH_X, _GH_W = np.polynomial.hermite_e.hermegauss(80)
_GH_W = _GH_W / _GH_W.sum()


def gaussian_mean(fun, sigma, width=None):
    """E[fun(X)] for X ~ N(0, sigma²) (sigma may be an array).

    Smooth laws: 80-point Gauss-Hermite quadrature. A law with a feature of ``width``
    near 0 (friction's tanh(v / v0)): trapezoid on a grid that resolves both sigma and width.

    Parameters
    ----------
    fun : callable, vectorised over its argument.
    sigma : standard deviation(s) of X.
    width : size of the law's sharpest feature around 0 (None: smooth).

    Returns
    -------
    ndarray or float
        The expectation, with sigma's shape.
    """
    s = np.asarray(sigma, float)
    if width is None:
        return np.sum(_GH_W * fun(s[..., None] * _GH_X), axis=-1)
    from scipy.integrate import quad

    out = np.empty(s.shape)
    for idx, sv in np.ndenumerate(s):
        sv, w = max(float(sv), TINY), float(width)
        dens = lambda v: np.exp(-0.5 * (v / sv) ** 2) / (sv * np.sqrt(2 * np.pi)) * fun(v)  # noqa: E731
        total = 0.0
        for lo, hi in ((-9 * sv, 0.0), (0.0, 9 * sv)):
            brk = [p for p in (-5 * w, -w, w, 5 * w) if lo < p < hi]
            total += quad(dens, lo, hi, points=brk or None, limit=200, epsabs=0.0, epsrel=1e-11)[0]
        out[idx] = total
    return out if out.ndim else float(out)


@dataclass(frozen=True)
class EquivalentLinear:
    """The linear parameter an element moves at a level (Gaussian statistical linearisation).

    Parameters
    ----------
    element : the element's name.
    parameter : the linear rig parameter it moves: ``kp``, ``k1``, ``cp`` or ``L``.
    nominal : that parameter's value in the linear rig (the small-signal value).
    value : its equivalent value at this level (float, or an array for a batch of levels).
    rms : RMS of the signal the element reads at this level ({signal: value}).
    """

    element: str
    parameter: str
    nominal: float
    value: Any  # a float or an array over levels
    rms: dict

    @property
    def direction(self) -> str:
        """``"up"``, ``"down"`` or ``"none"``: which way the equivalent value moves from nominal."""
        delta = float(np.mean(np.asarray(self.value, float) - self.nominal))
        return "up" if delta > 0 else "down" if delta < 0 else "none"

    @property
    def relative_change(self) -> np.ndarray:
        """(value - nominal) / nominal."""
        return (np.asarray(self.value, float) - self.nominal) / self.nominal

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        out = asdict(self)
        out["value"] = np.asarray(self.value, float).tolist()
        out["rms"] = {k: np.asarray(v, float).tolist() for k, v in self.rms.items()}
        out["direction"] = self.direction
        return out

    def report(self) -> str:
        """One line of text."""
        rel = 100 * float(np.mean(self.relative_change))
        return f"{self.element}: {self.parameter} {self.nominal:.4g} -> {float(np.mean(self.value)):.4g} ({rel:+.1f} %)"


@dataclass(frozen=True)
class Coordinate:
    """How a fit moves one of an element's parameters: in units of ``scale`` where it matters.

    ``kind``: ``linear`` (x = value / scale, either sign), ``positive`` (the same, value = max(x, 0) scale)
    or ``log`` (x = log(value / scale)). ``bounds`` and ``starts`` are in x.
    """

    name: str
    scale: float
    kind: str
    bounds: tuple
    starts: tuple

    def encode(self, value) -> float:
        """x of a parameter value."""
        v = float(value) / self.scale
        return math.log(v) if self.kind == "log" else v

    def decode(self, x):
        """Parameter value(s) of x (array-friendly)."""
        if self.kind == "log":
            return np.exp(x) * self.scale
        return (np.maximum(x, 0.0) if self.kind == "positive" else x) * self.scale


SIGNED_STARTS = (-2.0, -1.0, -0.3, 0.0, 0.3, 1.0, 2.0, 4.0)  # strength in units of its reference effect
POSITIVE_STARTS = (0.0, 0.3, 1.0, 2.0, 4.0, 8.0)


class NonlinearElement(Effect):
    """Base class of the SPEC §8b elements (see the module docstring).

    Subclasses declare ``name``, ``parameter_specs``, ``description``, ``acts``
    (``absorber``: equal and opposite on u1 and u2, positive on u2; ``host``: on
    u1; ``shunt``: the shunt current), ``reads`` (a tuple from ``d = u2 - u1``,
    ``v = d'``, ``u1``, ``v1``, ``i``; one signal, so that the integrator's Newton
    step is scalar), ``linear_parameter``, ``strength``, ``moves`` and ``law``, and
    implement ``kernel_parameters``. Closed forms of ``equivalent_value`` and
    ``strength_scale`` are optional (the defaults are numerical).
    """

    acts_on: ClassVar[str] = "nonlinear"
    acts: ClassVar[str] = ""
    reads: ClassVar[tuple[str, ...]] = ()
    linear_parameter: ClassVar[str] = ""
    strength: ClassVar[str] = ""  # the parameter that sets the element's size (k3, Fc, c2, isat)
    moves: ClassVar[str] = ""  # which way linear_parameter moves with level: "up", "down", "either" (sign of strength)
    law: ClassVar[Callable]  # staticmethod (p0, p1, y) -> (force, slope), NumPy functions only (see the module)
    law_width: ClassVar[float | None] = None  # a feature of the law narrower than the signal (quadrature hint)
    regressor: ClassVar[str] = ""  # the distortion test's regressor that stands for it ("d:cube", "v:sign", ...)

    def kernel_parameters(self) -> tuple:
        """(p0, p1) of ``law`` for this element's parameter values.

        Returns
        -------
        tuple
        """
        raise NotImplementedError

    def force(self, y: dict, rig):
        """The element's force beyond the linear model, for readings ``y`` ({signal: array}).

        Parameters
        ----------
        y : dict of arrays, one per name in ``reads`` (broadcasting with the parameters).
        rig : Rig the element sits in.

        Returns
        -------
        ndarray
            For ``absorber``/``host``: a restoring force [N] (added to the left side of
            the equation of motion, positive on u2 for the absorber); for ``shunt``:
            the true current minus the small-signal current [A].
        """
        p0, p1 = self.kernel_parameters()
        return type(self).law(p0, p1, y[self.reads[0]])[0]

    def slope(self, y: dict, rig):
        """Derivative of `force` with respect to the (single) signal the element reads.

        Parameters
        ----------
        y : dict of arrays, as for `force`.
        rig : Rig.

        Returns
        -------
        ndarray
            d force / d reading (used by the integrator's Newton step on the implicit force).
        """
        p0, p1 = self.kernel_parameters()
        return type(self).law(p0, p1, y[self.reads[0]])[1]

    def equivalent_value(self, rig, rms: dict):
        """Equivalent value of ``linear_parameter`` when the read signals have RMS ``rms``.

        Parameters
        ----------
        rig : Rig.
        rms : {signal: RMS} for the signals in ``reads`` (zero-mean Gaussian assumed).

        Returns
        -------
        float or ndarray
            By default nominal + E[slope(x)], x ~ N(0, rms²): E[f(x) x] / E[x²] by Stein's lemma, the
            stiffness (or damping) a linear fit sees; a shunt element must say its own.
        """
        if self.acts == "shunt":
            raise NotImplementedError(f"{self.name}: a shunt element gives its own equivalent_value")
        p0, p1 = self.kernel_parameters()
        sig = self.reads[0]
        law = type(self).law
        mean = gaussian_mean(lambda x: law(p0, p1, x)[1], np.asarray(rms[sig], float), width=self.law_width)
        return getattr(rig, self.linear_parameter) + mean

    def strength_scale(self, rig, rms: dict) -> float:
        """The strength that moves ``linear_parameter`` by a tenth of its value at these RMS (a fit's unit).

        Numerical by default (the equivalent value is taken as proportional to the strength, as it is for
        every force law linear in its strength).

        Parameters
        ----------
        rig : Rig.
        rms : {signal: RMS} of the read signals.

        Returns
        -------
        float
        """
        spec = next(p for p in self.parameter_specs if p.name == self.strength)
        probe = float(max(abs(s) for s in spec.starts) if spec.starts else 1.0)
        nominal = float(getattr(rig, self.linear_parameter))
        moved = float(np.mean(self.replace(**{self.strength: probe}).equivalent_value(rig, rms))) - nominal
        return probe * 0.1 * abs(nominal) / abs(moved) if moved else probe

    def coordinates(self, rig, rms: dict) -> tuple:
        """How a fit moves this element's parameters at a level with these RMS (one `Coordinate` each).

        The strength in units of `strength_scale` (either sign where its hard range allows, else
        positive), the others on a log scale about their present values.

        Parameters
        ----------
        rig : Rig.
        rms : {signal: RMS} of the read signals (e.g. at the highest level).

        Returns
        -------
        tuple of Coordinate
        """
        out = []
        for spec in self.parameter_specs:
            if spec.name == self.strength:
                scale = self.strength_scale(rig, rms)
                if spec.hard[0] < 0:
                    out.append(Coordinate(spec.name, scale, "linear", (-20.0, 20.0), SIGNED_STARTS))
                else:
                    out.append(Coordinate(spec.name, scale, "positive", (0.0, 200.0), POSITIVE_STARTS))
            else:
                value = float(np.mean(self.params[spec.name]))
                lo, hi = (max(float(b), TINY) for b in (spec.search or spec.hard))
                out.append(Coordinate(spec.name, value, "log", (math.log(lo / value), math.log(hi / value)), (0.0,)))
        return tuple(out)

    def coordinate_starts(self, rig, rms: dict, coordinates=None) -> list:
        """Every combination of the coordinates' starts (a fit's scan), in x.

        Parameters
        ----------
        rig, rms : as `coordinates`.
        coordinates : the coordinates already made (else made from rig and rms).

        Returns
        -------
        list of lists
        """
        coords = coordinates if coordinates is not None else self.coordinates(rig, rms)
        return [list(x) for x in itertools.product(*(c.starts for c in coords))]

    def trend_fixed(self, rms_levels: list) -> dict:
        """Parameters held fixed when only the equivalent values' trend with level is known (none by default).

        Parameters
        ----------
        rms_levels : the read signals' RMS at each level ({signal: RMS} each).

        Returns
        -------
        dict
        """
        return {}

    def equivalent_linear(self, rig, rms: dict) -> EquivalentLinear:
        """The linear parameter this element moves at a level, its value, and which way.

        Parameters
        ----------
        rig : Rig (its value of ``linear_parameter`` is the nominal).
        rms : {signal: RMS} of the read signals at the level.

        Returns
        -------
        EquivalentLinear
        """
        nominal = float(getattr(rig, self.linear_parameter))
        value = self.equivalent_value(rig, rms)
        return EquivalentLinear(self.name, self.linear_parameter, nominal, value,
                                {k: rms[k] for k in self.reads if k in rms})

    def linear_limit(self) -> "NonlinearElement":
        """The element at its neutral values (no force beyond the linear model), where there is one."""
        return cast("NonlinearElement", self.replace(**{k: v for k, v in self.neutral.items()}))

    def to_dict(self) -> dict:
        """JSON-ready dict: name and parameter values."""
        return {"name": self.name, "parameters": {k: float(np.mean(v)) for k, v in self.params.items()}}
