"""The F-16 ground vibration test at four levels: how each resonance moves with level (issue 35).

    python examples/f16_levels.py [--data DIR] [--out f16_levels.png]

Reads the four full-multisine levels of the F-16 benchmark (Noël & Schoukens 2017, nonlinearbenchmark.org:
cite it when you report results on it; ``../shared/data/real/f16`` unless ``--data``), with the force at the
shaker and the two accelerometers at the nonlinear payload interface (wing and payload side). satmd detects
the periodic multisine and estimates the FRF at the excited lines; `satmd.discover` judges the four levels
together. The aircraft is not a SATMD rig, so no SATMD element is named: the finding is a
``joint`` between the two sensors (SPEC §11), told per resonance (SPEC §9). The script prints, per resonance that moves, its
frequency and damping ratio at every level with 95 % intervals and the two trends, and draws |A1| and |A2|
per level with those resonances marked, and how they move with the force.

Exits 0 with a note when the data are not there. ``benchmarks/f16_levels.py`` records the same figures
for the README.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

import satmd
from satmd.io import load_recording
from satmd.signal import detect_excitation, estimate_frf
from satmd.io.shared import shared_dir

DATA = (shared_dir() or Path("../shared")) / "data" / "real" / "f16"
LEVELS = (1, 3, 5, 7)
CHANNELS = "force=Force,a1=Acceleration[2],a2=Acceleration[3]"


def read_levels(data: Path) -> list:
    """The recordings of levels 1, 3, 5, 7 (the file's ``Voltage`` is not used)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        return [load_recording(data / f"F16Data_FullMSine_Level{i}.mat", channel_map=CHANNELS) for i in LEVELS]


def table(levels, modes) -> str:
    """Per resonance: frequency and damping ratio at every level with 95 % intervals, and the trends."""
    lines = [f"{'resonance':>10}  {'force':>10}  {'f [Hz] (95 % interval)':<26}  zeta [%] (95 % interval)"]
    for m in modes:
        for i, lev in enumerate(levels):
            (flo, fhi), (zlo, zhi) = m["f_ci95"][i], m["zeta_ci95"][i]
            head = f"{m['f_hz'][0]:.3g} Hz" if i == 0 else ""
            f_cell = f"{m['f_hz'][i]:.3f} ({flo:.3f}-{fhi:.3f})"
            lines.append(f"{head:>10}  {lev:5.1f} N RMS  {f_cell:<26}  "
                         f"{100 * m['zeta'][i]:.2f} ({100 * zlo:.2f}-{100 * zhi:.2f})")
        lo, hi = int(np.argmin(levels)), int(np.argmax(levels))
        df = 100 * (m["f_hz"][hi] / m["f_hz"][lo] - 1)
        dz = m["zeta"][hi] / m["zeta"][lo]
        lines.append(f"{'':>10}  trend {m['trend']} ({df:+.1f} %), damping trend {m['damping_trend']} (x{dz:.2f})")
    return "\n".join(lines)


def figure(levels, frfs, modes, out: Path) -> None:
    """|A1| and |A2| per level with the moving resonances marked; frequency and damping against the force."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(levels)))
    fig = plt.figure(figsize=(11, 8.5))
    grid = fig.add_gridspec(3, 2, height_ratios=(1.0, 1.0, 0.8))
    for row, ch in enumerate(("a1", "a2")):
        ax = fig.add_subplot(grid[row, :])
        for lev, d, c in zip(levels, frfs, colours):
            mag = np.abs(d.channels[ch])
            ax.semilogy(d.freq_hz, mag, color=c, lw=0.9, label=f"{lev:.1f} N RMS")
            for m in modes:
                f = m["f_hz"][levels.index(lev)]
                ax.plot(f, np.interp(f, d.freq_hz, mag), "v", color=c, ms=6, mec="k", mew=0.4)
        for m in modes:
            ax.axvspan(min(m["f_hz"]), max(m["f_hz"]), color="0.85", zorder=0)
        ax.set_xlim(frfs[0].freq_hz[0], frfs[0].freq_hz[-1])
        ax.set_ylabel(f"|{ch.upper()}| [m/s² / N]")
        ax.set_title(f"{ch}: {'wing, next to the interface' if ch == 'a1' else 'payload, next to the interface'}",
                     fontsize=10, loc="left")
        if row == 0:
            ax.legend(fontsize=8, ncol=len(levels), loc="upper right")
        else:
            ax.set_xlabel("frequency [Hz]  (▼ the fitted resonance frequency at each level; grey: where it moves)")
    ax_f, ax_z = fig.add_subplot(grid[2, 0]), fig.add_subplot(grid[2, 1])
    for m in modes:
        f = np.asarray(m["f_hz"])
        fe = np.abs(np.asarray(m["f_ci95"]) - f[:, None]).T / f[0] * 100
        ze = np.abs(np.asarray(m["zeta_ci95"]) - np.asarray(m["zeta"])[:, None]).T * 100
        label = f"{f[0]:.2f} Hz"
        ax_f.errorbar(levels, 100 * (f / f[0] - 1), yerr=fe, marker="o", ms=3, capsize=2, label=label)
        ax_z.errorbar(levels, 100 * np.asarray(m["zeta"]), yerr=ze, marker="o", ms=3, capsize=2, label=label)
    ax_f.set_ylabel("frequency change [%]")
    ax_z.set_ylabel("damping ratio [%]")
    for ax in (ax_f, ax_z):
        ax.set_xlabel("force [N RMS]")
        ax.grid(alpha=0.3)
    ax_z.legend(fontsize=7, ncol=2)
    fig.suptitle("F-16 ground vibration test (Noël & Schoukens 2017): resonances against level (95 % intervals)",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=DATA, help="folder of F16Data_FullMSine_Level{1,3,5,7}.mat")
    ap.add_argument("--out", type=Path, default=Path("f16_levels.png"), help="where to save the figure")
    args = ap.parse_args(argv)
    if not all((args.data / f"F16Data_FullMSine_Level{i}.mat").is_file() for i in LEVELS):
        print(f"the F-16 files are not in {args.data} (../shared is absent): nothing to do")
        return 0
    recs = read_levels(args.data)
    rep = satmd.discover(recs)
    nl = rep.nonlinear
    levels = [float(x) for x in nl.levels]
    exc = detect_excitation(recs[0])
    print(f"F-16, levels {', '.join(map(str, LEVELS))}: force {', '.join(f'{x:.1f}' for x in levels)} N RMS; "
          f"excitation detected: {exc.kind}, {exc.periods} periods of {exc.period_s:g} s, "
          f"{len(exc.lines)} excited lines")
    print(f"SATMD model adequate: {rep.model_adequate}; nonlinear: {nl.detected}; "
          f"findings: {', '.join(f['name'] for f in nl.findings) or 'none'}")
    finding = next((f for f in nl.findings if f.get("modes") is not None), None)
    modes = finding["modes"] if finding else []
    if modes:
        print(table(levels, modes))
        print(finding["explanation"])
    else:
        print("no resonance moves beyond its uncertainty")
    frfs = [estimate_frf(r) for r in recs]
    figure(levels, frfs, modes, args.out)
    print(f"figure: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
