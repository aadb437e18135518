"""Recordings as WAV: one channel per column, 3 channels = force, acc1, acc2; 2 channels = acc1, acc2.

Other counts are ch1, ch2, ... unless a channel map names them
(``channel_map="force=#1,a1=#2,a2=#3,a3=#4"``: any number of accelerometers).
WAV has no units: integer samples are read as fractions of full scale; pass
``scale={"force": N_per_unit, ...}``. Files written by satmd are 64-bit float
and name their channels (SI) in a LIST/INFO comment.
"""
from __future__ import annotations

import io as _io
import math
import struct
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import channel_map_of, read_bytes, warn
from .atomic import atomic_write
from .limits import MAX_BINARY_BYTES, check_file, check_samples
from .recdata import Recording, is_role, ordered, role_of, si_unit, warn_clipping

_WAV_ROLES = {3: ("force", "acc1", "acc2"), 2: ("acc1", "acc2")}
_WAV_TAG = "satmd-recording v1"


def read_recording_wav(path, channel_map=None, scale=None) -> Recording:
    """A WAV file: channel roles by count or ``channel_map="force=#1,a1=#2"``, units by ``scale``."""
    import warnings

    from scipy.io import wavfile

    path = Path(path)
    size = check_file(path, MAX_BINARY_BYTES)
    if size == 0:
        raise FormatError(path, "empty file")
    with open(path, "rb") as fh:  # the header first: sizes and the sample cap are checked before the data are read
        _check_layout(path, fh.read(1 << 16), size)
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
        wanted = channel_map_of(path, channel_map, role_of)
        names = [f"ch{k + 1}" for k in range(n_ch)]
        for role, (kind, a, _) in wanted.items():
            if kind != "index" or not 1 <= a <= n_ch:
                raise FormatError(path, f"channel_map {role}: WAV channels are chosen as #1..#{n_ch}")
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
    units = {n: si_unit(n) if (n in scale or ours) else raw_unit for n in names}
    if not ours and any(is_role(n) and n not in scale for n in names):
        warn(path, f"WAV files carry no units: values are {'fractions of full scale' if is_int else 'as stored'}; "
                   "calibrate with scale (force=N_per_unit, ...) or FRF magnitudes are off")
    meta = {"source": str(path), "format": f"WAV {data.dtype}"}
    try:
        rec = Recording(float(fs), channels, units, meta, {n: f"WAV channel {k + 1}" for k, n in enumerate(names)})
    except DataError as exc:
        raise FormatError(path, str(exc)) from None
    extremes = ({n: tuple(sorted(g * x for x in limits)) for n, g in gains.items()}
                if is_int and limits is not None else None)
    warn_clipping(path, rec, extremes)
    return rec


def write_recording_wav(rec: Recording, path) -> Path:
    """64-bit float WAV (exact), channels in the order force, acc1, acc2, ..., accN (then others).

    A LIST/INFO comment ``satmd-recording v1; channels force,acc1,acc2; SI``
    lets `read_recording_wav` restore names and units; other programs ignore it.
    """
    from scipy.io import wavfile

    path = Path(path)
    if abs(rec.fs_hz - round(rec.fs_hz)) > 1e-9 * rec.fs_hz:
        raise DataError(f"WAV needs an integer sample rate, this recording has {rec.fs_hz:g} Hz")
    order = ordered(rec.channels)
    buf = _io.BytesIO()
    wavfile.write(buf, int(round(rec.fs_hz)), np.column_stack([rec.channels[n] for n in order]))
    text = f"{_WAV_TAG}; channels {','.join(order)}; SI".encode("ascii") + b"\0"
    text += b"\0" * (len(text) % 2)
    info = b"INFO" + b"ICMT" + struct.pack("<I", len(text)) + text
    riff = bytearray(buf.getvalue()) + b"LIST" + struct.pack("<I", len(info)) + info
    riff[4:8] = struct.pack("<I", len(riff) - 8)
    with atomic_write(path) as fh:
        fh.write(bytes(riff))
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


def _check_layout(path, raw: bytes, total: int):
    """Sizes the RIFF header declares, checked against the file's ``total`` bytes, and the sample cap.

    ``raw`` is the start of the file (the chunk headers before the data).
    """
    if len(raw) < 12 or raw[:4] not in (b"RIFF", b"RIFX", b"RF64") or raw[8:12] != b"WAVE":
        raise FormatError(path, "not a WAV file (no RIFF/WAVE header)")
    order = ">" if raw[:4] == b"RIFX" else "<"
    declared = struct.unpack(order + "I", raw[4:8])[0] + 8
    if raw[:4] != b"RF64" and declared > total:
        warn(path, f"the RIFF header declares {declared} bytes, the file holds {total}: truncated?")
    pos, channels, block = 12, None, None
    while pos + 8 <= len(raw):
        cid, size = raw[pos:pos + 4], struct.unpack(order + "I", raw[pos + 4:pos + 8])[0]
        if cid == b"fmt " and size >= 16 and pos + 24 <= len(raw):
            channels = struct.unpack(order + "H", raw[pos + 10:pos + 12])[0]
            block = struct.unpack(order + "H", raw[pos + 20:pos + 22])[0]
        elif cid == b"data":
            if raw[:4] != b"RF64" and pos + 8 + size > total:
                raise FormatError(path, f"truncated WAV file: the data chunk declares {size} bytes, the file holds "
                                        f"{total - pos - 8} after its header")
            if channels and block:
                check_samples(path, size // block, channels, path=path)
            return
        pos += 8 + size + size % 2
