"""Time recordings in .mat / .npz files as labs write them: their own names, matrices of signals, any rate variable.

Signals are the variables ``force``, ``acc1``, ``acc2``, ``acc3``, ... (any
case; beside a force, one matrix called ``Acceleration``, ``acc``, ... is read a row an accelerometer), or as
a channel map says
(``"force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]"``: a
variable, or one row of a matrix of signals, counted from 1; the long axis of a
matrix is time; any number of accelerometers ``a<N>``). An array of more axes (a lab's realizations: the
F-16 benchmark's odd multisines hold ``Acceleration`` 3×9×49152, channel × realization × time) takes one index
per axis but time, ``Acceleration[1,5]``; without a map, or with one that names the force whole
(``force=Force,a1=Acceleration[1]``), every realization is read, one after another (the recording's
`Recording.realisations`); axes of length one are dropped (3×1×N reads as 3×N). The sample rate
is given, or a variable (`FS_NAMES`, any case), or a uniform time vector (`TIME_NAMES`).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import FormatError
from .limits import check_samples
from .matfile import load_variables, scalar_variable, vector_variable, warn_unused
from .recdata import accelerometers, is_role, ordered, role_of

RECORDING_NAMES = ("force", "acc1", "acc2")  # the rig's; any acc<N> variable is read too (`recdata.is_role`)
FS_NAMES = ("fs_hz", "fs", "sample_rate", "samplerate", "sampling_rate", "sampling_frequency", "srate", "sr")
TIME_NAMES = ("time_s", "time", "t")
ACCELERATION_PREFIX = "acc"  # a matrix called Acceleration, Accel, acc, ...: one accelerometer a row
MAX_MATRIX_ROWS = 64  # more rows than a test has accelerometers: not a matrix of signals
MAX_REALISATIONS = 1000  # a force matrix with more rows than this is not a lab's realisations


def _lookup(variables, name):
    """The variable called ``name``, exactly or else ignoring case (None if absent)."""
    if name in variables:
        return name
    folded = [k for k in variables if k.lower() == name.lower()]
    return folded[0] if len(folded) == 1 else None


def _sample_rate(path, v, fs_hz):
    """The sample rate: given, from a rate variable, or from a time vector."""
    if fs_hz is not None:
        fs = float(fs_hz)
        if not np.isfinite(fs) or fs <= 0:
            raise FormatError(path, f"sample rate {fs_hz!r} Hz must be a finite number > 0")
        return fs, None
    for name in FS_NAMES:
        key = _lookup(v, name)
        if key is not None:
            return scalar_variable(path, key, v[key]), key
    for name in TIME_NAMES:
        key = _lookup(v, name)
        if key is not None:
            t = vector_variable(path, key, v[key])
            dt = np.diff(t)
            if t.size < 2 or not np.all(dt > 0) or np.ptp(dt) > 1e-6 * np.mean(dt):
                raise FormatError(path, f"variable {key!r} is not a uniform, increasing time axis")
            return 1.0 / float(np.mean(dt)), key
    raise FormatError(path, f"no sample rate: none of the variables {', '.join(FS_NAMES)} or a time vector "
                            f"({', '.join(TIME_NAMES)}); found: {', '.join(sorted(v)) or 'nothing'}; "
                            f"give the sample rate (fs_hz)")


def _source(path, spec, role):
    """``Name`` -> ('Name', None); ``Name[i]`` or ``Name(i)`` -> ('Name', (i,)); ``Name[i,j]`` -> ('Name', (i, j))."""
    spec = spec.strip()
    for open_, close in (("[", "]"), ("(", ")")):
        if spec.endswith(close) and open_ in spec:
            name, _, rest = spec[:-1].partition(open_)
            try:
                return name.strip(), tuple(int(i) for i in rest.split(","))
            except ValueError:
                raise FormatError(path, f"map {role}={spec}: {rest!r} is not a row number "
                                        "(or, for an array of more axes, one number per axis but time)") from None
    return spec, None


def _signal(path, v, spec, role):
    """One signal from ``Name`` or ``Name[i]`` (row or column i, from 1, of a matrix: the long axis is time), or
    ``Name[i,j,...]`` of an array of more axes (one index per axis but time, the longest)."""
    spec = spec.strip()
    name, index = _source(path, spec, role)
    key = _lookup(v, name)
    if key is None:
        raise FormatError(path, f"map {role}={spec}: no variable {name!r}; found: "
                                f"{', '.join(sorted(v)) or 'nothing'}")
    a = _squeezed(np.asarray(v[key]))
    if index is None:
        return _vector(path, key, a, f"map {role}={spec}: ")
    if a.ndim < 2:
        raise FormatError(path, f"map {role}={spec}: {key!r} has shape {_shape(a)}, not a matrix of signals")
    signals = np.moveaxis(a, int(np.argmax(a.shape)), -1)  # time last, the other axes in their order
    axes = signals.shape[:-1]
    if len(index) != len(axes):
        example = ",".join("1" for _ in axes)
        raise FormatError(path, f"map {role}={spec}: {key!r} has shape {_shape(a)}: give one index per axis but "
                                f"time ({len(axes)}), e.g. {key}[{example}]")
    if not all(1 <= i <= n for i, n in zip(index, axes)):
        raise FormatError(path, f"map {role}={spec}: {key!r} holds {axes[0]} signal(s) (rows 1..{axes[0]})"
                          if len(axes) == 1 else f"map {role}={spec}: {key!r} has shape {_shape(a)}: indices run "
                          + ", ".join(f"1..{n}" for n in axes))
    label = f"{key}[{','.join(map(str, index))}]"
    return vector_variable(path, label, signals[tuple(i - 1 for i in index)])


def _vector(path, key, a, where=""):
    """Variable ``key`` as one signal; an array of several named with its shape and how to pick one."""
    if a.ndim >= 2 and sum(n > 1 for n in a.shape) > 1:
        axes = sum(n > 1 for n in a.shape) - 1
        raise FormatError(path, f"{where}{key!r} has shape {_shape(a)}, several signals: say which, e.g. "
                                f"{key}[{','.join('1' for _ in range(axes))}] in a channel map (from 1; time is the "
                                "longest axis)")
    return vector_variable(path, key, a)


def _squeezed(a):
    """``a`` without its axes of length one (a 3×1×N array of signals is 3×N), a vector kept a vector."""
    return a.reshape([n for n in a.shape if n != 1] or [1]) if a.ndim > 2 else a


def _shape(a) -> str:
    return "×".join(map(str, a.shape))


def _parse_variable_map(path, spec) -> dict:
    """'force=Force,a1=Acceleration[2]' -> {'force': 'Force', 'acc1': 'Acceleration[2]'}; any a<N> -> acc<N>."""
    out: dict = {}
    sources: dict = {}
    for part in re.split(r",(?![^\[(]*[\])])", str(spec)):  # the commas between entries, not inside [i,j]
        if not part.strip():
            continue
        role, eq, source = part.partition("=")
        if not eq or not source.strip():
            raise FormatError(path, f"map {part.strip()!r}: write ROLE=VARIABLE or ROLE=VARIABLE[ROW]")
        try:
            role = role_of(role)
        except ValueError as exc:
            raise FormatError(path, f"map {part.strip()}: {exc}") from None
        if role in out:
            raise FormatError(path, f"map {part.strip()}: {role} given twice")
        name, index = _source(path, source, role)
        same = sources.get((name.lower(), index))  # one signal cannot be two channels
        if same:
            raise FormatError(path, f"map {part.strip()}: {same} and {role} both name {source.strip()}")
        out[role], sources[(name.lower(), index)] = source.strip(), role
    if not out:
        raise FormatError(path, "map is empty")
    return out


def _signal_rows(a):
    """A matrix of signals a row each: the long axis is time."""
    return a if a.shape[1] >= a.shape[0] else a.T


def _response_matrix(path, v):
    """(name, {acc1: row 1, acc2: row 2, ...}) from the one matrix of accelerations a lab's file holds beside its
    force (``Acceleration`` 3×N: rows 1, 2, 3 as acc1, acc2, acc3, the long axis being time); None when there is
    not exactly one."""
    found = [k for k, a in v.items() if k.lower().startswith(ACCELERATION_PREFIX)
             and _squeezed(np.asarray(a)).ndim == 2 and min(_squeezed(np.asarray(a)).shape) > 1
             and np.asarray(a).dtype.kind in "biuf"]
    if len(found) != 1:
        return None
    a = _squeezed(np.asarray(v[found[0]]))
    rows = _signal_rows(a)
    if rows.shape[0] > MAX_MATRIX_ROWS:
        return None
    return found[0], {f"acc{i + 1}": vector_variable(path, f"{found[0]}[{i + 1}]", r) for i, r in enumerate(rows)}


def _force_realisations(v, key):
    """Variable ``key`` as a force of several realisations, realisation × time (`MAX_REALISATIONS` at most); None
    when it is absent, not numbers, or one signal."""
    if key is None or np.asarray(v[key]).dtype.kind not in "biuf":
        return None
    force = _squeezed(np.asarray(v[key]))
    if force.ndim != 2 or min(force.shape) < 2 or min(force.shape) > MAX_REALISATIONS:
        return None
    return _signal_rows(force)


def _realisations(path, v):
    """(signals, used, meta) where the force is a matrix of realisations (realisation × time, `MAX_REALISATIONS`
    at most): each channel is its realisations one after another, and ``meta`` says where each starts
    (``realisations``, ``realisation_samples``: `Recording.realisations` splits them again). The responses are
    ``acc<N>`` variables of the force's shape, or the one matrix of accelerations beside it, channel ×
    realisation × time (the F-16 benchmark's odd multisines: 3×9×49152; realisation × channel read as well).
    None when the force is one signal."""
    key = _lookup(v, "force")
    force = _force_realisations(v, key)
    if force is None:
        return None
    r, n = force.shape
    signals, used = {"force": force}, {key}
    for name in ordered({k.lower() for k in v if is_role(k.lower()) and k.lower() != "force"}):
        k = _lookup(v, name)
        a = _squeezed(np.asarray(v[k]))
        if a.ndim != 2 or _signal_rows(a).shape != (r, n):
            raise FormatError(path, f"{k!r} has shape {_shape(a)}, the force {r}×{n} (realisation × time): "
                                    "each response needs the force's realisations")
        signals[name], used = _signal_rows(a), used | {k}
    if len(signals) == 1:
        found = [k for k, a in v.items() if k.lower().startswith(ACCELERATION_PREFIX)
                 and np.asarray(a).dtype.kind in "biuf" and np.asarray(a).size >= r * n and np.asarray(a).ndim >= 2]
        if len(found) != 1:
            return None
        a = _squeezed(np.asarray(v[found[0]]))
        a = np.moveaxis(a, int(np.argmax(a.shape)), -1)
        if a.ndim == 2 and a.shape == (r, n):
            a = a[None]  # one accelerometer's realisations
        if a.ndim != 3 or a.shape[-1] != n or r not in a.shape[:2]:
            raise FormatError(path, f"{found[0]!r} has shape {_shape(np.asarray(v[found[0]]))}, the force {r}×{n} "
                                    "(realisation × time): give channel × realisation × time, or a channel map "
                                    f"that picks one realisation, e.g. force={key}[1],a1={found[0]}[1,1]")
        channels_first = a.shape[1] == r  # F-16's order; realisation × channel where only that fits
        a = a if channels_first else a.transpose(1, 0, 2)
        signals.update({f"acc{i + 1}": a[i] for i in range(a.shape[0])})
        used.add(found[0])
    flat = {name: vector_variable(path, name, x.reshape(-1)) for name, x in signals.items()}
    return flat, used, {"realisations": str(r), "realisation_samples": str(n)}


def _mapped_realisations(path, v, roles):
    """`_realisations` as a channel map names the signals: the force a variable of realisation × time, given whole
    (``force=Force``), each response with one index fewer than its array has axes but time, the realisation axis left
    free (``a1=Acceleration[1]`` of channel × realisation × time: the F-16 benchmark's odd multisines), or a
    variable of the force's shape. None when the map's force is one signal."""
    name, index = _source(path, roles["force"], "force") if "force" in roles else (None, None)
    key = None if name is None or index is not None else _lookup(v, name)
    force = _force_realisations(v, key)
    if force is None:
        return None
    r, n = force.shape
    signals = {"force": force}
    for role, spec in roles.items():
        if role == "force":
            continue
        name, index = _source(path, spec, role)
        k = _lookup(v, name)
        if k is None:
            raise FormatError(path, f"map {role}={spec}: no variable {name!r}; found: {', '.join(sorted(v))}")
        a = _squeezed(np.asarray(v[k]))
        a = np.moveaxis(a, int(np.argmax(a.shape)), -1) if a.ndim >= 2 else a
        axes = a.shape[:-1]
        free = [i for i, m in enumerate(axes) if m == r]  # the realisation axis: the force's count
        if a.shape[-1] != n or len(axes) != (0 if index is None else len(index)) + 1 or not free:
            raise FormatError(path, f"map {role}={spec}: {k!r} has shape {_shape(np.asarray(v[k]))}, the force "
                                    f"{key} {r}×{n} (realisation × time): each response needs the force's "
                                    f"realisations (an index for every other axis), or pick one realisation, "
                                    f"e.g. force={key}[1]")
        at = free[-1]  # channel × realisation × time where both fit (the F-16's order)
        rest = [i for i in range(len(axes)) if i != at]
        picked = np.moveaxis(a, at, 0)
        for i, m in zip(index or (), [axes[j] for j in rest]):
            if not 1 <= i <= m:
                raise FormatError(path, f"map {role}={spec}: {k!r} has shape {_shape(np.asarray(v[k]))}: its index "
                                        f"runs 1..{m} (the realisations, {r}, are read one after another)")
        picked = picked[(slice(None),) + tuple(i - 1 for i in index or ())]
        signals[role] = picked
    flat = {role: vector_variable(path, roles[role], x.reshape(-1)) for role, x in signals.items()}
    used = {_lookup(v, _source(path, spec, role)[0]) for role, spec in roles.items()}
    return flat, used, {"realisations": str(r), "realisation_samples": str(n)}


def read_recording_variables(path, channel_map=None, fs_hz=None):
    """(fs_hz, {name: series}) from a .mat / .npz recording.

    Signals are the variables ``force``, ``acc1``, ``acc2``, ``acc3``, ... (any
    case; beside a force, one matrix called ``Acceleration``, ``acc``, ... is read a row an accelerometer,
    ``acc1`` from row 1), or as ``channel_map`` says (``"force=Force,a1=Acceleration[2],a3=Acceleration[1]"``:
    a variable, or one row of a matrix of signals, counted from 1; any ``a<N>``).
    The sample rate is ``fs_hz``, or a variable (`FS_NAMES`, any case), or a time vector. A force of several
    realisations (realisation × time) is read whole, its realisations one after another (`_realisations`), with
    a map too where it names the force whole (``force=Force,a1=Acceleration[1]``, `_mapped_realisations`).

    Returns
    -------
    (fs_hz, {name: series}, meta): ``meta`` says where realisations start (empty for one signal per channel)
    """
    path = Path(path)
    v = load_variables(path)
    if _lookup(v, "freq_hz") is not None and _lookup(v, "fs_hz") is None and fs_hz is None:
        raise FormatError(path, "it holds 'freq_hz' (it looks like FRFs), no sample rate")
    fs, fs_key = _sample_rate(path, v, fs_hz)
    meta: dict = {}
    roles = _parse_variable_map(path, channel_map) if channel_map else None
    several = _mapped_realisations(path, v, roles) if roles else _realisations(path, v)
    if several is not None:
        signals, used, meta = several
    elif roles:
        signals = {role: _signal(path, v, spec, role) for role, spec in roles.items()}
        used = {_lookup(v, _source(path, spec, role)[0]) for role, spec in roles.items()}
    else:
        signals, used = {}, set()
        for n in ordered({k.lower() for k in v if is_role(k.lower())}):  # force, acc1, acc2, ...
            key = _lookup(v, n)
            if key is not None:
                signals[n] = _vector(path, key, _squeezed(np.asarray(v[key])))
                used.add(key)
        matrices = [f"{k} {_shape(np.asarray(a))}" for k, a in v.items()
                    if _squeezed(np.asarray(a)).ndim >= 2 and min(np.asarray(a).shape) > 1]
        if "force" in signals and not accelerometers(signals):
            rows = _response_matrix(path, v)
            if rows is not None:
                key, responses = rows
                signals.update(responses)
                used.add(key)
        if not signals or (matrices and not accelerometers(signals)):
            hint = (f"; it holds {', '.join(matrices)}: say which signal is which, e.g. "
                    f"a channel map force=Force,a1=Acceleration[2],a2=Acceleration[3] (rows from 1; an array of "
                    f"more axes takes one index per axis but time, Acceleration[2,1])" if matrices else "")
            raise FormatError(path, f"no {'response ' if signals else ''}signal variable (any of "
                                    f"{', '.join(RECORDING_NAMES)}){hint}; found: {', '.join(sorted(v)) or 'nothing'}")
    lengths = {n: s.size for n, s in signals.items()}
    check_samples(path, max(lengths.values()), len(signals), path=path)
    if len(set(lengths.values())) > 1:
        raise FormatError(path, "signals have different lengths: " + ", ".join(f"{n} {k}" for n, k in lengths.items()))
    warn_unused(path, v, used | {fs_key, "time_s", "meta"})
    return fs, signals, meta


def is_recording_file(path) -> bool:
    """A time recording: a sample rate, a time vector or a long signal, and no frequency axis."""
    v = load_variables(path)
    if _lookup(v, "freq_hz") is not None:
        return False
    if any(_lookup(v, n) is not None for n in FS_NAMES + TIME_NAMES):
        return True
    return any(np.asarray(a).dtype.kind in "biuf" and max(np.asarray(a).shape or (1,)) >= 256 for a in v.values())


__all__ = ["FS_NAMES", "RECORDING_NAMES", "TIME_NAMES", "is_recording_file", "read_recording_variables"]
