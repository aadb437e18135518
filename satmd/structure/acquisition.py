"""The measurement chain above the force's band, seen through the joint's harmonics (SPEC §11, mission item 6).

Every channel of an acquisition passes one anti-alias low-pass. Below the force's band edge it does not show:
the force passes the same filter, so the FRF (a ratio) and the linear model fitted to it hold the structure
alone, and the model driven by the measured force reproduces the measured response. The joint's harmonics are
another matter: the model makes them from the stroke, and they reach the channels unfiltered, while the
measured ones went through the filter's roll-off and its phase lag near the cut-off (an 8th-order elliptic at
0.8 of Nyquist turns 100 Hz by 120° more than it turns the band). On an independent frame with a contact at its
base that lag was half of what its held-out level missed.

So the joint's share of the outputs is passed through one complex gain per band of frequency above the force's
band, the same for every channel and level (a property of the chain, not of a sensor), estimated by least
squares from the fitted records once the joint is fitted (`acquisition_of`): measured minus the linear part
against the joint's share. It never amplifies (an anti-alias filter does not), is one below the band, and is
kept only where it brings the fitted records closer.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import TINY
from .bands import mirrored

BANDS = 16        # bands of frequency between the force's band edge and Nyquist
MIN_SHARE = 1e-6  # of the joint's share's power above the band: a band with less says nothing
MIN_GAIN = 0.05   # the fitted records' misfit above the band must fall by this share
EDGE = 512        # samples mirrored at each end of a record the gain is applied to (`Acquisition.apply`)


@dataclass(frozen=True)
class Acquisition:
    """The chain's gain on the joint's share above ``band_top_hz``: complex ``gain`` at ``freq_hz`` (band centres),
    interpolated in magnitude and unwrapped phase; one at and below the band's edge."""

    band_top_hz: float
    freq_hz: np.ndarray
    gain: np.ndarray

    def at(self, f_hz) -> np.ndarray:
        """The complex gain at ``f_hz``."""
        f = np.asarray(f_hz, float)
        knots = np.concatenate([[self.band_top_hz], self.freq_hz])
        gain = np.concatenate([[1.0 + 0j], self.gain])
        mag = np.interp(f, knots, np.abs(gain))
        phase = np.interp(f, knots, np.unwrap(np.angle(gain)))
        out = mag * np.exp(1j * phase)
        out[f <= self.band_top_hz] = 1.0
        return out

    def apply(self, share, fs_hz: float) -> np.ndarray:
        """``share`` (C, N), sampled at ``fs_hz``, through the chain's gain, by FFT over the record mirrored about
        its first and last samples (`EDGE`): over the record alone the FFT joins its end to its start, a step
        that a gain rolling off toward Nyquist rings at both ends (on an independent wing the last sample of a
        quiet channel was missed by 2.5 times its RMS, 0.024 of its held-out NRMSE of 0.035)."""
        n = np.shape(share)[-1]
        extended, pad = mirrored(share, EDGE)
        m = extended.shape[-1]
        out = np.fft.irfft(np.fft.rfft(extended, axis=-1) * self.at(np.fft.rfftfreq(m, 1.0 / fs_hz)), m, axis=-1)
        return out[..., pad:pad + n]

    def cutoff_hz(self) -> float | None:
        """The first band's centre where the gain is below 1/√2 (the chain's -3 dB point lies in that band or the
        one before), None if none is."""
        below = np.flatnonzero(np.abs(self.gain) < 2 ** -0.5)
        return float(self.freq_hz[below[0]]) if below.size else None

    def describe(self) -> str:
        cut = self.cutoff_hz()
        passed = np.flatnonzero(np.abs(self.gain) >= 2 ** -0.5)
        lag = (f", phase {np.degrees(np.angle(self.gain[passed[-1]])):+.0f}° at {self.freq_hz[passed[-1]]:.4g} Hz"
               if passed.size else "")
        at = f"-3 dB by {cut:.4g} Hz" if cut is not None else "no -3 dB point below Nyquist"
        return (f"the joint's harmonics above {self.band_top_hz:.4g} Hz pass the acquisition's low-pass, estimated "
                f"from them: {at}{lag}")

    def to_dict(self) -> dict:
        return {"band_top_hz": float(self.band_top_hz), "freq_hz": [float(f) for f in self.freq_hz],
                "gain": [[float(g.real), float(g.imag)] for g in self.gain]}

    @classmethod
    def from_dict(cls, d: dict) -> "Acquisition":
        gain = np.asarray(d["gain"], float)
        freq = np.asarray(d["freq_hz"], float)
        if gain.ndim != 2 or gain.shape != (freq.size, 2) or not np.all(np.isfinite(gain)):
            raise ValueError(f"acquisition gain of shape {gain.shape} for {freq.size} frequencies")
        return cls(float(d["band_top_hz"]), freq, gain[:, 0] + 1j * gain[:, 1])


@np.errstate(over="ignore", invalid="ignore")  # a candidate's share far beyond the records: its sums are not finite
def acquisition_of(model, drives, band_top_hz: float) -> Acquisition | None:
    """The chain's gain on the joint's share above ``band_top_hz`` from ``drives`` [(Drive, measured (C, N))] of
    a fitted ``model``, or None where the joint puts nothing above the band or the gain does not bring the
    records closer there (by `MIN_GAIN`). The drives are of the model without a gain of its own: their outputs
    are the joint's share as the model makes it."""
    from sklearn.isotonic import IsotonicRegression

    joint = model.joint
    if joint is None:
        return None
    fs = drives[0][0].fs
    edges = np.linspace(band_top_hz, fs / 2, BANDS + 1)
    num, den = np.zeros(BANDS, complex), np.zeros(BANDS)
    spectra = []
    for drive, measured in drives:
        linear = drive.linear[:, drive.skip:]
        share = drive.outputs(joint) - linear
        if not np.all(np.isfinite(share)):
            return None
        w = 1.0 / np.maximum(np.var(measured, axis=1, keepdims=True), TINY)
        S, R = np.fft.rfft(share, axis=1), np.fft.rfft(measured - linear, axis=1)
        f = np.fft.rfftfreq(measured.shape[1], 1.0 / fs)
        band = np.digitize(f, edges) - 1  # -1 in the force's band; BANDS at Nyquist itself
        spectra.append((S, R, w, f, band))
        for b in range(BANDS):
            i = band == b
            num[b] += np.sum(w * R[:, i] * np.conj(S[:, i]))
            den[b] += float(np.sum(w * np.abs(S[:, i]) ** 2))
    total = float(den.sum())
    if not (np.all(np.isfinite(num)) and np.isfinite(total)):  # a candidate that ran far away: no gain
        return None
    seen = den > MIN_SHARE * max(total, TINY)
    if not np.any(seen):
        return None
    gain = num / np.maximum(den, TINY)
    for k in np.flatnonzero(~seen).tolist():  # a band the joint does not reach: as the one below (one at first)
        gain[k] = gain[k - 1] if k else 1.0
    # a low-pass: its gain never rises with frequency, nor above one (a dip the model's own miss makes is not one:
    # the bands are pooled, weighted by what the joint puts in each)
    mag = IsotonicRegression(y_max=1.0, increasing=False).fit_transform(np.arange(BANDS), np.abs(gain),
                                                                         sample_weight=np.maximum(den, TINY))
    gain = mag * np.exp(1j * np.angle(gain))
    centres = 0.5 * (edges[:-1] + edges[1:])
    chain = Acquisition(float(band_top_hz), centres, gain)
    before = after = 0.0
    for S, R, w, f, band in spectra:
        above = band >= 0
        C = chain.at(f[above])
        before += float(np.sum(w * np.abs(R[:, above] - S[:, above]) ** 2))
        after += float(np.sum(w * np.abs(R[:, above] - C * S[:, above]) ** 2))
    return chain if np.isfinite(before) and after < (1 - MIN_GAIN) * before else None
