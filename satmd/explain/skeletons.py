"""Small product skeletons for symbolic distillation, constants fitted by variable projection.

Genetic searches such as operon's put a free weight on every variable leaf,
so a formula they return pays three nodes (``Mul``, the weight, the symbol)
for each variable; the compact formulas a person writes, like the paper's
``1.69 + 0.02(x3 − x1 − 2.77 − 0.28 x2)[(x1 − 3.14)² + x0]``, lead every
affine form with a bare variable and reach the same accuracy with fewer
nodes. This back end enumerates that family directly:

    y ≈ c0 + c1 · F1 [· F2 [· F3]]  + Σ_k c_k · x_k

with one to three factors ``F``: an affine form ``x_i + a + Σ b_j x_j`` (its
lead variable bare), ``S`` (an affine form squared, optionally plus a bare
variable), ``exp(Σ b_j x_j)`` (written ``Π B_j^x_j``), ``1/S`` or ``1/A``, and as many linear terms
``c_k x_k`` as the node budget leaves room for (every choice of variables).
A linear term may also be a `UnitPower` ``B^x_k``, added with weight one: the same
three nodes, a curved main effect; or, with c0, a `ShiftedPower` ``(x_k + a)^m`` that
carries the level too: one node more, a main effect with its own amplitude
(`skeleton_search` tries both on its finalists). The blocks live in `skeleton_blocks`.
`skeletons` lists every skeleton whose node count (`symbolic.node_count`, the
counting rule of the module) fits the budget; `satmd.explain.varpro.fit` fits
one (variable projection: the outer constants c by linear least squares for
each value of the inner ones, the inner ones by Levenberg-Marquardt on that
projected residual, with the analytic derivatives each block declares here).
`satmd.explain.skeleton_search` searches the family with a beam.

A standalone affine factor is fitted scale-free, as ``1 + Σ w_j x_j`` (c1
absorbs the scale): its offset ``a = 1/w_lead`` may lie far outside the data
(a factor that only tilts the product, like ``(x2 − 6.5)``), where the offset
form has almost no gradient. Inside a square the offset form is kept, since
the square's centre is what the fit has to find.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np

from .skeleton_blocks import Affine, Exp, Inverse, ShiftedPower, Square, UnitPower

__all__ = ["Affine", "Exp", "Inverse", "ShiftedPower", "Square", "UnitPower", "Skeleton", "admissible", "budgeted",
           "factor_pool", "initial", "skeletons", "unit_weight"]


def unit_weight(e) -> bool:
    """A term added with weight one (no outer constant): `UnitPower`, `ShiftedPower`."""
    return getattr(e, "unit_weight", False)


@dataclass(frozen=True)
class Skeleton:
    """``c0 + c1 · Π factors + Σ c_k · E_k``: each ``E`` a variable (index), a one-variable
    block, or a unit-weight term (`UnitPower`, `ShiftedPower`: no ``c_k``). Without
    ``intercept`` there is no c0 (a `ShiftedPower` carries the level)."""

    factors: tuple
    extras: tuple = ()
    intercept: bool = True

    @property
    def nodes(self):
        extras = sum(3 if isinstance(e, int) else e.nodes if unit_weight(e) else 2 + e.nodes for e in self.extras)
        return (4 if self.intercept else 3) + sum(f.nodes for f in self.factors) + extras

    @property
    def blocks(self):
        """The blocks with inner constants, in the order of the parameter vector."""
        return [*self.factors, *(e for e in self.extras if not isinstance(e, int))]

    @property
    def n_inner(self):
        return sum(b.n_params for b in self.blocks)

    def parts(self, p):
        """The inner constants ``p`` cut into one array a block (`blocks`' order)."""
        out, k = [], 0
        for b in self.blocks:
            out.append(p[k:k + b.n_params])
            k += b.n_params
        return out

    def columns(self, p, Zt):
        """The columns multiplying c1, c2, ...; c0 multiplies ones. Unit-weight terms are in `offset`."""
        parts = iter(self.parts(p))
        product = 1.0
        for f in self.factors:
            product = product * f.value(next(parts), Zt)
        extras = [Zt[e] if isinstance(e, int) else e.value(next(parts), Zt) for e in self.extras]
        return [product] + [col for col, e in zip(extras, self.extras) if not unit_weight(e)]

    def offset(self, p, Zt):
        """The sum of the unit-weight terms (0 without any)."""
        parts = self.parts(p)[len(self.factors):]
        blocks = [e for e in self.extras if not isinstance(e, int)]
        return sum((b.value(q, Zt) for b, q in zip(blocks, parts) if unit_weight(b)), 0.0)

    def derivatives(self, p, Zt) -> list:
        """For each inner constant, ``(column, d)``: the derivative ``d`` of the `columns` entry
        ``column`` it moves (``None``: of the `offset`). A constant moves one column only."""
        parts = self.parts(p)
        nf = len(self.factors)
        values = [f.value(q, Zt) for f, q in zip(self.factors, parts[:nf])]
        out: list = []  # (column or None, derivative)
        for i, (f, q) in enumerate(zip(self.factors, parts[:nf])):
            others = 1.0
            for j, v in enumerate(values):
                if j != i:
                    others = others * v
            out += [(0, others * g) for g in f.grad(q, Zt)]
        column, blocks = 0, iter(parts[nf:])
        for e in self.extras:
            if isinstance(e, int):
                column += 1
            elif unit_weight(e):
                out += [(None, g) for g in e.grad(next(blocks), Zt)]
            else:
                column += 1
                out += [(column, g) for g in e.grad(next(blocks), Zt)]
        return out

    def text(self, p, c):
        parts = iter(self.parts(p))
        scale, texts = 1.0, []
        for f in self.factors:
            s, t = f.text(next(parts))
            scale, texts = scale * s, texts + [t]
        out = (f"({c[0]:.10g}) + " if self.intercept else "") + f"({c[1] * scale:.10g})*" + "*".join(texts)
        coefs = iter(c[2:])
        for e in self.extras:
            if isinstance(e, int):
                out += f" + ({next(coefs):.10g})*x{e}"
            elif unit_weight(e):
                out += " + " + e.text(next(parts))[1]
            else:
                s, t = e.text(next(parts))
                out += f" + ({next(coefs) * s:.10g})*{t}"
        return out


def factor_pool(d: int, order: list) -> list:
    """The blocks a product is made of. An affine form's scale is absorbed by c1
    where it stands alone, so each variable set gets one lead variable there;
    inside a square plus a bare variable the lead sets the bare variable's weight,
    so every lead is tried. A set's lead is its most important variable (``order``)."""
    V = range(d)
    sets = [c for k in (1, 2, 3) for c in itertools.combinations(order, k)]
    canon = [Affine(c[0], c[1:]) for c in sets]
    leads = [Affine(lead, cv) for lead in V for k in (0, 1)
             for cv in itertools.combinations([v for v in V if v != lead], k)]
    squares = [Square(a) for a in canon if len(a.cv) <= 1]
    squares += [Square(a, bare) for a in leads for bare in V if bare != a.lead and bare not in a.cv]
    exps = [Exp(vs) for k in (1, 2) for vs in itertools.combinations(V, k)]
    inverses = [Inverse(s) for s in squares if s.bare is None] + [Inverse(a) for a in canon]
    return canon + squares + exps + inverses


def admissible(factors: tuple) -> bool:
    """One exponential at most (a product of two is one exponential), no block
    beside its own inverse, and not a lone affine form (the linear terms cover it)."""
    if sum(isinstance(f, Exp) for f in factors) > 1:
        return False
    if any(isinstance(f, Inverse) and f.inner in factors for f in factors):
        return False
    return not (len(factors) == 1 and isinstance(factors[0], Affine))


def skeletons(d: int, budget: int, order=None, max_factors: int = 3, block_extras: bool = False) -> list:
    """Every skeleton in ``d`` variables with at most ``budget`` nodes, the largest
    (most expressive) first: the simpler ones are what a genetic search finds well.

    Each product gets as many linear terms as the budget leaves room for, in every
    choice of variables (fewer never fit better). ``order``: the variables by
    importance (`search` uses |correlation with y|); a set's lead is its most
    important variable, which starts the fit nearest the optimum. ``block_extras``
    also tries one term ``exp(b x_k)``, ``1/(x_k + a)`` or ``(x_k + a)²`` in place
    of linear ones.
    """
    order = list(range(d)) if order is None else [int(v) for v in order]
    pool = factor_pool(d, order)
    out = []
    for k in range(1, max_factors + 1):
        for factors in itertools.combinations_with_replacement(pool, k):
            if admissible(factors):
                out += budgeted(factors, d, budget, block_extras)
    return sorted(out, key=lambda s: (-s.nodes, s.n_inner))


def budgeted(factors: tuple, d: int, budget: int, block_extras: bool = False) -> list:
    """The skeletons of one product within ``budget``: as many linear terms as fit,
    in every choice of variables (fewer never fit better); with ``block_extras``
    also one one-variable block (``exp(b x_k)``, ``1/(x_k + a)``, ``(x_k + a)²``) among them.

    Parameters
    ----------
    factors : the product's blocks.
    d : number of variables.
    budget : node budget.
    block_extras : also try one block term.

    Returns
    -------
    list of Skeleton (empty when the product alone exceeds the budget)
    """
    head = 4 + sum(f.nodes for f in factors)
    V = range(d)
    blocks = [None] + ([Exp((v,)) for v in V] + [Inverse(Affine(v)) for v in V] + [Square(Affine(v)) for v in V]
                       if block_extras else [])
    out = []
    for block in blocks:
        room = budget - head - (0 if block is None else 2 + block.nodes)
        if room >= 0:
            out += [Skeleton(factors, lin + (() if block is None else (block,)))
                    for lin in itertools.combinations(V, min(d, room // 3))]
    return out


def initial(sk: Skeleton, start: int, rng) -> np.ndarray:
    """Inner constants to start from. Scale-free affine weights start small (the
    factor near 1), a square's offset is spread over (and beyond) the z-score range
    where its centre may lie, exponents start small."""
    offsets = (0.0, 3.0, -3.0, 1.5)
    p: list = []
    for n, block in enumerate(sk.blocks):
        inner: Any = block.inner if isinstance(block, Inverse) else block
        if isinstance(inner, ShiftedPower):  # the shift beyond the z-score range, a mild power
            p += [rng.uniform(2.0, 4.0), 0.5 * rng.standard_normal()]
        elif isinstance(inner, Square):
            offset = offsets[(start + 1 + n) % 4] + 0.1 * rng.standard_normal()
            p += [offset] + list(0.3 * rng.standard_normal(len(inner.inner.cv)))
        elif isinstance(inner, Affine):
            p += list((0.1 if start == 0 else 0.4) * rng.standard_normal(inner.n_params))
        else:
            p += list(0.5 * rng.standard_normal(inner.n_params))
    return np.asarray(p, float)
