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

from ..errors import DataError
from .periods import MIN_AUTOCORRELATION, PERIODIC_SPREAD, excited_lines, find_period, periodic_layout  # noqa: F401

KINDS = ("auto", "random", "periodic", "impact", "sweep")


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


def received(recording, kind: str = "auto", period_s: float | None = None):
    """The door a recording comes in by: the recording carrying its excitation (`with_excitation`).

    Read once: a recording that carries its excitation already is returned as it is (unless a
    kind or a period is given, which is read anew); one without a force has none to read. Every
    later step asks `excitation_of`, never the force again.

    Parameters
    ----------
    recording : Recording
    kind, period_s : as `detect_excitation`

    Returns
    -------
    Recording
    """
    if "force" not in recording.channels:
        return recording
    carried = (recording.meta or {}).get("excitation_layout")
    if carried and str(kind).lower() == "auto" and period_s is None:
        return recording
    return with_realisations(with_excitation(recording, detect_excitation(recording, kind, period_s)))


def with_realisations(recording):
    """A lab's realisations (`Recording.realisations`) that are each periodic with one period, one count of
    periods and one start-up, laid out as satmd's own multisine records of several realisations are
    (``period_samples``, ``periods`` of each, ``transient_periods``, ``lines`` excited in every one): the best
    linear approximation over them (`satmd.signal.periodic.multisine_frf`) and the detection-line test read
    them. Otherwise as it came, with no periodic layout claimed for the whole (its realisations differ)."""
    parts = recording.realisations() if hasattr(recording, "realisations") else [recording]
    if len(parts) < 2:
        return recording
    from dataclasses import replace

    found = [excitation_of(p) for p in parts]  # each read at the door on its own
    meta = {k: v for k, v in recording.meta.items()
            if k not in ("period_samples", "periods", "transient_periods", "steady_periods", "lines")}
    one = {(e.kind, e.period_samples, e.periods) for e in found}
    lines = set.intersection(*(set(e.lines) for e in found))
    if len(one) == 1 and found[0].kind == "periodic" and found[0].periods >= 2 and lines:
        meta |= {"period_samples": str(found[0].period_samples), "periods": str(found[0].periods),
                 "transient_periods": str(max(e.transient_periods for e in found)),
                 "lines": ",".join(str(k) for k in sorted(lines))}
    return replace(recording, meta=meta)


def excitation_of(recording) -> Excitation:
    """The excitation a recording carries (read at the door, `received`, if it came in another way).

    Parameters
    ----------
    recording : Recording with a ``force`` channel

    Returns
    -------
    Excitation
    """
    if "force" not in recording.channels:
        raise DataError("the recording has no force channel: no excitation to read")
    return Excitation.from_meta(received(recording).meta["excitation_layout"])


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


def _periodic(x, fs, outs, detected: bool):
    period, r = find_period(x)
    if not period:
        return None
    layout = periodic_layout(x, fs, outs, period, evidence=f"the force repeats every {period} samples "
                                                          f"(autocorrelation {r:.3f} there)")
    return None if layout is None else Excitation("periodic", detected, fs, **layout)


def _periodic_given(x, fs, outs, period_s):
    period = int(round(period_s * fs))
    if not np.isfinite(period_s) or period_s <= 0 or abs(period - period_s * fs) > 1e-6 * max(period, 1) + 1e-9:
        raise DataError(f"period_s = {period_s:g} s is not a whole number of samples at {fs:g} Hz "
                        f"({period_s * fs:g}); give it to the sample")
    if period < 8 or 2 * period > x.size:
        raise DataError(f"period_s = {period_s:g} s ({period} samples) does not fit twice in the "
                        f"{x.size / fs:g} s record")
    layout = periodic_layout(x, fs, outs, period, evidence=f"period {period_s:g} s as given")
    if layout is None:
        raise DataError(f"period_s = {period_s:g} s: the force does not repeat with it; its periods differ by more than "
                        f"{100 * PERIODIC_SPREAD:.0f} % of their power (a wrong period?)")
    return Excitation("periodic", False, fs, **layout)


def _random_evidence(x) -> str:
    period, r = find_period(x)
    return f"no period (autocorrelation ≤ {r:.2f} beyond the first lags), no pulses, no sweep"


__all__ = ["Excitation", "KINDS", "detect_excitation", "excited_lines", "find_period", "with_excitation",
           "with_realisations"]
