"""satmd modes: a structure's modes and their shapes over its sensors, from a recording or its FRFs."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ._recording import add_recording_options


def register(sub):
    p = sub.add_parser("modes", help="a structure's modes: frequencies, damping and shapes over its sensors",
                       description="The modes of a structure's FRFs, every sensor fitted with one set of poles "
                                   "(satmd.modal.survey): natural frequencies and damping ratios with 95 %% "
                                   "intervals, and each mode's shape over the sensors, mass-normalised where a "
                                   "sensor is at the force's point (named, or found from the residues' signs), "
                                   "with its complexity. From a time recording (every channel's FRF estimated "
                                   "first, as estimate-frf --channels all does), FRFs of every channel "
                                   "(estimate-frf --channels), or a rig's FRF file.")
    p.add_argument("inputs", nargs="+", metavar="FILE",
                   help="a time recording (several files of one test give one FRF), FRFs of every channel, or "
                        "FRF files of one structure over one grid (a roving test: one file a point, each named by "
                        "its file)")
    p.add_argument("--map", default=None, metavar="MAP",
                   help="recordings: which variables or columns are the force and the sensors, e.g. "
                        "force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]")
    add_recording_options(p)
    p.add_argument("--freq-axis", default=None, metavar="START:STEP",
                   help="frequency axis in Hz of .txt FRF files (one complex value per line)")
    p.add_argument("--band", default=None, metavar="LO:HI", help="fit the modes between LO and HI Hz")
    p.add_argument("--driving-point", default=None, metavar="NAME",
                   help="the sensor at the force's point (default: found, or none); taken at its word, the modes "
                        "where its modal constants have the other sign said")
    p.add_argument("--json", action="store_true", help="print the modes as JSON")
    p.add_argument("--plot", default=None, metavar="FIG.png", help="the FRFs with the fit, and the modes' shapes")
    p.set_defaults(func=run)


def run(args):
    from ..errors import SatmdError
    from ..modal import survey
    from ._common import check_outputs, dumps_json, one_line_warnings, parse_band, plot_suffixes

    if args.plot:
        check_outputs([("--plot", args.plot, plot_suffixes())], inputs=list(args.inputs))
    with one_line_warnings("modes"):
        freq, frf, std, where = _frfs(args)
        lo, hi = parse_band(args.band)
        band = None if lo is None and hi is None else (lo if lo is not None else freq[0], hi or freq[-1])
        try:
            found = survey(freq, frf, std, band, driving_point=args.driving_point)
        except SatmdError as err:
            raise SatmdError(f"{where}: {err}") from None
    if args.json:
        print(dumps_json({"source": where, **found.to_dict()}, "modes", indent=2))
    else:
        print(f"{where}:")
        print(found.report())
    if args.plot:
        plot_survey(found, freq, frf, args.plot, title=where)
        print(f"plot: {args.plot}", file=sys.stderr if args.json else sys.stdout)
    return 0


def _frfs(args):
    """(freq, {channel: FRF}, {channel: std} or None, where) from the inputs."""
    from ..conventions import ACCEL_CHANNELS
    from ..errors import SatmdError
    from ..io import is_recording, load_frf
    from ..io.channelfrfs import is_channel_frfs, load_channel_frfs
    from ..signal import estimate_frfs
    from ._recording import load_recording_args

    paths = list(args.inputs)
    where = " + ".join(paths)
    first = paths[0]
    if is_recording(first):
        recordings = [load_recording_args(args, p) for p in paths]
        try:
            frfs = estimate_frfs(recordings)
        except SatmdError as err:
            raise SatmdError(str(err) if first in str(err) else f"{where}: {err}") from None
        return (*_arrays(frfs), where)
    if args.map and is_channel_frfs(first):
        raise SatmdError(f"--map: {first} holds FRFs of named channels; it applies to recordings")
    if len(paths) == 1 and is_channel_frfs(first):
        frfs = load_channel_frfs(first)
        return (*_arrays(frfs), where)
    options = {k: v for k, v in (("channel_map", args.map), ("freq_axis", args.freq_axis)) if v}
    freq, frf, std = None, {}, {}
    for path in paths:
        if is_recording(path) or is_channel_frfs(path):
            raise SatmdError(f"{path}: FRF files of one structure are read together, not with recordings or FRFs "
                             "of every channel")
        data = load_frf(path, **options)
        accelerations = {c: v for c, v in data.channels.items() if c in ACCEL_CHANNELS}
        if not accelerations:
            raise SatmdError(f"{path}: no acceleration FRF (a1, a2): the modes' shapes are read from accelerances")
        if freq is None:
            freq = data.freq_hz
        elif data.freq_hz.shape != freq.shape or not np.allclose(data.freq_hz, freq, rtol=1e-9, atol=0):
            raise SatmdError(f"{path}: another frequency grid than {first}'s ({data.freq_hz.size} points "
                             f"{data.freq_hz[0]:g}..{data.freq_hz[-1]:g} Hz against {freq.size}, "
                             f"{freq[0]:g}..{freq[-1]:g})")
        for c, v in accelerations.items():  # one file: its channels; several: each channel named by its file
            name = c if len(paths) == 1 else (Path(path).stem if len(accelerations) == 1 else f"{Path(path).stem}:{c}")
            if name in frf:
                raise SatmdError(f"{path}: a second FRF named {name!r} (files of one name in two folders?)")
            frf[name] = v
            if c in data.std:
                std[name] = data.std[c]
    return freq, frf, _weights(std) if len(std) == len(frf) else None, where


def _arrays(frfs) -> tuple:
    """(freq, {channel: FRF}, {channel: std} or None) of `ChannelFRFs`."""
    return frfs.freq_hz, dict(zip(frfs.channels, frfs.frf)), _weights(dict(zip(frfs.channels, frfs.std)))


def _weights(std: dict):
    """``std`` ({channel: std}), or None where some point has none (the fit then weighs the channels by their RMS)."""
    return std if all(np.all(s > 0) for s in std.values()) else None


def plot_survey(found, freq, frf, path, title=""):
    """Each sensor's |FRF| with the fitted modes' model over it, and each mode's shape over the sensors."""
    from ..plots import pyplot, save

    plt = pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 7.5))
    model = found.fit.predict(freq) if found.fit.modes else {}
    for k, (name, h) in enumerate(frf.items()):
        colour = f"C{k % 10}"
        top.semilogy(freq, np.abs(h), color=colour, lw=0.8, label=name)
        if name in model:
            top.semilogy(freq, np.abs(model[name]), color=colour, lw=1.6, ls="--", alpha=0.7)
    for m in found.fit.modes:
        top.axvline(m.f_hz, color="0.7", lw=0.6)
    top.set_xlabel("frequency [Hz]")
    top.set_ylabel("|FRF| (dashed: the modes' fit)")
    top.legend(fontsize=8, ncol=min(len(frf), 6))
    x = np.arange(len(found.channels))
    for m, shape in zip(found.fit.modes, found.shapes):
        bottom.plot(x, shape, marker="o", label=f"{m.f_hz:.4g} Hz, ζ {100 * m.zeta:.2g} %")
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.set_xticks(x, found.channels)
    bottom.set_ylabel("shape (1/√kg)" if found.normalised == "mass" else "shape (1 at its largest sensor)")
    bottom.legend(fontsize=8, ncol=2)
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save(fig, path)
