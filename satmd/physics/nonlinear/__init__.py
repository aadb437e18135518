"""Nonlinear elements (SPEC §8b) and the one time-domain integrator that drives them.

Elements
--------
One class per element, each an `Effect` subclass (`NonlinearElement`) with
declared `Parameter`s (unit, default, neutral, hard/search ranges, starts)::

    name                    parameters     acts on    reads   moves (equivalent linear)
    cubic_absorber_spring   k3 [N/m³]      absorber   d       kp (up if k3 > 0)
    cubic_host_spring       k3 [N/m³]      host       u1      k1 (up if k3 > 0)
    absorber_friction       Fc [N], v0     absorber   v       cp (down with level)
    quadratic_damping       c2 [N·s²/m²]   absorber   v       cp (up with level)
    inductor_saturation     isat [A]       shunt      i       L  (down with level)

Build one with ``element("cubic_absorber_spring", k3=2e9)`` (or the class);
``NONLINEAR`` maps names to classes, ``nonlinear_names()`` lists them,
``register_nonlinear`` adds one (a class with its ``law``: nothing else is edited;
see ``tests/discovery/test_new_element.py``), ``unregister_nonlinear`` removes it. They are *not* in the linear vocabulary
(`satmd.physics.effects.VOCABULARY`): discovery never fits them as linear effects.

Interface of an element ``el`` (stable; see `NonlinearElement`):

- ``el.params``, ``el.parameter_names``, ``el.parameter_specs``, ``el.replace(**kw)``,
  ``el.bounds(rig)``, ``el.starts(rig)``, ``el.to_dict()`` as for linear effects;
- ``el.acts`` (``absorber``/``host``/``shunt``), ``el.reads`` (signals from
  ``d, v, u1, v1, i``), ``el.linear_parameter`` (``kp``/``k1``/``cp``/``L``),
  ``el.strength`` (the parameter that sets its size);
- ``el.law(p0, p1, y) -> (force, slope)`` with ``el.kernel_parameters()``: the force law
  beyond the linear model, once (NumPy functions: arrays and the compiled integrator);
  ``el.force(y, rig)``, ``el.slope(y, rig)`` apply it to readings;
- ``el.moves``: which way ``linear_parameter`` moves with level (``up``/``down``/``either``);
  ``el.coordinates(rig, rms)``: how a fit moves its parameters;
- ``el.equivalent_linear(rig, rms) -> EquivalentLinear`` (``.parameter``, ``.nominal``,
  ``.value``, ``.direction`` "up"/"down", ``.relative_change``) for Gaussian
  signals with the given RMS ({"d": ..} etc.);
- ``el.explain(rig)``: the element in words.

Levels: ``equivalent_rig(rig, elements, band_hz, force_rms)`` iterates the
statistical linearisation to its fixed point for a band-limited white force and
returns the equivalent linear rig with the signals' RMS (`linearise`).

Integrator: ``integrate(rig, force, fs_hz, elements)`` (`integrate.py`): states
u1, u2, q and their rates plus the element forces, driven by a sampled force,
exact for the linear part (first-order-hold state transition), implicit
trapezoidal-in-input for the element forces; outputs a1, a2 and states.
"""
from __future__ import annotations

from ...errors import DataError, DataTypeError
from ...validation import validate_params
from .base import ACTS, READS, EquivalentLinear, NonlinearElement, gaussian_mean
from .elements import (
    ELEMENT_CLASSES,
    AbsorberFriction,
    CubicAbsorberSpring,
    CubicHostSpring,
    InductorSaturation,
    QuadraticDamping,
)

NONLINEAR_UNEXPLAINED = "nonlinear_unexplained"  # a finding, not an element: distortion no element explains
NONLINEAR: dict[str, type[NonlinearElement]] = {}


@validate_params({"cls": [type]}, error=DataTypeError)
def register_nonlinear(cls: type[NonlinearElement]) -> type[NonlinearElement]:
    """Add a nonlinear element class to the registry (usable as a class decorator).

    Parameters
    ----------
    cls : a `NonlinearElement` subclass with a new ``name``.

    Returns
    -------
    type
        ``cls`` itself.
    """
    if not (isinstance(cls, type) and issubclass(cls, NonlinearElement)):
        raise TypeError(f"register_nonlinear expects a NonlinearElement subclass, got {cls!r}")
    if not cls.name or cls.name in NONLINEAR or cls.acts not in ACTS or not set(cls.reads) <= set(READS):
        raise DataError(f"nonlinear element {cls.name!r}: empty or taken name, or bad acts/reads")
    NONLINEAR[cls.name] = cls
    return cls


def unregister_nonlinear(name: str) -> None:
    """Remove an element added with `register_nonlinear`.

    Parameters
    ----------
    name : its registered name.

    Returns
    -------
    None
    """
    if name not in NONLINEAR:
        raise DataError(f"no nonlinear element {name!r} is registered")
    NONLINEAR.pop(name)


def nonlinear_names() -> tuple[str, ...]:
    """Names of the registered nonlinear elements, in registration order.

    Returns
    -------
    tuple of str
    """
    return tuple(NONLINEAR)


@validate_params({"name": [str]}, error=DataTypeError)
def element(name: str, **parameters) -> NonlinearElement:
    """Build a nonlinear element by its SPEC §8b name, e.g. ``element("quadratic_damping", c2=300)``.

    Parameters
    ----------
    name : a name from `nonlinear_names`.
    **parameters : values of its parameters (defaults fill the rest).

    Returns
    -------
    NonlinearElement
    """
    cls = NONLINEAR.get(name)
    if cls is None:
        raise DataError(f"unknown nonlinear element {name!r}; known: {', '.join(NONLINEAR)}")
    return cls(**parameters)


for _cls in ELEMENT_CLASSES:
    register_nonlinear(_cls)

from .linearise import equivalent_rig, response_rms  # noqa: E402
from .integrate import NonlinearResponse, integrate  # noqa: E402

__all__ = [
    "NonlinearElement", "EquivalentLinear", "CubicAbsorberSpring", "CubicHostSpring", "AbsorberFriction",
    "QuadraticDamping", "InductorSaturation", "NONLINEAR", "NONLINEAR_UNEXPLAINED", "register_nonlinear", "unregister_nonlinear",
    "nonlinear_names", "element", "gaussian_mean", "equivalent_rig", "response_rms", "integrate",
    "NonlinearResponse",
]
