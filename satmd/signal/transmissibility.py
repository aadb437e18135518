"""Transmissibilities (A2/A1) from output-only recordings, by Welch averaging (`satmd.signal.welch`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import renamed_keyword
from ..io.atomic import atomic_write
from ..io.recording import Recording
from .welch import STD_FLOOR, check_estimator, frf_from_spectra, usable_bins, spectra


@dataclass(frozen=True)
class Transmissibility:
    """T = response / reference (A2/A1 by default) from an output-only recording."""

    freq_hz: np.ndarray
    value: np.ndarray
    std: np.ndarray
    coherence: np.ndarray
    meta: dict = field(default_factory=dict)

    def model(self, rig=None, effects=()) -> np.ndarray:
        """The model's A2/A1 on this grid (`model_transmissibility`)."""
        return model_transmissibility(self.freq_hz, rig, effects)

    def __len__(self):
        return self.freq_hz.size

    def __repr__(self):
        return f"Transmissibility({self.freq_hz.size} points, {self.freq_hz[0]:g}..{self.freq_hz[-1]:g} Hz)"


def model_transmissibility(freq_hz, rig=None, effects=()) -> np.ndarray:
    """A2/A1 of the model: absorber over primary-mass acceleration (independent of the force).

    Parameters
    ----------
    freq_hz : array_like, shape (n_freq,)
        Frequencies in Hz.
    rig : Rig, optional
        The model (default: the paper's rig); fields may be arrays that
        broadcast to a batch shape.
    effects : sequence of Effect
        Missing-physics effects applied to the model (`satmd.frf`).

    Returns
    -------
    ndarray of complex, shape (n_freq,) or batch shape + (n_freq,)
        ``a2 / a1`` of `satmd.frf` at each frequency.
    """
    from ..physics import frf

    r = frf(freq_hz, rig, effects, outputs=ACCEL_CHANNELS)
    assert r.a1 is not None and r.a2 is not None  # both were asked for
    return r.a2 / r.a1


def transmissibility(recording: Recording, nperseg: int | None = None, window="hann", overlap: float = 0.5,
                     estimator: str = "H1", band_hz=None, reference: str = "acc1",
                     response: str = "acc2", band=None) -> Transmissibility:
    """Transmissibility response/reference with coherence and std, as `estimate_frf` does for FRFs.

    H1 assumes the noise is on ``response``; with comparable noise on both
    accelerometers H1 is biased low and H2 high where the coherence drops.

    Parameters
    ----------
    recording : Recording
        With the ``reference`` and ``response`` channels; a force channel is
        not needed (output-only recordings).
    nperseg : int, optional
        Samples per Welch segment, 8..n_samples (default: `default_nperseg`);
        it must leave at least 2 segments.
    window : str or tuple
        Window of each segment: ``hann`` (default), ``hamming``, ``blackman``,
        ``flattop``, ``boxcar``, or any `scipy.signal.get_window` name.
    overlap : float
        Overlap fraction of consecutive segments, in [0, 1).
    estimator : {"H1", "H2"}
        ``H1 = Gxy/Gxx`` (noise on the response) or ``H2 = Gyy/Gyx`` (noise on
        the reference); case does not matter.
    band_hz : (lo, hi), optional
        Band to keep in Hz, either may be None (default: every bin above 0 Hz).
    reference : str
        Channel in the denominator (default ``acc1``, the primary mass).
    response : str
        Channel in the numerator (default ``acc2``, the absorber).
    band : (lo, hi), optional
        Former name of ``band_hz`` (deprecated).

    Returns
    -------
    Transmissibility
        ``freq_hz``, complex ``value``, ``std`` (on each of Re and Im, floored
        at 1e-10 max|T|) and ``coherence`` on the kept bins (f > 0, inside
        ``band_hz``, where the reference has energy: others are dropped with a
        `DataWarning`); ``meta`` gives the source, estimator, channels and
        Welch settings (``nperseg``, ``segments``, ``resolution_hz``, ``n_eff``, ...).

    Raises
    ------
    DataError
        A missing channel, an unknown estimator or window, Welch settings the
        record cannot support, or a band that holds no usable bin.
    """
    band_hz = renamed_keyword(band, band_hz, "transmissibility")
    est = check_estimator(estimator)
    source = recording.meta.get("source", "recording")
    for name in (reference, response):
        recording[name]  # noqa: B018 - raises a DataError naming the missing channel
    s = spectra(recording, reference, [response], nperseg, window, overlap)
    h, g, sd = frf_from_spectra(s, response, est)
    keep = usable_bins(source, s, [h, g, sd], band_hz)
    t = h[keep]
    meta = {"source": str(source), "estimator": est, "reference": reference, "response": response, **s.meta,
            "n_eff": f"{s.n_eff:.4g}"}
    return Transmissibility(s.freq_hz[keep], t, np.maximum(sd[keep], STD_FLOOR * np.max(np.abs(t))), g[keep], meta)


def save_transmissibility(t: Transmissibility, path) -> Path:
    """CSV: ``# satmd-transmissibility v1`` then freq_hz,t_re,t_im,t_std,coherence.

    The ``meta`` entries go in ``# key: value`` lines before the header;
    floats have 17 significant digits, and the file is written atomically.

    Parameters
    ----------
    t : Transmissibility
        As `transmissibility` returns it.
    path : str or Path
        Target file (written as CSV whatever the suffix); an existing file is replaced.

    Returns
    -------
    Path
        The path written.
    """
    path = Path(path)
    lines = ["# satmd-transmissibility v1"]
    lines += [f"# {k}: {v}" for k, v in t.meta.items() if "\n" not in f"{k}{v}"]
    lines.append("freq_hz,t_re,t_im,t_std,coherence")
    table = np.column_stack([t.freq_hz, t.value.real, t.value.imag, t.std, t.coherence])
    lines += [",".join(f"{x:.17g}" for x in row) for row in table]
    with atomic_write(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path
