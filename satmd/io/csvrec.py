"""Recordings as CSV: ``# satmd-recording v1`` (optional), then ``time_s,force,acc1,acc2`` in SI units.

``force`` may be left out (output-only); any number of accelerometers
``acc1, acc2, ..., accN`` may follow; sampling must be uniform. A file that
starts with ``# satmd-recording v1`` (satmd writes it) may hold other channels
under their own names; elsewhere an unknown column is refused (a typo).

Lab files as their software writes them are read too: a first column that is
time (``time``, ``t``, ``Time [s]``, ``t (ms)``), channels under the lab's own
names, any case, with a unit in brackets (``Force [N]``, ``Acc wing (g)``:
converted to SI). Columns named ``force``/``acc1``/``acc2``/... (any case, unit
aside) are taken by name; otherwise ``channel_map="force=Force,a1=Acc wing"``
says which column is which.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from ._common import numeric_table, read_text, split_csv, text_lines
from .atomic import atomic_write
from .recdata import Recording, is_role, ordered, si_unit, uniform_rate, warn_clipping

CSV_MAGIC = "# satmd-recording v1"


def read_recording_csv(path, channel_map=None) -> Recording:
    """A ``time_s,force,acc1,acc2,...`` CSV (SI units) or a lab's CSV; malformed input names file, line and column."""
    path = Path(path)
    text = read_text(path)
    header, header_line, rows, meta = split_csv(path, text, "satmd-recording")
    if header is None:
        raise FormatError(path, "no column header (expected time_s,force,acc1,acc2)")
    if channel_map or header[0] != "time_s":
        from .labcsv import read_lab_csv

        return read_lab_csv(path, header, header_line, rows, meta, channel_map)
    _check_header(path, header, header_line, ours=text_lines(text)[0].strip() == CSV_MAGIC)
    if len(rows) < 2:
        raise FormatError(path, f"{len(rows)} data row(s): a recording needs at least 2 samples", line=header_line)
    values = numeric_table(path, header, rows)
    fs = uniform_rate(path, values[:, 0], [ln for ln, _ in rows])
    channels = {name: values[:, j] for j, name in enumerate(header) if j}
    meta.update({"source": str(path), "format": "csv"})
    rec = Recording(fs, channels, {n: si_unit(n) for n in channels if is_role(n)}, meta,  # others: unit unknown
                    {n: f"column {j + 1}" for j, n in enumerate(header) if j})
    warn_clipping(path, rec)
    return rec


def _check_header(path, header, lineno, ours=False):
    """Columns are roles (force, acc<N>); a file satmd wrote (``ours``) may name other channels too."""
    if header[0] != "time_s":
        raise FormatError(path, f"first column must be time_s, got {header[0]!r}", line=lineno, column=1)
    seen = set()
    for j, name in enumerate(header[1:], start=2):
        if not (is_role(name) or (ours and name and name != "time_s")):
            free = 1 + max((int(h[3:]) for h in header if is_role(h) and h.startswith("acc")), default=0)
            raise FormatError(path, f"unknown column {name!r} (known: force, acc1, acc2, acc3, ...): a lab's names "
                                    f"are read with a channel map that names every column, e.g. force=force,a1=acc1,"
                                    f"...,a{free}={name}", line=lineno, column=j)
        if name in seen:
            raise FormatError(path, f"duplicate column {name!r}", line=lineno, column=j)
        seen.add(name)
    if len(header) < 2:
        raise FormatError(path, "no signal columns after time_s", line=lineno)


def write_recording_csv(rec: Recording, path) -> Path:
    """Every channel as a column of a ``# satmd-recording v1`` CSV: force, acc1, ..., accN, then the others.

    Parameters
    ----------
    rec : Recording
        The recording; values are written as they are (17 digits: exact).
    path : str or Path
        The file to write (replaced if it exists).

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    DataError
        A channel name that cannot be a CSV column (empty, a comma, a line end,
        a leading ``#``, spaces around it, or ``time_s``).
    """
    path = Path(path)
    names = ordered(rec.channels)
    for name in names:  # the reader splits the header at commas and strips cells
        if (not isinstance(name, str) or not name or name != name.strip() or name.startswith("#")
                or name == "time_s" or any(c in name for c in ",\r\n")):
            raise DataError(f"channel {name!r} cannot be a CSV column name; rename it first")
    lines = [CSV_MAGIC]
    lines += [f"# {k}: {v}" for k, v in rec.meta.items()
              if k not in ("source", "excitation_layout", "steady_periods") and "\n" not in f"{k}{v}"]
    lines.append(",".join(["time_s"] + names))
    table = np.column_stack([rec.time_s] + [rec.channels[n] for n in names])
    lines += [",".join(f"{x:.17g}" for x in row) for row in table]
    with atomic_write(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path
