"""Beam search over the product skeletons of `satmd.explain.skeletons`.

Fitting every skeleton within 20 nodes (about 13 000 in four variables) takes
minutes; the beam grows products one factor at a time from the best ones
found, each from its parent's fitted constants, and only the best products
are fitted in every budgeted form.
"""
from __future__ import annotations

import itertools
import time
import zlib

import numpy as np

from .skeletons import Affine, ShiftedPower, Skeleton, UnitPower, admissible, budgeted, factor_pool, initial, unit_weight
from .varpro import fit, project

#: Tolerance of the fits on the subsample, which only rank products and skeletons (the
#: finalists are refitted on all rows at `varpro.fit`'s default tolerance).
RANK_TOL = 1e-5
#: Most starts of a ranking fit: starts go on until two agree on the best (`varpro.fit`), so a
#: product's rank does not hang on which basin one start's round-off falls into.
RANK_STARTS = 4


def _grow(parent: tuple, p_parent, new, factors: tuple, p_new) -> np.ndarray:
    """The parent product's fitted constants, with the new factor's start, in ``factors``' order."""
    slices, k = [], 0
    for f in parent:
        slices.append((f, p_parent[k:k + f.n_params]))
        k += f.n_params
    slices.append((new, p_new))
    out = []
    for f in factors:
        i = next(i for i, (g, _) in enumerate(slices) if g == f)
        out.append(slices.pop(i)[1])
    return np.concatenate(out) if out else np.zeros(0)


#: R² closer than this (relative to 1) rank as equal, and the tie is broken by the product's text: products
#: of one data set can tie to the last bits (a factor and its inverse's twin), and which one round-off
#: puts first must not decide the beam.
TIE = 1e-9


def _rank_key(r2: float, label) -> tuple:
    """Sort key, best first: R² rounded to `TIE`, then the text of the thing ranked."""
    return (-round(float(r2) / TIE) if np.isfinite(r2) else np.inf, repr(label))


def _structure_seed(seed: int, factors: tuple) -> int:
    """A product's own seed: from its structure, not from when the beam reached it."""
    return seed + zlib.crc32(repr(factors).encode()) % 100_003


def search(Z, y, *, budget: int = 20, seed: int = 0, time_limit: float | None = 60.0, subsample: int = 500,
           keep: int = 24, starts: int = 6, beam: tuple = (20, 12), expand: int = 40, block_extras: bool = False,
           curved: int | None = None) -> tuple:
    """Beam search over products, then every budgeted skeleton of the best products.

    A product (one to three factors from the pool of `skeletons`) is fitted on a
    subsample with every variable as a linear term; its inner constants are then
    kept while each choice of linear terms the budget allows is re-projected, and
    the best choice is refitted: that score ranks the product. The ``beam[k]``
    best products of k + 1 factors are grown by one more factor, each fit
    starting from its parent's constants. The ``expand`` best products of all
    sizes are then fitted in every budgeted form, and the ``keep`` best of those
    refitted on all rows (from their subsample constants, then ``starts`` - 1 fresh starts).
    In the ``curved`` best (None: all of them), linear terms are then made curved
    (`_curved_variants`: a unit power ``B^x``, the same three nodes; a shifted power
    ``(x + a)^m`` that may stand in for c0 too), each fit starting from the linear one's constants.

    Returns ``([(r2_train, text), ...], info)``, best first (infix strings in
    x0..); ``info`` says how many products and skeletons were fitted.
    ``time_limit`` caps the beam (the skeletons of the products found so far are still fitted).
    ``block_extras`` also tries ``exp(b x_k)``, ``1/(x_k + a)`` and ``(x_k + a)²``
    in place of linear terms (slower; on the SPEC §6 data they never won).
    """
    Z = np.asarray(Z, float)
    y = np.asarray(y, float)
    rng = np.random.default_rng(seed)
    rows = rng.choice(y.size, min(subsample, y.size), replace=False)
    t0 = time.perf_counter()
    beam_state = Beam(Z[rows].T, y[rows], budget, seed, rng)
    beam_state.run(_factor_pool(Z, y), beam, None if time_limit is None else t0 + time_limit)
    scored = beam_state.skeletons(expand, block_extras)
    out = _refit(scored[:keep], Z.T, y, starts, seed)
    n_curved = _add_curved(out, curved, Z.T, y, budget, seed)
    info = {"products_scored": beam_state.n_fit, "skeletons": len(scored) + beam_state.n_fit + n_curved,
            "skeletons_fitted": len(scored), "curved_variants": n_curved, "skeleton_s": time.perf_counter() - t0}
    return sorted(((r2, sk.text(p, c)) for r2, sk, p, c in out), key=lambda t: -t[0]), info


def _factor_pool(Z, y) -> list:
    """The factors of `skeletons.factor_pool`, variables ordered by |correlation| with ``y``."""
    with np.errstate(all="ignore"):
        corr = np.nan_to_num([abs(np.corrcoef(z, y)[0, 1]) for z in Z.T])
    return factor_pool(Z.shape[1], [int(v) for v in np.argsort(-corr, kind="stable")])


class Beam:
    """The beam over products on a subsample (``Zs`` (d, n), ``ys``): ``fitted`` holds each product's
    constants, ``ranked`` its best (R², skeleton); ``n_fit`` counts the ranking fits."""

    def __init__(self, Zs, ys, budget: int, seed: int, rng):
        self.Zs, self.ys, self.budget, self.seed, self.rng = Zs, ys, budget, seed, rng
        self.d = Zs.shape[0]
        self.ranked: dict = {}
        self.fitted: dict = {(): np.zeros(0)}
        self.n_fit = 0

    def run(self, pool, beam: tuple, deadline: float | None) -> None:
        """Grow the ``beam[k]`` best products of k + 1 factors by one factor of ``pool``, level by level,
        until the widths are spent or ``deadline`` (a `time.perf_counter` time) passes."""
        level = [()]
        for width in (*beam, 0):
            grown = self._grown(level, pool)
            for factors, (parent, new) in grown.items():
                if deadline is not None and time.perf_counter() > deadline:
                    break
                self._rank(factors, parent, new)
            level = sorted((f for f in grown if f in self.ranked), key=lambda f: _rank_key(self.ranked[f][0], f))[:width]

    def _grown(self, level, pool) -> dict:
        """{product: (parent, new factor)} of the admissible products one factor longer than ``level``'s."""
        grown: dict = {}
        for product in level:
            for f in pool:
                factors = tuple(sorted(product + (f,), key=repr))
                if (factors not in self.fitted and factors not in grown
                        and 4 + sum(g.nodes for g in factors) <= self.budget
                        and (admissible(factors) or len(factors) == 1)):
                    grown[factors] = (product, f)
        return grown

    def _rank(self, factors: tuple, parent: tuple, new) -> None:
        """Fit a product with every variable linear (from its parent's constants), re-project each choice
        of linear terms the budget allows and refit the best: that score ranks the product."""
        Zs, ys = self.Zs, self.ys
        seed = _structure_seed(self.seed, factors)
        choices = budgeted(factors, self.d, self.budget, block_extras=False)
        if not choices:
            return
        self.n_fit += 1
        if len(factors) == 1 and isinstance(factors[0], Affine):
            self._rank_lone_affine(factors[0])
            return
        warm = _grow(parent, self.fitted[parent], new, factors, initial(Skeleton((new,)), 1, np.random.default_rng(seed)))
        first = choices[0] if len(choices) == 1 else Skeleton(factors, tuple(range(self.d)))
        r2, p, _ = fit(first, Zs, ys, starts=2, seed=seed, p0=warm if parent else None, tol=RANK_TOL,
                       max_starts=RANK_STARTS)
        if not np.isfinite(r2):
            return
        self.fitted[factors], best = p, (r2, first)
        if len(choices) > 1:
            # the inner constants kept, each choice of linear terms re-projected (cheap), the best refitted
            sst = float(np.sum((ys - ys.mean()) ** 2)) or 1.0

            def projected(sk, p=p):
                with np.errstate(all="ignore"):
                    r = project(sk.columns(p, Zs), ys - sk.offset(p, Zs), sk.intercept)[0]
                return _rank_key(1.0 - float(r @ r) / sst if np.isfinite(r).all() else -np.inf, sk)
            sk = min(choices, key=projected)
            best = (fit(sk, Zs, ys, starts=1, seed=seed, p0=p, tol=RANK_TOL)[0], sk)
        if np.isfinite(best[0]):
            self.ranked[factors] = best

    def _rank_lone_affine(self, factor: Affine) -> None:
        """A lone affine form beside every variable as a linear term lies in their span: its cost is
        flat and a fit's constants would be round-off. Its R² is the linear model's, and the
        constants its children start from are the linear model's direction, ``1 + b·x / scale``."""
        Zs, ys = self.Zs, self.ys
        r, c = project([Zs[v] for v in range(self.d)], ys)
        b0, b = c[0], c[1:][[factor.lead, *factor.cv]]
        norm = float(np.linalg.norm(b))
        scale = b0 if abs(b0) >= norm else norm
        self.fitted[(factor,)] = b / scale if scale else np.zeros(factor.n_params)
        sst = float(np.sum((ys - ys.mean()) ** 2)) or 1.0
        self.ranked[(factor,)] = (1.0 - float(r @ r) / sst, Skeleton((factor,), tuple(range(self.d))))

    def skeletons(self, expand: int, block_extras: bool) -> list:
        """``[(r2, skeleton, constants), ...]``, best first: every budgeted form of the ``expand`` best
        products fitted on the subsample, each from its product's constants."""
        # a lone affine form only seeds the beam: its skeletons are the linear model, fitted flat
        best_products = sorted((f for f in self.ranked if admissible(f)),
                               key=lambda f: _rank_key(self.ranked[f][0], f))[:expand]
        scored = []
        forms = ((f, sk) for f in best_products for sk in budgeted(f, self.d, self.budget, block_extras))
        for i, (f, sk) in enumerate(forms):
            # a block term starts fresh
            warm = np.concatenate([self.fitted[f], initial(sk, 0, self.rng)[len(self.fitted[f]):]])
            r2, p, _ = fit(sk, self.Zs, self.ys, starts=2, seed=self.seed + i, p0=warm, tol=RANK_TOL,
                           max_starts=RANK_STARTS)
            if np.isfinite(r2):
                scored.append((r2, sk, p))
        scored.sort(key=lambda t: _rank_key(t[0], t[1]))
        return scored


def _refit(scored: list, Zt, y, starts: int, seed: int) -> list:
    """``[(r2, skeleton, inner, outer), ...]``, best first: ``scored`` refitted on all rows."""
    out = []
    for _, sk, p0 in scored:
        r2, p, c = fit(sk, Zt, y, starts=starts, seed=seed, max_nfev=100 * (sk.n_inner + 1), p0=p0)
        if p is not None and np.isfinite(r2):
            out.append((r2, sk, p, c))
    out.sort(key=lambda t: _rank_key(t[0], t[1]))
    return out


def _add_curved(out: list, curved: int | None, Zt, y, budget: int, seed: int) -> int:
    """Append to ``out`` the curved variants of its ``curved`` best (None: all); returns how many were fitted."""
    n_curved = 0
    for _, sk, p, c in list(out[:curved]):
        for variant, p0 in _curved_variants(sk, p, c, Zt, budget):
            r2, pv, cv = fit(variant, Zt, y, starts=2, seed=seed, max_nfev=100 * (variant.n_inner + 1), p0=p0)
            n_curved += 1
            if pv is not None and np.isfinite(r2):
                out.append((r2, variant, pv, cv))
    return n_curved


def _curved_variants(sk: Skeleton, p, c, Zt, budget: int) -> list:
    """``sk`` (fitted: inner ``p``, outer ``c``) with linear terms ``c_k x_k`` made curved, every
    choice within ``budget``: a unit power ``B^x_k`` (same nodes; starts with ``ln B = c_k``, the
    same slope at 0) and at most one shifted power ``(x_k + a)^m`` (`ShiftedPower`), which
    either replaces c0 too (one node more; starts with the level c0 and the slope c_k at 0)
    or keeps it (two more). Returns ``[(skeleton, start), ...]``."""
    linear = [i for i, e in enumerate(sk.extras) if isinstance(e, int)]
    coef = dict(zip([i for i, e in enumerate(sk.extras) if not unit_weight(e)], c[2:]))
    parts = sk.parts(p)
    nf = len(sk.factors)
    block_p = dict(zip([i for i, e in enumerate(sk.extras) if not isinstance(e, int)], parts[nf:]))
    make = {"linear": lambda v: v, "unit": UnitPower, "shifted": ShiftedPower}
    out = []
    for kinds in itertools.product(make, repeat=len(linear)):
        if all(k == "linear" for k in kinds) or kinds.count("shifted") > 1:
            continue
        kind = dict(zip(linear, kinds))
        extras = tuple(make[kind[i]](e) if i in kind else e for i, e in enumerate(sk.extras))
        for intercept in ((False, True) if "shifted" in kinds else (True,)):
            variant = Skeleton(sk.factors, extras, intercept)
            if variant.nodes > budget:
                continue
            p0 = list(parts[:nf])
            for i, e in enumerate(sk.extras):
                if kind.get(i) == "unit":
                    p0.append([coef[i]])
                elif kind.get(i) == "shifted":
                    p0.append(_shifted_start(Zt[e], coef[i], None if intercept else c[0]))
                elif not isinstance(e, int):
                    p0.append(block_p[i])
            out.append((variant, np.concatenate(p0) if p0 else np.zeros(0)))
    return out


def _shifted_start(x, slope: float, level: float | None) -> list:
    """``[a, m]`` for ``(x + a)^m`` with the given slope at x = 0 and, when ``level`` is given
    (and positive), that value there (``a^m = level``, ``m a^(m-1) = slope``); the shift stays
    beyond the data (``x + a > 0``)."""
    a = -float(np.min(x)) + np.geomspace(0.05, 50.0, 400)
    if level is not None and level > 0:
        m = slope * a / level
        best = int(np.argmin(np.abs(m * np.log(a) - np.log(level))))
        return [float(a[best]), float(m[best])]
    a0 = float(a[np.searchsorted(a, -np.min(x) + 1.5)])
    return [a0, float(slope * a0)]
