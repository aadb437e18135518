"""Small numerical routines more than one package needs, written once (issue 25).

At the floor of the import graph (numpy only): the pick of distinct best starts of a multistart
search, the lag-1 autocorrelation of residual series, every least-squares fit's covariance, and the
forward differences of a costly residual on every core.
"""
from __future__ import annotations

import os

import numpy as np


def distinct_best(values, coords, n: int, min_dist: float, finite_only: bool = True) -> list[int]:
    """Indices of up to ``n`` lowest ``values`` whose ``coords`` lie more than ``min_dist`` apart.

    The multistart pick of identification (Sobol design → least squares), of discovery's effect
    starts and of tuning (Sobol design → Nelder–Mead): walk the points from the best value up and
    keep one when it is farther than ``min_dist`` in max-norm from every point kept so far, so
    that the local runs start in different basins.

    Parameters
    ----------
    values : (N,) objective values (lower is better)
    coords : (N, d) coordinates in which distance is measured (e.g. log-parameters, the unit cube)
    n : most indices returned
    min_dist : the max-norm distance a new point must exceed from every kept one
    finite_only : skip points whose value is not finite (else they are candidates like any other)

    Returns
    -------
    list of int
        Indices into ``values``, best first.
    """
    values = np.asarray(values)
    picked: list[int] = []
    for i in np.argsort(values):
        if finite_only and not np.isfinite(values[i]):
            continue
        if all(np.max(np.abs(coords[i] - coords[j])) > min_dist for j in picked):
            picked.append(int(i))
        if len(picked) == n:
            break
    return picked


def lag1_autocorrelation(series) -> float:
    """Pooled lag-1 autocorrelation of real series along their last axis (≈ 0 for white noise).

    ``Σ z[:, k] z[:, k+1] / Σ z²`` over all series together; the series are used as given (centre
    them first for the sample autocorrelation about their means).

    Parameters
    ----------
    series : (n_series, n) real array (a 1-D array counts as one series)

    Returns
    -------
    float
        0.0 when the series have fewer than 3 points or no power.
    """
    z = np.atleast_2d(series)
    den = float(np.sum(z * z))
    return float(np.sum(z[:, 1:] * z[:, :-1]) / den) if den > 0 and z.shape[1] > 2 else 0.0


def jacobian_covariance(jac, noise_variance: float = 1.0) -> np.ndarray:
    """``noise_variance · (JᵀJ)⁻¹`` of a least-squares fit from its Jacobian: every fit's covariance, written once.

    Columns are scaled to unit norm first (well conditioned whatever the parameters' units); a Jacobian
    that is numerically rank deficient gives NaN (no interval), never a pseudo-inverse's arbitrary one.

    Parameters
    ----------
    jac : (n, p) Jacobian of the (weighted) residuals
    noise_variance : the residuals' variance (1 for residuals already divided by their std)

    Returns
    -------
    ndarray (p, p)
    """
    J = np.asarray(jac)
    J = J.astype(complex if np.iscomplexobj(J) else float)  # complex: (JᴴJ)⁻¹ of complex parameters
    norm = np.linalg.norm(J, axis=0)
    sc = np.where(norm > 0, 1.0 / np.where(norm > 0, norm, 1.0), 1.0)
    A, _ = inverse_gram(J * sc)
    if not np.all(np.isfinite(A)) or not np.all(norm > 0):
        return np.full((J.shape[1], J.shape[1]), np.nan)
    return A * np.outer(sc, sc) * noise_variance


def unit_columns(X):
    """(X with every nonzero column scaled to unit length, the scales): a least squares whose columns differ by
    orders of magnitude (a cubic's column is 1e-8 of a stroke's) otherwise loses the small ones to its rank cut;
    coefficients of the scaled columns divided by the scales are those of X."""
    norm = np.linalg.norm(X, axis=0)
    norm = np.where(norm > 0, norm, 1.0)
    return X / norm, norm


def inverse_gram(Js):
    """(JᵀJ)⁻¹ through the SVD (all inf when J is numerically rank deficient), and the singular values."""
    _, sv, vt = np.linalg.svd(Js, full_matrices=False)
    if sv[-1] <= sv[0] * 1e-14:
        return np.full((sv.size, sv.size), np.inf), sv
    return (vt.conj().T / sv**2) @ vt, sv


def batched_least_squares(residuals, x0, bounds, max_nfev: int, steps=None, rel_step: float = 1e-6, **tolerances):
    """`scipy.optimize.least_squares` (trust region) for a model evaluated for many parameter sets at once.

    The output-error fits (a simulation per parameter set, batched) share this: the residual at x is one
    batched call, and so is the Jacobian (forward differences: x and x + h_i e_i in one batch).

    Parameters
    ----------
    residuals : callable (P, p) -> (P, n), the residual vectors of P parameter sets.
    x0 : (p,) start.
    bounds : (lower, upper).
    max_nfev : most iterations.
    steps : fixed difference steps (p,) (default: ``rel_step`` · max(1, |x|) at each x).
    rel_step : relative step where ``steps`` is None.
    **tolerances : xtol, ftol, gtol of `least_squares` (default 1e-10 for xtol and ftol).

    Returns
    -------
    (OptimizeResult, callable)
        The solution, and the Jacobian function (for a covariance at the end).
    """
    from scipy.optimize import least_squares

    def fun(x):
        return residuals(x[None])[0]

    def jac(x):
        h = steps if steps is not None else rel_step * np.maximum(1.0, np.abs(x))
        X = np.vstack([x] + [x + h[i] * np.eye(x.size)[i] for i in range(x.size)])
        R = residuals(X)
        return ((R[1:] - R[0]) / h[:, None]).T

    opts = {"xtol": 1e-10, "ftol": 1e-10, **tolerances}
    sol = least_squares(fun, x0, jac=jac, bounds=bounds, method="trf", x_scale="jac", max_nfev=max_nfev, **opts)
    return sol, jac


#: threads `threaded_differences` takes at most by default: each holds a simulation of every record (the F-16's,
#: some 200 MB), and a large machine's cores would multiply that
MAX_THREADS = 8


def threaded_differences(fun, rel_step: float, bounds=(-np.inf, np.inf), workers: int | None = None):
    """(fun, jac) for `scipy.optimize.least_squares`: ``fun`` remembering its last value, and its Jacobian by
    forward differences, the steps least squares' own ``'2-point'`` takes with ``diff_step=rel_step`` (each
    ``rel_step · |x|``, √eps at zero, turned back where it would leave ``bounds``), the columns evaluated on ``workers``
    threads. Each column of an output-error fit is a simulation of every record, in compiled code and filters
    that let go of the interpreter's lock: two cores fill two columns at once (each on one BLAS thread: BLAS's own
    threads beside them only wait on each other).

    Parameters
    ----------
    fun : callable (p,) -> (n,), safe to call from several threads at once (it builds, never changes, what it shares)
    rel_step : relative step
    bounds : (lower, upper) of the parameters, as given to least squares
    workers : threads (default: the cores this process may run on, at most `MAX_THREADS`)

    Returns
    -------
    (callable, callable)
    """
    from concurrent.futures import ThreadPoolExecutor
    from contextlib import nullcontext

    last: dict = {}
    workers = workers or cores()

    def value(x):
        f = np.asarray(fun(x), float)
        last["x"], last["f"] = np.array(x, float), f
        return f

    def jac(x):
        x = np.asarray(x, float)
        f0 = last["f"] if "x" in last and np.array_equal(last["x"], x) else value(x)
        lower, upper = (np.broadcast_to(np.asarray(b, float), x.shape) for b in bounds)
        sign = np.where(x >= 0, 1.0, -1.0)
        h = rel_step * sign * np.abs(x)
        h = np.where((x + h) - x == 0, np.sqrt(np.finfo(float).eps) * sign * np.maximum(1.0, np.abs(x)), h)
        below, above = x - lower, upper - x
        fits = np.abs(h) <= np.maximum(below, above)
        h = np.where((x + h < lower) | (x + h > upper), np.where(fits, -h, np.where(above >= below, above, -below)), h)
        shifted = np.tile(x, (x.size, 1))
        shifted[np.diag_indices(x.size)] += h  # row i: x with its i-th parameter stepped
        steps = np.diag(shifted) - x  # the step as floating point takes it
        threads = max(1, min(workers, x.size))
        with one_blas_thread() if threads > 1 else nullcontext(), ThreadPoolExecutor(threads) as pool:
            columns = list(pool.map(lambda s: np.asarray(fun(s), float), shifted))
        return np.column_stack([(c - f0) / d for c, d in zip(columns, steps)]).reshape(f0.size, x.size)

    return value, jac


def cores() -> int:
    """The cores this process may run on, at most `MAX_THREADS`."""
    n = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return min(n, MAX_THREADS)


def side_by_side(calls) -> list:
    """Each of ``calls`` (callables of no argument) called, on the cores' threads, their results in order. For
    whole fits that are independent of each other (a structure's laws at one place): each one's Jacobian columns
    already run side by side (`threaded_differences`), its residuals, its least squares' steps and its checks
    between the fits do not. Each call runs in a copy of the caller's context (its progress listener).

    Parameters
    ----------
    calls : callables, safe to run at once (each builds what it changes)

    Returns
    -------
    list
    """
    import contextvars
    from concurrent.futures import ThreadPoolExecutor

    calls = list(calls)
    if len(calls) < 2 or cores() < 2:
        return [call() for call in calls]
    with ThreadPoolExecutor(min(cores(), len(calls))) as pool:
        futures = [pool.submit(contextvars.copy_context().run, call) for call in calls]
        return [f.result() for f in futures]


def one_blas_thread():
    """A context in which BLAS runs on one thread: tall, thin least-squares problems and many small products run
    faster so than on many (`satmd.modal.fit_modal`, the structure fits)."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def on_one_blas_thread(func):
    """``func`` run with BLAS on one thread. The structure fits' matrices are tall and narrow and their products
    many and small: BLAS's threads cost more than they gain (on two cores the F-16's `discover` took 218 s with
    them and 193 s without, a chain's fit 44 s and 30 s); their parallel work is the Jacobian's columns, each on its
    own thread (`threaded_differences`)."""
    import functools

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with one_blas_thread():
            return func(*args, **kwargs)

    return wrapper


def force_level(force) -> float:
    """The drive level of a recording: the force's RMS about its mean (a load cell's offset is no drive).

    Parameters
    ----------
    force : samples.

    Returns
    -------
    float
    """
    return float(np.std(np.asarray(force, float)))
