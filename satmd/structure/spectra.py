"""The steady spectra of a periodic test of a structure, every channel, and two sensors' relative motion.

A ground vibration test's multisine repeats; after the start-up transient every channel is periodic
(plus noise), so each line's spectrum is the mean over the steady periods (`satmd.signal.periodic`'s
estimator), and the spread over periods is its noise. Displacements come from the accelerations by
dividing by -ω² at the lines the force excites (the band where the accelerometers carry the motion), or, where a
law is weighed on them (`PeriodicSpectra.motion` ``whole``), at every line from the band's lowest up to 0.8 of
Nyquist: the joint's harmonics move the sensors too.

A sine sweep, the other classic of a ground vibration test, starts and ends at rest: padded with zeros until
its response has rung out, the whole record is one period of a periodic signal, so ``A = H F`` holds exactly at
every line of its DFT for the linear part (`transient_spectra`, given explicitly: it places a joint far less often
than a multisine; `transient_spectra` says why).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import TINY
from ..errors import DataError
from ..numerics import force_level
from ..signal.excitation import excitation_of, received
from ..signal.periodic import periodic_spectra as signal_spectra
from .bands import mirrored


@dataclass(frozen=True)
class PeriodicSpectra:
    """One periodic recording of a structure, at the lines its force excites.

    Attributes
    ----------
    source : the recording's name
    level : force RMS (N)
    fs_hz, period_samples : sample rate and samples per period
    lines : (K,) DFT lines of one period the force excites
    force : (K,) complex mean spectrum of the force
    responses : {channel: (K,) complex mean spectrum}
    std : {channel: (K,) std of the mean's real and imaginary parts, from the spread over periods}
    whole : {channel: (n // 2 + 1,) complex mean spectrum at every line}: what a joint throws outside the lines
        the force excites (`satmd.structure.outside`); None where not kept
    """

    source: str
    level: float
    fs_hz: float
    period_samples: int
    lines: np.ndarray
    force: np.ndarray
    responses: dict
    std: dict
    whole: dict | None = None

    @property
    def freq_hz(self) -> np.ndarray:
        return self.lines * self.fs_hz / self.period_samples

    def motion(self, channel: str, whole: bool = False):
        """(displacement, velocity) over one period of ``channel`` (zeros for ``"ground"``); ``whole``: from every
        line from the band's lowest up to 0.8 of the Nyquist frequency (the harmonics a joint makes above the
        band move the sensors too; below the band the accelerometers' noise, divided by ω², would swamp it)."""
        if channel == "ground":
            return np.zeros(self.period_samples), np.zeros(self.period_samples)
        if whole and self.whole is not None:
            lines = np.arange(int(self.lines.min()), int(0.8 * (self.period_samples // 2)) + 1)
            return motion(self.whole[channel][lines], lines, self.fs_hz, self.period_samples)
        return motion(self.responses[channel], self.lines, self.fs_hz, self.period_samples)

    def relative(self, a: str, b: str, whole: bool = False):
        """(d, v): the relative displacement and velocity of sensor a to sensor b (or the ground) over one period
        (``whole``: see `motion`)."""
        (da, va), (db, vb) = self.motion(a, whole), self.motion(b, whole)
        return da - db, va - vb

    def scales(self, a: str, b: str):
        """(RMS stroke, RMS relative velocity) of a to b: the scales a joint law is written in."""
        d, v = self.relative(a, b)
        return float(np.std(d)) or 1.0, float(np.std(v)) or 1.0

    def at_lines(self, x) -> np.ndarray:
        """The spectrum of one period of ``x`` at the excited lines (the scaling of `force`)."""
        return np.fft.rfft(np.asarray(x, float), self.period_samples)[self.lines]


def motion(accel, lines, fs_hz: float, period_samples: int):
    """(displacement, velocity) over one period from an acceleration's spectrum at ``lines`` (zero elsewhere).

    Parameters
    ----------
    accel : (K,) complex spectrum (one period's rfft scaling) at ``lines``
    lines : (K,) DFT lines of one period
    fs_hz, period_samples : sample rate and samples per period

    Returns
    -------
    (ndarray, ndarray)
    """
    w = 2 * np.pi * np.asarray(lines) * fs_hz / period_samples
    X = np.zeros(period_samples // 2 + 1, complex)
    V = np.zeros(period_samples // 2 + 1, complex)
    X[lines] = accel / -(w ** 2)
    V[lines] = accel / (1j * w)
    return np.fft.irfft(X, period_samples), np.fft.irfft(V, period_samples)


def periodic_spectra(recording) -> PeriodicSpectra:
    """`PeriodicSpectra` of a recording whose force is periodic (a multisine, a periodic chirp, ...).

    Parameters
    ----------
    recording : Recording with ``force`` and one or more response channels

    Returns
    -------
    PeriodicSpectra

    Raises
    ------
    DataError
        A force that is not periodic, or fewer than two steady periods.
    """
    source, rec, exc = _excited(recording)
    if exc.kind == "sweep":
        raise DataError(f"{source}: the force is a sweep; locating a joint needs a periodic force (a multisine, as a "
                        "ground vibration test uses) at every level: from one sweep a level the place "
                        "came out right on 7 of 10 independent tests and no law was named (a multisine: 9 and 9); "
                        "`structure.transient_spectra` tries it all the same")
    if exc.kind != "periodic":  # its length said: a record cut short of two periods reads as random
        n = np.asarray(rec["force"]).size
        raise DataError(f"{source}: the force is {exc.kind}, not periodic ({n} samples, {n / rec.fs_hz:.3g} s); "
                        "locating a joint needs a periodic force (a multisine, as a ground vibration test uses), two "
                        "or more whole periods, at every level")
    n = exc.period_samples
    lines = np.asarray(exc.lines, int)
    force = signal_spectra(rec, exc, "force").mean(axis=0)  # (steady periods, lines) of the periodic estimator
    responses, std, whole = {}, {}, {}
    for name in rec.channels:
        if name == "force":
            continue
        Y = signal_spectra(rec, exc, name)
        responses[name] = Y.mean(axis=0)
        x = np.asarray(rec[name], float)[: exc.periods * n].reshape(exc.periods, n)[list(exc.steady)]
        whole[name] = np.fft.rfft(x.mean(axis=0))
        std[name] = np.sqrt(np.var(Y, axis=0, ddof=1) / Y.shape[0] / 2.0)
    if not responses:
        raise DataError(f"{source}: no response channel beside the force")
    return PeriodicSpectra(source, force_level(rec["force"]), float(rec.fs_hz), int(n), lines, force, responses, std,
                           whole)


def _excited(recording):
    """(its name, the recording with its excitation read, that excitation)."""
    rec = received(recording)
    return str(recording.meta.get("source", "recording")), rec, excitation_of(rec)


RING_OUT = 0.25     # of the record: zeros after it (to a whole number of `BLOCK`: levels of one design share lines)
BLOCK = 1024


def transient_spectra(recording) -> PeriodicSpectra:
    """`PeriodicSpectra` of a sine sweep at rest at both ends (`sweepfrf.at_rest_at_the_end`): the record with zeros
    after it (`RING_OUT`) as one period, the lines between the sweep's two ends. One record has no periods to spread
    over: ``std`` is NaN (locating weighs each level by its mean response, not by it).

    Not taken by `locate_joint` or `discover` on their own (`periodic_spectra` refuses a sweep): given explicitly,
    ``locate_joint([transient_spectra(r) for r in levels])``. On the independent ground vibration tests swept
    instead of multisined (`benchmarks/structures_gvt_sweeps.py`, 10 joints and 2 nulls) it placed 7 joints, named
    no law (the sparse library won every time) and left both nulls clean, where the multisines placed 9 and named 9.
    Not for the noise of one record a level: simulated without noise, two of those tests got the same verdicts
    (`benchmarks/structures_sweeps_why.py`). On a wing's cubic joint to the ground, noise-free, the true law at the
    true place leaves 5.6 % of the levels' change ``E = A − H F`` unexplained (the sparse library 3.8 %); through the
    structure's exact transfer 50 %, and 0.9 % once the acquisition's anti-alias low-pass is taken off the stroke the law is evaluated on (its
    phase on the joint's harmonics) and the lowest level's own joint response is subtracted (a sweep's levels are
    one sweep scaled: it is in every other level's change, scaled, not random-phase as a multisine's). Neither is
    known before a model is fitted. The stroke is made from every line up to 0.8 of Nyquist (a sweep's start and its
    harmonics ring modes above its band): from the band alone it placed 5 of the 10.

    Parameters
    ----------
    recording : Recording of one level, its force a sine sweep, the structure at rest before it and rung down after

    Returns
    -------
    PeriodicSpectra

    Raises
    ------
    DataError
        A force that is not a sweep, a response not rung down by the record's end, or fewer than 8 lines.
    """
    from ..signal.sweepfrf import RUNG_DOWN, at_rest_at_the_end

    source, rec, exc = _excited(recording)
    if exc.kind != "sweep":
        raise DataError(f"{source}: the force is {exc.kind}, not a sweep")

    n_rec = len(rec["force"])
    n = int(np.ceil(n_rec * (1 + RING_OUT) / BLOCK)) * BLOCK
    fs = float(rec.fs_hz)
    lo, hi = sorted((float(exc.sweep["f_start_hz"]), float(exc.sweep["f_end_hz"])))
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    lines = np.flatnonzero((freq >= lo) & (freq <= hi))
    if lines.size < 8:
        raise DataError(f"{source}: the sweep covers {lines.size} lines of its record ({lo:.3g}–{hi:.3g} Hz); "
                        "at least 8 are needed")
    force = np.fft.rfft(np.asarray(rec["force"], float), n)
    names = [c for c in rec.channels if c != "force"]
    moving = [c for c in names if not at_rest_at_the_end(rec, [c])]
    if moving:
        raise DataError(f"{source}: the sweep's record ends with the structure still moving ({', '.join(moving)} "
                        f"above {100 * RUNG_DOWN:g} % of the loudest {'they' if len(moving) > 1 else 'it'} reached); "
                        "locating a joint from a sweep needs "
                        "the response recorded until it rings out (a few seconds of quiet after the sweep), or a "
                        "periodic force")
    responses, std, whole = {}, {}, {}
    for name in names:
        whole[name] = np.fft.rfft(np.asarray(rec[name], float), n)
        responses[name] = whole[name][lines]
        std[name] = np.full(lines.size, np.nan)
    if not responses:
        raise DataError(f"{source}: no response channel beside the force")
    return PeriodicSpectra(source, force_level(rec["force"]), fs, n, lines, force[lines], responses, std, whole)


FALSE_LINES = 0.1   # noise lines a record's force may keep by chance, on average (`significant_lines`)
POOL = 16           # lines each side whose spread over the periods gives a line's noise (`significant_lines`)
MIN_STEADY = 3      # steady periods needed to tell a line's mean from its noise


def at_the_door(recording):
    """The recording carrying its excitation (`signal.excitation.received`), read once for every simulation that
    follows (`drive_force`, `warmup_of`), or as it came where none is read (its force is then driven as measured);
    each response about its mean (`centred`)."""
    try:
        return centred(received(recording))
    except DataError:
        return centred(recording)


def centred(recording):
    """``recording`` with each response's mean taken off. A structure held in place has no mean acceleration: a
    response's mean is its sensor's or its acquisition's offset, which no model of the structure simulates (half
    a chain sensor's RMS of offset took its predicted level's NRMSE from 0.010 to 0.500). The force is left as
    measured (`drive_force` reads it at its lines)."""
    from ..io import Recording

    means = {c: float(np.mean(v)) for c, v in recording.channels.items() if c != "force"}
    if not any(means.values()):
        return recording
    channels = {c: (np.asarray(v, float) - means[c] if c in means else v) for c, v in recording.channels.items()}
    return Recording(recording.fs_hz, channels, recording.units, recording.meta, recording.labels)


def drive_force(recording) -> np.ndarray:
    """The force a model of the structure is driven by: as measured, except over the steady periods of a periodic
    force, where it is the mean period at the lines whose mean stands above its noise (`significant_lines`),
    nothing at the others. A simulation driven by the measured force answers the load cell's noise too,
    most where the structure is most mobile: above the band, at the driving point (on an independent frame the
    driving point's held-out NRMSE over the steady periods went from 0.037 to 0.014, its noise 0.010). Lines
    the shaker puts there by itself (harmonics of a structure's nonlinear feedback) stand above the noise and
    stay. The periods before the steady ones are that mean period plus their departure from it for as long as the
    departure stands above the load cell's noise (`start_transient`): a start from rest carries what a period
    cannot (the step the force starts with, a shaker's own start-up), and after it only the noise.
    """
    force = np.asarray(recording["force"], float)
    try:
        exc = excitation_of(received(recording))
    except DataError:
        return quiet_outside_band(force)
    steady = list(exc.steady)
    if exc.kind != "periodic" or len(steady) < MIN_STEADY:
        return quiet_outside_band(force)
    n = int(exc.period_samples)
    # its mean is the load cell's offset, or a preload met before the record: no drive, no step at the start
    force = force - force[steady[0] * n:(steady[-1] + 1) * n].mean()
    steady_periods = force[: exc.periods * n].reshape(exc.periods, n)[steady]
    X = np.fft.rfft(steady_periods, axis=1)
    mean = X.mean(axis=0)
    keep = significant_lines(X)
    keep[0] = True  # the load cell's offset as it was
    period = np.fft.irfft(np.where(keep, mean, 0.0), n)
    out = force.copy()
    for p in steady:
        out[p * n:(p + 1) * n] = period
    start = steady[0] * n
    if start:
        noise = float(np.std(steady_periods - period))
        periodic = np.tile(period, steady[0])
        out[:start] = periodic + start_transient(force[:start] - periodic, noise)
    return out


CONTRAST = 100.0  # a force's band stands this far (in power) above its floor before the floor is taken out
ABOVE_FLOOR = 10.0  # ... and a frequency keeps the force where its smoothed power is above this times the floor
FLOOR_SHARE = 0.1   # the floor: this quantile of the smoothed power (a band-limited force leaves more than this)
EDGE = 512        # samples mirrored at each end of the record before its FFT


def quiet_outside_band(force) -> np.ndarray:
    """``force`` less what it holds outside its own band, where that band stands well above its floor (`CONTRAST`):
    a force that is not periodic (a sweep, a band-limited random force) cannot be averaged over periods, and a
    model driven by it answers the load cell's noise at every frequency, most at the driving point, whose mass
    line passes it straight through (on independent ground vibration tests swept at seven levels, the driving
    point's error of a frame was 3.8 times its noise at every level, in the quiet after the sweep as in it).
    The power is smoothed over a few lines, the floor is its `FLOOR_SHARE` quantile, and the lines below
    `ABOVE_FLOOR` times the floor are cleared (the offset kept), over the record mirrored at its ends so that
    its start and end do not meet in a step. A force that fills its spectrum (an impact, a white random force)
    has no such contrast and is returned as it is."""
    x = np.asarray(force, float)
    extended, pad = mirrored(x, EDGE)
    if pad < 1:
        return x
    X = np.fft.rfft(extended)
    width = max(8, X.size // 256)
    power = np.convolve(np.abs(X) ** 2, np.ones(width) / width, mode="same")
    floor = float(np.quantile(power[1:], FLOOR_SHARE))
    keep = power > ABOVE_FLOOR * floor
    if not (floor > 0 and np.any(keep[1:]) and np.median(power[1:][keep[1:]]) >= CONTRAST * floor):
        return x
    keep[0] = True  # the load cell's offset as it was
    return np.fft.irfft(np.where(keep, X, 0.0), extended.size)[pad:pad + x.size]


def significant_lines(spectra) -> np.ndarray:
    """(K,) bool: the lines of ``spectra`` (P periods, K lines) whose mean over the periods stands above its noise,
    where no more than `FALSE_LINES` lines of noise would, on average, over the whole record.

    A line's noise is the spread over the periods of its `POOL` neighbours each side (the noise's spectrum is
    smooth), not of the line alone: from three to five periods the line's own spread is so uncertain that a
    ratio of three standard errors let one noise line in 60 through (F(2, 2(P − 1)) tails), 5 to 27 a record on
    independent ground vibration tests, and a lightly damped mode above the band then answered them (a wing's
    quiet channel missed its held-out level by 0.019 of its RMS at one such line, at 86.0 Hz beside its 86.8 Hz
    mode). With the pooled spread the mean's power over the noise's is nearly exponential, so the threshold that
    lets `FALSE_LINES` through K lines is ``ln(K / FALSE_LINES)``."""
    from scipy.ndimage import uniform_filter1d

    X = np.asarray(spectra)
    periods, lines = X.shape
    mean = X.mean(axis=0)
    variance = np.sum(np.abs(X - mean) ** 2, axis=0) / (periods - 1) / periods  # of the mean, line by line
    noise = uniform_filter1d(variance, 2 * POOL + 1, mode="nearest")
    return np.abs(mean) ** 2 > np.log(lines / FALSE_LINES) * np.maximum(noise, TINY)


TRANSIENT_LOUD = 4.0   # load-cell noise standard deviations a start's departure from the period stands above
TRANSIENT_SMOOTH = 8   # samples its envelope is averaged over


def start_transient(departure, noise: float) -> np.ndarray:
    """``departure`` (the start's force less the steady period) up to the last sample where its envelope stands
    `TRANSIENT_LOUD` noise deviations above nothing, zero after: the start's transient without the noise that
    follows it. On independent ground vibration tests the load cell's noise in the first period, through a
    sensor's flat accelerance, missed the first period by twice the steady periods' NRMSE."""
    d = np.asarray(departure, float)
    envelope = np.convolve(np.abs(d), np.ones(TRANSIENT_SMOOTH) / TRANSIENT_SMOOTH, mode="same")
    loud = np.flatnonzero(envelope > TRANSIENT_LOUD * noise)
    end = int(loud[-1]) + TRANSIENT_SMOOTH if loud.size else 0
    return np.where(np.arange(d.size) < end, d, 0.0)


START_SHARE = 1 / 32   # of a period: the start a start from rest shows, its response building up from nothing
AT_REST = 0.25         # the start's departure from the steady periods' (median over channels) beyond which it was at rest


def warmup_of(recording) -> int:
    """Samples of warm-up before a recording: one period of a periodic force whose record starts in steady
    state, else none (from rest, as the record did). A record starts in steady state where its first period
    has no start-up transient, or where the first `START_SHARE` of it departs from the steady periods by less
    than `AT_REST` of their RMS: a start from rest departs by all of it (on independent ground vibration tests
    0.4 to 1.3), a record cut from a longer test only by its drift (on the F-16, whose slow drift over the
    first periods reads as a transient, 0.13 to 0.16)."""
    try:
        rec = received(recording)
        exc = excitation_of(rec)
    except DataError:
        return 0
    if exc.kind != "periodic":
        return 0
    n = int(exc.period_samples)
    if not exc.transient_periods or not _starts_from_rest(rec, exc):
        return n
    return 0


def _starts_from_rest(rec, exc) -> bool:
    n, steady = int(exc.period_samples), list(exc.steady)
    m = max(int(START_SHARE * n), 1)
    if not steady or exc.periods < 2:
        return True
    departures = []
    for name in rec.channels:
        if name == "force":
            continue
        y = np.asarray(rec[name], float)[: exc.periods * n].reshape(exc.periods, n)
        mean = y[steady].mean(axis=0)[:m]
        departures.append(np.sqrt(np.mean((y[0, :m] - mean) ** 2) / max(np.mean(mean ** 2), TINY)))
    return bool(np.median(departures) > AT_REST) if departures else True
