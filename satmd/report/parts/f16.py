"""Report section: a real structure at four levels, resonance by resonance (the F-16 ground vibration test)."""
from __future__ import annotations

from pathlib import Path

ORDER = 58
TITLE = "A real structure at several levels: the F-16 ground vibration test"

LEVELS = (1, 3, 5, 7)
CHANNELS = "force=Force,a1=Acceleration[2],a2=Acceleration[3]"


def data_dir() -> Path | None:
    """``shared/data/real/f16`` (`satmd.io.shared`) when its level-1 file is there, else None."""
    from ...io.shared import real_data

    return real_data("f16") if real_data("f16", "F16Data_FullMSine_Level1.mat") else None


SKIPPED = "Skipped: the F-16 files (`shared/data/real/f16/`, nonlinearbenchmark.org) are not beside this checkout."


def recordings(levels, channel_map) -> dict | None:
    """{level: Recording} of the F-16's multisine levels read with ``channel_map``; None when the files are absent."""
    import warnings

    from ...io import load_recording

    folder = data_dir()
    if folder is None:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the files' Voltage variable is not used
        return {i: load_recording(folder / f"F16Data_FullMSine_Level{i}.mat", channel_map=channel_map) for i in levels}


def _figure(levels, recordings, datas):
    import numpy as np

    from ...conventions import ACCEL_CHANNELS
    from ...plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharex=True)
    for lev, d in zip(levels, datas):
        for ax, ch in zip(axes, ACCEL_CHANNELS):
            ax.semilogy(d.freq_hz, np.abs(d[ch]), lw=0.9, label=f"{lev:.1f} N RMS")
    for ax, where in zip(axes, ("wing, next to the payload's mounting", "payload")):
        ax.set_xlabel("frequency [Hz]")
        ax.set_title(f"|A| {where}", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("|A| [m/s²/N]")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    return fig


def build(ctx) -> str:
    from ...discovery import discover
    from ...signal import estimate_frf

    read = recordings(LEVELS, CHANNELS)
    if read is None:
        return SKIPPED
    recs = list(read.values())
    rep = discover(recs, fit_joint=not ctx.quick)  # quick: the joint placed and named, its model the next section's
    datas = [estimate_frf(r) for r in recs]
    levels = list(rep.nonlinear.levels) if rep.nonlinear is not None else [0.0] * len(recs)
    finding: dict = next((f for f in (rep.nonlinear.findings if rep.nonlinear is not None else [])), {})
    modes = finding.get("modes", [])
    rows = []
    for m in modes:
        cells = " | ".join(f"{f:.3f} ({lo:.3f}–{hi:.3f}); {100 * z:.2f} % ({100 * zl:.2f}–{100 * zh:.2f})"
                           for f, (lo, hi), z, (zl, zh) in zip(m["f_hz"], m["f_ci95"], m["zeta"], m["zeta_ci95"]))
        rows.append(f"| {m['f_hz'][0]:.2f} Hz | {cells} | {m['trend']} | {m['damping_trend']} |")
    ctx.results["f16"] = {"levels_n_rms": levels, "model_adequate": bool(rep.model_adequate),
                          "elements_named": [f.get("name") for f in (rep.nonlinear.findings if rep.nonlinear
                                                                     else [])],
                          "modes": modes}
    said = finding.get("explanation", "")
    said = (said[:1].upper() + said[1:]).rstrip(".") + "." if said else ""
    head = " | ".join(f"{lev:.1f} N RMS: f [Hz]; ζ" for lev in levels)
    return "\n".join([
        "Four levels of the F-16 benchmark (Noël & Schoukens 2017, nonlinearbenchmark.org), read as the lab wrote "
        f"them (`--map {CHANNELS}`: acc1 on the wing, acc2 on the payload beside its mounting): satmd detects the "
        "periodic multisine "
        f"({datas[0].estimator['excitation']['periods']} periods of {datas[0].estimator['excitation']['period_s']:g} s)"
        " and estimates each FRF at the excited lines. The aircraft is not a SATMD rig "
        f"(model adequate: {rep.model_adequate}); no SATMD element is named. " + said, "",
        f"| resonance | {head} | trend | damping trend |",
        "|---|" + "---|" * len(levels) + "---|---|", *rows, "",
        ctx.figure(_figure(levels, recs, datas), "f16_levels.png"), "",
        "(95 % intervals; a trend is `none` when the change from the lowest to the highest level is within its "
        "uncertainty.)",
    ])
