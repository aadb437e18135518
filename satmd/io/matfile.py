"""FRFs and recordings in MATLAB ``.mat`` (v5, i.e. -v6 and -v7) and NumPy ``.npz`` files.

Documented variable names (1-D arrays; MATLAB row or column vectors):

FRFs
    ``freq_hz``                 frequencies in Hz, strictly increasing, > 0
    ``a1 a2 u1 u2 q``           complex FRFs in SI units (SPEC §7), any subset
    ``<ch>_std``                std of the noise on each of Re and Im (optional)
    ``<ch>_coh``                coherence in [0, 1] (optional)

Recordings
    ``fs_hz``                   sample rate in Hz (scalar)
    ``force acc1 acc2``         time series in N and m/s^2; ``force`` may be
                                absent (output-only recording)

Other variables are ignored with a warning. ``.npz`` files are opened with
``allow_pickle=False``: a file cannot run code.
"""
from __future__ import annotations

import math
import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import read_bytes, short_error, warn
from .atomic import atomic_write
from .limits import MAX_BINARY_BYTES, MAX_SAMPLES, check_file, size_text
from .frfdata import CHANNELS, FRFData



def load_variables(path) -> dict:
    """name -> ndarray for a .mat or .npz file; anything unreadable is a FormatError."""
    path = Path(path)
    if path.suffix.lower() == ".npz":
        if check_file(path, MAX_BINARY_BYTES) == 0:  # missing, a FIFO, a device, too large: refused unopened
            raise FormatError(path, "empty file")
        try:
            with open(path, "rb") as fh:
                z = np.load(fh, allow_pickle=False)  # lazily: the directory is checked before any member is read
                if not hasattr(z, "files"):
                    raise FormatError(path, "a single .npy array, not an .npz archive of named arrays")
                with z:
                    _check_members(path, z.zip.infolist())
                    return {k: np.asarray(z[k]) for k in z.files}
        except FormatError:
            raise
        except (zipfile.BadZipFile, EOFError):
            raise FormatError(path, "not a NumPy .npz archive (corrupt or truncated zip)") from None
        except Exception as exc:  # noqa: BLE001 - numpy and zipfile raise many kinds
            raise FormatError(path, f"cannot read .npz archive ({short_error(exc)})") from None
    return read_mat5(path, read_bytes(path))


def _check_members(path, infos):
    """Refuse an archive whose members unpack beyond what satmd reads (sizes from the zip directory)."""
    total = sum(info.file_size for info in infos)
    if total > MAX_BINARY_BYTES:
        raise FormatError(path, f"the archive unpacks to {size_text(total)}: more than the "
                                f"{size_text(MAX_BINARY_BYTES)} satmd reads from one file")
    for info in infos:
        if info.file_size > 16 * MAX_SAMPLES + 4096:  # complex doubles, plus the .npy header
            raise FormatError(path, f"array {info.filename[:-4]!r} unpacks to {size_text(info.file_size)}: more "
                                    f"than the {MAX_SAMPLES} values satmd reads at once")


# --- MATLAB v5 (-v6, -v7) reader ------------------------------------------------
# scipy.io.loadmat trusts the byte counts in a file and can crash the
# interpreter (segmentation fault) on a corrupt one, so satmd reads the v5
# format itself: every length is checked against its enclosing element before
# anything is read. Numeric and char arrays are read; cells, structs, sparse
# and objects are skipped (they hold nothing satmd uses).
_MI_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 9: "f8", 12: "i8", 13: "u8",
             16: "u1", 17: "u2", 18: "u4"}
_NUMERIC_CLASSES = {6: "f8", 7: "f4", 8: "i1", 9: "u1", 10: "i2", 11: "u2", 12: "i4", 13: "u4", 14: "i8", 15: "u8"}
_CHAR_CLASS = 4
_MAX_BYTES = 1 << 30  # refuse to inflate compressed variables beyond 1 GiB


def read_mat5(path, raw: bytes) -> dict:
    """name -> ndarray for the numeric and char variables of a MATLAB v5/v6/v7 file."""
    if raw[:10] == b"MATLAB 7.3" or raw[512:520] == b"\x89HDF\r\n\x1a\n":
        raise FormatError(path, "MATLAB v7.3 (HDF5) files are not supported; save with -v7")
    if len(raw) < 128 or not raw.startswith(b"MATLAB"):
        raise FormatError(path, "not a MATLAB v5/v6/v7 file (no 'MATLAB 5.0' header); "
                                "MATLAB v4 files are not supported, save with -v7")
    order = {b"IM": "<", b"MI": ">"}.get(raw[126:128])
    if order is None:
        raise FormatError(path, "corrupt MATLAB header (no endian indicator)")
    out: dict[str, np.ndarray] = {}
    pos, inflated = 128, 0
    while pos < len(raw):
        etype, data, pos = _element(path, raw, pos, order)
        if etype == 15:  # miCOMPRESSED: zlib stream holding one or more elements
            inner = _inflate(path, data, _MAX_BYTES - inflated)
            inflated += len(inner)
            ipos = 0
            while ipos < len(inner):
                itype, idata, ipos = _element(path, inner, ipos, order)
                if itype == 14:
                    _matrix(path, idata, order, out)
        elif etype == 14:  # miMATRIX
            _matrix(path, data, order, out)
        else:
            raise FormatError(path, f"corrupt MATLAB file: unexpected element type {etype} at byte {pos}")
    return out


def _element(path, buf, pos, order):
    """(type, data, next position) of the data element at ``pos``; lengths are checked."""
    if pos + 8 > len(buf):
        raise FormatError(path, "truncated MATLAB file (incomplete data element)")
    etype, nbytes = struct.unpack(order + "II", buf[pos:pos + 8])
    if etype >> 16:  # small data element: type and size share the first word, data in the second
        nbytes, etype = etype >> 16, etype & 0xFFFF
        if nbytes > 4:
            raise FormatError(path, "corrupt MATLAB file (bad small data element)")
        return etype, buf[pos + 4:pos + 4 + nbytes], pos + 8
    end = pos + 8 + nbytes
    if end > len(buf):
        raise FormatError(path, f"truncated or corrupt MATLAB file (element of {nbytes} bytes at byte {pos} "
                                f"runs past the end)")
    padded = end if etype == 15 else pos + 8 + (nbytes + 7) // 8 * 8
    return etype, buf[pos + 8:end], min(padded, len(buf))


def _inflate(path, data, budget) -> bytes:
    z = zlib.decompressobj()
    try:
        inner = z.decompress(data, max(budget, 1))
    except zlib.error as exc:
        raise FormatError(path, f"corrupt compressed MATLAB variable ({exc})") from None
    if z.unconsumed_tail or budget <= 0:
        raise FormatError(path, f"compressed MATLAB variables unpack to more than {size_text(_MAX_BYTES)}, "
                                "the most satmd reads from one file")
    return inner


def _matrix(path, data, order, out):
    """Parse one miMATRIX element into ``out[name]`` (numeric and char classes only)."""
    parts, pos = [], 0
    while pos < len(data) and len(parts) < 5:
        etype, sub, pos = _element(path, data, pos, order)
        parts.append((etype, sub))
    if len(parts) < 3 or parts[0][0] != 6 or len(parts[0][1]) != 8 or parts[1][0] != 5 or parts[2][0] != 1:
        raise FormatError(path, "corrupt MATLAB variable header (flags, dimensions, name)")
    flags = struct.unpack(order + "II", parts[0][1])[0]
    cls, is_complex = flags & 0xFF, bool(flags & 0x800)
    if len(parts[1][1]) % 4:
        raise FormatError(path, "corrupt MATLAB variable dimensions")
    dims = [int(d) for d in np.frombuffer(parts[1][1], order + "i4")]
    try:
        name = parts[2][1].decode("ascii")
    except UnicodeDecodeError:
        raise FormatError(path, "corrupt MATLAB variable name") from None
    if not name:
        return  # MATLAB's subsystem data (class objects) has no name
    if not dims or any(d < 0 for d in dims) or not name.isidentifier():
        raise FormatError(path, f"corrupt MATLAB variable {name!r} (dimensions {dims})")
    if cls not in _NUMERIC_CLASSES and cls != _CHAR_CLASS:
        return  # cell, struct, object, sparse: nothing satmd reads
    count = math.prod(dims)  # Python integers: dimensions whose product overflows int64 are refused here
    if count > MAX_SAMPLES:
        raise FormatError(path, f"MATLAB variable {name!r} has {count:.4g} values (dimensions {dims}): more than the "
                                f"{MAX_SAMPLES} satmd reads at once")

    def values(k):
        if len(parts) <= k:
            raise FormatError(path, f"MATLAB variable {name!r} has no data")
        etype, raw = parts[k]
        dtype = _MI_TYPES.get(etype)
        if dtype is None or len(raw) != count * np.dtype(dtype).itemsize:
            raise FormatError(path, f"corrupt MATLAB variable {name!r} ({len(raw)} data bytes for {count} values)")
        return np.frombuffer(raw, order + dtype)

    if cls == _CHAR_CLASS:
        codes = values(3).astype(np.int64)
        if codes.size and (codes.min() < 0 or codes.max() > 0x10FFFF):
            raise FormatError(path, f"corrupt MATLAB char variable {name!r}")
        chars = np.array([chr(c) for c in codes]).reshape(dims, order="F") if codes.size else np.array([""])
        out[name] = np.array(["".join(row) for row in chars.reshape(chars.shape[0], -1)])
        return
    arr = values(3).astype(_NUMERIC_CLASSES[cls])
    if is_complex:
        arr = arr + 1j * values(4).astype(_NUMERIC_CLASSES[cls])
    out[name] = arr.reshape(dims, order="F")


def vector_variable(path, name, value, complex_ok=False) -> np.ndarray:
    """Variable ``name`` as a finite 1-D float (or complex) array; a `FormatError` naming it otherwise."""
    v = np.asarray(value)
    if v.ndim > 1 and sum(s > 1 for s in v.shape) <= 1:
        v = v.reshape(-1)
    if v.ndim != 1:
        raise FormatError(path, f"variable {name!r} must be a vector, has shape {v.shape}")
    if v.dtype.kind not in "biufc" or (v.dtype.kind == "c" and not complex_ok):
        raise FormatError(path, f"variable {name!r} must hold {'numbers' if complex_ok else 'real numbers'}, "
                                f"has type {v.dtype}")
    v = v.astype(complex if complex_ok else float)
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise FormatError(path, f"variable {name!r}: NaN or infinite value at element {bad[0] + 1}")
    return v


def scalar_variable(path, name, value) -> float:
    """Variable ``name`` as one finite number > 0; a `FormatError` naming it otherwise."""
    v = np.asarray(value)
    if v.size != 1 or v.dtype.kind not in "biuf":
        raise FormatError(path, f"variable {name!r} must be one real number")
    x = float(v.reshape(-1)[0])
    if not np.isfinite(x) or x <= 0:
        raise FormatError(path, f"variable {name!r} must be > 0, got {x:g}")
    return x


def _variables_with(path, name, other, hint) -> dict:
    """The file's variables; without ``name`` a `FormatError` lists them (adding ``hint`` when ``other`` is there)."""
    v = load_variables(path)
    if name not in v:
        hint = hint if other in v else ""
        raise FormatError(path, f"no variable {name!r}{hint}; found: {', '.join(sorted(v)) or 'nothing'}")
    return v


def read_frf_variables(path) -> FRFData:
    """FRFData from a .mat / .npz file with the documented variable names."""
    path = Path(path)
    v = _variables_with(path, "freq_hz", "fs_hz", " (it looks like a recording: use satmd estimate-frf)")
    freq = vector_variable(path, "freq_hz", v["freq_hz"])
    channels: dict[str, np.ndarray] = {}
    std: dict[str, np.ndarray] = {}
    coh: dict[str, np.ndarray] = {}
    used = {"freq_hz"}
    for ch in CHANNELS:
        if ch in v:
            channels[ch] = vector_variable(path, ch, v[ch], complex_ok=True)
            used.add(ch)
        for suffix, into in (("_std", std), ("_coh", coh)):
            if ch + suffix in v:
                into[ch] = vector_variable(path, ch + suffix, v[ch + suffix])
                used.add(ch + suffix)
    if not channels:
        every = " (it holds FRFs of every channel of a structure, ChannelFRFs: this reads a rig's A1 and A2)" \
            if {"frf", "channels"} <= set(v) else ""
        raise FormatError(path, f"no FRF channel variable (any of {', '.join(CHANNELS)}){every}")
    warn_unused(path, v, used | {"meta"})
    meta = {"source": str(path), "format": path.suffix.lower().lstrip(".")}
    try:
        return FRFData(freq, channels, std, meta, coherence=coh)
    except DataError as exc:
        raise FormatError(path, str(exc)) from None


def warn_unused(path, variables, used):
    """Warn (`DataWarning`) about the file's variables that were not read."""
    extra = sorted(set(variables) - used)
    if extra:
        warn(path, f"ignored variable(s) {', '.join(extra)}")


def write_frf_variables(data: FRFData, path) -> Path:
    """FRFData as .mat or .npz with the documented names (exact: doubles)."""
    out = {"freq_hz": data.freq_hz}
    for ch, values in data.channels.items():
        out[ch] = values
        if ch in data.std:
            out[ch + "_std"] = data.std[ch]
        if ch in data.coherence:
            out[ch + "_coh"] = data.coherence[ch]
    return write_variables(out, path)


def write_recording_variables(fs_hz: float, signals: dict, path) -> Path:
    return write_variables({"fs_hz": np.float64(fs_hz), **signals}, path)


def write_variables(variables: dict, path) -> Path:
    path = Path(path)
    with atomic_write(path) as fh:  # an open file: np.savez would otherwise append '.npz'
        if path.suffix.lower() == ".npz":
            np.savez(fh, **variables)
        else:
            from scipy.io import savemat

            savemat(fh, {k: np.asarray(v) for k, v in variables.items()}, oned_as="column")
    return path
