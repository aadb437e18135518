"""Small numerical routines more than one package needs, written once (issue 25).

At the floor of the import graph (numpy only): the pick of distinct best starts of a multistart
search, and the lag-1 autocorrelation of residual series.
"""
from __future__ import annotations

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
