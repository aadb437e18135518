"""Grey-box identification: global search + scipy least squares with the analytic Jacobian."""
from __future__ import annotations

import time
from dataclasses import replace
from functools import partial
from numbers import Integral, Real
from typing import Any, Sequence

import numpy as np

from ..validation import NAMES, Interval, Options, SequenceOf, Whole, validate_params
from ..numerics import distinct_best
from ..conventions import DEFAULT_FREE
from ..errors import DataError
from ..io.frfdata import FRFData, require_data
from ..physics import Rig
from ..physics.effects import Effect
from .adequacy import assess_fit
from .problem import SEARCH_RANGES, Problem
from .result import FitResult
from .statistics import build_result, emit_warnings

# The global search and the multi-start fits run on at most this many frequencies (chosen by
# Problem.thinned); only the best start is then refined on all points. Keeps a 16k-point FRF
# within seconds; data with fewer points are used whole, so small fits are unchanged.
SEARCH_POINTS = 512
# The starts are compared, not finished: each stops at this tolerance and only the best is taken on to
# ``tol``. A start in a poor basin crawls at 1e-12 to its evaluation limit (400 steps each on data
# the model cannot fit: 9 s of a copied channel's 9.3 s).
EXPLORE_TOL = 1e-8


@validate_params({
    "rig": [None, Rig],
    "free": [NAMES],
    "channels": [None, NAMES],
    "effects": [SequenceOf(Effect)],
    "start": [None, dict, SequenceOf(dict)],
    "reg": [Interval(Real, 0)],
    "global_search": [bool],
    "n_search": [Interval(Whole, 1, 1 << 20)],
    "n_refine": [Interval(Whole, 1, 1 << 20)],
    "bounds": [None, dict],
    "scale": [Options(("channel", "global"))],
    "max_nfev": [None, Interval(Whole, 1)],
    "tol": [Interval(Real, 0, 1, "both")],
    "seed": [Interval(Integral, 0)],
    "warn": [bool],
})
def identify(
    data: FRFData,
    rig: Rig | None = None,
    free: Sequence[str] = DEFAULT_FREE,
    channels: Sequence[str] | None = None,
    effects: Sequence[Effect] = (),
    start: dict | Sequence[dict] | None = None,
    reg: float = 0.0,
    global_search: bool = True,
    n_search: int = 4096,
    n_refine: int = 4,
    bounds: dict | None = None,
    scale: str = "channel",
    max_nfev: int | None = None,
    tol: float = 1e-12,
    seed: int = 0,
    warn: bool = True,
) -> FitResult:
    """Fit free model parameters to measured FRFs.

    Parameters
    ----------
    data : FRFData
        Measured FRFs; residuals are weighted by its std when present, else
        scaled by max|x*| per channel (paper eq. 13).
    rig : Rig
        Values of the parameters that stay fixed (default: the paper's rig).
    free : names of the parameters to fit (rig fields or ``effect.param``).
    channels : channels to fit (default a1, a2 when present, else all).
    effects : missing-physics effects included in the model.
    start : initial values (dict), or several dicts for a multi-start. They
        are also the nominal values of the relative corrections.
    reg : λ_reg of paper eq. 13. Off by default because it biases the
        answer. With reg > 0 the data term is normalised as a mean over all
        complex entries (as the paper's code), so ``reg=1e-8`` reproduces the
        paper's loss exactly.
    global_search : evaluate a Sobol design of ``n_search`` parameter sets
        (over m2, kp, R, L when free; SPEC §9 ranges) in one batched call
        and refine the best ``n_refine`` with least squares. The true values
        may lie anywhere in those ranges: no good start is needed.
    n_search : size of the Sobol design (rounded up to a power of 2).
    n_refine : distinct best design points refined by least squares.
    bounds : {name: (lo, hi)} overriding the default hard bounds.
    scale : without std in the data, residuals are divided by s = max|x*|
        per channel ("channel", default) or over all fitted channels
        together ("global", paper eq. 13 as the paper's code has it).
    max_nfev : most function evaluations of each least-squares run (None: SciPy's default).
    tol : ftol, xtol and gtol of the least squares that finishes the best start (the starts of a
        multi-start stop at `EXPLORE_TOL` when it is looser: they are compared, not finished).
    seed : seed of the scrambled Sobol design.
    warn : also emit the result's poor-fit and pinned-parameter warnings
        (`satmd.errors.PoorFitWarning`, `PinnedParameterWarning`, both
        `DataWarning`). They are always in ``FitResult.warnings`` (with their
        ``category``). satmd's own packages pass ``warn=False``: they fit
        wrong models on purpose (discovery's model selection) and judge the
        fits themselves.

    Returns
    -------
    FitResult

    Raises
    ------
    DataError
        For inputs that cannot give a meaningful fit: no more frequency
        points than free parameters, non-physical magnitudes, ``reg < 0``,
        start values outside the bounds, invalid search settings.
    """
    require_data(data, "data")
    if channels is not None and len(set(channels)) != len(tuple(channels)):
        raise DataError(f"channels {list(channels)} name a channel twice: its data would count twice")
    t0 = time.perf_counter()
    n_search, n_refine = int(n_search), int(n_refine)
    max_nfev = None if max_nfev is None else int(max_nfev)
    problem = Problem(data, rig, free, channels, effects, bounds, scale)
    starts = _starts(problem, start)
    nominal = starts[0]
    coarse = problem.thinned(SEARCH_POINTS)  # memory and time O(points), not O(points × starts)
    if global_search:
        starts = starts + _search(coarse, n_search, n_refine, seed, starts)
    best: Any = None  # the best local fit (a least-squares result)
    nfev = 0
    explore = max(tol, EXPLORE_TOL) if len(starts) > 1 else tol  # one start: finished where it stops
    for s in starts:
        fit = _local_fit(coarse, s, nominal, reg, max_nfev, explore)
        nfev += fit.nfev
        if best is None or fit.cost < best.cost:
            best = fit
    if global_search and _suspect(coarse, best, nominal):
        # a narrow basin (a lightly damped shunt, a resonance at the band edge) can slip between the
        # design's points: look again, 8x denser and with more starts, before settling for a poor fit
        for s in _search(coarse, 8 * n_search, 4 * n_refine, seed + 1, starts):
            fit = _local_fit(coarse, s, nominal, reg, max_nfev, explore)
            nfev += fit.nfev
            if fit.cost < best.cost:
                best = fit
    if coarse is not problem or explore != tol:  # the best start finished to ``tol``, on every point
        best = _local_fit(problem, coarse.values_from_x(best.x, nominal), nominal, reg, max_nfev, tol)
        nfev += best.nfev
    theta = problem.values_from_x(best.x, nominal)
    result = build_result(problem, theta, nominal, nfev, time.perf_counter() - t0, best, reg)
    result = replace(result, _assessor=partial(assess_fit, refit=identify))  # FitResult.adequacy, on first use
    if warn:
        emit_warnings(result)
    return result


def _suspect(problem: Problem, fit, nominal) -> bool:
    """A best fit that is far outside the noise, or sits on a bound: maybe not the global optimum."""
    theta = problem.values_from_x(fit.x, nominal)
    span = problem.upper - problem.lower
    on_bound = np.any((theta - problem.lower <= 1e-9 * span) | (problem.upper - theta <= 1e-9 * span))
    dof = max(problem.n_data - theta.size, 1)
    return bool(on_bound or (problem.weighted and 2.0 * fit.cost / dof > 3.0))


def _starts(problem: Problem, start) -> list[np.ndarray]:
    base = problem.values()
    if start is None:
        starts: list[dict] = [dict()]
    elif isinstance(start, dict):
        starts = [start]
    else:
        starts = list(start)
    out = []
    for s in starts:
        unknown = set(s) - set(problem.names)
        if unknown:
            raise DataError(f"start names {sorted(unknown)} are not free parameters ({', '.join(problem.names)})")
        theta = np.array([float(s.get(n, b)) for n, b in zip(problem.names, base)])
        # a given start outside the bounds is refused (clipping would silently fit from elsewhere);
        # defaults taken from the rig or effect are only brought inside
        for n, v, p in zip(problem.names, theta, problem.params):
            if n in s and not p.lower <= v <= p.upper:
                raise DataError(f"start {n}={v:g} is outside the bounds [{p.lower:g}, {p.upper:g}] of {n}")
        out.append(np.clip(theta, problem.lower, problem.upper))
    return out


def _search(problem: Problem, n_search, n_refine, seed, starts) -> list[np.ndarray]:
    """Best distinct points of a log-uniform Sobol design over the searchable parameters."""
    idx = [i for i, n in enumerate(problem.names) if n in SEARCH_RANGES]
    if not idx:
        return []
    lo = np.log([SEARCH_RANGES[problem.names[i]][0] for i in idx])
    hi = np.log([SEARCH_RANGES[problem.names[i]][1] for i in idx])
    m = int(np.ceil(np.log2(max(n_search, 2))))
    from scipy.stats import qmc  # imported here: scipy.stats costs 0.3 s at `import satmd`

    u = qmc.Sobol(len(idx), scramble=True, seed=seed).random_base2(m)
    thetas = np.repeat(starts[0][None, :], u.shape[0], axis=0)
    thetas[:, idx] = np.exp(lo + u * (hi - lo))
    cost = problem.batch_cost(thetas)
    # distinct basins: at least 10 % apart in some log-parameter
    picked = distinct_best(cost, np.log(thetas[:, idx]), n_refine, 0.1, finite_only=False)
    return [thetas[k] for k in picked]


def _local_fit(problem: Problem, theta0, nominal, reg, max_nfev, tol):
    """least_squares in relative corrections δ around ``nominal``."""
    scale = problem.scales(nominal)
    x0 = (theta0 - nominal) / scale
    lo, hi = (problem.lower - nominal) / scale, (problem.upper - nominal) / scale
    x0 = np.clip(x0, lo, hi)
    norm = 1.0
    if reg > 0:  # paper's code: mean over all complex entries + λ‖δ‖²
        norm = 1.0 / np.sqrt(problem.n_data / 2)
    sqrt_reg = np.sqrt(reg)

    def fun_jac(x):
        theta = nominal + scale * x
        r, J = problem.residuals_and_jacobian(theta)
        r, J = r * norm, J * (scale * norm)
        if reg > 0:
            r = np.concatenate([r, sqrt_reg * x])
            J = np.vstack([J, sqrt_reg * np.eye(x.size)])
        return r, J

    from scipy.optimize import least_squares  # imported where used: keeps `import satmd` fast

    fun, jac = _split(fun_jac)
    return least_squares(fun, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale="jac",
                         ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev)


def _split(fun_jac):
    """fun(x) and jac(x) sharing one evaluation of fun_jac(x): least_squares asks for both at each x."""
    last = {}

    def part(i):
        def f(x):
            key = x.tobytes()
            if key not in last:
                last.clear()
                last[key] = fun_jac(x)
            return last[key][i]
        return f

    return part(0), part(1)
