"""What excited a recording: a random force, a periodic one, impacts or a sweep, read from the force.

Lab files carry no metadata, so the excitation is detected from the force
itself (or given by the user, ``kind=``), in this order:

``impact``    sparse pulses: the samples above a tenth of the peak make < 5 % of
              the record and the pulses hold most of the force's energy; hits
              are segmented, double hits (a second pulse within the first's
              ring-down), clipped hits (a flat top) and a hit too close to the
              record's end are dropped, each with its reason;
``periodic``  the force repeats: the normalised autocorrelation peaks at a lag
              (the shortest lag within 5 % of the highest peak), and the periods
              agree within their noise (the spread over periods is < 10 % of the
              period's power); leading periods where the responses still carry
              the start-up transient are dropped, and so is a period that differs
              from the others (a glitch); multisines, pseudo-random noise and
              periodic chirps are all periodic;
``sweep``     one tone whose instantaneous frequency moves monotonically over a
              ratio of at least 1.5 with a near-constant envelope;
``random``    anything else (the local polynomial method's home).

The estimator each calls for lives in `satmd.signal.estimate`; this module only
says what the force is.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..conventions import TINY
from ..errors import DataError

KINDS = ("auto", "random", "periodic", "impact", "sweep")

PERIODIC_SPREAD = 0.10  # period-to-period spread of the force, as a share of its power, still called periodic
MIN_AUTOCORRELATION = 0.5  # normalised autocorrelation at the period: below it the force does not repeat


@dataclass(frozen=True)
class Excitation:
    """The excitation of a recording and the layout the estimators need.

    Attributes
    ----------
    kind : ``random``, ``periodic``, ``impact`` or ``sweep``
    detected : True when read from the force, False when given by the user
    fs_hz : the recording's sample rate
    period_samples : samples per period (periodic)
    periods : whole periods in the record (periodic)
    steady : indices of the periods averaged (periodic: transient and glitched periods left out)
    transient_periods : leading periods dropped for the start-up transient
    lines : excited DFT lines of one period (periodic)
    hits : (start, peak) sample of each kept hit (impact)
    segment_samples : samples per hit segment (impact)
    dropped : (what, reason) for each hit or period left out
    sweep : f_start_hz, f_end_hz, direction, law (sweep)
    evidence : how it was told, in words
    """

    kind: str
    detected: bool
    fs_hz: float
    period_samples: int = 0
    periods: int = 0
    steady: tuple = ()
    transient_periods: int = 0
    lines: tuple = ()
    hits: tuple = ()
    segment_samples: int = 0
    dropped: tuple = ()
    sweep: dict = field(default_factory=dict)
    evidence: str = ""

    @property
    def period_s(self) -> float:
        """Seconds per period (0 when not periodic)."""
        return self.period_samples / self.fs_hz if self.period_samples else 0.0

    def to_dict(self) -> dict:
        """The report's ``estimator.excitation`` (SPEC §9)."""
        out: dict = {"kind": self.kind, "source": "detected" if self.detected else "given"}
        if self.kind == "periodic":
            out |= {"period_s": round(self.period_s, 9), "periods": int(self.periods),
                    "periods_used": len(self.steady), "transient_periods": int(self.transient_periods),
                    "excited_lines": len(self.lines)}
        if self.kind == "impact":
            out |= {"hits": len(self.hits), "segment_s": round(self.segment_samples / self.fs_hz, 9)}
        if self.kind == "sweep":
            out |= {k: (round(v, 6) if isinstance(v, float) else v) for k, v in self.sweep.items()}
        if self.dropped:
            out["dropped"] = [f"{what}: {why}" for what, why in self.dropped]
        if self.evidence:
            out["evidence"] = self.evidence
        return out

    def to_meta(self) -> str:
        """The whole layout as a JSON string (a recording's ``meta["excitation_layout"]``)."""
        import json
        from dataclasses import asdict

        return json.dumps(asdict(self), separators=(",", ":"))

    @classmethod
    def from_meta(cls, text: str) -> "Excitation":
        """The inverse of `to_meta`."""
        import json

        d = json.loads(text)
        for key in ("steady", "lines", "dropped"):
            d[key] = tuple(tuple(x) if isinstance(x, list) else x for x in d.get(key, ()))
        d["hits"] = tuple(tuple(h) for h in d.get("hits", ()))
        return cls(**d)

    def describe(self) -> str:
        """One phrase for notes and reports."""
        how = "detected" if self.detected else "as given"
        if self.kind == "periodic":
            return (f"periodic force ({how}): {self.periods} periods of {self.period_s:.6g} s, "
                    f"{len(self.steady)} averaged, {len(self.lines)} excited lines")
        if self.kind == "impact":
            return f"impact ({how}): {len(self.hits)} hits of {self.segment_samples / self.fs_hz:.4g} s"
        if self.kind == "sweep":
            s = self.sweep
            return f"{s.get('law', '')} sweep ({how}) {s.get('f_start_hz', 0):.4g} → {s.get('f_end_hz', 0):.4g} Hz"
        return f"random force ({how})"


def detect_excitation(recording, kind: str = "auto", period_s: float | None = None,
                      responses: tuple = ("acc1", "acc2")) -> Excitation:
    """The excitation of ``recording``, detected from its force or as given.

    Parameters
    ----------
    recording : Recording
        With a ``force`` channel.
    kind : {"auto", "random", "periodic", "impact", "sweep"}
        ``auto`` detects it (see the module docstring); any other is taken as
        given, and its layout (periods, hits, sweep) is still read from the force.
    period_s : float, optional
        The period in seconds (periodic); implies ``kind="periodic"`` under ``auto``.
    responses : channels whose start-up transient decides the periods to drop

    Returns
    -------
    Excitation

    Raises
    ------
    DataError
        An unknown kind, a period that does not fit the record, or a given kind
        the force cannot be read as (no hit in an ``impact`` record, ...).
    """
    from .hits import find_hits
    from .sweep import find_sweep

    kind = str(kind).lower()
    known = (getattr(recording, "meta", None) or {}).get("excitation_layout")
    if known and kind == "auto" and period_s is None:  # read once, carried with the recording
        return Excitation.from_meta(known)
    if kind not in KINDS:
        raise DataError(f"excitation {kind!r} is not one of {', '.join(KINDS)}")
    x = np.asarray(recording["force"], float)
    fs = float(recording.fs_hz)
    outs = [np.asarray(recording[c], float) for c in responses if c in recording.channels]
    if not outs:
        outs = [np.asarray(recording[c], float) for c in recording.channels if c != "force"]
    if period_s is not None:
        if kind not in ("auto", "periodic"):
            raise DataError(f"a period ({period_s:g} s) is given but the excitation is {kind!r}")
        return _periodic_given(x, fs, outs, float(period_s))
    if kind == "random":
        return Excitation("random", False, fs)
    if kind == "impact":
        try:
            hits = find_hits(x, fs, detected=False)
        except DataError as why:
            raise DataError(f"excitation 'impact' given, but {why}") from None
        if hits is None:
            raise DataError("excitation 'impact' given, but the force holds no pulse that stands out "
                            "(no sample above a tenth of the peak is separated from the rest)")
        return Excitation("impact", False, fs, **hits)
    if kind == "periodic":
        exc = _periodic(x, fs, outs, detected=False)
        if exc is None:
            raise DataError("excitation 'periodic' given, but the force does not repeat within the record "
                            "(no period with at least two copies): give the period (period_s)")
        return exc
    if kind == "sweep":
        sweep = find_sweep(x, fs, detected=False)
        return Excitation("sweep", False, fs, **(sweep or {"evidence": "no sweep law could be read"}))
    hits = find_hits(x, fs, detected=True)
    if hits is not None:
        return Excitation("impact", True, fs, **hits)
    exc = _periodic(x, fs, outs, detected=True)
    if exc is not None:
        return exc
    sweep = find_sweep(x, fs, detected=True)
    if sweep is not None:
        return Excitation("sweep", True, fs, **sweep)
    return Excitation("random", True, fs, evidence=_random_evidence(x))


def with_excitation(recording, excitation: Excitation):
    """The recording with its excitation in ``meta`` (every later step reads the same layout).

    A periodic layout is also written as the multisine keys the nonlinear
    tests read (``period_samples``, ``periods``, ``transient_periods``, ``lines``).
    """
    from dataclasses import replace

    meta = dict(recording.meta, excitation_layout=excitation.to_meta())
    if excitation.kind == "periodic":
        meta |= {"period_samples": str(excitation.period_samples), "periods": str(excitation.periods),
                 "transient_periods": str(excitation.transient_periods),
                 "steady_periods": ",".join(str(i) for i in excitation.steady),
                 "lines": ",".join(str(k) for k in excitation.lines)}
    return replace(recording, meta=meta)


# --- periodic -------------------------------------------------------------------------------------------
def _autocorrelation(x):
    """Normalised autocorrelation r(L) for lags 0..n//2 (each lag by the energy of its own overlap)."""
    n = x.size
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    X = np.fft.rfft(x, nfft)
    r = np.fft.irfft(np.abs(X) ** 2, nfft)[: n // 2 + 1]
    e = np.concatenate(([0.0], np.cumsum(x * x)))
    lags = np.arange(n // 2 + 1)
    head = e[n - lags]  # energy of x[0:n-L]
    tail = e[n] - e[lags]  # energy of x[L:n]
    return r / np.sqrt(np.maximum(head * tail, TINY))


def find_period(x, min_lag: int = 16) -> tuple[int, float]:
    """(period in samples, autocorrelation there) of a record that repeats at least twice; (0, r) if none.

    The shortest lag whose normalised autocorrelation is within 5 % of the
    highest one beyond ``min_lag`` (a multiple of the period is as high).
    """
    x = np.asarray(x, float) - np.mean(x)
    if x.size < 4 * min_lag or not np.any(x):
        return 0, 0.0
    r = _autocorrelation(x)
    lags = np.arange(r.size)
    search = r.copy()
    # start after the first zero crossing: the band-limited force is correlated with itself at short lags
    first_neg = int(np.argmax(r[1:] <= 0)) + 1 if np.any(r[1:] <= 0) else r.size
    search[: max(min_lag, first_neg)] = -np.inf
    best = float(np.max(search))
    if not np.isfinite(best) or best < MIN_AUTOCORRELATION:
        return 0, max(best, 0.0) if np.isfinite(best) else 0.0
    peaks = (search[1:-1] >= search[:-2]) & (search[1:-1] >= search[2:]) & (search[1:-1] >= 0.95 * best)
    candidates = lags[1:-1][peaks]
    period = int(candidates[0]) if candidates.size else int(np.argmax(search))
    return period, float(r[period])


def _blocks(x, period, count):
    return np.asarray(x, float)[: count * period].reshape(count, period)


def _periodic(x, fs, outs, detected: bool):
    period, r = find_period(x)
    if not period:
        return None
    exc = _layout(x, fs, outs, period, detected, evidence=f"the force repeats every {period} samples "
                                                          f"(autocorrelation {r:.3f} there)")
    return exc


def _periodic_given(x, fs, outs, period_s):
    period = int(round(period_s * fs))
    if not np.isfinite(period_s) or period_s <= 0 or abs(period - period_s * fs) > 1e-6 * max(period, 1) + 1e-9:
        raise DataError(f"period_s = {period_s:g} s is not a whole number of samples at {fs:g} Hz "
                        f"({period_s * fs:g}); give it to the sample")
    if period < 8 or 2 * period > x.size:
        raise DataError(f"period_s = {period_s:g} s ({period} samples) does not fit twice in the "
                        f"{x.size / fs:g} s record")
    exc = _layout(x, fs, outs, period, False, evidence=f"period {period_s:g} s as given")
    if exc is None:
        raise DataError(f"period_s = {period_s:g} s: the force does not repeat with it; its periods differ by more than "
                        f"{100 * PERIODIC_SPREAD:.0f} % of their power (a wrong period?)")
    return exc


def _layout(x, fs, outs, period, detected, evidence):
    """Periods, the ones to average and the excited lines; None when the periods do not agree."""
    count = x.size // period
    U = _blocks(x, period, count)
    dropped = []
    # a glitch: a period far from the median period (robust to the glitch itself)
    med = np.median(U, axis=0)
    dist = np.mean((U - med) ** 2, axis=1)
    typical = np.median(dist)
    bad = dist > 25.0 * max(typical, 1e-30 * np.mean(med ** 2))
    if 0 < bad.sum() <= count // 4:
        dropped += [(f"period {i + 1}", "the force differs from the other periods there (a glitch)")
                    for i in np.flatnonzero(bad)]
    keep = np.flatnonzero(~bad) if bad.sum() <= count // 4 else np.arange(count)
    late = keep[len(keep) // 2:] if len(keep) >= 4 else keep
    mean = U[late].mean(axis=0)
    spread = float(np.mean((U[late] - mean) ** 2) / max(np.mean(mean ** 2), TINY))
    if spread > PERIODIC_SPREAD:
        return None
    lines = excited_lines(U[late])
    if lines.size < 1:
        return None
    # the start-up transient: leading periods whose responses are still far from the steady state
    transient = _transient_periods([_blocks(y, period, count) for y in outs], keep, lines)
    if count >= 3:  # the first period always goes (Pintelon & Schoukens): a transient below the test still leaks
        transient = max(transient, 1)
    if transient:
        dropped.append((f"period{'s' if transient > 1 else ''} 1{f'–{transient}' if transient > 1 else ''}",
                        "start-up transient in the responses"))
    steady = np.array([i for i in keep if i >= transient], int)
    if steady.size < 2:
        raise DataError(f"the force is periodic ({period / fs:.6g} s) but leaves {steady.size} steady period(s) "
                        f"of {count} after the start-up transient: at least 2 are needed to estimate the "
                        f"noise; record more periods")
    tail = x.size - count * period
    ev = evidence + (f"; {tail} samples after the last whole period left out" if tail else "")
    return Excitation("periodic", detected, fs, period_samples=int(period), periods=int(count),
                      steady=tuple(int(i) for i in steady), transient_periods=int(transient),
                      lines=tuple(int(k) for k in lines), dropped=tuple(dropped), evidence=ev)


def _transient_periods(outputs, keep, lines) -> int:
    """Leading periods where a response differs from its steady state beyond the noise, at the excited lines.

    The steady state and the noise per line come from the later half of the
    periods; a period is transient while its mean squared distance from the
    steady state is more than 3x what the noise gives (median over the lines) (at most all but 2 periods).
    """
    count = len(keep)
    if count < 3:
        return 0
    worst = 0
    for B in outputs:
        Y = np.fft.rfft(B, axis=1)[:, lines]
        late = Y[keep[count // 2:]]
        ref = late.mean(axis=0)
        h = late.shape[0]
        noise = np.sum(np.abs(late - ref) ** 2, axis=0) / max(h - 1, 1) * (1 + 1 / h)
        noise = np.maximum(noise, 1e-12 * np.mean(np.abs(ref) ** 2) + TINY)
        drop = 0
        for i in keep[: count - 2]:
            if np.median(np.abs(Y[i] - ref) ** 2 / noise) > 3.0:
                drop = int(i) + 1
            else:
                break
        worst = max(worst, drop)
    return min(worst, int(keep[count - 2]))


def excited_lines(periods) -> np.ndarray:
    """DFT lines of one period that the force excites: within 40 dB of the strongest and 15 dB above the noise.

    Parameters
    ----------
    periods : (P, N) steady periods of the force (P ≥ 2)

    Returns
    -------
    ndarray of int
        Lines 1 ≤ k < N/2.
    """
    U = np.fft.rfft(periods, axis=1)
    P, N = periods.shape
    mean = U.mean(axis=0)
    power = np.abs(mean) ** 2
    noise = np.sum(np.abs(U - mean) ** 2, axis=0) / max(P - 1, 1) / P  # variance of the mean, per line
    k = np.arange(power.size)
    ok = (k >= 1) & (k < (N + 1) // 2)
    floor = np.median(noise[ok]) if np.any(ok) else 0.0
    strong = power > 1e-4 * np.max(power[ok]) if np.any(ok) else np.zeros(power.size, bool)
    above = power > 10 ** 1.5 * max(floor, TINY)
    lines = np.flatnonzero(ok & strong & above)
    if lines.size < 5:
        return lines
    # a lone line far from the rest (mains pick-up in the force channel) is not part of the design
    # (far in both senses: a linear grid's low lines are far in relative terms, a log grid's high lines in absolute)
    steps = np.diff(lines).astype(float)
    nearest = np.minimum(np.append(steps, np.inf), np.insert(steps, 0, np.inf))
    relative = nearest / lines
    lone = (nearest > 10.0 * np.median(steps)) & (relative > 10.0 * np.median(steps / lines[1:]))
    return lines[~lone]


def _random_evidence(x) -> str:
    period, r = find_period(x)
    return f"no period (autocorrelation ≤ {r:.2f} beyond the first lags), no pulses, no sweep"


__all__ = ["Excitation", "KINDS", "detect_excitation", "excited_lines", "find_period", "with_excitation"]
