"""Recordings as UFF 58 / 58b time records (function type 1), several in one file, ASCII or binary.

Units stated in the file are converted to SI. Roles: files written by satmd
name their channels (force, acc1, acc2, acc3, ...); otherwise one force record
(specific data type 13 or 9, or a force unit) and two response records become
force/acc1/acc2 in file order, or ``channel_map="force=#1,a1=1:+Z,a2=2:+Z,a3=3:+Z"``
says which is which (any number of accelerometers ``a<N>``).
"""
from __future__ import annotations

import math
from pathlib import Path

from ..errors import DataError, FormatError
from ._common import channel_map_of, parse_quantity_unit, warn
from .recdata import (
    Recording,
    is_role,
    role_of,
    si_unit,
    snap_rate,
    uniform_rate,
    warn_clipping,
)
from .uff58 import (
    WRITE_DOF,
    dataset58,
    dof_label,
    match_records,
    read_records,
    write_datasets,
)


def read_recording_uff(path, channel_map=None) -> Recording:
    """Time records (function type 1) of a UFF 58 file as one recording (see the module docstring)."""
    path = Path(path)
    records, _ = read_records(path)
    times = [r for r in records if r.func_type == 1]
    if not times:
        kinds = sorted({r.function for r in records})
        raise FormatError(path, f"no time records (UFF 58, function type 1); found: {', '.join(kinds) or 'none'}")
    first = times[0]
    for r in times[1:]:
        if r.data.size != first.data.size:
            raise FormatError(path, f"dataset {r.index} has {r.data.size} samples, dataset {first.index} has "
                                    f"{first.data.size}", line=r.line)
    fs = _record_rate(path, first)
    for r in times[1:]:
        other = _record_rate(path, r)
        if abs(other - fs) > 1e-6 * fs:
            raise FormatError(path, f"dataset {r.index} is sampled at {other:g} Hz, dataset {first.index} at "
                                    f"{fs:g} Hz", line=r.line)
    names = _uff_roles(path, times, channel_map)
    channels, units, labels = {}, {}, {}
    for r in times:
        name = names[r.index]
        values, unit = _record_si(path, r, name)
        channels[name], units[name] = values, unit
        labels[name] = f"UFF #{r.index}, {dof_label(*r.rsp)}, {r.quantity()}".rstrip(", ")
    meta = {"source": str(path), "format": "UFF 58 time records"}
    try:
        rec = Recording(fs, channels, units, meta, labels)
    except DataError as exc:
        raise FormatError(path, str(exc)) from None
    warn_clipping(path, rec)
    return rec


def _record_rate(path, r) -> float:
    if int(r.get("abscissa_spacing", 0)) == 1:
        dt = float(r.get("abscissa_inc", 0.0))
        if not dt > 0 or not math.isfinite(dt):
            raise FormatError(path, f"dataset {r.index}: time step {dt:g} s is not > 0", line=r.line)
        return snap_rate(1.0 / dt)
    if r.x.size < 2:
        raise FormatError(path, f"dataset {r.index}: a time record needs at least 2 samples", line=r.line)
    try:
        return uniform_rate(path, r.x)
    except FormatError as exc:
        raise FormatError(path, f"dataset {r.index}: {str(exc).split(': ', 1)[1]}", line=r.line) from None


def _kind(r):
    """'force', 'acceleration' or None for a time record, from its units or specific data type."""
    try:
        q = parse_quantity_unit(r.units("ordinate"))
    except ValueError:
        q = None
    if q is not None:
        return {"force": "force", 2: "acceleration"}.get(q[0])
    return {9: "force", 13: "force", 12: "acceleration"}.get(int(r.get("ordinate_spec_data_type", 0)))


def _uff_roles(path, times, channel_map) -> dict:
    """{dataset number: channel name}."""
    names = {r.index: f"ch{r.index}" for r in times}
    if not channel_map and all(is_role(r.tag) for r in times) and len({r.tag for r in times}) == len(times):
        return {r.index: r.tag for r in times}  # written by satmd, and no map says otherwise
    if channel_map:
        wanted = channel_map_of(path, channel_map, role_of)
        for role, (kind, a, b) in wanted.items():
            hits = match_records(times, kind, a, b)
            listing = ", ".join(r.describe() for r in times)
            if len(hits) != 1:
                what = "no time record" if not hits else f"{len(hits)} time records"
                raise FormatError(path, f"channel_map {role}: {what} match (records: {listing}); use {role}=#N")
            if is_role(names[hits[0].index]):
                raise FormatError(path, f"channel_map: {names[hits[0].index]} and {role} both name dataset "
                                        f"{hits[0].index}; one record cannot be two channels")
            names[hits[0].index] = role
        return names
    # no map: one force (or none) and exactly two accelerometers, in file order
    kinds = {r.index: _kind(r) for r in times}
    forces = [r for r in times if kinds[r.index] == "force"]
    accs = [r for r in times if kinds[r.index] == "acceleration"]
    if len(forces) <= 1 and len(accs) == 2:
        if forces:
            names[forces[0].index] = "force"
        names[accs[0].index], names[accs[1].index] = "acc1", "acc2"
    return names


def _record_si(path, r, name):
    """Values in SI and their unit label; an acceleration channel must hold an acceleration."""
    label = r.units("ordinate")
    try:
        q = parse_quantity_unit(label)
    except ValueError:
        if is_role(name):
            warn(path, f"dataset {r.index}: unknown unit {label!r} for {name}; values used as they are")
        return r.data.real.astype(float), label
    if q is None:
        return r.data.real.astype(float), si_unit(name)
    kind, factor = q
    if is_role(name) and name != "force" and kind != 2:
        raise FormatError(path, f"dataset {r.index} mapped to {name} holds {label!r}, not an acceleration",
                          line=r.line)
    if name == "force" and kind != "force":
        raise FormatError(path, f"dataset {r.index} mapped to force holds {label!r}, not a force", line=r.line)
    si = {"force": "N", 2: "m/s^2", 1: "m/s", 0: "m", "charge": "C"}[kind]
    return r.data.real.astype(float) * factor, si


def write_recording_uff(rec: Recording, path, binary: bool = True) -> Path:
    """Each channel as a UFF 58 time record (function type 1), tagged ``satmd:<name>``."""
    parts = []
    for name, v in rec.channels.items():
        if name == "force":
            ordinate = (13, "Force", "N")
        elif is_role(name):
            ordinate = (12, "Acceleration", "m/s^2")
        else:
            ordinate = (1, name, rec.units.get(name) or "NONE")
        rsp = WRITE_DOF.get(name) or ((int(name[3:]), 3) if is_role(name) else (0, 0))  # acc<N> at node N, +Z
        parts.append(dataset58(rec.time_s, v, func_type=1, tag=name, rsp=rsp,
                               ordinate=ordinate, abscissa=(17, "Time", "s"), binary=binary,
                               id2="satmd-recording v1"))
    return write_datasets(parts, path)
