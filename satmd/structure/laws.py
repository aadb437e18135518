"""The joint laws of SPEC §11, each one object: its terms in the relative displacement d and velocity v.

A joint's force is ``g(d, v) = Σ_j c_j t_j(d, v)`` plus a linear part (``d``, ``v``) that every law
carries: the lowest level's FRF already holds the joint linearised there, and at a higher level its
equivalent stiffness and damping move as well. A law is the set of terms ``t_j``; the coefficients are
what the data fit (`satmd.structure.locate` in the frequency domain, `satmd.structure.model` in time).

Every term is written once, in `term`: its value and its slopes in d and v, as NumPy arithmetic on
scalars or arrays, so the same lines serve the regression's columns and the compiled time integrator
(`satmd.structure.kernel`). A term's ``aux`` is its one shape constant (a clearance's gap, a friction's
smoothing velocity), a property of the joint, the same at every level.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DataError

#: term name -> code of `term`
TERM_CODES = {"d": 0, "v": 1, "d³": 2, "d|d|": 3, "contact": 4, "sign(v)": 5, "v|v|": 6, "d²": 7, "v³": 8,
              "tanh(d)": 9}
#: term name -> the name of its coefficient in a model's parameters (force per term unit)
TERM_PARAMETERS = {"d": "k", "v": "c", "d³": "k3", "d|d|": "k_soft", "contact": "k_contact", "sign(v)": "f_slip",
                   "v|v|": "c2", "d²": "k2", "v³": "c3", "tanh(d)": "k_sat"}
#: term name -> the name of its shape constant
SHAPE_PARAMETERS = {"contact": "gap", "sign(v)": "v_slip", "tanh(d)": "d_sat"}
FRICTION_SMOOTHING = 0.05  # a Coulomb force smoothed over 5 % of the reference velocity's RMS
#: the shape constants tried for a shaped term, in units of the reference level's RMS stroke (a gap) or relative
#: velocity (a friction's smoothing): the law's evidence is its best over them (`JointLaw.shapes`). A slip
#: smoothed over up to 3 RMS velocities of the lowest level: a friction that slips only at the top levels (on
#: chains, 8 smoothed friction joints were named 1 time in 8 with the grid stopping at 1, 4 with it at 3); beyond
#: that a smoothed slip is a cubic damping of either sign and takes quadratic damping's place
#: A saturating spring's stroke from half the lowest level's RMS stroke to 8 of them (the top level of a test
#: 20 dB wide): beyond that it is a cubic at every level measured.
SHAPE_GRID = {"contact": (0.5, 1.0, 2.0, 3.0), "sign(v)": (FRICTION_SMOOTHING, 0.2, 0.5, 1.0, 2.0, 3.0),
              "tanh(d)": (0.5, 1.0, 2.0, 4.0, 8.0)}


def term(code, d, v, aux):
    """(value, ∂/∂d, ∂/∂v) of term ``code`` (`TERM_CODES`) at (d, v); ``aux`` its shape constant."""
    if code == 0:
        return d, 1.0 + 0.0 * d, 0.0 * d
    if code == 1:
        return v, 0.0 * v, 1.0 + 0.0 * v
    if code == 2:
        return d * d * d, 3.0 * d * d, 0.0 * d
    if code == 3:
        return d * np.abs(d), 2.0 * np.abs(d), 0.0 * d
    if code == 4:  # a gap of ±aux that closes: zero inside, the stroke beyond it outside
        beyond = 1.0 * (np.abs(d) > aux)
        return beyond * (d - np.sign(d) * aux), beyond, 0.0 * d
    if code == 5:
        t = np.tanh(v / aux)
        return t, 0.0 * v, (1.0 - t * t) / aux
    if code == 6:
        return v * np.abs(v), 0.0 * v, 2.0 * np.abs(v)
    if code == 7:
        return d * d, 2.0 * d, 0.0 * d
    if code == 8:
        return v * v * v, 0.0 * v, 3.0 * v * v
    t = np.tanh(d / aux)  # a spring that saturates: stiffness k_sat at small strokes, force k_sat·aux beyond aux
    return aux * t, 1.0 - t * t, 0.0 * d


@dataclass(frozen=True)
class JointLaw:
    """A joint law: ``name`` (SPEC §11), its ``term_names`` (keys of `TERM_CODES`) and its description.

    The linear terms ``d`` and ``v`` are added to every law (`all_terms`). ``aux(name, d0, v0)`` gives each
    term's shape constant from the reference level's RMS stroke ``d0`` and relative velocity ``v0``.
    ``units`` names each coefficient's unit (force per term unit), for the model's parameters."""

    name: str
    term_names: tuple
    description: str

    @property
    def all_terms(self) -> tuple:
        """The law's terms, then the linear part every law carries (d, v)."""
        return (*self.term_names, "d", "v")

    @property
    def codes(self) -> np.ndarray:
        return np.array([TERM_CODES[t] for t in self.all_terms], np.int64)

    @staticmethod
    def aux(term_name: str, d0: float, v0: float) -> float:
        """The shape constant of a term: the gap (the reference RMS stroke) or the friction's smoothing."""
        if term_name in ("contact", "tanh(d)"):
            return float(d0)
        if term_name == "sign(v)":
            return float(FRICTION_SMOOTHING * v0)
        return 1.0

    def auxes(self, d0: float, v0: float) -> np.ndarray:
        return np.array([self.aux(t, d0, v0) for t in self.all_terms], float)

    def shapes(self, d0: float, v0: float) -> list:
        """Every set of shape constants to try (`SHAPE_GRID`; one set for a law without a shaped term)."""
        shaped = [i for i, t in enumerate(self.all_terms) if t in SHAPE_GRID]
        if not shaped:
            return [self.auxes(d0, v0)]
        out = []
        for k in range(len(SHAPE_GRID[self.all_terms[shaped[0]]])):  # every shaped term at its k-th multiple
            aux = self.auxes(d0, v0)
            for i in shaped:
                t = self.all_terms[i]
                aux[i] = SHAPE_GRID[t][k] * (v0 if t == "sign(v)" else d0)
            out.append(aux)
        return out

    def columns(self, d, v, d0: float, v0: float, aux=None) -> list:
        """The law's terms at (d, v), then the linear part (d, v): one array each (``aux``: the shape constants,
        default `auxes`)."""
        d, v = np.asarray(d, float), np.asarray(v, float)
        aux = self.auxes(d0, v0) if aux is None else aux
        return [np.asarray(term(TERM_CODES[t], d, v, a)[0], float) for t, a in zip(self.all_terms, aux)]

    def force(self, coefficients, d, v, aux) -> np.ndarray:
        """Σ c_j t_j(d, v) for coefficients and shape constants in the order of `all_terms`."""
        d, v = np.asarray(d, float), np.asarray(v, float)
        return sum(c * term(TERM_CODES[t], d, v, a)[0] for c, t, a in zip(coefficients, self.all_terms, aux))

    def formula(self, coefficients, aux) -> str:
        """The force written out, e.g. ``-3.1e+04·d + 2.2·v - 41·tanh(v/0.0012)``."""
        parts = []
        for c, t, a in zip(coefficients, self.all_terms, aux):
            text = {"contact": f"(|d|>{a:.3g})·(d∓{a:.3g})", "sign(v)": f"tanh(v/{a:.3g})",
                    "tanh(d)": f"{a:.3g}·tanh(d/{a:.3g})"}.get(t, t)
            parts.append(f"{c:+.3g}·{text}")
        return " ".join(parts).lstrip("+")


LAWS = {law_.name: law_ for law_ in (
    JointLaw("cubic", ("d³",), "a cubic spring k3·d³ (hardening or softening by its sign)"),
    JointLaw("softening", ("tanh(d)",), "a saturating spring: stiff at small strokes, its force levelling off beyond "
             "a stroke d_sat (k_sat·d_sat·tanh(d/d_sat))"),
    JointLaw("clearance", ("contact",), "a gap that closes: stiffer beyond ±gap"),
    JointLaw("friction", ("sign(v)",), "stick-slip: a Coulomb force opposing the relative velocity"),
    JointLaw("quadratic_damping", ("v|v|",), "damping that grows with speed, v|v|"),
    JointLaw("sparse", ("d²", "d³", "d|d|", "v|v|", "v³", "sign(v)"),
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
