"""Search back ends of `satmd.explain.distill`: each returns candidate expressions.

A back end takes z-scored training data and returns ``(candidates, chosen)``:
infix strings (or sympy expressions) in x0..x{d-1}, and the index of the
candidate the back end itself would pick (its model-selection rule).
"""
from __future__ import annotations

import importlib.util
import os
import shutil

import numpy as np

from ..errors import SatmdError

#: Operators of the paper's search (+ − × / square).
OPERON_SYMBOLS = "add,sub,mul,div,square,constant,variable"


def operon(Z, y, *, seed=42, n_threads=1, time_limit=None, max_length=15, max_depth=8, generations=300,
           population_size=500, optimizer_iterations=5, search_samples=None, restarts=1, **extra):
    """pyoperon's NSGA-II over (R², tree length): the Pareto front's trees.

    ``search_samples``: run the search on a random subset of that many training
    rows (constants are polished on all of them afterwards); ``None``: all.
    ``restarts``: independent searches from seeds ``seed, seed + 1, ...``
    (``time_limit`` is shared among them); their fronts are pooled and
    `satmd.explain.distill` chooses among them (on a validation part when asked).
    """
    try:
        from pyoperon.sklearn import SymbolicRegressor
    except ImportError as exc:
        raise SatmdError("the operon backend needs pyoperon: pip install 'satmd[symbolic]'") from exc
    restarts = max(1, int(restarts))
    candidates, chosen, gens = [], None, []
    names = [f"x{i}" for i in range(Z.shape[1])]
    for r in range(restarts):
        rng = np.random.default_rng(seed + r)
        Zr, yr = Z, y
        if search_samples and search_samples < len(y):
            idx = rng.choice(len(y), int(search_samples), replace=False)
            Zr, yr = Z[idx], y[idx]
        options = dict(allowed_symbols=OPERON_SYMBOLS, objectives=["r2", "length"], max_length=int(max_length),
                       max_depth=int(max_depth), generations=int(generations), population_size=int(population_size),
                       optimizer_iterations=int(optimizer_iterations), n_threads=int(n_threads),
                       random_state=int(seed + r), max_evaluations=10**9)
        if time_limit:
            options["max_time"] = max(1, int(time_limit / restarts))
        options.update(extra)
        reg = SymbolicRegressor(**options)
        reg.fit(np.asarray(Zr, float), np.asarray(yr, float))
        candidates += [reg.get_model_string(p["tree"], 8, names=names) for p in reg.pareto_front_]
        if r == 0:  # operon's own (MDL) pick of the first search
            chosen = len(candidates)
            candidates.append(reg.get_model_string(reg.model_, 8, names=names))
        gens.append(int(reg.stats_.get("generations", -1)))
    return candidates, chosen, {"generations": gens[0] if restarts == 1 else gens, "restarts": restarts}


def skeleton(Z, y, *, seed=42, n_threads=1, time_limit=None, budget=20, **extra):
    """Every product skeleton within ``budget`` nodes, constants by variable
    projection (`satmd.explain.skeletons`): deterministic, no dependency beyond SciPy.
    ``n_threads`` is accepted for a uniform interface (the pass is serial)."""
    from .skeleton_search import search

    found, info = search(Z, y, budget=int(budget), seed=int(seed), time_limit=time_limit, **extra)
    return [text for _, text in found], None, info


def hybrid(Z, y, *, seed=42, n_threads=1, time_limit=None, budget=20, operon_share=0.35, skeleton_options=None,
           **operon_options):
    """operon's searches (the simple end of the front and whatever shapes it
    invents) pooled with the skeleton pass (the dense end, at the node budget).

    ``time_limit`` is split: ``operon_share`` of it for operon, the rest for the skeletons.
    Without pyoperon installed the skeleton pass runs alone (``info["operon"]`` says so).
    """
    share = float(operon_share)
    if importlib.util.find_spec("pyoperon") is None:  # the skeleton pass needs only SciPy: go on without operon
        op_cands, chosen, op_info, share = [], None, {"operon": "not installed (pip install 'satmd[symbolic]')"}, 0.0
    else:
        op_cands, chosen, op_info = operon(Z, y, seed=seed, n_threads=n_threads,
                                           time_limit=None if time_limit is None else share * time_limit,
                                           **operon_options)
    sk_cands, _, sk_info = skeleton(Z, y, seed=seed, time_limit=None if time_limit is None
                                    else (1.0 - share) * time_limit, budget=budget, **(skeleton_options or {}))
    return op_cands + sk_cands, chosen, {**op_info, **sk_info, "operon_candidates": len(op_cands)}


def julia_runtime() -> str | None:
    """Path of a Julia executable PySR could use, or None (never imports pysr/juliacall)."""
    for var in ("PYTHON_JULIAPKG_EXE", "JULIA_EXE"):
        path = os.environ.get(var)
        if path and os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    bindir = os.environ.get("JULIA_BINDIR")
    if bindir and os.path.isfile(os.path.join(bindir, "julia")):
        return os.path.join(bindir, "julia")
    return shutil.which("julia")


def pysr(Z, y, *, seed=42, n_threads=1, time_limit=None, maxsize=20, niterations=40, **extra):
    """PySR with the paper's operators; only when a Julia runtime is present.

    Importing pysr without Julia starts a download, so the runtime is checked first.
    """
    if julia_runtime() is None:
        raise SatmdError("the pysr backend needs a Julia runtime (julia not found on PATH); use backend='operon'")
    if importlib.util.find_spec("pysr") is None:
        raise SatmdError("the pysr backend needs pysr: pip install 'satmd[pysr]' (and a Julia runtime)")
    from pysr import PySRRegressor  # noqa: E402 - deliberately late: see the docstring

    names = [f"x{i}" for i in range(Z.shape[1])]
    options = dict(binary_operators=["+", "-", "*", "/"], unary_operators=["square"], maxsize=int(maxsize),
                   niterations=int(niterations), random_state=int(seed), deterministic=True, parallelism="serial",
                   progress=False, verbosity=0)
    if time_limit:
        options["timeout_in_seconds"] = float(time_limit)
    options.update(extra)
    model = PySRRegressor(**options)
    model.fit(np.asarray(Z, float), np.asarray(y, float), variable_names=names)
    eqs = model.equations_
    candidates = [str(e) for e in eqs["sympy_format"]]
    best = model.get_best()
    chosen = int(np.flatnonzero((eqs["equation"] == best["equation"]).to_numpy())[0])
    return candidates, chosen, {}


def sindy(Z, y, *, seed=42, n_threads=1, time_limit=None, degree=3, rational=False, thresholds=None, alpha=1e-6,
          **extra):
    """Sparse regression (PySINDy's STLSQ) over a polynomial library, as a static fit.

    No derivatives are involved: the optimiser fits ``y ≈ Θ(x) ξ`` directly on
    the library matrix Θ. With ``rational=True`` the library also holds
    ``-y q(x)`` for the non-constant polynomial terms q, the linearised form
    of ``y = p(x) / (1 + q(x))`` (as in SINDy-PI). Each threshold of
    ``thresholds`` gives one candidate (one sparsity level). ``seed``,
    ``n_threads`` and ``time_limit`` are accepted for a uniform interface (the
    fit is deterministic and takes well under a second).
    """
    try:
        import pysindy as ps
    except ImportError as exc:
        raise SatmdError("the sindy backend needs pysindy: pip install 'satmd[symbolic]'") from exc
    Z = np.asarray(Z, float)
    y = np.asarray(y, float)
    names = [f"x{i}" for i in range(Z.shape[1])]
    lib = ps.PolynomialLibrary(degree=int(degree)).fit(Z)
    P = lib.transform(Z)
    terms = [t.replace(" ", "*").replace("^", "**") for t in lib.get_feature_names(names)]
    theta = np.concatenate([P, -y[:, None] * P[:, 1:]], axis=1) if rational else P
    scale = np.linalg.norm(theta, axis=0) / np.sqrt(len(y))
    scale = np.where(scale > 0, scale, 1.0)
    thresholds = np.geomspace(1e-3, 0.3, 12) if thresholds is None else np.atleast_1d(thresholds)
    candidates = []
    for thr in thresholds:
        opt = ps.STLSQ(threshold=float(thr), alpha=float(alpha), max_iter=50, **extra)
        opt.fit(theta / scale, y[:, None])
        coef = np.ravel(opt.coef_) / scale
        num = " + ".join(f"({c:.10g})*({t})" for c, t in zip(coef[:P.shape[1]], terms) if c != 0) or "0"
        if rational:
            den = " + ".join(f"({c:.10g})*({t})" for c, t in zip(coef[P.shape[1]:], terms[1:]) if c != 0) or "0"
            candidates.append(f"({num}) / (1 + {den})")
        else:
            candidates.append(num)
    return candidates, None, {"library": f"polynomial degree {degree}" + (", rational" if rational else "")}


BACKENDS = {"operon": operon, "pysr": pysr, "sindy": sindy, "skeleton": skeleton, "hybrid": hybrid}
