"""satmd estimate-frf: FRFs (or transmissibilities) with coherence and std from a time recording."""
from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

from ..conventions import DEFAULT_FREE, RECORDING_CHANNELS
from ..errors import SatmdError
from ..io.atomic import all_or_none
from ._common import (add_recording_options, add_rig_options, check_outputs, integer, real, one_line_warnings, parse_band, parse_kv, plot_suffixes,
                      rig_from_args, safe_text)


def register(sub):
    p = sub.add_parser("estimate-frf", help="FRFs with coherence and std from a force/acceleration recording",
                       description="FRFs A1 = acc1/force, A2 = acc2/force with std columns and coherence. By "
                                   "default the local polynomial method on the full record (no window, full "
                                   "resolution, leakage and transient removed, independent points, std from the "
                                   "local residual) over the band the force excites; for a periodic force the mean "
                                   "over steady periods at the excited lines, for impacts H1 over hits (the "
                                   "excitation is detected, or given by --excitation); Welch H1/H2 on request. A "
                                   "recording without force (output-only) gives the transmissibility A2/A1 (Welch).")
    p.add_argument("recordings", nargs="+", metavar="REC",
                   help="time recording (.csv time_s,force,acc1,acc2; .uff; .wav; .npz; .mat); several files of one "
                        "test (hits saved one per file, periodic realisations, repeats at one level) give one FRF: "
                        "H1 over every hit, or the best linear approximation over the realisations")
    p.add_argument("-o", "--out", required=True, metavar="FRF.csv",
                   help="output: FRFs as .csv, .uff, .npz or .mat (coherence kept except in .csv); "
                        "a transmissibility as .csv")
    p.add_argument("--estimator", default=None, choices=("lpm", "H1", "H2"),
                   help="lpm: local polynomial method (default); Welch H1: noise on the responses; Welch H2: "
                        "noise on the force")
    p.add_argument("--width", type=real(0, 1e6, lo_open=True), default=None, metavar="HZ",
                   help="lpm: width of each local window in Hz (default 0.3, narrower for sharper resonances)")
    p.add_argument("--nperseg", type=integer(8), default=None, metavar="N",
                   help="Welch: samples per segment (default: ≈0.5 Hz resolution, at least 16 averages)")
    p.add_argument("--window", default=None, help="Welch: window (any scipy.signal.get_window name; default hann)")
    p.add_argument("--overlap", type=real(0, 1, hi_open=True), default=None, help="Welch: segment overlap fraction (default 0.5)")
    p.add_argument("--band", default=None, metavar="LO:HI", help="keep only LO <= f <= HI Hz")
    p.add_argument("--map", default=None, metavar="force=#1,a1=NODE:DIR,a2=#3",
                   help="which UFF records / WAV channels / .mat or .npz variables (Name or Name[row]) / CSV columns "
                        "are force, a1 and a2 (a3, a4, ... are read too; FRFs are estimated for a1 and a2)")
    p.add_argument("--channels", default=None, metavar="all|acc1,acc3,...",
                   help="a structure's FRFs: each of these response channels over the force (all: every channel "
                        "but the force), each estimated as A1 is, written as one table (.csv), arrays (.npz, "
                        ".mat) or UFF 58 records (.uff)")
    add_recording_options(p)
    p.add_argument("--scale", default=None, metavar="force=K,acc1=K,...",
                   help="calibration of WAV channels: SI units per stored unit")
    p.add_argument("--plot", default=None, metavar="FIG.png", help="plot magnitude, phase and coherence")
    g = p.add_argument_group("model overlay for transmissibility plots")
    add_rig_options(g)
    p.set_defaults(func=run)


def run(args):
    from ..io import WRITERS

    check_outputs([("-o", args.out, tuple(sorted(WRITERS))), ("--plot", args.plot, args.plot and plot_suffixes())],
                  inputs=list(args.recordings))
    with all_or_none():  # the data file and the figure appear together or not at all
        return _run(args)


def _run(args):
    from ..io import FRFData, load_recording, save_frf
    from ..io.recdata import accelerometers
    from ..signal import estimate_frf, save_transmissibility, transmissibility
    from ..signal.estimate import describe_estimate
    from ..signal.several import one_test

    scale = parse_kv(args.scale, "--scale") if args.scale else None
    band = parse_band(args.band)
    welch = {"--nperseg": args.nperseg, "--window": args.window, "--overlap": args.overlap}
    given = [k for k, v in welch.items() if v is not None]
    if args.width is not None and (args.estimator in ("H1", "H2") or given):
        why = f"--estimator {args.estimator}" if args.estimator else ", ".join(given)
        raise SatmdError(f"--width sets the lpm estimator's windows; it does not apply to Welch ({why})")
    if args.estimator == "lpm" and given:
        raise SatmdError(f"{', '.join(given)}: Welch settings, they do not apply to --estimator lpm")
    out = Path(args.out)
    with one_line_warnings("estimate-frf"):
        recs = []
        for path in args.recordings:
            try:
                recs.append(load_recording(path, channel_map=args.map, scale=scale, fs_hz=args.fs))
            except SatmdError as exc:
                raise SatmdError(_as_typed(str(exc))) from None
        rec = recs[0]
        args.recording = args.recordings[0] if len(recs) == 1 else " + ".join(args.recordings)
        options = dict(nperseg=args.nperseg, window=args.window, overlap=args.overlap, band_hz=band)
        if len(recs) > 1 and not all(r.has_force for r in recs):
            lacking = next(p for p, r in zip(args.recordings, recs) if not r.has_force)
            raise SatmdError(f"{safe_text(lacking)}: no force channel; several files give one FRF of one test "
                             "(a transmissibility is estimated from one output-only file)")
        if args.channels is not None:
            return _every_channel(args, recs, out)
        others = [n for n in accelerometers(rec.channels) if n not in RECORDING_CHANNELS]
        if others:  # read (satmd info lists them), but the rig's FRFs are A1 and A2
            print(f"satmd estimate-frf: note: {', '.join(others)} not estimated: the FRFs are A1 = acc1/force and "
                  f"A2 = acc2/force; --channels all estimates every channel's", file=sys.stderr)
        if rec.has_force:
            overlay = [f"--{n}" for n in DEFAULT_FREE if getattr(args, n, None) is not None]
            if overlay:
                raise SatmdError(f"{', '.join(overlay)}: the model overlay applies to the transmissibility of an "
                                 f"output-only recording; {safe_text(args.recording)} has a force")
            try:
                settings = dict(estimator=args.estimator, width_hz=args.width, excitation=args.excitation,
                                period_s=args.period_s, **options)
                data = estimate_frf(rec, **settings) if len(recs) == 1 else one_test(recs, **settings)
            except SatmdError as exc:
                text = _as_typed(str(exc))
                where = safe_text(args.recording)
                raise SatmdError(text if text.startswith(where) else f"{where}: {text}") from None
            save_frf(data, out)
            kind = f"FRFs {', '.join(data.channels)}"
            freq, coh = data.freq_hz, data.coherence
            curves = {ch: (data[ch], data.std[ch], None) for ch in data.channels}
        else:
            if not {"acc1", "acc2"} <= set(rec.channels):
                raise SatmdError(f"{args.recording}: no force channel, and not both acc1 and acc2 for a "
                                 f"transmissibility (channels: {', '.join(rec.channels)}); choose them with "
                                 f"--map a1=#N,a2=#M")
            if out.suffix.lower() != ".csv":
                raise SatmdError(f"{out}: a transmissibility is written as .csv")
            if args.width is not None:
                raise SatmdError(f"--width: {safe_text(args.recording)} has no force channel; its transmissibility is "
                                 "estimated by Welch, which has no lpm windows")
            if args.estimator == "lpm":
                raise SatmdError(f"{args.recording}: an output-only recording gives a transmissibility, "
                                 f"estimated by Welch H1/H2, not lpm")
            t = transmissibility(rec, estimator=args.estimator or "H1",
                                 **{k: v for k, v in options.items() if v is not None})
            save_transmissibility(t, out)
            kind = "transmissibility A2/A1 (output-only recording)"
            freq, coh = t.freq_hz, {"T": t.coherence}
            curves = {"T": (t.value, t.std, t.model(rig_from_args(args)))}
            data = t
    m = data.meta
    if isinstance(data, FRFData):
        how = describe_estimate(data)
        for finding in data.estimator.get("measurement", []):
            print(f"satmd estimate-frf: measurement: {finding['explanation']}; remedy: {finding['remedy']}",
                  file=sys.stderr)
    else:
        how = f"Welch {m['estimator']}, nperseg={m['nperseg']} ({m['resolution_hz']} Hz), {m['segments']} averages"
    median = float(np.median(np.concatenate(list(coh.values()))))
    if isinstance(data, FRFData):
        how += _several(data.estimator, args.recordings)
    print(f"wrote {safe_text(out)}: {kind}, {len(freq)} points {freq[0]:.6g}..{freq[-1]:.6g} Hz, {how}, "
          f"median coherence {median:.3f}")
    low = {name: float(np.median(g)) for name, g in coh.items() if np.median(g) < LOW_COHERENCE}
    if low:
        print(f"satmd estimate-frf: warning: low coherence ({', '.join(f'{n} {g:.2f}' for n, g in low.items())}, "
              f"median over the band): the responses are barely related to "
              f"{'the force' if isinstance(data, FRFData) else 'each other'}; check the channels (--map), the "
              "sensors and the excitation before trusting these FRFs", file=sys.stderr)
    if args.plot:
        plot_estimate(freq, curves, coh, args.plot, title=f"{Path(args.recording).name}: {kind}")
        print(f"plot: {args.plot}")
    return 0


def _every_channel(args, recs, out: Path) -> int:
    """``--channels``: the FRF of each response channel over the force, written as `ChannelFRFs`."""
    from ..signal import estimate_frfs
    from ..signal.estimate import describe_estimate

    where = safe_text(args.recording)
    if not recs[0].has_force:
        raise SatmdError(f"{where}: no force channel (channels: {', '.join(recs[0].channels)}); --channels gives "
                         "each response over the force")
    overlay = [f"--{n}" for n in DEFAULT_FREE if getattr(args, n, None) is not None]
    if overlay:
        raise SatmdError(f"{', '.join(overlay)}: the model overlay applies to a rig's transmissibility, not to "
                         "--channels")
    wanted = None if args.channels.strip() == "all" else [c.strip() for c in args.channels.split(",") if c.strip()]
    try:
        frfs = estimate_frfs(recs, wanted, estimator=args.estimator, width_hz=args.width, excitation=args.excitation,
                             period_s=args.period_s, nperseg=args.nperseg, window=args.window,
                             overlap=args.overlap, band_hz=parse_band(args.band))
    except SatmdError as exc:
        text = _as_typed(str(exc))
        raise SatmdError(text if text.startswith(where) else f"{where}: {text}") from None
    frfs.save(out)
    freq, coh = frfs.freq_hz, dict(zip(frfs.channels, frfs.coherence))
    for finding in frfs.estimator.get("measurement", []):
        print(f"satmd estimate-frf: measurement: {finding['explanation']}; remedy: {finding['remedy']}",
              file=sys.stderr)
    kind = f"FRFs of {len(frfs.channels)} channels ({', '.join(frfs.channels)}) over the force"
    how = describe_estimate(frfs.estimator) + _several(frfs.estimator, args.recordings)
    print(f"wrote {safe_text(out)}: {kind}, {freq.size} points {freq[0]:.6g}..{freq[-1]:.6g} Hz, {how}, "
          f"median coherence {float(np.median(frfs.coherence)):.3f}")
    low = {n: float(np.median(g)) for n, g in coh.items() if np.median(g) < LOW_COHERENCE}
    if low:
        print(f"satmd estimate-frf: warning: low coherence ({', '.join(f'{n} {g:.2f}' for n, g in low.items())}, "
              "median over the band): these responses are barely related to the force; check the channels "
              "(--map), the sensors and the excitation before trusting their FRFs", file=sys.stderr)
    if args.plot:
        title = f"{Path(args.recording).name}: {kind}"
        if len(frfs.channels) > SIDE_BY_SIDE:
            plot_overlaid(frfs, args.plot, title)
        else:
            curves = {c: (h, s, None) for c, h, s in zip(frfs.channels, frfs.frf, frfs.std)}
            plot_estimate(freq, curves, coh, args.plot, title=title)
        print(f"plot: {args.plot}")
    return 0


SIDE_BY_SIDE = 4  # FRFs plotted a column each; more are overlaid (a GVT's eight would make a figure 35 inches wide)


def plot_overlaid(frfs, path, title=""):
    """Every channel's |H|, phase and coherence overlaid, one colour a channel."""
    from ..plots import pyplot, save

    plt = pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(9, 8.5), sharex=True)
    for k, (name, h, g) in enumerate(zip(frfs.channels, frfs.frf, frfs.coherence)):
        colour = f"C{k % 10}"
        axes[0].semilogy(frfs.freq_hz, np.abs(h), color=colour, lw=0.8, label=name)
        axes[1].plot(frfs.freq_hz, np.degrees(np.angle(h)), color=colour, lw=0.6)
        axes[2].plot(frfs.freq_hz, g, color=colour, lw=0.6)
    axes[0].set_ylabel(f"|H| [{frfs.units}]")
    axes[0].legend(fontsize=8, ncol=min(len(frfs.channels), 8))
    axes[1].set_ylabel("phase [deg]")
    axes[2].set_ylabel("coherence γ²")
    axes[2].set_ylim(0, 1.05)
    axes[2].set_xlabel("frequency [Hz]")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save(fig, path)


def _several(estimator: dict, recordings) -> str:
    """What an estimate from several files of one test combined ("" for one file)."""
    if len(recordings) < 2:
        return ""
    if estimator.get("realisations"):
        return f", the best linear approximation over {estimator['realisations']} realisations (files)"
    return f", one FRF from {len(recordings)} files of one test"


def _as_typed(message: str) -> str:
    """A library message about a Welch setting, naming the option as typed (``nperseg`` -> ``--nperseg``)."""
    from ._recording import as_typed

    for name in ("nperseg", "window", "overlap"):
        message = re.sub(rf"(^|: ){name}\b", rf"\1--{name}", message, count=1)
    return as_typed(message)


LOW_COHERENCE = 0.5  # a median ordinary coherence below this: mostly noise, or the wrong channels

LABELS = {"a1": "A1 = acc1/force", "a2": "A2 = acc2/force", "T": "T = A2/A1"}


def plot_estimate(freq, curves, coherence, path, title=""):
    """|H| with ±2σ, phase and coherence for each curve; a model overlay where given."""
    from ..plots import pyplot, save

    plt = pyplot()
    names = list(curves)
    fig, axes = plt.subplots(3, len(names), figsize=(4.4 * len(names), 7.5), squeeze=False, sharex=True)
    for j, name in enumerate(names):
        h, std, model = curves[name]
        mag = np.abs(h)
        ax = axes[0, j]
        ax.semilogy(freq, mag, color="k", lw=0.8, label="estimate")
        ax.fill_between(freq, np.maximum(mag - 2 * std, mag * 1e-3), mag + 2 * std, color="0.6", alpha=0.4, lw=0,
                        label="±2σ")
        if model is not None:
            ax.semilogy(freq, np.abs(model), color="tab:blue", lw=1.0, label="model (nominal rig)")
            axes[1, j].plot(freq, np.degrees(np.angle(model)), color="tab:blue", lw=1.0)
        ax.set_title(LABELS.get(name, name))
        ax.set_ylabel("magnitude")
        ax.legend(fontsize=8)
        axes[1, j].plot(freq, np.degrees(np.angle(h)), color="k", lw=0.8)
        axes[1, j].set_ylabel("phase [deg]")
        axes[2, j].plot(freq, coherence[name], color="tab:green", lw=0.8)
        axes[2, j].set_ylim(0, 1.05)
        axes[2, j].set_ylabel("coherence γ²")
        axes[2, j].set_xlabel("frequency [Hz]")
        for ax in axes[:, j]:
            ax.grid(True, which="both", alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save(fig, path)
