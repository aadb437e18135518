"""The joint laws of SPEC §11, each one object: its terms in the relative displacement d and velocity v.

A joint's force is ``g(d, v) = Σ_j c_j t_j(d, v)`` plus a linear part (``d``, ``v``) that every law
carries: the lowest level's FRF already holds the joint linearised there, and at a higher level its
equivalent stiffness and damping move as well. A law is the set of terms ``t_j``; the coefficients are
what the data fit (`satmd.structure.locate`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import DataError


def _friction(d, v, d0, v0):
    return [np.tanh(v / (0.05 * v0))]  # a Coulomb force, smoothed over 5 % of the reference velocity's RMS


def _clearance(d, v, d0, v0):
    gap = d0  # contact beyond the reference level's RMS stroke: stiffer outside ±gap
    return [np.where(np.abs(d) > gap, d - np.sign(d) * gap, 0.0)]


@dataclass(frozen=True)
class JointLaw:
    """A joint law: ``name`` (SPEC §11), its ``terms(d, v, d0, v0) -> [array, ...]`` and their ``term_names``.

    ``d0`` and ``v0`` are the RMS stroke and relative velocity at the reference (lowest) level: a law's
    smoothing or gap is a property of the joint, the same at every level, so it is set from one level."""

    name: str
    terms: Callable
    term_names: tuple
    description: str

    def columns(self, d, v, d0: float, v0: float) -> list:
        """The law's terms, then the linear part every law carries (d, v)."""
        return [np.asarray(t, float) for t in self.terms(d, v, d0, v0)] + [d, v]


LAWS = {law_.name: law_ for law_ in (
    JointLaw("cubic", lambda d, v, d0, v0: [d ** 3], ("d³",), "a cubic spring k3·d³ (hardening or softening by its sign)"),
    JointLaw("softening", lambda d, v, d0, v0: [d * np.abs(d)], ("d|d|",),
             "a spring whose stiffness changes with the stroke, d|d| (softening when negative)"),
    JointLaw("clearance", _clearance, ("contact",), "a gap that closes: stiffer beyond ±gap"),
    JointLaw("friction", _friction, ("sign(v)",), "stick-slip: a Coulomb force opposing the relative velocity"),
    JointLaw("quadratic_damping", lambda d, v, d0, v0: [v * np.abs(v)], ("v|v|",), "damping that grows with speed, v|v|"),
    JointLaw("sparse", lambda d, v, d0, v0: [d ** 2, d ** 3, d * np.abs(d), v * np.abs(v), v ** 3, *_friction(d, v, d0, v0)],
             ("d²", "d³", "d|d|", "v|v|", "v³", "sign(v)"),
             "a law found over a library of d and v terms (none of the named laws explains the data alone)"),
)}


def law(name: str) -> JointLaw:
    """The law called ``name``.

    Parameters
    ----------
    name : one of `LAWS` (SPEC §11)

    Returns
    -------
    JointLaw
    """
    try:
        return LAWS[name]
    except KeyError:
        raise DataError(f"unknown joint law {name!r} (known: {', '.join(LAWS)})") from None
