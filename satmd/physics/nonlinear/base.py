"""The NonlinearElement base class and its equivalent-linear result.

A nonlinear element is the same kind of object as a linear effect (it *is* an
`Effect`: declared `Parameter`s, ``params``, ``replace``, ``bounds``, ``starts``,
``explain``), with three more things:

- where it acts and what it reads (``acts``, ``reads``), which the one
  time-domain integrator turns into an input column and output rows;
- its force law, ``force(y, rig)``: the part of the element's force beyond the
  linear model of SPEC §2 (the linear part, e.g. ``kp d``, stays in the model);
- its statistical (Gaussian) equivalent linearisation, ``equivalent_linear(rig,
  rms)``: the linear parameter it moves at a level and which way.

Its linear hooks are all identity: in a FRF the element is absent (its
small-signal limit), which is what the linear model of a rig at low level is.
"""
from __future__ import annotations

from ...conventions import TINY

from dataclasses import asdict, dataclass
from typing import Any, ClassVar, cast

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


class NonlinearElement(Effect):
    """Base class of the SPEC §8b elements (see the module docstring).

    Subclasses declare ``name``, ``parameter_specs``, ``description``, ``acts``
    (``absorber``: equal and opposite on u1 and u2, positive on u2; ``host``: on
    u1; ``shunt``: the shunt current), ``reads`` (a tuple from ``d = u2 - u1``,
    ``v = d'``, ``u1``, ``v1``, ``i``; one signal, so that the integrator's Newton
    step is scalar), ``linear_parameter`` and implement ``force``, ``slope`` and
    ``equivalent_value``.
    """

    acts_on: ClassVar[str] = "nonlinear"
    acts: ClassVar[str] = ""
    reads: ClassVar[tuple[str, ...]] = ()
    linear_parameter: ClassVar[str] = ""
    strength: ClassVar[str] = ""  # the parameter that sets the element's size (k3, Fc, c2, isat)
    kernel_law: ClassVar[int | None] = None  # the compiled integrator's form of `force` (see `kernel`)

    def kernel_parameters(self) -> tuple:
        """(p0, p1) of ``kernel_law`` (the compiled integrator's form of `force`).

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
        raise NotImplementedError

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
        raise NotImplementedError

    def equivalent_value(self, rig, rms: dict):
        """Equivalent value of ``linear_parameter`` when the read signals have RMS ``rms``.

        Parameters
        ----------
        rig : Rig.
        rms : {signal: RMS} for the signals in ``reads`` (zero-mean Gaussian assumed).

        Returns
        -------
        float or ndarray
        """
        raise NotImplementedError

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
