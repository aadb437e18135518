"""Universal File Format dataset 58 (ASCII "58" and binary "58b") via pyuff.

Reading goes through ``pyuff`` one dataset at a time; everything pyuff may
throw on a damaged file is turned into a one-line `FormatError` naming the
file, the dataset and its line. Checks pyuff does not make (truncated files,
a declared point count that the data do not fill, NaN) are made here.

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

Writing is done here (not by pyuff) so that the binary byte count in the
58b header is right and the data are stored as IEEE doubles with the
frequencies as an explicit abscissa: a binary round trip is bit-exact.
ASCII (``binary=False``) keeps the 13 significant digits of the format.
"""
from __future__ import annotations

import contextlib
import io as _io
import warnings
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import parse_channel_map, parse_frf_unit, parse_quantity_unit, read_bytes, warn
from .frfdata import CHANNELS, FRFData

FUNCTION_TYPES = {
    0: "general", 1: "time response", 2: "auto spectrum", 3: "cross spectrum", 4: "FRF",
    5: "transmissibility", 6: "coherence", 7: "auto correlation", 8: "cross correlation",
    9: "PSD", 10: "ESD", 11: "probability density", 12: "spectrum",
}
# UFF "specific data type" codes used here
SPEC_TYPES = {0: "unknown", 1: "general", 8: "displacement", 9: "reaction force", 11: "velocity",
              12: "acceleration", 13: "excitation force", 15: "pressure", 17: "time", 18: "frequency"}
_POWER_OF_SPEC = {8: 0, 11: 1, 12: 2}  # time derivatives of a length
_FORCE_SPECS = (9, 13)
_DIR_NAMES = {0: "S", 1: "+X", 2: "+Y", 3: "+Z", 4: "+RX", 5: "+RY", 6: "+RZ",
              -1: "-X", -2: "-Y", -3: "-Z", -4: "-RX", -5: "-RY", -6: "-RZ"}
TAG = "satmd:"
MARKER = b"    -1"


@dataclass
class UffRecord:
    """One dataset 58 of a universal file, as read (not yet converted)."""

    index: int  # 1-based dataset number in the file
    line: int  # line where the dataset starts
    binary: bool
    func_type: int
    x: np.ndarray
    data: np.ndarray
    fields: dict = field(default_factory=dict)  # every header field pyuff parsed

    def get(self, key, default=None):
        value = self.fields.get(key, default)
        return default if value is None else value

    @property
    def rsp(self) -> tuple[int, int]:
        return int(self.get("rsp_node", 0)), int(self.get("rsp_dir", 0))

    @property
    def ref(self) -> tuple[int, int]:
        return int(self.get("ref_node", 0)), int(self.get("ref_dir", 0))

    @property
    def tag(self) -> str | None:
        """The satmd channel name for files written by satmd, else None."""
        id1 = str(self.get("id1", ""))
        return id1[len(TAG):].strip() if id1.startswith(TAG) else None

    @property
    def function(self) -> str:
        return FUNCTION_TYPES.get(self.func_type, f"type {self.func_type}")

    def quantity(self, which="ordinate") -> str:
        spec = int(self.get(f"{which}_spec_data_type", 0))
        return str(self.get(f"{which}_axis_lab", "")) if spec not in SPEC_TYPES or spec in (0, 1) else SPEC_TYPES[spec]

    def units(self, which="ordinate") -> str:
        u = str(self.get(f"{which}_axis_units_lab", "NONE")).strip()
        return "" if u.upper() == "NONE" else u

    @property
    def response(self) -> str:
        """'1:+Z' plus the entity name when the file gives one: '1:+Z (1+Z)'."""
        name = str(self.get("rsp_ent_name", "")).strip()
        return dof_label(*self.rsp) + (f" ({name})" if name and name.upper() not in ("NONE", "SATMD") else "")

    def describe(self) -> str:
        return f"#{self.index} {self.response}"


def dof_label(node: int, direction: int) -> str:
    return f"{node}:{_DIR_NAMES.get(direction, direction)}"


# --- reading ----------------------------------------------------------------------
def _markers(raw: bytes) -> list[int]:
    """Offsets of the '    -1' dataset delimiters, by pyuff's own rule."""
    out, i, n = [], -1, len(raw)
    while True:
        i = raw.find(MARKER, i + 1)
        if i < 0:
            return out
        j = i + 6
        if j == n or raw[j] in (10, 13) or (i + 80 < n and raw[j:i + 80] == b" " * 74):
            out.append(i)


@contextlib.contextmanager
def _quiet():
    """pyuff prints and warns on damaged files; we report errors ourselves."""
    with warnings.catch_warnings(), contextlib.redirect_stdout(_io.StringIO()), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        yield


def _pyuff(path):
    try:
        import pyuff
    except ImportError:
        raise FormatError(path, "reading UFF files needs pyuff (pip install 'satmd[io]')") from None
    return pyuff


def read_records(path) -> tuple[list[UffRecord], list[tuple[int, int]]]:
    """Every dataset 58 in the file, validated; plus (number, type) of the other datasets."""
    path = Path(path)
    raw = read_bytes(path)
    marks = _markers(raw)
    if not marks:
        raise FormatError(path, "no UFF datasets found (no '    -1' delimiter lines): not a universal file")
    if len(marks) % 2:
        start = marks[-1]
        raise FormatError(path, f"truncated: dataset {len(marks) // 2 + 1} has no closing '    -1' line",
                          line=raw[:start].count(b"\n") + 1)
    pyuff = _pyuff(path)
    with _quiet():
        try:
            uff = pyuff.UFF(str(path))
            types = [int(t) for t in uff.get_set_types()]
        except Exception as exc:  # noqa: BLE001 - pyuff raises bare Exception
            raise FormatError(path, f"not a readable universal file ({_short(exc)})") from None
    if len(types) != len(marks) // 2:
        raise FormatError(path, "inconsistent dataset delimiters (corrupt file)")
    records, others = [], []
    line, counted = 1, 0
    for k, set_type in enumerate(types):
        start = marks[2 * k]
        line += raw.count(b"\n", counted, start)  # incrementally: large files hold many datasets
        counted = start
        if set_type != 58:
            others.append((k + 1, set_type))
            continue
        with _quiet():
            try:
                d = uff.read_sets(k)
            except Exception as exc:  # noqa: BLE001
                raise FormatError(path, f"dataset {k + 1} (UFF 58) is corrupt and cannot be read ({_short(exc)})",
                                  line=line) from None
        records.append(_validate(path, k + 1, line, d))
    return records, others


def _short(exc) -> str:
    text = " ".join(str(exc).split())
    return text[:120] or type(exc).__name__


def _validate(path, number, line, d) -> UffRecord:
    where = f"dataset {number}"
    if not isinstance(d, dict):
        raise FormatError(path, f"{where}: unreadable UFF 58 header", line=line)
    try:
        func_type = int(d["func_type"])
        num_pts = int(d["num_pts"])
        x = np.asarray(d["x"], dtype=float).reshape(-1)
        data = np.asarray(d["data"]).reshape(-1)
    except (KeyError, TypeError, ValueError, OverflowError):
        raise FormatError(path, f"{where}: incomplete UFF 58 header or data", line=line) from None
    if not np.issubdtype(data.dtype, np.number):
        raise FormatError(path, f"{where}: data are not numbers", line=line)
    if data.size == 0:
        raise FormatError(path, f"{where}: no data values", line=line)
    if num_pts != data.size or x.size != data.size:
        raise FormatError(path, f"{where}: header declares {num_pts} points, the data hold {data.size} "
                                f"(truncated or corrupt)", line=line)
    bad = np.flatnonzero(~np.isfinite(data))
    if bad.size:
        raise FormatError(path, f"{where}: NaN or infinite value at point {bad[0] + 1}", line=line)
    if not np.all(np.isfinite(x)):
        raise FormatError(path, f"{where}: NaN or infinite abscissa", line=line)
    return UffRecord(number, line, bool(d.get("binary", 0)), func_type, x, data, dict(d))


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
        return _read_tagged(path, records)
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


def _read_tagged(path, records) -> FRFData:
    """A file written by `write_uff`: names come from the tags, values are SI already."""
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
    meta = {"source": str(path), "format": "UFF 58 (satmd)"}
    try:
        return FRFData(freq, channels, std, meta, coherence=coherence)
    except DataError as exc:
        raise FormatError(path, str(exc)) from None


def _map_channels(path, frfs, channel_map) -> dict:
    """{channel: (record, sign)} from --map or the two-response rule."""
    listing = ", ".join(r.describe() for r in frfs)
    if channel_map:
        try:
            wanted = parse_channel_map(channel_map, CHANNELS)
        except ValueError as exc:
            raise FormatError(path, str(exc)) from None
        chosen = {}
        for ch, (kind, a, b) in wanted.items():
            if kind == "index":
                hits = [r for r in frfs if r.index == a]
                if not hits:
                    raise FormatError(path, f"--map {ch}=#{a}: dataset {a} is not an FRF record (FRFs: {listing})")
                chosen[ch] = (hits[0], _sign(hits[0]))
                continue
            hits = [r for r in frfs if r.rsp[0] == a and abs(r.rsp[1]) == abs(b)]
            if not hits:
                raise FormatError(path, f"--map {ch}={dof_label(a, b)}: no FRF record with that response "
                                        f"(FRFs: {listing})")
            if len(hits) > 1:
                raise FormatError(path, f"--map {ch}={dof_label(a, b)}: {len(hits)} FRF records match "
                                        f"({', '.join(r.describe() for r in hits)}); choose one with {ch}=#N")
            chosen[ch] = (hits[0], _sign(hits[0]) * (-1 if b < 0 else 1))
    elif len(frfs) == 2:
        names = ("u1", "u2") if all(_power(path, r)[0] == 0 for r in frfs) else ("a1", "a2")
        chosen = {names[0]: (frfs[0], _sign(frfs[0])), names[1]: (frfs[1], _sign(frfs[1]))}
    elif len(frfs) == 1:
        warn(path, f"one FRF record ({listing}): read as a1, the primary mass; use --map to say otherwise")
        chosen = {"a1": (frfs[0], _sign(frfs[0]))}
    else:
        raise FormatError(path, f"{len(frfs)} FRF records ({listing}): say which are A1 and A2 with "
                                f"--map a1=NODE:DIR,a2=NODE:DIR (or a1=#N,a2=#M)")
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
_WRITE_DOF = {"a1": (1, 3), "a2": (2, 3), "u1": (1, 3), "u2": (2, 3), "q": (3, 0),
              "force": (1, 3), "acc1": (1, 3), "acc2": (2, 3)}
_WRITE_ORDINATE = {"a": (12, "Acceleration", "m/s^2"), "u": (8, "Displacement", "m"), "q": (1, "Charge", "C"),
                   "f": (13, "Force", "N")}


def dataset58(x, data, *, func_type, tag, rsp=(1, 3), ref=(0, 0), ordinate=(0, "NONE", "NONE"),
              denominator=(0, "NONE", "NONE"), abscissa=(18, "Frequency", "Hz"), binary=True,
              id2="NONE", id3=None) -> bytes:
    """One UFF dataset 58 (binary 58b or ASCII) as bytes.

    Binary: IEEE doubles, little-endian, explicit abscissa (uneven spacing)
    so nothing is rounded. ASCII: even spacing when the abscissa is uniform
    to the format's precision, values with 13 significant digits.
    """
    x = np.asarray(x, dtype=float)
    data = np.asarray(data)
    cplx = np.iscomplexobj(data)
    n = data.size
    if binary:
        even = False
    else:
        step = (x[-1] - x[0]) / (n - 1) if n > 1 else 0.0
        even = n > 1 and np.allclose(np.diff(x), step, rtol=1e-9, atol=0)
    cols = [x] if not even else []
    cols += [data.real, data.imag] if cplx else [data.real]
    table = np.column_stack(cols).astype("<f8")
    ord_type = 6 if cplx else 4
    id3 = id3 or datetime.now().strftime("%d-%b-%y %H:%M:%S")
    lines = [f"{-1:6d}"]
    body = table.tobytes() if binary else b""
    if binary:
        lines.append(f"{58:6d}b{1:6d}{2:6d}{11:12d}{len(body):12d}{0:6d}{0:6d}{0:12d}{0:12d}")
    else:
        lines.append(f"{58:6d}")
    for text in (TAG + tag, id2, id3, "NONE", "NONE"):
        lines.append(f"{str(text)[:80]:<80s}")
    name = "satmd"
    lines.append(f"{func_type:5d}{0:10d}{0:5d}{0:10d} {name:>10s}{rsp[0]:10d}{rsp[1]:4d} "
                 f"{'NONE' if ref == (0, 0) else name:>10s}{ref[0]:10d}{ref[1]:4d}")
    x0, dx = (x[0], (x[-1] - x[0]) / (n - 1)) if even else (0.0, 0.0)
    lines.append(f"{ord_type:10d}{n:10d}{int(even):10d}{x0:13.5E}{dx:13.5E}{0.0:13.5E}")
    for spec, lab, units in (abscissa, ordinate, denominator, (0, "NONE", "NONE")):
        lines.append(f"{spec:10d}{0:5d}{0:5d}{0:5d} {lab[:20]:<20s} {units[:20]:<20s}")
    head = ("\n".join(lines) + "\n").encode("ascii")
    if binary:
        return head + body + MARKER + b"\n"
    if even:  # cases 5 and 7: 4E20.12, real and imaginary parts interleaved
        text = _fixed(table.reshape(-1), ["%20.12E"] * 4)
    elif cplx:  # case 8: E13.5,2E20.12 per point
        text = "".join("%13.5E%20.12E%20.12E\n" % tuple(row) for row in table)
    else:  # case 6: 2(E13.5,E20.12)
        text = _fixed(table.reshape(-1), ["%13.5E", "%20.12E"] * 2)
    return head + text.encode("ascii") + MARKER + b"\n"


def _fixed(values, fmts) -> str:
    out, k = [], len(fmts)
    for i in range(0, values.size, k):
        chunk = values[i:i + k]
        out.append("".join(f % v for f, v in zip(fmts, chunk)) + "\n")
    return "".join(out)


def write_uff(data: FRFData, path, binary: bool = True) -> Path:
    """Write FRFs (function type 4), their std (type 0) and coherence (type 6) as UFF 58.

    Each record is tagged ``satmd:<name>`` in ID line 1, so `read_uff` maps
    it back; other programs see ordinary FRFs with response node 1 (primary
    mass) or 2 (absorber) in +Z, force reference 1:+Z, units m/s^2 / N.
    """
    parts = []
    for ch, v in data.channels.items():
        spec = _WRITE_ORDINATE[ch[0]]
        common = dict(rsp=_WRITE_DOF[ch], ref=(1, 3), binary=binary, id2="satmd-frf v1")
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


def write_datasets(parts, path) -> Path:
    """Write datasets atomically, refusing the (astronomically rare) case of binary data that mimic a delimiter."""
    path = Path(path)
    blob = b"".join(parts)
    if len(_markers(blob)) != 2 * len(parts):
        raise DataError(f"{path}: the binary data happen to contain a UFF delimiter; write with binary=False")
    tmp = path.with_name(f".{path.name}.tmp{id(blob)}")
    try:
        tmp.write_bytes(blob)
        tmp.replace(path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


__all__ = ["UffRecord", "read_records", "read_uff", "write_uff", "dataset58", "write_datasets",
           "FUNCTION_TYPES", "dof_label"]
