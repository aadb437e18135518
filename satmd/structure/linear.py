"""`LinearStructure`: the structure at its lowest level, poles and residues on every channel, in time.

From a modal fit of the force-to-acceleration FRFs (`satmd.modal.fit_modes`, accelerance
``H_o(ω) = Σ_r A_or/(iω − λ_r) + A_or*/(iω − λ_r*) + D_o``), each mode is a first-order complex state
driven by the force; ``D_o`` (the real, frequency-flat residual: the mass line above the band) passes
the force straight through. The other residual terms of the fit (the imaginary constant and the terms in
ω² and 1/ω²) stand for modes outside the band and have no causal state: they are left out, which is
what the lowest level's linear NRMSE then measures.

A joint between sensors a and b is a pair of equal and opposite forces at a and b. Its path to every
channel is not measured (one shaker), but on one structure the residues of a column are those of the
force's column scaled per mode (reciprocity: ``A_o,ab = A_o c_r`` with ``c_r = (A_ar − A_br) / A_dr``
for a driving point d). `coupling` gives ``c_r`` from a driving point; without one the model fits it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from ..modal.shapes import driving_point_of


@dataclass(frozen=True)
class LinearStructure:
    """Poles and the force's residues on every channel (accelerance), with a flat feed-through.

    Attributes
    ----------
    channels : the response channels, in order
    poles : (n,) complex λ_r (upper half-plane)
    residues : (C, n) complex A_or
    feedthrough : (C,) real D_o [(m/s²)/N]
    """

    channels: tuple
    poles: np.ndarray
    residues: np.ndarray
    feedthrough: np.ndarray

    @classmethod
    def from_modal(cls, modal) -> "LinearStructure":
        """From a `satmd.modal.ModalFit` of accelerances (its modes and each channel's coefficients)."""
        n = len(modal.modes)
        poles = np.array([m.pole for m in modal.modes], complex)
        res = np.array([modal.coefficients[c][0:2 * n:2] + 1j * modal.coefficients[c][1:2 * n:2]
                        for c in modal.channels])
        feed = np.array([float(modal.coefficients[c][2 * n]) for c in modal.channels])
        return cls(tuple(modal.channels), poles, res, feed)

    def index(self, channel: str) -> int:
        try:
            return self.channels.index(channel)
        except ValueError:
            raise DataError(f"no channel {channel!r} in the structure (channels: {', '.join(self.channels)})") from None

    def frf(self, freq_hz) -> np.ndarray:
        """(C, M) complex accelerance of the model at ``freq_hz``."""
        iw = 2j * np.pi * np.asarray(freq_hz, float)[None, :, None]
        lam = self.poles[None, None, :]
        A = self.residues[:, None, :]
        return (A / (iw - lam) + A.conj() / (iw - lam.conj())).sum(axis=2) + self.feedthrough[:, None]

    def pair_residues(self, a: str, b: str) -> np.ndarray:
        """(n,) accelerance residues of the relative motion of a to b (b may be ``"ground"``) per unit force."""
        ra = self.residues[self.index(a)]
        return ra - (0.0 if b == "ground" else self.residues[self.index(b)])

    def coupling(self, a: str, b: str, driving_point: str) -> np.ndarray:
        """(n,) c_r: the joint's column of residues over the force's, from the driving point (reciprocity)."""
        return self.pair_residues(a, b) / self.residues[self.index(driving_point)]

    def to_dict(self) -> dict:
        return {"channels": list(self.channels), "poles": as_pairs(self.poles),
                "residues": [as_pairs(r) for r in self.residues], "feedthrough": self.feedthrough.tolist()}

    @classmethod
    def from_dict(cls, d: dict) -> "LinearStructure":
        return cls(tuple(d["channels"]), from_pairs(d["poles"]), np.array([from_pairs(r) for r in d["residues"]]),
                   np.asarray(d["feedthrough"], float))


def fit_linear(spectra, channels, between=None, n_pairs=None) -> LinearStructure:
    """The linear part from one level's spectra (its lowest): a vector fit of every channel's FRF.

    Parameters
    ----------
    spectra : PeriodicSpectra of the reference level
    channels : the response channels, in order
    between : (a, b) a joint's pair: the fit is made on the channels with ``a`` replaced by ``a − b``, so that
        the pair's relative motion (a small difference of large signals) is as accurate as each channel
    n_pairs : pole pairs (default: from 2 to 24, the fewest after which more pairs fit noise, `sufficient_pairs`)

    Returns
    -------
    LinearStructure
    """
    from ..signal.memo import fingerprint

    names = tuple(channels)
    # asked again for every law the cross-validation weighs (each a few seconds on the F-16): answered once
    key = fingerprint(spectra.freq_hz, spectra.force, *[spectra.responses[c] for c in names],
                      settings=(names, tuple(between) if between else None, n_pairs))
    return _FITTED.answer(key, lambda: _fit_linear(spectra, names, between, n_pairs))


def _fit_linear(spectra, names, between, n_pairs) -> LinearStructure:
    from ..modal.rational import vector_fit

    f = spectra.freq_hz
    H = np.array([spectra.responses[c] / spectra.force for c in names])
    ia = names.index(between[0]) if between else None
    ib = names.index(between[1]) if between and between[1] != "ground" else None
    fitted = H.copy()
    if ib is not None:
        fitted[ia] = H[ia] - H[ib]
    weight = np.abs(spectra.force)[None, :] / np.abs(fitted).mean(axis=1, keepdims=True)  # the response's error
    fits = []
    for k in ([n_pairs] if n_pairs else _pair_counts(f)):
        poles, res, feed = vector_fit(f, fitted, weight, k)
        err = float(np.sqrt(np.mean(_errors(poles, res, feed, f, fitted, weight) ** 2)))
        fits.append((err, poles, res, feed))
    _, poles, res, feed = fits[sufficient_pairs([e for e, *_ in fits], _noise_floor(spectra, names, ia, ib, weight))]
    poles, res, feed = _with_upper_residual(f, fitted, weight, poles, res, feed)
    if ib is not None:  # back to the sensors' own channels
        res, feed = res.copy(), feed.copy()
        res[ia] += res[ib]
        feed[ia] += feed[ib]
    return LinearStructure(names, poles, res, feed)


#: a pair more is a mode when it takes more than this share off the best error yet
MODE_GAIN = 0.3
#: ... or, while the fit still misses over MISS of the FRF and over FAR times the noise's share, this share a pair
#: over up to AHEAD counts (vector fits of nearby counts scatter): many modes, each a small share of the error
SMALL_GAIN, MISS, FAR, AHEAD = 0.12, 0.08, 3.0, 4
#: the upper residual's pole: at this multiple of the band's top, damped this much (its shape in the band, ~ω²,
#: hardly depends on either: at 1.5, 2 and 3 times the top the driving point's error was 0.013, 0.012, 0.012)
UPPER_AT, UPPER_ZETA = 1.5, 0.05


def _errors(poles, res, feed, f, fitted, weight) -> np.ndarray:
    """Each channel's weighted relative error of the rational model."""
    model = LinearStructure(tuple(map(str, range(fitted.shape[0]))), poles, res, feed).frf(f)
    return np.sqrt(np.sum(np.abs((model - fitted) * weight) ** 2, axis=1) / np.sum(np.abs(fitted * weight) ** 2, axis=1))


def _with_upper_residual(f, fitted, weight, poles, res, feed):
    """The fit with one more pole pair above the band, its residues solved with the others', where it takes more
    than `MODE_GAIN` off the worst channel's error. The modes above the band reach into it as a flexibility
    (accelerance ~ ω²), largest at the driving point where every mode adds with one sign, and a flat feed-through
    has no such shape, and with noise on the data the pairs that would stand for them do not pass `MODE_GAIN`
    (`sufficient_pairs`) (on an independent chain driven at
    acc2, four modes and two more at 79 and 82 Hz, the driving point's error at the lowest level was 0.050 with 4 to
    12 pole pairs, 0.013 with this pole; the other channels 0.010-0.013 either way)."""
    from ..modal.rational import residues_at

    w = 2 * np.pi * UPPER_AT * float(np.max(f))
    wider = np.concatenate([poles, [w * (-UPPER_ZETA + 1j * np.sqrt(1 - UPPER_ZETA ** 2))]])
    res2, feed2 = residues_at(f, fitted, weight, wider)
    before = _errors(poles, res, feed, f, fitted, weight).max()
    after = _errors(wider, res2, feed2, f, fitted, weight).max()
    return (wider, res2, feed2) if after < (1.0 - MODE_GAIN) * before else (poles, res, feed)


def _noise_floor(spectra, names, ia, ib, weight) -> float:
    """The error `_errors` would show for a model that missed nothing but the noise: each line's spread over
    periods, weighted as the fit weighs it (NaN where the spectra hold no spread, a sweep's)."""
    H = np.array([spectra.responses[c] / spectra.force for c in names])
    sd = np.array([spectra.std[c] for c in names], float) * np.sqrt(2.0) / np.abs(spectra.force)
    if ib is not None:
        H[ia], sd[ia] = H[ia] - H[ib], np.hypot(sd[ia], sd[ib])
    with np.errstate(divide="ignore", invalid="ignore"):  # a silent channel: no floor (NaN), no warning
        return float(np.sqrt(np.mean(np.sum((sd * weight) ** 2, axis=1) / np.sum(np.abs(H * weight) ** 2, axis=1))))


def sufficient_pairs(errors, floor: float | None = None) -> int:
    """Index of the pole-pair count that last takes more than `MODE_GAIN` off the best error of the fewer counts
    (``errors`` for counts in order). A mode left out takes most of the error with it when added; pairs beyond
    the modes fit the lowest level's noise and distortion a little each (and vector fits of nearby counts
    scatter: the best error so far is what a count must beat). On the 36 joints of 40 independent ground vibration tests
    (`benchmarks/structures_gvt.py`) this keeps the modes in the band and one for those above it, where the
    fewest pairs within 1.5 times the best error took up to 16 pairs for 3 modes: spurious poles beside a
    resonance, each a path the joint's force then drives (on a chain with a cubic joint, level 2 predicted at
    0.05-0.08 with 12 pairs, 0.018-0.025 with 4).

    A structure of many modes, each a small share of the error, passes no count that way: while the best error
    stands over `MISS` and over `FAR` times the noise's ``floor`` (`_noise_floor`), the furthest count up to
    `AHEAD` on that takes `SMALL_GAIN` a pair off it is taken too. The F-16's lowest level fitted without a joint's
    pair kept 3 pairs by `MODE_GAIN` alone (error 0.19, the noise's 0.001) and simulated its own level at NRMSE
    0.19; it keeps 7 now (0.0915, 0.49 of 0.1865 where 0.60 was asked), 0.07 (with the joint's pair acc2-acc3, 8
    either way). On the lowest levels of the 100 independent ground vibration tests of `structures_gvt` (184 fits,
    with and without the joint's pair) no count changed: three fits stood over `MISS` at their counts (a frame's
    0.088 and 0.092, a chain's 0.085: a level's distortion, not modes; the counts after took 0-8 % each), the
    nearest 6 % short of passing."""
    best = np.minimum.accumulate(np.asarray(errors, float))
    steps = np.flatnonzero(best[1:] < (1.0 - MODE_GAIN) * best[:-1])
    k = int(steps[-1] + 1) if steps.size else 0
    while floor is not None and np.isfinite(floor) and best[k] > max(MISS, FAR * floor):
        on = [j for j in range(k + 1, min(k + AHEAD, best.size - 1) + 1)
              if best[j] < (1.0 - SMALL_GAIN) ** (j - k) * best[k]]
        if not on:
            break
        k = on[-1]
    return k


def _memo():
    from ..signal.memo import ContentMemo

    return ContentMemo(size=8)


_FITTED = _memo()


def _pair_counts(freq_hz) -> list:
    top = int(min(24, (freq_hz.size - 2) // 4))
    return list(range(2, max(2, top) + 1))


def driving_point(linear: LinearStructure):
    """The channel at the force's point, found: the one whose receptance modal constants ``A_r / λ_r²`` all
    have the driving point's sign (a positive mass-normalised ``φ_d²``, so −Re(A/λ²)·… > 0 on every mode);
    None when no channel, or more than one, does (`satmd.modal.shapes.driving_point_of`)."""
    return driving_point_of(linear.channels, linear.residues, linear.poles)


def discretise(poles, fs_hz: float):
    """(ψ, G0, G1): ``z_k = ψ z_{k-1} + G0 u_{k-1} + G1 u_k`` for ``z' = λ z + u`` with u straight between samples."""
    h = 1.0 / fs_hz
    lam = np.asarray(poles, complex)
    psi = np.exp(lam * h)
    i0 = (psi - 1.0) / lam
    i1 = (psi - 1.0 - lam * h) / (lam ** 2 * h)
    return psi, i0 - i1, i1


def modal_states(u, poles, fs_hz: float) -> np.ndarray:
    """(n, N) complex states of ``z' = λ z + u`` from rest, u straight between samples (IIR filters, no loop)."""
    from scipy.signal import lfilter

    psi, G0, G1 = discretise(poles, fs_hz)
    u = np.asarray(u, float)
    return np.array([lfilter([g1, g0], [1.0, -p], u.astype(complex)) for p, g0, g1 in zip(psi, G0, G1)])


def response(states, residues) -> np.ndarray:
    """Re Σ_r 2 R_r z_r for residues R (n,) or (C, n): (N,) or (C, N)."""
    R = np.asarray(residues)
    return 2.0 * (R.real @ states.real - R.imag @ states.imag)  # the real part alone: half the work


def as_pairs(z) -> list:
    return [[float(x.real), float(x.imag)] for x in np.asarray(z, complex)]


def from_pairs(pairs) -> np.ndarray:
    a = np.asarray(pairs, float).reshape(-1, 2)
    return a[:, 0] + 1j * a[:, 1]
