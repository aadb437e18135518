"""Modes above the force's band, seen through the joint's harmonics (SPEC §11: predict what was not measured).

A multisine puts nothing above its band, so the lowest level's FRF knows no mode there; but a joint's force
carries harmonics and sum frequencies of the band, and where they reach a mode just above it the response at
the lines the force does not excite can be most of a sensor's RMS (on independent ground vibration tests,
`benchmarks/structures_gvt.py`, the held-out levels' worst errors were that share almost entirely). The
joint's force is an input like the shaker's (FNSI's feedback form, Noël & Kerschen 2013): at a line above the
band, each channel's response is the joint's column there times the spectrum of g(d, v), the law evaluated on
the measured stroke. What the modes in the model leave of it is fitted by a few more poles (vector fitting),
whose residues T are the joint's column alone: the force reaches them only through their tails, which the
lowest level's fit already holds in its flat terms, so they join the model with ``T = A κ`` at a large κ (the
shaker's path through them 1e-6 of the joint's, at the scale of the joint's path to the other modes).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY
from .linear import LinearStructure
from .startup import band_top_hz

MAX_PAIRS = 4          # poles tried above the band
TOP_SHARE = 0.8        # of the Nyquist frequency: beyond it an acquisition's anti-alias filter takes the response
GAIN = 1e6             # κ of a mode the joint alone drives over the largest of the others' (its shaker residue is T/κ)
MIN_GAIN = 0.3         # the fit must explain this share of what the model leaves above the band
RISING = 2.0           # ... where what the found poles leave rises this much toward the lines' top (`_rising`)
BEYOND_AT, BEYOND_ZETA = 0.95, 0.02  # a loop's start beyond the lines seen: at this share of Nyquist (`loop.TOP`)


def above_band(model, spectra, apart: float = 0.0):
    """``model`` with modes above the force's band that the joint's harmonics drive, where they explain most
    of what the model leaves at the lines above the band (on every level but the lowest); else ``model``.

    Parameters
    ----------
    model : StructureModel with a joint (its start: coefficients and path from the spectra)
    spectra : the levels' `PeriodicSpectra` (with each channel's whole spectrum, `PeriodicSpectra.whole`)
    apart : a set of added modes is refused where one lies within this share of another's frequency (0: none
        refused). A cluster of lightly damped poles can fit the harmonics of the fitted levels and ring at
        others (`fit.fit_structure` finishes the model both ways and keeps the one that simulates best)

    Returns
    -------
    StructureModel
    """

    blocks = _blocks(model, spectra)
    if not blocks:
        return model
    before = sum(float(np.sum(np.abs(E * W) ** 2)) for _, _, E, W, _ in blocks)
    best, best_rss = None, before
    band_top = band_top_hz(spectra)
    lin = model.linear
    for pairs in range(1, MAX_PAIRS + 1):
        poles = _poles_above(blocks, pairs, band_top)
        if poles.size == 0 or _crowded(poles, lin.poles, apart):
            continue
        T, rss = _residues(poles, blocks)
        n_rows = sum(2 * E.size for _, _, E, _, _ in blocks)
        penalty = 2 * poles.size * T.shape[0] * np.log(n_rows) * before / n_rows  # BIC's, in the RSS's units
        if rss + penalty < best_rss:
            best, best_rss = (poles, T), rss + penalty
    if best is None or best_rss > (1 - MIN_GAIN) * before:
        return model
    poles, T = best
    kappa = np.asarray(model.joint.coupling, complex)
    # in relative units the path's size is the joint force's unit (on a chain 1e9-1e11): a gain of 1e6 alone let
    # the shaker drive the added modes 1e4 times harder than the joint does, and the linear part ran away
    gain = GAIN * (float(np.max(np.abs(kappa), initial=0.0)) or 1.0)
    extra = LinearStructure(lin.channels, np.concatenate([lin.poles, poles]),
                            np.hstack([lin.residues, T / gain]), lin.feedthrough)
    joint = replace(model.joint, coupling=np.concatenate([kappa, np.full(poles.size, gain, complex)]))
    return replace(model, linear=extra, joint=joint)


def loop_poles(model, spectra, pairs: int) -> np.ndarray:
    """The poles above the force's band that a vector fit with ``pairs`` pairs finds in what ``model`` leaves at
    the lines above the band (every level but the lowest), whatever share of it they explain: the starts of the
    modes `loop.with_loop_modes` fits in the joint's loop, and one at `BEYOND_AT` of Nyquist where what they leave
    rises toward the last line (a mode the anti-alias filter hides). Empty where there are none."""
    blocks = _blocks(model, spectra)
    poles = _poles_above(blocks, pairs, band_top_hz(spectra))
    poles = poles[poles.imag / (2 * np.pi) < spectra[0].fs_hz / 2]
    if _rising(blocks, poles):  # a mode beyond the lines seen: a start at the top the loop's modes may reach
        top = 2 * np.pi * BEYOND_AT * spectra[0].fs_hz / 2
        poles = np.append(poles, top * (-BEYOND_ZETA + 1j * np.sqrt(1 - BEYOND_ZETA ** 2)))
    return np.sort_complex(poles)


def _rising(blocks, poles) -> bool:
    """Whether what ``poles`` leave of the blocks (their residues fitted) is, over the top eighth of the lines
    above the band, `RISING` times its median over the lines below (a median: the harmonics' own peaks are lines
    apart): the response rises toward a mode beyond `TOP_SHARE` of Nyquist, which the anti-alias filter hides
    from the vector fit (`structures_gvt` seed 62, a beam with a friction support and a mode at 0.96 of Nyquist:
    the loop's two poles went to the harmonics at 40 and 70 Hz and the held-out level 6 was missed by 4.9 times
    its noise, most of it at 80-128 Hz; with the third start at the top, by 3.2)."""
    if not blocks:
        return False
    T = _residues(poles, blocks)[0] if poles.size else None
    f = blocks[0][0]
    power = np.zeros(f.size)
    for g, G, E, W, _ in blocks:
        if g.size != f.size:  # a level of another period: its lines are not these
            continue
        left = E if T is None else E - _column(poles, T, g) * G[None, :]
        power = power + np.sum(np.abs(left * W) ** 2, axis=0)
    top = f >= f[0] + 0.875 * (f[-1] - f[0])
    return bool(np.any(top) and np.any(~top) and power[top].mean() > RISING * np.median(power[~top]))


def _blocks(model, spectra) -> list:
    """`_block` of every level but the lowest that has lines above the band."""
    ref = min(spectra, key=lambda s: s.level)
    return [b for b in (_block(model, s) for s in spectra if s is not ref) if b is not None]


def _poles_above(blocks, pairs: int, band_top: float) -> np.ndarray:
    """The poles a vector fit with ``pairs`` pairs finds in ``blocks`` (what a model leaves above the band), those
    above ``band_top`` Hz with a damping ratio in (0, 0.3); empty where there are none or the fit fails."""
    from ..modal.rational import vector_fit_inputs

    if not blocks:
        return np.zeros(0, complex)
    try:
        poles, _, _ = vector_fit_inputs([(f, G[None, :], E, W) for f, G, E, W, _ in blocks], pairs)
    except np.linalg.LinAlgError:
        return np.zeros(0, complex)
    f_hz = poles.imag / (2 * np.pi)
    zeta = -poles.real / np.maximum(np.abs(poles), TINY)
    return poles[(f_hz > band_top) & (zeta > 0) & (zeta < 0.3)]


def _crowded(added, poles, apart: float) -> bool:
    """Whether an added pole lies within ``apart`` (a share of its frequency) of another added one or of ``poles``."""
    if apart <= 0:
        return False
    f_added, f_all = np.abs(added), np.abs(np.concatenate([added, poles]))
    near = np.abs(f_added[:, None] - f_all[None, :]) <= apart * f_added[:, None]
    return bool(np.any(near.sum(axis=1) > 1))  # each added pole is near itself


def _block(model, s):
    """(freq, G, E, W, rows) at the lines above the band of one level: the joint's force spectrum, what the
    model's modes leave of each channel's response there, and the channels' weights; None without such lines."""
    lin, joint = model.linear, model.joint
    block = _lines_above(s, joint.between, lambda d, v: joint.law_form.force(joint.coefficients, d, v, joint.aux),
                         lin.channels)
    if block is None:
        return None
    f, G, A, W, lines = block
    column = _column(lin.poles, joint.column_of(lin), f)
    return f, G, A - column * G[None, :], W, lines


def _lines_above(s, between, force, channels):
    """(freq, G, A, W, lines): the force ``force(d, v)`` of the measured stroke between ``between`` and each
    channel's response at the lines above the band of one level, with the channels' weights; None without any."""
    n = s.period_samples
    top = int(TOP_SHARE * (n // 2))
    lines = np.arange(int(s.lines.max()) + 1, top + 1)
    if lines.size < 4 or s.whole is None:
        return None
    f = lines * s.fs_hz / n
    d, v = s.relative(*between, whole=True)
    G = np.fft.rfft(force(d, v), n)[lines]
    A = np.array([s.whole[c][lines] for c in channels])
    W = np.repeat(np.array([[1.0 / max(float(np.mean(np.abs(s.responses[c]))), TINY)] for c in channels]),
                  lines.size, axis=1)
    return f, G, A, W, lines


def harmonics_explained(spectra, between, force, channels, pairs: int = MAX_PAIRS) -> float:
    """The share of the response above the force's band (its power, weighted per channel, over every level but
    the lowest) that a joint's force ``force(d, v)`` on the measured stroke between ``between`` (``b`` may be
    ``"ground"``) explains through ``pairs`` modes above the band: FNSI's question (the joint's force as an input)
    of where the harmonics come from. 0 where no mode above the band is found."""
    from ..modal.rational import vector_fit_inputs

    ref = min(spectra, key=lambda s: s.level)
    blocks = [b for b in (_lines_above(s, between, force, channels) for s in spectra if s is not ref)
              if b is not None]
    if not blocks:
        return 0.0
    before = sum(float(np.sum(np.abs(A * W) ** 2)) for _, _, A, W, _ in blocks)
    band_top = band_top_hz(spectra)
    try:
        poles, _, _ = vector_fit_inputs([(f, G[None, :], A, W) for f, G, A, W, _ in blocks], pairs)
    except np.linalg.LinAlgError:
        return 0.0
    poles = poles[(poles.imag / (2 * np.pi) > band_top) & (poles.real < 0)]
    if poles.size == 0 or before <= 0:
        return 0.0
    return max(0.0, 1.0 - _residues(poles, blocks)[1] / before)


def _column(poles, T, f):
    """(C, M) the joint's accelerance column of residues T (C, K) at ``f`` Hz, zero at rest (`model.Drive`)."""
    iw = 2j * np.pi * np.asarray(f, float)[None, :, None]
    lam = poles[None, None, :]
    R = T[:, None, :]
    return (R * (1 / (iw - lam) + 1 / lam) + R.conj() * (1 / (iw - lam.conj()) + 1 / lam.conj())).sum(axis=2)


def _residues(poles, blocks):
    """(T (C, K), weighted RSS): the joint's residues at ``poles``, per channel in least squares over the levels."""
    n_out = blocks[0][2].shape[0]
    T = np.zeros((n_out, poles.size), complex)
    rss = 0.0
    for o in range(n_out):
        rows, rhs = [], []
        for f, G, E, W, _ in blocks:
            iw = 2j * np.pi * f[:, None]
            a = (1 / (iw - poles[None, :]) + 1 / poles[None, :]) * G[:, None]
            b = (1 / (iw - poles.conj()[None, :]) + 1 / poles.conj()[None, :]) * G[:, None]
            X = np.hstack([a + b, 1j * (a - b)]) * W[o][:, None]
            rows.append(X)
            rhs.append(E[o] * W[o])
        X, y = np.vstack(rows), np.concatenate(rhs)
        Xr, yr = np.vstack([X.real, X.imag]), np.concatenate([y.real, y.imag])
        coef, *_ = np.linalg.lstsq(Xr, yr, rcond=None)
        T[o] = coef[:poles.size] + 1j * coef[poles.size:]
        rss += float(np.sum((yr - Xr @ coef) ** 2))
    return T, rss


def same_modes(a, b) -> bool:
    """Whether two models have the same poles."""
    return a.linear.poles.shape == b.linear.poles.shape and bool(np.allclose(a.linear.poles, b.linear.poles))
