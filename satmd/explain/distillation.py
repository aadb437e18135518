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
from dataclasses import dataclass, field

import numpy as np
from sklearn.metrics import mean_absolute_error, r2_score
from sklearn.model_selection import train_test_split

from ..errors import DataError, SatmdError
from .backends import BACKENDS
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
    each entry a dict with complexity, r2/mae train/test and the expression.
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

    def best_within(self, max_complexity: int, on: str = "r2_test") -> dict | None:
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
            "pareto": [{**p, "expression": str(p["expression"])} for p in self.pareto], "info": self.info,
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


def split(X, y, test_size=0.2, seed=42, zscore=True):
    """z-score X with whole-data statistics (unless ``zscore`` is False), then the
    80/20 split. Returns Z_tr, Z_te, y_tr, y_te, mean, std."""
    X = np.asarray(X, float)
    y = np.asarray(y, float).ravel()
    if X.ndim != 2 or X.shape[0] != y.size:
        raise DataError(f"X must be (n, d) and y (n,); got {X.shape} and {y.shape}")
    keep = np.all(np.isfinite(X), axis=1) & np.isfinite(y)
    X, y = X[keep], y[keep]
    if y.size < 10:
        raise DataError(f"need at least 10 finite samples, got {y.size}")
    mean = X.mean(axis=0) if zscore else np.zeros(X.shape[1])
    std = X.std(axis=0) if zscore else np.ones(X.shape[1])
    std = np.where(std > 0, std, 1.0)
    Z = (X - mean) / std
    Ztr, Zte, ytr, yte = train_test_split(Z, y, test_size=test_size, random_state=seed)
    return Ztr, Zte, ytr, yte, mean, std


def metrics(expr, Ztr, Zte, ytr, yte) -> dict:
    symbolic = _symbolic()
    out = {}
    for part, Z, y in (("train", Ztr, ytr), ("test", Zte, yte)):
        p = symbolic.evaluate(expr, Z)
        ok = np.all(np.isfinite(p))
        out[f"r2_{part}"] = float(r2_score(y, p)) if ok else float("-inf")
        out[f"mae_{part}"] = float(mean_absolute_error(y, p)) if ok else float("inf")
    return out


def cv_r2(expr, Z, y, folds: int = 5, seed: int = 0) -> float:
    """Mean R² of ``expr`` over ``folds``-fold cross-validation, constants refitted
    (`symbolic.polish`) on each fold's training part.

    Parameters
    ----------
    expr : sympy expression in x0..
    Z, y : rows to cross-validate on (never the test rows).
    folds : number of folds.
    seed : seed of the fold assignment.

    Returns
    -------
    float
    """
    from sklearn.model_selection import KFold

    symbolic = _symbolic()
    scores = []
    for fit_rows, held in KFold(int(folds), shuffle=True, random_state=seed).split(Z):
        e = symbolic.polish(expr, Z[fit_rows], y[fit_rows])
        scores.append(metrics(e, Z[fit_rows], Z[held], y[fit_rows], y[held])["r2_test"])
    return float(np.mean(scores))


def pareto_front(entries: list, key: str = "r2_train") -> list:
    """Entries not dominated in (complexity low, ``key`` high), simplest first."""
    front, best = [], -np.inf
    for e in sorted(entries, key=lambda e: (e["complexity"], -e[key])):
        if e[key] > best:
            front.append(e)
            best = e[key]
    return front


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
    given = {"max_complexity": max_complexity, "validation": validation, "finalists": finalists,
             "time_limit": time_limit}
    if backend is None:
        preset = dict(DEFAULT_SEARCH)
        backend = preset.pop("backend")
        options = {**{k: v for k, v in preset.items() if k not in given}, **options}
    else:
        preset = NAMED_DEFAULTS
    given = {k: preset[k] if v is None else v for k, v in given.items()}
    max_complexity, validation, finalists, time_limit = (given[k] for k in ("max_complexity", "validation",
                                                                            "finalists", "time_limit"))
    if backend not in BACKENDS:
        raise SatmdError(f"unknown backend {backend!r}; choose from {', '.join(BACKENDS)}")
    if not 0.0 <= validation < 0.9:
        raise DataError(f"validation must be a share in [0, 0.9), got {validation}")
    symbolic = _symbolic()
    sp = symbolic.sp
    Ztr, Zte, ytr, yte, mean, std = split(X, y, test_size, seed, zscore)
    d = Ztr.shape[1]
    names = tuple(names) if names is not None else tuple(f"x{i}" for i in range(d))
    if validation:
        Zfit, Zval, yfit, yval = train_test_split(Ztr, ytr, test_size=validation, random_state=seed + 1)
    else:
        Zfit, yfit, Zval, yval = Ztr, ytr, None, None
    if backend in ("skeleton", "hybrid"):
        options.setdefault("budget", max_complexity if max_complexity is not None else 20)
    t0 = time.perf_counter()
    search_seed = seed if search_seed is None else search_seed
    candidates, chosen, info = BACKENDS[backend](Zfit, yfit, seed=search_seed, n_threads=n_threads,
                                                 time_limit=time_limit, **options)
    search_s = time.perf_counter() - t0
    if polish is None:
        polish = not (backend == "sindy" and not options.get("rational", False))
    prune = polish if prune is None else prune

    def finish(expr, Z, yy):
        if polish:
            expr = symbolic.polish(expr, Z, yy)
        if prune:
            expr = symbolic.prune(expr, Z, yy)
        return symbolic.round_floats(symbolic.compact(symbolic.round_floats(expr, digits)), digits)

    def entry(expr, is_chosen=False):
        e = {"complexity": symbolic.node_count(expr), **metrics(expr, Ztr, Zte, ytr, yte), "expression": expr,
             "_chosen": is_chosen}
        if Zval is not None:
            e["r2_val"] = metrics(expr, Zval, Zval, yval, yval)["r2_train"]
        return e

    entries, seen = [], set()
    for i, text in enumerate(candidates):
        expr = symbolic.parse(text, d) if isinstance(text, str) else sp.sympify(text)
        expr = finish(expr, Zfit, yfit)
        key = sp.srepr(expr)
        if key in seen:
            continue
        seen.add(key)
        entries.append(entry(expr, i == chosen))
    if not entries:
        raise SatmdError(f"the {backend} backend returned no expression")
    rank = "r2_val" if Zval is not None else "r2_train"
    if max_complexity is not None:
        pool = [e for e in entries if e["complexity"] <= max_complexity]
        pool = pool or [min(entries, key=lambda e: e["complexity"])]
        pick = max(pool, key=lambda e: e[rank])
        if Zval is not None and finalists > 1:  # one held-out part is noisy: the finalists by K-fold CV
            short = sorted(pool, key=lambda e: -e[rank])[:int(finalists)]
            for e in short:
                e["r2_cv"] = cv_r2(e["expression"], Ztr, ytr, folds=cv_folds, seed=seed)
            pick = max(short, key=lambda e: e["r2_cv"])
            rank = "r2_cv"
    else:
        own = [e for e in entries if e["_chosen"]]
        pick = own[0] if own else max(entries, key=lambda e: e[rank])
    if Zval is not None:  # the chosen structure's constants from all training rows
        refit = entry(finish(pick["expression"], Ztr, ytr), pick["_chosen"])
        if max_complexity is None or refit["complexity"] <= max(max_complexity, pick["complexity"]):
            entries.append(refit)
            pick = refit
    front = pareto_front(entries)
    seconds = time.perf_counter() - t0
    clean = tuple({k: v for k, v in e.items() if k != "_chosen"} for e in front)
    info = {**info, "search_s": search_s, "n_candidates": len(entries), "validation": validation,
            "chosen_on": rank}
    return DistillResult(backend, pick["expression"], pick["complexity"], pick["mae_train"], pick["mae_test"],
                         pick["r2_train"], pick["r2_test"], clean, seconds, names, mean, std, len(ytr), len(yte),
                         info)


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
