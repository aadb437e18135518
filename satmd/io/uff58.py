"""UFF dataset 58 (ASCII "58" and binary "58b") records: reading them validated, writing them as bytes.

Reading goes through ``pyuff`` one dataset at a time; everything pyuff may
throw on a damaged file is turned into a one-line `FormatError` naming the
file, the dataset and its line. Checks pyuff does not make (truncated files,
a declared point count that the data do not fill, NaN) are made here.
`UffRecord` is a dataset as read, not yet converted; `satmd.io.uff` turns FRF
records into `FRFData` and `satmd.io.recuff` time records into a `Recording`.

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
from ._common import read_bytes, short_error
from .atomic import atomic_write

FUNCTION_TYPES = {
    0: "general", 1: "time response", 2: "auto spectrum", 3: "cross spectrum", 4: "FRF",
    5: "transmissibility", 6: "coherence", 7: "auto correlation", 8: "cross correlation",
    9: "PSD", 10: "ESD", 11: "probability density", 12: "spectrum",
}
# UFF "specific data type" codes used here
SPEC_TYPES = {0: "unknown", 1: "general", 8: "displacement", 9: "reaction force", 11: "velocity",
              12: "acceleration", 13: "excitation force", 15: "pressure", 17: "time", 18: "frequency"}
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


def match_records(records, kind, a, b) -> list:
    """The records one channel-map entry names: ``("index", N, _)`` dataset N, ``("dof", node, dir)``
    the records measured at that node along that axis (either sign)."""
    if kind == "index":
        return [r for r in records if r.index == a]
    return [r for r in records if r.rsp[0] == a and abs(r.rsp[1]) == abs(b)]


# --- reading ----------------------------------------------------------------------
def _markers(raw: bytes) -> list[int]:
    """Offsets of the '    -1' dataset delimiters, by pyuff's own rule."""
    out: list[int] = []
    i, n = -1, len(raw)
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
            raise FormatError(path, f"not a readable universal file ({short_error(exc)})") from None
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
                raise FormatError(path, f"dataset {k + 1} (UFF 58) is corrupt and cannot be read ({short_error(exc)})",
                                  line=line) from None
        records.append(_validate(path, k + 1, line, d))
    return records, others


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


# --- writing ----------------------------------------------------------------------
# response DOF of each channel satmd writes: node 1 = primary mass, node 2 = absorber, +Z
WRITE_DOF = {"a1": (1, 3), "a2": (2, 3), "u1": (1, 3), "u2": (2, 3), "q": (3, 0),
             "force": (1, 3), "acc1": (1, 3), "acc2": (2, 3)}


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


def write_datasets(parts, path) -> Path:
    """Write datasets atomically, refusing the (astronomically rare) case of binary data that mimic a delimiter."""
    path = Path(path)
    blob = b"".join(parts)
    if len(_markers(blob)) != 2 * len(parts):
        raise DataError(f"{path}: the binary data happen to contain a UFF delimiter; write with binary=False")
    with atomic_write(path) as fh:
        fh.write(blob)
    return path

__all__ = ["FUNCTION_TYPES", "MARKER", "SPEC_TYPES", "TAG", "WRITE_DOF", "UffRecord", "dataset58", "dof_label",
           "read_records", "write_datasets"]
