"""The `satmd-frf v1` CSV format (SPEC §7): strict reader, exact writer."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import numeric_table, read_text, split_csv, text_lines
from .estmeta import validate_estimator
from .atomic import atomic_write
from .frfdata import CHANNELS, FRFData

MAGIC = "# satmd-frf v1"
_SUFFIXES = ("re", "im", "std")
ESTIMATOR_KEY = "satmd estimator"  # comment line holding FRFData.estimator as JSON


def read_csv(path) -> FRFData:
    """Read a SPEC §7 file; any malformation raises FormatError (file, line, column)."""
    path = Path(path)
    text = read_text(path)
    if text.lstrip().lower().startswith("# satmd-transmissibility"):  # say what the file is, not "unknown channel"
        raise FormatError(path, "holds a transmissibility A2/A1 (written by estimate-frf from an output-only "
                                "recording), not FRFs per unit force; FRFs need a recording with a force channel",
                          line=1)
    header, header_line, rows, meta = split_csv(path, text, "satmd-frf")
    if header is None:
        raise FormatError(path, "no column header (expected freq_hz,a1_re,a1_im,...)")
    columns = _parse_header(path, header, header_line)
    if not rows:
        raise FormatError(path, "no data rows after the header", line=header_line)
    values = numeric_table(path, header, rows)

    freq = values[:, 0]
    for i, (lineno, _) in enumerate(rows):
        if freq[i] <= 0:
            raise FormatError(path, f"frequency must be > 0, got {freq[i]:g}", line=lineno, column="1 (freq_hz)")
        if i and freq[i] <= freq[i - 1]:
            raise FormatError(path, f"frequency not strictly increasing ({freq[i]:g} after {freq[i - 1]:g})",
                              line=lineno, column="1 (freq_hz)")
    chans, std = {}, {}
    for ch, cols in columns.items():
        z = np.empty(len(rows), dtype=complex)  # not re + 1j*im, which turns a real part of -0.0 into +0.0
        z.real, z.imag = values[:, cols["re"]], values[:, cols["im"]]
        chans[ch] = z
        if "std" in cols:
            s = values[:, cols["std"]]
            bad = np.flatnonzero(s < 0)
            if bad.size:
                k = bad[0]
                raise FormatError(path, f"negative std {s[k]:g}", line=rows[k][0],
                                  column=f"{cols['std'] + 1} ({ch}_std)")
            std[ch] = s
    meta.setdefault("source", str(path))
    estimator = _estimator(path, text, meta, float(freq[-1]))
    return FRFData(freq, chans, std, meta, estimator=estimator)


def _estimator(path, text, meta, freq_max) -> dict:
    """The ``# satmd estimator: {...}`` comment, parsed and checked against the schema (`satmd.io.estmeta`)."""
    if ESTIMATOR_KEY not in meta:
        return {}
    raw = meta.pop(ESTIMATOR_KEY)
    line = next((k for k, ln in enumerate(text_lines(text), start=1)
                 if ln.strip().lstrip("#").strip().startswith(ESTIMATOR_KEY + ":")), None)
    try:
        estimator = json.loads(raw)
    except (ValueError, RecursionError):
        raise FormatError(path, f"the '# {ESTIMATOR_KEY}:' comment is not JSON (or nests too deeply)",
                          line=line) from None
    if not isinstance(estimator, dict):
        raise FormatError(path, f"the '# {ESTIMATOR_KEY}:' comment is not a JSON object", line=line)
    try:
        return validate_estimator(estimator, freq_max)
    except DataError as exc:
        raise FormatError(path, f"the '# {ESTIMATOR_KEY}:' comment: {exc}", line=line) from None


def _parse_header(path, header, lineno):
    if header[0] != "freq_hz":
        raise FormatError(path, f"first column must be freq_hz, got {header[0]!r}", line=lineno, column=1)
    columns: dict = {}
    for j, name in enumerate(header[1:], start=2):
        ch, _, suffix = name.rpartition("_")
        if suffix not in _SUFFIXES or not ch:
            raise FormatError(path, f"bad column name {name!r} (expected <channel>_re, _im or _std)", line=lineno, column=j)
        if ch not in CHANNELS:
            raise FormatError(path, f"unknown channel {ch!r} in column {name!r} (known: {', '.join(CHANNELS)})",
                              line=lineno, column=j)
        if suffix in columns.setdefault(ch, {}):
            raise FormatError(path, f"duplicate column {name!r}", line=lineno, column=j)
        columns[ch][suffix] = j - 1
    if not columns:
        raise FormatError(path, "no channel columns after freq_hz", line=lineno)
    for ch, cols in columns.items():
        for need in ("re", "im"):
            if need not in cols:
                raise FormatError(path, f"channel {ch} has no {ch}_{need} column", line=lineno)
    return columns


def write_csv(data: FRFData, path) -> Path:
    """Write SPEC §7 CSV; floats with 17 significant digits so a read gives the same bits.

    The file is written to a temporary name and renamed, so a failure never
    leaves a half-written file in place of an existing one.
    """
    path = Path(path)
    names = list(data.channels)
    header = ["freq_hz"] + [f"{c}_{p}" for c in names for p in ("re", "im")]
    header += [f"{c}_std" for c in names if c in data.std]
    cols = [data.freq_hz]
    for c in names:
        cols += [data.channels[c].real, data.channels[c].imag]
    cols += [data.std[c] for c in names if c in data.std]
    table = np.column_stack(cols)
    lines = [MAGIC]
    for k, v in data.meta.items():
        if k != "source" and k != ESTIMATOR_KEY and "\n" not in f"{k}{v}":
            lines.append(f"# {k}: {v}")
    if data.estimator:  # how the FRFs were estimated travels with them (a Welch kernel is part of the model)
        lines.append(f"# {ESTIMATOR_KEY}: {json.dumps(data.estimator, separators=(',', ':'))}")
    lines.append(",".join(header))
    lines += [",".join(f"{x:.17g}" for x in row) for row in table]
    with atomic_write(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path
