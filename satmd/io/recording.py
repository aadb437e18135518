"""Time recordings (force and accelerations) and the files they come in.

A `Recording` holds uniformly sampled channels. The channels satmd uses are
``force`` [N] on the primary mass and ``acc1``, ``acc2`` [m/s²] of the
primary mass and the absorber; other channels (a microphone, a fourth
accelerometer) are kept under their own names for inspection.

Formats (`load_recording` chooses by suffix):

``.csv``  ``# satmd-recording v1`` (optional), then the header
          ``time_s,force,acc1,acc2`` (``force`` may be left out: output-only),
          SI units, uniform sampling.
``.uff``  UFF 58 / 58b time records (function type 1), several in one file,
          ASCII or binary; units stated in the file are converted to SI.
          Roles: one force record (specific data type 13 or 9, or a force
          unit) and two response records become force/acc1/acc2 in file
          order; otherwise ``channel_map="force=#1,a1=1:+Z,a2=2:+Z"``.
``.wav``  one channel per column: 3 channels = force, acc1, acc2; 2 channels
          = acc1, acc2. WAV has no units: integer samples are read as
          fractions of full scale; pass ``scale={"force": N_per_unit, ...}``.
``.npz`` / ``.mat``  variables ``fs_hz``, ``force``, ``acc1``, ``acc2``.

Loaders warn (`DataWarning`) about clipped channels and refuse NaN,
mismatched lengths and non-uniform sampling with a one-line `FormatError`.
"""
from __future__ import annotations

import io as _io
import math
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import decode_text, numeric_table, parse_channel_map, parse_quantity_unit, read_bytes, split_csv, warn

ROLES = ("force", "acc1", "acc2")
SI_UNITS = {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}
CSV_MAGIC = "# satmd-recording v1"
_MAP_ALIASES = {"a1": "acc1", "a2": "acc2"}


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
            chans[name] = v
        if n < 2:
            raise DataError(f"a recording needs at least 2 samples, has {n}")
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


def clipped_channels(rec: Recording, extremes: dict | None = None) -> dict:
    """{name: number of samples at the channel's extremes} for channels that look clipped.

    A clipped sensor sits on its largest or smallest value for several
    samples in a row (flat tops); a healthy signal passes its extremes.
    ``extremes`` may give a channel's full-scale limits (integer WAV data).
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


def _warn_clipping(path, rec, extremes=None):
    for name, count in clipped_channels(rec, extremes).items():
        warn(path, f"channel {name} looks clipped: {count} samples sit at its extremes "
                   f"({100 * count / rec.n_samples:.2g} %); FRFs near those peaks are unreliable")


# --- CSV ------------------------------------------------------------------------
def read_recording_csv(path) -> Recording:
    """A ``time_s,force,acc1,acc2`` CSV (SI units); malformed input names file, line and column."""
    path = Path(path)
    text = decode_text(path, read_bytes(path))
    header, header_line, rows, meta = split_csv(path, text, "satmd-recording")
    if header is None:
        raise FormatError(path, "no column header (expected time_s,force,acc1,acc2)")
    _check_header(path, header, header_line)
    if len(rows) < 2:
        raise FormatError(path, f"{len(rows)} data row(s): a recording needs at least 2 samples", line=header_line)
    values = numeric_table(path, header, rows)
    fs = _uniform_rate(path, values[:, 0], [ln for ln, _ in rows])
    channels = {name: values[:, j] for j, name in enumerate(header) if j}
    meta.update({"source": str(path), "format": "csv"})
    rec = Recording(fs, channels, {n: SI_UNITS[n] for n in channels}, meta,
                    {n: f"column {j + 1}" for j, n in enumerate(header) if j})
    _warn_clipping(path, rec)
    return rec


def _check_header(path, header, lineno):
    if header[0] != "time_s":
        raise FormatError(path, f"first column must be time_s, got {header[0]!r}", line=lineno, column=1)
    seen = set()
    for j, name in enumerate(header[1:], start=2):
        if name not in ROLES:
            raise FormatError(path, f"unknown column {name!r} (known: {', '.join(ROLES)})", line=lineno, column=j)
        if name in seen:
            raise FormatError(path, f"duplicate column {name!r}", line=lineno, column=j)
        seen.add(name)
    if len(header) < 2:
        raise FormatError(path, "no signal columns after time_s", line=lineno)


def _uniform_rate(path, t, lines=None) -> float:
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
    return _snap_rate((t.size - 1) / (t[-1] - t[0]))  # the mean step: most digits


def _snap_rate(fs: float) -> float:
    """Rates like 1/1.52588e-05 (a step written with 6 digits) back to 65536 Hz."""
    r = round(fs)
    return float(r) if r > 0 and abs(fs - r) <= 2e-5 * fs else fs


def write_recording_csv(rec: Recording, path) -> Path:
    path = Path(path)
    names = [n for n in ROLES if n in rec.channels]
    if len(names) != len(rec.channels):
        raise DataError(f"CSV recordings hold {', '.join(ROLES)}; rename the other channels first")
    lines = [CSV_MAGIC]
    lines += [f"# {k}: {v}" for k, v in rec.meta.items() if k != "source" and "\n" not in f"{k}{v}"]
    lines.append(",".join(["time_s"] + names))
    table = np.column_stack([rec.time_s] + [rec.channels[n] for n in names])
    lines += [",".join(f"{x:.17g}" for x in row) for row in table]
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    os.replace(tmp, path)
    return path


# --- UFF time records -----------------------------------------------------------
def read_recording_uff(path, channel_map=None) -> Recording:
    """Time records (function type 1) of a UFF 58 file as one recording (see the module docstring)."""
    from .uff import dof_label, read_records

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
    _warn_clipping(path, rec)
    return rec


def _record_rate(path, r) -> float:
    if int(r.get("abscissa_spacing", 0)) == 1:
        dt = float(r.get("abscissa_inc", 0.0))
        if not dt > 0 or not math.isfinite(dt):
            raise FormatError(path, f"dataset {r.index}: time step {dt:g} s is not > 0", line=r.line)
        return _snap_rate(1.0 / dt)
    if r.x.size < 2:
        raise FormatError(path, f"dataset {r.index}: a time record needs at least 2 samples", line=r.line)
    try:
        return _uniform_rate(path, r.x)
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
    if all(r.tag in ROLES for r in times) and len({r.tag for r in times}) == len(times):
        return {r.index: r.tag for r in times}
    names = {r.index: f"ch{r.index}" for r in times}
    if channel_map:
        try:
            wanted = parse_channel_map(channel_map, ROLES, _MAP_ALIASES)
        except ValueError as exc:
            raise FormatError(path, str(exc)) from None
        for role, (kind, a, b) in wanted.items():
            if kind == "index":
                hits = [r for r in times if r.index == a]
            else:
                hits = [r for r in times if r.rsp[0] == a and abs(r.rsp[1]) == abs(b)]
            listing = ", ".join(r.describe() for r in times)
            if len(hits) != 1:
                what = "no time record" if not hits else f"{len(hits)} time records"
                raise FormatError(path, f"--map {role}: {what} match (records: {listing}); use {role}=#N")
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
        if name in ROLES:
            warn(path, f"dataset {r.index}: unknown unit {label!r} for {name}; values used as they are")
        return r.data.real.astype(float), label
    if q is None:
        return r.data.real.astype(float), SI_UNITS.get(name, "")
    kind, factor = q
    if name in ("acc1", "acc2") and kind != 2:
        raise FormatError(path, f"dataset {r.index} mapped to {name} holds {label!r}, not an acceleration",
                          line=r.line)
    if name == "force" and kind != "force":
        raise FormatError(path, f"dataset {r.index} mapped to force holds {label!r}, not a force", line=r.line)
    si = {"force": "N", 2: "m/s^2", 1: "m/s", 0: "m", "charge": "C"}[kind]
    return r.data.real.astype(float) * factor, si


def write_recording_uff(rec: Recording, path, binary: bool = True) -> Path:
    """Each channel as a UFF 58 time record (function type 1), tagged ``satmd:<name>``."""
    from .uff import _WRITE_DOF, dataset58, write_datasets

    parts = []
    for name, v in rec.channels.items():
        if name == "force":
            ordinate = (13, "Force", "N")
        elif name in ("acc1", "acc2"):
            ordinate = (12, "Acceleration", "m/s^2")
        else:
            ordinate = (1, name, rec.units.get(name) or "NONE")
        parts.append(dataset58(rec.time_s, v, func_type=1, tag=name, rsp=_WRITE_DOF.get(name, (0, 0)),
                               ordinate=ordinate, abscissa=(17, "Time", "s"), binary=binary,
                               id2="satmd-recording v1"))
    return write_datasets(parts, path)


# --- WAV ------------------------------------------------------------------------
_WAV_ROLES = {3: ("force", "acc1", "acc2"), 2: ("acc1", "acc2")}
_WAV_TAG = "satmd-recording v1"


def read_recording_wav(path, channel_map=None, scale=None) -> Recording:
    """A WAV file: channel roles by count or ``channel_map="force=#1,a1=#2"``, units by ``scale``."""
    import warnings

    from scipy.io import wavfile

    path = Path(path)
    raw = read_bytes(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # unknown chunks; we report what matters ourselves
            fs, data = wavfile.read(_io.BytesIO(raw))
    except Exception as exc:  # noqa: BLE001 - scipy raises ValueError, struct.error, ...
        raise FormatError(path, f"not a readable WAV file ({' '.join(str(exc).split())[:120]})") from None
    data = np.asarray(data)
    if data.ndim == 1:
        data = data[:, None]
    if data.shape[0] < 2:
        raise FormatError(path, f"{data.shape[0]} sample(s): a recording needs at least 2")
    n_ch, is_int = data.shape[1], data.dtype.kind in "iu"
    if data.dtype.kind == "f":
        bad = np.argwhere(~np.isfinite(data))
        if bad.size:
            raise FormatError(path, f"NaN or infinite sample {bad[0][0]} in channel {bad[0][1] + 1}")
    values, limits = data.astype(float), None
    if is_int:  # integer PCM: fractions of full scale; unsigned 8-bit is offset by 128
        info = np.iinfo(data.dtype)
        full = float(2 ** (8 * data.dtype.itemsize - 1))
        offset = full if data.dtype.kind == "u" else 0.0
        values = (values - offset) / full
        limits = ((info.min - offset) / full, (info.max - offset) / full)
    names = list(_WAV_ROLES.get(n_ch, [f"ch{k + 1}" for k in range(n_ch)]))
    comment = _wav_comment(raw)  # written by satmd: names and SI units are known
    ours = comment.startswith(_WAV_TAG) and not is_int
    if ours:
        listed = comment.split("; channels ")[-1].split(";")[0].split(",")
        if len(listed) == n_ch and len(set(listed)) == n_ch and all(n.isidentifier() for n in listed):
            names = listed
        else:
            ours = False
    if channel_map:
        try:
            wanted = parse_channel_map(channel_map, ROLES, _MAP_ALIASES)
        except ValueError as exc:
            raise FormatError(path, str(exc)) from None
        names = [f"ch{k + 1}" for k in range(n_ch)]
        for role, (kind, a, _) in wanted.items():
            if kind != "index" or not 1 <= a <= n_ch:
                raise FormatError(path, f"--map {role}: WAV channels are chosen as #1..#{n_ch}")
            names[a - 1] = role
    scale = dict(scale or {})
    unknown = set(scale) - set(names)
    if unknown:
        raise FormatError(path, f"scale given for missing channel(s) {', '.join(sorted(unknown))}")
    gains = {n: float(scale.get(n, 1.0)) for n in names}
    if not all(math.isfinite(g) and g != 0 for g in gains.values()):
        raise FormatError(path, "scale factors must be finite and non-zero")
    channels = {n: values[:, k] * gains[n] for k, n in enumerate(names)}
    raw_unit = "full scale" if is_int else "as stored"
    units = {n: SI_UNITS.get(n, "") if (n in scale or ours) else raw_unit for n in names}
    if not ours and any(n in ROLES and n not in scale for n in names):
        warn(path, f"WAV files carry no units: values are {'fractions of full scale' if is_int else 'as stored'}; "
                   "calibrate with scale={'force': N_per_unit, ...} (CLI: --scale) or FRF magnitudes are off")
    meta = {"source": str(path), "format": f"WAV {data.dtype}"}
    try:
        rec = Recording(float(fs), channels, units, meta, {n: f"WAV channel {k + 1}" for k, n in enumerate(names)})
    except DataError as exc:
        raise FormatError(path, str(exc)) from None
    extremes = {n: tuple(sorted(g * x for x in limits)) for n, g in gains.items()} if is_int else None
    _warn_clipping(path, rec, extremes)
    return rec


def write_recording_wav(rec: Recording, path) -> Path:
    """64-bit float WAV (exact), channels in the order force, acc1, acc2 (then others).

    A LIST/INFO comment ``satmd-recording v1; channels force,acc1,acc2; SI``
    lets `read_recording_wav` restore names and units; other programs ignore it.
    """
    from scipy.io import wavfile

    path = Path(path)
    if abs(rec.fs_hz - round(rec.fs_hz)) > 1e-9 * rec.fs_hz:
        raise DataError(f"WAV needs an integer sample rate, this recording has {rec.fs_hz:g} Hz")
    order = [n for n in ROLES if n in rec.channels] + [n for n in rec.channels if n not in ROLES]
    buf = _io.BytesIO()
    wavfile.write(buf, int(round(rec.fs_hz)), np.column_stack([rec.channels[n] for n in order]))
    text = f"{_WAV_TAG}; channels {','.join(order)}; SI".encode("ascii") + b"\0"
    text += b"\0" * (len(text) % 2)
    info = b"INFO" + b"ICMT" + struct.pack("<I", len(text)) + text
    riff = bytearray(buf.getvalue()) + b"LIST" + struct.pack("<I", len(info)) + info
    riff[4:8] = struct.pack("<I", len(riff) - 8)
    path.write_bytes(bytes(riff))
    return path


def _wav_comment(raw: bytes) -> str:
    """The ICMT text of a LIST/INFO chunk, or '' (every length checked)."""
    pos = 12
    while pos + 8 <= len(raw):
        cid, size = raw[pos:pos + 4], struct.unpack("<I", raw[pos + 4:pos + 8])[0]
        body = raw[pos + 8:pos + 8 + size]
        if cid == b"LIST" and body[:4] == b"INFO":
            sub = 4
            while sub + 8 <= len(body):
                sid, ssize = body[sub:sub + 4], struct.unpack("<I", body[sub + 4:sub + 8])[0]
                if sid == b"ICMT":
                    return body[sub + 8:sub + 8 + ssize].split(b"\0")[0].decode("ascii", "replace")
                sub += 8 + ssize + ssize % 2
        pos += 8 + size + size % 2
    return ""


# --- .npz / .mat ----------------------------------------------------------------
def read_recording_variables(path) -> Recording:
    from .matfile import read_recording_variables as _read

    path = Path(path)
    fs, signals = _read(path)
    try:
        rec = Recording(fs, signals, {n: SI_UNITS[n] for n in signals},
                        {"source": str(path), "format": path.suffix.lower().lstrip(".")})
    except DataError as exc:
        raise FormatError(path, str(exc)) from None
    _warn_clipping(path, rec)
    return rec


def write_recording_variables(rec: Recording, path) -> Path:
    from .matfile import write_recording_variables as _write

    return _write(rec.fs_hz, rec.channels, path)


# --- dispatch -------------------------------------------------------------------
RECORDING_READERS = {".csv": read_recording_csv, ".uff": read_recording_uff, ".unv": read_recording_uff,
                     ".wav": read_recording_wav, ".npz": read_recording_variables, ".mat": read_recording_variables}
RECORDING_WRITERS = {".csv": write_recording_csv, ".uff": write_recording_uff, ".unv": write_recording_uff,
                     ".wav": write_recording_wav, ".npz": write_recording_variables,
                     ".mat": write_recording_variables}


def load_recording(path, channel_map=None, scale=None) -> Recording:
    """Load a time recording; the reader is chosen by the suffix (see the module docstring)."""
    path = Path(path)
    if not path.exists():
        raise FormatError(path, "no such file")
    if path.is_dir():
        raise FormatError(path, "is a directory, not a file")
    suffix = path.suffix.lower()
    reader = RECORDING_READERS.get(suffix)
    if reader is None:
        known = ", ".join(sorted(RECORDING_READERS))
        raise FormatError(path, f"unknown recording type {path.suffix!r} (known: {known})")
    options = {}
    if channel_map:
        if suffix not in (".uff", ".unv", ".wav"):
            raise FormatError(path, f"--map does not apply to {suffix} recordings (their channels are named)")
        options["channel_map"] = channel_map
    if scale:
        if suffix != ".wav":
            raise FormatError(path, "scale applies to WAV files only (the others carry units)")
        options["scale"] = scale
    return reader(path, **options)


def save_recording(rec: Recording, path) -> Path:
    path = Path(path)
    writer = RECORDING_WRITERS.get(path.suffix.lower())
    if writer is None:
        known = ", ".join(sorted(RECORDING_WRITERS))
        raise FormatError(path, f"cannot write {path.suffix!r} recordings (known: {known})")
    if not path.parent.exists():
        raise FormatError(path, f"folder {path.parent} does not exist")
    return writer(rec, path)


def is_recording(path) -> bool:
    """Whether a file holds time data (True) rather than FRFs (False); unreadable files raise FormatError."""
    path = Path(path)
    suffix = path.suffix.lower()
    if not path.is_file():
        return False  # the FRF loader says what is wrong with the path
    if suffix == ".wav":
        return True
    if suffix == ".csv":
        text = decode_text(path, read_bytes(path))
        for line in text.splitlines():
            s = line.strip()
            if s and not s.startswith("#"):
                return s.split(",")[0].strip() == "time_s"
        return False
    if suffix in (".uff", ".unv"):
        from .uff import read_records

        records, _ = read_records(path)
        types = {r.func_type for r in records}
        return 1 in types and 4 not in types
    if suffix in (".npz", ".mat"):
        from .matfile import is_recording_file

        return is_recording_file(path)
    return False
