"""`Recording`: uniformly sampled time channels, and the checks every recording reader shares.

A `Recording` holds uniformly sampled channels. A channel's role is its name:
``force`` [N] or an accelerometer ``acc1``, ``acc2``, ``acc3``, ... [m/s²]
(`is_role`; a ground vibration test has one shaker and many accelerometers).
The SATMD rig's estimators use ``force`` on the primary mass and ``acc1``,
``acc2`` of the primary mass and the absorber (`ROLES`); other channels (a
microphone, a voltage) are kept under their own names for inspection. The
files recordings come in are read and written by `satmd.io.recording`.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..conventions import RECORDING_CHANNELS
from ..errors import DataError, FormatError
from ._common import warn
from .limits import check_samples

ROLES = ("force", "acc1", "acc2")  # the SATMD rig's channels; any acc<N> is a role too (`is_role`)
MAX_ABS_SAMPLE = 1e15  # no force (N) or acceleration (m/s²) reaches this; float32's 3.4e38 is a glitch
GLITCH_RATIO = 1e6  # a sample this many times the channel's 99.9th percentile is a glitch, not a measurement
MIN_RATE_HZ = 20.0  # a structural FRF needs a Nyquist frequency of at least 10 Hz
SI_UNITS = {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}  # the rig's; `si_unit` for any role
MAP_ALIASES = {ch: name for name, ch in RECORDING_CHANNELS.items()}  # a1, a2; `role_of` for any a<N>
_ACC = re.compile(r"acc([1-9][0-9]*)")  # acc1, acc2, ...: no acc0, no acc01 (one name per sensor)


# --- channel names ----------------------------------------------------------------
def is_role(name) -> bool:
    """Whether ``name`` is a role: ``force`` or an accelerometer ``acc<N>`` (N = 1, 2, ...).

    Parameters
    ----------
    name : str
        A channel name, as a `Recording` holds it (case matters: ``Acc3`` is not a role).

    Returns
    -------
    bool
        True for ``force``, ``acc1``, ``acc2``, ``acc3``, ...; False for anything else
        (``acc0``, ``acc01``, ``a1``, ``ch1``, ``mic``).
    """
    return name == "force" or (isinstance(name, str) and _ACC.fullmatch(name) is not None)


def accelerometers(names) -> list[str]:
    """The accelerometer channels among ``names`` in numeric order (acc1, acc2, ..., acc10).

    Parameters
    ----------
    names : iterable of str
        Channel names (a `Recording`'s ``channels`` will do).

    Returns
    -------
    list of str
        The ``acc<N>`` names, sorted by N (not as text: acc2 before acc10).
    """
    return sorted((n for n in names if is_role(n) and n != "force"), key=lambda n: int(n[3:]))


def ordered(names) -> list[str]:
    """``names`` in writing order: ``force``, then `accelerometers`, then the others as given.

    Parameters
    ----------
    names : iterable of str
        Channel names.

    Returns
    -------
    list of str
        The same names, each once: the order satmd writes channels in (CSV, WAV).
    """
    names = list(names)
    accs = accelerometers(names)
    return ["force"] * ("force" in names) + accs + [n for n in names if n != "force" and n not in accs]


def si_unit(name, default: str = "") -> str:
    """The SI unit of a role: ``N`` for ``force``, ``m/s^2`` for every ``acc<N>``; ``default`` for other names."""
    if name == "force":
        return "N"
    return "m/s^2" if is_role(name) else default


def role_of(key: str) -> str:
    """The role a channel map's key names: ``f``/``force``, ``a<N>``/``acc<N>`` (any case) -> ``force``, ``acc<N>``.

    Parameters
    ----------
    key : str
        The left side of a map entry (``a3`` in ``a3=Acceleration[1]``).

    Returns
    -------
    str
        ``force`` or ``acc<N>``.

    Raises
    ------
    ValueError
        An accelerometer numbered 0 or not by a number (``a0``, ``acc``, ``accx``), or
        an unknown channel; the message says what the names are (callers name the entry).
    """
    name = str(key).strip()
    k = name.lower()
    if k in ("f", "force"):
        return "force"
    digits = k[3:] if k.startswith("acc") else k[1:] if k.startswith("a") else ""
    if k.startswith("acc") or digits[:1].isdigit():  # an accelerometer, well numbered or not
        if not (digits.isascii() and digits.isdigit()):
            raise ValueError("an accelerometer is a<N> or acc<N> with N = 1, 2, ...")
        if int(digits) == 0:
            raise ValueError("accelerometers are numbered from 1 (a1 or acc1, a2, ...)")
        return f"acc{int(digits)}"
    raise ValueError(f"unknown channel {name!r} (use force, a1, a2, a3, ... or acc1, acc2, ...)")


# what describes the whole record, not one realisation of it: the layout and the excitation read from it
WHOLE_RECORD_KEYS = ("realisations", "realisation_samples", "excitation_layout", "period_samples", "periods",
                     "transient_periods", "steady_periods", "lines")


@dataclass(frozen=True)
class Recording:
    """Uniformly sampled channels.

    Attributes
    ----------
    fs_hz : sample rate in Hz
    channels : dict name -> (n,) float array (``force``, ``acc1``, ``acc2`` or other names)
    units : dict name -> unit label ("N", "m/s^2"; the file's label when not converted)
    meta : dict of strings (source, generator, ...)
    labels : dict name -> where the channel came from (e.g. "UFF #2, node 1 +Z")
    """

    fs_hz: float
    channels: dict
    units: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)
    labels: dict = field(default_factory=dict)

    def __post_init__(self):
        fs = float(self.fs_hz)
        if not math.isfinite(fs) or fs <= 0:
            raise DataError(f"sample rate must be a finite number > 0, got {self.fs_hz!r}")
        if not self.channels:
            raise DataError("a recording needs at least one channel")
        chans, n = {}, None
        for name, v in self.channels.items():
            v = np.asarray(v, dtype=float)
            if v.ndim != 1:
                raise DataError(f"channel {name} must be 1-D, has shape {v.shape}")
            if n is not None and v.size != n:
                raise DataError(f"channels have different lengths ({name}: {v.size}, others: {n})")
            n = v.size
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                raise DataError(f"channel {name} has NaN or infinite values (first at sample {bad[0]}, "
                                f"t = {bad[0] / fs:g} s)")
            big = np.flatnonzero(np.abs(v) > MAX_ABS_SAMPLE)  # squares (power spectra) would overflow
            if big.size:
                raise DataError(f"channel {name} reaches {v[big[0]]:.3g} at sample {big[0]}: not a measurement "
                                f"in SI units (a damaged file or a wrong sample format?)")
            chans[name] = v
        if n < 2:
            raise DataError(f"a recording needs at least 2 samples, has {n}")
        check_samples("recording", n, len(chans))
        object.__setattr__(self, "fs_hz", fs)
        object.__setattr__(self, "channels", chans)
        object.__setattr__(self, "units", {k: str(v) for k, v in (self.units or {}).items() if k in chans})
        object.__setattr__(self, "meta", dict(self.meta or {}))
        object.__setattr__(self, "labels", {k: str(v) for k, v in (self.labels or {}).items() if k in chans})

    @property
    def n_samples(self) -> int:
        return next(iter(self.channels.values())).size

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.fs_hz

    @property
    def time_s(self) -> np.ndarray:
        return np.arange(self.n_samples) / self.fs_hz

    @property
    def has_force(self) -> bool:
        return "force" in self.channels

    def __getitem__(self, name) -> np.ndarray:
        try:
            return self.channels[name]
        except KeyError:
            raise DataError(f"no channel {name!r} in the recording (has {', '.join(self.channels)})") from None

    def realisations(self) -> list:
        """The recording's realisations, each a recording of its own (a lab's matrix of realisations read whole,
        meta ``realisations`` and ``realisation_samples``); ``[self]`` for one. Each is read again at the door
        (its excitation, its steady periods): the whole record's reading describes none of them."""
        try:
            count, n = int(self.meta.get("realisations", 1)), int(self.meta.get("realisation_samples", 0))
        except ValueError:
            return [self]
        if count < 2 or n < 2 or count * n != self.n_samples:
            return [self]
        meta = {k: v for k, v in self.meta.items() if k not in WHOLE_RECORD_KEYS}  # read again for each
        source = meta.get("source", "recording")
        return [Recording(self.fs_hz, {c: v[i * n:(i + 1) * n] for c, v in self.channels.items()}, self.units,
                          {**meta, "source": f"{source} (realisation {i + 1})", "realisation": str(i + 1)},
                          self.labels) for i in range(count)]

    def rename(self, mapping: dict) -> "Recording":
        """New names for some channels: {old: new}."""
        new = {mapping.get(k, k): v for k, v in self.channels.items()}
        if len(new) != len(self.channels):
            raise DataError(f"renaming {mapping} makes two channels share a name")
        return Recording(self.fs_hz, new, {mapping.get(k, k): u for k, u in self.units.items()}, self.meta,
                         {mapping.get(k, k): u for k, u in self.labels.items()})

    def __repr__(self):
        return (f"Recording({len(self.channels)} channels {', '.join(self.channels)}, {self.fs_hz:g} Hz, "
                f"{self.n_samples} samples = {self.duration_s:g} s)")


def each_realisation(recordings) -> list:
    """The recordings with a lab's realisations apart (`Recording.realisations`): each a periodic test of its
    own, at its level (the F-16's odd multisines: ten random-phase realisations of three periods in one file)."""
    return [part for r in recordings for part in (r.realisations() if isinstance(r, Recording) else [r])]


def clipped_channels(rec: Recording, extremes: dict | None = None) -> dict:
    """{name: number of samples at the channel's extremes} for channels that look clipped.

    A clipped sensor sits on its largest or smallest value for several
    samples in a row (flat tops); a healthy signal passes its extremes.
    ``extremes`` may give a channel's full-scale limits (integer WAV data).

    Parameters
    ----------
    rec : Recording
        The recording to check, every channel.
    extremes : dict, optional
        ``{channel: (lo, hi)}`` limits a channel clips at (default: each
        channel's own minimum and maximum). A channel whose limits have
        ``hi <= lo`` (a constant one) is skipped.

    Returns
    -------
    dict
        ``{channel: number of samples at or beyond its extremes}`` for the
        channels with at least 3 pairs of consecutive, equal samples at an
        extreme (flat tops); empty when none looks clipped.
    """
    out = {}
    for name, v in rec.channels.items():
        lo, hi = (extremes or {}).get(name, (v.min(), v.max()))
        if hi <= lo:
            continue
        at = (v >= hi) | (v <= lo)
        flat_tops = np.count_nonzero(at[1:] & at[:-1] & (v[1:] == v[:-1]))
        if flat_tops >= 3:
            out[name] = int(np.count_nonzero(at))
    return out


def warn_clipping(path, rec, extremes=None):
    """A `DataWarning` per channel that `clipped_channels` finds, that is constant, or that holds a glitch (every
    reader calls this)."""
    for name, count in clipped_channels(rec, extremes).items():
        warn(path, f"channel {name} looks clipped: {count} samples sit at its extremes "
                   f"({100 * count / rec.n_samples:.2g} %); FRFs near those peaks are unreliable")
    for name, v in rec.channels.items():
        if name != "force" and v.size >= 16 and np.ptp(v) == 0:  # a constant force is refused where it is used
            warn(path, f"channel {name} is constant ({v[0]:.3g} throughout): a sensor that recorded nothing?")
            continue
        mag = np.abs(v)
        typical = np.percentile(mag, 99.9) if mag.size >= 1000 else np.median(mag)
        k = int(np.argmax(mag))
        if mag[k] > GLITCH_RATIO * typical and typical > 0:
            warn(path, f"channel {name}: sample {k} (t = {k / rec.fs_hz:g} s) is {v[k]:.3g}, {mag[k] / typical:.2g} "
                       f"times the channel's typical level: a glitch? It dominates every spectrum of the record")


def check_rate(path, fs_hz: float):
    """Refuse (`FormatError`) a sample rate too slow for structural FRFs (time in ms read as s, a wrong step)."""
    if fs_hz < MIN_RATE_HZ:
        raise FormatError(path, f"sample rate {fs_hz:.4g} Hz (time step {1 / fs_hz:.4g} s) is below the "
                                f"{MIN_RATE_HZ:g} Hz a structural FRF needs: is the time axis in milliseconds, "
                                f"or the step wrong?")


# --- time axes ------------------------------------------------------------------
def uniform_rate(path, t, lines=None) -> float:
    """Sample rate of a time axis; a gap, a repeat or jitter over 1 % of a step is refused."""
    dt = np.diff(t)
    typical = np.median(dt)  # a single gap does not move the median
    if not typical > 0:
        raise FormatError(path, "time does not increase", line=lines[1] if lines else None,
                          column="1 (time_s)" if lines else None)
    bad = np.flatnonzero(np.abs(dt - typical) > 0.01 * typical)
    if bad.size:
        k = bad[0] + 1
        raise FormatError(path, f"non-uniform sampling: step {dt[k - 1]:g} s at t = {t[k]:g} s, "
                                f"expected {typical:g} s", line=lines[k] if lines else None,
                          column="1 (time_s)" if lines else None)
    return snap_rate((t.size - 1) / (t[-1] - t[0]))  # the mean step: most digits


def snap_rate(fs: float) -> float:
    """Rates like 1/1.52588e-05 (a step written with 6 digits) back to 65536 Hz."""
    r = round(fs)
    return float(r) if r > 0 and abs(fs - r) <= 2e-5 * fs else fs
