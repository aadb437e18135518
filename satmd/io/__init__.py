"""Reading and writing FRFs.

``load_frf(path)`` dispatches on the file's suffix; ``save_frf(data, path)``
likewise. Readers are registered in ``READERS`` / ``WRITERS`` so that new
formats plug in without touching the callers.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import FormatError
from .csvfrf import read_csv, write_csv
from .frfdata import CHANNELS, UNITS, FRFData

READERS = {".csv": read_csv}
WRITERS = {".csv": write_csv}


def load_frf(path, **options) -> FRFData:
    """Load FRFs from a file; the reader is chosen by the suffix."""
    path = Path(path)
    if not path.exists():
        raise FormatError(path, "no such file")
    if path.is_dir():
        raise FormatError(path, "is a directory, not a file")
    reader = READERS.get(path.suffix.lower())
    if reader is None:
        raise FormatError(path, f"unknown file type {path.suffix!r} (known: {', '.join(sorted(READERS))})")
    return reader(path, **options)


def save_frf(data: FRFData, path, **options) -> Path:
    """Save FRFs; the writer is chosen by the suffix."""
    path = Path(path)
    writer = WRITERS.get(path.suffix.lower())
    if writer is None:
        raise FormatError(path, f"cannot write {path.suffix!r} files (known: {', '.join(sorted(WRITERS))})")
    if path.parent and not path.parent.exists():
        raise FormatError(path, f"folder {path.parent} does not exist")
    return writer(data, path, **options)


__all__ = ["FRFData", "CHANNELS", "UNITS", "load_frf", "save_frf", "READERS", "WRITERS"]
