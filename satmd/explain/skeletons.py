"""Exhaustive pass over small product skeletons, constants fitted by variable projection.

Genetic searches such as operon's put a free weight on every variable leaf,
so a formula they return pays three nodes (``Mul``, the weight, the symbol)
for each variable; the compact formulas a person writes, like the paper's
``1.69 + 0.02(x3 − x1 − 2.77 − 0.28 x2)[(x1 − 3.14)² + x0]``, lead every
affine form with a bare variable and reach the same accuracy with fewer
nodes. This back end enumerates that family directly:

    y ≈ c0 + c1 · A · B  [+ c2 · x_k]

where ``A`` is an affine form ``x_i + a + Σ b_j x_j`` (its lead variable bare)
and ``B`` is one of ``S`` (an affine form squared, optionally plus a bare
variable), ``exp(Σ b_j x_j)``, ``1/S`` or ``1/A'``. Every skeleton whose node
count (`symbolic.node_count`, the counting rule of the module) fits the budget
is fitted: the outer constants c by linear least squares for each value of the
inner ones, the inner ones by Levenberg-Marquardt on that projected residual
(variable projection), on a subsample of the training rows. The best are then
refitted on all training rows from several starts. Deterministic for a seed.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares


@dataclass(frozen=True)
class Affine:
    """``x_lead + a + Σ b_j x_j`` (``cv`` the variables with a free coefficient)."""

    lead: int
    cv: tuple

    @property
    def n_params(self):
        return 1 + len(self.cv)

    @property
    def nodes(self):
        return 3 + 3 * len(self.cv)

    def value(self, p, Zt):
        out = Zt[self.lead] + p[0]
        for b, j in zip(p[1:], self.cv):
            out = out + b * Zt[j]
        return out

    def text(self, p):
        return "(" + " + ".join([f"x{self.lead}", f"({p[0]:.10g})"]
                                + [f"({b:.10g})*x{j}" for b, j in zip(p[1:], self.cv)]) + ")"


@dataclass(frozen=True)
class Square:
    """``A² [+ x_bare]``."""

    inner: Affine
    bare: int | None = None

    @property
    def n_params(self):
        return self.inner.n_params

    @property
    def nodes(self):
        return self.inner.nodes + 2 + (2 if self.bare is not None else 0)

    def value(self, p, Zt):
        out = self.inner.value(p, Zt) ** 2
        return out if self.bare is None else out + Zt[self.bare]

    def text(self, p):
        sq = f"{self.inner.text(p)}**2"
        return sq if self.bare is None else f"({sq} + x{self.bare})"


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
        return "exp(" + " + ".join(f"({b:.10g})*x{j}" for b, j in zip(p, self.vs)) + ")"


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
        return f"1/{self.inner.text(p)}"


@dataclass(frozen=True)
class Skeleton:
    """``c0 + c1 · A · B [+ c2 · E]``: ``E`` a variable (index) or a one-variable block."""

    a: Affine
    b: object
    extra: object = None

    @property
    def nodes(self):
        extra = 0 if self.extra is None else 3 if isinstance(self.extra, int) else 2 + self.extra.nodes
        return 4 + self.a.nodes + self.b.nodes + extra

    @property
    def n_inner(self):
        return self.a.n_params + self.b.n_params + self._n_extra

    @property
    def _n_extra(self):
        return 0 if self.extra is None or isinstance(self.extra, int) else self.extra.n_params

    def product(self, p, Zt):
        k = self.a.n_params
        m = k + self.b.n_params
        return self.a.value(p[:k], Zt) * self.b.value(p[k:m], Zt)

    def _extra(self, p, Zt):
        if isinstance(self.extra, int):
            return Zt[self.extra]
        return self.extra.value(p[self.n_inner - self._n_extra:], Zt)

    def columns(self, p, Zt):
        """The columns multiplying c1 (and c2); c0 multiplies ones."""
        cols = [self.product(p, Zt)]
        if self.extra is not None:
            cols.append(self._extra(p, Zt))
        return cols

    def text(self, p, c):
        k = self.a.n_params
        m = k + self.b.n_params
        out = f"({c[0]:.10g}) + ({c[1]:.10g})*{self.a.text(p[:k])}*{self.b.text(p[k:m])}"
        if self.extra is None:
            return out
        extra = f"x{self.extra}" if isinstance(self.extra, int) else self.extra.text(p[m:])
        return out + f" + ({c[2]:.10g})*{extra}"


def skeletons(d: int, budget: int, order=None) -> list:
    """Every skeleton in ``d`` variables with at most ``budget`` nodes, the largest
    (most expressive) first: the simpler ones are what a genetic search finds well.

    An affine form's scale is absorbed by c1 wherever it stands alone, so each
    variable set gets one lead variable there; inside a square plus a bare
    variable the lead sets the bare variable's weight, so every lead is tried.
    ``order``: the variables by importance (`search` uses |correlation with y|);
    a set's lead is its most important variable, which starts the fit nearest
    the optimum (the others' coefficients start small).
    """
    V = range(d)
    order = list(V) if order is None else [int(v) for v in order]
    sets = [c for k in (1, 2, 3) for c in itertools.combinations(order, k)]
    canon = [Affine(c[0], c[1:]) for c in sets]
    leads = [Affine(lead, cv) for lead in V for k in (0, 1)
             for cv in itertools.combinations([v for v in V if v != lead], k)]
    squares = [Square(a) for a in canon if len(a.cv) <= 1]
    squares += [Square(a, bare) for a in leads for bare in V if bare != a.lead and bare not in a.cv]
    exps = [Exp(vs) for k in (1, 2) for vs in itertools.combinations(V, k)]
    partners = squares + exps + [Inverse(s) for s in squares if s.bare is None] + [Inverse(a) for a in canon]
    extras = [Exp((v,)) for v in V] + [Inverse(Affine(v, ())) for v in V] + [Square(Affine(v, ())) for v in V]
    out = []
    for a in canon:
        for b in partners:
            if isinstance(b, Inverse) and b.inner == a:
                continue
            for extra in [None] + list(V) + extras:
                sk = Skeleton(a, b, extra)
                if sk.nodes <= budget:
                    out.append(sk)
    return sorted(out, key=lambda s: (-s.nodes, s.n_inner))


def _initial(sk: Skeleton, start: int, rng) -> np.ndarray:
    """Inner constants to start from: affine offsets spread over (and beyond) the
    z-score range, where a square's centre or a pole may lie; small coefficients and exponents."""
    offsets = (0.0, 3.0, -3.0, 1.5)
    blocks = [sk.a, sk.b] + ([sk.extra] if sk._n_extra else [])
    p = []
    for n, block in enumerate(blocks):
        inner = block.inner if isinstance(block, Inverse) else block
        inner = inner.inner if isinstance(inner, Square) else inner
        if isinstance(inner, Affine):
            offset = offsets[(start + n) % 4] if isinstance(block, Affine) else offsets[(start + 1 + n) % 4]
            if isinstance(block, Inverse) and offset == 0.0:
                offset = 3.0  # start away from the pole
            p += [offset + 0.1 * rng.standard_normal()] + list(0.3 * rng.standard_normal(len(inner.cv)))
        else:
            p += list(0.5 * rng.standard_normal(inner.n_params))
    return np.asarray(p, float)


def _project(cols: list, y: np.ndarray):
    """Residual and coefficients of y on [1, cols...] by least squares, via the
    centred normal equations (one or two columns: far cheaper than ``lstsq``)."""
    n = y.size
    ym = y.sum() / n
    yc = y - ym
    means = [c.sum() / n for c in cols]
    C = [c - m for c, m in zip(cols, means)]
    if len(C) == 1:
        den = float(C[0] @ C[0])
        b = (float(C[0] @ yc) / den,) if den > 0 else (0.0,)
        r = b[0] * C[0] - yc
    else:
        g00, g01, g11 = float(C[0] @ C[0]), float(C[0] @ C[1]), float(C[1] @ C[1])
        h0, h1 = float(C[0] @ yc), float(C[1] @ yc)
        det = g00 * g11 - g01 * g01
        if det <= 1e-12 * (g00 * g11 + 1e-300):
            b = (h0 / g00 if g00 > 0 else 0.0, 0.0)
        else:
            b = ((g11 * h0 - g01 * h1) / det, (g00 * h1 - g01 * h0) / det)
        r = b[0] * C[0] + b[1] * C[1] - yc
    c0 = ym - sum(bi * m for bi, m in zip(b, means))
    return r, np.array([c0, *b])


def fit(sk: Skeleton, Zt: np.ndarray, y: np.ndarray, starts: int = 2, seed: int = 0, max_nfev: int | None = None):
    """Variable-projection fit of one skeleton: (R², inner constants, outer constants)."""
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
            sol = least_squares(residual, _initial(sk, s, rng), method="lm",
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


def search(Z, y, *, budget: int = 20, seed: int = 0, time_limit: float | None = 60.0, subsample: int = 500,
           keep: int = 24, starts: int = 6, block_extras: bool = False) -> tuple:
    """Fit every skeleton within ``budget`` on a subsample, refit the ``keep`` best on all rows.

    Returns ``([(r2_train, text), ...], info)``, best first (infix strings in
    x0..); ``info`` says how many skeletons were fitted of how many.
    ``time_limit`` caps the first pass (the largest skeletons are visited first).
    ``block_extras`` also tries ``exp(b x_k)``, ``1/(x_k + a)`` and ``(x_k + a)²``
    as the extra term (slower; on the SPEC §6 data they never won).
    """
    Z = np.asarray(Z, float)
    y = np.asarray(y, float)
    rng = np.random.default_rng(seed)
    rows = rng.choice(y.size, min(subsample, y.size), replace=False)
    Zs, ys = Z[rows].T, y[rows]
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        corr = np.nan_to_num([abs(np.corrcoef(z, y)[0, 1]) for z in Z.T])
    pool = [sk for sk in skeletons(Z.shape[1], budget, order=np.argsort(-corr, kind="stable"))
            if block_extras or sk.extra is None or isinstance(sk.extra, int)]
    scored, fitted = [], 0
    for i, sk in enumerate(pool):
        if time_limit is not None and time.perf_counter() - t0 > time_limit:
            break
        r2, _, _ = fit(sk, Zs, ys, starts=2, seed=seed + i)
        fitted += 1
        if np.isfinite(r2):
            scored.append((r2, sk))
    scored.sort(key=lambda t: -t[0])
    out = []
    for _, sk in scored[:keep]:
        r2, p, c = fit(sk, Z.T, y, starts=starts, seed=seed, max_nfev=100 * (sk.n_inner + 1))
        if p is not None and np.isfinite(r2):
            out.append((r2, sk.text(p, c)))
    info = {"skeletons": len(pool), "skeletons_fitted": fitted, "skeleton_s": time.perf_counter() - t0}
    return sorted(out, key=lambda t: -t[0]), info
