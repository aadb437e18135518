"""Symbolic distillation (paper eqs. 27-29, SPEC §6): a scalar descriptor as a formula.

>>> from satmd.explain import xi_dataset, distill
>>> data = xi_dataset()                                   # doctest: +SKIP
>>> res = distill(data.X, data.targets["xi"])   # the search `satmd explain` runs  # doctest: +SKIP
>>> print(res.report())                                   # doctest: +SKIP

Inputs are z-scored with the mean and std (ddof 0) of the whole dataset, as
the paper's x0..x3, then split 80/20 (``seed`` 42). The back end searches on
the training part; every candidate is converted to sympy, constants are
refitted on the training part (``polish``), constants the others can absorb
are dropped (``prune``), the rest rounded to 4 significant digits, and *all* reported metrics are computed from that rounded sympy
expression. Complexity is `satmd.explain.symbolic.node_count`.

Back ends: the default pools the skeleton pass with ``operon`` (``hybrid``,
`DEFAULT_SEARCH`); ``operon`` (pyoperon), ``skeleton``, ``pysr`` (needs a Julia runtime;
refused in one line without it), ``sindy`` (PySINDy's STLSQ over a
polynomial, optionally rational, library: the transparent baseline).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import DataError, SatmdError
from .backends import BACKENDS
from .pareto import Finish, ParetoEntry, Parts, cv_r2, metrics, pareto_front, split

__all__ = ["distill", "DistillResult", "DEFAULT_SEARCH", "NAMED_DEFAULTS", "paper_formula_result", "split",
           "metrics", "cv_r2", "pareto_front", "ParetoEntry", "grid_ceiling"]
from .anova import grid_ceiling  # noqa: F401 - re-exported: it bounds what distill can reach


def _symbolic():
    """The sympy helpers, imported on first use (sympy is an optional dependency)."""
    from . import symbolic

    return symbolic


@dataclass(frozen=True)
class DistillResult:
    """A distilled formula and its accuracy-complexity trade-off.

    ``expression`` is in z-scored variables x0..x{d-1} (``names`` says which
    physical input each is; ``mean``/``std`` undo the scoring); ``pareto`` is
    the non-dominated set over (complexity, training MSE), simplest first,
    each entry a `ParetoEntry` (complexity, r2/mae train/test, the expression;
    read like a dict).
    """

    backend: str
    expression: object  # sympy expression
    complexity: int
    mae_train: float
    mae_test: float
    r2_train: float
    r2_test: float
    pareto: tuple
    seconds: float
    names: tuple
    mean: np.ndarray
    std: np.ndarray
    n_train: int
    n_test: int
    info: dict = field(default_factory=dict)

    def predict(self, X) -> np.ndarray:
        """The formula at physical inputs X (n, d)."""
        Z = (np.asarray(X, float) - self.mean) / self.std
        return _symbolic().evaluate(self.expression, Z)

    def best_within(self, max_complexity: int, on: str = "r2_test") -> ParetoEntry | None:
        """The Pareto entry with the highest ``on`` among complexity <= max_complexity."""
        ok = [p for p in self.pareto if p["complexity"] <= max_complexity and np.isfinite(p[on])]
        return max(ok, key=lambda p: p[on]) if ok else None

    def to_dict(self) -> dict:
        return {
            "backend": self.backend, "expression": str(self.expression), "complexity": self.complexity,
            "mae_train": self.mae_train, "mae_test": self.mae_test, "r2_train": self.r2_train,
            "r2_test": self.r2_test, "seconds": self.seconds, "names": list(self.names),
            "zscore_mean": self.mean.tolist(), "zscore_std": self.std.tolist(),
            "n_train": self.n_train, "n_test": self.n_test,
            "pareto": [p.to_dict() for p in self.pareto], "info": self.info,
        }

    def report(self) -> str:
        scored = np.any(self.mean != 0) or np.any(self.std != 1)
        var = ", ".join(f"x{i} = z({n})" if scored else f"x{i} = {n}" for i, n in enumerate(self.names))
        lines = [f"symbolic distillation ({self.backend}, {self.seconds:.1f} s; {var})",
                 f"  {self.expression}",
                 f"  complexity {self.complexity} nodes; MAE train/test {self.mae_train:.4g}/{self.mae_test:.4g}; "
                 f"R² train/test {self.r2_train:.4f}/{self.r2_test:.4f}",
                 "  Pareto front (complexity: R² test):  "
                 + ", ".join(f"{p['complexity']}: {p['r2_test']:.3f}" for p in self.pareto)]
        return "\n".join(lines)


#: What `distill` runs when no back end is named: the search `satmd explain` runs for ξ (the
#: skeleton pass pooled with operon, finalists by cross-validation on a validation share), the
#: best of those measured (`benchmarks/distill.py`), at about 75 s.
DEFAULT_SEARCH = {"backend": "hybrid", "max_complexity": 20, "validation": 0.2, "finalists": 10, "time_limit": 75,
                  "operon_share": 0.25, "restarts": 2,
                  "allowed_symbols": "add,sub,mul,div,square,exp,constant,variable", "max_length": 18,
                  "max_depth": 8, "generations": 20, "population_size": 1000, "optimizer_iterations": 10}
#: The settings a named back end starts from (each overridden by the keyword of that name).
NAMED_DEFAULTS = {"max_complexity": None, "validation": 0.0, "finalists": 5, "time_limit": None}


def distill(X, y, backend: str | None = None, names=None, *, max_complexity: int | None = None,
            test_size: float = 0.2, seed: int = 42, search_seed: int | None = None, zscore: bool = True,
            n_threads: int = 1,
            time_limit: float | None = None, polish: bool | None = None, prune: bool | None = None, digits: int = 4,
            validation: float | None = None, finalists: int | None = None, cv_folds: int = 5,
            **options) -> DistillResult:
    """Fit a compact formula y ≈ f(z(X)).

    Parameters
    ----------
    X : (n, d) physical inputs
    y : (n,) target (non-finite rows are dropped)
    backend : None (default: `DEFAULT_SEARCH`, the hybrid search `satmd explain` runs, at
        most 20 nodes, chosen on a validation share; about 75 s), "operon", "pysr", "sindy",
        "skeleton" (product skeletons within the node budget, `satmd.explain.skeletons`) or
        "hybrid" (operon and the skeletons pooled). A named back end starts from
        `NAMED_DEFAULTS` and its own settings.
    names : names of the d inputs (default x0..)
    max_complexity : return the most accurate candidate (training R², or
        validation R² with ``validation``) with at most this many nodes; None:
        the back end's own choice (operon: MDL; others: best training R²).
        It is also the node budget of the skeleton and hybrid back ends (default 20)
    test_size : share of the test split
    seed : seed of the train/test split (SPEC §6: 42)
    search_seed : seed of the back end's search (default: ``seed``)
    zscore : standardise the inputs first (the paper's x_i); False: x_i are the raw inputs
    n_threads, time_limit : resources of the search (time_limit in s, a cap)
    polish : refit each candidate's constants on the training data (default:
        yes, except for SINDy's polynomial library whose fit is already least squares)
    prune : drop the constants the others can absorb (`symbolic.prune`: the
        squared error may grow by 1e-4 relative); default: when polishing
    digits : significant digits the constants are rounded to (metrics use the rounded formula)
    validation : share of the *training* rows held out to choose among the
        candidates (0: choose on training R²). The search and the constants
        see only the rest; the chosen formula's constants are then refitted
        on all training rows. The test rows are never seen.
    finalists, cv_folds : with ``validation``, the ``finalists`` best on the
        held-out part are compared by ``cv_folds``-fold cross-validation over
        all training rows (constants refitted per fold), which a single
        held-out part is too noisy to separate
    **options : passed to the back end (e.g. max_length, generations, degree, rational)

    Returns
    -------
    DistillResult
    """
    settings = Settings.resolve(backend, max_complexity, validation, finalists, time_limit, options)
    _symbolic()  # sympy first: without it, one error before any work
    parts = Parts.make(X, y, test_size, seed, zscore, settings.validation)
    names = tuple(names) if names is not None else tuple(f"x{i}" for i in range(parts.d))
    t0 = time.perf_counter()
    search_seed = seed if search_seed is None else search_seed
    candidates, chosen, info = BACKENDS[settings.backend](parts.Zfit, parts.yfit, seed=search_seed,
                                                          n_threads=n_threads, time_limit=settings.time_limit,
                                                          **settings.options)
    search_s = time.perf_counter() - t0
    if polish is None:
        polish = not (settings.backend == "sindy" and not settings.options.get("rational", False))
    finish = Finish(polish, polish if prune is None else prune, digits)
    entries = _entries(candidates, chosen, parts, finish, settings.backend)
    pick, entries, rank = _choose(entries, parts, settings, cv_folds, seed)
    if parts.Zval is not None:  # the chosen structure's constants from all training rows
        refit = parts.score(finish(pick.expression, parts.Ztr, parts.ytr), pick.chosen)
        if settings.max_complexity is None or refit.complexity <= max(settings.max_complexity, pick.complexity):
            entries.append(refit)
            pick = refit
    front = tuple(pareto_front(entries))
    seconds = time.perf_counter() - t0
    info = {**info, "search_s": search_s, "n_candidates": len(entries), "validation": settings.validation,
            "chosen_on": rank}
    return DistillResult(settings.backend, pick.expression, pick.complexity, pick.mae_train, pick.mae_test,
                         pick.r2_train, pick.r2_test, front, seconds, names, parts.mean, parts.std, len(parts.ytr),
                         len(parts.yte), info)


@dataclass(frozen=True)
class Settings:
    """The search `distill` runs: the back end, its node budget, validation share, finalists, time
    limit and options, from `DEFAULT_SEARCH` (no back end named) or `NAMED_DEFAULTS` and the keywords."""

    backend: str
    max_complexity: int | None
    validation: float
    finalists: int
    time_limit: float | None
    options: dict

    @classmethod
    def resolve(cls, backend, max_complexity, validation, finalists, time_limit, options: dict) -> "Settings":
        """The settings of a `distill` call (keywords given win over the preset; None: not given).

        Parameters
        ----------
        backend : a back end's name, or None for `DEFAULT_SEARCH`
        max_complexity, validation, finalists, time_limit : as `distill`
        options : the back end's own options (``**options`` of `distill`)

        Returns
        -------
        Settings
        """
        given: dict[str, Any] = {"max_complexity": max_complexity, "validation": validation,
                                 "finalists": finalists, "time_limit": time_limit}
        if backend is None:
            preset: dict[str, Any] = dict(DEFAULT_SEARCH)
            backend = preset.pop("backend")
            options = {**{k: v for k, v in preset.items() if k not in given}, **options}
        else:
            preset = NAMED_DEFAULTS
        given = {k: preset[k] if v is None else v for k, v in given.items()}
        if backend not in BACKENDS:
            raise SatmdError(f"unknown backend {backend!r}; choose from {', '.join(BACKENDS)}")
        if not 0.0 <= given["validation"] < 0.9:
            raise DataError(f"validation must be a share in [0, 0.9), got {given['validation']}")
        if backend in ("skeleton", "hybrid"):
            options = dict(options)
            options.setdefault("budget", given["max_complexity"] if given["max_complexity"] is not None else 20)
        return cls(backend, given["max_complexity"], given["validation"], given["finalists"], given["time_limit"],
                   options)


def _entries(candidates, chosen, parts: Parts, finish: Finish, backend: str) -> list:
    """The back end's candidates finished on the search rows and scored, duplicates dropped."""
    symbolic = _symbolic()
    sp = symbolic.sp
    entries, seen = [], set()
    for i, text in enumerate(candidates):
        expr = symbolic.parse(text, parts.d) if isinstance(text, str) else sp.sympify(text)
        expr = finish(expr, parts.Zfit, parts.yfit)
        key = sp.srepr(expr)
        if key in seen:
            continue
        seen.add(key)
        entries.append(parts.score(expr, i == chosen))
    if not entries:
        raise SatmdError(f"the {backend} backend returned no expression")
    return entries


def _choose(entries: list, parts: Parts, settings: Settings, cv_folds: int, seed: int) -> tuple:
    """(pick, entries, the score it was chosen on): the best within the node budget on validation (or
    training) R², the finalists compared by cross-validation; without a budget, the back end's choice."""
    rank = "r2_val" if parts.Zval is not None else "r2_train"
    if settings.max_complexity is None:
        own = [e for e in entries if e.chosen]
        return (own[0] if own else max(entries, key=lambda e: e[rank])), entries, rank
    pool = [e for e in entries if e.complexity <= settings.max_complexity]
    pool = pool or [min(entries, key=lambda e: e.complexity)]
    pick = max(pool, key=lambda e: e[rank])
    if parts.Zval is not None and settings.finalists > 1:  # one held-out part is noisy: the finalists by K-fold CV
        short = sorted(pool, key=lambda e: -e[rank])[:int(settings.finalists)]
        scored = {id(e): replace(e, r2_cv=cv_r2(e.expression, parts.Ztr, parts.ytr, folds=cv_folds, seed=seed))
                  for e in short}
        entries = [scored.get(id(e), e) for e in entries]
        pick = max((scored[id(e)] for e in short), key=lambda e: e.r2_cv)
        rank = "r2_cv"
    return pick, entries, rank


def paper_formula_result(X, y, test_size: float = 0.2, seed: int = 42) -> dict:
    """The paper's formula evaluated on our data and split: complexity and metrics.

    Parameters
    ----------
    X : (n, d) physical inputs.
    y : (n,) target.
    test_size : share of the test split.
    seed : seed of the split (SPEC §6: 42).

    Returns
    -------
    dict
        ``expression``, ``complexity`` and the train/test metrics.
    """
    symbolic = _symbolic()
    Ztr, Zte, ytr, yte, _, _ = split(X, y, test_size, seed)
    expr = symbolic.compact(symbolic.parse(symbolic.PAPER_FORMULA, Ztr.shape[1]))
    return {"expression": symbolic.PAPER_FORMULA, "complexity": symbolic.node_count(expr),
            **metrics(expr, Ztr, Zte, ytr, yte)}
