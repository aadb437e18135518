"""Confidence intervals of a fit: profile likelihood, and their text and JSON forms.

`FitResult.confidence_intervals` calls `profile_intervals` with its problem;
`describe_interval` and `intervals_to_dict` present the result.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import DataError
from .covariance import naive_variance


def profile_intervals(problem, result, level: float = 0.95, names=None, max_steps: int = 12) -> dict:
    """Profile-likelihood intervals {name: (lo, hi)} of a fit (`FitResult.confidence_intervals`).

    For each parameter the others are re-optimised along a scan outwards from
    the fit (`_scan`); the threshold on Δχ² is the χ²₁ quantile with given std,
    else the Student-t quantile squared times the noise variance, scaled by
    the sandwich-to-naive variance ratio. Open sides are ±inf.
    """
    from scipy import stats  # heavy: imported where used, not at `import satmd`
    from scipy.optimize import least_squares

    from .problem import Problem

    check_level(level)
    p = problem
    noise_factor = 1.0 if result.weighted else result.chi2_reduced  # noise variance factor of χ²
    _, J = p.residuals_and_jacobian(result.theta)
    free = np.array([n not in result.pinned for n in result.names])
    naive = naive_variance(J, p.scales(result.theta), free, noise_factor)
    out = {}
    for name in names or result.names:
        if name not in result.names:
            raise DataError(f"{name!r} is not a fitted parameter ({', '.join(result.names)})")
        i = result.names.index(name)
        if result.weighted:
            delta = stats.chi2.ppf(level, 1)
        else:
            q2 = stats.t.ppf(0.5 + level / 2, result.dof) ** 2
            ratio = result.std[name] ** 2 / naive[i]  # sandwich / naive variance (1 for homoscedastic noise)
            delta = q2 * noise_factor * (ratio if math.isfinite(ratio) and ratio > 0 else 1.0)
        others = [n for n in result.names if n != name]
        best = result.theta
        sd = result.std[name]
        s = sd if math.isfinite(sd) and sd > 0 else abs(best[i]) * 1e-3 + 1e-12
        sub_bounds = {q.name: (q.lower, q.upper) for q in p.params if q.name != name}

        def profile(v, x_start):
            """Δχ² at θ_i = v with the others re-optimised from x_start; and their optimum."""
            theta = np.where(np.arange(len(best)) == i, v, best)
            if not others:
                return float(np.sum(p.residuals(np.array([v])) ** 2)) - result.chi2, x_start
            rig, effects = p.apply(theta)
            sub = Problem(p.data, rig, others, p.channels, effects, sub_bounds, p.scale_mode)
            x0 = np.clip(x_start, sub.lower, sub.upper)
            sc = sub.scales(x0)

            def fj(x):
                r, J = sub.residuals_and_jacobian(x0 + sc * x)
                return r, J * sc

            fit = least_squares(lambda x: fj(x)[0], np.zeros_like(x0), jac=lambda x: fj(x)[1],
                                bounds=((sub.lower - x0) / sc, (sub.upper - x0) / sc), method="trf",
                                x_scale="jac", max_nfev=100)
            return 2 * fit.cost - result.chi2, x0 + sc * fit.x

        ends = []
        for direction in (-1, 1):
            lim = p.params[i].lower if direction < 0 else p.params[i].upper
            ends.append(_scan(profile, best[i], np.delete(best, i), direction, lim, s, delta, max_steps))
        out[name] = tuple(ends)
    return out


def describe_interval(lo: float, hi: float) -> str:
    """Text for a profile interval, naming open sides.

    Parameters
    ----------
    lo, hi : ends of the interval; -inf / +inf for an open side.

    Returns
    -------
    str
        e.g. ``[0.51, unbounded above]``.
    """
    a = f"{lo:.8g}" if math.isfinite(lo) else "unbounded below"
    b = f"{hi:.8g}" if math.isfinite(hi) else "unbounded above"
    return f"[{a}, {b}]"


def intervals_to_dict(intervals: dict) -> dict:
    """Profile intervals as JSON-ready data (no inf).

    Parameters
    ----------
    intervals : {name: (lo, hi)} from `FitResult.confidence_intervals`.

    Returns
    -------
    dict
        ``{"intervals": {name: [lo, hi]}, "open": {name: "unbounded above"}}``
        with None for an open side, named in ``open``.
    """
    out = {n: [lo if math.isfinite(lo) else None, hi if math.isfinite(hi) else None]
           for n, (lo, hi) in intervals.items()}
    open_sides = {n: ("unbounded below" if v[0] is None else "") + (" and " if v[0] is None and v[1] is None else "")
                  + ("unbounded above" if v[1] is None else "") for n, v in out.items() if None in v}
    return {"intervals": out, "open": open_sides}


def check_level(level):
    """Refuse a confidence level outside (0, 1) with a `DataError`."""
    if not (isinstance(level, (int, float, np.floating)) and 0 < level < 1):
        raise DataError(f"level must be in (0, 1), got {level!r}")


def _scan(profile, start, x_best, direction, lim, step, delta, max_steps):
    """Where Δχ²(θ_i) crosses ``delta`` going from ``start`` towards ``lim``; ±inf when it never does.

    Doubling steps outwards, then bisection. Every evaluation starts from the
    others' optimum at the last point known inside the interval, so the
    bracket [inside, outside] stays valid even when the profile is not
    monotone (brentq needs a sign change that re-optimisation may not give).
    """
    inside, x_in, v = start, x_best, start
    for _ in range(max_steps):
        v = start + direction * step
        if (v - lim) * direction >= 0:
            v = lim
        g, x = profile(v, x_in)
        if g > delta:
            break
        if v == lim:
            return direction * np.inf
        inside, x_in, step = v, x, step * 2
    else:
        return direction * np.inf
    outside, tol = v, abs(v - inside) * 1e-4
    for _ in range(60):
        if abs(outside - inside) <= max(tol, 1e-12 * abs(inside)):
            break
        mid = 0.5 * (inside + outside)
        g, x = profile(mid, x_in)
        if g > delta:
            outside = mid
        else:
            inside, x_in = mid, x
    return float(0.5 * (inside + outside))
