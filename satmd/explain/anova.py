"""How much of a descriptor small formulas can explain, read off a full-factorial grid.

On a full-factorial grid the functional ANOVA (Sobol') decomposition is exact
and cheap: y = y0 + Σ f_i(x_i) + Σ f_ij(x_i, x_j) + ..., each term a
difference of cell means. Its variance shares say what structure any
formula must have: with main effects alone (an additive formula) R² cannot
exceed ``main``; ``grid_ceiling`` bounds any function of a subset of inputs.

>>> from satmd.explain import xi_dataset
>>> from satmd.explain.anova import grid_anova
>>> data = xi_dataset()                                  # doctest: +SKIP
>>> print(grid_anova(data.X, data.targets["xi"], data.names).report())   # doctest: +SKIP
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import DataError


@dataclass(frozen=True)
class GridAnova:
    """Variance shares of the ANOVA terms (fractions of the total variance).

    ``main[name]`` is the share of f_i; ``pairs[(a, b)]`` of f_ab; ``r2_main``
    and ``r2_pairs`` the R² of the additive model and of the model with every
    two-way term (the most an additive / pairwise formula can reach);
    ``r2_greedy`` the R² as the largest terms are added one at a time.
    """

    names: tuple
    main: dict
    pairs: dict
    r2_main: float
    r2_pairs: float
    r2_greedy: tuple  # ((label, cumulative R²), ...)

    def report(self) -> str:
        mains = ", ".join(f"{n} {s:.3f}" for n, s in self.main.items())
        pairs = ", ".join(f"{a}×{b} {s:.3f}" for (a, b), s in sorted(self.pairs.items(), key=lambda kv: -kv[1]))
        steps = " → ".join(f"{lab} {r2:.3f}" for lab, r2 in self.r2_greedy)
        return (f"ANOVA shares: main {mains}; pairs {pairs}\n"
                f"  additive R² ≤ {self.r2_main:.3f}, with every pair ≤ {self.r2_pairs:.3f}; adding terms: {steps}")

    def to_dict(self) -> dict:
        return {"names": list(self.names), "main": dict(self.main),
                "pairs": {f"{a}x{b}": s for (a, b), s in self.pairs.items()}, "r2_main": self.r2_main,
                "r2_pairs": self.r2_pairs, "r2_greedy": [list(step) for step in self.r2_greedy]}


def _cube(X, y):
    """y as an array over the grid's axes (one axis per input); raises unless X is a full factorial."""
    X = np.asarray(X, float)
    y = np.asarray(y, float).ravel()
    if X.ndim != 2 or X.shape[0] != y.size:
        raise DataError(f"X must be (n, d) and y (n,); got {X.shape} and {y.shape}")
    if not np.all(np.isfinite(y)):
        raise DataError(f"grid_anova needs a finite target at every grid point ({np.sum(~np.isfinite(y))} are not)")
    levels, index = [], []
    for j in range(X.shape[1]):
        lv, inv = np.unique(X[:, j], return_inverse=True)
        levels.append(lv.size)
        index.append(inv.ravel())
    if int(np.prod(levels)) != y.size:
        raise DataError(f"X is not a full-factorial grid: {'x'.join(map(str, levels))} levels "
                        f"but {y.size} samples")
    cube = np.full(levels, np.nan)
    cube[tuple(index)] = y
    if np.isnan(cube).any():
        raise DataError("X is not a full-factorial grid: some level combinations repeat")
    return cube


def _term(cube, keep):
    """The ANOVA term over the axes in ``keep`` (by inclusion-exclusion of cell means)."""
    d = cube.ndim
    out = 0.0
    for k in range(len(keep) + 1):
        for sub in itertools.combinations(keep, k):
            other = tuple(a for a in range(d) if a not in sub)
            out = out + (-1) ** (len(keep) - k) * cube.mean(axis=other, keepdims=True)
    return out


def grid_anova(X, y, names=None) -> GridAnova:
    """Main-effect and two-way ANOVA shares of ``y`` over a full-factorial grid.

    Parameters
    ----------
    X : (n, d) inputs on a full-factorial grid.
    y : (n,) target.
    names : names of the d inputs (default x0..).

    Returns
    -------
    GridAnova
    """
    cube = _cube(X, y)
    d = cube.ndim
    names = tuple(names) if names is not None else tuple(f"x{i}" for i in range(d))
    total = np.mean((cube - cube.mean()) ** 2)
    if total == 0:
        raise DataError("the target is constant over the grid: nothing to decompose")
    terms: dict[tuple, np.ndarray] = {(i,): _term(cube, (i,)) for i in range(d)}
    terms.update({p: _term(cube, p) for p in itertools.combinations(range(d), 2)})
    share = {k: float(np.mean(np.broadcast_to(t, cube.shape) ** 2) / total) for k, t in terms.items()}

    def r2(keys):
        fit = cube.mean() + sum((terms[k] for k in keys), np.zeros(cube.shape))
        return float(1.0 - np.mean((cube - fit) ** 2) / total)

    mains: list[tuple] = [(i,) for i in range(d)]
    pairs = [k for k in terms if len(k) == 2]
    greedy, chosen = [], list(mains)
    greedy.append(("main effects", r2(chosen)))
    for k in sorted(pairs, key=lambda k: -share[k]):
        chosen.append(k)
        greedy.append((f"+{names[k[0]]}×{names[k[1]]}", r2(chosen)))
    return GridAnova(names, {names[i]: share[(i,)] for i in range(d)},
                     {(names[a], names[b]): share[(a, b)] for a, b in pairs}, r2(mains), r2(mains + pairs),
                     tuple(greedy))


def grid_ceiling(X, y, columns) -> float:
    """R² of the per-cell means of y over the distinct value combinations of
    ``X[:, columns]``: on grid data, the most any function of only those
    inputs can explain."""
    X = np.asarray(X, float)
    y = np.asarray(y, float).ravel()
    keep = np.isfinite(y)
    X, y = X[keep], y[keep]
    _, cell = np.unique(X[:, list(columns)], axis=0, return_inverse=True)
    cell = cell.ravel()
    means = np.bincount(cell, y) / np.bincount(cell)
    return float(1.0 - np.sum((y - means[cell]) ** 2) / np.sum((y - y.mean()) ** 2))


def structure_ceiling(X, y, products, linear=(), names=None, iters: int = 300, starts: int = 3) -> float:
    """R² of the best formula of a given structure, with every shape left free.

    The structure is ``c0 + Σ_k a_k x_k + Σ_P Π_{i∈P} g_{P,i}(x_i)``, each g a
    free value per grid level of its input. On grid data no formula of that
    structure, whatever its factors' shapes, explains more (up to the
    alternating least squares finding the optimum: the best of ``starts``
    starts is returned).

    Example: ``structure_ceiling(X, y, [("L", "m2", "kp")], ("R", "L"), names)``
    bounds every ``c0 + a R + b L + F(L) G(m2) H(kp)``.

    Parameters
    ----------
    X : (n, d) inputs on a full-factorial grid.
    y : (n,) target.
    products : the products, each a tuple of input indices or names.
    linear : the inputs with a linear term.
    names : names of the d inputs (default x0..).
    iters : sweeps of the alternating least squares.
    starts : random starts of the shapes.

    Returns
    -------
    float
    """
    _cube(X, y)  # a full-factorial grid with a finite target, or a one-line error
    X = np.asarray(X, float)
    y = np.asarray(y, float).ravel()
    d = X.shape[1]
    names = list(names) if names is not None else [f"x{i}" for i in range(d)]

    def index(v):
        if isinstance(v, str):
            if v not in names:
                raise DataError(f"structure_ceiling: unknown input {v!r} (inputs: {', '.join(names)})")
            return names.index(v)
        return int(v)

    products = [tuple(index(v) for v in p) for p in products]
    linear = [index(v) for v in linear]
    level = [np.unique(X[:, j], return_inverse=True)[1].ravel() for j in range(d)]
    sizes = [int(lv.max()) + 1 for lv in level]
    A = np.column_stack([np.ones(y.size)] + [X[:, j] for j in linear])
    total = np.sum((y - y.mean()) ** 2)
    best = -np.inf
    for start in range(starts):
        rng = np.random.default_rng(start)
        shapes = [[1.0 + 0.3 * rng.standard_normal(sizes[j]) for j in p] for p in products]

        def term(k):
            out = np.ones(y.size)
            for g, j in zip(shapes[k], products[k]):
                out = out * g[level[j]]
            return out

        for _ in range(iters):
            for k, p in enumerate(products):
                others = sum((term(m) for m in range(len(products)) if m != k), np.zeros(y.size))
                for i, j in enumerate(p):
                    coef = np.linalg.lstsq(A, y - others - term(k), rcond=None)[0]
                    r = y - A @ coef - others
                    rest = np.ones(y.size)
                    for g, jj in zip(shapes[k][:i] + shapes[k][i + 1:], p[:i] + p[i + 1:]):
                        rest = rest * g[level[jj]]
                    den = np.bincount(level[j], rest * rest, sizes[j])
                    shapes[k][i] = np.bincount(level[j], r * rest, sizes[j]) / np.where(den > 0, den, 1.0)
        fit = sum((term(k) for k in range(len(products))), np.zeros(y.size))
        coef = np.linalg.lstsq(A, y - fit, rcond=None)[0]
        best = max(best, float(1.0 - np.sum((y - A @ coef - fit) ** 2) / total))
    return best
