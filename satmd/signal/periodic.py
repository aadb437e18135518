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

With M random-phase realisations of P periods each (`multisine_bla`; Pintelon & Schoukens ch. 3-4),
per realisation the FRF ``G_r(k)`` is the same ratio of means (`ratio_of_means`, one estimator for every
periodic test) and the spread over periods its noise variance (noise is not periodic; the distortion is); the best linear approximation (BLA) is the mean
over realisations, and the spread of ``G_r`` over realisations holds noise *and* the stochastic
nonlinear distortion, so ``var_nl = var_total − var_noise`` (M ≥ 2, P ≥ 2). `multisine_frf` gives a
multisine recording's BLA as FRFData; `multisine_arrays` its (M, P, N) periods.
"""
from __future__ import annotations

import numpy as np

from ..conventions import ACCEL_CHANNELS, RECORDING_CHANNELS, TINY
from ..errors import DataError
from .chain import MeasurementFinding


def periodic_spectra(recording, excitation, channel) -> np.ndarray:
    """(P, K) spectra of ``channel`` over the steady periods at the excited lines."""
    n = excitation.period_samples
    x = np.asarray(recording[channel], float)
    blocks = x[: excitation.periods * n].reshape(excitation.periods, n)[list(excitation.steady)]
    return np.fft.rfft(blocks, axis=1)[:, list(excitation.lines)]


def in_band(freq_hz, band_hz) -> np.ndarray:
    """Which of ``freq_hz`` lie in ``band_hz`` = (lo, hi), either None (no bound), or None (all)."""
    lo = -np.inf if not band_hz or band_hz[0] is None else band_hz[0]
    hi = np.inf if not band_hz or band_hz[1] is None else band_hz[1]
    return (freq_hz >= lo) & (freq_hz <= hi)


def coherence_over(U, Y, axis) -> np.ndarray:
    """The ordinary coherence at each line over the spectra's blocks (periods, realisations) along ``axis``."""
    cross = np.abs(np.sum(Y * np.conj(U), axis=axis)) ** 2
    power = np.sum(np.abs(U) ** 2, axis=axis) * np.sum(np.abs(Y) ** 2, axis=axis)
    return np.clip(cross / np.maximum(power, TINY), 0.0, 1.0)


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
    keep = in_band(f, band_hz)
    if keep.sum() < 2:
        raise DataError(f"band {band_hz[0]}:{band_hz[1]} Hz holds {int(keep.sum())} of the {lines.size} lines the "
                        f"periodic force excites ({f[0]:.4g}–{f[-1]:.4g} Hz)")
    U = periodic_spectra(recording, excitation, "force")[:, keep]
    P = U.shape[0]
    frf, std, coh = {}, {}, {}
    for r in responses:
        Y = periodic_spectra(recording, excitation, r)[:, keep]
        G, var = ratio_of_means(U, Y)
        ch = RECORDING_CHANNELS[r]
        frf[ch] = G
        std[ch] = np.sqrt(np.maximum(var, 0.0) / 2.0)
        coh[ch] = coherence_over(U, Y, axis=0)
    return f[keep], frf, std, coh, 2.0 * (P - 1)


def ratio_of_means(U, Y):
    """(G, var): the FRF of one realisation of a periodic test, the mean output spectrum over its periods
    divided by the mean force spectrum, and G's variance from the periods' scatter (noise on both channels,
    correlated or not; first order).

    The estimator of every periodic test here (`periodic_frf`, and each realisation of `multisine_bla`):
    averaging the spectra before dividing keeps the force's noise out of the denominator, where a mean of
    per-period ratios is biased by it (Pintelon & Schoukens, *System Identification*, 2nd ed., §2.5).

    Parameters
    ----------
    U, Y : (P, L) force and response spectra over P periods at L lines

    Returns
    -------
    tuple of (L,) complex G and (L,) real variance of G (NaN with one period)
    """
    P = U.shape[0]
    Um, Ym = U.mean(axis=0), Y.mean(axis=0)
    G = Ym / Um
    if P < 2:
        return G, np.full(G.shape, np.nan)
    dU, dY = U - Um, Y - Ym
    var_u = np.sum(np.abs(dU) ** 2, axis=0) / (P - 1) / P
    var_y = np.sum(np.abs(dY) ** 2, axis=0) / (P - 1) / P
    cov = np.sum(dY * np.conj(dU), axis=0) / (P - 1) / P
    var = (var_y + np.abs(G) ** 2 * var_u - 2.0 * np.real(np.conj(G) * cov)) / np.abs(Um) ** 2
    return G, var


def excitation_findings(excitation) -> list[MeasurementFinding]:
    """What was left out of the estimate (transient periods, a glitch, double or clipped hits), or could not be
    (the first of two periods), in words."""
    out = []
    if excitation.kind == "periodic" and excitation.periods == 2:
        out.append(MeasurementFinding(
            "two_periods", "two periods, both averaged: a start-up transient in the first cannot be told from the "
            "noise, so it is averaged in and counted as noise (2 degrees of freedom)",
            "record 3 or more periods (the first is then left out where it still holds the start-up)"))
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


__all__ = ["excitation_findings", "periodic_frf", "periodic_spectra", "ratio_of_means"]


# --- several realisations: the best linear approximation (moved from discovery, issue 48) ----------------
def periodic_blocks(x, period: int, periods: int | None = None, skip: int = 1) -> np.ndarray:
    """(P, period) blocks of a periodic record, dropping the first ``skip`` periods (transient).

    Parameters
    ----------
    x : (n,) samples; n a multiple of ``period`` (the rest is dropped)
    period : samples per period
    periods : use at most this many periods
    skip : leading periods to drop

    Returns
    -------
    ndarray (P, period)
    """
    x = np.asarray(x, float)
    p = x.size // period
    blocks = x[: p * period].reshape(p, period)[skip:]
    return blocks if periods is None else blocks[:periods]


def multisine_bla(u, y, lines, fs_hz: float) -> dict:
    """Best linear approximation with its noise and nonlinear variances apart (see the module docstring).

    Parameters
    ----------
    u, y : (M, P, N) input and output periods (M realisations, P periods, N samples)
    lines : excited DFT lines of one period
    fs_hz : sample rate

    Returns
    -------
    dict
        ``freq_hz``, ``bla`` (complex), ``var_noise`` and ``var_total`` of the BLA
        (per line; ``var_total`` NaN when M = 1), ``var_nl`` (≥ 0 where
        measurable), ``std`` (per Re/Im part of the BLA), ``M``, ``P``.
    """
    u, y = np.asarray(u, float), np.asarray(y, float)
    if u.ndim == 2:
        u, y = u[None], y[None]
    M, P, N = u.shape
    lines = np.asarray(lines, int)
    U = np.fft.rfft(u, axis=2)[..., lines]
    Y = np.fft.rfft(y, axis=2)[..., lines]
    per = [ratio_of_means(U[m], Y[m]) for m in range(M)]  # each realisation as one periodic test
    Gr = np.array([g for g, _ in per])
    var_noise_r = np.array([v for _, v in per])
    bla = Gr.mean(axis=0)
    var_noise = np.nanmean(var_noise_r, axis=0) / M
    var_total = Gr.var(axis=0, ddof=1) / M if M > 1 else np.full(bla.shape, np.nan)
    var_nl = np.maximum(var_total - var_noise, 0.0)
    best = np.where(np.isfinite(var_total), var_total, var_noise)
    return {"freq_hz": lines * fs_hz / N, "bla": bla, "var_noise": var_noise, "var_total": var_total,
            "var_nl": var_nl, "std": np.sqrt(best / 2.0), "M": M, "P": P}


def is_multisine(recording) -> bool:
    """True for a periodic multisine recording that says its layout (``period_samples``, ``lines`` in meta)."""
    meta = getattr(recording, "meta", {}) or {}
    return "period_samples" in meta and "lines" in meta


def multisine_arrays(recording):
    """(u, {channel: y}, lines): (M, P, N) steady-state periods of a multisine recording (transient dropped)."""
    meta = recording.meta
    n = int(meta["period_samples"])
    per = int(meta.get("periods", recording.n_samples // n))
    m = int(meta.get("realisations", 1))
    skip = int(meta.get("transient_periods", 1 if per > 1 else 0))
    lines = np.array([int(k) for k in str(meta["lines"]).split(",") if k.strip()])

    steady = [int(i) for i in str(meta.get("steady_periods", "")).split(",") if i.strip()]

    def shape(x):
        blocks = np.asarray(x, float)[: m * per * n].reshape(m, per, n)
        return blocks[:, steady] if steady and m == 1 else blocks[:, skip:]

    outs = {ch: shape(recording[c]) for c, ch in zip(("acc1", "acc2"), ACCEL_CHANNELS) if c in recording.channels}
    if not outs:
        outs = {c: shape(recording[c]) for c in recording.channels if c != "force"}
    return shape(recording["force"]), outs, lines


def multisine_frf(recording):
    """FRFData: the best linear approximation of a multisine recording, std from noise + distortion."""
    from ..io.frfdata import FRFData

    u, outs, lines = multisine_arrays(recording)
    U = np.fft.rfft(u, axis=-1)[..., lines]
    chans, std, coherence, info = {}, {}, {}, {}
    for c, y in outs.items():
        b = multisine_bla(u, y, lines, recording.fs_hz)
        chans[c], std[c] = b["bla"], b["std"]
        coherence[c] = coherence_over(U, np.fft.rfft(y, axis=-1)[..., lines], axis=(0, 1))  # every steady period
        share = b["var_nl"] / np.maximum(b["var_total"], TINY)
        if np.isfinite(share).any():  # one realisation holds no estimate of the distortion's variance
            info[f"var_nl/var_total {c}"] = float(np.nanmedian(share))
    meta = {"estimator": "multisine_bla", "realisations": str(u.shape[0]), "periods": str(u.shape[1])}
    meta.update({k: f"{v:.3g}" for k, v in info.items()})
    if "force_rms" in recording.meta:
        meta["force_rms"] = recording.meta["force_rms"]
    return FRFData(b["freq_hz"], chans, std, meta, coherence=coherence)
