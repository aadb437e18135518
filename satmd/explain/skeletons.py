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
variable), ``exp(Σ b_j x_j)``, ``1/S`` or ``1/A``, and as many linear terms
``c_k x_k`` as the node budget leaves room for (every choice of variables).
`skeletons` lists every skeleton whose node count (`symbolic.node_count`, the
counting rule of the module) fits the budget; `fit` fits one: the outer
constants c by linear least squares for each value of the inner ones, the
inner ones by Levenberg-Marquardt on that projected residual (variable
projection). `satmd.explain.skeleton_search` searches the family with a beam.

A standalone affine factor is fitted scale-free, as ``1 + Σ w_j x_j`` (c1
absorbs the scale): its offset ``a = 1/w_lead`` may lie far outside the data
(a factor that only tilts the product, like ``(x2 − 6.5)``), where the offset
form has almost no gradient. Inside a square the offset form is kept, since
the square's centre is what the fit has to find.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares


@dataclass(frozen=True)
class Affine:
    """``x_lead + a + Σ b_j x_j`` (``cv`` the variables with a free coefficient)."""

    lead: int
    cv: tuple = ()

    @property
    def n_params(self):
        return 1 + len(self.cv)

    @property
    def nodes(self):
        return 3 + 3 * len(self.cv)

    def value(self, p, Zt):
        """Scale-free: ``1 + w_lead x_lead + Σ w_j x_j``."""
        out = 1.0 + p[0] * Zt[self.lead]
        for w, j in zip(p[1:], self.cv):
            out = out + w * Zt[j]
        return out

    def text(self, p):
        """``(scale, text)`` with value = scale · text; the largest weight is written bare."""
        vs = (self.lead, *self.cv)
        k = int(np.argmax(np.abs(p)))
        s = float(p[k])
        if abs(s) < 1e-12:
            return 1.0, "1"
        terms = [f"x{vs[k]}", f"({1.0 / s:.10g})"] + [f"({p[i] / s:.10g})*x{v}" for i, v in enumerate(vs) if i != k]
        return s, "(" + " + ".join(terms) + ")"

    def offset_value(self, p, Zt):
        """Offset form: ``x_lead + p0 + Σ p_j x_j`` (inside a square)."""
        out = Zt[self.lead] + p[0]
        for b, j in zip(p[1:], self.cv):
            out = out + b * Zt[j]
        return out

    def offset_text(self, p):
        return "(" + " + ".join([f"x{self.lead}", f"({p[0]:.10g})"]
                                + [f"({b:.10g})*x{j}" for b, j in zip(p[1:], self.cv)]) + ")"


@dataclass(frozen=True)
class Square:
    """``A² [+ x_bare]`` (``A`` in its offset form)."""

    inner: Affine
    bare: int | None = None

    @property
    def n_params(self):
        return self.inner.n_params

    @property
    def nodes(self):
        return self.inner.nodes + 2 + (2 if self.bare is not None else 0)

    def value(self, p, Zt):
        out = self.inner.offset_value(p, Zt) ** 2
        return out if self.bare is None else out + Zt[self.bare]

    def text(self, p):
        sq = f"{self.inner.offset_text(p)}**2"
        return 1.0, sq if self.bare is None else f"({sq} + x{self.bare})"


@dataclass(frozen=True)
class Exp:
    """``exp(Σ b_j x_j)``."""

    vs: tuple

    @property
    def n_params(self):
        return len(self.vs)

    @property
    def nodes(self):
        return 1 + 3 * len(self.vs) + (1 if len(self.vs) > 1 else 0)

    def value(self, p, Zt):
        return np.exp(sum(b * Zt[j] for b, j in zip(p, self.vs)))

    def text(self, p):
        return 1.0, "exp(" + " + ".join(f"({b:.10g})*x{j}" for b, j in zip(p, self.vs)) + ")"


@dataclass(frozen=True)
class Inverse:
    """``1 / B`` for an affine form or a square."""

    inner: object

    @property
    def n_params(self):
        return self.inner.n_params

    @property
    def nodes(self):
        return self.inner.nodes + 2

    def value(self, p, Zt):
        return 1.0 / self.inner.value(p, Zt)

    def text(self, p):
        s, t = self.inner.text(p)
        return 1.0 / s, f"1/{t}"


@dataclass(frozen=True)
class Skeleton:
    """``c0 + c1 · Π factors + Σ c_k · E_k``: each ``E`` a variable (index) or a one-variable block."""

    factors: tuple
    extras: tuple = ()

    @property
    def nodes(self):
        extras = sum(3 if isinstance(e, int) else 2 + e.nodes for e in self.extras)
        return 4 + sum(f.nodes for f in self.factors) + extras

    @property
    def blocks(self):
        """The blocks with inner constants, in the order of the parameter vector."""
        return [*self.factors, *(e for e in self.extras if not isinstance(e, int))]

    @property
    def n_inner(self):
        return sum(b.n_params for b in self.blocks)

    def _split(self, p):
        out, k = [], 0
        for b in self.blocks:
            out.append(p[k:k + b.n_params])
            k += b.n_params
        return out

    def columns(self, p, Zt):
        """The columns multiplying c1, c2, ...; c0 multiplies ones."""
        parts = iter(self._split(p))
        product = 1.0
        for f in self.factors:
            product = product * f.value(next(parts), Zt)
        return [product] + [Zt[e] if isinstance(e, int) else e.value(next(parts), Zt) for e in self.extras]

    def text(self, p, c):
        parts = iter(self._split(p))
        scale, texts = 1.0, []
        for f in self.factors:
            s, t = f.text(next(parts))
            scale, texts = scale * s, texts + [t]
        out = f"({c[0]:.10g}) + ({c[1] * scale:.10g})*" + "*".join(texts)
        for ck, e in zip(c[2:], self.extras):
            if isinstance(e, int):
                out += f" + ({ck:.10g})*x{e}"
            else:
                s, t = e.text(next(parts))
                out += f" + ({ck * s:.10g})*{t}"
        return out


def _factor_pool(d: int, order: list) -> list:
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


def _admissible(factors: tuple) -> bool:
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
    pool = _factor_pool(d, order)
    out = []
    for k in range(1, max_factors + 1):
        for factors in itertools.combinations_with_replacement(pool, k):
            if _admissible(factors):
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


def _initial(sk: Skeleton, start: int, rng) -> np.ndarray:
    """Inner constants to start from. Scale-free affine weights start small (the
    factor near 1), a square's offset is spread over (and beyond) the z-score range
    where its centre may lie, exponents start small."""
    offsets = (0.0, 3.0, -3.0, 1.5)
    p = []
    for n, block in enumerate(sk.blocks):
        inner = block.inner if isinstance(block, Inverse) else block
        if isinstance(inner, Square):
            offset = offsets[(start + 1 + n) % 4] + 0.1 * rng.standard_normal()
            p += [offset] + list(0.3 * rng.standard_normal(len(inner.inner.cv)))
        elif isinstance(inner, Affine):
            p += list((0.1 if start == 0 else 0.4) * rng.standard_normal(inner.n_params))
        else:
            p += list(0.5 * rng.standard_normal(inner.n_params))
    return np.asarray(p, float)


def _project(cols: list, y: np.ndarray):
    """Residual and coefficients of y on [1, cols...] by least squares, via the
    centred normal equations (a few columns: far cheaper than ``lstsq``);
    rank-deficient columns get the minimum-norm answer."""
    A = np.column_stack(cols)
    means = A.mean(axis=0)
    ym = y.mean()
    C = A - means
    yc = y - ym
    G = C.T @ C
    h = C.T @ yc
    try:
        b = np.linalg.solve(G, h)
        ok = np.all(np.isfinite(b)) and np.linalg.cond(G) < 1e12
    except np.linalg.LinAlgError:
        ok = False
    if not ok:
        b, *_ = np.linalg.lstsq(C, yc, rcond=None)
    return C @ b - yc, np.array([ym - means @ b, *b])


def fit(sk: Skeleton, Zt: np.ndarray, y: np.ndarray, starts: int = 2, seed: int = 0, max_nfev: int | None = None,
        p0=None):
    """Variable-projection fit of one skeleton: (R², inner constants, outer constants).
    ``p0``: inner constants for the first start (a warm start), else `_initial`'s."""
    rng = np.random.default_rng(seed)
    sst = float(np.sum((y - y.mean()) ** 2)) or 1.0
    bad = np.full(y.shape, 1e3)

    def residual(p):
        with np.errstate(all="ignore"):
            cols = sk.columns(p, Zt)
            if not all(np.isfinite(c.sum()) for c in cols):
                return bad
            return _project(cols, y)[0]

    best = None
    for s in range(starts):
        try:
            start = np.asarray(p0, float) if (p0 is not None and s == 0) else _initial(sk, s, rng)
            sol = least_squares(residual, start, method="lm",
                                max_nfev=max_nfev or 25 * (sk.n_inner + 1))
        except (ValueError, np.linalg.LinAlgError):
            continue
        if best is None or sol.cost < best.cost:
            best = sol
    if best is None:
        return -np.inf, None, None
    with np.errstate(all="ignore"):
        r, c = _project(sk.columns(best.x, Zt), y)
    return 1.0 - float(r @ r) / sst, best.x, c
