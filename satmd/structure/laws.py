"""The joint laws of SPEC §11, each one object: its terms in the relative displacement d and velocity v.

A joint's force is ``g(d, v) = Σ_j c_j t_j(d, v)`` plus a linear part (``d``, ``v``) that every law
carries: the lowest level's FRF already holds the joint linearised there, and at a higher level its
equivalent stiffness and damping move as well. A law is the set of terms ``t_j``; the coefficients are
what the data fit (`satmd.structure.locate` in the frequency domain, `satmd.structure.model` in time).

Every term is written once, in `term`: its value and its slopes in d and v, as NumPy arithmetic on
scalars or arrays, so the same lines serve the regression's columns and the compiled time integrator
(`satmd.structure.kernel`). A term's ``aux`` is its one shape constant (a clearance's gap, a friction's
smoothing velocity), a property of the joint, the same at every level.

One term has a memory: ``slip(d)``, a friction contact that sticks, then slides (a Jenkins element: a spring
k_stick in series with a Coulomb slider, smoothed as a Bouc–Wen element of exponent 2 with β = γ = ½). Its
state r ∈ (−1, 1) is the spring's share of the slip force: toward zero it moves elastically, ``dr = dd/d_slip``;
away from zero it saturates, ``dr = (1 − r²) dd/d_slip``. Its force is ``k_stick·d_slip·r``: stiff at a
reversal, at most ``k_stick·d_slip`` while it slides, so its loops hold energy at every level. `slide` steps
it exactly over a monotone stroke (the integrator's), `play` gives its periodic steady state over one
period (the regression's columns).
"""
from __future__ import annotations

import math
import threading
from dataclasses import dataclass, replace

import numpy as np

from ..errors import DataError

#: term name -> code of `term`
TERM_CODES = {"d": 0, "v": 1, "d³": 2, "d|d|": 3, "contact": 4, "sign(v)": 5, "v|v|": 6, "d²": 7, "v³": 8,
              "tanh(d)": 9, "slip(d)": 10}
#: the codes of terms with a memory (`slide`): the integrator carries their state, the columns `play` them
HYSTERETIC = (10,)
#: term name -> the name of its coefficient in a model's parameters (force per term unit)
TERM_PARAMETERS = {"d": "k", "v": "c", "d³": "k3", "d|d|": "k_soft", "contact": "k_contact", "sign(v)": "f_slip",
                   "v|v|": "c2", "d²": "k2", "v³": "c3", "tanh(d)": "k_sat", "slip(d)": "k_stick"}
#: term name -> the name of its shape constant
SHAPE_PARAMETERS = {"contact": "gap", "sign(v)": "v_slip", "tanh(d)": "d_sat", "slip(d)": "d_slip"}
FRICTION_SMOOTHING = 0.05  # a Coulomb force smoothed over 5 % of the reference velocity's RMS
#: the shape constants tried for a shaped term, in units of the reference level's RMS stroke (a gap) or relative
#: velocity (a friction's smoothing): the law's evidence is its best over them (`JointLaw.shapes`). A slip
#: smoothed over up to 3 RMS velocities of the lowest level: a friction that slips only at the top levels (on
#: chains, 8 smoothed friction joints were named 1 time in 8 with the grid stopping at 1, 4 with it at 3); beyond
#: that a smoothed slip is a cubic damping of either sign and takes quadratic damping's place
#: A saturating spring's stroke from half the lowest level's RMS stroke to 8 of them (the top level of a test
#: 20 dB wide): beyond that it is a cubic at every level measured.
#: A stick-slip contact's stick stroke from 2 % of the lowest level's RMS stroke (sliding at every level, nearly
#: Coulomb) to 8 of them (sticking up to the top level).
SHAPE_GRID = {"contact": (0.5, 1.0, 2.0, 3.0), "sign(v)": (FRICTION_SMOOTHING, 0.2, 0.5, 1.0, 2.0, 3.0),
              "tanh(d)": (0.5, 1.0, 2.0, 4.0, 8.0), "slip(d)": (0.02, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0)}
#: how far r may come to ±1 (its arctanh stays finite)
EDGE = 1.0 - 1e-12


def term(code, d, v, aux):
    """(value, ∂/∂d, ∂/∂v) of term ``code`` (`TERM_CODES`) at (d, v); ``aux`` its shape constant. A term with a
    memory (`HYSTERETIC`) is not a function of (d, v): `slide` and `play` give it."""
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


def slide(r0, u):
    """(r, dr/du): a stick-slip contact's state after a monotone stroke of ``u`` stick strokes (d_slip) from ``r0``,
    exact: elastic toward zero, ``tanh`` away from it (the module docstring)."""
    if r0 * u < 0.0:  # toward zero: the spring unloads elastically
        r = r0 + u
        if r * r0 >= 0.0:
            return r, 1.0
        r0, u = 0.0, r  # past zero: the rest of the stroke loads it the other way
    r = math.tanh(math.atanh(min(max(r0, -EDGE), EDGE)) + u)
    return r, 1.0 - r * r


def sweep(r0, d, width):
    """The state over one period of strokes ``d`` from ``r0``, the state at the period's last sample."""
    r = np.empty(d.size)
    x, prev = r0, d[-1]
    for k in range(d.size):
        x = slide(x, (d[k] - prev) / width)[0]
        r[k] = x
        prev = d[k]
    return r


def play(d, width):
    """(N,) the state of a stick-slip contact over one period of its periodic stroke ``d`` (the steady state: the
    state the period starts from is the one it ends at, found by secant steps; the map is a contraction)."""
    x0 = 0.0
    f0 = sweep(x0, d, width)[-1] - x0
    x1 = x0 + f0
    r = sweep(x1, d, width)
    for _ in range(50):
        f1 = r[-1] - x1
        if abs(f1) <= 1e-13:
            break
        x2 = x1 - f1 * (x1 - x0) / (f1 - f0) if f1 != f0 else x1 + f1
        x2 = min(max(x2, -EDGE), EDGE)
        x0, f0, x1 = x1, f1, x2
        r = sweep(x1, d, width)
    return r


def periodic_value(code, d, v, aux):
    """A term's value over one period of a periodic motion (d, v): the steady state `play` of a term with a memory."""
    if code in HYSTERETIC:
        return aux * play_compiled()(np.ascontiguousarray(d, float), float(aux))
    return term(code, d, v, aux)[0]


_PLAY: dict = {}
COMPILING = threading.RLock()  # fits run side by side: one thread compiles (`slide` once), the others wait


def play_compiled():
    """`play`, compiled with numba where it is there (its pure-Python loop is ~100x slower)."""
    with COMPILING:
        return _compile_play()


def _compile_play():
    if "play" not in _PLAY:
        _PLAY["play"] = play
        try:
            import numba
        except ImportError:  # pragma: no cover - exercised where numba is absent
            pass
        else:
            compile_slide(numba)
            from .. import _compiled

            global sweep
            sweep = _compiled.njit_cached(numba, sweep, [__file__])  # play calls it by this name
            _PLAY["play"] = _compiled.njit_cached(numba, play, [__file__])
    return _PLAY["play"]


def compile_slide(numba):
    """Make `slide` the numba-compiled function of the same text (its callers, compiled, call it by this name)."""
    global slide
    if not hasattr(slide, "py_func"):
        slide = numba.njit(cache=True, fastmath=False)(slide)


@dataclass(frozen=True)
class JointLaw:
    """A joint law: ``name`` (SPEC §11), its ``term_names`` (keys of `TERM_CODES`) and its description.

    The linear terms ``d`` and ``v`` are added to every law (`all_terms`). ``aux(name, d0, v0)`` gives each
    term's shape constant from the reference level's RMS stroke ``d0`` and relative velocity ``v0``.
    ``forms``: the other sets of terms the law may take (a friction: a stick-slip contact with a memory, or a
    memoryless Coulomb force smoothed in the velocity), each tried as its shapes are (`variants`)."""

    name: str
    term_names: tuple
    description: str
    forms: tuple = ()

    def variants(self) -> list:
        """The law in each of its forms (itself first)."""
        return [self] + [replace(self, term_names=tuple(f), forms=()) for f in self.forms]

    def form(self, term_names) -> "JointLaw":
        """The law in the form with these terms (the law's own, without the linear d and v; none: the first form)."""
        if not term_names:
            return self
        for v in self.variants():
            if v.term_names == tuple(term_names):
                return v
        raise DataError(f"the {self.name} law has no form with the terms {', '.join(term_names)} (its forms: "
                        + "; ".join(", ".join(v.term_names) for v in self.variants()) + ")")

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
        if term_name in ("contact", "tanh(d)", "slip(d)"):
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
        return [np.asarray(periodic_value(TERM_CODES[t], d, v, a), float) for t, a in zip(self.all_terms, aux)]

    def force(self, coefficients, d, v, aux) -> np.ndarray:
        """Σ c_j t_j(d, v) over one period of a periodic motion, for coefficients and shape constants in the order
        of `all_terms`."""
        d, v = np.asarray(d, float), np.asarray(v, float)
        return sum(c * periodic_value(TERM_CODES[t], d, v, a) for c, t, a in zip(coefficients, self.all_terms, aux))

    def formula(self, coefficients, aux) -> str:
        """The force written out, e.g. ``-3.1e+04·d + 2.2·v - 41·tanh(v/0.0012)``."""
        parts = []
        for c, t, a in zip(coefficients, self.all_terms, aux):
            text = {"contact": f"(|d|>{a:.3g})·(d∓{a:.3g})", "sign(v)": f"tanh(v/{a:.3g})",
                    "tanh(d)": f"{a:.3g}·tanh(d/{a:.3g})", "slip(d)": f"{a:.3g}·slip(d/{a:.3g})"}.get(t, t)
            parts.append(f"{c:+.3g}·{text}")
        return " ".join(parts).lstrip("+")


LAWS = {law_.name: law_ for law_ in (
    JointLaw("cubic", ("d³",), "a cubic spring k3·d³ (hardening or softening by its sign)"),
    JointLaw("softening", ("tanh(d)",), "a saturating spring: stiff at small strokes, its force levelling off beyond "
             "a stroke d_sat (k_sat·d_sat·tanh(d/d_sat))"),
    JointLaw("clearance", ("contact",), "a gap that closes: stiffer beyond ±gap"),
    JointLaw("friction", ("slip(d)",), "stick-slip: a contact that sticks, then slides at a Coulomb force "
             "(a Jenkins element, k_stick up to a slip force k_stick·d_slip; or a Coulomb force opposing the "
             "relative velocity, smoothed over v_slip)", forms=(("sign(v)",),)),
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
