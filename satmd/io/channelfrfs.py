"""FRFs of every response channel of a structure over its one force: what a ground vibration test's engineer
looks at first, with each FRF's std and coherence.

A SATMD rig's FRFs are A1 and A2 (`FRFData`, SPEC §7); a structure's are as many as its accelerometers, named as
its channels are (``acc1`` … ``accN``, or a lab's names). They are written as a table (CSV, one row per
frequency: ``<channel>_re``, ``_im``, ``_std``, ``_coh`` each), as arrays (``.npz``, ``.mat``: ``freq_hz``,
``channels``, ``frf`` channel × frequency, ``std``, ``coherence``), or as UFF 58 records (one FRF, std and
coherence each per channel, the response node N for ``accN``, the channel's name in ID line 1), which modal
software reads. Each reads back (`load_channel_frfs`).
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataError, FormatError
from .atomic import atomic_write

MAGIC = "# satmd-frfs v1: the FRF of every response channel over the force"
SUFFIXES = (".csv", ".npz", ".mat", ".uff", ".unv")
UFF_ID = "satmd-frfs v1"  # ID line 2 of each UFF record written here


@dataclass(frozen=True)
class ChannelFRFs:
    """FRFs of several response channels over one force, on one frequency grid.

    Attributes
    ----------
    freq_hz : (n,) increasing frequencies
    channels : the response channels' names, in the order of the rows
    frf : (channels, n) complex, each channel over the force (its unit over the force's)
    std : (channels, n) the std of the noise on each of the real and imaginary parts
    coherence : (channels, n) in [0, 1]
    units : the FRFs' unit, e.g. ``m/s^2/N``
    estimator : how they were estimated (`FRFData.estimator` of each pair, the same method for every channel)
    source : the recording they came from
    """

    freq_hz: np.ndarray
    channels: tuple
    frf: np.ndarray
    std: np.ndarray
    coherence: np.ndarray
    units: str = "m/s^2/N"
    estimator: dict = field(default_factory=dict)
    source: str = ""

    def __post_init__(self):
        f = np.asarray(self.freq_hz, float)
        shape = (len(self.channels), f.size)
        if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(np.diff(f) <= 0):
            raise DataError("freq_hz must be a non-empty, finite, strictly increasing 1-D array")
        if len(set(self.channels)) != len(self.channels) or not self.channels:
            raise DataError(f"the channels must be one or more distinct names, got {list(self.channels)}")
        for name in ("frf", "std", "coherence"):
            a = np.asarray(getattr(self, name))
            if a.shape != shape:
                raise DataError(f"{name} has shape {a.shape}, expected {shape} (channels × frequencies)")
            if not np.all(np.isfinite(a)):
                raise DataError(f"{name} has NaN or infinite values")
        object.__setattr__(self, "freq_hz", f)
        object.__setattr__(self, "channels", tuple(self.channels))

    def __getitem__(self, channel: str) -> np.ndarray:
        """The FRF of one channel."""
        try:
            return self.frf[self.channels.index(channel)]
        except ValueError:
            raise DataError(f"no FRF of {channel!r} (channels: {', '.join(self.channels)})") from None

    def save(self, path) -> Path:
        """Write to ``path`` (.csv, .npz, .mat, .uff/.unv by its suffix), atomically."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in SUFFIXES:
            raise FormatError(path, f"FRFs of every channel are written as {', '.join(SUFFIXES)}")
        if suffix == ".csv":
            return self._write_csv(path)
        if suffix in (".uff", ".unv"):
            return self._write_uff(path)
        from .matfile import write_variables

        return write_variables({"freq_hz": self.freq_hz, "channels": np.array(self.channels), "frf": self.frf,
                       "std": self.std, "coherence": self.coherence, "units": np.array(self.units),
                       "estimator": np.array(json.dumps(self.estimator))}, path)

    def _write_csv(self, path: Path) -> Path:
        header = ["freq_hz"] + [f"{c}_{p}" for c in self.channels for p in ("re", "im", "std", "coh")]
        cols = [self.freq_hz]
        for i in range(len(self.channels)):
            cols += [self.frf[i].real, self.frf[i].imag, self.std[i], self.coherence[i]]
        lines = [MAGIC, f"# units: {self.units}", f"# estimator: {json.dumps(self.estimator, separators=(',', ':'))}",
                 ",".join(header)]
        lines += [",".join(f"{x:.17g}" for x in row) for row in np.column_stack(cols)]
        with atomic_write(path, "w") as fh:
            fh.write("\n".join(lines) + "\n")
        return path

    def _write_uff(self, path: Path) -> Path:
        from .uff58 import dataset58, write_datasets

        parts = []
        for i, ch in enumerate(self.channels):
            node = int(ch[3:]) if ch.startswith("acc") and ch[3:].isdigit() else i + 1
            common = dict(rsp=(node, 3), ref=(0, 0), id2=UFF_ID, binary=True)
            parts.append(dataset58(self.freq_hz, self.frf[i], func_type=4, tag=ch,
                                   ordinate=(12, "Acceleration", "m/s^2"), denominator=(13, "Force", "N"), **common))
            parts.append(dataset58(self.freq_hz, self.std[i], func_type=0, tag=f"{ch}_std",
                                   ordinate=(1, "Std of Re and Im", "m/s^2/N"), **common))
            parts.append(dataset58(self.freq_hz, self.coherence[i], func_type=6, tag=f"{ch}_coh",
                                   ordinate=(1, "Coherence", "NONE"), **common))
        return write_datasets(parts, path)


def is_channel_frfs(path) -> bool:
    """Whether ``path`` holds FRFs of every channel as `ChannelFRFs.save` writes them."""
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix == ".csv":
            from .limits import MAX_TEXT_BYTES, check_file

            check_file(path, MAX_TEXT_BYTES)  # a FIFO or a device refused before it is opened
            with open(path, encoding="utf-8", errors="replace") as fh:
                return fh.readline(len(MAGIC) + 2).rstrip("\r\n") == MAGIC
        if suffix in (".npz", ".mat"):
            from .matfile import load_variables

            return {"frf", "channels", "freq_hz"} <= set(load_variables(path))
        if suffix in (".uff", ".unv"):
            from .uff58 import read_records

            return any(str(r.get("id2", "")).strip() == UFF_ID for r in read_records(path)[0])
    except (OSError, DataError):
        return False
    return False


def load_channel_frfs(path) -> ChannelFRFs:
    """FRFs of every channel as `ChannelFRFs.save` wrote them.

    Parameters
    ----------
    path : a .csv, .npz, .mat or .uff file (the UFF without the estimator's description)

    Returns
    -------
    ChannelFRFs

    Raises
    ------
    FormatError
        Another kind of file, or one damaged (its file and what is wrong named).
    """
    path = Path(path)
    try:
        return _read(path)
    except FormatError:
        raise
    except DataError as exc:  # what the file holds is not FRFs (NaN, a falling grid): said with the file's name
        raise FormatError(path, str(exc)) from None


def _read(path: Path) -> ChannelFRFs:
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return _read_csv(path)
    if suffix in (".uff", ".unv"):
        return _read_uff(path)
    if suffix not in (".npz", ".mat"):
        raise FormatError(path, "FRFs of every channel are read from .csv, .npz, .mat or .uff")
    from .matfile import load_variables

    v = load_variables(path)
    try:
        return ChannelFRFs(np.ravel(v["freq_hz"]), tuple(str(c).strip() for c in np.ravel(v["channels"])),
                           np.atleast_2d(v["frf"]), np.atleast_2d(v["std"]), np.atleast_2d(v["coherence"]),
                           str(np.ravel(v["units"])[0]), json.loads(str(np.ravel(v["estimator"])[0])), str(path))
    except KeyError as exc:
        raise FormatError(path, f"no variable {exc.args[0]!r}: not FRFs of every channel") from None


def _read_uff(path: Path) -> ChannelFRFs:
    from .uff58 import read_records

    records = {r.tag: r for r in read_records(path)[0] if str(r.get("id2", "")).strip() == UFF_ID and r.tag}
    names = [t for t, r in records.items() if r.func_type == 4]
    parts = [(records[c], records.get(f"{c}_std"), records.get(f"{c}_coh")) for c in names]
    if not names or any(p is None for part in parts for p in part):
        raise FormatError(path, "not FRFs of every channel as satmd writes them (each channel's FRF, std and "
                                "coherence records, ID line 2 'satmd-frfs v1')")
    frf, std, coh = ([r.data for r in column] for column in zip(*parts))  # type: ignore[union-attr]
    return ChannelFRFs(parts[0][0].x, tuple(names), np.array(frf), np.real(std), np.real(coh), "m/s^2/N", {},
                       str(path))


def _read_csv(path: Path) -> ChannelFRFs:
    from ._common import read_text, text_lines

    lines = [ln for ln in text_lines(read_text(path)) if ln.strip()]
    if not lines or lines[0] != MAGIC:
        raise FormatError(path, f"line 1 is not {MAGIC!r}")
    notes = {k.strip("# "): v.strip() for k, v in (ln.split(":", 1) for ln in lines[1:] if ln.startswith("#"))}
    body = [ln for ln in lines[1:] if not ln.startswith("#")]
    header = body[0].split(",")
    names = [h[:-3] for h in header[1::4]]
    if header != ["freq_hz"] + [f"{c}_{p}" for c in names for p in ("re", "im", "std", "coh")]:
        raise FormatError(path, f"its header {body[0]!r} is not freq_hz, then <channel>_re, _im, _std, _coh")
    try:
        table = np.array([[float(x) for x in ln.split(",")] for ln in body[1:]], ndmin=2)
    except ValueError as exc:
        raise FormatError(path, f"a value that is not a number ({exc})") from None
    if table.shape[1] != len(header):
        raise FormatError(path, f"rows of {table.shape[1]} values under a header of {len(header)}")
    cols = table[:, 1:].T.reshape(len(names), 4, -1)
    return ChannelFRFs(table[:, 0], tuple(names), cols[:, 0] + 1j * cols[:, 1], cols[:, 2], cols[:, 3],
                       notes.get("units", ""), json.loads(notes.get("estimator", "{}")), str(path))


__all__ = ["ChannelFRFs", "load_channel_frfs", "is_channel_frfs"]
