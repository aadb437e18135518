"""FRFs in Universal File Format dataset 58 (ASCII "58" and binary "58b").

The datasets themselves are read and written by `satmd.io.uff58` (through
``pyuff``, every error a one-line `FormatError`); this module maps FRF records
to channels and units.

FRF records (function type 4) become `FRFData`:

* files written by satmd carry ``satmd:<name>`` in ID line 1 and map back
  to their channels exactly (std as function type 0, coherence as type 6);
* other files: with exactly two responses the first in the file is ``a1``
  and the second ``a2``; otherwise ``channel_map="a1=NODE:DIR,a2=NODE:DIR"``
  (or ``#N`` for the N-th dataset) says which is which;
* units stated in the file (ordinate and denominator labels, or the
  specific data types) are converted to SI, and displacement / velocity /
  acceleration records are converted to the requested channel by factors
  of ``iω`` (convention ``e^{+iωt}``); record directions and the reference
  direction set the sign.

Writing is bit-exact in binary; ASCII (``binary=False``) keeps the 13
significant digits of the format (see `satmd.io.uff58`).
"""
from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import DataError, FormatError
from ._common import channel_map_of, parse_frf_unit, parse_quantity_unit, warn
from .frfdata import CHANNELS, FRFData
from .uff58 import (  # noqa: F401 - the record layer, importable from here as before
    FUNCTION_TYPES,
    SPEC_TYPES,
    TAG,
    WRITE_DOF,
    UffRecord,
    dataset58,
    dof_label,
    match_records,
    read_records,
    write_datasets,
)

_POWER_OF_SPEC = {8: 0, 11: 1, 12: 2}  # time derivatives of a length


# --- reading ----------------------------------------------------------------------
def read_uff(path, channel_map=None) -> FRFData:
    """FRFs (function type 4) from a UFF 58 / 58b file; see the module docstring."""
    path = Path(path)
    records, others = read_records(path)
    frfs = [r for r in records if r.func_type == 4]
    if not frfs:
        kinds = sorted({r.function for r in records})
        if any(r.func_type == 1 for r in records):
            raise FormatError(path, f"holds {sum(r.func_type == 1 for r in records)} time record(s) (function type 1), "
                                    f"not FRFs: estimate FRFs with `satmd estimate-frf`")
        found = ", ".join(kinds) if kinds else "no dataset 58"
        raise FormatError(path, f"no FRF records (UFF 58, function type 4); found: {found}")
    if all(r.tag for r in records):
        return _read_tagged(path, records, channel_map and _map_channels(path, frfs, channel_map))
    chosen = _map_channels(path, frfs, channel_map)
    freq = _common_axis(path, [rec for rec, _ in chosen.values()])
    keep, freq = _positive(path, freq)
    channels, coherence = {}, {}
    for ch, (rec, sign) in chosen.items():
        channels[ch] = sign * _to_channel(path, rec, ch, freq, rec.data[keep].astype(complex))
        coh = [r for r in records if r.func_type == 6 and r.rsp == rec.rsp and r.ref == rec.ref
               and r.data.size == rec.data.size]
        if len(coh) == 1:
            coherence[ch] = np.clip(coh[0].data.real[keep], 0.0, 1.0)
    meta = {"source": str(path), "format": "UFF 58",
            "records": ", ".join(f"{ch}={rec.describe()}" for ch, (rec, _) in chosen.items())}
    try:
        return FRFData(freq, channels, {}, meta, coherence=coherence)
    except DataError as exc:
        raise FormatError(path, str(exc)) from None


def _read_tagged(path, records, chosen=None) -> FRFData:
    """A file written by `write_uff`: names come from the tags (or ``chosen``, a checked map), values are SI."""
    by_tag = {}
    for r in records:
        if r.tag in by_tag:
            raise FormatError(path, f"dataset {r.index}: second record tagged {TAG}{r.tag}", line=r.line)
        by_tag[r.tag] = r
    chans = [t for t in by_tag if t in CHANNELS]
    if not chans:
        raise FormatError(path, "satmd-tagged file without FRF channels")
    freq = _common_axis(path, list(by_tag.values()))
    channels, std, coherence = {}, {}, {}
    for tag, r in by_tag.items():
        name, _, kind = tag.partition("_")
        if name not in CHANNELS or kind not in ("", "std", "coh") or (kind and name not in chans):
            raise FormatError(path, f"dataset {r.index}: unknown satmd record {TAG}{tag}", line=r.line)
        if kind == "":
            channels[name] = r.data.astype(complex)
        elif kind == "std":
            std[name] = r.data.real.astype(float)
        else:
            coherence[name] = r.data.real.astype(float)
    if chosen:  # a channel map renames the tagged FRF records; their std and coherence follow them
        renamed = {ch: rec.tag for ch, (rec, _) in chosen.items()}
        channels = {ch: channels[tag] for ch, tag in renamed.items()}
        std = {ch: std[tag] for ch, tag in renamed.items() if tag in std}
        coherence = {ch: coherence[tag] for ch, tag in renamed.items() if tag in coherence}
    meta = {"source": str(path), "format": "UFF 58 (satmd)"}
    try:
        return FRFData(freq, channels, std, meta, coherence=coherence)
    except DataError as exc:
        raise FormatError(path, str(exc)) from None


def _map_channels(path, frfs, channel_map) -> dict:
    """{channel: (record, sign)} from --map or the two-response rule."""
    listing = ", ".join(r.describe() for r in frfs)
    if channel_map:
        wanted = channel_map_of(path, channel_map, CHANNELS)
        chosen = {}
        for ch, (kind, a, b) in wanted.items():
            if kind == "index":
                hits = match_records(frfs, kind, a, b)
                if not hits:
                    raise FormatError(path, f"channel_map {ch}=#{a}: dataset {a} is not an FRF record (FRFs: {listing})")
                chosen[ch] = (hits[0], _sign(hits[0]))
                continue
            hits = match_records(frfs, kind, a, b)
            if not hits:
                raise FormatError(path, f"channel_map {ch}={dof_label(a, b)}: no FRF record with that response "
                                        f"(FRFs: {listing})")
            if len(hits) > 1:
                raise FormatError(path, f"channel_map {ch}={dof_label(a, b)}: {len(hits)} FRF records match "
                                        f"({', '.join(r.describe() for r in hits)}); choose one with {ch}=#N")
            chosen[ch] = (hits[0], _sign(hits[0]) * (-1 if b < 0 else 1))
    elif len(frfs) == 2:
        names = ("u1", "u2") if all(_power(path, r)[0] == 0 for r in frfs) else ACCEL_CHANNELS
        chosen = {names[0]: (frfs[0], _sign(frfs[0])), names[1]: (frfs[1], _sign(frfs[1]))}
    elif len(frfs) == 1:
        warn(path, f"one FRF record ({listing}): read as a1, the primary mass; give a channel_map to say otherwise")
        chosen = {"a1": (frfs[0], _sign(frfs[0]))}
    else:
        raise FormatError(path, f"{len(frfs)} FRF records ({listing}): say which are A1 and A2 with "
                                f"channel_map a1=NODE:DIR,a2=NODE:DIR (or a1=#N,a2=#M)")
    seen: dict[int, str] = {}
    for ch, (rec, _) in chosen.items():
        if rec.index in seen:
            raise FormatError(path, f"channel_map: {seen[rec.index]} and {ch} both name dataset {rec.index}; "
                                    "one record cannot be two channels")
        seen[rec.index] = ch
    refs = {r.ref for r, _ in chosen.values()}
    if len(refs) > 1:
        warn(path, "the chosen FRF records have different reference DOFs "
                   f"({', '.join(dof_label(*x) for x in sorted(refs))}); satmd assumes one force on the primary mass")
    return chosen


def _sign(rec) -> int:
    """FRF for positive response and force directions: flip for each negative direction."""
    s = -1 if rec.rsp[1] < 0 else 1
    return -s if rec.ref[1] < 0 else s


def _power(path, rec):
    """(power, factor to SI) of an FRF record: power 0/1/2 = displacement/velocity/acceleration,
    None for a quantity that is not a motion (charge, unknown)."""
    power = _POWER_OF_SPEC.get(int(rec.get("ordinate_spec_data_type", 0)))
    num, den = rec.units("ordinate"), rec.units("orddenom")
    try:
        if num and not den and "/" in num:
            with contextlib.suppress(ValueError):
                return parse_frf_unit(num)  # the whole FRF unit in one label, e.g. 'g/N'
        factor = 1.0
        q = parse_quantity_unit(num)
        if q is not None:
            if q[0] == "force":
                raise ValueError(f"ordinate unit {num!r} is a force, not a response")
            power, factor = (None if q[0] == "charge" else q[0]), q[1]
        d = parse_quantity_unit(den)
        if d is not None:
            if d[0] != "force":
                raise ValueError(f"denominator unit {den!r} is not a force")
            factor /= d[1]
        return power, factor
    except ValueError as exc:
        warn(path, f"dataset {rec.index}: {exc}; values used as they are (SI assumed)")
        return power, 1.0


def _to_channel(path, rec, ch, freq, values):
    """Convert the record's quantity to channel `ch` (a* acceleration, u* displacement) in SI."""
    power, factor = _power(path, rec)
    target = {"a": 2, "u": 0}.get(ch[0])
    if power is None or target is None:
        if target is not None and not rec.tag:
            warn(path, f"dataset {rec.index}: ordinate quantity not stated; read as {ch} in SI units")
        return values * factor if factor != 1.0 else values
    if power != target:
        values = values * (2j * np.pi * freq) ** (target - power)
    return values * factor if factor != 1.0 else values


def _common_axis(path, records) -> np.ndarray:
    first = records[0]
    for r in records[1:]:
        if r.x.size != first.x.size:
            raise FormatError(path, f"dataset {r.index} has {r.x.size} points, dataset {first.index} has "
                                    f"{first.x.size}: records must share one frequency axis", line=r.line)
        if not np.allclose(r.x, first.x, rtol=1e-9, atol=0):
            raise FormatError(path, f"dataset {r.index}: frequency axis differs from dataset {first.index}",
                              line=r.line)
    x = first.x.astype(float)
    units = first.units("abscissa").lower().replace(" ", "")
    if units in ("rad/s", "rad/sec"):
        x = x / (2 * np.pi)
    elif units not in ("", "hz", "1/s"):
        warn(path, f"dataset {first.index}: abscissa unit {first.units('abscissa')!r} read as Hz")
    return x


def _positive(path, freq):
    keep = freq > 0
    if not keep.all():
        warn(path, f"dropped {int((~keep).sum())} point(s) at f <= 0 Hz (FRFs are used for f > 0)")
    f = freq[keep]
    if f.size == 0:
        raise FormatError(path, "no frequency above 0 Hz")
    bad = np.flatnonzero(np.diff(f) <= 0)
    if bad.size:
        raise FormatError(path, f"frequencies not strictly increasing ({f[bad[0] + 1]:g} Hz after {f[bad[0]]:g} Hz)")
    return keep, f


# --- writing ----------------------------------------------------------------------
_WRITE_ORDINATE = {"a": (12, "Acceleration", "m/s^2"), "u": (8, "Displacement", "m"), "q": (1, "Charge", "C"),
                   "f": (13, "Force", "N")}


def write_uff(data: FRFData, path, binary: bool = True) -> Path:
    """Write FRFs (function type 4), their std (type 0) and coherence (type 6) as UFF 58.

    Each record is tagged ``satmd:<name>`` in ID line 1, so `read_uff` maps
    it back; other programs see ordinary FRFs with response node 1 (primary
    mass) or 2 (absorber) in +Z, force reference 1:+Z, units m/s^2 / N.
    """
    parts = []
    for ch, v in data.channels.items():
        spec = _WRITE_ORDINATE[ch[0]]
        common = dict(rsp=WRITE_DOF[ch], ref=(1, 3), binary=binary, id2="satmd-frf v1")
        parts.append(dataset58(data.freq_hz, v, func_type=4, tag=ch, ordinate=spec,
                               denominator=(13, "Force", "N"), **common))
        if ch in data.std:
            parts.append(dataset58(data.freq_hz, data.std[ch], func_type=0, tag=f"{ch}_std",
                                   ordinate=(1, "Std of Re and Im", spec[2] + "/N"), **common))
        coherence = getattr(data, "coherence", {}) or {}
        if ch in coherence:
            parts.append(dataset58(data.freq_hz, coherence[ch], func_type=6, tag=f"{ch}_coh",
                                   ordinate=(1, "Coherence", "NONE"), **common))
    return write_datasets(parts, path)


__all__ = ["UffRecord", "read_records", "read_uff", "write_uff", "dataset58", "write_datasets",
           "FUNCTION_TYPES", "dof_label"]
