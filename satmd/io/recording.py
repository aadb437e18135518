"""Time recordings (force and accelerations) and the files they come in: one suffix dispatch.

A `Recording` (`satmd.io.recdata`) holds uniformly sampled channels: ``force`` [N] and any number of
accelerometers ``acc1``, ``acc2``, ``acc3``, ... [m/s²] (`recdata.is_role`). The SATMD rig's estimators use
``force`` on the primary mass and ``acc1``, ``acc2`` of the primary mass and the absorber; other
channels (a microphone, a voltage) are kept under their own names for inspection.

Formats (`load_recording` chooses by suffix; each has its module: `csvrec`, `uffrec`, `wavrec`, `matfile`):

``.csv``  ``# satmd-recording v1`` (optional), then the header
          ``time_s,force,acc1,acc2`` (``force`` may be left out: output-only;
          ``acc3``, ... may follow), SI units, uniform sampling.
``.uff``  UFF 58 / 58b time records (function type 1), several in one file,
          ASCII or binary; units stated in the file are converted to SI.
          Roles: one force record (specific data type 13 or 9, or a force
          unit) and two response records become force/acc1/acc2 in file
          order; otherwise ``channel_map="force=#1,a1=1:+Z,a2=2:+Z,a3=3:+Z"``.
``.wav``  one channel per column: 3 channels = force, acc1, acc2; 2 channels
          = acc1, acc2; other counts ch1, ch2, ... unless a map names them. WAV has no units: integer samples are read as
          fractions of full scale; pass ``scale={"force": N_per_unit, ...}``.
``.npz`` / ``.mat``  variables ``force``, ``acc1``, ``acc2``, ... and a rate (``fs_hz``, ``Fs``, ...), or as a
          channel map names them (``force=Force,a1=Acceleration[2]``; `matrec`).

Loaders warn (`DataWarning`) about clipped channels and refuse NaN,
mismatched lengths and non-uniform sampling with a one-line `FormatError`.
"""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import DataError, DataTypeError, FormatError
from ..validation import validate_params
from ._common import read_text, text_lines, writer_for
from .limits import MAX_BINARY_BYTES, check_file
from .csvrec import CSV_MAGIC, read_recording_csv, write_recording_csv
from .recdata import (
    MAX_ABS_SAMPLE,
    ROLES,
    SI_UNITS,
    Recording,
    check_rate,
    clipped_channels,
    si_unit,
    warn_clipping,
)
from .uffrec import read_recording_uff, write_recording_uff
from .wavrec import read_recording_wav, write_recording_wav


# --- .npz / .mat ----------------------------------------------------------------
def read_recording_variables(path, channel_map=None, fs_hz=None) -> Recording:
    from .matrec import read_recording_variables as _read

    path = Path(path)
    fs, signals, meta = _read(path, channel_map, fs_hz)
    try:
        rec = Recording(fs, signals, {n: si_unit(n) for n in signals},
                        {"source": str(path), "format": path.suffix.lower().lstrip("."), **meta})
    except DataError as exc:
        raise FormatError(path, str(exc)) from None
    warn_clipping(path, rec)
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


@validate_params({"path": [str, os.PathLike], "channel_map": [None, str], "scale": [None, dict]}, error=DataTypeError)
def load_recording(path, channel_map=None, scale=None, fs_hz=None) -> Recording:
    """Load a time recording; the reader is chosen by the suffix (see the module docstring).

    Parameters
    ----------
    path : str or Path
        An existing ``.csv``, ``.uff``/``.unv``, ``.wav``, ``.npz`` or ``.mat``
        file (suffix case does not matter).
    channel_map : str, optional
        Which record or column is which channel, e.g.
        ``"force=#1,a1=1:+Z,a2=2:+Z"`` (UFF), ``"force=#1,a1=#2"`` (WAV) or
        ``"force=Force,a1=Acceleration[2],a2=Acceleration[3]"`` (.mat/.npz: a
        variable, or a row of a matrix of signals counted from 1) or
        ``"force=Force,a1=Acc wing"`` (a lab's CSV columns). Any number of
        accelerometers: ``a3`` (or ``acc3``) names channel ``acc3``, and so on.
    scale : dict, optional
        ``{channel: SI units per stored unit}`` (e.g. ``{"force": N_per_unit}``)
        for WAV files, which carry no units; WAV only.
    fs_hz : float, optional
        The sample rate, for .mat/.npz files that hold none (otherwise read
        from a rate variable such as ``fs_hz`` or ``Fs``, or a time vector).

    Returns
    -------
    Recording
        The channels (``force``, ``acc1``, ``acc2``, ..., others under their own
        names) in SI units where the file states or ``scale`` gives them.
        Clipped channels are reported with a `DataWarning`.

    Raises
    ------
    FormatError
        No such file, a directory, an unknown suffix, an option the format does
        not take, or a malformed file (NaN, mismatched lengths, non-uniform
        sampling, ...).
    """
    path = Path(path)
    check_file(path, MAX_BINARY_BYTES)  # missing, a folder, a FIFO or a device: refused before any reader
    suffix = path.suffix.lower()
    reader = RECORDING_READERS.get(suffix)
    if reader is None:
        known = ", ".join(sorted(RECORDING_READERS))
        raise FormatError(path, f"unknown recording type {path.suffix!r} (known: {known})")
    options = {}
    if channel_map:
        if suffix not in (".uff", ".unv", ".wav", ".mat", ".npz", ".csv"):
            raise FormatError(path, f"channel_map does not apply to {suffix} recordings (their channels are named)")
        options["channel_map"] = channel_map
    if fs_hz is not None:
        if suffix not in (".mat", ".npz"):
            raise FormatError(path, f"a sample rate applies to .mat/.npz recordings; {suffix} files state theirs")
        options["fs_hz"] = fs_hz
    if scale:
        if suffix != ".wav":
            raise FormatError(path, "scale applies to WAV files only (the others carry units)")
        options["scale"] = scale
    rec = reader(path, **options)
    check_rate(path, rec.fs_hz)
    return rec


@validate_params({"rec": [Recording], "path": [str, os.PathLike]}, error=DataTypeError)
def save_recording(rec: Recording, path) -> Path:
    """Save a time recording; the writer is chosen by the suffix (see the module docstring).

    Parameters
    ----------
    rec : Recording
        The recording to write, every channel (force, acc1, ..., accN, then
        the others); WAV needs an integer sample rate (writers refuse others with
        a `DataError`).
    path : str or Path
        Target file: ``.csv``, ``.uff``/``.unv`` (binary UFF 58b), ``.wav``
        (64-bit float), ``.npz`` or ``.mat``; its folder must exist. An
        existing file is replaced.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    FormatError
        A suffix satmd cannot write or a missing folder.
    """
    path = Path(path)
    return writer_for(path, RECORDING_WRITERS, "recordings")(rec, path)


def is_recording(path) -> bool:
    """Whether a file holds time data (True) rather than FRFs (False); unreadable files raise FormatError.

    Parameters
    ----------
    path : str or Path
        The file to look at; only its suffix and content decide.

    Returns
    -------
    bool
        True for ``.wav``; for ``.csv`` whose header (first line that is not
        blank or a ``#`` comment) starts with ``time_s``; for ``.uff``/``.unv``
        with time records (function type 1) and no FRF (type 4); for
        ``.npz``/``.mat`` with ``fs_hz`` and no ``freq_hz``. False otherwise,
        and for a path that is not a file (the FRF loader then says what is wrong).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if not path.is_file():
        return False  # the FRF loader says what is wrong with the path
    if suffix == ".wav":
        return True
    if suffix == ".csv":
        text = read_text(path)
        from .labcsv import TIME_NAMES, split_unit

        for line in text_lines(text):
            s = line.strip()
            if s and not s.startswith("#"):
                return split_unit(s.split(",")[0])[0].lower() in TIME_NAMES
        return False
    if suffix in (".uff", ".unv"):
        from .uff58 import read_records

        records, _ = read_records(path)
        types = {r.func_type for r in records}
        return 1 in types and 4 not in types
    if suffix in (".npz", ".mat"):
        from .matrec import is_recording_file

        return is_recording_file(path)
    return False


__all__ = ["CSV_MAGIC", "MAX_ABS_SAMPLE", "RECORDING_READERS", "RECORDING_WRITERS", "ROLES", "SI_UNITS", "Recording",
           "clipped_channels", "is_recording", "load_recording", "read_recording_csv", "read_recording_uff",
           "read_recording_variables", "read_recording_wav", "save_recording", "write_recording_csv",
           "write_recording_uff", "write_recording_variables", "write_recording_wav"]
