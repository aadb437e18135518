"""satmd info: what a data file holds (records, channels, sample rate, length, units)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..conventions import RECORDING_CHANNELS, TINY
from ..errors import FormatError, SatmdError
from ._common import one_line_warnings, safe_text

_FORMATS = {".uff": "universal file (UFF)", ".unv": "universal file (UFF)", ".csv": "CSV", ".wav": "WAV audio",
            ".npz": "NumPy .npz archive", ".mat": "MATLAB file", ".txt": "text"}


def register(sub):
    p = sub.add_parser("info", help="describe a data file: records, channels, sample rate, length, units",
                       description="Describe what FILE holds: UFF datasets, channels, sample rate, length, units, "
                                   "and whether satmd can use it as FRFs or as a time recording.")
    p.add_argument("file", metavar="FILE", help="any file satmd reads (.csv .uff .unv .wav .mat .npz .txt)")
    p.add_argument("--map", default=None, metavar="a1=NODE:DIR,...", help="channel mapping, as for the other commands")
    p.add_argument("--freq-axis", default=None, metavar="START:STEP", help="frequency axis of a .txt file")
    p.set_defaults(func=run)


def run(args):
    path = Path(args.file)
    if not path.exists():
        raise FormatError(path, "no such file")
    if path.is_dir():
        raise FormatError(path, "is a directory, not a file")
    with one_line_warnings("info"):
        lines = describe(path, channel_map=args.map, freq_axis=args.freq_axis)
    print("\n".join(lines))
    return 0


def describe(path, channel_map=None, freq_axis=None) -> list[str]:
    """Lines of text describing the file; raises SatmdError when nothing in it is readable."""
    from ..io import is_recording, load_frf, load_recording
    from ..io.channelfrfs import is_channel_frfs

    path = Path(path)
    suffix = path.suffix.lower()
    lines = [f"{safe_text(path)}: {_FORMATS.get(suffix, suffix or 'no suffix')}, {_size(path.stat().st_size)}"]
    if suffix in (".uff", ".unv"):
        return lines + _uff(path, channel_map)
    if suffix == ".txt":
        return lines + _txt(path, freq_axis)
    if suffix in (".npz", ".mat"):
        from ..io.matfile import load_variables

        variables = load_variables(path)
        lines.append("variables: " + (", ".join(f"{k} {tuple(v.shape)} {v.dtype}" for k, v in variables.items())
                                      or "none"))
    if suffix not in _FORMATS:
        raise FormatError(path, f"unknown file type {suffix!r} (known: {', '.join(sorted(_FORMATS))})")
    if suffix in (".csv", ".npz", ".mat") and is_channel_frfs(path):
        return lines + channel_frf_lines(path)
    if is_recording(path):
        return lines + recording_lines(load_recording(path, channel_map=channel_map), path, channel_map)
    return lines + frf_lines(load_frf(path, **({"channel_map": channel_map} if channel_map else {})))


def channel_frf_lines(path) -> list[str]:
    """FRFs of every channel: their channels, grid, how they were estimated and their median coherence."""
    from ..io import load_channel_frfs
    from ..signal.estimate import describe_estimate

    frfs = load_channel_frfs(path)
    f = frfs.freq_hz
    how = describe_estimate(frfs.estimator)
    return [f"FRFs of every channel: {len(frfs.channels)} ({', '.join(frfs.channels)}) over the force "
            f"[{frfs.units}], {f.size} points {f[0]:.6g}..{f[-1]:.6g} Hz",
            *([f"estimated as: {how}"] if how else []),
            "median coherence: " + ", ".join(f"{c} {np.median(g):.3f}" for c, g in zip(frfs.channels, frfs.coherence))]


def _size(n: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return ""


def _uff(path, channel_map) -> list[str]:
    from ..io import load_frf, load_recording
    from ..io.uff import FUNCTION_TYPES, dof_label, read_records

    records, others = read_records(path)
    n_sets = len(records) + len(others)
    lines = [f"{n_sets} dataset(s): {len(records)} of type 58 (function at nodal DOF)"
             + (f"; other types ignored: {', '.join(str(t) for _, t in others)}" if others else "")]
    for r in records:
        ref = dof_label(*r.ref) if r.ref != (0, 0) else "-"
        x = r.x
        if r.func_type == 1:
            fs = 1.0 / (x[1] - x[0]) if x.size > 1 and x[1] > x[0] else float("nan")
            axis = f"{x.size} samples, {x[0]:g}..{x[-1] + (x[1] - x[0] if x.size > 1 else 0):g} s at {fs:.6g} Hz"
        else:
            axis = f"{x.size} points, {x[0]:g}..{x[-1]:g} {r.units('abscissa') or 'Hz'}"
        units = r.units("ordinate") + (f" / {r.units('orddenom')}" if r.units("orddenom") else "")
        id1 = str(r.get("id1", "")).strip()
        function = str(FUNCTION_TYPES.get(r.func_type, r.func_type))
        lines.append(f"  #{r.index:<3d} {'58b' if r.binary else '58':<4s}{function:<14s}"
                     f" rsp {r.response:<14s} ref {ref:<7s} {axis}; "
                     f"{r.quantity() or 'unknown quantity'} [{units or 'no units'}]"
                     + (f"; '{id1}'" if id1 and id1.upper() != "NONE" else ""))
    dofs: dict = {}
    for r in records:
        dofs.setdefault((r.func_type, r.rsp), []).append(f"#{r.index}")
    for (ft, dof), where in dofs.items():
        if len(where) > 1:
            lines.append(f"note: {', '.join(where)} share response {dof_label(*dof)} "
                         f"({FUNCTION_TYPES.get(ft, ft)}); choose one with --map ...=#N")
    types = {r.func_type for r in records}
    if 1 in types:
        try:
            lines += recording_lines(load_recording(path, channel_map=channel_map), path, channel_map)
        except SatmdError as exc:
            lines.append(f"time records: not usable as a recording: {_tail(exc)}")
    if 4 in types:
        try:
            lines += frf_lines(load_frf(path, **({"channel_map": channel_map} if channel_map else {})))
        except SatmdError as exc:
            lines.append(f"FRF records: {_tail(exc)}")
    if not types & {1, 4}:
        lines.append("no time records (function type 1) and no FRFs (function type 4): nothing satmd uses")
    return lines


def _tail(exc) -> str:
    """The message without the leading file name (the header line names the file)."""
    from ._common import with_flags

    text = with_flags(str(exc))
    return text.split(": ", 1)[1] if ": " in text else text


def _txt(path, freq_axis) -> list[str]:
    from ..io import load_frf
    from ..io.txtfrf import read_values

    values = read_values(path)
    mag = np.abs(values)
    lines = [f"{values.size} complex values, one per line; |value| {mag.min():.3g}..{mag.max():.3g}"]
    if freq_axis is None:
        lines.append("no frequency axis in the file: read it as FRFs with --freq-axis START:STEP (Hz)")
        return lines
    return lines + frf_lines(load_frf(path, freq_axis=freq_axis))


def recording_lines(rec, path, channel_map=None) -> list[str]:
    """Lines on a time recording: every channel (unit, rms, peak, where it came from) and what satmd can do with it."""
    from ..io import clipped_channels
    from ..io.recdata import accelerometers

    cmd = f"satmd estimate-frf {path}" + (f" --map {channel_map}" if channel_map else "")
    lines = [f"time recording: {len(rec.channels)} channel(s), {rec.fs_hz:.6g} Hz, {rec.n_samples} samples "
             f"({rec.duration_s:.6g} s)"]
    parts = rec.realisations()
    if len(parts) > 1:
        lines.append(f"  {len(parts)} realisations of {parts[0].n_samples} samples, one after another: their FRF "
                     "is the best linear approximation over them (each periodic), each is simulated from its start")
    width = max(len(n) for n in rec.channels)
    for name, v in rec.channels.items():
        unit = rec.units.get(name, "") or "?"
        lines.append(f"  {name:<{width}s}  [{unit}]  rms {np.sqrt(np.mean(v * v)):.4g}  peak {np.max(np.abs(v)):.4g}"
                     + (f"  ({rec.labels[name]})" if name in rec.labels else ""))
    for name, count in clipped_channels(rec).items():
        lines.append(f"  clipped? {name}: {count} samples at its extremes")
    others = [n for n in accelerometers(rec.channels) if n not in RECORDING_CHANNELS]
    if others:  # read and listed above; the rig's FRFs are A1 and A2 only
        lines.append(f"{', '.join(others)}: read; a rig's FRFs are acc1's and acc2's, a structure's every "
                     f"channel's (`{cmd} --channels all -o FRFs.csv`)")
    if rec.has_force and ("acc1" in rec.channels or "acc2" in rec.channels):
        lines.append(f"force and responses present: estimate FRFs with `{cmd} -o FRF.csv`")
    elif "acc1" in rec.channels and "acc2" in rec.channels:
        lines.append(f"output-only (no force channel): transmissibility A2/A1 with "
                     f"`{cmd} -o T.csv`")
    else:
        lines.append("channels are not assigned to force/acc1/acc2: use --map force=#N,a1=#M,a2=#K "
                     "(or NODE:DIR) to choose them")
    return lines


def frf_lines(data) -> list[str]:
    from ..io import UNITS

    f = data.freq_hz
    steps = np.diff(f)
    grid = (f"uniform step {steps[0]:.6g} Hz" if f.size > 1 and np.allclose(steps, steps[0], rtol=1e-6)
            else "non-uniform grid" if f.size > 1 else "one point")
    lines = [f"FRFs: {f.size} points, {f[0]:.6g}..{f[-1]:.6g} Hz ({grid}), channels {', '.join(data.channels)}"]
    for ch, v in data.channels.items():
        mag = np.abs(v)
        text = (f"  {ch}  [{UNITS.get(ch, '')}]  |H| {mag.min():.3g}..{mag.max():.3g} "
                f"(peak at {f[np.argmax(mag)]:.5g} Hz)")
        if ch in data.std:
            text += f"; std median {100 * np.median(data.std[ch] / np.maximum(mag, TINY)):.3g} % of |H|"
        if ch in data.coherence:
            g = data.coherence[ch]
            text += f"; coherence min {g.min():.3f}, median {np.median(g):.3f}"
        lines.append(text)
    lines.append("noise: std given (fits weight by it)" if data.has_std else
                 "noise: no std (fits estimate the noise level)")
    return lines
