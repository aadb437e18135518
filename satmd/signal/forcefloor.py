"""The force sensor's noise floor, told from the force spectrum only where the spectrum shows one.

Force noise biases an FRF towards zero by S_noise / S_force (errors in
variables). `satmd.signal.lpm` removes that bias only where this module finds the
floor; a force that keeps rolling off up to Nyquist gets no correction and a
``force_noise_floor_unseen`` measurement finding (`satmd.signal.chain`) instead.
"""
from __future__ import annotations

from ..conventions import TINY

import numpy as np
from scipy import stats

#: relative std of the median of m exponential bins, times √m: 1 / (2 f(ln 2) ln 2) with f(x) = e^{-x}
_MEDIAN_REL_SD = 1.0 / np.log(2)


def force_noise_floor(power: np.ndarray, f: np.ndarray, start: int, level: float) -> dict:
    """The force sensor's noise floor above the excited band, only where the spectrum shows one.

    A shaker's force does not stop at the band edge: it rolls off (gently or
    steeply, with the shaker's own resonance, pink or coloured), and a roll-off
    is not noise. The noise floor is where the spectrum stops falling: above
    ``start`` the periodogram is cut into blocks whose level is the block median
    / ln 2 (the mean of exponential bins, robust to hum lines); the floor is the
    longest run of blocks that is flat within their scatter, ends in the lowest
    levels, spans at least half an octave and lies 30 dB under the excitation.
    Otherwise the floor cannot be told from the signal: no floor, and
    ``bound`` = the lowest block level, an upper bound on it (signal + noise ≥
    noise), from which the bias that was *not* corrected can be bounded.

    Parameters
    ----------
    power : |X_k|² of the force (rfft bins).
    f : frequencies of the bins [Hz].
    start : first bin clear of the excited band.
    level : the excitation's typical per-bin power.

    Returns
    -------
    dict
        ``floor`` (per-bin E|N_k|², or None), ``bound`` (per-bin upper bound or None), ``status``
        (``estimated``, ``no_plateau``, ``not_below_excitation`` or ``no_region``), ``slope_db_per_octave``
        (of the spectrum's last stretch, when there is no floor) and ``span_hz``.
    """
    region = power[start:]
    m = max(32, region.size // 48)
    n_blocks = region.size // m
    if n_blocks < 6:
        return {"floor": None, "bound": None, "status": "no_region", "slope_db_per_octave": None, "span_hz": None}
    blocks = region[: n_blocks * m].reshape(n_blocks, m)
    fb = f[start: start + n_blocks * m].reshape(n_blocks, m).mean(axis=1)
    lev = np.median(blocks, axis=1) / np.log(2)
    db = 10 * np.log10(np.maximum(lev, TINY))
    sd = 10 / np.log(10) * 1.25 / np.sqrt(m)  # scatter of a block median's level [dB]
    tol = max(1.0, 3.0 * sd)
    # an upper bound on the floor from the lowest block: its median of m exponential bins scatters by
    # 1/(ln 2 √m) relative; the lowest of n_blocks is a minimum, so the margin covers all of them at 1 %
    z = float(stats.norm.isf(0.01 / n_blocks))
    bound = float(lev.min() * (1 + z * _MEDIAN_REL_SD / np.sqrt(m)))
    ref = np.percentile(db, 10)
    near = db <= ref + tol
    best = max(true_runs(near, bridge=1), key=lambda r: r[1] - r[0])
    r0, r1 = best
    run = slice(r0, r1 + 1)
    octaves = np.log2(fb[r1] / max(fb[r0], TINY))
    slope = None
    flat = False
    if r1 - r0 + 1 >= 6 and octaves >= 0.5:
        x = np.log2(fb[run])
        slope = float(np.polyfit(x, db[run], 1)[0])
        flat = abs(slope) * octaves <= tol
    out = {"bound": bound, "span_hz": [float(fb[r0]), float(fb[r1])], "slope_db_per_octave": slope}
    if not flat:
        tail = slice(max(0, n_blocks - max(6, n_blocks // 4)), n_blocks)
        x = np.log2(fb[tail])
        out["slope_db_per_octave"] = float(np.polyfit(x, db[tail], 1)[0]) if np.ptp(x) > 0 else None
        return {**out, "floor": None, "status": "no_plateau"}
    floor = float(np.median(blocks[run]) / np.log(2))
    out["floor_rel_std"] = float(_MEDIAN_REL_SD / np.sqrt(blocks[run].size))
    if floor * 1e3 >= level:  # not 30 dB below the excitation: a flat stretch of force, not noise
        return {**out, "floor": None, "status": "not_below_excitation"}
    return {**out, "floor": floor, "status": "estimated"}


def true_runs(mask, bridge) -> list:
    """(start, end) of each run of True in ``mask``, gaps of at most ``bridge`` False bridged."""
    runs, start, gap = [], None, 0
    for i, m in enumerate(mask):
        if m:
            if start is None:
                start = i
            end, gap = i, 0
        elif start is not None:
            gap += 1
            if gap > bridge:
                runs.append((start, end))
                start, gap = None, 0
    if start is not None:
        runs.append((start, end))
    return runs
