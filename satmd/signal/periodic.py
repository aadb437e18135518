"""FRFs of a periodic excitation (multisine, pseudo-random, periodic chirp): the mean over steady periods.

Pintelon & Schoukens, *System Identification* (2012), §2.4 and ch. 3: at each
excited line k of one period, with the spectra ``U_p(k)``, ``Y_p(k)`` of the P
steady periods,

- the FRF is the ratio of the means, ``G = Ȳ / Ū`` (noise on the force and on the
  responses alike: errors-in-variables, no bias to first order);
- its variance is ``(σ²_Y + |G|² σ²_U − 2 Re(conj(G) σ²_YU)) / |Ū|²`` with the
  sample (co)variances of the means over the periods, 2(P − 1) degrees of freedom;
- the lines the force does not excite hold no FRF: nothing is divided by the
  noise there (they are the detection lines of the distortion test,
  `satmd.discovery.nonlinear.periodic`).
"""
from __future__ import annotations

import numpy as np

from ..conventions import RECORDING_CHANNELS, TINY
from ..errors import DataError
from .chain import MeasurementFinding


def periodic_spectra(recording, excitation, channel) -> np.ndarray:
    """(P, K) spectra of ``channel`` over the steady periods at the excited lines."""
    n = excitation.period_samples
    x = np.asarray(recording[channel], float)
    blocks = x[: excitation.periods * n].reshape(excitation.periods, n)[list(excitation.steady)]
    return np.fft.rfft(blocks, axis=1)[:, list(excitation.lines)]


def periodic_frf(recording, excitation, responses, band_hz=None):
    """(freq_hz, frf, std, coherence, noise_dof) at the excited lines within ``band_hz``.

    Parameters
    ----------
    recording : Recording
    excitation : a periodic `satmd.signal.excitation.Excitation`
    responses : recording channels (``acc1``, ``acc2``)
    band_hz : (lo, hi) Hz, either may be None

    Returns
    -------
    tuple
        Frequencies, and per FRF channel (``a1``, ``a2``) the FRF, the std of
        each of its real and imaginary parts, and the coherence over periods;
        the noise degrees of freedom 2(P − 1).
    """
    lines = np.asarray(excitation.lines, int)
    f = lines * recording.fs_hz / excitation.period_samples
    lo = -np.inf if not band_hz or band_hz[0] is None else band_hz[0]
    hi = np.inf if not band_hz or band_hz[1] is None else band_hz[1]
    keep = (f >= lo) & (f <= hi)
    if keep.sum() < 2:
        raise DataError(f"band {band_hz[0]}:{band_hz[1]} Hz holds {int(keep.sum())} of the {lines.size} lines the "
                        f"periodic force excites ({f[0]:.4g}–{f[-1]:.4g} Hz)")
    U = periodic_spectra(recording, excitation, "force")[:, keep]
    P = U.shape[0]
    Um = U.mean(axis=0)
    dU = U - Um
    var_u = np.sum(np.abs(dU) ** 2, axis=0) / (P - 1) / P
    frf, std, coh = {}, {}, {}
    for r in responses:
        Y = periodic_spectra(recording, excitation, r)[:, keep]
        Ym = Y.mean(axis=0)
        dY = Y - Ym
        var_y = np.sum(np.abs(dY) ** 2, axis=0) / (P - 1) / P
        cov = np.sum(dY * np.conj(dU), axis=0) / (P - 1) / P
        G = Ym / Um
        var = (var_y + np.abs(G) ** 2 * var_u - 2.0 * np.real(np.conj(G) * cov)) / np.abs(Um) ** 2
        ch = RECORDING_CHANNELS[r]
        frf[ch] = G
        std[ch] = np.sqrt(np.maximum(var, 0.0) / 2.0)
        coh[ch] = np.clip(np.abs(np.sum(Y * np.conj(U), axis=0)) ** 2
                          / np.maximum(np.sum(np.abs(U) ** 2, axis=0) * np.sum(np.abs(Y) ** 2, axis=0), TINY),
                          0.0, 1.0)
    return f[keep], frf, std, coh, 2.0 * (P - 1)


def excitation_findings(excitation) -> list[MeasurementFinding]:
    """What was left out of the estimate (transient periods, a glitch, double or clipped hits), in words."""
    out = []
    for what, why in excitation.dropped:
        if "transient" in why:
            out.append(MeasurementFinding(
                "transient_periods", f"{what} left out of the average: {why}",
                "nothing to do: the steady periods carry the FRF (start the acquisition later, or record more "
                "periods, to keep more of them)", corrected=True))
        elif "glitch" in why:
            out.append(MeasurementFinding("glitch", f"{what} left out of the average: {why}",
                                          "check the acquisition for dropped or repeated samples", corrected=True))
        else:
            name = ("double_hit" if "double" in why else "clipped_hit" if "clipped" in why
                    else "truncated_hit")
            remedy = {"double_hit": "let the hammer rebound clear of the structure (a firmer, quicker hit)",
                      "clipped_hit": "hit more softly or raise the force channel's input range",
                      "truncated_hit": "leave the response time to ring down before the record ends"}[name]
            out.append(MeasurementFinding(name, f"{what} left out: {why}", remedy, corrected=True))
    return out


__all__ = ["excitation_findings", "periodic_frf", "periodic_spectra"]
