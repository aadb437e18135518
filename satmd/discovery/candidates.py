"""Candidate effects and where to start fitting them.

Every registered effect is a candidate (`satmd.physics.effects`). Its own
declarations say where a fit starts: the grid of its parameters' declared
starts, or, for an effect with a location (a `MatchedFilter` scan), a
matched-filter scan over the measured band. All starts of one candidate are
screened in one batched model call with the other parameters held at the
current fit, and only the best few are refined.
"""
from __future__ import annotations

import numpy as np

from ..conventions import TINY
from ..physics import frf
from ..physics.effects import registered_names

GRID_REFINE = 2  # distinct best grid starts refined by least squares


def default_candidates() -> tuple[str, ...]:
    """Every effect name the vocabulary knows (SPEC §8 plus registered ones)."""
    return registered_names()


def candidate_starts(new, fit, rig) -> tuple[list[dict], int]:
    """Starting values of ``new``'s own parameters when it joins the model of ``fit``,
    and how many distinct best of them to refine."""
    if new.scan is None:
        return new.starts(rig), GRID_REFINE
    return matched_filter(new, fit), new.scan.refine


def matched_filter(new, fit) -> list[dict]:
    """Scan ``new`` over the band as its `MatchedFilter` declares: for every location and
    shape the amplitude enters linearly near its neutral value, so the best amplitude and the
    χ² it removes follow in closed form from one batched Jacobian at the neutral amplitude."""
    scan = new.scan
    freq = fit.freq_hz
    lo, hi = float(freq[0]), float(freq[-1])
    grid = [np.geomspace(lo, hi, int(np.ceil(np.log(hi / lo) / np.log(1 + scan.step))) + 1)]
    grid += [np.asarray(v) for v in scan.shapes.values()]
    mesh = [g.ravel() for g in np.meshgrid(*grid, indexing="ij")]
    names = [scan.location, *scan.shapes]
    base = new.neutral[scan.amplitude]
    trial = new.replace(**dict(zip(names, mesh)), **{scan.amplitude: base})
    r = frf(freq, fit.rig, list(fit.effects) + [trial], wrt=[trial.qualified(scan.amplitude)], outputs=fit.channels)
    resid, sigma = fit.residuals(), fit.sigma
    num = np.zeros(mesh[0].size)
    den = np.zeros(mesh[0].size)
    for c in fit.channels:
        J = r.jac[c][..., 0] / sigma[c]  # (N, F)
        num += np.real(np.sum(np.conj(J) * (-resid[c] / sigma[c]), axis=-1))  # against data - model
        den += np.sum(np.abs(J) ** 2, axis=-1)
    amp = np.clip(base + num / np.maximum(den, TINY), *scan.amplitude_range)
    gain = np.where(num > 0, num**2 / np.maximum(den, TINY), 0.0)
    order = np.argsort(-gain)[: scan.keep]
    return [{**{n: float(m[i]) for n, m in zip(names, mesh)}, scan.amplitude: float(amp[i])} for i in order]
