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
from ..physics import dual
from ..physics.kernels import solve_with_tangents
from ..physics.model import Terms, terms
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
    resid, sigma = fit.residuals(), fit.sigma
    sens = _sensitivities(fit)
    # J_c = Σ_k S_ck dT_k (S: the fit's sensitivities, dT_k: the trial's tangent of intermediate k), so
    # Σ_c conj(J_c) r_c / σ_c² and Σ_c |J_c|² / σ_c² need per frequency only S's weighted products
    proj = {k: sum(np.conj(sens[c][:, j]) * (-resid[c] / sigma[c] ** 2) for c in fit.channels)
            for j, k in enumerate(_FIELDS)}
    gram = {(k, m): sum(np.conj(sens[c][:, j]) * sens[c][:, i] / sigma[c] ** 2 for c in fit.channels)
            for j, k in enumerate(_FIELDS) for i, m in enumerate(_FIELDS)}
    num = np.zeros(mesh[0].size)
    den = np.zeros(mesh[0].size)
    rows = max(1, _CHUNK_POINTS // max(freq.size, 1))
    for start in range(0, mesh[0].size, rows):
        sl = slice(start, start + rows)
        trial = new.replace(**{n: m[sl, None] for n, m in zip(names, mesh)}, **{scan.amplitude: base})
        d = _term_tangents(fit, trial, scan.amplitude)
        for k, dk in d.items():
            num[sl] += np.real(np.conj(dk) @ proj[k])
            for m, dm in d.items():
                den[sl] += np.real(np.sum(np.conj(dk) * dm * gram[k, m], axis=-1))
    amp = np.clip(base + num / np.maximum(den, TINY), *scan.amplitude_range)
    gain = np.where(num > 0, num**2 / np.maximum(den, TINY), 0.0)
    order = np.argsort(-gain)[: scan.keep]
    return [{**{n: float(m[i]) for n, m in zip(names, mesh)}, scan.amplitude: float(amp[i])} for i in order]


_CHUNK_POINTS = 1 << 19  # (location x frequency) points per chunk of the scan: ~8 MB a complex array
_FIELDS = ("K1", "Kp", "b", "Z33", "M2", "F0", "s1", "s2")  # the intermediates every parameter acts through


def _sensitivities(fit) -> dict:
    """d(channel)/d(intermediate) of the model of ``fit`` (one rig, no batch): {channel: (F, fields)}."""
    omega = 2.0 * np.pi * np.asarray(fit.freq_hz, dtype=float)
    t = terms(omega, fit.rig, list(fit.effects))
    seeded = {}
    for k in _FIELDS:
        v = getattr(t, k)
        v = 1.0 if v is None else dual.value(v)  # no sensor factor: a factor of 1
        seeded[k] = dual.Dual.variable(np.broadcast_to(np.asarray(v, dtype=complex), omega.shape).copy(), k)
    values = {c: np.empty(omega.size, dtype=complex) for c in fit.channels}
    out = {c: np.empty((omega.size, len(_FIELDS)), dtype=complex) for c in fit.channels}
    solve_with_tangents(Terms(omega=omega, **seeded), _FIELDS, fit.channels, values, out)
    return out


def _term_tangents(fit, trial, amplitude: str) -> dict:
    """{intermediate: d(intermediate)/d(amplitude)} for the intermediates ``trial``'s amplitude moves, (rows, F)."""
    omega = 2.0 * np.pi * np.asarray(fit.freq_hz, dtype=float)
    name = trial.qualified(amplitude)
    seeded = trial.replace(**{amplitude: dual.Dual.variable(trial.params[amplitude], name)})
    t = terms(omega, fit.rig, list(fit.effects) + [seeded])
    rows = np.broadcast_shapes(*(np.shape(v) for v in trial.params.values()), (1,))[:-1] or (1,)
    out = {}
    for k in _FIELDS:
        d = dual.tangent(getattr(t, k), name)
        if d is not None:
            out[k] = np.broadcast_to(np.asarray(d, dtype=complex), rows + omega.shape)
    return out


def amplitude_jacobian(fit, trial, amplitude: str) -> dict:
    """d(channel)/d(``trial``'s ``amplitude``) when ``trial`` (parameters may be (rows, 1) arrays) joins the
    model of ``fit`` at the amplitude's neutral value (where ``trial`` leaves the model as it is):
    {channel: (rows, F)}.

    Exact chain rule through the model's intermediates: only the effects' hooks (`terms`) are evaluated for
    the whole batch; the solve's sensitivities are the fit's own, computed once. Equals the Jacobian
    `frf(..., wrt=[amplitude])` gives, at a fraction of its cost for a long scan.
    """
    sens = _sensitivities(fit)
    d = _term_tangents(fit, trial, amplitude)
    rows = np.broadcast_shapes(*(np.shape(v) for v in trial.params.values()), (1,))[:-1] or (1,)
    out = {}
    for c in fit.channels:
        total = np.zeros(rows + (len(fit.freq_hz),), dtype=complex)
        for j, k in enumerate(_FIELDS):
            if k in d:
                total = total + sens[c][:, j] * d[k]
        out[c] = total
    return out
