"""Statistical (Gaussian) equivalent linearisation of a rig with nonlinear elements at a drive level.

For a random force, each element is replaced by the linear parameter value a
linear fit at that level sees (`NonlinearElement.equivalent_value`); the RMS
of the signals it reads follow from the equivalent linear rig's FRF and the
force spectrum, so the two are iterated to their fixed point.
"""
from __future__ import annotations

from ...conventions import PAPER_BAND_HZ, TINY

import numpy as np

from ...errors import DataError
from ..model import frf
from ..rig import Rig

_SIGNALS = ("d", "v", "u1", "v1", "i")


def _force_psd(band_hz, force_rms, force, fs_hz, n_grid):
    """(freq, one-sided PSD [N²/Hz]) of the force: a flat band, or the Welch PSD of a sampled force."""
    if force is None:
        lo, hi = float(band_hz[0]), float(band_hz[1])
        if not 0 < lo < hi:
            raise DataError(f"band {lo:g}:{hi:g} Hz must satisfy 0 < lo < hi")
        f = np.linspace(lo, hi, n_grid)
        return f, np.full(f.size, float(force_rms) ** 2 / (hi - lo))
    from scipy.signal import welch

    force = np.asarray(force, float)
    if fs_hz is None or fs_hz <= 0:
        raise DataError("response_rms: a sampled force needs fs_hz > 0")
    nper = int(min(force.size, 8 * fs_hz))
    f, p = welch(force, fs_hz, nperseg=nper)
    keep = (f > 0) & (p > 1e-12 * p.max())
    f, p = f[keep], p[keep]
    # refine onto a fine grid so sharp resonances are resolved
    fine = np.linspace(f[0], f[-1], max(n_grid, f.size))
    return fine, np.interp(fine, f, p)


def response_rms(rig: Rig, band_hz=PAPER_BAND_HZ, force_rms: float = 1.0, force=None, fs_hz=None,
                 n_grid: int = 6000) -> dict:
    """RMS of the signals elements read, for the linear rig under a random force.

    Parameters
    ----------
    rig : Rig (scalar or a batch; the RMS then has the batch's shape).
    band_hz : (lo, hi) of a flat (white) force band.
    force_rms : RMS of that force [N].
    force : optional sampled force [N]; its Welch PSD replaces the flat band.
    fs_hz : sample rate of ``force``.
    n_grid : points of the frequency grid the PSD is integrated on.

    Returns
    -------
    dict
        {"d", "v", "u1", "v1", "i"}: RMS of u2 - u1 [m], its rate [m/s], u1 [m], u1' [m/s],
        the shunt current q' [A].
    """
    f, psd = _force_psd(band_hz, force_rms, force, fs_hz, n_grid)
    r = frf(f, rig, outputs=("u1", "u2", "q"))
    jw = 2j * np.pi * f
    u1, u2, q = r.channel("u1"), r.channel("u2"), r.channel("q")
    d = u2 - u1
    sig = {"d": d, "v": jw * d, "u1": u1, "v1": jw * u1, "i": jw * q}
    return {k: np.sqrt(np.trapezoid(np.abs(x) ** 2 * psd, f, axis=-1)) for k, x in sig.items()}


def equivalent_rig(rig: Rig, elements, band_hz=PAPER_BAND_HZ, force_rms: float = 1.0, force=None, fs_hz=None,
                   iterations: int = 60, rtol: float = 1e-8, n_grid: int = 6000):
    """The equivalent linear rig at a drive level (statistical linearisation iterated to its fixed point).

    Parameters
    ----------
    rig : Rig, the small-signal (linear) rig.
    elements : sequence of NonlinearElement.
    band_hz, force_rms, force, fs_hz : the force, as in `response_rms`.
    iterations : at most this many fixed-point steps (damped by half when they oscillate).
    rtol : stop when the equivalent values change by less than this (relative).
    n_grid : points of the frequency grid the RMS are integrated on.

    Returns
    -------
    (Rig, dict, list)
        The equivalent rig, the signals' RMS at the fixed point, and one `EquivalentLinear` per element.
    """
    current = rig
    rms = response_rms(current, band_hz, force_rms, force, fs_hz, n_grid)
    prev = None
    for it in range(iterations):
        changes: dict = {}
        eqs = []
        for el in elements:
            eq = el.equivalent_linear(rig, rms)
            eqs.append(eq)
            changes[eq.parameter] = changes.get(eq.parameter, 0.0) + (np.asarray(eq.value, float) - eq.nominal)
        values = {p: np.asarray(getattr(rig, p), float) + dv for p, dv in changes.items()}
        values = {p: np.maximum(v, 1e-6 * np.abs(np.asarray(getattr(rig, p), float))) for p, v in values.items()}
        if prev is not None:
            step = max(float(np.max(np.abs(values[p] - prev[p]) / np.maximum(np.abs(prev[p]), TINY)))
                       for p in values)
            if step < rtol:
                break
            if it > 5:  # damp: a hardening spring can make the plain iteration oscillate
                values = {p: 0.5 * (values[p] + prev[p]) for p in values}
        prev = values
        current = rig.replace(**{p: v if np.ndim(v) else float(v) for p, v in values.items()})
        rms = response_rms(current, band_hz, force_rms, force, fs_hz, n_grid)
    return current, rms, eqs
