"""Files in and out, and the data containers they fill: FRFs (`FRFData`) and time recordings (`Recording`).

``load_frf(path)`` dispatches on the file's suffix; ``save_frf(data, path)``
likewise. Readers are registered in ``READERS`` / ``WRITERS`` so that new
formats plug in without touching the callers.

FRF formats: ``.csv`` (SPEC §7), ``.uff``/``.unv`` (UFF 58/58b, function
type 4), ``.mat`` and ``.npz`` (documented variable names, see
`satmd.io.matfile`), ``.txt`` (one complex value per line; needs
``freq_axis``). Time recordings (`load_recording`): ``.csv``, ``.uff``,
``.wav``, ``.npz``, ``.mat``; `satmd.signal.estimate_frf` turns them into FRFs. Where the project's
shared real data lie: `satmd.io.shared`.
"""
from __future__ import annotations


import inspect
import os
from pathlib import Path

from ..errors import DataError, DataTypeError, FormatError
from ..validation import validate_params
from ._common import DataWarning, writer_for
from .channelfrfs import ChannelFRFs, load_channel_frfs
from .csvfrf import read_csv, write_csv
from .frfdata import CHANNELS, UNITS, FRFData
from .matfile import read_frf_variables, write_frf_variables
from .recording import Recording, clipped_channels, is_recording, load_recording, save_recording
from .txtfrf import read_txt
from .uff import read_uff, write_uff

READERS = {".csv": read_csv, ".uff": read_uff, ".unv": read_uff, ".mat": read_frf_variables,
           ".npz": read_frf_variables, ".txt": read_txt}
WRITERS = {".csv": write_csv, ".uff": write_uff, ".unv": write_uff, ".mat": write_frf_variables,
           ".npz": write_frf_variables}


@validate_params({"path": [str, os.PathLike]}, error=DataTypeError)
def load_frf(path, **options) -> FRFData:
    """Load FRFs from a file; the reader is chosen by the suffix.

    Options go to the reader: ``channel_map`` (UFF), ``freq_axis`` and
    ``channel`` (.txt). An option the format has no use for is refused.

    Parameters
    ----------
    path : str or Path
        An existing file: ``.csv``, ``.uff``/``.unv``, ``.mat``, ``.npz`` or
        ``.txt`` (suffix case does not matter).
    **options
        Keywords for the reader: ``channel_map`` (``.uff``/``.unv``: which
        record is which channel), ``freq_axis="START:STEP"`` (Hz; required for
        ``.txt``) and ``channel`` (``.txt``: the channel the values are,
        default ``a1``). Options set to None are ignored.

    Returns
    -------
    FRFData
        The file's FRFs, with ``std``, coherence and metadata where the file
        holds them (``meta["source"]`` names the file unless the file says otherwise).

    Raises
    ------
    FormatError
        No such file, a directory, an unknown suffix, an option the format
        does not take, or a malformed file or invalid data (naming the file).
    """
    path = Path(path)
    if not path.exists():
        raise FormatError(path, "no such file")
    if path.is_dir():
        raise FormatError(path, "is a directory, not a file")
    reader = READERS.get(path.suffix.lower())
    if reader is None:
        raise FormatError(path, f"unknown file type {path.suffix!r} (known: {', '.join(sorted(READERS))})")
    accepted = inspect.signature(reader).parameters
    for name, value in options.items():
        if name not in accepted and value is not None:
            raise FormatError(path, f"option {name} does not apply to {path.suffix} files")
    try:
        return reader(path, **{k: v for k, v in options.items() if k in accepted})
    except FormatError:
        raise
    except DataError as exc:  # FRFData's checks, without the file name
        raise FormatError(path, str(exc)) from None


@validate_params({"data": [FRFData], "path": [str, os.PathLike]}, error=DataTypeError)
def save_frf(data: FRFData, path, **options) -> Path:
    """Save FRFs; the writer is chosen by the suffix.

    Parameters
    ----------
    data : FRFData
        The FRFs to write, with their std and coherence where the format holds them.
    path : str or Path
        Target file: ``.csv`` (SPEC §7), ``.uff``/``.unv`` (UFF 58), ``.mat`` or
        ``.npz``; its folder must exist. An existing file is replaced.
    **options
        Keywords for the writer: ``binary`` for UFF (default True: 58b;
        False writes ASCII 58). The other writers take none.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    FormatError
        A suffix satmd cannot write (``.txt`` included) or a missing folder.
    """
    path = Path(path)
    return writer_for(path, WRITERS, "files")(data, path, **options)


def __getattr__(name):
    """Names this package gave before the estimators and simulators moved out (issue 48): warned aliases."""
    from .._moved import moved_name

    return moved_name(__name__, name)


__all__ = [
    "FRFData", "CHANNELS", "UNITS", "load_frf", "save_frf", "READERS", "WRITERS", "DataWarning",
    "Recording", "load_recording", "save_recording", "is_recording", "clipped_channels",
    "ChannelFRFs", "load_channel_frfs",
]
