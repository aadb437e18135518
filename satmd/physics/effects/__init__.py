"""The missing-physics vocabulary (SPEC §8): each effect is an exact change to the model.

An effect is one class that knows everything about itself: its parameters
(declared as data, `Parameter`), how it changes the model (hooks), how
discovery should search for it (starts, or a `MatchedFilter` scan) and what a
fitted instance means in words (``explain``). Modules hold one family each:
``sensor`` (sensor_gain, time_delay), ``host`` (structural_damping,
extra_mode), ``piezo`` (dielectric_loss, shunt_capacitance), ``offset``
(parameter_offset:<p>).

Adding an effect means writing one class and registering it, here for the
vocabulary or anywhere with `register`::

    @register
    class MyEffect(Effect):
        name = "my_effect"
        parameter_specs = (Parameter("x", neutral=0.0, default=0.0, hard=(0, 1), starts=(0.01, 0.1)),)
        def host(self, omega, rig, K1): ...

`satmd.discover` then considers it with the others (`registered_names`).
"""
from __future__ import annotations

from ...errors import DataError
from .base import Effect, MatchedFilter, Parameter
from .host import ExtraMode, StructuralDamping
from .offset import OFFSET_PARAMETERS, ParameterOffset
from .piezo import DielectricLoss, ShuntCapacitance
from .sensor import SensorGain, TimeDelay

_REGISTRY: dict[str, type[Effect]] = {}  # name (family name for effects with variants) -> class
VOCABULARY: dict[str, type[Effect]] = {}  # registered effects without variants, by name


def _key(cls) -> str:
    return cls.family if cls.variants else cls.name


def register(cls: type[Effect]) -> type[Effect]:
    """Add an effect class to the vocabulary; returns it, so it works as a class decorator.

    Parameters
    ----------
    cls : an `Effect` subclass with a new ``name`` (or ``family`` and ``variants``).

    Returns
    -------
    type
        ``cls`` itself.
    """
    if not (isinstance(cls, type) and issubclass(cls, Effect)):
        raise TypeError(f"register expects an Effect subclass, got {cls!r}")
    key = _key(cls)
    if not key or ":" in key or key in _REGISTRY:
        raise DataError(f"effect name {key!r} is empty, has ':' or is already registered")
    _REGISTRY[key] = cls
    if not cls.variants:
        VOCABULARY[key] = cls
    return cls


def unregister(name: str) -> None:
    """Remove an effect added with `register` (its name, or family name for variants).

    Parameters
    ----------
    name : the registered name.

    Returns
    -------
    None
    """
    _REGISTRY.pop(name)
    VOCABULARY.pop(name, None)


def registered_names() -> tuple[str, ...]:
    """Every effect name `effect` accepts, in registration order (variants spelled out).

    Returns
    -------
    tuple of str
        e.g. ``("sensor_gain", ..., "parameter_offset:m1", ...)``.
    """
    names = []
    for key, cls in _REGISTRY.items():
        names += [f"{key}:{v}" for v in cls.variants] if cls.variants else [key]
    return tuple(names)


def _lookup(name: str) -> tuple[type[Effect], tuple]:
    """The class of an effect name and the variant arguments of its constructor."""
    key, sep, variant = name.partition(":")
    cls = _REGISTRY.get(key)
    if cls is None or (sep and not cls.variants):
        raise DataError(f"unknown effect {name!r}; known: {', '.join(registered_names())}")
    if cls.variants and not variant:
        raise DataError(f"{key} needs a target, e.g. {key}:{cls.variants[0]}")
    return cls, ((variant,) if cls.variants else ())


def effect(name: str, **parameters) -> Effect:
    """Build an effect from its SPEC §8 name, e.g. ``effect("time_delay", tau_s=1e-4)``.

    Parameters
    ----------
    name : a name from `registered_names` (``parameter_offset:<p>`` for offsets).
    **parameters : values of the effect's parameters (defaults fill the rest).

    Returns
    -------
    Effect
    """
    cls, variant = _lookup(name)
    return cls(*variant, **parameters)


def at_rest(name: str, rig) -> Effect:
    """The effect ``name`` at harmless values, to put in a model before a fit sets them.

    Parameters
    ----------
    name : a name from `registered_names`.
    rig : the rig the model starts from (offsets start at its values).

    Returns
    -------
    Effect
    """
    cls, variant = _lookup(name)
    return cls.at_rest(rig, *variant)


for _cls in (SensorGain, TimeDelay, StructuralDamping, DielectricLoss, ShuntCapacitance, ExtraMode, ParameterOffset):
    register(_cls)
VOCABULARY_NAMES = registered_names()  # the SPEC §8 vocabulary; registered_names() adds later registrations

__all__ = [
    "Effect", "Parameter", "MatchedFilter", "register", "unregister", "registered_names", "effect", "at_rest",
    "VOCABULARY", "VOCABULARY_NAMES", "OFFSET_PARAMETERS", "SensorGain", "TimeDelay", "StructuralDamping",
    "DielectricLoss", "ShuntCapacitance", "ExtraMode", "ParameterOffset",
]
