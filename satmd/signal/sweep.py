"""Swept sines: one tone whose frequency moves monotonically, read from the force's analytic signal."""
from __future__ import annotations

import numpy as np

from ..conventions import TINY

SWEEP_RATIO = 1.5  # a sweep spans at least this frequency ratio


def find_sweep(x, fs, detected: bool):
    """A sweep's law from the force's instantaneous frequency; None when the force is not one tone sweeping.

    Parameters
    ----------
    x : the force
    fs : sample rate in Hz
    detected : True when probing (strict), False when the user said it is a sweep

    Returns
    -------
    dict or None
        ``evidence`` and ``sweep``: f_start_hz, f_end_hz, direction, law
        (linear or logarithmic), duration_s and the rate (Hz/s or octaves/s).
    """
    from scipy.signal import hilbert

    x = np.asarray(x, float) - np.mean(x)
    n = x.size
    if n < 256:
        return None
    z = hilbert(x)
    env = np.abs(z)
    active = env > 0.3 * np.percentile(env, 95)
    if active.mean() < 0.2:  # a sweep and its ring-down: the sweep may fill only part of the record
        return None
    idx = np.flatnonzero(active)
    i0, i1 = int(idx[0]), int(idx[-1])
    phase = np.unwrap(np.angle(z[i0:i1 + 1]))
    m = max(8, (i1 - i0) // 200)
    # the instantaneous frequency over blocks (phase advance per block): robust to noise
    edges = np.arange(0, phase.size - m, m)
    if edges.size < 20:
        return None
    f = (phase[edges + m] - phase[edges]) * fs / (2 * np.pi * m)
    e = env[i0:i1 + 1][edges]
    if np.any(f <= 0):
        return None
    steps = np.diff(f)
    up = np.mean(steps > 0)
    monotone = max(up, 1 - up)
    ratio = float(np.max(f) / max(np.min(f), 1e-12))
    cv = float(np.std(e) / max(np.mean(e), TINY))
    if detected and (monotone < 0.9 or ratio < SWEEP_RATIO or cv > 0.35):
        return None
    t = (edges + m / 2) / fs
    lin = np.polyfit(t, f, 1)
    log = np.polyfit(t, np.log(f), 1)
    lin_err = np.std(f - np.polyval(lin, t)) / np.mean(f)
    log_err = np.std(np.log(f) - np.polyval(log, t))
    law = "logarithmic" if log_err < lin_err else "linear"
    f0, f1 = float(np.median(f[:5])), float(np.median(f[-5:]))
    info = {"f_start_hz": f0, "f_end_hz": f1, "direction": "up" if f1 > f0 else "down", "law": law,
            "duration_s": float((i1 - i0) / fs)}
    info["rate_hz_per_s"] = float(lin[0]) if law == "linear" else float(log[0] / np.log(2))  # octaves/s for log
    if law == "logarithmic":
        info["rate_octaves_per_s"] = info.pop("rate_hz_per_s")
    ev = (f"one tone whose frequency moves {info['direction']} from {f0:.4g} to {f1:.4g} Hz "
          f"({100 * monotone:.0f} % of steps one way; envelope varies {100 * cv:.0f} %)")
    return {"sweep": info, "evidence": ev}


__all__ = ["SWEEP_RATIO", "find_sweep"]
