"""One complex FRF value per line (``(re+imj)`` or ``re+imj``), as some lab scripts write them.

Such a file has no frequency axis, so reading it needs ``freq_axis="START:STEP"``
(Hz; CLI ``--freq-axis``). Values are taken as one channel (``a1`` unless
``channel=`` says otherwise) in SI units; points at f <= 0 are dropped with a
warning. Lines starting with ``#`` and blank lines are skipped.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import read_text, text_lines, warn
from .frfdata import CHANNELS, FRFData


def read_values(path) -> np.ndarray:
    """The complex values, refusing anything else with file and line."""
    path = Path(path)
    text = read_text(path)
    values = []
    for lineno, line in enumerate(text_lines(text), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        try:
            z = complex(s.replace(" ", ""))
        except ValueError:
            raise FormatError(path, f"not a complex number: {s[:40]!r}", line=lineno) from None
        if not (math.isfinite(z.real) and math.isfinite(z.imag)):
            raise FormatError(path, f"{s[:40]} is not finite", line=lineno)
        values.append(z)
    if not values:
        raise FormatError(path, "no values")
    return np.asarray(values, dtype=complex)


def parse_freq_axis(spec):
    """'0:1' or (0.0, 1.0) -> (start, step) with step > 0."""
    try:
        start, step = (spec.split(":") if isinstance(spec, str) else spec)
        start, step = float(start), float(step)
    except (ValueError, TypeError):
        raise DataError(f"freq_axis {spec!r}: expected START:STEP in Hz, e.g. 0:1") from None
    for name, x in (("START", start), ("STEP", step)):
        if not math.isfinite(x):
            raise DataError(f"freq_axis {spec!r}: {name} {x} is not a finite number")
    if not step > 0:
        raise DataError(f"freq_axis {spec!r}: STEP must be > 0, got {step:g}")
    return start, step


def read_txt(path, freq_axis=None, channel: str = "a1") -> FRFData:
    path = Path(path)
    values = read_values(path)
    if freq_axis is None:
        raise FormatError(path, f"{values.size} complex values but no frequency axis: pass "
                                "freq_axis START:STEP (Hz)")
    if channel not in CHANNELS:
        raise DataError(f"channel {channel!r}: choose from {', '.join(CHANNELS)}")
    start, step = parse_freq_axis(freq_axis)
    freq = start + step * np.arange(values.size)
    keep = freq > 0
    if not keep.all():
        warn(path, f"dropped {int((~keep).sum())} point(s) at f <= 0 Hz (FRFs are used for f > 0)")
    if not keep.any():
        raise FormatError(path, "no frequency above 0 Hz")
    meta = {"source": str(path), "format": "complex values, one per line",
            "freq_axis": f"{start:g}:{step:g}", "units": "as stored (SI assumed)"}
    return FRFData(freq[keep], {channel: values[keep]}, {}, meta)
